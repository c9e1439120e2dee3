/* test_course_cli.c — clpt standing in for the courses' reference programs
 * (host/course_args.c): the MIT command line (-size -input -output -normals -depth
 * -bounces -shadows) and the Tsinghua one (SCENE OUT.bmp) render the scenes/classic/
 * examples bit for bit as clpt's own flags do; the depth and normal images of a scene
 * with known distances; bad course command lines are usage errors; and --shadows with
 * its defaults (off for classic scenes, on for clpt's format). */
#include "cli_util.h"
#include "harness.h"

static CliResult r;   /* large: static */

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static const char *const classic_scenes[] = { "spheres", "glass", "mesh", "ortho", "textured", "vase" };
#define N_CLASSIC (sizeof classic_scenes / sizeof classic_scenes[0])

static void tmp_name(char *buf, size_t n, const char *what)
{
    test_tmp_path(buf, n, what);
}

/* MIT: -size 48 36 -bounces 2 -shadows -normals, against the whitted integrator, one
 * sample, no gamma, --shadows on, --max-depth 2 and --aov normal. (The depth image's
 * values are pinned by test_depth_and_normals_known_values.) */
static void test_mit_equals_own_flags(void)
{
    char scene[256], a[256], an[256], b[256], bn[256];
    tmp_name(a, sizeof a, "mit.bmp");
    tmp_name(an, sizeof an, "mit-n.bmp");
    tmp_name(b, sizeof b, "own.bmp");
    tmp_name(bn, sizeof bn, "own-normal.bmp");
    for (size_t i = 0; i < N_CLASSIC; i++) {
        snprintf(scene, sizeof scene, "scenes/classic/%s.txt", classic_scenes[i]);
        cli_run(ARGS("-size", "48", "36", "-input", scene, "-output", a, "-normals", an, "-bounces", "2",
                     "-shadows", "--quiet"), &r);
        CHECK_MSG(r.status == 0, "%s: %s", scene, r.err);
        cli_run(ARGS(scene, "--width", "48", "--height", "36", "--integrator", "whitted", "--spp", "1", "--gamma",
                     "none", "--shadows", "on", "--max-depth", "2", "--aov", "normal", "-o", b, "--quiet"), &r);
        CHECK_MSG(r.status == 0, "%s: %s", scene, r.err);
        CHECK_MSG(files_equal(a, b) && files_equal(an, bn), "%s: MIT command line differs", scene);
        /* without -bounces and -shadows: direct light only, no shadows */
        cli_run(ARGS("-input", scene, "-size", "48", "36", "-output", a, "--quiet"), &r);
        CHECK_MSG(r.status == 0, "%s: %s", scene, r.err);
        cli_run(ARGS(scene, "--width", "48", "--height", "36", "--integrator", "whitted", "--spp", "1", "--gamma",
                     "none", "--shadows", "off", "--max-depth", "0", "-o", b, "--quiet"), &r);
        CHECK_MSG(files_equal(a, b), "%s: MIT command line without -bounces/-shadows differs", scene);
    }
    const char *made[] = { a, an, b, bn };
    for (size_t i = 0; i < 4; i++) unlink(made[i]);
}

/* Tsinghua: SCENE OUT, the size the scene's camera gives (or clpt's --width/--height
 * after it), each output format by its extension. */
static void test_tsinghua_equals_own_flags(void)
{
    const char *ext[] = { "bmp", "png", "ppm" };
    char scene[256], a[256], b[256], what[32];
    for (size_t i = 0; i < N_CLASSIC; i++) {
        snprintf(scene, sizeof scene, "scenes/classic/%s.txt", classic_scenes[i]);
        snprintf(what, sizeof what, "pa1.%s", ext[i % 3]);
        tmp_name(a, sizeof a, what);
        snprintf(what, sizeof what, "own.%s", ext[i % 3]);
        tmp_name(b, sizeof b, what);
        if (i == 0)
            cli_run(ARGS(scene, a), &r);          /* exactly the course's two arguments */
        else
            cli_run(ARGS(scene, a, "--width", "40", "--height", "30", "--quiet"), &r);
        CHECK_MSG(r.status == 0, "%s: %s", scene, r.err);
        if (i == 0)
            cli_run(ARGS(scene, "--integrator", "whitted", "--spp", "1", "--gamma", "none", "--shadows", "off",
                         "--max-depth", "0", "-o", b, "--quiet"), &r);
        else
            cli_run(ARGS(scene, "--width", "40", "--height", "30", "--integrator", "whitted", "--spp", "1",
                         "--gamma", "none", "--shadows", "off", "--max-depth", "0", "-o", b, "--quiet"), &r);
        CHECK_MSG(r.status == 0, "%s: %s", scene, r.err);
        CHECK_MSG(files_equal(a, b), "%s: Tsinghua command line differs (%s)", scene, ext[i % 3]);
        unlink(a);
        unlink(b);
    }
}

