/* viewer_render.c — see viewer_render.h. */
#include "viewer_render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/camera.h"

/* How often a pass publishes what is finished, and how often the scheduler looks at the
 * stop flag (a camera change). */
#define VIEWER_TICK_SECONDS 0.1
#define VIEWER_POLL_SECONDS 0.005

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
        batch_set_free(&vr->done);
        vr->done = stats.done;   /* the ranges the film holds now */
        memset(&stats.done, 0, sizeof stats.done);
        if (vr->film.samples > 0) publish(vr, &vr->film, vr->done.ranges, vr->done.n);
    }
    error_clear(&err);
    schedule_stats_free(&stats);
}

/* The next pass's target: 1 sample per pixel first (the new view appears at once),
 * then doubling, up to the cap. */
static uint pass_target(const ViewerRender *vr)
{
    uint64_t have = vr->film.samples;
    uint64_t next = have ? 2u * have : 1u;
    return next > vr->spp_cap ? vr->spp_cap : (uint)next;
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
            pthread_mutex_unlock(&vr->lock);
            view_begin(vr, &cam);
            pthread_mutex_lock(&vr->lock);
            continue;
        }
        if (vr->paused || vr->failure != ST_OK || !vr->view_ok || vr->film.samples >= vr->spp_cap) {
            pthread_cond_wait(&vr->wake, &vr->lock);
            continue;
        }
        vr->stop = 0;   /* under the lock: a change made after this cancels the pass */
        pthread_mutex_unlock(&vr->lock);
        pass_run(vr, pass_target(vr));
        pthread_mutex_lock(&vr->lock);
    }
    pthread_mutex_unlock(&vr->lock);
    return NULL;
}

Status viewer_render_start(ViewerRender *vr, Device **devices, size_t n, const RenderParams *params,
                           const SceneCamera *camera, uint spp_cap, uint fixed_batch, Error *err)
{
    memset(vr, 0, sizeof *vr);
    vr->devices = devices;
    vr->n_devices = n;
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
    film_free(&vr->film);
    batch_set_free(&vr->done);
    free(vr->rgb);
    free(vr->spare);
    vr->rgb = vr->spare = NULL;
    return st;
}
