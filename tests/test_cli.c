/* test_cli.c — the program as a user meets it: help, exit codes, error messages, the
 * device flag, and a real render to each output format. */
#include "cli_util.h"
#include "harness.h"

static CliResult r;   /* large: static */

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static void test_help_documents_every_flag(void)
{
    cli_run(ARGS("--help"), &r);
    CHECK_EQ_INT(r.status, 0);
    const char *flags[] = { "--output", "--spp", "--width", "--height", "--seed", "--max-depth", "--time-limit",
                            "--progressive-output", "--list-devices", "--device", "--threads", "--stats",
                            "--quiet", "--help", "--version", "--kernel-dir", "--batch", "--wave-paths",
                            "Exit status" };
    for (size_t i = 0; i < sizeof flags / sizeof flags[0]; i++) CHECK_STR_CONTAINS(r.out, flags[i]);
}

static void test_usage_errors(void)
{
    cli_run(ARGS("--spp"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--spp needs a value");
    cli_run(ARGS("scenes/cornell-box.scene", "--spp", "ten"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--spp expects an integer, got 'ten'");
    cli_run(ARGS("scenes/cornell-box.scene", "--width", "0"), &r);
    CHECK_EQ_INT(r.status, 2);
    cli_run(ARGS("--frobnicate"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "unknown option '--frobnicate'");
    cli_run(ARGS("-q"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "no scene given");
    cli_run(ARGS("scenes/cornell-box.scene", "-o", "image.jpg"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, ".jpg");
}

static void test_missing_scene_is_io_error(void)
{
    cli_run(ARGS("/nonexistent/scene.scene", "-o", "/tmp/x.png"), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "/nonexistent/scene.scene");
}

static void test_parse_error_names_line_and_column(void)
{
    char path[256];
    write_temp(path, sizeof path, ".scene", "# a bad scene\ncamera { from 0 0 5 at 0 0 0 }\nsphere { center 0 0 zero radius 1 }\n");
    cli_run(ARGS(path, "-o", "/tmp/clpt-never.png"), &r);
    CHECK_EQ_INT(r.status, 3);
    char where[300];
    snprintf(where, sizeof where, "%s:3:", path);
    CHECK_STR_CONTAINS(r.err, where);
    CHECK_STR_CONTAINS(r.err, "zero");
    CHECK(!file_exists("/tmp/clpt-never.png"));
    unlink(path);
}

static void test_unknown_device_lists_devices(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "99", "-o", "/tmp/clpt-never.png"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "no device matches '99'");
    CHECK_STR_CONTAINS(r.err, "scalar");
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "no-such-gpu", "-o", "/tmp/clpt-never.png"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "no-such-gpu");
}

static void test_list_devices(void)
{
    cli_run(ARGS("--list-devices"), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_STR_CONTAINS(r.out, "scalar");
    CHECK_STR_CONTAINS(r.out, "opencl");   /* PoCL is installed by make test */
}

static void check_render(const char *device, const char *out, const char *magic)
{
    unlink(out);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", device, "--width", "16", "--height", "12", "--spp", "2",
                 "-o", out),
            &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
    FILE *f = fopen(out, "rb");
    CHECK_MSG(f != NULL, "no output %s", out);
    if (f) {
        char head[8] = { 0 };
        size_t n = fread(head, 1, strlen(magic), f);
        CHECK(n == strlen(magic) && memcmp(head, magic, n) == 0);
        fclose(f);
    }
    CHECK_STR_CONTAINS(r.err, "Msamples/s");   /* the summary line */
    unlink(out);
}

static void test_render_each_format(void)
{
    check_render("scalar", "/tmp/clpt-test-render.png", "\x89PNG");
    check_render("cpu", "/tmp/clpt-test-render.ppm", "P6");
    check_render("0", "/tmp/clpt-test-render.pfm", "PF");
}

static void test_quiet_prints_nothing(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "-q", "--device", "scalar", "--width", "8", "--height", "8", "--spp", "1",
                 "-o", "/tmp/clpt-test-quiet.png"),
            &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_EQ_INT(strlen(r.err), 0);
    unlink("/tmp/clpt-test-quiet.png");
}

static void test_unwritable_output_is_io_error(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "8", "--height", "8", "--spp", "1",
                 "-o", "/nonexistent-dir/out.png"),
            &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "/nonexistent-dir/out.png");
}

static void test_stats(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--stats", "-q", "--device", "cpu", "--width", "8", "--height", "8",
                 "--spp", "1", "-o", "/tmp/clpt-test-stats.png"),
            &r);
    CHECK_EQ_INT(r.status, 0);
    const char *want[] = { "kd-tree: built in", "nodes", "leaves", "depth", "SAH cost", "kernels", "Msamples/s",
                           "Mrays/s", "total" };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) CHECK_STR_CONTAINS(r.out, want[i]);
    unlink("/tmp/clpt-test-stats.png");
}

