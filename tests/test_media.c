/*
 * test_media.c — participating media (kernels/medium/, docs/media.md): the
 * Henyey-Greenstein phase function against its own density (chi-square) and its
 * normalisation; whole images against analytic answers (the transmittance of a slab,
 * chromatic and scattering; white furnaces of non-absorbing media behind a boundary
 * that is no surface and behind glass); next-event estimation, phase sampling and MIS
 * agreeing; and the same bits on every device and wave launch, and after a resume.
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
#include "medium/phase.h"
#include "medium/medium.h"
#include "render_util.h"

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static CliResult r;

/* ------------------------------------------------------------------ the phase function */

static uint32_t rng_state = 12345u;
static float next_uniform(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) * (1.0f / 16777216.0f);
}

/* P(chi-square with k degrees of freedom > x), by Wilson and Hilferty's cube-root
 * normal approximation (good to a few per cent of p at the k used here). */
static double chi2_tail(double x, double k)
{
    double h = 2.0 / (9.0 * k);
    double z = (cbrt(x / k) - (1.0 - h)) / sqrt(h);
    return 0.5 * erfc(z / sqrt(2.0));
}

enum { NMU = 40, NPHI = 24, NSAMPLE = 400000 };

/* Directions from phase_hg_sample about a tilted travel direction, binned by the cosine to
 * it and the angle about it, against the density integrated over each cell; returns p. */
static double hg_chi2(float g)
{
    vec3 d = v3_norm(v3(0.3f, -0.5f, 0.8f)), t, b;
    k_onb(d, &t, &b);
    static double count[NMU][NPHI];
    memset(count, 0, sizeof count);
    int bad_pdf = 0;
    for (int i = 0; i < NSAMPLE; i++) {
        float pdf;
        vec3 wi = phase_hg_sample(g, d, next_uniform(), next_uniform(), &pdf);
        float f = phase_hg(g, d, wi);
        if (!(fabsf(pdf - f) <= 2e-3f * f) || fabsf(v3_len(wi) - 1.0f) > 1e-5f) bad_pdf++;
        double mu = v3_dot(wi, d), phi = atan2(v3_dot(wi, b), v3_dot(wi, t)) + M_PI;
        int im = (int)((mu + 1.0) * 0.5 * NMU), ip = (int)(phi / (2.0 * M_PI) * NPHI);
        count[im < 0 ? 0 : im >= NMU ? NMU - 1 : im][ip < 0 ? 0 : ip >= NPHI ? NPHI - 1 : ip] += 1.0;
    }
    CHECK_MSG(bad_pdf == 0, "g %g: %d samples whose pdf is not the phase function's value", (double)g, bad_pdf);
    double chi2 = 0.0, pool_e = 0.0, pool_o = 0.0;
    int dof = 0;
    for (int im = 0; im < NMU; im++) {
        /* the density over a band of mu, by Simpson's rule on 64 panels, shared by its cells */
        double lo = -1.0 + 2.0 * im / NMU, h = 2.0 / NMU / 64.0, band = 0.0;
        for (int k = 0; k <= 64; k++)
            band += (k == 0 || k == 64 ? 1.0 : (k % 2 ? 4.0 : 2.0)) * phase_hg_mu(g, (float)(lo + k * h));
        band *= h / 3.0 * 2.0 * M_PI;
        for (int ip = 0; ip < NPHI; ip++) {
            double e = band / NPHI * NSAMPLE, o = count[im][ip];
            if (e < 5.0) {
                pool_e += e;
                pool_o += o;
                continue;
            }
            chi2 += (o - e) * (o - e) / e;
            dof++;
        }
    }
    if (pool_e > 0.0) {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof++;
    }
    double p = chi2_tail(chi2, dof - 1);
    fprintf(stderr, "  HG g %5.2f: chi2 %.1f, %d dof, p %.3f\n", (double)g, chi2, dof - 1, p);
    return p;
}

static void test_hg_sampling_matches_density(void)
{
    const float gs[] = { -0.7f, 0.0f, 0.3f, 0.9f };
    for (int i = 0; i < 4; i++) CHECK_MSG(hg_chi2(gs[i]) > 0.002, "g %g: sampled directions do not follow "
                                          "the phase function", (double)gs[i]);
}

