/* test_cli.c — the program as a user meets it: help, exit codes, error messages, the
 * device flag, and a real render to each output format. */
#include <math.h>
#include <time.h>

#include "cli_util.h"
#include "harness.h"
#include "options.h"

static CliResult r;   /* large: static */

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static void test_help_documents_every_flag(void)
{
    cli_run(ARGS("--help"), &r);
    CHECK_EQ_INT(r.status, 0);
    const char *flags[] = { "--output", "--spp", "--width", "--height", "--seed", "--max-depth", "--split", "--time-limit",
                            "--progressive-output", "--list-devices", "--device", "--threads", "--stats",
                            "--quiet", "--help", "--version", "--kernel-dir", "--batch", "--wave-paths", "--wave-launch",
                            "--shadows", "--sampler", "--accel", "--profile", "-size W H -input SCENE -output FILE", "-depth NEAR FAR FILE",
                            "-bounces N", "clpt SCENE OUT.bmp", "Exit status" };
    for (size_t i = 0; i < sizeof flags / sizeof flags[0]; i++) CHECK_STR_CONTAINS(r.out, flags[i]);
}

/* Every flag of options.c's list has its line in --help ("  -o, --output" or
 * "      --spp") and is read into Options: parsing it with a good value changes what a
 * bare command line gives. A CUSTOM flag needs a value from this table. */
static void test_every_listed_flag_is_documented_and_parsed(void)
{
    static const struct { const char *flag, *value; } custom[] = {
        { "--aov", "normal" }, { "--depth-range", "1,2" }, { "--sample-range", "0:1" }, { "--adaptive", "0.5" },
        { "--frames", "0:1" }, { "--fps", "30" }, { "--time", "1" }, { "--shutter", "0:1" },
        { "--exposure", "-1.5" }, { "--noise-threshold", "0.05" }, { "--clamp", "10" },
        { "--set", "camera.fov=30" }, { "--crop", "0,0.5,0,1" }, { "--pixel-bounds", "0,8,0,8" },
        { "--lookat", "0,0,5,0,0,0,0,1,0" }, { "--fov", "30" },
        { "--display-server", "localhost:14158" }, { "--split", "auto" },
    };
    cli_run(ARGS("--help"), &r);
    CHECK_EQ_INT(r.status, 0);
    Options base, with;
    Error err = { 0 };
    char prog[] = "clpt", scene[] = "scene.scene";
    char *bare[] = { prog, scene, NULL };
    CHECK_EQ_INT(options_parse(2, bare, &base, &err), ST_OK);
    size_t n = 0;
    for (const OptionSpec *s; (s = options_flag(n)); n++) {
        char line[96];
        snprintf(line, sizeof line, "\n  %s%s%s", s->alias ? s->alias : "  ", s->alias ? ", " : "  ", s->name);
        CHECK_MSG(strstr(r.out, line), "--help has no line for %s", s->name);
        char value[64] = "";
        switch (s->kind) {
        case OPTION_SWITCH: break;
        case OPTION_TEXT: snprintf(value, sizeof value, "x"); break;
        case OPTION_LONG: case OPTION_UINT: case OPTION_INT: snprintf(value, sizeof value, "%ld", s->hi); break;
        case OPTION_SECONDS: snprintf(value, sizeof value, "2.5"); break;
        case OPTION_CHOICE: {
            size_t last = 0;
            while (s->choices[last + 1].name) last++;
            snprintf(value, sizeof value, "%s", s->choices[last].name);
            break;
        }
        case OPTION_CUSTOM:
            for (size_t k = 0; k < sizeof custom / sizeof custom[0]; k++)
                if (strcmp(custom[k].flag, s->name) == 0) snprintf(value, sizeof value, "%s", custom[k].value);
            CHECK_MSG(value[0], "%s: give this test a value for it", s->name);
            break;
        }
        for (int form = 0; form < (s->alias ? 2 : 1); form++) {
            char *argv[] = { prog, scene, (char *)(form ? s->alias : s->name), value, NULL };
            int argc = s->kind == OPTION_SWITCH ? 3 : 4;
            error_clear(&err);
            memset(&with, 0, sizeof with);
            Status st = options_parse(argc, argv, &with, &err);
            CHECK_MSG(!strstr(err.msg, "unknown option") && !strstr(err.msg, "expects") && !strstr(err.msg, "needs a"),
                      "%s %s: %s", argv[2], value, err.msg);
            CHECK_MSG(memcmp(&with, &base, sizeof base) != 0, "%s %s (status %d) sets nothing", argv[2], value, (int)st);
        }
    }
    CHECK_MSG(n >= 40, "options_flag lists %zu flags", n);
}

static void test_usage_errors(void)
{
    static const CliRefusal refused[] = {
        { { "--spp" },
          "--spp needs a value" },
        { { "scenes/cornell-box.scene", "--spp", "ten" },
          "--spp expects an integer, got 'ten'" },
        { { "scenes/cornell-box.scene", "--width", "0" },
          NULL },
        { { "scenes/cornell-box.scene", "--split", "0" },
          "--split expects auto or an integer in 1..64, got '0'" },
        { { "scenes/cornell-box.scene", "--split", "some" },
          "--split expects auto or an integer in 1..64, got 'some'" },
        { { "--frobnicate" },
          "unknown option '--frobnicate'" },
        { { "-q" },
          "no scene given" },
        { { "scenes/cornell-box.scene", "-o", "image.tga" },
          "unsupported extension '.tga' (supported: .png, .jpg, .jpeg, .ppm, .pfm, .bmp, .exr, "
          ".hdr)" },
        { { "scenes/cornell-box.scene", "-o", "image.png", "--jpeg-quality", "80" },
          "clpt: error: --jpeg-quality sets the quality of a JPEG output, and 'image.png' is none "
          "(write a .jpg or .jpeg, or leave it out)\n" },
        { { "scenes/cornell-box.scene", "-o", "image.jpg", "--png-depth", "16" },
          "clpt: error: --png-depth sets the bits of a PNG output, and 'image.jpg' is none "
          "(write a .png, or leave it out)\n" },
        { { "scenes/cornell-box.scene", "-o", "image.jpg", "--jpeg-quality", "0" },
          "--jpeg-quality must be between 1 and 100, got 0" },
        { { "scenes/cornell-box.scene", "-o", "image.png", "--png-depth", "12" },
          "--png-depth expects '8' or '16', got '12'" },
        { { "scenes/cornell-box.scene", "--sampler", "halton" },
          "--sampler expects 'sobol' or 'independent', got 'halton'" },
        { { "scenes/cornell-box.scene", "--accel", "octree" },
          "--accel expects 'bvh' or 'kdtree', got 'octree'" },
        { { "scenes/cornell-box.scene", "--wave-launch", "fast" },
          "--wave-launch expects 'counted', 'bounded' or 'megakernel', got 'fast'" },
        /* a blank before a number was skipped (" 5" was 5, "5 " refused): refused too */
        { { "scenes/cornell-box.scene", "--spp", " 5" },
          "clpt: error: --spp expects an integer, got ' 5'" },
        { { "scenes/cornell-box.scene", "--time-limit", " 5" },
          "--time-limit expects a positive number of seconds, got ' 5'" },
        { { "scenes/cornell-box.scene", "--sample-range", "0: 5" },
          "--sample-range expects A:B" },
        /* flags that shape what another flag turns on were ignored alone */
        { { "scenes/cornell-box.scene", "--adaptive-spp", "8" },
          "clpt: error: --adaptive-spp sets the samples of the adaptive pass, which --adaptive "
          "THRESHOLD turns on; give both, or neither" },
        { { "scenes/cornell-box.scene", "--depth-range", "1,10" },
          "clpt: error: --depth-range scales the depth image, which --aov depth turns on; "
          "give both, or neither" },
        { { "scenes/cornell-box.scene", "--depth-range", "1,10", "--aov", "normal" },
          NULL },
    };
    cli_check_refusals(refused, sizeof refused / sizeof refused[0], ST_USAGE);
}

