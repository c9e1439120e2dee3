/* stats.c — see stats.h. */
#include "render/stats.h"

#include <stdio.h>
#include <string.h>

/* The instancing line (docs/instancing.md): triangles stored once and as many times
 * as the instances place them, and the memory of each level on the devices. */
static void print_instances(FILE *out, const Scene *s, const RenderScene *rs)
{
    if (!rs->instanced) return;
    size_t in_objects = 0;
    double instanced = 0.0;
    for (size_t i = 0; i < s->n_objects; i++) in_objects += s->objects[i].end[OBJ_TRIANGLES] - s->objects[i].first[OBJ_TRIANGLES];
    for (size_t i = 0; i < s->n_instances; i++) {
        const SceneObject *o = &s->objects[s->instance_objects[i]];
        instanced += (double)(o->end[OBJ_TRIANGLES] - o->first[OBJ_TRIANGLES]);
    }
    const BvhLevels *lv = &rs->levels;
    double top = (double)lv->top_nodes * sizeof(BvhTopNode) + (double)rs->n_instances * sizeof(Instance);
    double protos = (double)lv->proto_nodes * sizeof(BvhNode) + (double)lv->proto_leaf_words * sizeof(uint);
    fprintf(out, "instances: %zu of %zu objects; triangles: %zu unique (%zu in objects), %.0f instanced "
           "(%.0f with the world's)\n", s->n_instances, s->n_objects, s->n_triangles, in_objects, instanced,
           instanced + (double)(s->n_triangles - in_objects));
    if (s->accel == ACCEL_KDTREE) {
        /* the prototypes are kd-trees (accel/kd_inst.h): their walk has its own stack */
        const KdProtoStats *kp = &rs->kd_levels;
        fprintf(out, "levels: top %u nodes and %zu instance records, %.1f KiB (%.1f bytes per instance); "
               "prototypes %u of %zu built as kd-trees, %u nodes and %.1f KiB of leaves, %.1f KiB; stack %u of %u, "
               "kd depth %u of %u\n",
               lv->top_nodes, rs->n_instances, top / 1024.0, rs->n_instances ? top / (double)rs->n_instances : 0.0,
               kp->n_protos_built, s->n_objects + 1, kp->n_nodes, (double)kp->n_leaf_words * 4.0 / 1024.0,
               (double)kp->bytes / 1024.0, lv->top.max_stack, BVH_STACK, kp->max_depth, KD_MAX_DEPTH - 1u);
        return;
    }
    fprintf(out, "levels: top %u nodes and %zu instance records, %.1f KiB (%.1f bytes per instance); "
           "prototypes %u of %zu built, %u nodes and %.1f KiB of leaves, %.1f KiB; stack %u + 1 + %u of %u\n",
           lv->top_nodes, rs->n_instances, top / 1024.0, rs->n_instances ? top / (double)rs->n_instances : 0.0,
           lv->n_protos_built, s->n_objects + 1, lv->proto_nodes, (double)lv->proto_leaf_words * 4.0 / 1024.0,
           protos / 1024.0, lv->top.max_stack, lv->max_proto_stack, BVH_STACK);
}