/* The phase function integrates to 1 over the sphere, and its mean cosine is g. */
static void test_hg_normalised(void)
{
    const float gs[] = { -0.9f, -0.3f, 0.0f, 0.5f, 0.95f };
    for (int i = 0; i < 5; i++) {
        double sum = 0.0, mean = 0.0;
        int n = 200000;
        for (int k = 0; k < n; k++) {
            double mu = -1.0 + (k + 0.5) * 2.0 / n;
            double f = phase_hg_mu(gs[i], (float)mu) * 2.0 * M_PI * 2.0 / n;
            sum += f;
            mean += f * mu;
        }
        fprintf(stderr, "  HG g %5.2f: integral %.5f, mean cosine %.5f\n", (double)gs[i], sum, mean);
        CHECK_NEAR(sum, 1.0, 2e-3);
        CHECK_NEAR(mean, gs[i], 2e-3);
    }
}

/* Channel choice keeps to the throughput and never picks a channel of probability 0. */
static void test_channel_pick(void)
{
    vec3 pc = medium_channel_pdf(v3(0.0f, 2.0f, 6.0f));
    CHECK_NEAR(pc.y, 0.25, 1e-6);
    float rest;
    int zero_picked = 0, counts[3] = { 0, 0, 0 };
    for (int k = 0; k < 4096; k++) {
        int c = medium_pick_channel(pc, (k + 0.5f) / 4096.0f, &rest);
        counts[c]++;
        zero_picked += c == 0;
        CHECK(rest >= 0.0f && rest < 1.0f);
    }
    CHECK_EQ_INT(zero_picked, 0);
    CHECK_EQ_INT(counts[1], 1024);
    /* rounding at the top of the range falls on a channel that can be chosen */
    CHECK(medium_pick_channel(v3(0.5f, 0.5f, 0.0f), 0.99999994f, &rest) == 1);
    CHECK(medium_pick_channel(v3(1.0f, 0.0f, 0.0f), 0.99999994f, &rest) == 0);
}

/* ------------------------------------------------------------------ whole images */

static Status load_text(Scene *s, const char *text, Error *err)
{
    scene_init(s);
    return scene_load_text("media-test.scene", text, strlen(text), s, err);
}

/* Renders `text` on `devices` and returns its channel means. */
static int render_means(const char *text, const char *devices, double mean[3])
{
    Error err = { 0 };
    Status st = render_util_text_means("media-test.scene", text, devices, mean, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    error_clear(&err);
    return st == ST_OK;
}

/* A camera looking through a slab 2 thick of a chromatic medium at a white lamp, with
 * no bounce allowed: only light that flew straight through counts, exp(-sigma_t 2) per
 * channel. With scattering the free-flight sampling decides it (chosen by one channel,
 * weighted by all three); without, the transmittance is exact. */
#define SLAB_SCENE \
    "image { width 16 height 16 spp %s depth 0 split %s }\n" \
    "camera { from 0 0 5 at 0 0 0 up 0 1 0 fov 2 }\n" \
    "medium m { type homogeneous sigma_a %s sigma_s %s }\n" \
    "material lamp { type emissive radiance 1 1 1 }\n" \
    "box { min -2 -2 -1 max 2 2 1 material none interior m }\n" \
    "quad { v0 -3 -3 -2 v1 3 -3 -2 v2 3 3 -2 v3 -3 3 -2 material lamp }\n"

/* The image mean the slab should give: exp(-sigma_t 2 / cos) over the film, whose rays
 * cross the slab at up to 1.4 degrees (the 2-degree field's corners), 1e-4 longer on
 * average than straight through. */
static void slab_expected(vec3 sigma_t, double want[3])
{
    double half = tan(1.0 * M_PI / 180.0), sum[3] = { 0.0, 0.0, 0.0 };
    int n = 200;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double x = half * (2.0 * (i + 0.5) / n - 1.0), y = half * (2.0 * (j + 0.5) / n - 1.0);
            double len = 2.0 * sqrt(1.0 + x * x + y * y);
            sum[0] += exp(-sigma_t.x * len);
            sum[1] += exp(-sigma_t.y * len);
            sum[2] += exp(-sigma_t.z * len);
        }
    for (int c = 0; c < 3; c++) want[c] = sum[c] / ((double)n * n);
}

/* split > 1: first-hit splitting, whose first hit is the slab's boundary (each branch
 * flies through the slab on its own), at the same number of flights */
