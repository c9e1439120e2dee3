/*
 * test_adaptive.c — adaptive sampling (--noise-threshold, host/render/adaptive.c): the
 * error measure against its formula, the counts at which it decides, the mask (3x3
 * blocks' mean errors, or half a pixel's own) with its widening; then whole renders through clpt: converged pixels stop while noisy ones go
 * on, the same bits on PoCL, the scalar device, both together, other batch sizes, the
 * wavefront and resumed from a checkpoint, and a lower error against a converged
 * reference than uniform sampling with the same number of samples. No timings.
 */
#include <math.h>
#include <stdlib.h>
#include <unistd.h>

#include "cli_util.h"
#include "harness.h"
#include "render/adaptive.h"
#include "render/checkpoint.h"

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

/* The sky (constant: no noise) fills the upper half; the lower half is a floor and a
 * ball under a small lamp above the view (soft shadows: noisy). */
static const char *scene_text =
    "image { width 40 height 30 spp 256 depth 4 }\n"
    "camera { from 0 1.5 -6 at 0 1.5 0 up 0 1 0 fov 40 }\n"
    "background { color 0.4 0.5 0.7 }\n"
    "material floor { type diffuse albedo 0.8 0.8 0.8 }\n"
    "material lamp { type emissive radiance 60 50 40 }\n"
    "plane { point 0 0 0 normal 0 1 0 material floor }\n"
    "sphere { center 0 0.6 0 radius 0.6 material floor }\n"
    "sphere { center 1.5 4.5 -0.5 radius 0.3 material lamp }\n";

static char scene_path[128], dir[64];
static CliResult r;

static void path_in_dir(char *out, size_t size, const char *name)
{
    snprintf(out, size, "%s/%s", dir, name);
}

/* ------------------------------------------------------------------ the pieces */

static double film_units(double v)
{
    return v * (double)(1u << FILM_FRAC_BITS);
}

static void test_error_formula(void)
{
    AdaptiveFilm af;
    Error err = { 0 };
    CHECK(adaptive_film_init(&af, 2, 1, &err) == ST_OK);
    /* pixel 0: 4 samples summing to (4, 2, 0), the odd ones to (1, 1.5, 0): the even
     * ones (3, 0.5, 0); sum |E - O| = 2 + 1 = 3, over n = 0.75; sqrt(6 / 4) */
    double all[3] = { 4.0, 2.0, 0.0 }, odd[3] = { 1.0, 1.5, 0.0 };
    for (int c = 0; c < 3; c++) {
        af.film.sum[c] = (int64_t)film_units(all[c]);
        af.odd[c] = (int64_t)film_units(odd[c]);
    }
    af.spp[0] = 4;
    af.film.samples = 4;
    CHECK_NEAR(adaptive_pixel_error(&af, 0), 0.75 / (1e-4 + sqrt(1.5)), 1e-15);
    /* halves alike: no error; no samples: none either */
    for (int c = 0; c < 3; c++) af.film.sum[3 + c] = 2 * (af.odd[3 + c] = (int64_t)film_units(0.25 * (c + 1)));
    af.spp[1] = 4;
    CHECK(adaptive_pixel_error(&af, 1) == 0.0);
    af.spp[1] = 0;
    CHECK(adaptive_pixel_error(&af, 1) == 0.0);
    adaptive_film_free(&af);
}

static void test_decision_counts(void)
{
    AdaptiveSettings s = { 0.01, 16 };
    CHECK(adaptive_decides_at(&s, 16));
    CHECK(!adaptive_decides_at(&s, 17) && !adaptive_decides_at(&s, 18) && !adaptive_decides_at(&s, 8));
    /* 4, 5 or 6 times a power of two: a fifth to a third more each */
    uint want[] = { 20, 24, 32, 40, 48, 64, 80, 96, 128 };
    uint at = 16;
    for (size_t i = 0; i < sizeof want / sizeof *want; i++) {
        at = adaptive_next_stop(&s, at, 1000);
        CHECK_EQ_INT(at, want[i]);
        CHECK(adaptive_decides_at(&s, at));
    }
    CHECK_EQ_INT(adaptive_next_stop(&s, 0, 1000), 16);
    CHECK_EQ_INT(adaptive_next_stop(&s, 17, 1000), 20);   /* a grown render's odd count */
    CHECK_EQ_INT(adaptive_next_stop(&s, 600, 1000), 640);
    CHECK_EQ_INT(adaptive_next_stop(&s, 640, 1000), 768);
    CHECK_EQ_INT(adaptive_next_stop(&s, 20, 22), 22);     /* capped at the render's spp */
    CHECK_EQ_INT(adaptive_next_stop(&s, 0, 10), 10);
    AdaptiveSettings odd = { 0.01, 5 };   /* rounded up to even: the halves hold as many */
    CHECK_EQ_INT(adaptive_next_stop(&odd, 0, 100), 6);
    CHECK_EQ_INT(adaptive_next_stop(&odd, 6, 100), 8);
}

