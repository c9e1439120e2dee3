/*
 * test_grid_media.c — heterogeneous (grid) media (kernels/medium/grid.h, docs/media.md):
 * delta tracking and ratio tracking against exact transmittances (a constant grid is
 * Beer-Lambert and renders as the homogeneous medium does; a linear ramp against its
 * integral; a sphere of density in a mostly empty majorant grid against a fine march of
 * the same trilinear field), residual ratio tracking's variance against plain ratio
 * tracking's, the white furnace, and the same bits on every device.
 * Run from the project root.
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

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static CliResult r;

/* Renders `text` on `devices` and returns its channel means. */
static int render_means(const char *text, const char *devices, double mean[3])
{
    Error err = { 0 };
    Status st = render_util_text_means("grid-test.scene", text, devices, mean, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    error_clear(&err);
    return st == ST_OK;
}

/* "[ v v v ... ]" of n values f(i) into a growing string. */
static char *number_list(size_t n, double (*f)(size_t i, void *ctx), void *ctx)
{
    char *out = malloc(n * 16 + 8);
    size_t o = 0;
    o += (size_t)sprintf(out + o, "[");
    for (size_t i = 0; i < n; i++) o += (size_t)sprintf(out + o, " %.7g", f(i, ctx));
    sprintf(out + o, " ]");
    return out;
}

/* ------------------------------------------------------------------ a slab of constant density */

/* A camera looking through a slab 2 thick at a white lamp, no bounce: only light that
 * flew straight through counts (as test_media.c's slab), the medium `m` given by %s. */
#define SLAB_SCENE \
    "image { width 16 height 16 spp 256 depth 0 }\n" \
    "camera { from 0 0 5 at 0 0 0 up 0 1 0 fov 2 }\n" \
    "%s\n" \
    "material lamp { type emissive radiance 1 1 1 }\n" \
    "box { min -2 -2 -1 max 2 2 1 material none interior m }\n" \
    "quad { v0 -3 -3 -2 v1 3 -3 -2 v2 3 3 -2 v3 -3 3 -2 material lamp }\n"

/* The mean over the film of exp(-tau(len)), len the slab's crossing (2 / cos: the rays
 * of the 2-degree field cross at up to 1.4 degrees) and tau = depth(len) per channel. */
static void slab_expected(vec3 sigma_t, double depth_per_len, double want[3])
{
    double half = tan(1.0 * M_PI / 180.0), sum[3] = { 0.0, 0.0, 0.0 };
    int n = 200;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double x = half * (2.0 * (i + 0.5) / n - 1.0), y = half * (2.0 * (j + 0.5) / n - 1.0);
            double len = 2.0 * sqrt(1.0 + x * x + y * y) * depth_per_len;
            sum[0] += exp(-sigma_t.x * len);
            sum[1] += exp(-sigma_t.y * len);
            sum[2] += exp(-sigma_t.z * len);
        }
    for (int c = 0; c < 3; c++) want[c] = sum[c] / ((double)n * n);
}

static void check_slab(const char *what, const char *medium, vec3 sigma_t, double depth_per_len, double tol,
                       double out[3])
{
    char text[4096];
    snprintf(text, sizeof text, SLAB_SCENE, medium);
    const char *devices[] = { "scalar", TEST_OPENCL };
    double want[3];
    slab_expected(sigma_t, depth_per_len, want);
    for (int d = 0; d < 2; d++) {
        double m[3];
        if (!render_means(text, devices[d], m)) continue;
        fprintf(stderr, "  %s on %s: %.5f %.5f %.5f (exact %.5f %.5f %.5f)\n", what, devices[d], m[0], m[1], m[2],
                want[0], want[1], want[2]);
        for (int c = 0; c < 3; c++) CHECK_NEAR(m[c], want[c], tol);
        if (out && d == 0) memcpy(out, m, sizeof m);
    }
}

