/*
 * api_render.c — clpt_render: the program's render (main.c) into the caller's memory.
 *
 * The same steps in the same order, so the image is the program's bits: the scene read
 * and the settings applied (scene_options.c), the scene prepared, the film (from a
 * checkpoint when resuming), the devices, the scheduler, then the final checkpoint, the
 * image resolved, and the passes after it (adaptive, auxiliary images).
 */
#include "api/api.h"

#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "render/checkpoint.h"
#include "render/film.h"
#include "render/passes.h"
#include "render/render_scene.h"
#include "render/schedule.h"

/* Everything one render holds, freed by render_free whatever step failed. */
typedef struct {
    clpt_context *ctx;
    Options o;
    Scene scene;
    RenderScene rs;
    Film film;
    Checkpoint resume;
    CheckpointId id;
    Device **devs;
    size_t n_devs;
    ScheduleConfig cfg;
    ScheduleStats stats;
    /* the progress callback and its cancel */
    clpt_progress_fn progress;
    void *user;
    volatile sig_atomic_t stop;
    unsigned pass_base, total;    /* samples per pixel of the passes before this one; of all */
    int checkpoint_failed;
} ApiRun;

static void render_free(ApiRun *r)
{
    schedule_stats_free(&r->stats);
    for (size_t i = 0; i < r->n_devs; i++) device_close(r->devs[i]);
    free(r->devs);
    film_free(&r->film);
    checkpoint_free(&r->resume);
    render_scene_free(&r->rs);
    scene_free(&r->scene);
}

/* The scheduler's poll: the caller's callback, whose non-zero answer stops the render. */
static void on_poll(void *vr, uint spp_done)
{
    ApiRun *r = vr;
    if (r->progress && r->progress(r->user, r->pass_base + spp_done, r->total)) r->stop = 1;
}

/* Periodic checkpoints: a failure is a warning, said once, as the program does. */
static void on_checkpoint(void *vr, const ScheduleSnapshot *snap)
{
    ApiRun *r = vr;
    Error err = { 0 };
    if (checkpoint_write(r->o.checkpoint_path, &r->id, snap->film, snap->done, snap->n_done, &err) != ST_OK &&
        !r->checkpoint_failed) {
        r->checkpoint_failed = 1;
        api_warn(r->ctx, err.msg);
    }
    error_clear(&err);
}

static int wants(const clpt_image *img, unsigned aov)
{
    return aov == INTEGRATOR_AOV_NORMAL ? img->normal != NULL
         : aov == INTEGRATOR_AOV_DEPTH ? img->depth != NULL : img->albedo != NULL;
}

/* The size of the image a render of s gives: its crop's window (--crop), else the
 * whole image. (A window that selects nothing is the whole image's size here, and
 * refused by the render, which says why.) */
static void render_image_size(const Scene *s, uint *w, uint *h)
{
    CropWindow win;
    int cropped = crop_window(&s->crop, s->image.width, s->image.height, &win);
    *w = cropped ? win.width : s->image.width;
    *h = cropped ? win.height : s->image.height;
}

/* The image's buffers against the render: its size, and a buffer for each --aov asked. */
static Status image_check(const ApiRun *r, const clpt_image *img, Error *err)
{
    uint w, h;
    render_image_size(&r->scene, &w, &h);
    if (!img || !img->rgb) return error_set(err, ST_USAGE, "clpt_render needs an image with an rgb buffer");
    if (img->width != w || img->height != h)
        return error_set(err, ST_USAGE, "the image is %ux%u, the render %ux%u (clpt_render_size)", img->width,
                         img->height, w, h);
    for (unsigned a = INTEGRATOR_AOV_NORMAL; a <= INTEGRATOR_AOV_ALBEDO; a++)
        if ((r->o.aovs & (1u << a)) && !wants(img, a))
            return error_set(err, ST_USAGE, "the settings ask for the %s image (aov), and the image has no %s buffer",
                             passes_aov_name(a), passes_aov_name(a));
    return ST_OK;
}

