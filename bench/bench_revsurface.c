/*
 * bench_revsurface.c — surfaces of revolution drawn exactly (Newton iteration in the
 * kernels, kernels/geom/revsurface.h) against the same surfaces as triangle meshes.
 *
 *   build/bench/bench_revsurface [--reps N] [--spp N] [--integrator whitted|path]
 *                                [--mesh STEPS AROUND] [SCENE]
 *
 * SCENE (default scenes/classic/vase.txt) is read twice: as it is, and with each of its
 * surfaces of revolution replaced by a mesh of STEPS rows per profile segment by AROUND
 * columns (default 16 x 96, what the reader makes of a surface whose axis a transform
 * tilts; curve_mesh_revsurface) with the exact surface's normals at its corners. On each
 * device (the scalar device, then every OpenCL device) the two are rendered in turns, N
 * times each (default 3), and the median render time of each is printed, with the
 * kd-tree build time, the primitive counts, and the mean and largest difference of the
 * two images (scalar device). Machines here are shared: the load average is printed
 * before and after, and only ratios within one run mean much.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/timer.h"
#include "device/device.h"
#include "io/scene_load.h"
#include "render/film.h"
#include "render/render_scene.h"
#include "render/schedule.h"
#include "scene/curve.h"

#include "bench_util.h"

/* Replaces every surface of revolution of s by its mesh. */
static Status to_mesh(Scene *s, unsigned steps, unsigned around, Error *err)
{
    for (size_t i = 0; i < s->n_revsurfaces; i++) {
        const RevSurface *r = &s->revsurfaces[i];
        Transform m = transform_translate(r->axis_x, 0.0, r->axis_z);
        Status st = curve_mesh_revsurface(s, s->rev_points + 2u * r->first, r->n_segments, r->degree, &m,
                                          r->material, steps, around, err);
        if (st) return st;
    }
    s->n_revsurfaces = 0;
    s->n_rev_points = 0;
    return ST_OK;
}

/* One render of rs on dev: seconds, and the image into rgb when not NULL. */
static double render_once(Device *dev, const RenderScene *rs, uint spp, float *rgb, Error *err)
{
    Film film;
    ScheduleConfig cfg;
    ScheduleStats st;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = spp;
    if (film_init(&film, rs->ds.params.width, rs->ds.params.height, err)) return -1.0;
    double t0 = timer_now();
    Status s = schedule_run(&dev, 1, &cfg, &film, &st, err);
    double secs = timer_now() - t0;
    schedule_stats_free(&st);
    if (!s && rgb) film_resolve(&film, rgb);
    film_free(&film);
    return s ? -1.0 : secs;
}

int main(int argc, char **argv)
{
    int reps = 3;
    uint spp = 0, steps = 16, around = 96, integrator = NO_INDEX;
    const char *path = "scenes/classic/vase.txt";
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--spp") == 0 && i + 1 < argc) spp = (uint)atoi(argv[++i]);
        else if (strcmp(argv[i], "--integrator") == 0 && i + 1 < argc)
            integrator = strcmp(argv[++i], "path") == 0 ? INTEGRATOR_PATH : INTEGRATOR_WHITTED;
        else if (strcmp(argv[i], "--mesh") == 0 && i + 2 < argc) {
            steps = (uint)atoi(argv[++i]);
            around = (uint)atoi(argv[++i]);
        } else if (argv[i][0] != '-') path = argv[i];
        else {
            fprintf(stderr, "usage: bench_revsurface [--reps N] [--spp N] [--integrator whitted|path] "
                            "[--mesh STEPS AROUND] [SCENE]\n");
            return 2;
        }
    }
    if (reps < 1) reps = 1;
    if (reps > 32) reps = 32;
    if (steps < 1 || around < 3) steps = 16, around = 96;

    Error err = { 0 };
    Scene sc[2];
    RenderScene rs[2];
    for (int k = 0; k < 2; k++) {
        scene_init(&sc[k]);
        if (scene_load_file(path, SCENE_FORMAT_AUTO, &sc[k], NULL, &err) || (k == 1 && to_mesh(&sc[k], steps, around, &err))) {
            fprintf(stderr, "bench_revsurface: %s\n", err.msg);
            return 1;
        }
        if (integrator != NO_INDEX) sc[k].integrator = integrator;
        if (spp) sc[k].image.spp = spp;
        if (render_scene_prepare(&sc[k], 0, &rs[k], &err)) {
            fprintf(stderr, "bench_revsurface: %s\n", err.msg);
            return 1;
        }
    }
    printf("%s, %ux%u, %u spp, %s; mesh %u x %u quads per segment; median of %d\n", path, sc[0].image.width,
           sc[0].image.height, sc[0].image.spp, sc[0].integrator == INTEGRATOR_PATH ? "path" : "whitted", steps,
           around, reps);
    printf("exact: %zu surfaces of revolution, %zu triangles, kd-tree %.3f s; mesh: %zu triangles, kd-tree %.3f s\n",
           sc[0].n_revsurfaces, sc[0].n_triangles, rs[0].kd.stats.build_seconds, sc[1].n_triangles,
           rs[1].kd.stats.build_seconds);
    bench_print_load("before");

    DeviceDesc *all = NULL;
    size_t n_all = 0;
    char warning[1100];
    if (device_list(&all, &n_all, warning, sizeof warning, &err)) {
        fprintf(stderr, "bench_revsurface: %s\n", err.msg);
        return 1;
    }
    size_t npx = (size_t)sc[0].image.width * sc[0].image.height * 3u;
    float *img[2] = { calloc(npx, sizeof(float)), calloc(npx, sizeof(float)) };
    for (size_t d = n_all; d-- > 0;) {
        Device *dev[2] = { NULL, NULL };
        double secs[2][32];
        int ok = 1;
        for (int k = 0; k < 2 && ok; k++)
            ok = !device_open(&all[d], NULL, &dev[k], &err) && !dev[k]->ops->load_scene(dev[k], &rs[k].ds, &err);
        for (int r = 0; r < reps && ok; r++)
            for (int k = 0; k < 2 && ok; k++) {
                int keep = all[d].kind == DEVICE_SCALAR && r == 0;
                secs[k][r] = render_once(dev[k], &rs[k], sc[k].image.spp, keep ? img[k] : NULL, &err);
                ok = secs[k][r] >= 0.0;
            }
        if (!ok) fprintf(stderr, "bench_revsurface: %s: %s\n", all[d].name, err.msg);
        else {
            double e = bench_median(secs[0], reps), m = bench_median(secs[1], reps);
            printf("%-40.40s exact %8.3f s   mesh %8.3f s   exact/mesh %.2f\n",
                   all[d].kind == DEVICE_SCALAR ? "scalar (all cores)" : all[d].name, e, m, e / m);
        }
        for (int k = 0; k < 2; k++) device_close(dev[k]);
        error_clear(&err);
    }
    double sum = 0.0, worst = 0.0;
    for (size_t i = 0; i < npx; i++) {
        double v = img[0][i] > img[1][i] ? img[0][i] - img[1][i] : img[1][i] - img[0][i];
        sum += v;
        if (v > worst) worst = v;
    }
    printf("images (scalar): mean |exact - mesh| %.5f, largest %.4f\n", sum / (double)npx, worst);
    bench_print_load("after");
    free(img[0]);
    free(img[1]);
    free(all);
    for (int k = 0; k < 2; k++) {
        render_scene_free(&rs[k]);
        scene_free(&sc[k]);
    }
    return 0;
}
