/*
 * main.c — command line → scene → kd-tree → devices → render → image → exit code.
 *
 * The whole life of a render reads top to bottom in run(). Errors travel up as Status
 * values with their message in one Error, printed once here; the status is the exit code.
 */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/checkpoint.h"
#include "io/classic_parse.h"
#include "device/device.h"
#include "render/film.h"
#include "io/image_write.h"
#include "base/limit.h"
#include "io/mesh.h"
#include "io/mesh_view.h"
#include "options.h"
#include "render/passes.h"
#include "base/progress.h"
#include "render/render_scene.h"
#include "scene/scene.h"
#include "render/schedule.h"
#include "base/timer.h"

#define CLPT_VERSION "0.1.0"

static volatile sig_atomic_t stop_requested;

static void on_stop_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

static void install_signal_handlers(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

typedef struct {
    const char *output;
    int quiet;
    int progressive_failed;
    ImageEncoding encoding;
    const char *checkpoint;       /* NULL: none */
    CheckpointId checkpoint_id;
    int checkpoint_failed;
} RenderContext;

static void print_warning(void *ctx, const char *msg)
{
    (void)ctx;
    fprintf(stderr, "\r\033[Kclpt: warning: %s\n", msg);
}

static Status write_film(const Film *film, const char *path, ImageEncoding encoding, Error *err)
{
    size_t n = (size_t)film->width * film->height * 3u;
    float *rgb = malloc(n * sizeof *rgb);
    if (!rgb) return error_set(err, ST_INTERNAL, "out of memory resolving the image");
    film_resolve(film, rgb);
    Status st = image_write_encoded(path, rgb, film->width, film->height, encoding, err);
    free(rgb);
    return st;
}

/* Progressive output: rewrites the image during the render (atomically, so a viewer
 * never sees half a file). A failure is reported once and does not stop the render. */
static void on_progress_tick(void *vctx, const ScheduleSnapshot *snap)
{
    RenderContext *ctx = vctx;
    Error err = { 0 };
    if (write_film(snap->film, ctx->output, ctx->encoding, &err) != ST_OK && !ctx->progressive_failed) {
        ctx->progressive_failed = 1;
        print_warning(NULL, err.msg);
    }
    error_clear(&err);
}

/* Periodic checkpoints; a failure is reported once (the next one may succeed) and does
 * not stop the render. */
static void on_checkpoint(void *vctx, const ScheduleSnapshot *snap)
{
    RenderContext *ctx = vctx;
    Error err = { 0 };
    if (checkpoint_write(ctx->checkpoint, &ctx->checkpoint_id, snap->film, snap->done, snap->n_done, &err) != ST_OK &&
        !ctx->checkpoint_failed) {
        ctx->checkpoint_failed = 1;
        print_warning(NULL, err.msg);
    }
    error_clear(&err);
}

/* --resume: the checkpoint, checked against this render, becomes the film's start. */
static Status resume_film(const char *path, const CheckpointId *id, Checkpoint *ck, Film *film, int quiet, Error *err)
{
    Status st = checkpoint_read(path, ck, err);
    if (st == ST_OK) st = checkpoint_check(ck, path, id, err);
    if (st != ST_OK) return st;
    memcpy(film->sum, ck->film.sum, (size_t)film->width * film->height * 3u * sizeof *film->sum);
    film->samples = ck->film.samples;
    if (!quiet)
        fprintf(stderr, "clpt: resuming from '%s': %llu of %u samples per pixel already done\n", path,
                (unsigned long long)film->samples, id->spp);
    return ST_OK;
}

/* Output name when -o is not given: the scene's file name with .png, in the current
 * folder. */
static char *default_output(const char *scene_path)
{
    const char *base = strrchr(scene_path, '/');
    base = base ? base + 1 : scene_path;
    size_t n = strlen(base);
    const char *dot = strrchr(base, '.');
    if (dot && dot != base) n = (size_t)(dot - base);
    char *out = malloc(n + 5);
    if (out) {
        memcpy(out, base, n);
        memcpy(out + n, ".png", 5);
    }
    return out;
}

static void apply_overrides(const Options *o, Scene *s)
{
    if (o->spp >= 0) s->image.spp = (uint)o->spp;
    if (o->width >= 0) s->image.width = (uint)o->width;
    if (o->height >= 0) s->image.height = (uint)o->height;
    if (o->seed >= 0) s->image.seed = (uint)o->seed;
    if (o->max_depth >= 0) s->image.max_depth = (uint)o->max_depth;
    if (o->integrator >= 0) s->integrator = (uint)o->integrator;
    if (o->gamma >= 0) s->linear_output = o->gamma == 1;
}

/* The adaptive pass and the auxiliary images, after the main image is in rgb (and
 * written). A failure here is the run's failure; the main image stays written. */
static Status run_passes(const Options *o, const PassContext *pc, const char *output, ImageEncoding encoding,
                         float *rgb, uint spp, Error *err)
{
    uint w = pc->rs->ds.params.width, h = pc->rs->ds.params.height;
    Status st = ST_OK;
    if (o->adaptive > 0.0) {
        size_t marked = 0;
        double secs = 0.0;
        if ((st = passes_adaptive(pc, rgb, spp, (float)o->adaptive, o->adaptive_spp, &marked, &secs, err)))
            return st;
        if ((st = image_write_encoded(output, rgb, w, h, encoding, err))) return st;
        if (!o->quiet)
            fprintf(stderr, "clpt: adaptive pass: %zu of %u pixels (%.1f%%) got %u more samples in %.2f s -> %s\n",
                    marked, w * h, 100.0 * (double)marked / ((double)w * h), o->adaptive_spp, secs, output);
    }
    for (unsigned aov = INTEGRATOR_AOV_NORMAL; aov <= INTEGRATOR_AOV_ALBEDO; aov++) {
        if (!(o->aovs & (1u << aov))) continue;
        char *path = passes_aov_path(output, options_aov_name(aov));
        if (!path) return error_set(err, ST_INTERNAL, "out of memory");
        ImageFormat fmt = IMAGE_PNG;
        image_format_from_path(path, &fmt, err);
        double secs = 0.0;
        DepthScale depth = { fmt == IMAGE_PFM ? DEPTH_RAW : (o->depth_far > 0.0 ? DEPTH_RANGE : DEPTH_AUTO),
                             o->depth_near, o->depth_far };
        st = passes_aov(pc, aov, spp, &depth, rgb, &secs, err);
        /* auxiliary images hold data, not light: no sRGB curve */
        if (!st) st = image_write_encoded(path, rgb, w, h, IMAGE_LINEAR, err);
        if (!st && !o->quiet)
            fprintf(stderr, "clpt: %s image in %.2f s -> %s\n", options_aov_name(aov), secs, path);
        free(path);
        if (st) return st;
    }
    return ST_OK;
}

static void print_scene_stats(const Scene *s, const KdTree *kd)
{
    const KdStats *k = &kd->stats;
    size_t in_tree = s->n_spheres + s->n_triangles + s->n_boxes;
    printf("scene: %zu spheres, %zu triangles, %zu boxes, %zu planes, %zu materials, %zu lights\n",
           s->n_spheres, s->n_triangles, s->n_boxes, s->n_planes, s->n_materials, s->n_lights);
    double per = in_tree ? 1.0 / (double)in_tree : 0.0;
    printf("kd-tree: built in %.3f s; %u nodes, %u leaves (%u empty), depth %u, "
           "%.2f primitives per non-empty leaf, SAH cost %.2f, %.1f KiB (nodes and leaf ids %.1f, copies "
           "of the triangles' corners in the leaves %.1f bytes per primitive)\n",
           k->build_seconds, k->n_nodes, k->n_leaves, k->n_empty_leaves, k->max_depth,
           k->mean_prims_per_leaf, k->sah_cost, (double)k->bytes / 1024.0,
           (double)(k->bytes - k->bytes_corners) * per, (double)k->bytes_corners * per);
}

static void print_render_stats(const ScheduleStats *st, uint spp, Device **devs, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        const DeviceCounters *c = &devs[i]->counters;
        if (devs[i]->desc.kind == DEVICE_OPENCL)
            printf("device %zu '%s': kernels %s in %.3f s, scene upload %.3f s\n", i, devs[i]->desc.name,
                   c->from_cache ? "loaded from cache" : "compiled", c->compile_seconds, c->upload_seconds);
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

/* No device of the default choice could be used: warns, and replaces *chosen with the
 * next group of the default order; 0 when none is left. */
static int fall_back(const DeviceDesc *all, size_t n_all, size_t **chosen, size_t *n_chosen, const Error *last)
{
    size_t *next = NULL, n_next = 0;
    Error err = { 0 };
    if (device_select_fallback(all, n_all, (*chosen)[0], &next, &n_next, &err) != ST_OK || n_next == 0) {
        free(next);
        error_clear(&err);
        return 0;
    }
    if (*n_chosen == 1) {   /* several were each reported as they were dropped */
        print_warning(NULL, last->msg);
        if (last->detail) fprintf(stderr, "%s\n", last->detail);
    }
    fprintf(stderr, "clpt: warning: the default device%s cannot be used; falling back to device %u '%s'%s\n",
            *n_chosen > 1 ? "s" : "", all[next[0]].index, all[next[0]].name, n_next > 1 ? " and others" : "");
    free(*chosen);
    *chosen = next;
    *n_chosen = n_next;
    return 1;
}

/* Opens the chosen devices and gives each the scene. A device that fails is dropped with
 * a warning as long as another one works. */
static Status open_devices(const Options *o, const DeviceScene *ds, Device ***out, size_t *n_out, Error *err)
{
    DeviceDesc *all = NULL;
    size_t n_all = 0, *chosen = NULL, n_chosen = 0;
    char warning[1100];
    Status st = device_list(&all, &n_all, warning, sizeof warning, err);
    if (st) return st;
    if (warning[0]) print_warning(NULL, warning);
    if ((st = device_select(o->device_spec, all, n_all, &chosen, &n_chosen, err))) {
        free(all);
        return st;
    }
    Device **devs = calloc(n_all, sizeof *devs);
    if (!devs) {
        free(all);
        free(chosen);
        return error_set(err, ST_INTERNAL, "out of memory");
    }
    DeviceConfig cfg = { o->threads, o->kernel_dir, o->wave_paths };
    size_t n = 0;
    Error last = { 0 };
try_chosen:
    for (size_t i = 0; i < n_chosen; i++) {
        Device *d = NULL;
        error_clear(&last);
        st = device_open(&all[chosen[i]], &cfg, &d, &last);
        if (st == ST_OK) st = d->ops->load_scene(d, ds, &last);
        if (st == ST_OK) {
            devs[n++] = d;
            continue;
        }
        device_close(d);
        if (n_chosen > 1) {
            print_warning(NULL, last.msg);
            if (last.detail) fprintf(stderr, "%s\n", last.detail);
            fprintf(stderr, "clpt: warning: device %u '%s' dropped; rendering with the others\n",
                    all[chosen[i]].index, all[chosen[i]].name);
        }
    }
    if (n == 0 && (!o->device_spec || !o->device_spec[0]) && fall_back(all, n_all, &chosen, &n_chosen, &last))
        goto try_chosen;
    free(all);
    free(chosen);
    if (n == 0) {
        free(devs);
        if (n_chosen == 1) {
            *err = last;   /* the one device's own error, with its build log */
            return last.status ? last.status : ST_DEVICE;
        }
        error_clear(&last);
        return error_set(err, ST_DEVICE, "none of the %zu chosen devices could be used", n_chosen);
    }
    error_clear(&last);
    *out = devs;
    *n_out = n;
    return ST_OK;
}

static Status run(int argc, char **argv, Error *err)
{
    Options o;
    Status st = options_parse(argc, argv, &o, err);
    if (st) return st;
    if (o.help) {
        options_print_help(stdout);
        return ST_OK;
    }
    if (o.version) {
        printf("clpt %s\n", CLPT_VERSION);
        return ST_OK;
    }
    if (o.list_devices) {
        DeviceDesc *all = NULL;
        size_t n = 0;
        char warning[1100];
        if ((st = device_list(&all, &n, warning, sizeof warning, err))) return st;
        if (warning[0]) print_warning(NULL, warning);
        device_list_print(stdout, all, n);
        free(all);
        return ST_OK;
    }

    char *default_out = NULL;
    const char *output = o.output;
    if (!output && !(output = default_out = default_output(o.scene_path)))
        return error_set(err, ST_INTERNAL, "out of memory");
    ImageFormat format;
    Scene scene;
    scene_init(&scene);
    RenderScene rs;
    memset(&rs, 0, sizeof rs);
    Film film;
    memset(&film, 0, sizeof film);
    Device **devs = NULL;
    size_t n_devs = 0;
    ScheduleStats stats;
    memset(&stats, 0, sizeof stats);
    Checkpoint resume;
    memset(&resume, 0, sizeof resume);
    RenderContext ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.output = output;
    ctx.quiet = o.quiet;
    ctx.checkpoint = o.checkpoint_path;
    double t_start = timer_now();

    if ((st = image_format_from_path(output, &format, err))) goto done;
    /* a mesh file given in place of a scene is shown in a scene made around it */
    int bare_mesh = mesh_kind(o.scene_path) != MESH_NONE;
    if ((st = bare_mesh ? mesh_view_load(o.scene_path, &scene, err)
                        : scene_load_format(o.scene_path, (SceneFormat)o.format, &scene, err)))
        goto done;
    apply_overrides(&o, &scene);
    if ((o.width >= 0 || o.height >= 0) &&
        (st = limit_pixels(scene.image.width, scene.image.height, ST_USAGE, "--width/--height", err)))
        goto done;
    if (bare_mesh) mesh_view_fit(&scene);
    if (o.adaptive > 0.0 && scene.integrator != INTEGRATOR_WHITTED) {
        st = error_set(err, ST_USAGE, "--adaptive needs the whitted integrator (--integrator whitted)");
        goto done;
    }
    ImageEncoding encoding = scene.linear_output ? IMAGE_LINEAR : IMAGE_SRGB;
    if ((st = render_scene_prepare(&scene, 0, &rs, err))) goto done;
    const DeviceScene *ds = &rs.ds;
    if (o.stats) print_scene_stats(&scene, &rs.kd);
    checkpoint_id(ds, scene.image.spp, &ctx.checkpoint_id);
    if ((st = film_init(&film, ds->params.width, ds->params.height, err))) goto done;
    if (o.resume_path && (st = resume_film(o.resume_path, &ctx.checkpoint_id, &resume, &film, o.quiet, err)))
        goto done;

    if ((st = open_devices(&o, ds, &devs, &n_devs, err))) goto done;

    install_signal_handlers();
    ctx.encoding = encoding;
    ScheduleConfig cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = scene.image.spp;
    cfg.done = resume.done;
    cfg.n_done = resume.n_done;
    cfg.on_checkpoint = o.checkpoint_path ? on_checkpoint : NULL;
    cfg.checkpoint_seconds = o.checkpoint_seconds;
    cfg.time_limit = o.time_limit;
    cfg.fixed_batch = o.batch;
    cfg.show_progress = progress_should_enable(o.quiet);
    cfg.stop = &stop_requested;
    cfg.on_tick = o.progressive_seconds > 0.0 ? on_progress_tick : NULL;
    cfg.tick_seconds = o.progressive_seconds;
    cfg.on_warning = print_warning;
    cfg.ctx = &ctx;
    Status render_st = schedule_run(devs, n_devs, &cfg, &film, &stats, err);
    if (render_st != ST_OK && film.samples == 0) {
        st = render_st;
        goto done;
    }
    /* Whatever was finished is written, also after an interrupt or device failures. */
    Error werr = { 0 };
    if ((st = write_film(&film, output, encoding, &werr))) {
        if (render_st == ST_OK) {
            *err = werr;
        } else {
            fprintf(stderr, "clpt: error: %s\n", werr.msg);
            error_clear(&werr);
            st = render_st;
        }
        goto done;
    }
    /* The last checkpoint holds everything finished: after an interrupt or a failure it
     * is what a resume starts from, so failing to write it then is an error. */
    if (o.checkpoint_path && film.samples > 0) {
        Error cerr = { 0 };
        Status cst = batch_set_total(&stats.done) == film.samples
                         ? checkpoint_write(o.checkpoint_path, &ctx.checkpoint_id, &film, stats.done.ranges,
                                            stats.done.n, &cerr)
                         : error_set(&cerr, ST_INTERNAL, "the record of finished samples is incomplete; "
                                                         "no final checkpoint written");
        if (cst != ST_OK) {
            int complete = render_st == ST_OK && !stats.interrupted && !stats.time_up;
            if (complete) {
                print_warning(NULL, cerr.msg);
            } else {
                fprintf(stderr, "clpt: error: %s\n", cerr.msg);
                if (render_st == ST_OK && !stats.interrupted) render_st = cst;
            }
        }
        error_clear(&cerr);
    }
    if (o.stats) print_render_stats(&stats, scene.image.spp, devs, n_devs);
    if (!o.quiet || render_st != ST_OK || stats.interrupted) {
        double secs = stats.seconds > 0.0 ? stats.seconds : 1e-9;
        fprintf(stderr, "clpt: %s %ux%u, %llu spp%s in %.2f s (%.2f s total): %.3f Msamples/s, %.3f Mrays/s -> %s\n",
                stats.interrupted ? "interrupted:" : (stats.time_up ? "time limit reached:" : "rendered"),
                film.width, film.height, (unsigned long long)film.samples,
                film.samples < scene.image.spp ? " (partial)" : "", stats.seconds, timer_now() - t_start,
                (double)stats.samples / secs / 1e6, (double)stats.rays / secs / 1e6, output);
    }
    st = render_st != ST_OK ? render_st : (stats.interrupted ? ST_INTERRUPTED : ST_OK);
    if (st == ST_OK && (o.adaptive > 0.0 || o.aovs)) {
        size_t n = (size_t)film.width * film.height * 3u;
        float *rgb = malloc(n * sizeof *rgb);
        if (!rgb) {
            st = error_set(err, ST_INTERNAL, "out of memory");
            goto done;
        }
        film_resolve(&film, rgb);
        ScheduleConfig pcfg = cfg;
        pcfg.show_progress = 0;
        PassContext pc = { devs, n_devs, &rs, &pcfg };
        st = run_passes(&o, &pc, output, encoding, rgb, (uint)film.samples, err);
        free(rgb);
        if (st == ST_OK && stop_requested) st = ST_INTERRUPTED;
    }

done:
    schedule_stats_free(&stats);
    for (size_t i = 0; i < n_devs; i++) device_close(devs[i]);
    free(devs);
    film_free(&film);
    checkpoint_free(&resume);
    render_scene_free(&rs);
    scene_free(&scene);
    free(default_out);
    return st;
}

int main(int argc, char **argv)
{
    Error err = { 0 };
    Status st = run(argc, argv, &err);
    if (st != ST_OK && st != ST_INTERRUPTED) {
        error_print(&err);
        if (st == ST_USAGE) fprintf(stderr, "Try 'clpt --help' for more information.\n");
    }
    error_clear(&err);
    return (int)st;
}