/* A grid of constant density is Beer-Lambert, and renders as the homogeneous medium of
 * the same coefficients within noise: delta tracking (scattering, chromatic) and ratio
 * tracking (absorption only). The grid's box is smaller than the slab's boundary in x
 * and y only where the camera does not look. */
static void test_constant_grid(void)
{
    double grid[3], homo[3];
    check_slab("constant grid, scattering", "medium m { type grid sigma_a 0.05 0.1 0.2 sigma_s 0.15 0.05 0.25 "
               "size 2 2 2 data [ 2 2 2 2 2 2 2 2 ] min -1 -1 -1 max 1 1 1 }",
               v3(0.4f, 0.3f, 0.9f), 1.0, 0.01, grid);
    check_slab("the homogeneous medium", "medium m { type homogeneous sigma_a 0.1 0.2 0.4 sigma_s 0.3 0.1 0.5 }",
               v3(0.4f, 0.3f, 0.9f), 1.0, 0.01, homo);
    for (int c = 0; c < 3; c++) CHECK_NEAR(grid[c], homo[c], 0.012);
    /* residual ratio tracking: a constant grid's minorant is its majorant, the control
     * is the whole extinction and every estimate exact (0.81871 0.24656 0.04977) */
    check_slab("constant grid, absorbing", "medium m { type grid sigma_a 0.1 0.7 1.5 size 1 1 1 data [ 1 ] "
               "scale 2 translate 0 0 0 min -0.5 -0.5 -0.5 max 0.5 0.5 0.5 }",
               v3(0.1f, 0.7f, 1.5f), 1.0, 2e-5, NULL);
}

/* ------------------------------------------------------------------ a linear ramp */

enum { RAMP_N = 8 };
static double ramp_value(size_t i, void *ctx)
{
    (void)ctx;
    return (double)(i % RAMP_N) * 0.25;   /* only z varies: x y z sizes 1 1 RAMP_N */
}

/* The mean density along z through a grid of RAMP_N cell-centred samples 0, 0.25, ...:
 * linear between the first and last centre, constant in the half cells at the ends. */
static double ramp_mean(void)
{
    double sum = 0.0;
    int n = 1 << 20;
    for (int k = 0; k < n; k++) {
        double u = (k + 0.5) / n, x = u * RAMP_N - 0.5;
        x = x < 0.0 ? 0.0 : x > RAMP_N - 1 ? RAMP_N - 1 : x;
        sum += x * 0.25;
    }
    return sum / n;
}

static void test_ramp(void)
{
    char *list = number_list(RAMP_N, ramp_value, NULL);
    char medium[2048];
    double mean = ramp_mean();
    snprintf(medium, sizeof medium, "medium m { type grid sigma_a 0.3 0.6 0.9 size 1 1 %d data %s "
             "min -2 -2 -1 max 2 2 1 }", RAMP_N, list);
    check_slab("density ramp, absorbing (ratio tracking)", medium, v3(0.3f, 0.6f, 0.9f), mean, 0.01, NULL);
    snprintf(medium, sizeof medium, "medium m { type grid sigma_a 0.1 0.2 0.3 sigma_s 0.2 0.4 0.6 size 1 1 %d "
             "data %s min -2 -2 -1 max 2 2 1 }", RAMP_N, list);
    check_slab("density ramp, scattering (delta tracking)", medium, v3(0.3f, 0.6f, 0.9f), mean, 0.012, NULL);
    free(list);
}

/* ------------------------------------------------------------------ residual ratio tracking */

/* The per-pixel variance of `text` rendered at 1 sample a pixel (every pixel of the
 * same expected value) on the scalar device and on OpenCL, which must give the same
 * bits; its channel means and variances in mean[3], var[3]. */
