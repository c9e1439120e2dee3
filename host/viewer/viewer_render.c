/* viewer_render.c — see viewer_render.h. */
#include "viewer/viewer_render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/timer.h"
#include "render/passes.h"
#include "scene/camera.h"

/* How often a pass publishes what is finished, and how often the scheduler looks at the
 * stop flag (a camera change). */
#define VIEWER_TICK_SECONDS 0.1
#define VIEWER_POLL_SECONDS 0.005
/* What a preview should take, in seconds, and its largest reduction. */
#define PREVIEW_SECONDS 0.025
#define PREVIEW_MAX_FACTOR 16u

static size_t frame_floats(const ViewerRender *vr)
{
    return (size_t)vr->params.width * vr->params.height * 3u;
}

/* Resolves `film` into the spare image and makes it the published frame. */
static void publish(ViewerRender *vr, const Film *film, const Batch *done, size_t n_done)
{
    film_resolve(film, vr->spare);
    pthread_mutex_lock(&vr->lock);
    float *t = vr->rgb;
    vr->rgb = vr->spare;
    vr->spare = t;
    vr->samples = film->samples;
    vr->frame_gen = vr->my_gen;
    vr->frame_prefix = film->samples > 0 && n_done == 1 && done[0].first == 0 && done[0].count == film->samples;
    vr->frame_seq++;
    pthread_mutex_unlock(&vr->lock);
}

/* The scheduler's tick during a pass: shows the batches finished so far, unless the
 * view has changed meanwhile. */
static void on_tick(void *ctx, const ScheduleSnapshot *snap)
{
    ViewerRender *vr = ctx;
    pthread_mutex_lock(&vr->lock);
    int current = vr->gen == vr->my_gen;
    pthread_mutex_unlock(&vr->lock);
    if (current) publish(vr, snap->film, snap->done, snap->n_done);
}

static void on_warning(void *ctx, const char *msg)
{
    (void)ctx;
    fprintf(stderr, "clpt: warning: %s\n", msg);
}

static void set_failure(ViewerRender *vr, Status st, const char *msg)
{
    pthread_mutex_lock(&vr->lock);
    vr->failure = st;
    snprintf(vr->failure_msg, sizeof vr->failure_msg, "%s", msg);
    pthread_mutex_unlock(&vr->lock);
    fprintf(stderr, "clpt: error: %s\n", msg);
}

/* ------------------------------------------------------------------ denoising */

/* Open Image Denoise and the denoiser's images, at the first request; when it is not
 * there, that is said once and the window's title says so. */
static int denoiser_ready(ViewerRender *vr)
{
    if (vr->denoise_state != 0) return vr->denoise_state == 1;
    Error err = { 0 };
    Status st = ST_OK;
    if (!vr->denoiser) {
        st = denoiser_open(&vr->denoiser, &err);
        vr->own_denoiser = st == ST_OK;
    }
    /* the thread's own images; the published one is set under the lock (the window
     * reads it) */
    size_t n = frame_floats(vr);
    float **bufs[] = { &vr->albedo, &vr->normal, &vr->noisy, &vr->denoise_out };
    for (size_t i = 0; st == ST_OK && i < sizeof bufs / sizeof *bufs; i++)
        if (!(*bufs[i] = calloc(n, sizeof **bufs[i]))) st = error_set(&err, ST_INTERNAL, "out of memory");
    float *published = st == ST_OK ? calloc(n, sizeof *published) : NULL;
    if (st == ST_OK && !published) st = error_set(&err, ST_INTERNAL, "out of memory");
    if (st != ST_OK) fprintf(stderr, "clpt: warning: the viewer cannot denoise: %s\n", err.msg);
    /* the render thread's stop flag also stops OIDN: a camera change, a pause, N off
     * or quitting then waits no longer for a denoise than for a batch */
    if (st == ST_OK) denoiser_set_cancel(vr->denoiser, &vr->stop);
    error_clear(&err);
    pthread_mutex_lock(&vr->lock);
    vr->denoised = published;
    vr->denoise_state = st == ST_OK ? 1 : -1;
    pthread_mutex_unlock(&vr->lock);
    return st == ST_OK;
}

