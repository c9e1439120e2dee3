/*
 * bench_render.c — rendering throughput of the shipped scenes on every device.
 *
 *   build/bench/bench_render [--reps N] [--json FILE] [--accel bvh|kdtree] [SCENE:WIDTHxHEIGHT:SPP ...]
 *
 * For each scene, every device (each OpenCL device alone, and the scalar device) renders
 * the scene with a fixed seed in `reps` rounds, the devices in turns within a round, and
 * it reports the median samples/s and rays/s and the median of the rounds' ratios to the
 * scalar device (so that a busy spell of a shared machine hits both sides), plus the tree's
 * build time (the BVH, or the kd-tree with --accel kdtree) and the kernel build/cache-load
 * time. Prints a table and writes JSON.
 * Machines here are shared and noisy: read medians and ratios, not single times.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "device/device.h"
#include "render/film.h"
#include "render/render_scene.h"
#include "render/schedule.h"
#include "base/timer.h"

#include "bench_util.h"

typedef struct {
    const char *path;
    uint width, height, spp;
} BenchScene;

static const BenchScene default_scenes[] = {
    { "scenes/cornell-box.scene", 512, 512, 16 },
    { "scenes/one-weekend.scene", 400, 225, 16 },
    { "scenes/mesh.scene", 320, 320, 16 },
    { "scenes/envmap.scene", 480, 270, 16 },
};

typedef struct {
    double samples_per_s, rays_per_s, compile_s;
    double ratio;                /* median over the rounds of samples/s over the scalar device's */
    int from_cache, ok;
} Result;

#define MAX_REPS 32

/* One device's runs of a scene: samples/s and rays/s of each round. */
typedef struct {
    Device *dev;
    double sps[MAX_REPS], rps[MAX_REPS];
    int n;
} DeviceRuns;

static int device_start(const DeviceDesc *desc, const RenderScene *rs, DeviceRuns *dr, Result *res)
{
    Error err = { 0 };
    memset(dr, 0, sizeof *dr);
    if (device_open(desc, NULL, &dr->dev, &err) || dr->dev->ops->load_scene(dr->dev, &rs->ds, &err)) {
        fprintf(stderr, "bench: %s: %s\n", desc->name, err.msg);
        device_close(dr->dev);
        dr->dev = NULL;
        error_clear(&err);
        return -1;
    }
    res->compile_s = dr->dev->counters.compile_seconds;
    res->from_cache = dr->dev->counters.from_cache;
    return 0;
}

/* One render of the scene on the device; a failure closes it. */
static void device_round(const DeviceDesc *desc, const RenderScene *rs, uint spp, DeviceRuns *dr)
{
    Error err = { 0 };
    Film film;
    ScheduleConfig cfg;
    ScheduleStats st;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = spp;
    if (film_init(&film, rs->ds.params.width, rs->ds.params.height, &err)) {
        fprintf(stderr, "bench: %s\n", err.msg);
        error_clear(&err);
        return;
    }
    Device *dev = dr->dev;
    uint64_t rays0 = dev->counters.rays, samples0 = dev->counters.samples;
    double t0 = timer_now();
    Status s = schedule_run(&dev, 1, &cfg, &film, &st, &err);
    double secs = timer_now() - t0;
    schedule_stats_free(&st);
    film_free(&film);
    if (s) {
        fprintf(stderr, "bench: %s: %s\n", desc->name, err.msg);
        error_clear(&err);
        device_close(dr->dev);
        dr->dev = NULL;
        return;
    }
    dr->sps[dr->n] = (double)(dev->counters.samples - samples0) / secs;
    dr->rps[dr->n] = (double)(dev->counters.rays - rays0) / secs;
    dr->n++;
}

/* Every device renders the scene `reps` times, the devices in turns within each round
 * (a busy spell of the machine then slows them alike): medians of samples/s and rays/s,
 * and the median of each round's ratio to the scalar device (the last one). */
static void bench_devices(const DeviceDesc *all, size_t n_all, const RenderScene *rs, uint spp, int reps, Result *res)
{
    DeviceRuns *dr = calloc(n_all, sizeof *dr);
    if (!dr) return;
    for (size_t k = 0; k < n_all; k++) device_start(&all[k], rs, &dr[k], &res[k]);
    for (int r = 0; r < reps; r++)
        for (size_t k = n_all; k-- > 0;)
            if (dr[k].dev) device_round(&all[k], rs, spp, &dr[k]);
    /* the rounds' ratios first: bench_median() sorts its array in place, which would part
     * the rounds of the two sides */
    const DeviceRuns *ref = &dr[n_all - 1];
    int have_ref = ref->dev && ref->n == reps;
    for (size_t k = 0; k < n_all; k++) {
        if (!dr[k].dev || dr[k].n < reps || !have_ref) continue;
        double ratio[MAX_REPS];
        for (int r = 0; r < reps; r++) ratio[r] = dr[k].sps[r] / ref->sps[r];
        res[k].ratio = bench_median(ratio, reps);
    }
    for (size_t k = 0; k < n_all; k++) {
        if (!dr[k].dev || dr[k].n < reps) continue;
        res[k].samples_per_s = bench_median(dr[k].sps, reps);
        res[k].rays_per_s = bench_median(dr[k].rps, reps);
        res[k].ok = 1;
    }
    for (size_t k = 0; k < n_all; k++) device_close(dr[k].dev);
    free(dr);
}

