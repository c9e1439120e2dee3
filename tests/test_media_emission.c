/*
 * test_media_emission.c — emission from media (kernels/medium/, docs/media.md,
 * "Emission"): whole images against exact answers. An emitting slab seen by the camera
 * gives Le sigma_a / sigma_t (1 - exp(-sigma_t d)) per channel (homogeneous: exact,
 * absorbing or scattering); an emitting grid (a density ramp, with and without an
 * emission-scale grid) against a numeric integral of T sigma_a Le, by ratio tracking
 * and by delta tracking; emitting furnaces (a medium whose emission equals the
 * background's radiance renders that radiance, whatever it absorbs and scatters); and
 * the same bits on every device and wave launch. Run from the project root.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "cli_util.h"
#include "util/kmath.h"
#include "render_util.h"
#include "io/scene_load.h"
#include "scene/blackbody.h"
#include "scene/scene.h"

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static CliResult r;

/* Renders `text` on `devices` and returns its channel means. */
static int render_means(const char *text, const char *devices, double mean[3])
{
    Error err = { 0 };
    Status st = render_util_text_means("emission-test.scene", text, devices, mean, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    error_clear(&err);
    return st == ST_OK;
}

/* A camera looking along -z through a slab 2 thick (z in [-1, 1]) of medium `m` (the
 * %s) at a black background, no bounce: only the emission along the camera rays counts. */
#define SLAB_SCENE \
    "image { width 16 height 16 spp %d depth 0 }\n" \
    "camera { from 0 0 5 at 0 0 0 up 0 1 0 fov 2 }\n" \
    "background { color 0 0 0 }\n" \
    "%s\n" \
    "box { min -2 -2 -1 max 2 2 1 material none interior m }\n"

/* The mean over the film of f(k), k = 1 / cos of the ray's angle to -z: the rays of
 * the 2-degree field cross the slab at up to 1.4 degrees. */
static void slab_mean(void (*f)(double k, const void *ctx, double out[3]), const void *ctx, double want[3])
{
    double half = tan(1.0 * M_PI / 180.0);
    int n = 40;
    want[0] = want[1] = want[2] = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double x = half * (2.0 * (i + 0.5) / n - 1.0), y = half * (2.0 * (j + 0.5) / n - 1.0), v[3];
            f(sqrt(1.0 + x * x + y * y), ctx, v);
            for (int c = 0; c < 3; c++) want[c] += v[c] / ((double)n * n);
        }
}

static int check_scene(const char *what, const char *text, const double want[3], double tol)
{
    const char *devices[] = { "scalar", TEST_OPENCL };
    int ok = 1;
    for (int d = 0; d < 2; d++) {
        double m[3];
        if (!render_means(text, devices[d], m)) return 0;
        fprintf(stderr, "  %s on %s: %.5f %.5f %.5f (exact %.5f %.5f %.5f)\n", what, devices[d], m[0], m[1], m[2],
                want[0], want[1], want[2]);
        for (int c = 0; c < 3; c++) {
            CHECK_NEAR(m[c], want[c], tol);
            ok &= fabs(m[c] - want[c]) <= tol;
        }
    }
    return ok;
}

/* ------------------------------------------------------------------ homogeneous slabs */

typedef struct { double sa[3], st[3], le[3]; } Homog;

/* Le sigma_a / sigma_t (1 - exp(-sigma_t 2k)) per channel. */
static void homog_emitted(double k, const void *ctx, double out[3])
{
    const Homog *h = ctx;
    for (int c = 0; c < 3; c++)
        out[c] = h->st[c] > 0.0 ? h->le[c] * h->sa[c] / h->st[c] * (1.0 - exp(-h->st[c] * 2.0 * k)) : 0.0;
}

/* Homogeneous media add their emission in closed form, so the image is exact up to
 * float rounding, absorbing or scattering (the scattered paths end at depth 0). */