/* The three ways an OpenCL device runs a wave (--wave-launch: counted; bounded, the
 * GPUs' default, here forced on PoCL; megakernel, the CPUs') give the scalar device's
 * bits, with small waves (several per batch) and several batches, and report the same
 * number of rays. The Cornell box suits k_path_lanes (device_ocl.c), so the megakernel
 * here is the one that shades eight paths at once in float8. */
static void test_wave_launches_match_scalar(void)
{
    const char *modes[] = { "counted", "bounded", "megakernel" };
    const char *outs[] = { TEST_TMP("clpt-test-launch-counted.pfm"), TEST_TMP("clpt-test-launch-bounded.pfm"),
                           TEST_TMP("clpt-test-launch-megakernel.pfm") };
    const char *ref = TEST_TMP("clpt-test-launch-scalar.pfm");
    double rays[3] = { 0.0, -1.0, -1.0 };
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "40", "--height", "32", "--spp", "12",
                 "--seed", "9", "-q", "-o", ref),
            &r);
    CHECK_EQ_INT(r.status, 0);
    for (int i = 0; i < 3; i++) {
        cli_run(ARGS("scenes/cornell-box.scene", "--device", TEST_OPENCL, "--width", "40", "--height", "32", "--spp", "12",
                     "--seed", "9", "--wave-launch", modes[i], "--wave-paths", "1000", "--batch", "5", "--stats", "-q",
                     "-o", outs[i]),
                &r);
        CHECK_MSG(r.status == 0, "%s: %s", modes[i], r.err);
        CHECK_MSG(files_equal(ref, outs[i]), "--wave-launch %s: the image differs from the scalar device's", modes[i]);
        /* --stats names the wave size and how a wave runs */
        const char *runs[] = { "waves of 1000 paths, counted bounces", "waves of 1000 paths, bounded bounces",
                               "waves of 1000 paths, megakernel k_path" };   /* _lanes on CPUs */
        CHECK_STR_CONTAINS(r.out, runs[i]);
        /* the total line: samples, seconds, Msamples/s, Mrays/s; rays per sample compared
         * (both rates printed to 3 decimals: equal to within their rounding) */
        const char *t = strstr(r.out, "\ntotal");
        double samples = 0, secs = 0, ms = 0, mr = 0;
        if (t && sscanf(t + 6, "%lf %lf %lf %lf", &samples, &secs, &ms, &mr) == 4 && ms > 0) rays[i] = mr / ms;
        unlink(outs[i]);
    }
    for (int i = 1; i < 3; i++)
        CHECK_MSG(rays[0] > 1.0 && fabs(rays[0] - rays[i]) < 0.01 * rays[0], "rays per sample: counted %.3f, %s %.3f",
                  rays[0], modes[i], rays[i]);
    unlink(ref);
}

/* --split auto, the default: the pilot chooses the same split on the scalar device, on
 * OpenCL and on both at once, and the image is that split's, bit for bit, also when a
 * render of fewer samples is grown to these; an image too small for a pilot keeps
 * split 1 (one-weekend.scene at 400x225: its pilot chooses 2, 0.78 of split 1's error
 * x rays on its fitted curve, with 4 no better and 16 twice split 1's). */