void render_stats_print_scene(FILE *out, const Scene *s, const RenderScene *rs)
{
    const KdStats *k = &rs->kd.stats;
    size_t in_tree = s->n_spheres + s->n_triangles + s->n_boxes + s->n_revsurfaces;
    fprintf(out, "scene: %zu spheres, %zu triangles, %zu boxes, %zu planes, %zu materials, %zu lights", s->n_spheres,
           s->n_triangles, s->n_boxes, s->n_planes, s->n_materials, s->n_lights);
    /* only when there are any: the line's form stays what scripts read for other scenes */
    if (s->n_revsurfaces) fprintf(out, ", %zu surfaces of revolution", s->n_revsurfaces);
    fprintf(out, "\n");
    size_t images = 0, rgbe = 0;
    for (size_t i = 0; i < s->n_textures; i++) {
        images += s->textures[i].type == TEX_IMAGE;
        rgbe += s->textures[i].type == TEX_IMAGE && (s->textures[i].flags & TEX_RGBE);
    }
    if (images)
        fprintf(out, "textures: %zu images, %.1f KiB of texels, %zu of them packed as RGBE words\n", images,
               (double)s->n_texels * sizeof(uint) / 1024.0, rgbe);
    double per = in_tree ? 1.0 / (double)in_tree : 0.0;
    if (s->accel == ACCEL_BVH) {
        const BvhStats *b = &rs->bvh.stats;
        size_t bytes = (size_t)rs->bvh.n_nodes * sizeof(BvhNode) + (size_t)rs->bvh.n_top * sizeof(BvhTopNode) +
                       (size_t)rs->bvh.n_leaf_prims * sizeof(uint);
        fprintf(out, "BVH: built in %.3f s; %u nodes of 8, %u leaves, depth %u (binary tree %u), %.2f primitives "
               "per leaf, SAH cost %.2f, %.1f KiB (%.1f bytes per primitive)\n",
               b->build_seconds, b->n_nodes, b->n_leaves, b->max_depth, b->max_binary_depth,
               b->mean_prims_per_leaf, b->sah_cost, (double)bytes / 1024.0, (double)bytes * per);
        print_instances(out, s, rs);
        return;
    }
    if (rs->instanced) {
        /* the prototypes' trees (accel/kd_inst.h): each its own SAH cost, so none here */
        fprintf(out, "kd-tree: prototypes' trees built in %.3f s; %u nodes, %u leaves (%u empty), deepest %u, "
               "%.2f primitives per non-empty leaf, %.1f KiB (nodes and leaf ids %.1f, copies of the triangles' "
               "corners in the leaves %.1f bytes per primitive stored)\n",
               k->build_seconds, k->n_nodes, k->n_leaves, k->n_empty_leaves, k->max_depth, k->mean_prims_per_leaf,
               (double)k->bytes / 1024.0, (double)(k->bytes - k->bytes_corners) * per, (double)k->bytes_corners * per);
        print_instances(out, s, rs);
        return;
    }
    fprintf(out, "kd-tree: built in %.3f s; %u nodes, %u leaves (%u empty), depth %u, "
           "%.2f primitives per non-empty leaf, SAH cost %.2f, %.1f KiB (nodes and leaf ids %.1f, copies "
           "of the triangles' corners in the leaves %.1f bytes per primitive)\n",
           k->build_seconds, k->n_nodes, k->n_leaves, k->n_empty_leaves, k->max_depth,
           k->mean_prims_per_leaf, k->sah_cost, (double)k->bytes / 1024.0,
           (double)(k->bytes - k->bytes_corners) * per, (double)k->bytes_corners * per);
    print_instances(out, s, rs);
}

