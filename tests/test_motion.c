/*
 * test_motion.c — motion blur (docs/motion.md): a transform's keys decomposed and
 * interpolated as pbrt-v4's AnimatedTransform (T R S; translation and stretch linear,
 * rotation slerp); a moving camera's and a moving instance's images against the
 * average of still ones at fixed times; the top level's box over an instance's motion;
 * a still scene with a shutter unchanged bit for bit; every device and wave launch
 * giving the scalar device's bits on moving scenes, and after a resume; moving
 * instances under the kd-tree's prototypes as under the BVH's.
 * Bad input: tests/data/bad/motion-* (test_bad_input.c). Run from the project root.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "cli_util.h"
#include "render_util.h"
#include "io/scene_load.h"
#include "scene/motion.h"
#include "scene/transform.h"
#include "util/kmath.h"

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static CliResult r;

static double max_diff(const Transform *a, const Transform *b)
{
    double d = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) d = fmax(d, fabs(a->m[i][j] - b->m[i][j]));
    return d;
}

/* A key evaluated at its own time is its transform again: rotations, non-uniform
 * scales, shears and mirrors, to float precision. */
static void test_key_round_trip(void)
{
    Transform r1 = transform_rotate(1, 2, 3, 71), s1 = transform_scale(2, 0.5, 3), t1 = transform_translate(4, -5, 6);
    Transform shear = transform_identity();
    shear.m[0][1] = 0.7;
    Transform mirror = transform_scale(-1, 1, 1);
    Transform rs = transform_compose(&r1, &s1), cases[5];
    cases[0] = transform_compose(&t1, &rs);
    cases[1] = transform_compose(&cases[0], &shear);
    cases[2] = transform_compose(&cases[0], &mirror);
    cases[3] = transform_rotate(0, 1, 0, 180);
    cases[4] = transform_identity();
    for (int c = 0; c < 5; c++) {
        MotionKey k;
        Error err = { 0 };
        CHECK_MSG(motion_key_make(&cases[c], 0.25f, &k, &err) == ST_OK, "%s", err.msg);
        Transform back = motion_transform_at(&k, 1, 0.25f);
        double d = max_diff(&back, &cases[c]);
        CHECK_MSG(d < 2e-5 * 7.0, "case %d: the key's transform is %g away", c, d);
    }
    Transform singular = transform_scale(1, 0, 1);
    MotionKey k;
    Error err = { 0 };
    CHECK(motion_key_make(&singular, 2.0f, &k, &err) == ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "a moving transform's key at time 2 is singular");
    error_clear(&err);
}

/* Between two keys: translation and scale linear, rotation by slerp (an angle linear in
 * time), before the first key the first's, after the last the last's; and the shorter
 * arc whichever sign the quaternions were given. */
static void test_interpolation(void)
{
    Transform a = transform_identity();
    Transform r90 = transform_rotate(0, 1, 0, 90), s3 = transform_scale(3, 3, 3), t = transform_translate(2, 0, -4);
    Transform rs = transform_compose(&r90, &s3), b = transform_compose(&t, &rs);
    MotionKey k[2];
    Error err = { 0 };
    CHECK(motion_key_make(&a, 0.0f, &k[0], &err) == ST_OK);
    CHECK(motion_key_make(&b, 2.0f, &k[1], &err) == ST_OK);
    /* the same rotation with the other sign: the shorter arc again after the flip */
    for (int i = 0; i < 4; i++) k[1].rotate[i] = -k[1].rotate[i];
    motion_keys_shortest_arcs(k, 2);
    for (int step = 0; step <= 8; step++) {
        double u = step / 8.0;
        Transform got = motion_transform_at(k, 2, (float)(2.0 * u));
        Transform rot = transform_rotate(0, 1, 0, 90.0 * u), sc = transform_scale(1 + 2 * u, 1 + 2 * u, 1 + 2 * u);
        Transform tr = transform_translate(2 * u, 0, -4 * u), want_rs = transform_compose(&rot, &sc);
        Transform want = transform_compose(&tr, &want_rs);
        double d = max_diff(&got, &want);
        CHECK_MSG(d < 1e-5, "at u = %g the transform is %g from the expected", u, d);
    }
    Transform before = motion_transform_at(k, 2, -5.0f);
    CHECK(max_diff(&before, &a) < 1e-6);
    Transform after = motion_transform_at(k, 2, 9.0f);
    CHECK(max_diff(&after, &b) < 1e-5);
}