static void test_split_auto_chooses_alike(void)
{
    const char *devices[] = { "scalar", TEST_OPENCL };
    const char *outs[] = { TEST_TMP("clpt-test-split-scalar.pfm"), TEST_TMP("clpt-test-split-opencl.pfm") };
    const char *ref = TEST_TMP("clpt-test-split-2.pfm"), *ck = TEST_TMP("clpt-test-split.ckpt");
    cli_run(ARGS("scenes/one-weekend.scene", "--device", "scalar", "--spp", "6", "--split", "2", "-q", "-o", ref), &r);
    CHECK_EQ_INT(r.status, 0);
    for (int i = 0; i < 2; i++) {
        cli_run(ARGS("scenes/one-weekend.scene", "--device", devices[i], "--spp", "6", "--batch", i ? "2" : "6",
                     "--stats=json", "-q", "-o", outs[i]),
                &r);
        CHECK_MSG(r.status == 0, "%s: %s", devices[i], r.err);
        CHECK_STR_CONTAINS(r.out, "\"split\":{\"chosen\":2,\"auto\":true,\"pilot\":{\"pixels\":1100,\"spp\":8");
        CHECK_MSG(files_equal(ref, outs[i]), "%s: split auto's image differs from --split 2's", devices[i]);
        unlink(outs[i]);
    }
    /* 2 samples with a checkpoint, grown to 6 on both devices: the same split and image */
    unlink(ck);
    cli_run(ARGS("scenes/one-weekend.scene", "--device", "scalar", "--spp", "2", "--checkpoint", ck, "-q", "-o",
                 outs[0]),
            &r);
    CHECK_EQ_INT(r.status, 0);
    cli_run(ARGS("scenes/one-weekend.scene", "--device", "cpu,scalar", "--spp", "6", "--resume", ck,
                 "--stats", "-q", "-o", outs[1]),
            &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.out, "split: 2, chosen by a pilot of 1100 pixels x 8 spp in ");
    CHECK_STR_CONTAINS(r.out, "(error x rays against split 1, measured: 2 0.");
    CHECK_STR_CONTAINS(r.out, "; fitted: 2 0.");
    CHECK_MSG(files_equal(ref, outs[1]), "grown from 2 to 6 samples: the image differs from --split 2's");
    /* too small for a pilot: split 1's image */
    cli_run(ARGS("scenes/one-weekend.scene", "--device", "scalar", "--width", "64", "--height", "48", "--spp", "16",
                 "--split", "1", "-q", "-o", ref),
            &r);
    CHECK_EQ_INT(r.status, 0);
    cli_run(ARGS("scenes/one-weekend.scene", "--device", TEST_OPENCL, "--width", "64", "--height", "48", "--spp", "16",
                 "--stats", "-q", "-o", outs[1]),
            &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_STR_CONTAINS(r.out, "split: 1 (auto without a pilot: an image under 256x256, or a camera in a medium)");
    CHECK(files_equal(ref, outs[1]));
    unlink(outs[0]);
    unlink(outs[1]);
    unlink(ref);
    unlink(ck);
}

static void test_missing_scene_is_io_error(void)
{
    cli_run(ARGS("/nonexistent/scene.scene", "-o", TEST_TMP("x.png")), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "/nonexistent/scene.scene");
}

static void test_parse_error_names_line_and_column(void)
{
    char path[256];
    write_temp(path, sizeof path, ".scene", "# a bad scene\ncamera { from 0 0 5 at 0 0 0 }\nsphere { center 0 0 zero radius 1 }\n");
    cli_run(ARGS(path, "-o", TEST_TMP("clpt-never.png")), &r);
    CHECK_EQ_INT(r.status, 3);
    char where[300];
    snprintf(where, sizeof where, "%s:3:", path);
    CHECK_STR_CONTAINS(r.err, where);
    CHECK_STR_CONTAINS(r.err, "zero");
    CHECK(!file_exists(TEST_TMP("clpt-never.png")));
    unlink(path);
}

static void test_unknown_device_lists_devices(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "99", "-o", TEST_TMP("clpt-never.png")), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "no device matches '99'");
    CHECK_STR_CONTAINS(r.err, "scalar");
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "no-such-gpu", "-o", TEST_TMP("clpt-never.png")), &r);
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
    check_render("scalar", TEST_TMP("clpt-test-render.png"), "\x89PNG");
    check_render(TEST_OPENCL, TEST_TMP("clpt-test-render.ppm"), "P6");
    check_render("0", TEST_TMP("clpt-test-render.pfm"), "PF");
}

/* --view and --exposure: the default and "--view standard --exposure 0" are the same
 * bytes; agx, filmic and an exposure change the PNG; a float output, a bad view or
 * exposure is a usage error before rendering; merge takes them too. */