static int render_variance(const char *text, double mean[3], double var[3])
{
    const char *devices[] = { "scalar", TEST_OPENCL };
    Film f[2];
    int ok = 1;
    for (int d = 0; d < 2; d++) {
        Error err = { 0 };
        Status st = render_util_text_film("grid-test.scene", text, SCENE_FORMAT_CLPT, devices[d], &f[d], &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        error_clear(&err);
        ok &= st == ST_OK;
    }
    if (ok) {
        size_t n = (size_t)f[0].width * f[0].height;
        CHECK_MSG(film_sums_same(&f[0], &f[1]) == 3 * n, "%s differs from the scalar device", TEST_OPENCL);
        float *rgb = malloc(3 * n * sizeof *rgb);
        film_resolve(&f[0], rgb);
        for (int c = 0; c < 3; c++) {
            double sum = 0.0, sq = 0.0;
            for (size_t i = 0; i < n; i++) sum += rgb[3 * i + c];
            mean[c] = sum / (double)n;
            for (size_t i = 0; i < n; i++) sq += (rgb[3 * i + c] - mean[c]) * (rgb[3 * i + c] - mean[c]);
            var[c] = sq / (double)(n - 1);
        }
        free(rgb);
    }
    film_free(&f[0]);
    film_free(&f[1]);
    return ok;
}

/* Residual ratio tracking (grid.h) against the exact transmittance of a density ramp,
 * and its variance: a camera ray through an absorbing ramp (a flight's transmittance)
 * and a shadow ray through one (a floor lit from straight above through a ramp in y,
 * seen from below it: every pixel is albedo / pi times the transmittance). Plain ratio
 * tracking measured, per sample: variance 0.056 0.100 0.121 through the camera's ramp,
 * 0.0012 0.0031 0.0050 on the floor; residual tracking 0.009 0.013 0.011 and 0.00017
 * 0.00043 0.00059. */
static void test_residual_variance(void)
{
    char *list = number_list(RAMP_N, ramp_value, NULL);
    char text[4096];
    double mean[3], var[3], want[3], depth = ramp_mean();
    vec3 sigma = v3(0.3f, 0.6f, 0.9f);
    snprintf(text, sizeof text, "image { width 64 height 64 spp 1 depth 0 }\n"
             "camera { from 0 0 5 at 0 0 0 up 0 1 0 fov 2 }\n"
             "medium m { type grid sigma_a 0.3 0.6 0.9 size 1 1 %d data %s min -2 -2 -1 max 2 2 1 }\n"
             "material lamp { type emissive radiance 1 1 1 }\n"
             "box { min -2 -2 -1 max 2 2 1 material none interior m }\n"
             "quad { v0 -3 -3 -2 v1 3 -3 -2 v2 3 3 -2 v3 -3 3 -2 material lamp }\n", RAMP_N, list);
    slab_expected(sigma, depth, want);
    if (render_variance(text, mean, var)) {
        fprintf(stderr, "  camera ray through a ramp, 1 spp: %.5f %.5f %.5f (exact %.5f %.5f %.5f), variance "
                "%.4f %.4f %.4f\n", mean[0], mean[1], mean[2], want[0], want[1], want[2], var[0], var[1], var[2]);
        for (int c = 0; c < 3; c++) {
            CHECK_NEAR(mean[c], want[c], 0.01);
            CHECK_MSG(var[c] < 0.025, "channel %d: variance %g (plain ratio tracking: 0.056 to 0.121)", c, var[c]);
        }
    }
    snprintf(text, sizeof text, "image { width 64 height 64 spp 1 depth 1 }\n"
             "camera { from 0 0.5 0 at 0 0 0 up 0 0 -1 fov 30 }\n"
             "background { color 0 0 0 }\n"
             "light { type directional direction 0 -1 0 intensity 1 1 1 }\n"
             "material floor { type diffuse albedo 0.5 0.5 0.5 }\n"
             "plane { point 0 0 0 normal 0 1 0 material floor }\n"
             "medium m { type grid sigma_a 0.3 0.6 0.9 size 1 %d 1 data %s min -100 1 -100 max 100 2 100 }\n"
             "box { min -100 1 -100 max 100 2 100 material none interior m }\n", RAMP_N, list);
    if (render_variance(text, mean, var)) {
        for (int c = 0; c < 3; c++) want[c] = 0.5 / M_PI * exp(-(double)v3_get(sigma, c) * depth);
        fprintf(stderr, "  shadow rays through a ramp, 1 spp: %.5f %.5f %.5f (exact %.5f %.5f %.5f), variance "
                "%.5f %.5f %.5f\n", mean[0], mean[1], mean[2], want[0], want[1], want[2], var[0], var[1], var[2]);
        for (int c = 0; c < 3; c++) {
            CHECK_NEAR(mean[c], want[c], 0.0025);
            CHECK_MSG(var[c] < 0.0008, "channel %d: variance %g (plain ratio tracking: 0.0012 to 0.0050)", c,
                      var[c]);
        }
    }
    free(list);
}

/* ------------------------------------------------------------------ a sphere in empty space */

enum { SPH_N = 32 };
static double sphere_value(size_t i, void *ctx)
{
    (void)ctx;
    double x = ((double)(i % SPH_N) + 0.5) / SPH_N * 2.0 - 1.0;
    double y = ((double)(i / SPH_N % SPH_N) + 0.5) / SPH_N * 2.0 - 1.0;
    double z = ((double)(i / SPH_N / SPH_N) + 0.5) / SPH_N * 2.0 - 1.0;
    return x * x + y * y + z * z < 0.25 ? 3.0 : 0.0;
}

static double sph_at(int x, int y, int z)
{
    return sphere_value(((size_t)z * SPH_N + (size_t)y) * SPH_N + (size_t)x, NULL);
}

/* The grid's trilinear density at p in [-1, 1]^3, as grid.h interpolates it. */
static double sph_density(double px, double py, double pz)
{
    double q[3] = { (px + 1.0) / 2.0, (py + 1.0) / 2.0, (pz + 1.0) / 2.0 }, f[3];
    int i0[3], i1[3];
    for (int a = 0; a < 3; a++) {
        double x = q[a] * SPH_N - 0.5;
        x = x < 0.0 ? 0.0 : x > SPH_N - 1 ? SPH_N - 1 : x;
        i0[a] = (int)x;
        i1[a] = i0[a] + 1 < SPH_N ? i0[a] + 1 : i0[a];
        f[a] = x - i0[a];
    }
    double v = 0.0;
    for (int k = 0; k < 8; k++) {
        int bx = k & 1, by = (k >> 1) & 1, bz = k >> 2;
        double w = (bx ? f[0] : 1 - f[0]) * (by ? f[1] : 1 - f[1]) * (bz ? f[2] : 1 - f[2]);
        v += w * sph_at(bx ? i1[0] : i0[0], by ? i1[1] : i0[1], bz ? i1[2] : i0[2]);
    }
    return v;
}

/* An orthographic view of the grid along -z: the film's mean of exp(-sigma_t tau(x, y)),
 * tau marched finely through the trilinear field. */
static double sphere_expected(double sigma_t)
{
    int n = 128, steps = 1024;
    double sum = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double x = -1.0 + 2.0 * (i + 0.5) / n, y = -1.0 + 2.0 * (j + 0.5) / n, tau = 0.0;
            for (int k = 0; k < steps; k++) tau += sph_density(x, y, -1.0 + 2.0 * (k + 0.5) / steps) * 2.0 / steps;
            sum += exp(-sigma_t * tau);
        }
    return sum / ((double)n * n);
}