/* Counts a denoise that the stop flag cancelled (--stats) and says so: its frame is
 * not shown, and the request that raised the flag goes on at once. */
static void denoise_cancelled(ViewerRender *vr, const char *during)
{
    pthread_mutex_lock(&vr->lock);
    vr->denoise_cancels++;
    pthread_mutex_unlock(&vr->lock);
    fprintf(stderr, "clpt: viewer: denoise cancelled (during %s)\n", during);
}

/* The denoiser's albedo and normal images of the current view, as --denoise renders
 * them (passes_aov_data), on the render's devices, which get the view's parameters back
 * after; then prefiltered once for all the view's passes (denoiser_clean_features).
 * 0 when a camera change or a pause cancelled them, or they failed. */
/* A pass of the current view (the features, the emission) on the render's devices: the
 * view's parameters, the stop flag, the render's batches. */
static void view_pass_context(ViewerRender *vr, RenderScene *rs, ScheduleConfig *cfg, PassContext *pc)
{
    memset(rs, 0, sizeof *rs);
    rs->ds = *vr->scene;
    rs->ds.params = vr->params;
    memset(cfg, 0, sizeof *cfg);
    cfg->fixed_batch = vr->fixed_batch;
    cfg->stop = &vr->stop;
    cfg->poll_seconds = VIEWER_POLL_SECONDS;
    cfg->on_warning = on_warning;
    PassContext c = { vr->devices, vr->n_devices, rs, cfg, vr->denoiser, NULL, NULL };
    *pc = c;
}

static int features_render(ViewerRender *vr)
{
    RenderScene rs;
    ScheduleConfig cfg;
    PassContext pc;
    view_pass_context(vr, &rs, &cfg, &pc);
    double secs = 0.0;
    Error err = { 0 };
    Status st = passes_aov_data(&pc, INTEGRATOR_FEATURE_ALBEDO, VIEWER_FEATURE_SPP, vr->albedo, &secs, &err);
    if (st == ST_OK) st = passes_aov_data(&pc, INTEGRATOR_FEATURE_NORMAL, VIEWER_FEATURE_SPP, vr->normal, &secs, &err);
    if (st != ST_OK) set_failure(vr, st, err.msg);
    error_clear(&err);
    if (st == ST_OK && vr->stop) denoise_cancelled(vr, "the features' render");
    if (st != ST_OK || vr->stop) return 0;
    st = denoiser_clean_features(vr->denoiser, vr->albedo, vr->normal, vr->params.width, vr->params.height, &err);
    if (st == ST_INTERRUPTED) {   /* cancelled: rendered again for the next request */
        error_clear(&err);
        denoise_cancelled(vr, "the features' filter");
        return 0;
    }
    if (st != ST_OK) {
        fprintf(stderr, "clpt: warning: the viewer cannot denoise: %s\n", err.msg);
        error_clear(&err);
        pthread_mutex_lock(&vr->lock);
        vr->denoise_state = -1;
        pthread_mutex_unlock(&vr->lock);
        return 0;
    }
    vr->feature_gen = vr->my_gen;
    return 1;
}

/* Adds samples [have, want) of the emission image of `want` samples per pixel to *acc
 * (vr->emission[]): the frame's emission grows with its passes as the film does, in
 * the same integer sums, so it is the emission image of [0, want) rendered at once. A
 * stopped render adds nothing. */
static Status emission_extend(ViewerRender *vr, const PassContext *pc, Film *acc, uint want, Error *err)
{
    uint have = (uint)acc->samples;
    if (have >= want) return ST_OK;
    Film part;
    double secs = 0.0;
    Status st = passes_data_film(pc, INTEGRATOR_FEATURE_EMISSION, want, have, want, &part, &secs, err);
    if (st == ST_OK && !vr->stop && part.samples == want - have) {
        for (size_t i = 0; i < (size_t)acc->width * acc->height * 3u; i++) acc->sum[i] += part.sum[i];
        acc->samples += part.samples;
    }
    film_free(&part);
    return st;
}