static void check_slab(const char *sa, const char *ss, vec3 sigma_t, double tol, int split)
{
    char text[1024], spp[16], splits[16];
    snprintf(spp, sizeof spp, "%d", 256 / split);
    snprintf(splits, sizeof splits, "%d", split);
    snprintf(text, sizeof text, SLAB_SCENE, spp, splits, sa, ss);
    const char *devices[] = { "scalar", TEST_OPENCL };
    for (int d = 0; d < 2; d++) {
        double m[3];
        if (!render_means(text, devices[d], m)) continue;
        double want[3];
        slab_expected(sigma_t, want);
        fprintf(stderr, "  slab sigma_a %s sigma_s %s, split %d, on %s: %.5f %.5f %.5f (exp(-sigma_t d / cos): %.5f "
                "%.5f %.5f)\n", sa, ss, split, devices[d], m[0], m[1], m[2], want[0], want[1], want[2]);
        for (int c = 0; c < 3; c++) CHECK_NEAR(m[c], want[c], tol);
    }
}

static void test_slab_transmittance(void)
{
    check_slab("0.1 0.2 0.4", "0.3 0.1 0.5", v3(0.4f, 0.3f, 0.9f), 0.006, 1);
    check_slab("0.1 0.7 1.5", "0 0 0", v3(0.1f, 0.7f, 1.5f), 2e-5, 1);
    check_slab("0.1 0.2 0.4", "0.3 0.1 0.5", v3(0.4f, 0.3f, 0.9f), 0.006, 4);
    check_slab("0.1 0.7 1.5", "0 0 0", v3(0.1f, 0.7f, 1.5f), 2e-5, 4);
}

/* The white furnace: a non-absorbing medium (albedo 1) inside a sphere, under a white
 * background and nothing else. Light neither appears nor disappears in it, so every
 * pixel's expected value is 1, whatever g and whichever channel scatters most; the
 * boundary is `material none`, or glass (whose refraction clpt does not scale by
 * 1/eta^2, so the radiance inside is 1 too). */
#define FURNACE_SCENE \
    "image { width 16 height 16 spp %s depth 512 split %s }\n" \
    "camera { from 0 0 %s at 0 0 -1 up 0 1 0 fov 60 }\n" \
    "background { color 1 1 1 }\n" \
    "medium m { type homogeneous sigma_a 0 0 0 sigma_s %s g %s }\n" \
    "material glass { type dielectric ior 1.5 }\n" \
    "sphere { center 0 0 0 radius 1 material %s interior m }\n"

static void check_furnace(const char *cam_z, const char *ss, const char *g, const char *boundary, int split)
{
    char text[1024], spp[16], splits[16];
    snprintf(spp, sizeof spp, "%d", 128 / split);
    snprintf(splits, sizeof splits, "%d", split);
    snprintf(text, sizeof text, FURNACE_SCENE, spp, splits, cam_z, ss, g, boundary);
    double m[3];
    if (!render_means(text, "scalar", m)) return;
    fprintf(stderr, "  furnace sigma_s %s, g %s, %s, camera at z %s, split %d: %.4f %.4f %.4f (expected 1)\n", ss, g,
            boundary, cam_z, split, m[0], m[1], m[2]);
    for (int c = 0; c < 3; c++) CHECK_NEAR(m[c], 1.0, 0.02);
}

static void test_furnace(void)
{
    check_furnace("0", "2 2 2", "0", "none", 1);
    check_furnace("0", "2 2 2", "0.7", "none", 1);
    check_furnace("0", "0.5 2 4", "-0.5", "none", 1);   /* chromatic */
    check_furnace("3", "1 2 3", "0.3", "glass", 1);      /* seen from outside, through glass */
    /* first-hit splitting from outside: at the boundary, and at the glass */
    check_furnace("3", "1 2 3", "0.3", "none", 4);
    check_furnace("3", "1 2 3", "0.3", "glass", 4);
}

/* Single scattering against a numeric integral: the camera and a point light in one
 * medium that fills the scene (the background's), paths of one bounce, so that the
 * only light is that of one stop in the medium lit by the light sample there. Along the
 * camera ray x(t) = t d, the radiance is
 *   L = int_0^inf exp(-sigma_t t) sigma_s p(d . w(t)) I exp(-sigma_t r(t)) / r(t)^2 dt,
 * w the direction from x(t) to the light and r its distance: the free-flight density,
 * the phase function and the transmittance to the light all enter. */