static Status render_text(const char *text, Film *film, Error *err)
{
    return render_util_text_film("motion.scene", text, SCENE_FORMAT_CLPT, "scalar", film, err);
}

#define STILL_SCENE                                                                      \
    "image { width 40 height 30 spp %u depth 3 seed 5 }\n"                              \
    "background { color 0.5 0.6 0.8 }\n"                                                 \
    "material floor { type diffuse albedo 0.5 0.5 0.5 }\n"                               \
    "plane { point 0 0 0 normal 0 1 0 material floor }\n"                                \
    "sphere { center 0 1 0 radius 1 material { type diffuse albedo 0.8 0.2 0.2 } }\n"     \
    "sphere { center 1.6 0.5 0.5 radius 0.5 material { type diffuse albedo 0.2 0.8 0.2 } }\n"

enum { K = 8, SPP_STILL = 64 };

/* Renders `moving` (K * SPP_STILL samples) and the K still scenes `still` writes;
 * checks, in 8 x 6 pixel blocks, that the moving image is their average within `tol`
 * and far (> 0.1, relative to the average) from the middle still one, so that a render
 * with no blur at all fails. */
static void check_moving_against_stills(const char *what, const char *moving, RenderUtilStillText still, double tol)
{
    Error err = { 0 };
    double worst, worst_mid;
    CHECK_MSG(render_util_motion_diffs(what, "motion.scene", SCENE_FORMAT_CLPT, moving, still, K, 0, &worst, &worst_mid,
                                       &err) == ST_OK, "%s", err.msg);
    CHECK(worst < tol);
    CHECK(worst_mid > 0.1);
}

/* The still camera at x on the sweep below, at shutter time u. */
static void camera_still(double u, char *text, size_t size)
{
    double x = -0.8 + 1.6 * u;
    snprintf(text, size, STILL_SCENE "camera { from %.9g 1.4 6 at %.9g 1 0 fov 35 }\n", (unsigned)SPP_STILL, x, x);
}

/* The camera sweeping from x = -0.8 to 0.8 over the shutter sees, per pixel, the mean
 * of what still cameras along the sweep see: the moving render against the average of
 * 8 still renders at the times (k + 1/2) / 8, within noise (8 x 6 pixel blocks, 48
 * samples of 512 each), while the still camera at the sweep's middle is far from it
 * (the test would notice no blur). */
static void test_moving_camera_is_average_of_still(void)
{
    char text[2048];
    snprintf(text, sizeof text,
             STILL_SCENE "camera { from -0.8 1.4 6 at -0.8 1 0 fov 35 shutter 0 1 }\n"
                         "camera_key { time 1 from 0.8 1.4 6 at 0.8 1 0 }\n",
             (unsigned)(K * SPP_STILL));
    check_moving_against_stills("moving camera", text, camera_still, 0.02);
}

/* A sliding, turning and growing instance seen by a still camera: its image is the
 * average of still instances at 8 fixed times (its keys' poses interpolated by hand:
 * the translation and scale linear, the angle about y linear, as slerp about one axis
 * is), within noise in 8 x 6 pixel blocks; a still instance at the middle time is far
 * from it. */
#define INSTANCE_SCENE                                                                   \
    STILL_SCENE "camera { from 0 1.4 6 at 0 1 0 fov 35 shutter 0 1 }\n"                 \
                "object thing { sphere { center 0 0 0 radius 0.5 material { type diffuse albedo 0.9 0.9 0.2 } }\n" \
                "  box { min 0.3 -0.2 -0.2 max 0.9 0.2 0.2 material { type diffuse albedo 0.2 0.2 0.9 } } }\n"