void render_stats_print_run(FILE *out, const ScheduleStats *st, uint spp, Device **devs, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        const DeviceCounters *c = &devs[i]->counters;
        if (devs[i]->desc.kind == DEVICE_OPENCL) {
            char in_place[64] = "";
            if (c->bytes_in_place)
                snprintf(in_place, sizeof in_place, " (%.1f MiB of it used in place)",
                         (double)c->bytes_in_place / 1048576.0);
            fprintf(out, "device %zu '%s': kernels %s in %.3f s, scene upload %.3f s%s; waves of %u paths, %s\n", i,
                   devs[i]->desc.name, c->from_cache ? "loaded from cache" : "compiled", c->compile_seconds,
                   c->upload_seconds, in_place, c->wave_paths, c->wave_run ? c->wave_run : "-");
        } else if (c->kernel_build)
            fprintf(out, "device %zu '%s': kernels of its '%s' build, the leanest with the scene's features\n", i,
                    devs[i]->desc.name, c->kernel_build);
    }
    fprintf(out, "%-32s %7s %12s %8s %8s %12s %10s %6s %s\n", "device", "batches", "samples", "busy s",
           "idle s", "Msamples/s", "Mrays/s", "share", "batch sizes (min/max/last spp)");
    for (size_t i = 0; i < st->n_devices && st->devices; i++) {
        const DeviceRunStats *d = &st->devices[i];
        double busy = d->busy_seconds > 0.0 ? d->busy_seconds : 1e-9;
        fprintf(out, "%-32.32s %7u %12llu %8.2f %8.2f %12.3f %10.3f %5.1f%% %u/%u/%u%s%s\n", d->name, d->batches,
               (unsigned long long)d->samples, d->busy_seconds, d->idle_seconds, (double)d->samples / busy / 1e6,
               (double)d->rays / busy / 1e6,
               st->samples ? 100.0 * (double)d->samples / (double)st->samples : 0.0, d->batch_min, d->batch_max,
               d->batch_last, d->failed ? "  FAILED: " : "", d->failed ? d->failure : "");
    }
    double secs = st->seconds > 0.0 ? st->seconds : 1e-9;
    fprintf(out, "%-32s %7s %12llu %8.2f %8s %12.3f %10.3f %5.1f%%\n", "total", "",
           (unsigned long long)st->samples, st->seconds, "", (double)st->samples / secs / 1e6,
           (double)st->rays / secs / 1e6, 100.0);
    /* Batches cover the whole image, so every pixel holds the same samples. */
    if (st->adaptive)
        fprintf(out, "film: up to %u of %u samples per pixel, each pixel its own count (--noise-threshold); sample "
                "indices", st->spp_done, spp);
    else
        fprintf(out, "film: %u of %u samples per pixel, the same in every pixel; sample indices", st->spp_done, spp);
    for (size_t i = 0; i < st->done.n && i < 8; i++)
        fprintf(out, " [%u,%u)", st->done.ranges[i].first, st->done.ranges[i].first + st->done.ranges[i].count);
    fprintf(out, "%s%s\n", st->done.n > 8 ? " ..." : "", st->done.n == 0 ? " none" : "");
    if (st->checkpoints)
        fprintf(out, "checkpoints: %u written during the render, %.1f ms each (film copied under the lock in %.2f ms)\n",
               st->checkpoints, 1e3 * st->checkpoint_seconds / st->checkpoints, 1e3 * st->snapshot_seconds / st->checkpoints);
}

void render_stats_print_profile(FILE *out, const ScheduleStats *st, Device **devs, size_t n)
{
    static const char *const names[PHASE_N] = { "raygen", "traverse", "shade", "shadow", "film", "queues",
                                                "host wait" };
    fprintf(out, "profile (seconds, %% of busy time; OpenCL: device time of its commands, scalar: thread time / threads)\n");
    fprintf(out, "%-32s", "device");
    for (int p = 0; p < PHASE_N; p++) fprintf(out, " %15s", names[p]);
    fprintf(out, " %8s\n", "busy s");
    for (size_t i = 0; i < n && i < st->n_devices && st->devices; i++) {
        const double *t = devs[i]->counters.phase_seconds;
        double busy = st->devices[i].busy_seconds > 0.0 ? st->devices[i].busy_seconds : 1e-9;
        fprintf(out, "%-32.32s", devs[i]->desc.name);
        for (int p = 0; p < PHASE_N; p++) fprintf(out, " %8.3f %5.1f%%", t[p], 100.0 * t[p] / busy);
        fprintf(out, " %8.2f\n", st->devices[i].busy_seconds);
    }
}

/* ------------------------------------------------------------------ --stats=json */

/* A JSON string: quotes, backslashes and control characters escaped (a scene's or a
 * device's name may hold any of them). */
static void json_string(FILE *out, const char *v)
{
    fputc('"', out);
    for (const unsigned char *p = (const unsigned char *)(v ? v : ""); *p; p++) {
        if (*p == '"' || *p == '\\') fprintf(out, "\\%c", *p);
        else if (*p < 0x20) fprintf(out, "\\u%04x", *p);
        else fputc(*p, out);
    }
    fputc('"', out);
}

