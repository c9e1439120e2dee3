/* test_cli_habits.c — the command-line habits users bring from other programs (issue
 * 44): the version with its commit, `--` ending the options, bundled short options,
 * "did you mean", the usage hint said once, `-o -` and --stats=json. */
#include <ctype.h>

#include <cjson/cJSON.h>

#include "cli_util.h"
#include "harness.h"

static CliResult r;   /* large: static */

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })
/* a render of a second or less on the scalar device */
#define TINY "scenes/cornell-box.scene", "--device", "scalar", "--width", "8", "--height", "6", "--spp", "2"
#define HINT "Try 'clpt --help' for more information.\n"

/* The whole of stderr is `want` (a usage error: the message, then the hint once). */
#define CHECK_USAGE(args, want)                                                       \
    do {                                                                              \
        cli_run(args, &r);                                                            \
        CHECK_EQ_INT(r.status, 2);                                                    \
        CHECK_MSG(strcmp(r.err, want) == 0, "stderr:\n%s\nwanted:\n%s", r.err, want); \
    } while (0)

/* The bytes of a file (up to size - 1), their count in *n; 0 if it cannot be read. */
static int read_file(const char *path, char *buf, size_t size, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    *n = fread(buf, 1, size - 1, f);
    fclose(f);
    return 1;
}

/* The VERSION file's line, without its newline. */
static void read_version_file(char *buf, size_t size)
{
    buf[0] = '\0';
    FILE *f = fopen("VERSION", "r");
    if (!f) return;
    if (!fgets(buf, (int)size, f)) buf[0] = '\0';
    fclose(f);
    buf[strcspn(buf, "\n")] = '\0';
}

/* "clpt 0.2.0 (commit 0123456789ab)": the one version, and the commit (12 hex digits,
 * maybe -dirty) or "unknown" outside git. */
static void test_version_names_version_and_commit(void)
{
    char version[64], want[96];
    read_version_file(version, sizeof version);
    CHECK_MSG(version[0], "no VERSION file");
    cli_run(ARGS("--version"), &r);
    CHECK_EQ_INT(r.status, 0);
    snprintf(want, sizeof want, "clpt %s (commit ", version);
    CHECK_MSG(strncmp(r.out, want, strlen(want)) == 0, "--version printed '%s'", r.out);
    const char *c = r.out + strlen(want);
    size_t hex = 0;
    while (isxdigit((unsigned char)c[hex])) hex++;
    CHECK_MSG((hex == 12 && (strcmp(c + 12, ")\n") == 0 || strcmp(c + 12, "-dirty)\n") == 0)) ||
                  strcmp(c, "unknown)\n") == 0,
              "--version's commit: '%s'", c);
}

/* "--" ends the options: what follows is the scene, even when it looks like a flag. */
static void test_double_dash_ends_options(void)
{
    const char *out = TEST_TMP("clpt-test-habits-dd.pfm");
    remove(out);
    cli_run(ARGS("--device", "scalar", "--width", "8", "--height", "6", "--spp", "2", "-q", "-o", out, "--",
                 "scenes/cornell-box.scene"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(file_exists(out));
    cli_run(ARGS("-q", "--", "--spp"), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "'--spp'");
    CHECK_USAGE(ARGS("--", "a.scene", "--spp"), "clpt: error: more than one scene given: 'a.scene' and '--spp'\n" HINT);
    remove(out);
}

/* -qo FILE, -qoFILE: one-letter flags bundled as getopt reads them. */
static void test_bundled_short_options(void)
{
    const char *out = TEST_TMP("clpt-test-habits-bundle.pfm"), *glued = TEST_TMP("clpt-test-habits-glued.pfm");
    remove(out);
    remove(glued);
    cli_run(ARGS(TINY, "-qo", out), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(r.err[0] == '\0', "-q in a bundle: stderr '%s'", r.err);
    CHECK(file_exists(out));
    char glued_flag[1024];
    snprintf(glued_flag, sizeof glued_flag, "-qo%s", glued);
    cli_run(ARGS(TINY, glued_flag), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(out, glued));
    CHECK_USAGE(ARGS(TINY, "-qz"), "clpt: error: unknown option '-z' in '-qz'\n" HINT);
    CHECK_USAGE(ARGS(TINY, "-qo"), "clpt: error: -o needs a value\n" HINT);
    remove(out);
    remove(glued);
}

/* A near miss names the flag meant; the hint at --help comes once, from main. */
static void test_did_you_mean(void)
{
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "--sp", "4"),
                "clpt: error: unknown option '--sp'; did you mean '--spp'?\n" HINT);
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "--sampel=sobol"),
                "clpt: error: unknown option '--sampel'; did you mean '--sampler'?\n" HINT);
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "-spp", "4"),
                "clpt: error: unknown option '-spp'; did you mean '--spp'?\n" HINT);
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "--frobnicate"), "clpt: error: unknown option '--frobnicate'\n" HINT);
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "-x"), "clpt: error: unknown option '-x'\n" HINT);
    CHECK_USAGE(ARGS("-q"), "clpt: error: no scene given (usage: clpt [options] SCENE)\n" HINT);
}