static void instance_still(double u, char *text, size_t size)
{
    snprintf(text, size, INSTANCE_SCENE "instance thing { scale %.9g ry %.9g translate %.9g %.9g 0.5 }\n",
             (unsigned)SPP_STILL, 1.0 + 0.5 * u, 120.0 * u, -1.2 + 2.4 * u, 2.0 + 0.2 * u);
}

static void test_moving_instance_is_average_of_still(void)
{
    char text[4096];
    snprintf(text, sizeof text,
             INSTANCE_SCENE "instance thing { translate -1.2 2 0.5 }\n"
                            "instance_key { time 1 scale 1.5 ry 120 translate 1.2 2.2 0.5 }\n",
             (unsigned)(K * SPP_STILL));
    check_moving_against_stills("moving instance", text, instance_still, 0.03);
}

/* Moving emitters (LIGHT_MOVING, docs/motion.md): a quad lamp and an emissive triangle
 * of one object, sliding and turning about y, and a glowing ball rising and growing,
 * over a floor and a block, the camera still. */
#define LAMPS_HEAD                                                                       \
    "image { width 48 height 32 spp %u depth 4 seed %u }\n"                              \
    "camera { from 0 3 6 at 0 0.6 0 fov 40 shutter 0 1 }\n"                             \
    "background { color 0.02 0.02 0.03 }\n"                                              \
    "material floor { type diffuse albedo 0.6 0.6 0.6 }\n"                               \
    "material glow { type emissive radiance 6 5 4 }\n"                                   \
    "material hot { type emissive radiance 4 6 8 }\n"                                    \
    "plane { point 0 0 0 normal 0 1 0 material floor }\n"                                \
    "box { min -0.4 0 -0.4 max 0.4 0.8 0.4 material { type diffuse albedo 0.7 0.3 0.2 } }\n" \
    "object lamp {\n"                                                                    \
    "  quad { v0 -0.5 0 -0.3 v1 0.5 0 -0.3 v2 0.5 0 0.3 v3 -0.5 0 0.3 material glow }\n" \
    "  triangle { v0 0.6 0 -0.2 v1 0.9 0 0.2 v2 0.6 0 0.2 material hot } }\n"          \
    "object ball { sphere { center 0 0 0 radius 0.2 material hot } }\n"

static void lamps_text(uint spp, uint seed, char *text, size_t size)
{
    snprintf(text, size, LAMPS_HEAD "instance lamp { translate -1.5 2 0 }\n"
                                    "instance_key { time 1 ry 40 translate 1.5 1.6 0.3 }\n"
                                    "instance ball { translate 1.2 0.4 1.2 }\n"
                                    "instance_key { time 1 scale 1.8 translate 0.8 1.2 1 }\n", spp, seed);
}

/* The lamp still at shutter time u: its keys interpolated by hand (the slide linear,
 * the angle about y linear, as slerp about one axis is). The ball is left out: the
 * camera sees it, and the midpoint rule's 8 stills miss the last sixteenth of its
 * streak on the dark background, a difference of the stills and not of the light;
 * the lamp faces away from the camera, so only its light is compared. */
static void lamp_still(double u, char *text, size_t size)
{
    snprintf(text, size, LAMPS_HEAD "instance lamp { ry %.9g translate %.9g %.9g %.9g }\n", (unsigned)SPP_STILL, 5u,
             40.0 * u, -1.5 + 3.0 * u, 2.0 - 0.4 * u, 0.3 * u);
}

static Status lamps_rgb(uint spp, uint seed, uint mis_mode, float *rgb, Error *err)
{
    char text[4096];
    Scene s;
    lamps_text(spp, seed, text, sizeof text);
    scene_init(&s);
    Status st = scene_load_text("lamps.scene", text, strlen(text), &s, err);
    if (!st) st = render_util_rgb_mis(&s, mis_mode, "scalar", rgb, err);
    scene_free(&s);
    return st;
}

/* The mean of 8 x 8 pixel blocks (6 x 4 of them), for comparisons within noise. */
static void lamps_blocks(const float *rgb, double blocks[24], double *mean)
{
    *mean = 0.0;
    for (int b = 0; b < 24; b++) blocks[b] = 0.0;
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 48; x++)
            for (int c = 0; c < 3; c++) {
                double v = rgb[3 * (48 * y + x) + c];
                blocks[(y / 8) * 6 + x / 8] += v / (8 * 8 * 3);
                *mean += v / (48 * 32 * 3);
            }
}