static void test_view_flags(void)
{
#define VIEW_RENDER "scenes/cornell-box.scene", "-q", "--device", "scalar", "--width", "16", "--height", "12", \
                    "--spp", "2"
    const char *plain = TEST_TMP("clpt-test-view-plain.png"), *same = TEST_TMP("clpt-test-view-same.png"),
               *other = TEST_TMP("clpt-test-view-other.png");
    cli_run(ARGS(VIEW_RENDER, "-o", plain), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(VIEW_RENDER, "--view", "standard", "--exposure", "0", "-o", same), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(plain, same));
    const char *looks[][2] = { { "--view", "agx" }, { "--view", "filmic" }, { "--exposure", "-1.5" } };
    for (int k = 0; k < 3; k++) {
        cli_run(ARGS(VIEW_RENDER, looks[k][0], looks[k][1], "-o", other), &r);
        CHECK_MSG(r.status == 0, "%s %s: %s", looks[k][0], looks[k][1], r.err);
        CHECK_MSG(!files_equal(plain, other), "%s %s left the PNG as it was", looks[k][0], looks[k][1]);
    }
    cli_run(ARGS(VIEW_RENDER, "--view", "aces", "-o", other), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --view expects 'standard', 'agx' or 'filmic', got 'aces'\n");
    cli_run(ARGS(VIEW_RENDER, "--exposure", "33", "-o", other), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --exposure expects a number of stops from -32 to 32, got '33'\n");
    cli_run(ARGS(VIEW_RENDER, "--exposure", "1 ", "-o", other), &r);
    CHECK_EQ_INT(r.status, 2);
    unlink(TEST_TMP("clpt-test-view.pfm"));
    cli_run(ARGS(VIEW_RENDER, "--view", "agx", "-o", TEST_TMP("clpt-test-view.pfm")), &r);
    CHECK_EQ_INT(r.status, 2);
    char want[1024];
    snprintf(want, sizeof want,
             "clpt: error: --view and --exposure form the picture of 8-bit images; "
             "'%s' keeps the linear radiance (write a .png, .jpg, .ppm or .bmp, or "
             "leave them out)\n", TEST_TMP("clpt-test-view.pfm"));
    CHECK_STR_CONTAINS(r.err, want);
    CHECK(!file_exists(TEST_TMP("clpt-test-view.pfm")));
    /* merge: a part merged with --view agx is the render's agx PNG */
    const char *part = TEST_TMP("clpt-test-view.ckpt"), *merged = TEST_TMP("clpt-test-view-merged.png");
    cli_run(ARGS(VIEW_RENDER, "--view", "agx", "--exposure", "0.5", "-o", other, "--checkpoint", part), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS("merge", "-q", "--view", "agx", "--exposure", "0.5", "-o", merged, part), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(other, merged));
    cli_run(ARGS("merge", "-q", "--view", "log", "-o", merged, part), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: merge: --view expects 'standard', 'agx' or 'filmic', got 'log'\n");
    cli_run(ARGS("merge", "-q", "--exposure", "x", "-o", merged, part), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: merge: --exposure expects a number of stops from -32 to 32, got 'x'\n");
    unlink(plain);
    unlink(same);
    unlink(other);
    unlink(part);
    unlink(merged);
#undef VIEW_RENDER
}

static void test_quiet_prints_nothing(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "-q", "--device", "scalar", "--width", "8", "--height", "8", "--spp", "1",
                 "-o", TEST_TMP("clpt-test-quiet.png")),
            &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_EQ_INT(strlen(r.err), 0);
    unlink(TEST_TMP("clpt-test-quiet.png"));
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
    cli_run(ARGS("scenes/cornell-box.scene", "--stats", "-q", "--device", TEST_OPENCL, "--width", "8", "--height", "8",
                 "--spp", "1", "-o", TEST_TMP("clpt-test-stats.png")),
            &r);
    CHECK_EQ_INT(r.status, 0);
    const char *want[] = { "BVH: built in", "nodes of 8", "leaves", "depth", "SAH cost", "kernels", "waves of",
                           "Msamples/s", "Mrays/s", "total" };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) CHECK_STR_CONTAINS(r.out, want[i]);
    /* the kd-tree on request, and the same image */
    CHECK(rename(TEST_TMP("clpt-test-stats.png"), TEST_TMP("clpt-test-stats-bvh.png")) == 0);
    cli_run(ARGS("scenes/cornell-box.scene", "--stats", "-q", "--device", TEST_OPENCL, "--width", "8", "--height", "8",
                 "--spp", "1", "--accel", "kdtree", "-o", TEST_TMP("clpt-test-stats.png")),
            &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_STR_CONTAINS(r.out, "kd-tree: built in");
    CHECK(files_equal(TEST_TMP("clpt-test-stats.png"), TEST_TMP("clpt-test-stats-bvh.png")));
    unlink(TEST_TMP("clpt-test-stats.png"));
    unlink(TEST_TMP("clpt-test-stats-bvh.png"));
}

/* --profile: the stats, then each device's time per phase; the traversal and shading of
 * a real render take some time on both kinds of device. The table prints milliseconds, so
 * the render is large enough to show some on a fast GPU or sixteen cores (32x32 at 4 spp
 * printed 0.000 s of shading on an H200). */
static void test_profile(void)
{
    const char *devices[] = { TEST_OPENCL, "scalar" };
    for (int i = 0; i < 2; i++) {
        cli_run(ARGS("scenes/cornell-box.scene", "--profile", "-q", "--device", devices[i], "--width", "128",
                     "--height", "128", "--spp", "16", "-o", TEST_TMP("clpt-test-profile.png")),
                &r);
        CHECK_EQ_INT(r.status, 0);
        const char *want[] = { "Msamples/s", "profile (seconds", "raygen", "traverse", "shade", "shadow", "film",
                               "queues", "host wait" };
        for (size_t k = 0; k < sizeof want / sizeof want[0]; k++) CHECK_STR_CONTAINS(r.out, want[k]);
        /* the device's row: its name in 32 columns, then (seconds, share) per phase */
        const char *row = strstr(r.out, "host wait");
        row = row ? strchr(row, '\n') : NULL;
        double t[3] = { 0 };
        int n = row && strlen(row) > 33 ? sscanf(row + 33, "%lf %*s %lf %*s %lf", &t[0], &t[1], &t[2]) : 0;
        CHECK_MSG(n == 3 && t[1] > 0.0 && t[2] > 0.0, "%s: traversal %g s, shading %g s in:\n%s", devices[i], t[1],
                  t[2], r.out);
    }
    unlink(TEST_TMP("clpt-test-profile.png"));
}

#define SMALL "--device", "scalar", "--width", "8", "--height", "8", "--spp", "1"

static int count_of(const char *hay, const char *needle)
{
    int n = 0;
    for (const char *p = hay; (p = strstr(p, needle)); p += strlen(needle)) n++;
    return n;
}

static void wait_for_file(const char *path)
{
    for (int i = 0; i < 400 && !file_exists(path); i++) {
        struct timespec ts = { 0, 25000000L };
        nanosleep(&ts, NULL);
    }
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static int file_holds(const char *path, const char *text)
{
    char buf[256] = { 0 };
    FILE *f = fopen(path, "r");
    if (!f) return 0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    return n == strlen(text) && memcmp(buf, text, n) == 0;
}

/* Runs clpt with its stdout on `out_fd` (SIGPIPE as a shell leaves it: default). */
static void run_with_stdout(const char *const *args, int out_fd, CliResult *res)
{
    char err_name[] = "/tmp/clpt-cli-err-XXXXXX";
    int err_fd = mkstemp(err_name);
    unlink(err_name);
    const char *argv[64] = { CLI_PROGRAM };
    int n = 1;
    for (; args[n - 1] && n < 63; n++) argv[n] = args[n - 1];
    argv[n] = NULL;
    pid_t pid = fork();
    if (pid == 0) {
        signal(SIGPIPE, SIG_DFL);
        dup2(out_fd, 1);
        dup2(err_fd, 2);
        execv(CLI_PROGRAM, (char *const *)argv);
        _exit(127);
    }
    int wstatus = 0;
    waitpid(pid, &wstatus, 0);
    res->status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
    res->out[0] = '\0';
    cli_slurp(err_fd, res->err);
    close(err_fd);
}

static void test_help_fits_80_columns(void)
{
    cli_run(ARGS("--help"), &r);
    CHECK_EQ_INT(r.status, 0);
    int line = 1;
    for (const char *p = r.out; *p; line++) {
        const char *end = strchr(p, '\n');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        CHECK_MSG(len <= 80, "--help line %d has %zu columns: %.*s", line, len, (int)len, p);
        p += len + (end ? 1 : 0);
    }
}

/* The README's command-line reference is --help, word for word, so the two cannot
 * drift apart when a flag is added. */
static void test_readme_reference_is_help(void)
{
    cli_run(ARGS("--help"), &r);
    CHECK_EQ_INT(r.status, 0);
    FILE *f = fopen("README.md", "rb");
    CHECK(f != NULL);
    if (!f) return;
    static char readme[1 << 17];
    size_t n = fread(readme, 1, sizeof readme - 1, f);
    fclose(f);
    readme[n] = '\0';
    const char *mark = "### Command-line reference\n\n```\n";
    const char *start = strstr(readme, mark);
    CHECK_MSG(start != NULL, "README.md has no \"### Command-line reference\" block");
    if (!start) return;
    start += strlen(mark);
    const char *end = strstr(start, "```\n");
    CHECK(end != NULL);
    if (!end) return;
    size_t len = (size_t)(end - start);
    CHECK_MSG(len == strlen(r.out) && memcmp(start, r.out, len) == 0,
              "README.md's command-line reference differs from --help: paste `build/clpt --help` into it");
}

/* A bad output is found before the render, not after it (when nothing, not even the
 * checkpoint, could be saved). */
static void test_bad_outputs_found_before_rendering(void)
{
    const char *ck = TEST_TMP("clpt-test-early.ckpt"), *out = TEST_TMP("clpt-test-early.png");
    unlink(ck);
    unlink(out);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "--checkpoint", ck, "-o", "/nonexistent-dir/x.png"), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "clpt: error: cannot write '/nonexistent-dir/x.png': cannot create a temporary file "
                              "beside it: No such file or directory");
    CHECK(strstr(r.err, "Msamples/s") == NULL);   /* no render ran */
    CHECK(!file_exists(ck));
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "--checkpoint", "/nonexistent-dir/x.ckpt", "-o", out), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "cannot write checkpoint '/nonexistent-dir/x.ckpt'");
    CHECK(strstr(r.err, "Msamples/s") == NULL);
    CHECK(!file_exists(out));
    /* JPEG and 16-bit PNG outputs are checked as early */
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "-o", "/nonexistent-dir/x.jpg", "--jpeg-quality", "50"), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "clpt: error: cannot write '/nonexistent-dir/x.jpg': cannot create a temporary file "
                              "beside it: No such file or directory");
    CHECK(strstr(r.err, "Msamples/s") == NULL);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "-o", "/nonexistent-dir/x.png", "--png-depth", "16"), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK(strstr(r.err, "Msamples/s") == NULL);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "-o", test_tmp_dir()), &r);   /* a folder named like an image */
    CHECK_EQ_INT(r.status, 2);
    mkdir(TEST_TMP("clpt-test-dir.png"), 0700);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "-o", TEST_TMP("clpt-test-dir.png")), &r);
    CHECK_EQ_INT(r.status, 4);
    char want[1024];
    snprintf(want, sizeof want, "cannot write '%s': not a file: Is a directory", TEST_TMP("clpt-test-dir.png"));
    CHECK_STR_CONTAINS(r.err, want);
    rmdir(TEST_TMP("clpt-test-dir.png"));
    if (geteuid() == 0) {
        printf("     (skipped the read-only folder case: root writes anywhere)\n");
        return;
    }
    mkdir(TEST_TMP("clpt-test-ro"), 0500);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "-o", TEST_TMP("clpt-test-ro/x.png")), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "Permission denied");
    CHECK(strstr(r.err, "Msamples/s") == NULL);
    rmdir(TEST_TMP("clpt-test-ro"));
}