static void test_sphere_in_box(void)
{
    char *list = number_list((size_t)SPH_N * SPH_N * SPH_N, sphere_value, NULL);
    size_t size = strlen(list) + 1024;
    char *text = malloc(size);
    double want = sphere_expected(0.8);
    const char *kinds[] = { "sigma_a 0.8 0.8 0.8", "sigma_a 0.2 0.2 0.2 sigma_s 0.6 0.6 0.6" };
    for (int k = 0; k < 2; k++) {
        snprintf(text, size, "image { width 32 height 32 spp 64 depth 0 }\n"
                 "camera { type orthographic from 0 0 5 at 0 0 0 up 0 1 0 width 2 }\n"
                 "medium m { type grid %s size %d %d %d data %s min -1 -1 -1 max 1 1 1 }\n"
                 "material lamp { type emissive radiance 1 1 1 }\n"
                 "box { min -1.5 -1.5 -1.5 max 1.5 1.5 1.5 material none interior m }\n"
                 "quad { v0 -3 -3 -2 v1 3 -3 -2 v2 3 3 -2 v3 -3 3 -2 material lamp }\n",
                 kinds[k], SPH_N, SPH_N, SPH_N, list);
        const char *devices[] = { "scalar", TEST_OPENCL };
        for (int d = 0; d < 2; d++) {
            double m[3];
            if (!render_means(text, devices[d], m)) continue;
            fprintf(stderr, "  sphere of density in a %d^3 grid, %s, on %s: %.5f %.5f %.5f (marched %.5f)\n", SPH_N,
                    kinds[k], devices[d], m[0], m[1], m[2], want);
            for (int c = 0; c < 3; c++) CHECK_NEAR(m[c], want, 0.005);
        }
    }
    free(text);
    free(list);
}