/* A rate that stays a JSON number when nothing was timed. */
static double per_second(double amount, double seconds)
{
    return seconds > 0.0 ? amount / seconds : 0.0;
}

static void json_devices(FILE *out, const ScheduleStats *st)
{
    fprintf(out, "\"devices\":[");
    for (size_t i = 0; i < st->n_devices && st->devices; i++) {
        const DeviceRunStats *d = &st->devices[i];
        fprintf(out, "%s{\"name\":", i ? "," : "");
        json_string(out, d->name);
        fprintf(out, ",\"batches\":%u,\"samples\":%llu,\"rays\":%llu,\"busy_seconds\":%.6f,\"idle_seconds\":%.6f,"
                "\"share\":%.6f,\"failed\":%s", d->batches, (unsigned long long)d->samples,
                (unsigned long long)d->rays, d->busy_seconds, d->idle_seconds,
                st->samples ? (double)d->samples / (double)st->samples : 0.0, d->failed ? "true" : "false");
        if (d->failed) {
            fprintf(out, ",\"failure\":");
            json_string(out, d->failure);
        }
        fputc('}', out);
    }
    fputc(']', out);
}

/* A candidate's error x rays over split 1's. */
static double pilot_ratio(const SplitPilot *sp, uint i)
{
    double one = sp->error[0] * (double)sp->rays[0];
    return one > 0.0 ? sp->error[i] * (double)sp->rays[i] / one : 0.0;
}

void render_stats_print_split(FILE *out, const SplitPilot *sp, uint scene_split)
{
    if (scene_split != SCENE_SPLIT_AUTO) {
        fprintf(out, "split: %u, as asked\n", sp->chosen);
        return;
    }
    if (!sp->ran) {
        fprintf(out, sp->pixels ? "split: 1 (auto: the pilot was interrupted)\n"
                                : "split: 1 (auto without a pilot: an image under 256x256, or a camera in a medium)\n");
        return;
    }
    fprintf(out, "split: %u, chosen by a pilot of %u pixels x %u spp in %.2f s (error x rays against split 1,",
            sp->chosen, sp->pixels, sp->spp, sp->seconds);
    fprintf(out, " measured:");
    for (uint i = 1; i < sp->measured; i++) fprintf(out, "%s %u %.3f", i > 1 ? "," : "", sp->split[i], pilot_ratio(sp, i));
    if (sp->fitted) {
        double one = split_model_cost(&sp->model, 1u);
        fprintf(out, "; fitted:");
        for (uint i = 1; i < SPLIT_PILOT_CANDIDATES; i++)
            fprintf(out, "%s %u %.3f", i > 1 ? "," : "", split_pilot_candidates[i],
                    one > 0.0 ? split_model_cost(&sp->model, split_pilot_candidates[i]) / one : 0.0);
    }
    fprintf(out, ")\n");
}

/* "split":{"chosen":2,"auto":true,"pilot":{"pixels":1024,"spp":16,"seconds":0.12,
 * "measured":[{"split":1,"error":..,"rays":..},...],"fitted":[{"split":1,"error_x_rays":..},...]}} */
static void json_split(FILE *out, const SplitPilot *sp, uint scene_split)
{
    fprintf(out, ",\"split\":{\"chosen\":%u,\"auto\":%s", sp->chosen, scene_split == SCENE_SPLIT_AUTO ? "true" : "false");
    if (sp->ran) {
        fprintf(out, ",\"pilot\":{\"pixels\":%u,\"spp\":%u,\"seconds\":%.6f,\"measured\":[", sp->pixels, sp->spp,
                sp->seconds);
        for (uint i = 0; i < sp->measured; i++)
            fprintf(out, "%s{\"split\":%u,\"error\":%.9g,\"rays\":%llu}", i ? "," : "", sp->split[i], sp->error[i],
                    (unsigned long long)sp->rays[i]);
        fprintf(out, "]");
        if (sp->fitted) {
            fprintf(out, ",\"fitted\":[");
            for (uint i = 0; i < SPLIT_PILOT_CANDIDATES; i++)
                fprintf(out, "%s{\"split\":%u,\"error_x_rays\":%.9g}", i ? "," : "", split_pilot_candidates[i],
                        split_model_cost(&sp->model, split_pilot_candidates[i]));
            fputc(']', out);
        }
        fprintf(out, "}");
    }
    fputc('}', out);
}