/* Two outputs naming one file, or an output naming the scene: refused, nothing written. */
static void test_outputs_must_be_distinct_files(void)
{
    const char *out = TEST_TMP("clpt-test-same.png");
    unlink(out);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "--checkpoint", out, "-o", out), &r);
    CHECK_EQ_INT(r.status, 2);
    char want[1024];
    snprintf(want, sizeof want,
             "clpt: error: the output image '%s' and the checkpoint "
             "'%s' are the same file; give each its own name", out, out);
    CHECK_STR_CONTAINS(r.err, want);
    CHECK(!file_exists(out));
    /* the same file by another spelling: DIR/../BASENAME(DIR)/name */
    const char *dir = test_tmp_dir(), *dir_name = strrchr(dir, '/') + 1;
    char roundabout[1024];
    snprintf(roundabout, sizeof roundabout, "%s/../%s/clpt-test-same.png", dir, dir_name);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "--checkpoint", roundabout, "-o", out), &r);
    CHECK_EQ_INT(r.status, 2);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "--aov", "depth", "--checkpoint", TEST_TMP("clpt-test-same-depth.png"),
                 "-o", out),
            &r);
    CHECK_EQ_INT(r.status, 2);
    snprintf(want, sizeof want, "the --aov image '%s' and the checkpoint", TEST_TMP("clpt-test-same-depth.png"));
    CHECK_STR_CONTAINS(r.err, want);
    /* the scene itself, by name and through a hard link */
    const char *scene = TEST_TMP("clpt-test-scene.png"), *link_name = TEST_TMP("clpt-test-scene-link.png");
    char text[64 * 1024];
    FILE *f = fopen("scenes/cornell-box.scene", "r");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    if (f) fclose(f);
    text[n] = '\0';
    write_text(scene, text);
    unlink(link_name);
    CHECK(link(scene, link_name) == 0);
    cli_run(ARGS(scene, "--format", "clpt", SMALL, "-o", scene), &r);
    CHECK_EQ_INT(r.status, 2);
    snprintf(want, sizeof want, "the output image '%s' and the scene", scene);
    CHECK_STR_CONTAINS(r.err, want);
    cli_run(ARGS(scene, "--format", "clpt", SMALL, "-o", link_name), &r);
    CHECK_EQ_INT(r.status, 2);
    struct stat sb;
    CHECK(stat(scene, &sb) == 0 && (size_t)sb.st_size == n);   /* untouched */
    cli_run(ARGS(scene, "--format", "clpt", SMALL, "--checkpoint", scene, "-o", out), &r);
    CHECK_EQ_INT(r.status, 2);
    snprintf(want, sizeof want, "the checkpoint '%s' and the scene", scene);
    CHECK_STR_CONTAINS(r.err, want);
    CHECK(stat(scene, &sb) == 0 && (size_t)sb.st_size == n);
    unlink(scene);
    unlink(link_name);
}

/* As editors do: a symlinked output is written through the link, and an existing file
 * keeps its permissions. */
static void test_output_symlink_and_mode_kept(void)
{
    const char *target = TEST_TMP("clpt-test-target.png"), *sym = TEST_TMP("clpt-test-symlink.png");
    unlink(target);
    unlink(sym);
    write_text(target, "old");
    chmod(target, 0600);
    CHECK(symlink("clpt-test-target.png", sym) == 0);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "-q", "-o", sym), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    struct stat sb;
    CHECK(lstat(sym, &sb) == 0 && S_ISLNK(sb.st_mode));
    CHECK(stat(target, &sb) == 0 && sb.st_size > 8 && (sb.st_mode & 07777) == 0600);
    CHECK(!file_holds(target, "old"));
    /* a dangling link is followed too: its target is created */
    unlink(target);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "-q", "-o", sym), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(lstat(sym, &sb) == 0 && S_ISLNK(sb.st_mode));
    CHECK(file_exists(target));
    unlink(target);
    unlink(sym);
}