/* stderr to a file (a batch log): plain progress lines, the first when the render
 * begins and then every 5 s, with no carriage return or escape code anywhere */
static void test_log_shows_plain_progress(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--threads", "1", "--width", "64", "--height",
                 "64", "--spp", "1000000", "--time-limit", "5.6", "-o", "/tmp/clpt-test-log.png"),
            &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(strchr(r.err, '\r') == NULL);
    CHECK(strchr(r.err, '\033') == NULL);
    CHECK_MSG(strncmp(r.err, "clpt: render 0%, ", 17) == 0, "%s", r.err);
    const char *nl = strchr(r.err, '\n');
    CHECK(nl && nl - r.err > 40 && strstr(r.err, "/1000000 spp, ") < nl && strstr(r.err, " 00:00 elapsed, ETA ") < nl);
    const char *second = strstr(r.err + 1, "clpt: render ");
    CHECK_MSG(second != NULL, "one progress line only: %s", r.err);
    if (second) {
        CHECK(strncmp(second, "clpt: render 0%, ", 17) == 0);
        CHECK_STR_CONTAINS(second, "samples/s, 00:05 elapsed, ETA ");
        CHECK(strstr(second, "-- samples/s") == NULL);
    }
    CHECK_STR_CONTAINS(r.err, "clpt: time limit reached:");
    unlink("/tmp/clpt-test-log.png");
}

/* the first build of the kernels for a device says so; a cache hit and -q do not */
static void test_kernel_build_notice(void)
{
    char cache[] = "/tmp/clpt-test-cache-XXXXXX";
    if (!mkdtemp(cache)) return;
    const char *saved = getenv("CLPT_CACHE_DIR");
    char *old = saved ? strdup(saved) : NULL;
    setenv("CLPT_CACHE_DIR", cache, 1);
    const char *out = "/tmp/clpt-test-notice.png";
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "0", "--width", "8", "--height", "8", "--spp", "1", "-q",
                 "-o", out), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(strstr(r.err, "compiling kernels") == NULL);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "0", "--width", "8", "--height", "8", "--spp", "1", "-o",
                 out), &r);
    CHECK(strstr(r.err, "compiling kernels") == NULL);     /* the quiet run filled the cache */
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -f %s/*.bin", cache);
    CHECK(system(cmd) == 0);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "0", "--width", "8", "--height", "8", "--spp", "1", "-o",
                 out), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.err, "clpt: compiling kernels for ");
    CHECK_STR_CONTAINS(r.err, " (first run; cached afterwards)...\n");
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "0", "--width", "8", "--height", "8", "--spp", "1", "-o",
                 out), &r);
    CHECK(strstr(r.err, "compiling kernels") == NULL);
    if (old) setenv("CLPT_CACHE_DIR", old, 1);
    else unsetenv("CLPT_CACHE_DIR");
    free(old);
    snprintf(cmd, sizeof cmd, "rm -rf %s", cache);
    CHECK(system(cmd) == 0);
    unlink(out);
}

int main(void)
{
    RUN(test_help_documents_every_flag);
    RUN(test_usage_errors);
    RUN(test_missing_scene_is_io_error);
    RUN(test_parse_error_names_line_and_column);
    RUN(test_unknown_device_lists_devices);
    RUN(test_list_devices);
    RUN(test_render_each_format);
    RUN(test_quiet_prints_nothing);
    RUN(test_unwritable_output_is_io_error);
    RUN(test_stats);
    RUN(test_log_shows_plain_progress);
    RUN(test_kernel_build_notice);
    return harness_report();
}