void render_stats_print_json(FILE *out, const RenderStatsRun *run, const Scene *s, const ScheduleStats *st)
{
    fprintf(out, "{\"clpt\":");
    json_string(out, run->version);
    fprintf(out, ",\"scene\":");
    json_string(out, run->scene_path);
    fprintf(out, ",\"output\":");
    json_string(out, run->output);
    fprintf(out, ",\"result\":");
    json_string(out, run->result);
    fprintf(out, ",\"width\":%u,\"height\":%u,\"spp\":%u,\"spp_done\":%u", run->width, run->height, run->spp,
            st->spp_done);
    fprintf(out, ",\"seconds\":%.6f,\"total_seconds\":%.6f,\"samples\":%llu,\"rays\":%llu", st->seconds,
            run->total_seconds, (unsigned long long)st->samples, (unsigned long long)st->rays);
    fprintf(out, ",\"msamples_per_second\":%.6f,\"mrays_per_second\":%.6f",
            per_second((double)st->samples / 1e6, st->seconds), per_second((double)st->rays / 1e6, st->seconds));
    fprintf(out, ",\"scene_contents\":{\"spheres\":%zu,\"triangles\":%zu,\"boxes\":%zu,\"planes\":%zu,"
            "\"materials\":%zu,\"lights\":%zu,\"textures\":%zu}", s->n_spheres, s->n_triangles, s->n_boxes,
            s->n_planes, s->n_materials, s->n_lights, s->n_textures);
    if (run->split && s->integrator == INTEGRATOR_PATH) json_split(out, run->split, s->image.split);
    fputc(',', out);
    json_devices(out, st);
    fprintf(out, "}\n");
}

const char *render_stats_result(const ScheduleStats *st)
{
    return st->interrupted ? "interrupted" : (st->time_up ? "time limit reached" : "rendered");
}

/* The samples per pixel in words: "16 spp", "12 spp (partial)", or an adaptive
 * render's "adaptive 16..256 spp (mean 41.2)". */
static void spp_words(const RenderJob *job, char *buf, size_t size)
{
    const AdaptiveFilm *af = &job->af;
    if (!job->adaptive) {
        snprintf(buf, size, "%llu spp%s", (unsigned long long)job->film.samples,
                 job->film.samples < job->scene->image.spp ? " (partial)" : "");
        return;
    }
    size_t n = (size_t)af->film.width * af->film.height;
    uint lo = af->spp[0], hi = af->spp[0];
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        lo = af->spp[i] < lo ? af->spp[i] : lo;
        hi = af->spp[i] > hi ? af->spp[i] : hi;
        sum += af->spp[i];
    }
    snprintf(buf, size, "adaptive %u..%u spp (mean %.1f)", lo, hi, sum / (double)n);
}

void render_stats_print_summary(FILE *out, const RenderJob *job, double total_seconds, const char *output)
{
    const ScheduleStats *s = &job->stats;
    const char *result = render_stats_result(s);
    double secs = s->seconds > 0.0 ? s->seconds : 1e-9;
    char words[96];
    spp_words(job, words, sizeof words);
    fprintf(out, "clpt: %s%s %ux%u, %s in %.2f s (%.2f s total): %.3f Msamples/s, %.3f Mrays/s -> %s\n", result,
            strcmp(result, "rendered") ? ":" : "", job->film.width, job->film.height, words, s->seconds,
            total_seconds, (double)s->samples / secs / 1e6, (double)s->rays / secs / 1e6, output);
}