/* --time-limit that ends before the first batch: the old image stays, and the exit
 * status (7) says nothing was rendered. */
static void test_time_limit_without_samples_keeps_the_output(void)
{
    const char *out = TEST_TMP("clpt-test-keep.png");
    write_text(out, "keep");
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "64", "--height", "64", "--spp", "100",
                 "--time-limit", "1e-9", "-o", out),
            &r);
    CHECK_EQ_INT(r.status, 7);
    char want[1024];
    snprintf(want, sizeof want,
             "clpt: error: the time limit of 1e-09 s was reached before the first batch "
             "finished: nothing was rendered, and '%s' was left as it was", out);
    CHECK_STR_CONTAINS(r.err, want);
    CHECK(file_holds(out, "keep"));
    unlink(out);
}

/* A final checkpoint that cannot be written after --time-limit is an I/O error with
 * its message (it printed "clpt: error: success"). The folder goes away mid-render. */
static void test_failed_checkpoint_after_time_limit_says_why(void)
{
    char ck_dir[] = "/tmp/clpt-test-ckdir-XXXXXX";
    if (!mkdtemp(ck_dir)) return;
    char ck[64];
    snprintf(ck, sizeof ck, "%s/c.ckpt", ck_dir);
    const char *out = TEST_TMP("clpt-test-tl.pfm");
    unlink(out);
    CliChild c = cli_start(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--threads", "1", "--width", "32",
                                "--height", "32", "--spp", "1000000", "--time-limit", "1.5", "--progressive-output",
                                "0.1", "--checkpoint", ck, "-o", out));
    wait_for_file(out);
    CHECK(rmdir(ck_dir) == 0);
    cli_finish(c, &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "clpt: error: cannot write checkpoint");
    CHECK(strstr(r.err, "error: success") == NULL);
    CHECK(file_exists(out));   /* the image is still written */
    unlink(out);
}

/* stdout that cannot be written is an I/O error; a reader that leaves early
 * (`| head -1`) is not, and the image is written. */
static void test_stdout_failures(void)
{
    int full = open("/dev/full", O_WRONLY);
    CHECK(full >= 0);
    if (full >= 0) {
        run_with_stdout(ARGS("--help"), full, &r);
        CHECK_EQ_INT(r.status, 4);
        CHECK_STR_CONTAINS(r.err, "clpt: error: cannot write to standard output: No space left on device");
        run_with_stdout(ARGS("--list-devices"), full, &r);
        CHECK_EQ_INT(r.status, 4);
        run_with_stdout(ARGS("scenes/cornell-box.scene", SMALL, "--stats", "-o", TEST_TMP("clpt-test-full.png")), full, &r);
        CHECK_EQ_INT(r.status, 4);
        CHECK(file_exists(TEST_TMP("clpt-test-full.png")));
        unlink(TEST_TMP("clpt-test-full.png"));
        close(full);
    }
    int fds[2];
    CHECK(pipe(fds) == 0);
    close(fds[0]);   /* the reader is gone before clpt writes */
    const char *out = TEST_TMP("clpt-test-pipe.png");
    unlink(out);
    run_with_stdout(ARGS("scenes/cornell-box.scene", SMALL, "--stats", "-o", out), fds[1], &r);
    close(fds[1]);
    CHECK_EQ_INT(r.status, 0);
    CHECK(strstr(r.err, "error") == NULL);
    CHECK(file_exists(out));
    unlink(out);
}

static void test_device_list_with_empty_item(void)
{
    const char *specs[] = { ",", "scalar,", ",,scalar", " ", "scalar, ,0" };
    for (size_t i = 0; i < sizeof specs / sizeof specs[0]; i++) {
        cli_run(ARGS("scenes/cornell-box.scene", "--device", specs[i], "--width", "8", "--height", "8", "--spp", "1",
                     "-o", TEST_TMP("clpt-never.png")),
                &r);
        CHECK_EQ_INT(r.status, 2);
        CHECK_STR_CONTAINS(r.err, "has an empty item");
    }
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "", "--width", "8", "--height", "8", "--spp", "1", "-o",
                 TEST_TMP("clpt-never.png")),
            &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--device needs a device list");
    CHECK(!file_exists(TEST_TMP("clpt-never.png")));
}

/* With no OpenCL platform the scalar device renders, and that is said once, as plain
 * text when stderr is not a terminal. */
static void test_no_opencl_said_once_without_escapes(void)
{
    const char *out = TEST_TMP("clpt-test-noocl.png");
    const char *vendors[] = { "/nonexistent", TEST_TMP("clpt-test-empty-vendors") };
    mkdir(vendors[1], 0700);
    for (size_t i = 0; i < 2; i++) {
        setenv("OCL_ICD_VENDORS", vendors[i], 1);
        cli_run(ARGS("scenes/cornell-box.scene", "--width", "8", "--height", "8", "--spp", "1", "-o", out), &r);
        unsetenv("OCL_ICD_VENDORS");
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_EQ_INT(count_of(r.err, "no OpenCL platform found"), 1);
        CHECK_STR_CONTAINS(r.err, "clpt: warning: no OpenCL platform found (none installed, or OCL_ICD_VENDORS "
                                  "names none): rendering on the scalar device");
        CHECK(strchr(r.err, '\033') == NULL && strchr(r.err, '\r') == NULL);
        /* an index names an OpenCL device: 0 was the scalar device, without a word */
        setenv("OCL_ICD_VENDORS", vendors[i], 1);
        cli_run(ARGS("scenes/cornell-box.scene", "--device", "0", "--width", "8", "--height", "8", "--spp", "1", "-o",
                     out), &r);
        unsetenv("OCL_ICD_VENDORS");
        CHECK_EQ_INT(r.status, 2);
        CHECK_STR_CONTAINS(r.err, "clpt: error: --device 0: there is no OpenCL device 0: no OpenCL device was found "
                                  "(see --list-devices); the scalar device is --device scalar");
    }
    rmdir(vendors[1]);
}

/* stderr to a file (a batch log): plain progress lines, the first when the render
 * begins and then every 5 s, with no carriage return or escape code anywhere */
static void test_log_shows_plain_progress(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--threads", "1", "--width", "64", "--height",
                 "64", "--spp", "1000000", "--time-limit", "5.6", "-o", TEST_TMP("clpt-test-log.png")),
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
    unlink(TEST_TMP("clpt-test-log.png"));
}