/* A 5x4 film at a decision count (16) with one pixel that stopped before (spp 12) and
 * one noisy pixel. A decision judges the mean error of each 3x3 block (fewer pixels at
 * the image's edges) or half the pixel's own, the larger: an estimate 1.5 times the
 * threshold among quiet neighbours is outvoted, and nothing goes on; one eight times
 * above it goes on, with the blocks its error lifts above the threshold, and the 3x3
 * around each of those (the widening), nothing else. */
static void test_mask(void)
{
    AdaptiveFilm af;
    Error err = { 0 };
    CHECK(adaptive_film_init(&af, 5, 4, &err) == ST_OK);
    AdaptiveSettings s = { 0.05, 16 };
    af.film.samples = 16;
    for (size_t i = 0; i < 20; i++) {
        af.spp[i] = 16;
        for (int c = 0; c < 3; c++) af.odd[3 * i + c] = (af.film.sum[3 * i + c] = (int64_t)film_units(8.0)) / 2;
    }
    af.spp[2] = 12;                             /* (2, 0): stopped at 12 */
    uint mask[20];
    size_t active = 0;
    /* (2, 1): halves 4.75 and 3.25 in red, error 0.077 (half: 0.038); the blocks
     * holding it have 6 pixels (along the top edge) or 9: means 0.013 or less */
    af.odd[3 * 7] = (int64_t)film_units(3.25);
    CHECK_NEAR(adaptive_pixel_error(&af, 7), 0.09375 / (1e-4 + sqrt(1.5)), 1e-12);
    CHECK(adaptive_mask(&s, &af, mask, &active, &err) == ST_OK);
    CHECK_EQ_INT(active, 0);
    /* (1, 1) instead: halves 8 and 0, error 0.408 (half: 0.204): it goes on; the
     * blocks holding it have 4, 6 or 9 pixels, means 0.102, 0.068 (above) and 0.045
     * (below: (2, 1), (1, 2), (2, 2)); with the widening, columns 0-1 and the
     * neighbours of (1, 1) and (0, 2) */
    af.odd[3 * 7] = (int64_t)film_units(4.0);
    af.odd[3 * 6] = 0;
    CHECK(adaptive_mask(&s, &af, mask, &active, &err) == ST_OK);
    uint want[20] = { 1, 1, 0, 0, 0,  1, 1, 1, 0, 0,  1, 1, 1, 0, 0,  1, 1, 0, 0, 0 };
    for (size_t i = 0; i < 20; i++) CHECK_MSG(mask[i] == want[i], "pixel %zu", i);
    CHECK_EQ_INT(active, 10);
    /* between decisions every pixel at the count goes on, and only those */
    af.film.samples = 18;
    for (size_t i = 0; i < 20; i++) af.spp[i] = i == 2 ? 12u : 18u;
    CHECK(adaptive_mask(&s, &af, mask, &active, &err) == ST_OK);
    CHECK_EQ_INT(active, 19);
    CHECK(mask[2] == 0 && mask[0] == 1);
    adaptive_film_free(&af);
}

/* ------------------------------------------------------------------ whole renders */

/* Renders the scene at the threshold with extra arguments into `out` (and `ckpt`
 * when not NULL). */
static int render_at(const char *threshold, const char *out, const char *ckpt, const char *const *extra)
{
    const char *args[40];
    int n = 0;
    const char *base[] = { scene_path, "-q", "-o", out, "--noise-threshold", threshold };
    for (size_t i = 0; i < sizeof base / sizeof *base; i++) args[n++] = base[i];
    if (ckpt) {
        args[n++] = "--checkpoint";
        args[n++] = ckpt;
    }
    for (; *extra && n < 38; extra++) args[n++] = *extra;
    args[n] = NULL;
    cli_run(args, &r);
    if (r.status != 0) fprintf(stderr, "  clpt said: %s\n", r.err);
    return r.status;
}

static int render(const char *out, const char *ckpt, const char *const *extra)
{
    return render_at("0.05", out, ckpt, extra);
}