/* The emission images of the frame of `n` samples per pixel (its samples [0, n), and
 * [0, 4n) to add back), as passes_denoise_emission makes them for --denoise, but
 * accumulated along the view's passes: each pass renders only the emission samples the
 * last did not (camera rays alone). *e and *more stay NULL where --denoise would give
 * the colour whole (the whitted integrator, media, nothing seen emitted). Freed by the
 * caller. */
static Status emission_images(ViewerRender *vr, uint n, float **e, float **more, Error *err)
{
    *e = *more = NULL;
    if (!passes_emission_splits(&vr->params, 1)) return ST_OK;
    Status st = ST_OK;
    if (vr->emission_gen != vr->my_gen || vr->emission[0].samples > n) {   /* a new view */
        for (int k = 0; k < 2 && st == ST_OK; k++) {
            film_free(&vr->emission[k]);
            st = film_init(&vr->emission[k], vr->params.width, vr->params.height, err);
        }
        if (st != ST_OK) return st;
        vr->emission_gen = vr->my_gen;
    }
    RenderScene rs;
    ScheduleConfig cfg;
    PassContext pc;
    view_pass_context(vr, &rs, &cfg, &pc);
    size_t floats = (size_t)vr->params.width * vr->params.height * 3u;
    st = emission_extend(vr, &pc, &vr->emission[0], n, err);
    if (st != ST_OK || vr->stop) return st;
    if (!(*e = malloc(floats * sizeof **e))) return error_set(err, ST_INTERNAL, "out of memory for the denoiser");
    passes_resolve_data(INTEGRATOR_FEATURE_EMISSION, &vr->emission[0], *e);
    if (!passes_emission_lit(*e, floats)) {   /* nothing seen emitted: the colour whole */
        free(*e);
        *e = NULL;
        return ST_OK;
    }
    st = emission_extend(vr, &pc, &vr->emission[1], passes_emission_more_spp(n), err);
    if (st != ST_OK || vr->stop) return st;
    if (!(*more = malloc(floats * sizeof **more))) return error_set(err, ST_INTERNAL, "out of memory for the denoiser");
    passes_resolve_data(INTEGRATOR_FEATURE_EMISSION, &vr->emission[1], *more);
    return ST_OK;
}

/* Whether the film holds samples [0, film.samples) exactly: a finished pass. */
static int film_is_prefix(const ViewerRender *vr)
{
    return vr->film.samples > 0 && vr->done.n == 1 && vr->done.ranges[0].first == 0 &&
           vr->done.ranges[0].count == vr->film.samples;
}

/* Under the lock: whether the frame of the finished pass waits to be denoised. */
static int denoise_due(const ViewerRender *vr)
{
    return vr->denoise && vr->denoise_state != -1 && !vr->paused && vr->failure == ST_OK && vr->view_ok &&
           film_is_prefix(vr) && !(vr->tried_gen == vr->my_gen && vr->tried_samples == vr->film.samples);
}