static void test_homogeneous_slab(void)
{
    char text[2048];
    Homog a = { { 0.1, 0.7, 1.5 }, { 0.1, 0.7, 1.5 }, { 2.0, 1.0, 0.5 } };
    double want[3];
    slab_mean(homog_emitted, &a, want);
    snprintf(text, sizeof text, SLAB_SCENE, 4,
             "medium m { type homogeneous sigma_a 0.1 0.7 1.5 sigma_s 0 0 0 emission 1 0.5 0.25 "
             "emission_scale 2 }");
    check_scene("absorbing slab, Le (1 - exp(-sigma_a d))", text, want, 2e-5);

    Homog s = { { 0.1, 0.2, 0.4 }, { 0.4, 0.3, 0.9 }, { 1.0, 3.0, 0.5 } };
    slab_mean(homog_emitted, &s, want);
    snprintf(text, sizeof text, SLAB_SCENE, 16,
             "medium m { type homogeneous sigma_a 0.1 0.2 0.4 sigma_s 0.3 0.1 0.5 g 0.4 emission 1 3 0.5 }");
    check_scene("scattering slab, Le sigma_a / sigma_t (1 - exp(-sigma_t d))", text, want, 2e-5);

    /* the same slab given by albedo and density: sigma_a = (1 - albedo) density */
    Homog d = { { 0.5, 0.5, 0.5 }, { 2.0, 2.0, 2.0 }, { 0.2, 0.4, 0.6 } };
    slab_mean(homog_emitted, &d, want);
    snprintf(text, sizeof text, SLAB_SCENE, 4,
             "medium m { type homogeneous albedo 0.75 0.75 0.75 density 2 emission 0.2 0.4 0.6 }");
    check_scene("albedo and density", text, want, 2e-5);
}

/* ------------------------------------------------------------------ grids */

/* A grid over the box [-1, 1]^3 whose density and emission scale vary along z only:
 * RAMP_N cell-centred samples each, x y z sizes 1 1 RAMP_N. */
enum { RAMP_N = 4 };
static const double ramp_density[RAMP_N] = { 0.2, 0.6, 1.0, 1.4 };
static const double ramp_scale[RAMP_N] = { 1.0, 0.0, 2.0, 0.5 };

typedef struct { double sa[3], st[3], le[3]; int scaled; } Ramp;

/* A cell-centred sample list at unit coordinate q, clamped to the outermost centres,
 * linear between (kernels/medium/grid.h). */
static double ramp_at(const double *v, double q)
{
    double x = q * RAMP_N - 0.5;
    x = x < 0.0 ? 0.0 : x > RAMP_N - 1 ? RAMP_N - 1 : x;
    int i = (int)x;
    if (i > RAMP_N - 2) i = RAMP_N - 2;
    return v[i] + (v[i + 1] - v[i]) * (x - i);
}

/* int T(t) sigma_a d(t) s(t) Le dt along a ray from z = 1 to z = -1 (k: 1 / cos), by
 * the midpoint rule on a fine grid. */
static void ramp_emitted(double k, const void *ctx, double out[3])
{
    const Ramp *g = ctx;
    int n = 4000;
    double dz = 2.0 / n, tau[3] = { 0.0, 0.0, 0.0 };
    out[0] = out[1] = out[2] = 0.0;
    for (int i = 0; i < n; i++) {
        double z = 1.0 - (i + 0.5) * dz, q = (z + 1.0) * 0.5;
        double dens = ramp_at(ramp_density, q), s = g->scaled ? ramp_at(ramp_scale, q) : 1.0;
        for (int c = 0; c < 3; c++) {
            double half = 0.5 * g->st[c] * dens * dz * k;
            out[c] += exp(-(tau[c] + half)) * g->sa[c] * dens * s * g->le[c] * dz * k;
            tau[c] += 2.0 * half;
        }
    }
}

static void check_ramp(const char *what, const char *medium, const Ramp *g, double tol)
{
    char text[2048];
    double want[3];
    slab_mean(ramp_emitted, g, want);
    snprintf(text, sizeof text, SLAB_SCENE, 256, medium);
    check_scene(what, text, want, tol);
}

/* Ratio tracking (absorption only) and delta tracking (scattering) add each tentative
 * collision's emission; both estimate the integral without bias. */
static void test_grid_ramp(void)
{
    Ramp absorbing = { { 0.5, 1.0, 2.0 }, { 0.5, 1.0, 2.0 }, { 1.0, 0.5, 2.0 }, 0 };
    check_ramp("absorbing ramp, ratio tracking",
               "medium m { type grid sigma_a 0.5 1 2 size 1 1 4 data [ 0.2 0.6 1.0 1.4 ] min -1 -1 -1 max 1 1 1 "
               "emission 1 0.5 2 }", &absorbing, 0.004);
    Ramp scaled = absorbing;
    scaled.scaled = 1;
    check_ramp("absorbing ramp with an emission grid",
               "medium m { type grid sigma_a 0.5 1 2 size 1 1 4 data [ 0.2 0.6 1.0 1.4 ] min -1 -1 -1 max 1 1 1 "
               "emission 0.5 0.25 1 emission_scale 2 emission_data [ 1 0 2 0.5 ] }", &scaled, 0.004);
    Ramp scattering = { { 0.3, 0.5, 1.0 }, { 1.0, 0.8, 2.0 }, { 2.0, 1.0, 1.0 }, 1 };
    check_ramp("scattering ramp with an emission grid, delta tracking",
               "medium m { type grid sigma_a 0.3 0.5 1 sigma_s 0.7 0.3 1 g 0.5 size 1 1 4 data [ 0.2 0.6 1.0 1.4 ] "
               "min -1 -1 -1 max 1 1 1 emission 2 1 1 emission_data [ 1 0 2 0.5 ] }", &scattering, 0.006);
}

