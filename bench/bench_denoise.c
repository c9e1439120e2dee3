/*
 * bench_denoise.c — time to a given error with --denoise and without (docs/denoise.md).
 *
 * For each scene: a converged reference (REF_SPP samples), then renders at rising spp
 * as they are and with --denoise, each timed whole (start-up, render, the feature
 * images and the denoiser: what a user waits for), and measured against the reference:
 * RMSE over the image, RMSE away from the emitters seen directly (a denoiser spreads a
 * lamp's edge; tests/image_metrics.h), and SSIM. The question asked: does 16 spp
 * denoised reach the error of 256 spp as rendered? Last, the denoiser alone on a
 * 1920x1080 image, wall and CPU time, colour alone and with prefiltered features.
 *
 * Usage: bench_denoise [BUILD]   (BUILD: the folder holding clpt; default build)
 *        bench_denoise --full-hd (the 1920x1080 timing alone)
 * Needs Open Image Denoise (sh tools/deps.sh oidn); scenes that read ../shared are
 * skipped, said, when it is missing. Minutes long on two cores.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "../tests/image_metrics.h"
#include "bench_util.h"
#include "base/timer.h"
#include "render/denoise.h"

#define REF_SPP "2048"
/* The reference's seed: another than the renders' (clpt's default), so that its samples
 * are not the first ones of every render measured against it. With the same seed a
 * 256-spp render is the first eighth of the 2048-spp reference's samples, and its RMSE
 * against it is about 11% below its RMSE against an independent reference (the dragon:
 * 0.00276 against 0.00309), while a 16-spp render, denoised or not, gains almost nothing. */
#define REF_SEED "777"

typedef struct {
    const char *name, *scene, *width, *height;
} BenchScene;

static const BenchScene scenes[] = {
    { "Cornell box", "scenes/cornell-box.scene", "192", "192" },
    { "materials", "scenes/materials.scene", "320", "180" },
    { "dragon", "../shared/peers/dragon.scene", "256", "256" },
};

static const char *build = "build";
static char tmpdir[] = "/tmp/clpt-bench-denoise-XXXXXX";

/* Runs clpt on the scene with spp samples (and --denoise, and the options in extra) into
 * out; the wall time, or -1 when it failed. */
static double run_clpt(const BenchScene *s, const char *spp, int denoise, const char *extra, const char *out)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "'%s/clpt' '%s' -q --width %s --height %s --spp %s %s %s -o '%s'", build, s->scene,
             s->width, s->height, spp, denoise ? "--denoise" : "", extra, out);
    double t0 = timer_now();
    int rc = system(cmd);
    double t = timer_now() - t0;
    if (rc != 0) fprintf(stderr, "bench_denoise: failed (%d): %s\n", rc, cmd);
    return rc == 0 ? t : -1.0;
}

typedef struct {
    float *ref;
    unsigned char *away;
    unsigned w, h;
} Reference;

static void bench_one(const BenchScene *s, const Reference *r, const char *spp, int denoise)
{
    char out[600];
    snprintf(out, sizeof out, "%s/%s-%s.pfm", tmpdir, spp, denoise ? "d" : "n");
    double t = run_clpt(s, spp, denoise, "", out);
    unsigned w = 0, h = 0;
    float *img = t >= 0.0 ? metrics_read_pfm(out, &w, &h) : NULL;
    if (!img || w != r->w || h != r->h) {
        free(img);
        return;
    }
    size_t n = (size_t)w * h;
    printf("| %s | %s%s | %.2f | %.5f | %.5f | %.4f | %s |\n", s->name, spp, denoise ? " + denoise" : "", t,
           metrics_rmse(img, r->ref, n), metrics_rmse_masked(img, r->ref, r->away, n), metrics_ssim(img, r->ref, w, h),
           metrics_all_finite(img, n) ? "yes" : "NO");
    free(img);
}