/* Denoises the finished pass's frame and publishes it beside the noisy one. */
static void denoise_step(ViewerRender *vr)
{
    uint64_t samples = vr->film.samples;
    if (!denoiser_ready(vr)) return;
    if (vr->feature_gen != vr->my_gen && !features_render(vr)) return;   /* tried again unless it failed */
    double t0 = timer_now();
    Error err = { 0 };
    /* the lamps seen directly are left out of the denoiser and added back, as
     * --denoise leaves them out (docs/denoise.md, "Emitters' edges") */
    float *e = NULL, *more = NULL;
    Status st = emission_images(vr, (uint)samples, &e, &more, &err);
    if (st == ST_OK && vr->stop) {   /* cancelled: the same frame again when still due */
        free(e);
        free(more);
        denoise_cancelled(vr, "the emission's render");
        return;
    }
    if (st != ST_OK) {
        set_failure(vr, st, err.msg);
        error_clear(&err);
        free(e);
        free(more);
        return;
    }
    pthread_mutex_lock(&vr->lock);
    vr->denoising = 2;
    pthread_mutex_unlock(&vr->lock);
    film_resolve(&vr->film, vr->noisy);
    st = passes_denoise_split(vr->denoiser, vr->noisy, vr->albedo, vr->normal, e, more, vr->params.width,
                              vr->params.height, 1, vr->denoise_out, &err);
    free(e);
    free(more);
    double secs = timer_now() - t0;
    if (st == ST_INTERRUPTED) {   /* not tried: the same frame is denoised again when still due */
        error_clear(&err);
        denoise_cancelled(vr, "the colour's filter");
        return;
    }
    vr->tried_gen = vr->my_gen;
    vr->tried_samples = samples;
    if (st != ST_OK) fprintf(stderr, "clpt: warning: the viewer cannot denoise: %s\n", err.msg);
    error_clear(&err);
    pthread_mutex_lock(&vr->lock);
    if (st != ST_OK) {
        vr->denoise_state = -1;
    } else if (vr->gen == vr->my_gen) {
        float *t = vr->denoised;
        vr->denoised = vr->denoise_out;
        vr->denoise_out = t;
        vr->denoised_samples = samples;
        vr->denoised_gen = vr->my_gen;
        vr->denoised_seq++;
        vr->denoise_count++;
        vr->denoise_seconds += secs;
        vr->denoise_last = secs;
    }
    pthread_mutex_unlock(&vr->lock);
}

/* ------------------------------------------------------------------ passes */

/* Gives every device the new view's camera and empties the film. A camera that cannot
 * be set up (the view functions keep it valid; this is the defensive check) leaves the
 * view unrendered. */
static void view_begin(ViewerRender *vr, const SceneCamera *camera)
{
    Error err = { 0 };
    memset(vr->film.sum, 0, frame_floats(vr) * sizeof *vr->film.sum);
    vr->film.samples = 0;
    batch_set_free(&vr->done);
    pthread_mutex_lock(&vr->lock);
    vr->view_samples = vr->view_seconds = 0.0;
    pthread_mutex_unlock(&vr->lock);
    vr->view_ok = camera_setup(camera, vr->params.width, vr->params.height, &vr->params.camera, &err) == ST_OK;
    if (!vr->view_ok) {
        fprintf(stderr, "clpt: warning: this view cannot be rendered: %s\n", err.msg);
        error_clear(&err);
        return;
    }
    for (size_t i = 0; i < vr->n_devices; i++) {
        Device *d = vr->devices[i];
        if (d->ops->update_params(d, &vr->params, NULL, &err) != ST_OK) {
            set_failure(vr, err.status ? err.status : ST_DEVICE, err.msg);
            error_clear(&err);
            return;
        }
    }
}

/* One pass: the film goes from what it holds to `target` samples per pixel (fewer when
 * the pass is cancelled). */
static void pass_run(ViewerRender *vr, uint target)
{
    int first = vr->film.samples == 0 && target == 1;
    ScheduleConfig cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = target;
    cfg.done = vr->done.ranges;
    cfg.n_done = vr->done.n;
    cfg.fixed_batch = vr->fixed_batch;
    cfg.stop = &vr->stop;
    cfg.poll_seconds = VIEWER_POLL_SECONDS;
    cfg.on_tick = on_tick;
    cfg.tick_seconds = VIEWER_TICK_SECONDS;
    cfg.on_warning = on_warning;
    cfg.ctx = vr;
    ScheduleStats stats;
    Error err = { 0 };
    Status st = schedule_run(vr->devices, vr->n_devices, &cfg, &vr->film, &stats, &err);
    pthread_mutex_lock(&vr->lock);
    int current = vr->gen == vr->my_gen;
    if (current) {
        vr->view_samples += (double)stats.samples;
        vr->view_seconds += stats.seconds;
    }
    pthread_mutex_unlock(&vr->lock);
    if (st != ST_OK) {
        set_failure(vr, st, err.msg);
    } else if (current) {
        if (first && !stats.interrupted) vr->one_spp_seconds = stats.seconds;
        batch_set_free(&vr->done);
        vr->done = stats.done;   /* the ranges the film holds now */
        memset(&stats.done, 0, sizeof stats.done);
        if (vr->film.samples > 0) publish(vr, &vr->film, vr->done.ranges, vr->done.n);
    }
    error_clear(&err);
    schedule_stats_free(&stats);
}