/* ------------------------------------------------------------------ temperature */

/* A grid of uniform density and temperature is a homogeneous slab whose Le is the
 * blackbody's colour at T = (value - offset) scale, times `emission` and
 * `emission_scale`: Le sigma_a / sigma_t (1 - exp(-sigma_t d)) again, the colour from
 * scene/blackbody.h (pbrt-v4's BlackbodySpectrum, peak 1). Ratio tracking (absorbing)
 * and delta tracking (scattering). */
static void test_temperature_slab(void)
{
    BlackbodyTable table;
    blackbody_table_init(&table);
    vec3 bb = blackbody_rgb_peak_normalised(&table, (3100.0 - 100.0) * 1.0);   /* 3000 K */
    fprintf(stderr, "  blackbody 3000 K, peak 1: %.6f %.6f %.6f; the fit's y-bar integral %.4f\n", (double)bb.x,
            (double)bb.y, (double)bb.z, table.y_integral);
    CHECK(bb.x > bb.y && bb.y > bb.z && bb.z > 0.0f);
    /* pbrt-v4's CIE_Y_integral, 106.856895: the fit's own within 0.5% */
    CHECK_NEAR(table.y_integral, 106.856895, 0.5);
    /* emission 1 0.5 2 times emission_scale 0.04: a colour of the order of 1 (the film
     * records the blackbody's integrals against the matching functions: ~78 in red) */
    Homog a = { { 0.6, 0.6, 0.6 }, { 0.6, 0.6, 0.6 }, { 0.04 * bb.x, 0.02 * bb.y, 0.08 * bb.z } };
    double want[3];
    slab_mean(homog_emitted, &a, want);
    char text[2048];
    snprintf(text, sizeof text, SLAB_SCENE, 256,
             "medium m { type grid sigma_a 0.3 0.3 0.3 size 2 1 2 data [ 2 2 2 2 ] min -2 -2 -1 max 2 2 1 "
             "temperature_data [ 3100 3100 3100 3100 ] temperature_offset 100 emission 1 0.5 2 emission_scale 0.04 }");
    check_scene("uniform temperature slab, ratio tracking", text, want, 0.006 * want[0]);
    Homog sc = { { 0.4, 0.4, 0.4 }, { 1.2, 1.2, 1.2 }, { 0.02 * bb.x, 0.02 * bb.y, 0.02 * bb.z } };
    slab_mean(homog_emitted, &sc, want);
    snprintf(text, sizeof text, SLAB_SCENE, 256,
             "medium m { type grid sigma_a 0.2 0.2 0.2 sigma_s 0.4 0.4 0.4 size 1 1 1 data [ 2 ] min -2 -2 -1 "
             "max 2 2 1 temperature_data [ 1500 ] temperature_scale 2 emission_scale 0.02 }");
    check_scene("uniform temperature slab, delta tracking", text, want, 0.006 * want[0]);
    /* below 100 K nothing glows */
    snprintf(text, sizeof text, SLAB_SCENE, 4,
             "medium m { type grid sigma_a 0.3 0.3 0.3 size 1 1 1 data [ 2 ] min -2 -2 -1 max 2 2 1 "
             "temperature_data [ 150 ] temperature_offset 60 emission_scale 1e6 }");
    double zero[3] = { 0, 0, 0 };
    check_scene("90 K, no emission", text, zero, 0.0);
}

/* The same fire ball as pbrt-v4's uniformgrid (temperature, temperaturescale, the
 * older temperaturecutoff as the offset, a Lescale grid) and in clpt's format: the same
 * coefficients and the same baked colours, bit for bit, and the same image. */
