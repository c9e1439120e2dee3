/*
 * api_render.c — clpt_render: the program's render (main.c) into the caller's memory.
 *
 * The same run (render/render_job.h) in the same order, so the image is the program's
 * bits: the scene read and the settings applied (scene_options.c), the job prepared
 * (the film, from a checkpoint when resuming), the devices, the scheduler or the
 * adaptive rounds (noise_threshold), then the final checkpoint, the image resolved,
 * and the passes after it (whitted's edge pass, auxiliary images, the denoiser).
 */
#include "api/api.h"

#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "job_options.h"
#include "render/render_job.h"

/* One render: the job, and the progress callback with its cancel. */
typedef struct {
    clpt_context *ctx;
    Options o;
    Scene scene;
    RenderJob job;
    clpt_progress_fn progress;
    void *user;
    volatile sig_atomic_t stop;
    unsigned total;               /* samples per pixel of the render and its passes */
} ApiRun;

/* The caller's callback, whose non-zero answer stops the render. */
static void report_progress(ApiRun *r, unsigned done)
{
    if (r->progress && r->progress(r->user, done, r->total)) r->stop = 1;
}

/* The scheduler's poll, during the render and each pass. */
static void on_poll(void *vjob, uint spp_done)
{
    RenderJob *job = vjob;
    report_progress(job->user, job->passes_spp + spp_done);
}

/* An adaptive render's rounds (which do not poll): the most a pixel holds. */
static void on_round(void *vjob, const AdaptiveFilm *af)
{
    RenderJob *job = vjob;
    report_progress(job->user, (unsigned)af->film.samples);
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

/* The job: the settings (the context's devices), the denoiser, the scene prepared,
 * the film (resumed from a checkpoint), the devices, and the scheduler's hooks. */
static Status render_prepare(ApiRun *r, Error *err)
{
    RenderJob *job = &r->job;
    Status st;
    if ((st = render_job_prepare_scene(job, &r->scene, err))) return st;
    if ((st = render_job_prepare_film(job, 0, 0, err))) return st;
    if ((st = render_job_open_devices(job, err))) return st;
    render_job_configure(job);
    job->cfg.stop = &r->stop;
    job->cfg.on_poll = on_poll;
    job->on_round = on_round;
    return ST_OK;
}

/* After the render: the checkpoint, the image, the passes. The status is the first
 * failure: the render's, else the cancel, else a write's. */
static Status render_results(ApiRun *r, clpt_image *img, Error *err)
{
    RenderJob *job = &r->job;
    Status render_st = job->render_st;
    if (job->film.samples == 0) {
        if (render_st != ST_OK) return render_st;
        return error_set(err, ST_NOTHING_RENDERED, "%s before the first batch finished: nothing was rendered",
                         job->stats.interrupted ? "cancelled" : "the time limit was reached");
    }
    Error cerr = { 0 };
    Status st = render_job_final_checkpoint(job, &cerr);
    if (st != ST_OK && render_st == ST_OK) {
        error_clear(err);
        *err = cerr;
    } else {
        error_clear(&cerr);
    }
    if (render_st != ST_OK) return render_st;
    render_job_resolve(job, img->rgb);
    img->spp = (unsigned)job->film.samples;
    if (st != ST_OK) return st;
    if (job->stats.interrupted) return error_set(err, ST_INTERRUPTED, "cancelled: %u of %u samples per pixel rendered",
                                                 img->spp, r->scene.image.spp);
    /* after a time limit, as in the program: the passes at the samples the image got */
    RenderJobAovs aovs = { img->normal, img->albedo, img->depth };
    job->passes_spp = job->scene->image.spp;
    return render_job_passes_to_memory(job, img->rgb, &aovs, err);
}

/* The samples per pixel of the render and its passes, as progress counts them. */
static unsigned render_total(const ApiRun *r, const clpt_image *img)
{
    unsigned passes = 0;
    for (unsigned a = INTEGRATOR_AOV_NORMAL; a <= INTEGRATOR_AOV_ALBEDO; a++)
        passes += wants(img, a) || (r->o.denoise && a != INTEGRATOR_AOV_DEPTH);
    return r->scene.image.spp * (1u + passes) + (r->o.adaptive > 0.0 ? r->o.adaptive_spp : 0u);
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
    if (st == ST_OK) {
        RenderJobSettings set = job_options_settings(&r->o);
        set.device_spec = ctx->device_spec;
        set.device.profile = 0;
        render_job_init(&r->job, &set, api_warn, ctx, r);
        /* --denoise's library loaded before anything slow, as the program does */
        st = render_job_open_denoiser(&r->job, err);
    }
    if (st == ST_OK) st = api_scene_read(sc, &r->o, &r->scene, err);
    if (st == ST_OK) st = image_check(r, img, err);
    if (st == ST_OK) st = render_prepare(r, err);
    if (st == ST_OK) {
        r->total = render_total(r, img);
        render_job_run(&r->job, err);
        st = render_results(r, img, err);
    }
    render_job_free(&r->job);
    scene_free(&r->scene);
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