static void bench_scene(const BenchScene *s)
{
    struct stat st;
    if (stat(s->scene, &st) != 0) {
        printf("| %s | skipped: %s is missing | | | | | |\n", s->name, s->scene);
        return;
    }
    char ref_path[600];
    snprintf(ref_path, sizeof ref_path, "%s/ref.pfm", tmpdir);
    Reference r = { NULL, NULL, 0, 0 };
    if (run_clpt(s, REF_SPP, 0, "--seed " REF_SEED, ref_path) < 0.0 || !(r.ref = metrics_read_pfm(ref_path, &r.w, &r.h))) return;
    if (!(r.away = malloc((size_t)r.w * r.h))) return;
    metrics_emitter_mask(r.ref, r.w, r.h, 2.0f, 6, r.away);
    static const char *const plain[] = { "16", "64", "256" }, *const denoised[] = { "4", "16", "64" };
    for (int i = 0; i < 3; i++) bench_one(s, &r, plain[i], 0);
    for (int i = 0; i < 3; i++) bench_one(s, &r, denoised[i], 1);
    free(r.ref);
    free(r.away);
}

/* One denoise of the 1920x1080 image, with the features (prefiltered: three RT
 * filters) or the colour alone (one): wall and CPU seconds (OIDN's threads included,
 * which other jobs on the machine do not change). */
static void full_hd_once(Denoiser *d, float *c, const float *a, const float *nr, int features, Error *err)
{
    double t0 = timer_now(), c0 = bench_cpu_now();
    if (denoiser_run(d, c, features ? a : NULL, features ? nr : NULL, 1920, 1080, c, err) != ST_OK) return;
    printf("1920x1080, %s: %.2f s wall, %.2f CPU-s\n",
           features ? "albedo and normal prefiltered (three RT filters)" : "colour alone (one RT filter)",
           timer_now() - t0, bench_cpu_now() - c0);
}

/* The denoiser alone on a 1920x1080 image: its time does not depend on the content. */
static void bench_full_hd(void)
{
    const unsigned w = 1920, h = 1080;
    size_t n = (size_t)w * h * 3u;
    float *c = malloc(n * sizeof *c), *a = malloc(n * sizeof *a), *nr = malloc(n * sizeof *nr);
    Denoiser *d = NULL;
    Error err = { 0 };
    if (c && a && nr && denoiser_open(&d, &err) == ST_OK) {
        srand(1);
        for (size_t i = 0; i < n; i++) {
            c[i] = (float)rand() / (float)RAND_MAX;
            a[i] = 0.5f;
            nr[i] = i % 3 == 2 ? 1.0f : 0.0f;
        }
        printf("\nOIDN %s device, %s\n", denoiser_device_kind(d), denoiser_library(d));
        full_hd_once(d, c, a, nr, 0, &err);   /* the first also warms OIDN up */
        full_hd_once(d, c, a, nr, 1, &err);
        full_hd_once(d, c, a, nr, 0, &err);
    }
    if (err.msg[0] || !d) printf("\n1920x1080: not measured: %s\n", err.msg[0] ? err.msg : "out of memory");
    error_clear(&err);
    denoiser_close(d);
    free(c);
    free(a);
    free(nr);
}

int main(int argc, char **argv)
{
    int full_hd_only = argc > 1 && !strcmp(argv[1], "--full-hd");
    bench_print_load("at the start");
    if (full_hd_only) {
        bench_full_hd();
        return 0;
    }
    if (argc > 1) build = argv[1];
    if (!mkdtemp(tmpdir)) return 1;
    printf("Reference: %s spp, seed %s. Time: the whole clpt run (with --denoise: features and denoiser too).\n"
           "RMSE away: pixels more than 6 from a reference pixel brighter than 2 (the lamps).\n\n", REF_SPP, REF_SEED);
    printf("| scene | spp | time s | RMSE | RMSE away | SSIM | finite |\n|---|---|---|---|---|---|---|\n");
    fflush(stdout);
    for (size_t i = 0; i < sizeof scenes / sizeof *scenes; i++) {
        bench_scene(&scenes[i]);
        fflush(stdout);
    }
    bench_full_hd();
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : 1;
}