#define SINGLE_SCENE \
    "image { width 4 height 4 spp 4096 depth 1 }\n" \
    "medium fog { type homogeneous sigma_a 0.1 0.1 0.1 sigma_s 0.5 0.5 0.5 g 0.6 }\n" \
    "camera { from 0 0 0 at 0 0 -1 up 0 1 0 fov 0.5 medium fog }\n" \
    "background { color 0 0 0 medium fog }\n" \
    "light { type point position 0 1 -2 intensity 10 10 10 }\n"

static double single_scatter_integral(void)
{
    const double st = 0.6, ss = 0.5, g = 0.6, I = 10.0;
    double sum = 0.0, h = 1e-4;
    for (int k = 0; k < 600000; k++) {   /* midpoint rule over t in [0, 60] */
        double t = (k + 0.5) * h, dz = -2.0 + t, r2 = 1.0 + dz * dz, dist = sqrt(r2);
        double mu = -dz / dist;   /* d = (0, 0, -1); w = (0, 1, -2 + t) / dist */
        double ph = (1.0 - g * g) / (4.0 * M_PI * pow(1.0 + g * g - 2.0 * g * mu, 1.5));
        sum += exp(-st * t) * ss * ph * I * exp(-st * dist) / r2 * h;
    }
    return sum;
}

static void test_single_scattering(void)
{
    double want = single_scatter_integral();
    const char *devices[] = { "scalar", TEST_OPENCL };
    for (int d = 0; d < 2; d++) {
        double m[3];
        if (!render_means(SINGLE_SCENE, devices[d], m)) continue;
        fprintf(stderr, "  single scattering on %s: %.5f %.5f %.5f (numeric integral %.5f)\n", devices[d], m[0], m[1],
                m[2], want);
        for (int c = 0; c < 3; c++) CHECK_NEAR(m[c], want, 0.01 * want);
    }
}

/* A fog lit by a small spherical lamp: light sampling alone, phase (and BSDF) sampling
 * alone and their MIS estimate the same image. */
static const char *mis_scene =
    "image { width 24 height 24 spp 256 depth 6 }\n"
    "camera { from 0 1 4 at 0 0.5 0 up 0 1 0 fov 50 }\n"
    "medium fog { type homogeneous albedo 0.8 0.7 0.6 density 0.6 g 0.4 }\n"
    "material floor { type diffuse albedo 0.5 0.5 0.5 }\n"
    "material lamp { type emissive radiance 20 20 20 }\n"
    "plane { point 0 0 0 normal 0 1 0 material floor }\n"
    "box { min -1 0.001 -1 max 1 1.5 1 material none interior fog }\n"
    "sphere { center 0.3 1.2 0.2 radius 0.15 material lamp }\n";

static Status render_mis(uint mode, double mean[3], Error *err)
{
    Scene s;
    RenderScene rs;
    Device *dev = NULL;
    DeviceDesc *all = NULL;
    size_t n_all = 0, *chosen = NULL, n_chosen = 0;
    char warning[1100];
    Film film;
    memset(&film, 0, sizeof film);
    memset(&rs, 0, sizeof rs);
    Status st = load_text(&s, mis_scene, err);
    if (!st) st = render_scene_prepare(&s, 0, &rs, err);
    if (st) goto out;
    rs.ds.params.mis_mode = mode;
    if ((st = device_list(&all, &n_all, warning, sizeof warning, err)) ||
        (st = device_select("scalar", all, n_all, &chosen, &n_chosen, err)) ||
        (st = device_open(&all[chosen[0]], NULL, &dev, err)) || (st = dev->ops->load_scene(dev, &rs.ds, err)) ||
        (st = film_init(&film, rs.ds.params.width, rs.ds.params.height, err)))
        goto out;
    ScheduleConfig cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = s.image.spp;
    ScheduleStats stats;
    memset(&stats, 0, sizeof stats);
    st = schedule_run(&dev, 1, &cfg, &film, &stats, err);
    schedule_stats_free(&stats);
    if (!st) film_channel_means(&film, mean);
out:
    if (dev) device_close(dev);
    film_free(&film);
    free(all);
    free(chosen);
    render_scene_free(&rs);
    scene_free(&s);
    return st;
}

