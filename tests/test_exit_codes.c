/* test_exit_codes.c — every exit code of docs/exit-codes.md, by running the program:
 * 0 success, 1 internal, 2 usage, 3 input, 4 I/O, 5 device, 6 interrupted, 7 nothing
 * rendered. Codes 1 and
 * 5 are provoked with the test-only variables of host/base/fault.h. */
#include <time.h>

#include "cli_util.h"
#include "harness.h"

static CliResult r;   /* large: static */

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })
#define SMALL "--width", "16", "--height", "12", "--spp", "2"

static void test_0_success(void)
{
    const char *out = TEST_TMP("clpt-test-exit0.ppm");
    unlink(out);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", SMALL, "-o", out), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK(file_exists(out));
    unlink(out);
}

static void test_1_internal(void)
{
    const char *out = TEST_TMP("clpt-test-exit1.png");
    unlink(out);
    setenv("CLPT_TEST_FAIL_ALLOC", "film", 1);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", SMALL, "-o", out), &r);
    unsetenv("CLPT_TEST_FAIL_ALLOC");
    CHECK_EQ_INT(r.status, 1);
    CHECK_STR_CONTAINS(r.err, "clpt: error: out of memory for a 16x12 film");
    CHECK(!file_exists(out));
}

static void test_2_usage(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--spp", "0"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--spp must be between 1 and 1000000, got 0");
    CHECK_STR_CONTAINS(r.err, "Try 'clpt --help'");
    /* each side is allowed, the product is not */
    cli_run(ARGS("scenes/cornell-box.scene", "--width", "16384", "--height", "16384", "-o", TEST_TMP("clpt-never.png")), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--width/--height: an image of 16384x16384 pixels is larger than clpt renders");
    CHECK(!file_exists(TEST_TMP("clpt-never.png")));
}

/* A scene's image too large to render is checked after --width and --height, which
 * can make it small: the parse refused it before the flags were looked at. */
static void test_flags_rescue_a_large_scene_image(void)
{
    const char *out = TEST_TMP("clpt-test-rescued.png");
    unlink(out);
    cli_run(ARGS("tests/data/huge-image.scene", "--device", "scalar", "--threads", "1", "-q", "--width", "64",
                 "--height", "48", "-o", out), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(file_exists(out));
    unlink(out);
    /* one flag leaves the other side too large */
    cli_run(ARGS("tests/data/huge-image.scene", "--device", "scalar", "--width", "64", "-o", out), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --width/--height: an image of 64x100000 pixels is larger than clpt "
                              "renders (at most 134217728 pixels, as in 16384x8192, and 16384 on each side)\n");
    /* no flag: the file's own size, at its place */
    cli_run(ARGS("tests/data/huge-image.scene", "--device", "scalar", "-o", out), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_STR_CONTAINS(r.err, "clpt: error: tests/data/huge-image.scene:3:22: an image of 100000x100000 pixels is "
                              "larger than clpt renders (at most 134217728 pixels, as in 16384x8192, and 16384 on "
                              "each side); --width and --height render it smaller\n");
    CHECK(!file_exists(out));
}

static void test_3_input(void)
{
    cli_run(ARGS("tests/data/bad/zero-radius.scene", "-o", TEST_TMP("clpt-never.png")), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_STR_CONTAINS(r.err, "tests/data/bad/zero-radius.scene:3:30: expected a radius > 0 for 'radius', found '0'");
    CHECK(!file_exists(TEST_TMP("clpt-never.png")));
}

static void test_4_io(void)
{
    cli_run(ARGS("tests/data/no-such.scene", "-o", TEST_TMP("clpt-never.png")), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "cannot open 'tests/data/no-such.scene': No such file or directory");
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", SMALL, "-o", "/nonexistent-dir/x.png"), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "/nonexistent-dir/x.png");
}

static void test_5_device(void)
{
    const char *out = TEST_TMP("clpt-test-exit5.png");
    unlink(out);
    setenv("CLPT_TEST_DEVICE_MEMORY", "0:1048576", 1);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "0", SMALL, "-o", out), &r);
    unsetenv("CLPT_TEST_DEVICE_MEMORY");
    CHECK_EQ_INT(r.status, 5);
    CHECK_STR_CONTAINS(r.err, "more than its largest allocation (1.0 MiB)");
    CHECK(!file_exists(out));
}

static void test_6_interrupted(void)
{
    const char *out = TEST_TMP("clpt-test-exit6.pfm");
    unlink(out);
    /* the first progressive image shows the render has started (the signal handlers
     * are in place by then) */
    CliChild c = cli_start(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--threads", "1", "--width", "32",
                                "--height", "32", "--spp", "1000000", "--progressive-output", "0.1", "-o", out));
    for (int i = 0; i < 400 && !file_exists(out); i++) {
        struct timespec ts = { 0, 50000000L };
        nanosleep(&ts, NULL);
    }
    CHECK(file_exists(out));
    kill(c.pid, SIGINT);
    cli_finish(c, &r);
    CHECK_EQ_INT(r.status, 6);
    CHECK_STR_CONTAINS(r.err, "interrupted:");
    CHECK(file_exists(out));
    unlink(out);
}

static void test_7_nothing_rendered(void)
{
    const char *out = TEST_TMP("clpt-test-exit7.png");
    FILE *f = fopen(out, "w");
    if (f) {
        fputs("an older image", f);
        fclose(f);
    }
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", SMALL, "--time-limit", "1e-9", "-o", out), &r);
    CHECK_EQ_INT(r.status, 7);
    char want[512];
    snprintf(want, sizeof want, "nothing was rendered, and '%s' was left as it was", out);
    CHECK_STR_CONTAINS(r.err, want);
    struct stat sb;
    CHECK(stat(out, &sb) == 0 && sb.st_size == 14);
    unlink(out);
}

/* the table in --help and in docs/exit-codes.md */
static void test_documented(void)
{
    cli_run(ARGS("--help"), &r);
    const char *help[] = { "0  success", "1  internal error", "2  usage error", "3  input error", "4  I/O error",
                           "5  device error", "6  interrupted", "7  nothing rendered" };
    for (size_t i = 0; i < sizeof help / sizeof help[0]; i++) CHECK_STR_CONTAINS(r.out, help[i]);
    FILE *f = fopen("docs/exit-codes.md", "r");
    CHECK(f != NULL);
    if (!f) return;
    static char doc[16384];
    size_t n = fread(doc, 1, sizeof doc - 1, f);
    doc[n] = '\0';
    fclose(f);
    const char *rows[] = { "| 0    | success", "| 1    | internal", "| 2    | usage", "| 3    | input", "| 4    | I/O",
                           "| 5    | device", "| 6    | interrupted", "| 7    | nothing rendered" };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) CHECK_STR_CONTAINS(doc, rows[i]);
}

int main(void)
{
    RUN(test_0_success);
    RUN(test_1_internal);
    RUN(test_2_usage);
    RUN(test_flags_rescue_a_large_scene_image);
    RUN(test_3_input);
    RUN(test_4_io);
    RUN(test_5_device);
    RUN(test_6_interrupted);
    RUN(test_7_nothing_rendered);
    RUN(test_documented);
    return harness_report();
}