static const char fire_pbrt[] =
    "LookAt 0 0 5  0 0 0  0 1 0\n"
    "Camera \"perspective\" \"float fov\" 30\n"
    "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n"
    "Sampler \"independent\" \"integer pixelsamples\" 64\n"
    "Integrator \"volpath\" \"integer maxdepth\" 0\n"
    "WorldBegin\n"
    "MakeNamedMedium \"fire\" \"string type\" \"uniformgrid\" \"rgb sigma_a\" [2 2 2] \"rgb sigma_s\" [0 0 0]\n"
    "  \"integer nx\" 2 \"integer ny\" 2 \"integer nz\" 2 \"float density\" [0 1 1 0.5 1 0.25 0.5 1]\n"
    "  \"float temperature\" [200 1400 900 1700 600 2300 1000 1200] \"float temperaturecutoff\" 150\n"
    "  \"float temperaturescale\" 1.5 \"float Lescale\" [.01 .02 .03 .04 .05 .06 .07 .08]\n"
    "  \"point3 p0\" [-1 -1 -1] \"point3 p1\" [1 1 1]\n"
    "AttributeBegin\n"
    "MediumInterface \"fire\" \"\"\n"
    "Material \"interface\"\n"
    "Shape \"sphere\" \"float radius\" 1.5\n"
    "AttributeEnd\n";
static const char fire_clpt[] =
    "image { width 16 height 16 spp 64 depth 0 }\n"
    "camera { from 0 0 5 at 0 0 0 up 0 1 0 fov 30 }\n"
    "background { color 0 0 0 }\n"
    "medium fire { type grid sigma_a 2 2 2 size 2 2 2 data [ 0 1 1 0.5 1 0.25 0.5 1 ] min -1 -1 -1 max 1 1 1\n"
    "  temperature_data [ 200 1400 900 1700 600 2300 1000 1200 ] temperature_offset 150 temperature_scale 1.5\n"
    "  emission_data [ .01 .02 .03 .04 .05 .06 .07 .08 ] }\n"
    "sphere { center 0 0 0 radius 1.5 material none interior fire }\n";

static void test_temperature_pbrt_and_clpt(void)
{
    Scene a, b;
    Error err = { 0 };
    scene_init(&a);
    scene_init(&b);
    Status sa = scene_load_bytes("fire.pbrt", fire_pbrt, strlen(fire_pbrt), SCENE_FORMAT_AUTO, &a, NULL, &err);
    CHECK_MSG(sa == ST_OK, "%s", err.msg);
    error_clear(&err);
    Status sb = scene_load_text("fire.scene", fire_clpt, strlen(fire_clpt), &b, &err);
    CHECK_MSG(sb == ST_OK, "%s", err.msg);
    error_clear(&err);
    if (!sa && !sb && a.n_grids == 1 && b.n_grids == 1 && a.n_media == 1 && b.n_media == 1) {
        const GridMedium *ga = &a.grids[0], *gb = &b.grids[0];
        CHECK(ga->temperature_at != 0u && gb->temperature_at != 0u && ga->emission_at != 0u);
        CHECK(memcmp(a.grid_data + ga->temperature_at, b.grid_data + gb->temperature_at,
                     (8 + 1 + 3 * GRID_BLACKBODY_STEPS) * sizeof(float)) == 0);
        CHECK(memcmp(a.grid_data + ga->emission_at, b.grid_data + gb->emission_at, 8 * sizeof(float)) == 0);
        CHECK(memcmp(&a.media[0].emission, &b.media[0].emission, sizeof(vec3)) == 0);
        CHECK(memcmp(&a.media[0].sigma_a, &b.media[0].sigma_a, sizeof(vec3)) == 0);
        /* cell 0: (200 - 150) 1.5 = 75 K, no glow; cell 5: 3225 K, the hottest */
        const float *kelvin = a.grid_data + ga->temperature_at;
        CHECK(kelvin[0] == 75.0f && kelvin[5] == 3225.0f && kelvin[8] == (GRID_BLACKBODY_STEPS - 1u) / 3225.0f);
    }
    double ma[3], mb[3];
    Film fa, fb;
    memset(&fa, 0, sizeof fa);
    memset(&fb, 0, sizeof fb);
    if (!sa && !sb && render_util_run(&a, "scalar", 0, &fa, &err) == ST_OK &&
        render_util_run(&b, "scalar", 0, &fb, &err) == ST_OK) {
        film_channel_means(&fa, ma);
        film_channel_means(&fb, mb);
        fprintf(stderr, "  fire ball, pbrt-v4 file: %.5f %.5f %.5f; clpt scene: %.5f %.5f %.5f\n", ma[0], ma[1], ma[2],
                mb[0], mb[1], mb[2]);
        for (int c = 0; c < 3; c++) CHECK_NEAR(ma[c], mb[c], 0.03 * mb[0]);
        CHECK(ma[0] > ma[1] && ma[1] > ma[2] && ma[0] > 0.0);
    } else if (!sa && !sb) {
        CHECK_MSG(0, "%s", err.msg);
    }
    film_free(&fa);
    film_free(&fb);
    scene_free(&a);
    scene_free(&b);
    error_clear(&err);
}