static double blocks_apart(const double *a, const double *b)
{
    double worst = 0.0;
    for (int i = 0; i < 24; i++) worst = fmax(worst, fabs(a[i] - b[i]) / fmax(b[i], 1e-3));
    return worst;
}

/* Every emitter of a moving instance is a light placed at the path's time: the quad's
 * two halves, the triangle and the ball (its instance a similarity at both keys), each
 * with its instance and a share of the choice. */
static void test_moving_lamps_are_lights(void)
{
    char text[4096];
    Scene s;
    RenderScene rs;
    Error err = { 0 };
    lamps_text(1, 1, text, sizeof text);
    scene_init(&s);
    CHECK_MSG(scene_load_text("lamps.scene", text, strlen(text), &s, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_scene_prepare(&s, 1, &rs, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_lights, 4);
    CHECK(s.instance_lights != NULL);
    if (s.n_lights == 4 && s.instance_lights) {
        CHECK(s.instance_lights[0] == 0 && s.instance_lights[1] == 3);
        for (uint i = 0; i < 4; i++) {
            CHECK(s.lights[i].type == LIGHT_MOVING && s.lights[i].pick_pdf > 0.0f);
            CHECK(light_instance(s.lights[i]) == (i < 3 ? 0u : 1u));
        }
        CHECK(s.lights[0].quad == LIGHT_QUAD_FIRST && s.lights[1].quad == LIGHT_QUAD_SECOND);
        /* the ball's record keeps its first pose's area (radius 0.2); its power is its
         * mean area's over the shutter (test_growing_lamp_chosen_by_mean_power) */
        CHECK(fabsf(s.lights[3].area - (float)(4.0 * M_PI * 0.04)) < 1e-5f);
    }
    render_scene_free(&rs);
    scene_free(&s);

    /* a ball whose instance squashes it at a key is an ellipsoid then: no power, never
     * chosen (found by BSDF sampling at full weight, as a still squashed one) */
    static const char squashed[] =
        "camera { from 0 3 6 at 0 0.6 0 fov 40 shutter 0 1 }\n"
        "material hot { type emissive radiance 4 6 8 }\n"
        "object ball { sphere { center 0 0 0 radius 0.2 material hot } }\n"
        "instance ball { translate 1.2 0.4 1.2 }\n"
        "instance_key { time 1 scale 1 2 1 translate 0.8 1.2 1 }\n"
        "quad { v0 -1 4 -1 v1 1 4 -1 v2 1 4 1 v3 -1 4 1 material hot }\n";
    scene_init(&s);
    CHECK_MSG(scene_load_text("squashed.scene", squashed, strlen(squashed), &s, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_scene_prepare(&s, 1, &rs, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_lights, 3);
    if (s.n_lights == 3) CHECK(s.lights[2].type == LIGHT_MOVING && s.lights[2].pick_pdf == 0.0f);
    render_scene_free(&rs);
    scene_free(&s);
    error_clear(&err);
}

/* The mean area over the shutter (motion_mean_area): exact for a similarity's keys,
 * whose area is quadratic in time (a unit square growing from 0.25 to 2 across: the
 * mean of s^2 is (2^3 - 0.25^3) / (3 x 1.75)), held before the first key, and within
 * 1e-6 of a fine midpoint sum for a stretch that makes it the root of a quartic. */
static void test_mean_area(void)
{
    Error err = { 0 };
    MotionKey k[2];
    Transform a = transform_scale(0.25, 0.25, 0.25), b = transform_scale(2, 2, 2);
    CHECK(motion_key_make(&a, 0.0f, &k[0], &err) == ST_OK && motion_key_make(&b, 1.0f, &k[1], &err) == ST_OK);
    k[0].count = k[1].count = 2;
    const double ex[3] = { 1, 0, 0 }, ey[3] = { 0, 1, 0 };
    double exact = (8.0 - 0.25 * 0.25 * 0.25) / (3.0 * 1.75);
    double got = motion_mean_area(k, 2, 0.0, 1.0, ex, ey);
    CHECK_MSG(fabs(got - exact) < 1e-9, "similarity: %.12g, exact %.12g", got, exact);
    /* a shutter open from -1: half of it at the first pose */
    got = motion_mean_area(k, 2, -1.0, 1.0, ex, ey);
    CHECK_MSG(fabs(got - 0.5 * (0.0625 + exact)) < 1e-9, "shutter before the keys: %.12g", got);
    CHECK(fabs(motion_mean_area(k, 2, 1.5, 1.5, ex, ey) - 4.0) < 1e-9);

    /* three keys, a stretch along x turned: S(t) not diagonal in the edges' frame */
    MotionKey m[3];
    Transform turn = transform_rotate(0, 0, 1, 30), sx = transform_scale(3, 0.5, 1), rt = transform_rotate(0, 0, 1, -30);
    Transform rs = transform_compose(&turn, &sx), c1 = transform_compose(&rs, &rt), c2 = transform_scale(1, 1, 2),
              c0 = transform_identity();
    CHECK(motion_key_make(&c0, 0.0f, &m[0], &err) == ST_OK && motion_key_make(&c1, 0.5f, &m[1], &err) == ST_OK &&
          motion_key_make(&c2, 1.0f, &m[2], &err) == ST_OK);
    m[0].count = m[1].count = m[2].count = 3;
    const double e1[3] = { 1, 1, 0 }, e2[3] = { 0, 1, 1 };
    double sum = 0.0;
    enum { STEPS = 200000 };
    for (int i = 0; i < STEPS; i++) {
        double t = 0.1 + 0.8 * (i + 0.5) / STEPS;
        Transform mt = motion_transform_at(m, 3, (float)t);
        double u[3], v[3];
        for (int j = 0; j < 3; j++) {
            u[j] = mt.m[j][0] * e1[0] + mt.m[j][1] * e1[1] + mt.m[j][2] * e1[2];
            v[j] = mt.m[j][0] * e2[0] + mt.m[j][1] * e2[1] + mt.m[j][2] * e2[2];
        }
        double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2], cz = u[0] * v[1] - u[1] * v[0];
        sum += sqrt(cx * cx + cy * cy + cz * cz);
    }
    double fine = sum / STEPS;
    got = motion_mean_area(m, 3, 0.1, 0.9, e1, e2);
    fprintf(stderr, "  mean area over [0.1, 0.9] of a turned stretch: Simpson %.9f, 200000 midpoints of the "
            "kernels' transform %.9f\n", got, fine);
    CHECK_MSG(fabs(got - fine) < 1e-6 * fine, "Simpson %.9g against %.9g", got, fine);
    error_clear(&err);
}

/* A growing lamp is chosen by its mean power over the shutter
 * (tests/data/motion/growing-lamp.scene): a 1 x 0.6 quad scaled from 0.25 to 2, mean
 * area 0.6 x 1.5208, beside a still 1.2 x 0.8 quad of the same radiance; each is two
 * lights (its quad's halves) of half its power. At its first pose it would get 3.8%
 * of the choice, over the shutter it gives 48.7% of the light. The kernels' records keep
 * the first pose's area (and the still scene's lights their bits). */
static void test_growing_lamp_chosen_by_mean_power(void)
{
    Scene s;
    RenderScene rs;
    Error err = { 0 };
    scene_init(&s);
    CHECK_MSG(scene_load_file("tests/data/motion/growing-lamp.scene", SCENE_FORMAT_AUTO, &s, NULL, &err) == ST_OK,
              "%s", err.msg);
    CHECK_MSG(render_scene_prepare(&s, 1, &rs, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_lights, 4);
    if (s.n_lights == 4) {
        double still = 1.2 * 0.8, moving = 0.6 * (8.0 - 0.25 * 0.25 * 0.25) / (3.0 * 1.75);
        double want = 0.5 * moving / (still + moving);
        CHECK(s.lights[2].type == LIGHT_MOVING && s.lights[3].type == LIGHT_MOVING);
        for (int i = 0; i < 4; i++) {
            double p = i < 2 ? 0.5 - want : want;
            CHECK_MSG(fabs(s.lights[i].pick_pdf - p) < 1e-6, "light %d: chosen with %g, not %g", i,
                      (double)s.lights[i].pick_pdf, p);
        }
        CHECK(fabsf(s.lights[2].area - (float)(0.5 * 0.6 * 0.0625)) < 1e-6f);
        fprintf(stderr, "  growing lamp: each half chosen with %.4f (its first pose's power would give %.4f)\n",
                (double)s.lights[2].pick_pdf, 0.5 * 0.6 * 0.0625 / (still + 0.6 * 0.0625));
    }
    render_scene_free(&rs);
    scene_free(&s);
    error_clear(&err);
}

/* The moving lamps' image is the same under MIS, light sampling alone and BSDF sampling
 * alone (1024 spp; image means within 1%, 8 x 8 pixel blocks within noise), so the light
 * samples, their densities at the path's time and MIS's weights at a hit agree; and at
 * 16 spp MIS is far closer to that image than BSDF sampling alone (how the moving lamps
 * were found before they were lights): RMSE over the pixels below 1 in the image. */
static void test_moving_lamps_strategies_agree(void)
{
    enum { N = 48 * 32 * 3 };
    static const uint modes[3] = { MIS_BOTH, MIS_LIGHT_ONLY, MIS_BSDF_ONLY };
    static const char *const names[3] = { "MIS", "light", "BSDF" };
    float *img[3], *noisy = malloc(N * sizeof *noisy);
    double blocks[3][24], mean[3], rmse[2];
    Error err = { 0 };
    for (int m = 0; m < 3; m++) {
        img[m] = malloc(N * sizeof *img[m]);
        CHECK_MSG(lamps_rgb(1024, 1, modes[m], img[m], &err) == ST_OK, "%s", err.msg);
        lamps_blocks(img[m], blocks[m], &mean[m]);
    }
    for (int m = 0; m < 2; m++) {
        CHECK_MSG(lamps_rgb(16, 2, modes[2 * m], noisy, &err) == ST_OK, "%s", err.msg);
        /* over the pixels the lamps light, not those that see the ball itself, whose
         * blur (the time's noise) neither strategy changes */
        double e = 0.0, n = 0.0;
        for (int i = 0; i < N; i++) {
            if (!(img[0][i] < 1.0f)) continue;
            e += ((double)noisy[i] - img[0][i]) * ((double)noisy[i] - img[0][i]);
            n += 1.0;
        }
        rmse[m] = sqrt(e / fmax(n, 1.0));
    }
    fprintf(stderr, "  moving lamps, 1024 spp: mean %s %.4f, %s %.4f, %s %.4f; worst block difference to MIS: "
            "light %.1f%%, BSDF %.1f%%\n", names[0], mean[0], names[1], mean[1], names[2], mean[2],
            100.0 * blocks_apart(blocks[1], blocks[0]), 100.0 * blocks_apart(blocks[2], blocks[0]));
    fprintf(stderr, "  moving lamps, 16 spp: RMSE to MIS at 1024 spp: MIS %.4g, BSDF sampling alone %.4g (%.1fx)\n",
            rmse[0], rmse[1], rmse[1] / rmse[0]);
    CHECK(mean[0] > 0.05);
    for (int m = 1; m < 3; m++) CHECK(fabs(mean[m] - mean[0]) < 0.01 * mean[0]);
    CHECK(blocks_apart(blocks[1], blocks[0]) < 0.05);
    CHECK(blocks_apart(blocks[2], blocks[0]) < 0.08);
    CHECK(rmse[0] * 2.0 < rmse[1]);
    for (int m = 0; m < 3; m++) free(img[m]);
    free(noisy);
    error_clear(&err);
}

/* The moving lamp (light sampled at each path's time) against the average of the still
 * lamp at 8 times, within noise in 8 x 6 pixel blocks; the middle still one is far. */
static void test_moving_lamp_is_average_of_still(void)
{
    char text[4096];
    snprintf(text, sizeof text, LAMPS_HEAD "instance lamp { translate -1.5 2 0 }\n"
                                           "instance_key { time 1 ry 40 translate 1.5 1.6 0.3 }\n",
             (unsigned)(K * SPP_STILL), 5u);
    check_moving_against_stills("moving lamp", text, lamp_still, 0.03);
}

/* motion_bounds holds the box's corners at every time, sampled far more finely than
 * it samples: a half turn and more between keys, a stretch and a slide. */
static void test_bounds_hold_the_motion(void)
{
    Transform r0 = transform_rotate(0.3, 1, 0.2, 10), r1 = transform_rotate(0.3, 1, 0.2, 185);
    Transform s1 = transform_scale(2, 0.5, 1), t1 = transform_translate(3, -1, 2), r2 = transform_rotate(1, 0, 0, 90);
    Transform a = r0, rs = transform_compose(&r1, &s1), b = transform_compose(&t1, &rs), c = r2;
    MotionKey k[3];
    Error err = { 0 };
    CHECK(motion_key_make(&a, 0.0f, &k[0], &err) == ST_OK);
    CHECK(motion_key_make(&b, 1.0f, &k[1], &err) == ST_OK);
    CHECK(motion_key_make(&c, 3.0f, &k[2], &err) == ST_OK);
    motion_keys_shortest_arcs(k, 3);
    double lo[3] = { -1, -0.5, -2 }, hi[3] = { 2, 0.5, 1 }, wl[3], wh[3];
    motion_bounds(k, 3, lo, hi, wl, wh);
    int outside = 0;
    for (int i = 0; i <= 30000; i++) {
        Transform m = motion_transform_at(k, 3, (float)(3.0 * i / 30000.0));
        for (int corner = 0; corner < 8; corner++) {
            vec3 p = transform_point(&m, v3((float)((corner & 1) ? hi[0] : lo[0]), (float)((corner & 2) ? hi[1] : lo[1]),
                                            (float)((corner & 4) ? hi[2] : lo[2])));
            double w[3] = { p.x, p.y, p.z };
            for (int q = 0; q < 3; q++) outside += !(w[q] >= wl[q] && w[q] <= wh[q]);
        }
    }
    CHECK_EQ_INT(outside, 0);
}

/* A shutter without keys moves nothing: the same bits as the scene without it. */
static void test_still_with_shutter_same_bits(void)
{
    char with[2048], without[2048];
    snprintf(with, sizeof with, STILL_SCENE "camera { from 0 1.4 6 at 0 1 0 fov 35 shutter 0.2 0.7 }\n", 8u);
    snprintf(without, sizeof without, STILL_SCENE "camera { from 0 1.4 6 at 0 1 0 fov 35 }\n", 8u);
    Film a, b;
    Error err = { 0 };
    CHECK_MSG(render_text(with, &a, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_text(without, &b, &err) == ST_OK, "%s", err.msg);
    size_t n = (size_t)a.width * a.height * 3u;
    CHECK(film_sums_same(&a, &b) == n);
    film_free(&a);
    film_free(&b);
}

/* Every wave launch of the OpenCL device, and the classic ray tracer's kernel, give
 * the scalar device's bits on the moving camera and on moving instances. */
static void test_devices_match_scalar(void)
{
    const char *scenes[] = { "tests/data/motion/camera.scene", "tests/data/motion/instances.scene",
                             "tests/data/motion/lamps.scene" };
    const char *ref = TEST_TMP("clpt-test-motion-scalar.pfm"), *out = TEST_TMP("clpt-test-motion-ocl.pfm");
    const char *modes[] = { "counted", "bounded", "megakernel" };
    for (int k = 0; k < 3; k++) {
        const char *scene = scenes[k];
        cli_run(ARGS(scene, "--device", "scalar", "-q", "-o", ref), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        for (int i = 0; i < 3; i++) {
            cli_run(ARGS(scene, "--device", TEST_OPENCL, "--wave-launch", modes[i], "--wave-paths", "1000", "--batch",
                         "2", "-q", "-o", out), &r);
            CHECK_MSG(r.status == 0, "%s: %s", modes[i], r.err);
            CHECK_MSG(files_equal(ref, out), "%s, --wave-launch %s: the image differs from the scalar device's", scene,
                      modes[i]);
        }
        cli_run(ARGS(scene, "--device", "scalar", "--integrator", "whitted", "-q", "-o", ref), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        cli_run(ARGS(scene, "--device", TEST_OPENCL, "--integrator", "whitted", "-q", "-o", out), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_MSG(files_equal(ref, out), "%s, whitted: the image differs from the scalar device's", scene);
    }
    unlink(ref);
    unlink(out);
}

/* Moving instances under --accel kdtree: the top level (the BVH's, over the instances'
 * boxes of their whole motion) carries the ray into each instance where it is at the
 * path's time, and the prototype's kd-tree finds what the BVH's finds: the BVH's image
 * bit for bit, on the scalar device, and on OpenCL under every wave launch and with the
 * classic ray tracer's kernel. */
static void test_kdtree_moving_instances(void)
{
    const char *scenes[] = { "tests/data/motion/instances.scene", "tests/data/motion/lamps.scene" };
    const char *ref = TEST_TMP("clpt-test-motion-bvh.pfm"), *out = TEST_TMP("clpt-test-motion-kd.pfm");
    const char *modes[] = { "counted", "bounded", "megakernel" };
    for (int k = 0; k < 2; k++) {
        cli_run(ARGS(scenes[k], "--device", "scalar", "-q", "-o", ref), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        cli_run(ARGS(scenes[k], "--device", "scalar", "--accel", "kdtree", "-q", "-o", out), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_MSG(files_equal(ref, out), "%s: the kd-tree's image differs from the BVH's", scenes[k]);
        for (int i = 0; i < 3; i++) {
            cli_run(ARGS(scenes[k], "--device", TEST_OPENCL, "--accel", "kdtree", "--wave-launch", modes[i],
                         "--wave-paths", "1000", "--batch", "2", "-q", "-o", out), &r);
            CHECK_MSG(r.status == 0, "%s: %s", modes[i], r.err);
            CHECK_MSG(files_equal(ref, out), "%s, --accel kdtree --wave-launch %s: the image differs from the scalar "
                      "BVH's", scenes[k], modes[i]);
        }
        /* the classic ray tracer's kernel (k_whitted) */
        cli_run(ARGS(scenes[k], "--device", "scalar", "--integrator", "whitted", "-q", "-o", ref), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        cli_run(ARGS(scenes[k], "--device", TEST_OPENCL, "--accel", "kdtree", "--integrator", "whitted", "-q", "-o",
                     out), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_MSG(files_equal(ref, out), "%s, --accel kdtree, whitted: the image differs from the scalar BVH's",
                  scenes[k]);
    }
    unlink(ref);
    unlink(out);
}

/* Checkpointed at 4 samples and resumed to 8 on the OpenCL and scalar devices together:
 * the straight 8-sample render bit for bit. */
static void test_resume_matches_straight(void)
{
    cli_check_resume_matches_straight("tests/data/motion/instances.scene", TEST_TMP("clpt-test-motion-ref.pfm"),
                                      TEST_TMP("clpt-test-motion-out.pfm"), TEST_TMP("clpt-test-motion.ckpt"));
}

int main(void)
{
    RUN(test_key_round_trip);
    RUN(test_interpolation);
    RUN(test_moving_camera_is_average_of_still);
    RUN(test_moving_instance_is_average_of_still);
    RUN(test_moving_lamps_are_lights);
    RUN(test_mean_area);
    RUN(test_growing_lamp_chosen_by_mean_power);
    RUN(test_moving_lamps_strategies_agree);
    RUN(test_moving_lamp_is_average_of_still);
    RUN(test_bounds_hold_the_motion);
    RUN(test_still_with_shutter_same_bits);
    RUN(test_devices_match_scalar);
    RUN(test_kdtree_moving_instances);
    RUN(test_resume_matches_straight);
    return harness_report();
}