/* The scene prepared, the film (resumed from a checkpoint), and the devices. */
static Status render_prepare(ApiRun *r, Error *err)
{
    Status st;
    if ((st = render_scene_prepare(&r->scene, 0, &r->rs, err))) return st;
    if (r->o.checkpoint_path || r->o.resume_path) checkpoint_id(&r->rs.ds, r->scene.image.spp, &r->id);
    if ((st = film_init(&r->film, r->rs.ds.params.width, r->rs.ds.params.height, err))) return st;
    if (r->o.resume_path) {
        if ((st = checkpoint_read(r->o.resume_path, &r->resume, err))) return st;
        if ((st = checkpoint_check(&r->resume, r->o.resume_path, &r->id, err))) return st;
        memcpy(r->film.sum, r->resume.film.sum, (size_t)r->film.width * r->film.height * 3u * sizeof *r->film.sum);
        r->film.samples = r->resume.film.samples;
    }
    DeviceConfig dc = { r->o.threads, r->o.kernel_dir, r->o.wave_paths, 0, r->o.wave_launch };
    return device_open_all(r->ctx->device_spec, &dc, &r->rs.ds, api_warn, r->ctx, &r->devs, &r->n_devs, err);
}

static void render_configure(ApiRun *r)
{
    ScheduleConfig *cfg = &r->cfg;
    memset(cfg, 0, sizeof *cfg);
    cfg->spp = r->scene.image.spp;
    cfg->done = r->resume.done;
    cfg->n_done = r->resume.n_done;
    if (r->o.range_end >= 0) {
        cfg->range_first = (uint)r->o.range_first;
        cfg->range_end = (uint)r->o.range_end;
    }
    cfg->on_checkpoint = r->o.checkpoint_path ? on_checkpoint : NULL;
    cfg->checkpoint_seconds = r->o.checkpoint_seconds;
    cfg->time_limit = r->o.time_limit;
    cfg->fixed_batch = r->o.batch;
    cfg->stop = &r->stop;
    cfg->on_poll = on_poll;
    cfg->on_warning = api_warn;
    cfg->ctx = r;
}

/* The final checkpoint, before the image as in the program: after a cancel it is what
 * a resume starts from, and failing to write it is then the render's error. */
static Status write_checkpoint(ApiRun *r, Status render_st, Error *err)
{
    if (!r->o.checkpoint_path) return ST_OK;
    Error cerr = { 0 };
    Status st = batch_set_total(&r->stats.done) == r->film.samples
                    ? checkpoint_write(r->o.checkpoint_path, &r->id, &r->film, r->stats.done.ranges, r->stats.done.n,
                                       &cerr)
                    : error_set(&cerr, ST_INTERNAL, "the record of finished samples is incomplete; "
                                                    "no final checkpoint written");
    int complete = render_st == ST_OK && !r->stats.interrupted && !r->stats.time_up;
    if (st != ST_OK && complete) {
        api_warn(r->ctx, cerr.msg);
        st = ST_OK;
    } else if (st != ST_OK && render_st == ST_OK) {
        error_clear(err);
        *err = cerr;
        return st;
    }
    error_clear(&cerr);
    return st;
}

/* The auxiliary images asked for, one pass each, then the adaptive pass. */
static Status render_passes(ApiRun *r, clpt_image *img, Error *err)
{
    uint spp = (uint)r->film.samples;
    ScheduleConfig pcfg = r->cfg;
    pcfg.on_checkpoint = NULL;
    /* a pass renders all its samples: those a resumed checkpoint held were the main
     * image's, not the pass's (as results_run_passes in main.c) */
    pcfg.done = NULL;
    pcfg.n_done = 0;
    PassContext pc = { r->devs, r->n_devs, &r->rs, &pcfg, NULL, NULL, NULL };   /* the API does not denoise (yet) */
    size_t n = (size_t)r->film.width * r->film.height;
    Status st = ST_OK;
    if (r->o.adaptive > 0.0) {
        size_t marked = 0;
        double secs = 0.0;
        st = passes_adaptive(&pc, img->rgb, spp, (float)r->o.adaptive, r->o.adaptive_spp, &marked, &secs, err);
        r->pass_base += r->o.adaptive_spp;
    }
    float *data = NULL;
    if (st == ST_OK && !(data = malloc(n * 3 * sizeof *data))) st = error_set(err, ST_INTERNAL, "out of memory");
    for (unsigned a = INTEGRATOR_AOV_NORMAL; a <= INTEGRATOR_AOV_ALBEDO && st == ST_OK && !r->stop; a++) {
        if (!wants(img, a)) continue;
        double secs = 0.0;
        if ((st = passes_aov_data(&pc, a, spp, data, &secs, err))) break;
        if (r->stop) break;   /* an interrupted pass is incomplete: not handed out */
        if (a == INTEGRATOR_AOV_DEPTH)
            for (size_t i = 0; i < n; i++) img->depth[i] = data[3 * i];
        else
            memcpy(a == INTEGRATOR_AOV_NORMAL ? img->normal : img->albedo, data, n * 3 * sizeof *data);
        r->pass_base += spp;
    }
    free(data);
    return st == ST_OK && r->stop ? ST_INTERRUPTED : st;
}