/* The next pass's target: 1 sample per pixel first (the new view appears at once),
 * then doubling, up to the cap. After a paused pass on several devices the film may
 * hold ranges beyond its count (a later batch finished, an earlier one was dropped):
 * the target covers them, as the scheduler requires. */
static uint pass_target(const ViewerRender *vr)
{
    uint64_t have = vr->film.samples;
    uint64_t next = have ? 2u * have : 1u;
    for (size_t i = 0; i < vr->done.n; i++) {
        uint64_t end = (uint64_t)vr->done.ranges[i].first + vr->done.ranges[i].count;
        if (end > next) next = end;
    }
    return next > vr->spp_cap ? vr->spp_cap : (uint)next;
}

/* Opens the preview's devices: each device of the render opened again, with the scene
 * at 1/factor of the size. On failure previews are left off, with a warning. */
static void preview_open(ViewerRender *vr)
{
    double k = ceil(sqrt(vr->one_spp_seconds / PREVIEW_SECONDS));
    vr->preview_factor = k < 2.0 ? 2u : (k > PREVIEW_MAX_FACTOR ? PREVIEW_MAX_FACTOR : (uint)k);
    DeviceScene small = *vr->scene;
    small.params.width = (vr->params.width + vr->preview_factor - 1) / vr->preview_factor;
    small.params.height = (vr->params.height + vr->preview_factor - 1) / vr->preview_factor;
    small.pixel_list = NULL;
    small.params.pixel_list_size = 0;
    vr->preview_params = small.params;
    Error err = { 0 };
    vr->preview_state = -1;
    vr->preview_devices = calloc(vr->n_devices, sizeof *vr->preview_devices);
    Status st = vr->preview_devices ? ST_OK : error_set(&err, ST_INTERNAL, "out of memory");
    if (st == ST_OK) st = film_init(&vr->preview_film, small.params.width, small.params.height, &err);
    if (st == ST_OK && !(vr->preview_rgb = calloc((size_t)small.params.width * small.params.height * 3u,
                                                  sizeof *vr->preview_rgb)))
        st = error_set(&err, ST_INTERNAL, "out of memory");
    for (size_t i = 0; st == ST_OK && i < vr->n_devices; i++) {
        Device *d = NULL;
        st = device_open(&vr->devices[i]->desc, &vr->device_config, &d, &err);
        if (st == ST_OK) st = d->ops->load_scene(d, &small, &err);
        if (st == ST_OK) vr->preview_devices[vr->n_preview++] = d;
        else device_close(d);
    }
    if (st == ST_OK) {
        vr->preview_state = 1;
        return;
    }
    fprintf(stderr, "clpt: warning: no previews (the devices could not be opened a second time: %s)\n", err.msg);
    error_clear(&err);
}

static void preview_close(ViewerRender *vr)
{
    for (size_t i = 0; i < vr->n_preview; i++) device_close(vr->preview_devices[i]);
    free(vr->preview_devices);
    vr->preview_devices = NULL;
    vr->n_preview = 0;
    film_free(&vr->preview_film);
    free(vr->preview_rgb);
    vr->preview_rgb = NULL;
}

/* The small image, each of its pixels shown as a factor x factor block. Not a sample
 * of the view's film (frame_prefix 0: never saved). */