/* The pixels of a binary PPM (P6, maxval 255) into rgb; returns the pixel count. */
static size_t read_ppm(const char *path, unsigned char *rgb, size_t max_pixels)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    unsigned w = 0, h = 0, maxval = 0;
    size_t n = 0;
    if (fscanf(f, "P6 %u %u %u", &w, &h, &maxval) == 3 && maxval == 255 && fgetc(f) != EOF &&
        (size_t)w * h <= max_pixels)
        n = fread(rgb, 3, (size_t)w * h, f) == (size_t)w * h ? (size_t)w * h : 0;
    fclose(f);
    return n;
}

/* A sphere of radius 2 at the origin seen from z = 10 down the axis, 3x1 pixels: the
 * middle ray hits at distance 8, the outer ones miss. -depth 4 14: (8 - 4) / 10 = 0.4,
 * 102 of 255 (near black, far white); misses black. The normal there is +z: (0.5, 0.5,
 * 1) -> 128 128 255. */
static void test_depth_and_normals_known_values(void)
{
    char scene[256], out[256], normals[256], depth[256];
    write_temp(scene, sizeof scene, ".txt",
               "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }\n"
               "Lights { numLights 0 }\n"
               "Background { color 0 0 0 ambientLight 0 0 0 }\n"
               "Materials { numMaterials 1 PhongMaterial { diffuseColor 0.5 0.5 0.5 } }\n"
               "Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 2 } }\n");
    tmp_name(out, sizeof out, "known.ppm");
    tmp_name(normals, sizeof normals, "known-n.ppm");
    tmp_name(depth, sizeof depth, "known-d.ppm");
    cli_run(ARGS("-size", "3", "1", "-input", scene, "-output", out, "-normals", normals, "-depth", "4", "14", depth,
                 "--quiet"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    unsigned char px[9];
    CHECK(read_ppm(depth, px, 3) == 3);
    fprintf(stderr, "  depth 3x1: %u %u %u; ", px[0], px[3], px[6]);
    CHECK(px[0] == 0 && px[1] == 0 && px[2] == 0 && px[6] == 0);
    CHECK(px[3] == 102 && px[4] == 102 && px[5] == 102);
    CHECK(read_ppm(normals, px, 3) == 3);
    fprintf(stderr, "normal at the middle: %u %u %u\n", px[3], px[4], px[5]);
    CHECK(px[3] == 128 && px[4] == 128 && px[5] == 255);
    unlink(scene);
    unlink(out);
    unlink(normals);
    unlink(depth);
}

static void expect_usage(const char *const *args, const char *message)
{
    cli_run(args, &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, message);
    CHECK_STR_CONTAINS(r.err, "usage: clpt -size W H -input FILE -output FILE");
}

static void test_bad_course_command_lines(void)
{
    expect_usage(ARGS("-size", "64", "64", "-output", TEST_TMP("clpt-never.bmp")),
                 "the course command line needs -input FILE");
    expect_usage(ARGS("-input", "scenes/classic/spheres.txt", "-size", "64"), "-size needs a width and a height");
    expect_usage(ARGS("-size", "64", "-input", "scenes/classic/spheres.txt", "-output", TEST_TMP("clpt-never.bmp")),
                 "-size needs a width and a height");
    expect_usage(ARGS("-input", "scenes/classic/spheres.txt", "-output", TEST_TMP("clpt-never.bmp"), "-jitter"),
                 "unknown option '-jitter' in the course command line");
    expect_usage(ARGS("-input", "scenes/classic/spheres.txt"), "the course command line needs -output FILE");
    expect_usage(ARGS("-input", "scenes/classic/spheres.txt", "-output", TEST_TMP("clpt-never.bmp"), "-bounces", "two"),
                 "-bounces expects an integer in 0..1024, got 'two'");
    expect_usage(ARGS("-input", "scenes/classic/spheres.txt", "-output", TEST_TMP("clpt-never.bmp"), "-depth", "8", "8",
                      TEST_TMP("clpt-never-d.bmp")), "-depth NEAR FAR FILE needs NEAR and FAR to differ, got 8 and 8");
    expect_usage(ARGS("-input", "scenes/classic/spheres.txt", "-output", TEST_TMP("clpt-never.bmp"), "-depth", "8",
                      "18"), "-depth needs NEAR FAR FILE");
    expect_usage(ARGS("-input", "scenes/classic/spheres.txt", "-output", TEST_TMP("clpt-never.bmp"), "extra.txt"),
                 "unexpected argument 'extra.txt'");
    CHECK(!file_exists(TEST_TMP("clpt-never.bmp")));
    /* two positional arguments whose second is no image name stay clpt's own error */
    cli_run(ARGS("scenes/classic/spheres.txt", "other.txt"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "more than one scene given");
}

/* --shadows: a bad value is a usage error; a classic scene renders without shadows
 * unless --shadows on, a scene of our format with them unless --shadows off or its
 * image block says 'shadows off'. */
static void test_shadows_flag_and_defaults(void)
{
    cli_run(ARGS("scenes/classic/spheres.txt", "--shadows", "maybe"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--shadows expects 'on' or 'off', got 'maybe'");
    char def[256], on[256], off[256];
    tmp_name(def, sizeof def, "def.png");
    tmp_name(on, sizeof on, "on.png");
    tmp_name(off, sizeof off, "off.png");
    const char *scene = "scenes/classic/spheres.txt";
    cli_run(ARGS(scene, "--width", "48", "--height", "36", "-o", def, "--quiet"), &r);
    cli_run(ARGS(scene, "--width", "48", "--height", "36", "-o", on, "--shadows", "on", "--quiet"), &r);
    cli_run(ARGS(scene, "--width", "48", "--height", "36", "-o", off, "--shadows", "off", "--quiet"), &r);
    CHECK(files_equal(def, off) && !files_equal(def, on));
    char own[256];
    write_temp(own, sizeof own, ".scene",
               "camera { from 0 3 4 at 0 0 0 }\nimage { width 24 height 24 spp 4 }\n"
               "light { type point position 0 3 0 intensity 3 3 3 }\n"
               "plane { point 0 0 0 normal 0 1 0 material { type diffuse albedo 0.5 0.5 0.5 } }\n"
               "sphere { center 0 1 0 radius 0.5 material { type diffuse albedo 0.5 0.5 0.5 } }\n");
    cli_run(ARGS(own, "-o", def, "--quiet"), &r);
    cli_run(ARGS(own, "-o", on, "--shadows", "on", "--quiet"), &r);
    cli_run(ARGS(own, "-o", off, "--shadows", "off", "--quiet"), &r);
    CHECK(files_equal(def, on) && !files_equal(def, off));
    unlink(own);
    write_temp(own, sizeof own, ".scene",
               "camera { from 0 3 4 at 0 0 0 }\nimage { width 24 height 24 spp 4 shadows off }\n"
               "light { type point position 0 3 0 intensity 3 3 3 }\n"
               "plane { point 0 0 0 normal 0 1 0 material { type diffuse albedo 0.5 0.5 0.5 } }\n"
               "sphere { center 0 1 0 radius 0.5 material { type diffuse albedo 0.5 0.5 0.5 } }\n");
    cli_run(ARGS(own, "-o", def, "--quiet"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(def, off));
    unlink(own);
    unlink(def);
    unlink(on);
    unlink(off);
}

int main(void)
{
    RUN(test_mit_equals_own_flags);
    RUN(test_tsinghua_equals_own_flags);
    RUN(test_depth_and_normals_known_values);
    RUN(test_bad_course_command_lines);
    RUN(test_shadows_flag_and_defaults);
    return harness_report();
}