static void test_strategies_agree(void)
{
    const char *names[] = { "MIS", "light sampling only", "phase/BSDF sampling only" };
    const uint modes[] = { MIS_BOTH, MIS_LIGHT_ONLY, MIS_BSDF_ONLY };
    double m[3][3];
    for (int i = 0; i < 3; i++) {
        Error err = { 0 };
        Status st = render_mis(modes[i], m[i], &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        error_clear(&err);
        if (st) return;
        fprintf(stderr, "  fog lit by a small lamp, %s: %.4f %.4f %.4f\n", names[i], m[i][0], m[i][1], m[i][2]);
    }
    for (int i = 1; i < 3; i++)
        for (int c = 0; c < 3; c++) CHECK_MSG(fabs(m[i][c] - m[0][c]) < 0.03 * m[0][c], "%s differs from MIS in "
                                              "channel %d: %.4f against %.4f", names[i], c, m[i][c], m[0][c]);
}

/* Every wave launch of an OpenCL device (counted and bounded wavefront, megakernel)
 * gives the scalar device's bits on media scenes, with several waves and batches (a
 * split render, split.scene, runs the megakernel whatever the launch asked). */
static void test_devices_match_scalar(void)
{
    const char *scenes[] = { "scenes/fog.scene", "tests/data/media/mix.scene", "tests/data/media/split.scene" };
    const char *modes[] = { "counted", "bounded", "megakernel" };
    const char *ref = TEST_TMP("clpt-test-media-scalar.pfm"), *out = TEST_TMP("clpt-test-media-ocl.pfm");
    for (int k = 0; k < 3; k++) {
        cli_run(ARGS(scenes[k], "--device", "scalar", "--width", "40", "--height", "30", "--spp", "6", "-q", "-o",
                     ref), &r);
        CHECK_MSG(r.status == 0, "%s: %s", scenes[k], r.err);
        for (int i = 0; i < 3; i++) {
            cli_run(ARGS(scenes[k], "--device", TEST_OPENCL, "--width", "40", "--height", "30", "--spp", "6",
                         "--wave-launch", modes[i], "--wave-paths", "1000", "--batch", "2", "-q", "-o", out), &r);
            CHECK_MSG(r.status == 0, "%s, %s: %s", scenes[k], modes[i], r.err);
            CHECK_MSG(files_equal(ref, out), "%s, --wave-launch %s: the image differs from the scalar device's",
                      scenes[k], modes[i]);
            fprintf(stderr, "  %s, --wave-launch %s: %s\n", scenes[k], modes[i],
                    files_equal(ref, out) ? "the scalar device's bits" : "DIFFERENT");
        }
    }
    unlink(ref);
    unlink(out);
}

/* A media render checkpointed at 4 samples and resumed to 8, on PoCL and the scalar
 * device together, is the straight 8-sample render bit for bit; also split 3. */
static void test_resume_matches_straight(void)
{
    cli_check_resume_matches_straight("tests/data/media/mix.scene", TEST_TMP("clpt-test-media-ref.pfm"),
                                      TEST_TMP("clpt-test-media-out.pfm"), TEST_TMP("clpt-test-media.ckpt"));
    cli_check_resume_matches_straight("tests/data/media/split.scene", TEST_TMP("clpt-test-media-ref.pfm"),
                                      TEST_TMP("clpt-test-media-out.pfm"), TEST_TMP("clpt-test-media.ckpt"));
}

/* First-hit splitting restarts paths at the camera ray's first hit, which a camera
 * inside a medium may never reach: refused there, with the way out. */
static void test_split_refused(void)
{
    cli_run(ARGS("tests/data/media/mix.scene", "--device", "scalar", "--split", "2", "-q", "-o",
                 TEST_TMP("clpt-test-media-split.pfm")), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "first-hit splitting (--split 2) does not work with the camera inside a "
                              "participating medium; render it with --split 1");
}

/* First-hit splitting with the camera in vacuum: a fog lit by a lamp over a floor (the
 * camera rays' first hits the floor, the lamp and the fog's boundary) at split 4 and 64
 * samples has the means of split 1 at 256, on both devices; and scenes/fog.scene at
 * split 3 on PoCL is the scalar device's render bit for bit. */
static void test_split_in_vacuum(void)
{
    const char *rest = strchr(mis_scene, '\n') + 1;   /* all but its image line */
    char text[2048];
    double m[3][3];
    const char *devices[] = { "scalar", "scalar", TEST_OPENCL };
    const int split[] = { 1, 4, 4 };
    for (int i = 0; i < 3; i++) {
        snprintf(text, sizeof text, "image { width 24 height 24 spp %d depth 6 split %d }\n%s", 256 / split[i],
                 split[i], rest);
        if (!render_means(text, devices[i], m[i])) return;
        fprintf(stderr, "  fog over a floor, split %d on %s: %.4f %.4f %.4f\n", split[i], devices[i], m[i][0], m[i][1],
                m[i][2]);
    }
    for (int c = 0; c < 3; c++) {
        CHECK_NEAR(m[1][c], m[0][c], 0.02 * m[0][c]);
        CHECK(m[2][c] == m[1][c]);
    }
    const char *ref = TEST_TMP("clpt-test-media-split-scalar.pfm"), *out = TEST_TMP("clpt-test-media-split-ocl.pfm");
    cli_run(ARGS("scenes/fog.scene", "--device", "scalar", "--width", "40", "--height", "30", "--spp", "4", "--split",
                 "3", "-q", "-o", ref), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS("scenes/fog.scene", "--device", TEST_OPENCL, "--width", "40", "--height", "30", "--spp", "4",
                 "--split", "3", "--batch", "2", "-q", "-o", out), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(files_equal(ref, out), "scenes/fog.scene at --split 3: PoCL's image differs from the scalar device's");
    unlink(ref);
    unlink(out);
}

/* A shadow ray decides by the material the path sees: an instance's where it replaces
 * its object's. A floor lit by a point light only through a lid, an instance of an
 * object whose quad bounds a medium (`material none`, which a shadow ray passes
 * through) but which the instance makes black and opaque: seen from below the lid the
 * floor is in its shadow, every pixel exactly 0, on both devices. (The shadow rays once
 * took the object's material and lit it through the lid.) */
static void test_instance_material_blocks_shadows(void)
{
    static const char *text =
        "image { width 16 height 16 spp 4 depth 1 }\n"
        "camera { from 0 1 0 at 0 0 0 up 0 0 1 fov 40 }\n"
        "medium m { type homogeneous sigma_a 0.1 0.1 0.1 sigma_s 0 0 0 }\n"
        "material white { type diffuse albedo 1 1 1 }\n"
        "material black { type diffuse albedo 0 0 0 }\n"
        "quad { v0 -50 0 -50 v1 -50 0 50 v2 50 0 50 v3 50 0 -50 material white }\n"
        "object lid { quad { v0 -50 0 -50 v1 50 0 -50 v2 50 0 50 v3 -50 0 50 material none interior m } }\n"
        "instance lid { translate 0 2 0 material black }\n"
        "light { type point position 0 5 0 intensity 10 10 10 }\n";
    const char *devices[] = { "scalar", TEST_OPENCL };
    for (int kd = 0; kd < 2; kd++)   /* the BVH's walk and --accel kdtree's prototypes */
        for (int d = 0; d < 2; d++) {
            Scene s;
            Film f;
            Error err = { 0 };
            double m[3] = { -1.0, -1.0, -1.0 };
            memset(&f, 0, sizeof f);
            Status st = load_text(&s, text, &err);
            if (kd) s.accel = ACCEL_KDTREE;
            if (!st) st = render_util_run(&s, devices[d], 0, &f, &err);
            CHECK_MSG(st == ST_OK, "%s", err.msg);
            if (!st) film_channel_means(&f, m);
            film_free(&f);
            scene_free(&s);
            error_clear(&err);
            fprintf(stderr, "  floor under an instanced opaque lid, %s, on %s: %g %g %g\n", kd ? "kd-tree" : "BVH",
                    devices[d], m[0], m[1], m[2]);
            for (int c = 0; c < 3; c++) CHECK(m[c] == 0.0);
        }
}

int main(void)
{
    RUN(test_hg_sampling_matches_density);
    RUN(test_hg_normalised);
    RUN(test_channel_pick);
    RUN(test_slab_transmittance);
    RUN(test_furnace);
    RUN(test_single_scattering);
    RUN(test_strategies_agree);
    RUN(test_devices_match_scalar);
    RUN(test_resume_matches_straight);
    RUN(test_split_refused);
    RUN(test_split_in_vacuum);
    RUN(test_instance_material_blocks_shadows);
    return harness_report();
}