static void preview_publish(ViewerRender *vr)
{
    uint w = vr->params.width, h = vr->params.height, pw = vr->preview_params.width;
    film_resolve(&vr->preview_film, vr->preview_rgb);
    for (uint y = 0; y < h; y++)
        for (uint x = 0; x < w; x++)
            memcpy(&vr->spare[((size_t)y * w + x) * 3u],
                   &vr->preview_rgb[((size_t)(y / vr->preview_factor) * pw + x / vr->preview_factor) * 3u],
                   3 * sizeof *vr->spare);
    pthread_mutex_lock(&vr->lock);
    if (vr->gen == vr->my_gen) {
        float *t = vr->rgb;
        vr->rgb = vr->spare;
        vr->spare = t;
        vr->samples = 0;
        vr->frame_gen = vr->my_gen;
        vr->frame_prefix = 0;
        vr->frame_seq++;
    }
    pthread_mutex_unlock(&vr->lock);
}

/* The new view at 1 spp in the small image, shown at once; a camera change meanwhile
 * cancels it like a pass. */
static void preview_run(ViewerRender *vr)
{
    Error err = { 0 };
    vr->preview_params.camera = vr->params.camera;
    Status st = camera_setup(&vr->camera_shown, vr->preview_params.width, vr->preview_params.height,
                             &vr->preview_params.camera, &err);
    for (size_t i = 0; st == ST_OK && i < vr->n_preview; i++)
        st = vr->preview_devices[i]->ops->update_params(vr->preview_devices[i], &vr->preview_params, NULL, &err);
    ScheduleConfig cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = 1;
    cfg.stop = &vr->stop;
    cfg.poll_seconds = VIEWER_POLL_SECONDS;
    cfg.on_warning = on_warning;
    ScheduleStats stats;
    memset(&stats, 0, sizeof stats);
    memset(vr->preview_film.sum, 0,
           (size_t)vr->preview_params.width * vr->preview_params.height * 3u * sizeof *vr->preview_film.sum);
    vr->preview_film.samples = 0;
    if (st == ST_OK) st = schedule_run(vr->preview_devices, vr->n_preview, &cfg, &vr->preview_film, &stats, &err);
    if (st == ST_OK && !stats.interrupted && vr->preview_film.samples == 1) preview_publish(vr);
    if (st != ST_OK) {
        fprintf(stderr, "clpt: warning: previews stopped: %s\n", err.msg);
        preview_close(vr);
        vr->preview_state = -1;
    }
    error_clear(&err);
    schedule_stats_free(&stats);
}

static void *render_main(void *arg)
{
    ViewerRender *vr = arg;
    pthread_mutex_lock(&vr->lock);
    for (;;) {
        if (vr->quit) break;
        if (vr->gen != vr->my_gen) {
            SceneCamera cam = vr->camera;
            vr->my_gen = vr->gen;
            vr->stop = 0;
            pthread_mutex_unlock(&vr->lock);
            vr->camera_shown = cam;
            view_begin(vr, &cam);
            if (vr->view_ok && vr->preview_state == 1) preview_run(vr);
            pthread_mutex_lock(&vr->lock);
            continue;
        }
        if (denoise_due(vr)) {
            vr->stop = 0;   /* as for a pass: a change made after this cancels the denoise */
            vr->denoising = 1;
            pthread_mutex_unlock(&vr->lock);
            denoise_step(vr);
            pthread_mutex_lock(&vr->lock);
            vr->denoising = 0;
            continue;
        }
        if (vr->paused || vr->failure != ST_OK || !vr->view_ok || vr->film.samples >= vr->spp_cap) {
            pthread_cond_wait(&vr->wake, &vr->lock);
            continue;
        }
        vr->stop = 0;   /* under the lock: a change made after this cancels the pass */
        pthread_mutex_unlock(&vr->lock);
        pass_run(vr, pass_target(vr));
        if (vr->preview_state == 0 && vr->one_spp_seconds > VIEWER_PREVIEW_AFTER) preview_open(vr);
        pthread_mutex_lock(&vr->lock);
    }
    pthread_mutex_unlock(&vr->lock);
    return NULL;
}