/* ------------------------------------------------------------------ the furnace */

/* A non-absorbing grid (albedo 1, any density) inside a sphere under a white
 * background: every pixel's expected value is 1. */
static void test_furnace(void)
{
    char *list = number_list((size_t)SPH_N * SPH_N * SPH_N, sphere_value, NULL);
    size_t size = strlen(list) + 1024;
    char *text = malloc(size);
    const char *kinds[] = { "sigma_s 2 2 2 g 0.5", "sigma_s 0.5 2 4 g -0.3" };
    for (int k = 0; k < 2; k++) {
        snprintf(text, size, "image { width 16 height 16 spp 128 depth 512 }\n"
                 "camera { from 0 0 2.5 at 0 0 0 up 0 1 0 fov 50 }\n"
                 "background { color 1 1 1 }\n"
                 "medium m { type grid %s size %d %d %d data %s min -1 -1 -1 max 1 1 1 }\n"
                 "sphere { center 0 0 0 radius 1 material none interior m }\n",
                 kinds[k], SPH_N, SPH_N, SPH_N, list);
        double m[3];
        if (!render_means(text, "scalar", m)) continue;
        fprintf(stderr, "  furnace, grid %s: %.4f %.4f %.4f (expected 1)\n", kinds[k], m[0], m[1], m[2]);
        for (int c = 0; c < 3; c++) CHECK_NEAR(m[c], 1.0, 0.02);
    }
    free(text);
    free(list);
}

/* ------------------------------------------------------------------ the reader */

/* `file` reads the same densities as `data`; the majorant of each coarse cell bounds the
 * samples the interpolation blends in it; the transform maps the box onto the unit cube. */