/* --flag=value for flags with values; a switch takes none, unless it lists words. */
static void test_equals_values(void)
{
    const char *out = TEST_TMP("clpt-test-habits-eq.pfm");
    char output_flag[1024];
    snprintf(output_flag, sizeof output_flag, "--output=%s", out);
    cli_run(ARGS("scenes/cornell-box.scene", "--device=scalar", "--width=8", "--height=6", "--spp=2", "-q",
                 output_flag), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(file_exists(out));
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "--quiet=yes"), "clpt: error: --quiet takes no value, got '--quiet=yes'\n" HINT);
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "--spp="), "clpt: error: --spp expects an integer, got ''\n" HINT);
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "--stats=xml"),
                "clpt: error: --stats expects 'text' or 'json', got 'xml'\n" HINT);
    remove(out);
}

/* -o - writes the image to stdout (PNG; FORMAT:- for the others), the same bytes as
 * the file; --stats then goes to stderr. */
static void test_output_to_stdout(void)
{
    static char file[CLI_OUT_MAX];
    const char *pfm = TEST_TMP("clpt-test-habits-stdout.pfm");
    size_t n = 0;
    cli_run(ARGS(TINY, "-q", "-o", pfm), &r);
    CHECK_MSG(r.status == 0 && read_file(pfm, file, sizeof file, &n), "%s", r.err);
    cli_run(ARGS(TINY, "-q", "-o", "pfm:-"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(n > 0 && memcmp(r.out, file, n) == 0, "-o pfm:- differs from -o %s", pfm);
    cli_run(ARGS(TINY, "-o", "-", "--stats"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(memcmp(r.out, "\x89PNG\r\n\x1a\n", 8) == 0);
    CHECK_STR_CONTAINS(r.err, "\nfilm: 2 of 2 samples per pixel");
    CHECK_STR_CONTAINS(r.err, "-> standard output\n");
    cli_run(ARGS(TINY, "-q", "-o", "EXR:-"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(memcmp(r.out, "\x76\x2f\x31\x01", 4) == 0);
    CHECK(!file_exists("-") && !file_exists("EXR:-"));
    CHECK_USAGE(ARGS(TINY, "-o", "tga:-"), "clpt: error: cannot write the image to standard output as 'tga': -o - "
                                          "writes PNG, and FORMAT:- one of png, jpg, ppm, pfm, bmp, exr, hdr\n" HINT);
    CHECK_USAGE(ARGS(TINY, "-o", "-", "--aov", "normal"),
                "clpt: error: --aov cannot be used with -o -: standard output takes the image once, and --aov "
                "writes it again or beside it; name a file with -o\n" HINT);
    CHECK_USAGE(ARGS(TINY, "-o", "exr:-", "--progressive-output", "1"),
                "clpt: error: --progressive-output cannot be used with -o exr:-: standard output takes the image "
                "once, and --progressive-output writes it again or beside it; name a file with -o\n" HINT);
    remove(pfm);
}

/* --stats=json: one JSON object on stdout, with the render's numbers. */
static void test_stats_json(void)
{
    cli_run(ARGS(TINY, "-q", "-o", TEST_TMP("clpt-test-habits-json.pfm"), "--stats=json"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(strchr(r.out, '\n') == r.out + strlen(r.out) - 1, "not one line: %s", r.out);
    cJSON *j = cJSON_Parse(r.out);
    CHECK_MSG(j, "not JSON: %s", r.out);
    if (j) {
        CHECK_EQ_INT(cJSON_GetObjectItem(j, "width")->valueint, 8);
        CHECK_EQ_INT(cJSON_GetObjectItem(j, "height")->valueint, 6);
        CHECK_EQ_INT(cJSON_GetObjectItem(j, "spp_done")->valueint, 2);
        CHECK_EQ_INT((int)cJSON_GetObjectItem(j, "samples")->valuedouble, 8 * 6 * 2);
        CHECK(strcmp(cJSON_GetObjectItem(j, "result")->valuestring, "rendered") == 0);
        CHECK(strcmp(cJSON_GetObjectItem(j, "output")->valuestring, TEST_TMP("clpt-test-habits-json.pfm")) == 0);
        cJSON *devs = cJSON_GetObjectItem(j, "devices");
        CHECK(cJSON_IsArray(devs) && cJSON_GetArraySize(devs) == 1);
        CHECK_STR_CONTAINS(cJSON_GetObjectItem(cJSON_GetArrayItem(devs, 0), "name")->valuestring, "scalar");
        CHECK_EQ_INT(cJSON_GetObjectItem(cJSON_GetObjectItem(j, "scene_contents"), "lights")->valueint, 2);
        cJSON_Delete(j);
    }
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "--interactive", "--stats=json"),
                "clpt: error: --interactive cannot be combined with --stats=json (the viewer saves frames with the C "
                "key; see docs/viewer.md)\n" HINT);
    remove(TEST_TMP("clpt-test-habits-json.pfm"));
}

int main(void)
{
    RUN(test_version_names_version_and_commit);
    RUN(test_double_dash_ends_options);
    RUN(test_bundled_short_options);
    RUN(test_did_you_mean);
    RUN(test_equals_values);
    RUN(test_output_to_stdout);
    RUN(test_stats_json);
    return harness_report();
}