/* After the render: the checkpoint, the image, the passes. The status is the first
 * failure: the render's, else the cancel, else a write's. */
static Status render_results(ApiRun *r, Status render_st, clpt_image *img, Error *err)
{
    if (r->film.samples == 0) {
        if (render_st != ST_OK) return render_st;
        return error_set(err, ST_NOTHING_RENDERED, "%s before the first batch finished: nothing was rendered",
                         r->stats.interrupted ? "cancelled" : "the time limit was reached");
    }
    Status st = write_checkpoint(r, render_st, err);
    if (render_st != ST_OK) return render_st;
    film_resolve(&r->film, img->rgb);
    img->spp = (unsigned)r->film.samples;
    if (st != ST_OK) return st;
    if (r->stats.interrupted) return error_set(err, ST_INTERRUPTED, "cancelled: %u of %u samples per pixel rendered",
                                               img->spp, r->scene.image.spp);
    if (r->stats.time_up) return ST_OK;
    return render_passes(r, img, err);
}

clpt_status clpt_render(clpt_scene *sc, const clpt_settings *settings, clpt_image *img, clpt_progress_fn progress,
                        void *user)
{
    if (!sc) return CLPT_ERROR_USAGE;
    ApiRun *r = calloc(1, sizeof *r);
    clpt_context *ctx = sc->ctx;
    error_clear(&ctx->err);
    if (!r) return api_fail(ctx, ST_INTERNAL, "out of memory");
    Error *err = &ctx->err;
    r->ctx = ctx;
    r->progress = progress;
    r->user = user;
    scene_init(&r->scene);
    Status st = api_render_options(sc, settings, &r->o, err);
    /* adaptive sampling's rounds are the program's alone so far (host/render/adaptive.c) */
    if (st == ST_OK && r->o.noise_threshold > 0.0)
        st = error_set(err, ST_USAGE, "noise_threshold (--noise-threshold) is not available in the library; render "
                       "with the clpt program");
    if (st == ST_OK) st = api_scene_read(sc, &r->o, &r->scene, err);
    if (st == ST_OK) st = image_check(r, img, err);
    if (st == ST_OK) st = render_prepare(r, err);
    if (st == ST_OK) {
        unsigned aov_spp = 0;
        for (unsigned a = INTEGRATOR_AOV_NORMAL; a <= INTEGRATOR_AOV_ALBEDO; a++) aov_spp += wants(img, a);
        r->total = r->scene.image.spp * (1u + aov_spp) + (r->o.adaptive > 0.0 ? r->o.adaptive_spp : 0u);
        render_configure(r);
        Status render_st = schedule_run(r->devs, r->n_devs, &r->cfg, &r->film, &r->stats, err);
        st = render_results(r, render_st, img, err);
    }
    render_free(r);
    free(r);
    return (clpt_status)st;
}

clpt_status clpt_render_size(clpt_scene *sc, const clpt_settings *settings, unsigned *width, unsigned *height)
{
    if (!sc || !width || !height) return CLPT_ERROR_USAGE;
    clpt_context *ctx = sc->ctx;
    error_clear(&ctx->err);
    Options o;
    Scene s;
    scene_init(&s);
    Status st = api_render_options(sc, settings, &o, &ctx->err);
    if (st == ST_OK) st = api_scene_read(sc, &o, &s, &ctx->err);
    uint w = 0, h = 0;
    if (st == ST_OK) render_image_size(&s, &w, &h);
    *width = w;
    *height = h;
    scene_free(&s);
    return (clpt_status)st;
}