/* ------------------------------------------------------------------ furnaces */

/* A medium emitting Le inside a background of radiance Le: L = Le everywhere solves the
 * radiative transfer equation (what is absorbed is emitted again, what is scattered
 * out is scattered in), so every pixel's expected value is Le, whatever the medium
 * absorbs, scatters and how its density varies: all bounces and both kinds of flight
 * count (homogeneous in closed form, grids by tracking). */
#define FURNACE_SCENE \
    "image { width 16 height 16 spp 128 depth 256 }\n" \
    "camera { from 0 0 3 at 0 0 0 up 0 1 0 fov 50 }\n" \
    "background { color 0.6 0.8 1.0 }\n" \
    "%s\n" \
    "box { min -1 -1 -1 max 1 1 1 material none interior m }\n"

static void test_furnace(void)
{
    const char *media[] = {
        "medium m { type homogeneous sigma_a 0.3 1 2 sigma_s 1 0.5 2 g 0.5 emission 0.6 0.8 1.0 }",
        "medium m { type grid sigma_a 0.3 1 2 sigma_s 1 0.5 2 g -0.3 size 2 2 2 data [ 0.5 1 2 1 0.2 0.8 1.5 1 ] "
        "min -1 -1 -1 max 1 1 1 emission 0.6 0.8 1.0 }",
        "medium m { type grid sigma_a 0.5 1 3 size 2 2 2 data [ 0.5 1 2 1 0.2 0.8 1.5 1 ] min -1 -1 -1 "
        "max 1 1 1 emission 0.6 0.8 1.0 }",
    };
    const char *what[] = { "homogeneous, chromatic", "grid, scattering", "grid, absorbing" };
    const double want[3] = { 0.6, 0.8, 1.0 };
    for (int i = 0; i < 3; i++) {
        char text[2048];
        snprintf(text, sizeof text, FURNACE_SCENE, media[i]);
        char label[96];
        snprintf(label, sizeof label, "emitting furnace, %s", what[i]);
        check_scene(label, text, want, 0.012);
    }
}

/* ------------------------------------------------------------------ devices */

/* scenes/glow.scene (emitting homogeneous and grid media, scattering, lit by a sun) and
 * scenes/fireball.scene (a temperature grid's per-cell blackbody colours) render the
 * same bits on the scalar device and on every wave launch of OpenCL. */
static void test_devices_match_scalar(void)
{
    const char *scenes[] = { "scenes/glow.scene", "scenes/fireball.scene" };
    const char *modes[] = { "counted", "bounded", "megakernel" };
    const char *ref = TEST_TMP("clpt-test-emission-scalar.pfm"), *out = TEST_TMP("clpt-test-emission-ocl.pfm");
    for (int k = 0; k < 2; k++) {
        const char *scene = scenes[k];
        cli_run(ARGS(scene, "--device", "scalar", "--width", "40", "--height", "30", "--spp", "6", "-q", "-o", ref), &r);
        CHECK_MSG(r.status == 0, "%s: %s", scene, r.err);
        for (int i = 0; i < 3; i++) {
            cli_run(ARGS(scene, "--device", TEST_OPENCL, "--width", "40", "--height", "30", "--spp", "6",
                         "--wave-launch", modes[i], "--wave-paths", "1000", "--batch", "2", "-q", "-o", out), &r);
            CHECK_MSG(r.status == 0, "%s, %s: %s", scene, modes[i], r.err);
            int same = files_equal(ref, out);
            CHECK_MSG(same, "%s, --wave-launch %s: the image differs from the scalar device's", scene, modes[i]);
            fprintf(stderr, "  %s, --wave-launch %s: %s\n", scene, modes[i], same ? "the scalar device's bits" : "DIFFERENT");
        }
    }
    unlink(ref);
    unlink(out);
}

int main(void)
{
    RUN(test_homogeneous_slab);
    RUN(test_grid_ramp);
    RUN(test_temperature_slab);
    RUN(test_temperature_pbrt_and_clpt);
    RUN(test_furnace);
    RUN(test_devices_match_scalar);
    return harness_report();
}