/* Converged pixels (the sky) stop at the minimum; the noisy floor goes on to the end. */
static void test_converged_stop(void)
{
    char out[128], ck[128];
    path_in_dir(out, sizeof out, "stop.pfm");
    path_in_dir(ck, sizeof ck, "stop.ckpt");
    CHECK(render_at("0.01", out, ck, ARGS("--device", "cpu")) == 0);
    Checkpoint c;
    Error err = { 0 };
    CHECK(checkpoint_read(ck, &c, &err) == ST_OK);
    if (!c.pixel_spp) {
        CHECK_MSG(0, "no adaptive state: %s", err.msg);
        checkpoint_free(&c);
        return;
    }
    uint w = c.film.width, h = c.film.height;
    size_t sky_min = 0, floor_more = 0, floor_max = 0, floor = 0;
    for (uint y = 0; y < h; y++)
        for (uint x = 0; x < w; x++) {
            uint n = c.pixel_spp[(size_t)y * w + x];
            if (y < h / 2 - 2) sky_min += n == 16;
            if (y > h / 2 + 2) {
                floor++;
                floor_more += n > 16;
                floor_max += n == 256;
            }
        }
    fprintf(stderr, "  sky pixels at 16 spp: %zu of %u; floor pixels past 16: %zu, at 256: %zu, of %zu\n",
            sky_min, w * (h / 2 - 2), floor_more, floor_max, floor);
    CHECK_EQ_INT(sky_min, w * (h / 2 - 2));
    CHECK(floor_more * 2 > floor);
    CHECK(floor_max > 0);
    CHECK_EQ_INT(c.film.samples, 256);
    checkpoint_free(&c);
}

/* The same bytes on every device mix, batch size, launch and after a resume. */
static void test_same_bits(void)
{
    char ref[128], out[128], ck[128];
    path_in_dir(ref, sizeof ref, "ref.pfm");
    path_in_dir(out, sizeof out, "out.pfm");
    path_in_dir(ck, sizeof ck, "part.ckpt");
    CHECK(render(ref, NULL, ARGS("--device", "scalar")) == 0);
    static const char *const runs[][6] = {
        { "--device", "cpu", NULL },
        { "--device", "cpu,scalar", "--batch", "3", NULL },
        { "--device", "cpu", "--wave-launch", "counted", NULL },
        { "--device", "scalar", "--batch", "1", NULL },
    };
    for (size_t i = 0; i < sizeof runs / sizeof *runs; i++) {
        unlink(out);
        CHECK(render(out, NULL, runs[i]) == 0);
        CHECK_MSG(files_equal(ref, out), "run %zu (%s %s %s)", i, runs[i][1], runs[i][2] ? runs[i][2] : "",
                  runs[i][3] ? runs[i][3] : "");
    }
    /* 50 spp (no decision count: its last round is cut short) on PoCL, then grown to
     * 256 on PoCL and the scalar device together */
    unlink(ck);
    CHECK(render(out, ck, ARGS("--device", "cpu", "--spp", "50")) == 0);
    unlink(out);
    CHECK(render(out, NULL, ARGS("--device", "cpu,scalar", "--resume", ck)) == 0);
    CHECK_MSG(files_equal(ref, out), "resumed from 50 spp");
    /* a resume must keep the settings that decided */
    CHECK(render(out, NULL, ARGS("--device", "scalar", "--resume", ck, "--min-spp", "8")) == 3);
    CHECK_STR_CONTAINS(r.err, "is an adaptive render with --noise-threshold 0.05 --min-spp 16, this render asks "
                              "for --noise-threshold 0.05 --min-spp 8; resume it with its settings");
}

/* The Cornell box's plain diffuse triangles take PoCL's eight-paths-per-work-item
 * kernel (k_path_lanes): its masked lanes too give the scalar device's bits. */
static void test_same_bits_lanes(void)
{
    char a[128], b[128];
    path_in_dir(a, sizeof a, "box-scalar.pfm");
    path_in_dir(b, sizeof b, "box-cpu.pfm");
    const char *args_a[] = { "scenes/cornell-box.scene", "-q", "--width", "40", "--height", "30", "--spp", "64",
                             "--noise-threshold", "0.05", "--device", "scalar", "-o", a, NULL };
    cli_run(args_a, &r);
    CHECK_EQ_INT(r.status, 0);
    const char *args_b[] = { "scenes/cornell-box.scene", "-q", "--width", "40", "--height", "30", "--spp", "64",
                             "--noise-threshold", "0.05", "--device", "cpu", "-o", b, "--stats", NULL };
    cli_run(args_b, &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_STR_CONTAINS(r.out, "k_path_lanes");
    CHECK_STR_CONTAINS(r.out, "each pixel its own count (--noise-threshold)");
    CHECK(files_equal(a, b));
}

/* The film of a checkpoint resolved: uniform (film_resolve) or adaptive. */
static float *checkpoint_image(const char *path, uint *w, uint *h, uint64_t *pixel_samples)
{
    Checkpoint c;
    Error err = { 0 };
    if (checkpoint_read(path, &c, &err) != ST_OK) {
        fprintf(stderr, "  %s\n", err.msg);
        checkpoint_free(&c);
        return NULL;
    }
    *w = c.film.width;
    *h = c.film.height;
    size_t n = (size_t)*w * *h;
    float *rgb = malloc(n * 3u * sizeof *rgb);
    *pixel_samples = 0;
    if (c.pixel_spp) {
        AdaptiveFilm af = { c.film, c.odd, c.pixel_spp };
        adaptive_film_resolve(&af, rgb);
        for (size_t i = 0; i < n; i++) *pixel_samples += c.pixel_spp[i];
    } else {
        film_resolve(&c.film, rgb);
        *pixel_samples = c.film.samples * n;
    }
    checkpoint_free(&c);
    return rgb;
}

static double rmse(const float *a, const float *b, size_t n)
{
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) sum += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return sqrt(sum / (double)n);
}

