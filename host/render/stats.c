/* stats.c — see stats.h. */
#include "render/stats.h"

#include <stdio.h>

void render_stats_print_scene(const Scene *s, const RenderScene *rs)
{
    const KdStats *k = &rs->kd.stats;
    size_t in_tree = s->n_spheres + s->n_triangles + s->n_boxes + s->n_revsurfaces;
    printf("scene: %zu spheres, %zu triangles, %zu boxes, %zu planes, %zu materials, %zu lights", s->n_spheres,
           s->n_triangles, s->n_boxes, s->n_planes, s->n_materials, s->n_lights);
    /* only when there are any: the line's form stays what scripts read for other scenes */
    if (s->n_revsurfaces) printf(", %zu surfaces of revolution", s->n_revsurfaces);
    printf("\n");
    size_t images = 0, rgbe = 0;
    for (size_t i = 0; i < s->n_textures; i++) {
        images += s->textures[i].type == TEX_IMAGE;
        rgbe += s->textures[i].type == TEX_IMAGE && (s->textures[i].flags & TEX_RGBE);
    }
    if (images)
        printf("textures: %zu images, %.1f KiB of texels, %zu of them packed as RGBE words\n", images,
               (double)s->n_texels * sizeof(uint) / 1024.0, rgbe);
    double per = in_tree ? 1.0 / (double)in_tree : 0.0;
    if (s->accel == ACCEL_BVH) {
        const BvhStats *b = &rs->bvh.stats;
        size_t bytes = (size_t)rs->bvh.n_nodes * sizeof(BvhNode) + (size_t)rs->bvh.n_leaf_prims * sizeof(uint);
        printf("BVH: built in %.3f s; %u nodes of 8, %u leaves, depth %u (binary tree %u), %.2f primitives "
               "per leaf, SAH cost %.2f, %.1f KiB (%.1f bytes per primitive)\n",
               b->build_seconds, b->n_nodes, b->n_leaves, b->max_depth, b->max_binary_depth,
               b->mean_prims_per_leaf, b->sah_cost, (double)bytes / 1024.0, (double)bytes * per);
        return;
    }
    printf("kd-tree: built in %.3f s; %u nodes, %u leaves (%u empty), depth %u, "
           "%.2f primitives per non-empty leaf, SAH cost %.2f, %.1f KiB (nodes and leaf ids %.1f, copies "
           "of the triangles' corners in the leaves %.1f bytes per primitive)\n",
           k->build_seconds, k->n_nodes, k->n_leaves, k->n_empty_leaves, k->max_depth,
           k->mean_prims_per_leaf, k->sah_cost, (double)k->bytes / 1024.0,
           (double)(k->bytes - k->bytes_corners) * per, (double)k->bytes_corners * per);
}

void render_stats_print_run(const ScheduleStats *st, uint spp, Device **devs, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        const DeviceCounters *c = &devs[i]->counters;
        if (devs[i]->desc.kind == DEVICE_OPENCL)
            printf("device %zu '%s': kernels %s in %.3f s, scene upload %.3f s; waves of %u paths, %s\n", i,
                   devs[i]->desc.name, c->from_cache ? "loaded from cache" : "compiled", c->compile_seconds,
                   c->upload_seconds, c->wave_paths, c->wave_run ? c->wave_run : "-");
    }
    printf("%-32s %7s %12s %8s %8s %12s %10s %6s %s\n", "device", "batches", "samples", "busy s",
           "idle s", "Msamples/s", "Mrays/s", "share", "batch sizes (min/max/last spp)");
    for (size_t i = 0; i < st->n_devices && st->devices; i++) {
        const DeviceRunStats *d = &st->devices[i];
        double busy = d->busy_seconds > 0.0 ? d->busy_seconds : 1e-9;
        printf("%-32.32s %7u %12llu %8.2f %8.2f %12.3f %10.3f %5.1f%% %u/%u/%u%s%s\n", d->name, d->batches,
               (unsigned long long)d->samples, d->busy_seconds, d->idle_seconds, (double)d->samples / busy / 1e6,
               (double)d->rays / busy / 1e6,
               st->samples ? 100.0 * (double)d->samples / (double)st->samples : 0.0, d->batch_min, d->batch_max,
               d->batch_last, d->failed ? "  FAILED: " : "", d->failed ? d->failure : "");
    }
    double secs = st->seconds > 0.0 ? st->seconds : 1e-9;
    printf("%-32s %7s %12llu %8.2f %8s %12.3f %10.3f %5.1f%%\n", "total", "",
           (unsigned long long)st->samples, st->seconds, "", (double)st->samples / secs / 1e6,
           (double)st->rays / secs / 1e6, 100.0);
    /* Batches cover the whole image, so every pixel holds the same samples. */
    printf("film: %u of %u samples per pixel, the same in every pixel; sample indices", st->spp_done, spp);
    for (size_t i = 0; i < st->done.n && i < 8; i++)
        printf(" [%u,%u)", st->done.ranges[i].first, st->done.ranges[i].first + st->done.ranges[i].count);
    printf("%s%s\n", st->done.n > 8 ? " ..." : "", st->done.n == 0 ? " none" : "");
    if (st->checkpoints)
        printf("checkpoints: %u written during the render, %.1f ms each (film copied under the lock in %.2f ms)\n",
               st->checkpoints, 1e3 * st->checkpoint_seconds / st->checkpoints, 1e3 * st->snapshot_seconds / st->checkpoints);
}

void render_stats_print_profile(const ScheduleStats *st, Device **devs, size_t n)
{
    static const char *const names[PHASE_N] = { "raygen", "traverse", "shade", "shadow", "film", "queues",
                                                "host wait" };
    printf("profile (seconds, %% of busy time; OpenCL: device time of its commands, scalar: thread time / threads)\n");
    printf("%-32s", "device");
    for (int p = 0; p < PHASE_N; p++) printf(" %15s", names[p]);
    printf(" %8s\n", "busy s");
    for (size_t i = 0; i < n && i < st->n_devices && st->devices; i++) {
        const double *t = devs[i]->counters.phase_seconds;
        double busy = st->devices[i].busy_seconds > 0.0 ? st->devices[i].busy_seconds : 1e-9;
        printf("%-32.32s", devs[i]->desc.name);
        for (int p = 0; p < PHASE_N; p++) printf(" %8.3f %5.1f%%", t[p], 100.0 * t[p] / busy);
        printf(" %8.2f\n", st->devices[i].busy_seconds);
    }
}