static void test_file_and_majorant(void)
{
    enum { N = 20 };
    static float d[N * N * N];
    for (int i = 0; i < N * N * N; i++) d[i] = (float)((i * 7919) % 1000) / 500.0f;
    const char *raw = TEST_TMP("clpt-test-grid.raw");
    FILE *f = fopen(raw, "wb");
    CHECK(f != NULL);
    if (!f) return;
    fwrite(d, sizeof d, 1, f);
    fclose(f);
    char text[256];
    snprintf(text, sizeof text, "medium m { type grid sigma_s 1 1 1 size %d %d %d file \"%s\" min 0 0 0 max 2 4 8 "
             "translate 1 0 0 }\n", N, N, N, raw);
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    Status st = scene_load_text("grid-test.scene", text, strlen(text), &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (!st && s.n_grids == 1) {
        const GridMedium *g = &s.grids[0];
        CHECK(memcmp(s.grid_data + g->density_at, d, sizeof d) == 0);
        CHECK_EQ_INT(g->mx, 16);
        /* every sample bounded by the majorant of every coarse cell its support touches */
        int bad = 0;
        for (int z = 0; z < N; z++)
            for (int y = 0; y < N; y++)
                for (int x = 0; x < N; x++) {
                    float v = d[(z * N + y) * N + x];
                    /* the sample's support: centre +- one cell, in unit coordinates */
                    int c[3][2];
                    int p[3] = { x, y, z };
                    for (int a = 0; a < 3; a++) {
                        double lo = (p[a] - 0.5) / N, hi = (p[a] + 1.5) / N;
                        c[a][0] = (int)(lo * 16) < 0 ? 0 : (int)(lo * 16);
                        c[a][1] = (int)(hi * 16) > 15 ? 15 : (int)(hi * 16);
                        if ((p[a] + 1.5) / N * 16 == c[a][1]) c[a][1]--;   /* open end */
                        if (c[a][0] < 0) c[a][0] = 0;
                    }
                    for (int cz = c[2][0]; cz <= c[2][1]; cz++)
                        for (int cy = c[1][0]; cy <= c[1][1]; cy++)
                            for (int cx = c[0][0]; cx <= c[0][1]; cx++)
                                if (s.grid_data[g->majorant_at + (cz * 16 + cy) * 16 + cx] < v) bad++;
                }
        CHECK_MSG(bad == 0, "%d samples above a majorant of a cell they reach", bad);
        /* world (1, 0, 0) is the box's corner min; (3, 4, 8) its corner max */
        CHECK_NEAR(g->to_grid[0] * 3.0f + g->to_grid[3], 1.0, 1e-6);
        CHECK_NEAR(g->to_grid[5] * 4.0f + g->to_grid[7], 1.0, 1e-6);
        CHECK_NEAR(g->to_grid[10] * 8.0f + g->to_grid[11], 1.0, 1e-6);
        CHECK_NEAR(g->to_grid[0] * 1.0f + g->to_grid[3], 0.0, 1e-6);
    }
    scene_free(&s);
    error_clear(&err);
    unlink(raw);
}

/* ------------------------------------------------------------------ devices */

/* Every wave launch of an OpenCL device gives the scalar device's bits on the smoke. */
static void test_devices_match_scalar(void)
{
    const char *scene = "scenes/smoke.scene";
    const char *modes[] = { "counted", "bounded", "megakernel" };
    const char *ref = TEST_TMP("clpt-test-grid-scalar.pfm"), *out = TEST_TMP("clpt-test-grid-ocl.pfm");
    cli_run(ARGS(scene, "--device", "scalar", "--width", "40", "--height", "30", "--spp", "4", "-q", "-o", ref), &r);
    CHECK_MSG(r.status == 0, "%s: %s", scene, r.err);
    for (int i = 0; i < 3; i++) {
        cli_run(ARGS(scene, "--device", TEST_OPENCL, "--width", "40", "--height", "30", "--spp", "4",
                     "--wave-launch", modes[i], "--wave-paths", "1000", "--batch", "2", "-q", "-o", out), &r);
        CHECK_MSG(r.status == 0, "%s, %s: %s", scene, modes[i], r.err);
        CHECK_MSG(files_equal(ref, out), "%s, --wave-launch %s: the image differs from the scalar device's", scene,
                  modes[i]);
        fprintf(stderr, "  %s, --wave-launch %s: %s\n", scene, modes[i],
                files_equal(ref, out) ? "the scalar device's bits" : "DIFFERENT");
    }
    unlink(ref);
    unlink(out);
}

int main(void)
{
    RUN(test_constant_grid);
    RUN(test_ramp);
    RUN(test_residual_variance);
    RUN(test_sphere_in_box);
    RUN(test_furnace);
    RUN(test_file_and_majorant);
    RUN(test_devices_match_scalar);
    return harness_report();
}