/* The path tracer and the whitted integrator are programs of their own, each built on
 * first use (host/device/device_ocl.c): a path-tracer run stores one, the first whitted
 * run builds (and announces) the other, and later runs of either load them. */
static void test_kernel_programs_on_first_use(void)
{
    char cache[] = "/tmp/clpt-test-programs-XXXXXX";
    if (!mkdtemp(cache)) return;
    const char *saved = getenv("CLPT_CACHE_DIR");
    char *old = saved ? strdup(saved) : NULL;
    setenv("CLPT_CACHE_DIR", cache, 1);
    const char *out = TEST_TMP("clpt-test-programs.png");
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "0", "--width", "8", "--height", "8", "--spp", "1", "-o",
                 out), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.err, "clpt: compiling kernels for ");
    CHECK_EQ_INT(count_dir_entries(cache, ".bin"), 1);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "0", "--width", "8", "--height", "8", "--spp", "1",
                 "--integrator", "whitted", "-o", out), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.err, "clpt: compiling kernels for ");
    CHECK_EQ_INT(count_dir_entries(cache, ".bin"), 2);
    for (int whitted = 0; whitted < 2; whitted++) {
        cli_run(ARGS("scenes/cornell-box.scene", "--device", "0", "--width", "8", "--height", "8", "--spp", "1",
                     "--integrator", whitted ? "whitted" : "path", "-o", out), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK(strstr(r.err, "compiling kernels") == NULL);
    }
    CHECK_EQ_INT(count_dir_entries(cache, ".bin"), 2);
    if (old) setenv("CLPT_CACHE_DIR", old, 1);
    else unsetenv("CLPT_CACHE_DIR");
    free(old);
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -rf %s", cache);
    CHECK(system(cmd) == 0);
    unlink(out);
}