/* With as many samples in all, adaptive sampling puts them where the noise is: its
 * error against a converged reference is lower than uniform sampling's. */
static void test_equal_budget_error(void)
{
    char ref[128], ad[128], un[128], img[128];
    path_in_dir(ref, sizeof ref, "ref2048.ckpt");
    path_in_dir(ad, sizeof ad, "adaptive.ckpt");
    path_in_dir(un, sizeof un, "uniform.ckpt");
    path_in_dir(img, sizeof img, "img.pfm");
    const char *args_ref[] = { scene_path, "-q", "-o", img, "--spp", "2048", "--device", "cpu", "--seed", "7",
                               "--checkpoint", ref, NULL };
    cli_run(args_ref, &r);
    CHECK_EQ_INT(r.status, 0);
    /* 0.03: about 30 samples a pixel; at 0.05 nearly every pixel stops at the first
     * decision (16), 18 on average, and there is little left to place */
    CHECK(render_at("0.03", img, ad, ARGS("--device", "cpu", "--spp", "512")) == 0);
    uint w, h;
    uint64_t n_ref, n_ad, n_un;
    float *a = checkpoint_image(ad, &w, &h, &n_ad);
    char spp[32];
    uint64_t n_pixels = (uint64_t)w * h;
    snprintf(spp, sizeof spp, "%llu", (unsigned long long)((n_ad + n_pixels - 1) / n_pixels));
    const char *args_un[] = { scene_path, "-q", "-o", img, "--spp", spp, "--device", "cpu", "--checkpoint", un, NULL };
    cli_run(args_un, &r);
    CHECK_EQ_INT(r.status, 0);
    float *reference = checkpoint_image(ref, &w, &h, &n_ref), *u = checkpoint_image(un, &w, &h, &n_un);
    if (a && u && reference) {
        double ea = rmse(a, reference, (size_t)w * h * 3u), eu = rmse(u, reference, (size_t)w * h * 3u);
        fprintf(stderr, "  %llu pixel samples adaptive, %llu uniform (%s spp): RMSE %.5f against %.5f (%.2fx)\n",
                (unsigned long long)n_ad, (unsigned long long)n_un, spp, ea, eu, eu / ea);
        CHECK(n_un >= n_ad);
        CHECK(ea < 0.8 * eu);
    } else {
        CHECK(a && u && reference);
    }
    free(a);
    free(u);
    free(reference);
}

static void test_refusals(void)
{
    char out[128];
    path_in_dir(out, sizeof out, "refused.png");
    cli_run(ARGS(scene_path, "-o", out, "--noise-threshold", "0"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --noise-threshold expects a threshold in (0, 1], got '0'");
    cli_run(ARGS(scene_path, "-o", out, "--min-spp", "8"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--min-spp sets the samples before --noise-threshold stops a pixel; give both, or "
                              "neither");
    cli_run(ARGS(scene_path, "-o", out, "--noise-threshold", "0.1", "--sample-range", "0:8"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--noise-threshold cannot be used with --sample-range (its decisions need the whole "
                              "render)");
    cli_run(ARGS(scene_path, "-o", out, "--noise-threshold", "0.1", "--integrator", "whitted"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--noise-threshold needs the path tracer (--integrator path); the whitted integrator "
                              "has --adaptive");
    CHECK(!file_exists(out));
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/clpt-test-adaptive-XXXXXX");
    if (!mkdtemp(dir)) perror("mkdtemp");
    path_in_dir(scene_path, sizeof scene_path, "easy-hard.scene");
    FILE *f = fopen(scene_path, "w");
    if (f) {
        fputs(scene_text, f);
        fclose(f);
    }
    RUN(test_error_formula);
    RUN(test_decision_counts);
    RUN(test_mask);
    RUN(test_refusals);
    RUN(test_converged_stop);
    RUN(test_same_bits);
    RUN(test_same_bits_lanes);
    RUN(test_equal_budget_error);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return harness_report();
}