int main(int argc, char **argv)
{
    int reps = 3;
    const char *json_path = "build/bench/render.json";
    BenchScene scenes[16];
    int n_scenes = 0;
    uint accel = ACCEL_BVH;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--accel") == 0 && i + 1 < argc) accel = strcmp(argv[++i], "kdtree") == 0 ? ACCEL_KDTREE : ACCEL_BVH;
        else if (strcmp(argv[i], "--json") == 0 && i + 1 < argc) json_path = argv[++i];
        else if (n_scenes < 16) {
            static char paths[16][512];
            unsigned w, h, spp;
            if (sscanf(argv[i], "%511[^:]:%ux%u:%u", paths[n_scenes], &w, &h, &spp) != 4) {
                fprintf(stderr, "usage: bench_render [--reps N] [--json FILE] [--accel bvh|kdtree] "
                        "[SCENE:WIDTHxHEIGHT:SPP ...]\n");
                return 2;
            }
            scenes[n_scenes] = (BenchScene){ paths[n_scenes], w, h, spp };
            n_scenes++;
        }
    }
    if (reps < 1) reps = 1;
    if (reps > MAX_REPS) reps = MAX_REPS;
    if (n_scenes == 0) {
        n_scenes = (int)(sizeof default_scenes / sizeof default_scenes[0]);
        memcpy(scenes, default_scenes, sizeof default_scenes);
    }

    DeviceDesc *all = NULL;
    size_t n_all = 0;
    char warning[1100];
    Error err = { 0 };
    if (device_list(&all, &n_all, warning, sizeof warning, &err)) {
        fprintf(stderr, "bench: %s\n", err.msg);
        return 1;
    }
    FILE *json = fopen(json_path, "w");
    if (json) fprintf(json, "{\n  \"reps\": %d,\n  \"results\": [\n", reps);
    printf("clpt render benchmark: %d rounds, the devices in turns in each; medians; ratio = median of the rounds' "
           "samples/s over the scalar device's\n\n", reps);
    printf("%-28s %-36s %12s %10s %7s %10s %s\n", "scene", "device", "Msamples/s", "Mrays/s", "ratio",
           "kernels s", accel == ACCEL_KDTREE ? "kd-tree" : "BVH");
    int first_json = 1;
    for (int si = 0; si < n_scenes; si++) {
        Scene scene;
        scene_init(&scene);
        RenderScene rs;
        if (scene_load(scenes[si].path, &scene, &err)) {
            fprintf(stderr, "bench: %s\n", err.msg);
            error_clear(&err);
            scene_free(&scene);
            continue;
        }
        scene.image.width = scenes[si].width;
        scene.image.height = scenes[si].height;
        scene.accel = accel;
        if (render_scene_prepare(&scene, 0, &rs, &err)) {
            fprintf(stderr, "bench: %s\n", err.msg);
            error_clear(&err);
            scene_free(&scene);
            continue;
        }
        Result *res = calloc(n_all, sizeof *res);
        bench_devices(all, n_all, &rs, scenes[si].spp, reps, res);
        double tree_s = accel == ACCEL_KDTREE ? rs.kd.stats.build_seconds : rs.bvh.stats.build_seconds;
        double sah = accel == ACCEL_KDTREE ? rs.kd.stats.sah_cost : rs.bvh.stats.sah_cost;
        char label[64];
        snprintf(label, sizeof label, "%s %ux%u", strrchr(scenes[si].path, '/') ? strrchr(scenes[si].path, '/') + 1
                                                                                : scenes[si].path,
                 scenes[si].width, scenes[si].height);
        for (size_t k = 0; k < n_all; k++) {
            if (!res[k].ok) continue;
            char kern[32] = "-";
            if (all[k].kind == DEVICE_OPENCL)
                snprintf(kern, sizeof kern, "%.3f%s", res[k].compile_s, res[k].from_cache ? " (cache)" : "");
            printf("%-28.28s %-36.36s %12.3f %10.3f %6.2fx %10s %.3f s, SAH %.1f\n", label,
                   all[k].kind == DEVICE_SCALAR ? "scalar (all cores)" : all[k].name, res[k].samples_per_s / 1e6,
                   res[k].rays_per_s / 1e6, res[k].ratio, kern,
                   tree_s, sah);
            if (json) {
                fprintf(json, "%s    {\"scene\": \"%s\", \"width\": %u, \"height\": %u, \"spp\": %u, \"device\": \"%s\", "
                              "\"kind\": \"%s\", \"samples_per_s\": %.1f, \"rays_per_s\": %.1f, \"ratio_to_scalar\": %.4f, "
                              "\"kernel_build_s\": %.4f, \"kernel_from_cache\": %d, \"tree\": \"%s\", \"tree_build_s\": %.4f, "
                              "\"sah_cost\": %.3f}",
                        first_json ? "" : ",\n", scenes[si].path, scenes[si].width, scenes[si].height, scenes[si].spp,
                        all[k].name, all[k].kind == DEVICE_SCALAR ? "scalar" : "opencl", res[k].samples_per_s,
                        res[k].rays_per_s, res[k].ratio, res[k].compile_s,
                        res[k].from_cache, accel == ACCEL_KDTREE ? "kdtree" : "bvh", tree_s, sah);
                first_json = 0;
            }
        }
        free(res);
        render_scene_free(&rs);
        scene_free(&scene);
    }
    if (json) {
        fprintf(json, "\n  ]\n}\n");
        fclose(json);
        printf("\nJSON: %s\n", json_path);
    }
    free(all);
    return 0;
}