Status viewer_render_start(ViewerRender *vr, Device **devices, size_t n, const DeviceScene *scene,
                           const DeviceConfig *device_config, const SceneCamera *camera, uint spp_cap,
                           uint fixed_batch, Denoiser *denoiser, Error *err)
{
    memset(vr, 0, sizeof *vr);
    vr->denoiser = denoiser;
    vr->denoise = denoiser != NULL;
    vr->devices = devices;
    vr->n_devices = n;
    vr->scene = scene;
    vr->device_config = *device_config;
    const RenderParams *params = &scene->params;
    vr->params = *params;
    vr->spp_cap = spp_cap ? spp_cap : 1u;
    vr->fixed_batch = fixed_batch;
    vr->camera = *camera;
    vr->gen = 1;
    Status st = film_init(&vr->film, params->width, params->height, err);
    if (st != ST_OK) return st;
    vr->rgb = calloc(frame_floats(vr), sizeof *vr->rgb);
    vr->spare = calloc(frame_floats(vr), sizeof *vr->spare);
    if (!vr->rgb || !vr->spare) {
        viewer_render_stop(vr, NULL);
        return error_set(err, ST_INTERNAL, "out of memory for the viewer's images");
    }
    pthread_mutex_init(&vr->lock, NULL);
    pthread_cond_init(&vr->wake, NULL);
    if (pthread_create(&vr->thread, NULL, render_main, vr) != 0) {
        pthread_cond_destroy(&vr->wake);
        pthread_mutex_destroy(&vr->lock);
        film_free(&vr->film);
        free(vr->rgb);
        free(vr->spare);
        return error_set(err, ST_INTERNAL, "cannot start the viewer's render thread");
    }
    vr->started = 1;
    return ST_OK;
}

void viewer_render_set_camera(ViewerRender *vr, const SceneCamera *camera)
{
    pthread_mutex_lock(&vr->lock);
    vr->camera = *camera;
    vr->gen++;
    vr->stop = 1;
    pthread_cond_signal(&vr->wake);
    pthread_mutex_unlock(&vr->lock);
}

void viewer_render_set_denoise(ViewerRender *vr, int on)
{
    pthread_mutex_lock(&vr->lock);
    vr->denoise = on;
    if (!on && vr->denoising) vr->stop = 1;   /* a denoise nobody will see: stopped, not awaited */
    pthread_cond_signal(&vr->wake);
    pthread_mutex_unlock(&vr->lock);
}

void viewer_render_set_paused(ViewerRender *vr, int paused)
{
    pthread_mutex_lock(&vr->lock);
    vr->paused = paused;
    if (paused) vr->stop = 1;
    pthread_cond_signal(&vr->wake);
    pthread_mutex_unlock(&vr->lock);
}

Status viewer_render_stop(ViewerRender *vr, Error *err)
{
    Status st = ST_OK;
    if (vr->started) {
        pthread_mutex_lock(&vr->lock);
        vr->quit = 1;
        vr->stop = 1;
        pthread_cond_signal(&vr->wake);
        pthread_mutex_unlock(&vr->lock);
        pthread_join(vr->thread, NULL);
        pthread_cond_destroy(&vr->wake);
        pthread_mutex_destroy(&vr->lock);
        vr->started = 0;
        if (vr->failure != ST_OK) st = error_set(err, vr->failure, "%s", vr->failure_msg);
    }
    preview_close(vr);
    film_free(&vr->film);
    film_free(&vr->emission[0]);
    film_free(&vr->emission[1]);
    vr->emission_gen = 0;
    batch_set_free(&vr->done);
    free(vr->rgb);
    free(vr->spare);
    vr->rgb = vr->spare = NULL;
    /* a caller's denoiser outlives vr, its stop flag does not */
    if (vr->denoiser && !vr->own_denoiser) denoiser_set_cancel(vr->denoiser, NULL);
    if (vr->own_denoiser) denoiser_close(vr->denoiser);
    vr->denoiser = NULL;
    float **bufs[] = { &vr->albedo, &vr->normal, &vr->noisy, &vr->denoise_out, &vr->denoised };
    for (size_t i = 0; i < sizeof bufs / sizeof *bufs; i++) {
        free(*bufs[i]);
        *bufs[i] = NULL;
    }
    return st;
}