/* the first build of the kernels for a device says so; a cache hit and -q do not */
static void test_kernel_build_notice(void)
{
    char cache[] = "/tmp/clpt-test-cache-XXXXXX";
    if (!mkdtemp(cache)) return;
    const char *saved = getenv("CLPT_CACHE_DIR");
    char *old = saved ? strdup(saved) : NULL;
    setenv("CLPT_CACHE_DIR", cache, 1);
    const char *out = TEST_TMP("clpt-test-notice.png");
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
    CHECK_STR_CONTAINS(r.err, ", cached for next time...\n");
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

/* Runs `script` with sh -c, $CLPT naming the program: for pipes and FIFOs, which need a
 * shell around clpt. Each clpt in a script runs under `timeout`, so that a regression
 * that blocks on a pipe fails the test (exit 124) instead of hanging it. */
static void shell_run(const char *script, CliResult *res)
{
    char out_name[] = "/tmp/clpt-cli-out-XXXXXX", err_name[] = "/tmp/clpt-cli-err-XXXXXX";
    int out_fd = mkstemp(out_name), err_fd = mkstemp(err_name);
    unlink(out_name);
    unlink(err_name);
    pid_t pid = fork();
    if (pid == 0) {
        dup2(out_fd, 1);
        dup2(err_fd, 2);
        setenv("CLPT", CLI_PROGRAM, 1);
        execl("/bin/sh", "sh", "-c", script, (char *)NULL);
        _exit(127);
    }
    CliChild c = { pid, out_fd, err_fd };
    cli_finish(c, res);
}

#define PIPE_FLAGS "-q --device scalar --width 16 --height 12 --spp 2"

/* The scene read from a pipe or a FIFO is read once: it renders the same image as from
 * the file (it was read twice, once to tell the format, and rendered empty). */
static void test_scene_from_pipe(void)
{
    shell_run("set -e; d=$(mktemp -d /tmp/clpt-test-pipe-XXXXXX); trap 'rm -rf \"$d\"' EXIT\n"
              "timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/file.pfm\" scenes/cornell-box.scene\n"
              "cat scenes/cornell-box.scene | timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/stdin.pfm\" /dev/stdin\n"
              "cmp \"$d/file.pfm\" \"$d/stdin.pfm\"\n"
              "mkfifo \"$d/fifo\"; cat scenes/cornell-box.scene > \"$d/fifo\" &\n"
              "timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/fifo.pfm\" \"$d/fifo\"\n"
              "cmp \"$d/file.pfm\" \"$d/fifo.pfm\"\n"
              /* a classic scene is told from ours by its content: read once, it is both */
              "timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/classic.pfm\" scenes/classic/spheres.txt\n"
              "cat scenes/classic/spheres.txt | timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/classic-stdin.pfm\" /dev/stdin\n"
              "cmp \"$d/classic.pfm\" \"$d/classic-stdin.pfm\"\n"
              /* --format still chooses */
              "cat scenes/classic/spheres.txt | timeout 60 \"$CLPT\" " PIPE_FLAGS " --format classic "
              "-o \"$d/classic-forced.pfm\" /dev/stdin\n"
              "cmp \"$d/classic.pfm\" \"$d/classic-forced.pfm\"\n"
              "echo all-same\n", &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
    CHECK_STR_CONTAINS(r.out, "all-same");
}

/* What a scene names (a mesh, a texture, an include, an MTL file) must be a regular
 * file: a FIFO there is refused at once (it blocked clpt for ever), a directory is an
 * I/O error (exit 4). */
static void test_named_files_must_be_regular(void)
{
    static const struct {
        const char *scene;      /* written to $d/s.scene; $d/x.* are FIFOs or folders */
        const char *message;
    } cases[] = {
        { "mesh { file \"x.obj\" material m }",
          "/s.scene:3:13: cannot read '" },
        { "texture t { type image file \"x.png\" }",
          "cannot read '" },
        { "include \"x.scene\"",
          "/s.scene:3:9: cannot read '" },
    };
    for (int dir = 0; dir < 2; dir++)
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            char script[2048];
            snprintf(script, sizeof script,
                     "d=$(mktemp -d /tmp/clpt-test-fifo-XXXXXX); trap 'rm -rf \"$d\"' EXIT\n"
                     "for x in x.obj x.png x.scene; do %s \"$d/$x\"; done\n"
                     "printf 'camera { from 0 0 5 at 0 0 0 }\\nmaterial m { type diffuse albedo 1 1 1 }\\n%%s\\n' '%s' "
                     "> \"$d/s.scene\"\n"
                     "timeout 20 \"$CLPT\" " PIPE_FLAGS " -o \"$d/o.png\" \"$d/s.scene\"\n",
                     dir ? "mkdir" : "mkfifo", cases[i].scene);
            shell_run(script, &r);
            CHECK_MSG(r.status == 4, "%s (%s): exit %d: %s", cases[i].scene, dir ? "a folder" : "a FIFO", r.status,
                      r.err);
            CHECK_STR_CONTAINS(r.err, cases[i].message);
            CHECK_STR_CONTAINS(r.err, dir ? "it is a directory, not a file" : "it is a pipe, not a regular file");
        }
    /* an OBJ's MTL file that is a FIFO is skipped like a missing one, without waiting */
    shell_run("d=$(mktemp -d /tmp/clpt-test-fifo-XXXXXX); trap 'rm -rf \"$d\"' EXIT\n"
              "mkfifo \"$d/x.mtl\"\n"
              "printf 'mtllib x.mtl\\nv 0 0 0\\nv 1 0 0\\nv 0 1 0\\nusemtl a\\nf 1 2 3\\n' > \"$d/m.obj\"\n"
              "timeout 20 \"$CLPT\" " PIPE_FLAGS " -o \"$d/o.png\" \"$d/m.obj\"\n", &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
}

/* A FIFO named by --resume is refused at once (fopen waited for a writer for ever). It
 * is also the checkpoint written (--resume FILE implies --checkpoint FILE), so it is
 * found by the output check, before anything is read. */
static void test_resume_from_fifo_refused(void)
{
    shell_run("d=$(mktemp -d /tmp/clpt-test-fifo-XXXXXX); trap 'rm -rf \"$d\"' EXIT\n"
              "mkfifo \"$d/r.ckpt\"\n"
              "timeout 20 \"$CLPT\" " PIPE_FLAGS " --resume \"$d/r.ckpt\" -o \"$d/o.png\" scenes/cornell-box.scene\n",
              &r);
    CHECK_MSG(r.status == 4, "exit %d: %s", r.status, r.err);
    CHECK_STR_CONTAINS(r.err, "cannot write checkpoint '");
    CHECK_STR_CONTAINS(r.err, "/r.ckpt': it is a FIFO, not a regular file");
}

/* An output or checkpoint that is a FIFO, or a symlink to one (as to a device node: as
 * root, `-o out.png` with out.png -> /dev/null replaced /dev/null with a PNG), is
 * refused before rendering and left as it is. Only FIFOs in a temporary folder: never
 * real device nodes. */
static void test_outputs_must_be_regular_files(void)
{
    shell_run("d=$(mktemp -d /tmp/clpt-test-special-XXXXXX); trap 'rm -rf \"$d\"' EXIT\n"
              "mkfifo \"$d/f.png\" \"$d/f.ckpt\"; ln -s f.png \"$d/link.png\"; ln -s f.ckpt \"$d/link.ckpt\"\n"
              "for o in f.png link.png; do\n"
              "  timeout 20 \"$CLPT\" " PIPE_FLAGS " -o \"$d/$o\" scenes/cornell-box.scene; echo \"exit $?\"\n"
              "done\n"
              "timeout 20 \"$CLPT\" " PIPE_FLAGS " -o \"$d/o.png\" --checkpoint \"$d/link.ckpt\" "
              "scenes/cornell-box.scene; echo \"exit $?\"\n"
              "for f in f.png f.ckpt; do [ -p \"$d/$f\" ] && echo \"$f still a FIFO\"; done\n"
              "[ -L \"$d/link.png\" ] && [ -L \"$d/link.ckpt\" ] && echo 'links kept'\n"
              "[ -e \"$d/o.png\" ] || echo 'nothing rendered'\n"
              "ls \"$d\" | grep -c tmp\n"
              "echo \"dir $d\"\n", &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
    CHECK_EQ_INT(count_of(r.out, "exit 4"), 3);
    CHECK_STR_CONTAINS(r.err, "/f.png': it is a FIFO, not a regular file (clpt replaces only regular files)");
    CHECK_STR_CONTAINS(r.err, "/link.png': it leads to '");
    CHECK_STR_CONTAINS(r.err, "/f.png', which is a FIFO, not a regular file (clpt replaces only regular files)");
    CHECK_STR_CONTAINS(r.err, "clpt: error: cannot write checkpoint '");
    CHECK_STR_CONTAINS(r.err, "/link.ckpt': it leads to '");
    CHECK_STR_CONTAINS(r.out, "f.png still a FIFO");
    CHECK_STR_CONTAINS(r.out, "f.ckpt still a FIFO");
    CHECK_STR_CONTAINS(r.out, "links kept");
    CHECK_STR_CONTAINS(r.out, "nothing rendered");
    CHECK_STR_CONTAINS(r.out, "\n0\n");   /* no temporary file left behind */
}

int main(void)
{
    RUN(test_help_documents_every_flag);
    RUN(test_every_listed_flag_is_documented_and_parsed);
    RUN(test_usage_errors);
    RUN(test_missing_scene_is_io_error);
    RUN(test_parse_error_names_line_and_column);
    RUN(test_unknown_device_lists_devices);
    RUN(test_list_devices);
    RUN(test_render_each_format);
    RUN(test_quiet_prints_nothing);
    RUN(test_unwritable_output_is_io_error);
    RUN(test_stats);
    RUN(test_wave_launches_match_scalar);
    RUN(test_split_auto_chooses_alike);
    RUN(test_profile);
    RUN(test_help_fits_80_columns);
    RUN(test_readme_reference_is_help);
    RUN(test_bad_outputs_found_before_rendering);
    RUN(test_outputs_must_be_distinct_files);
    RUN(test_output_symlink_and_mode_kept);
    RUN(test_outputs_must_be_regular_files);
    RUN(test_time_limit_without_samples_keeps_the_output);
    RUN(test_failed_checkpoint_after_time_limit_says_why);
    RUN(test_stdout_failures);
    RUN(test_device_list_with_empty_item);
    RUN(test_no_opencl_said_once_without_escapes);
    RUN(test_log_shows_plain_progress);
    RUN(test_kernel_build_notice);
    RUN(test_kernel_programs_on_first_use);
    RUN(test_scene_from_pipe);
    RUN(test_named_files_must_be_regular);
    RUN(test_resume_from_fifo_refused);
    RUN(test_view_flags);
    return harness_report();
}
