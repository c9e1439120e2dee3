/*
 * device_scalar.c — the scalar C device: the kernel stage functions of kernels/ compiled as
 * plain C (one source with the OpenCL build, through kernels/util/compat.h) and run by a pool
 * of pthreads. It is the reference the tests compare OpenCL against, and it renders when
 * no OpenCL platform is installed. The paths' code is compiled in a few builds, each with
 * other kernel features (scalar_paths.h), and a scene runs on the leanest that has its
 * features, as the OpenCL device compiles a program with the scene's features alone.
 *
 * Where the OpenCL device runs the stages as a wavefront (all paths intersect, then all
 * shade, ...), this device runs each path from birth to death before the next, calling
 * the same stage functions in the same order, so each path computes the same bits while
 * its state stays in cache.
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "device/device.h"
#include "device/kernel_features.h"
#include "device/scalar_paths.h"
#include "base/timer.h"

/* The film's kernel source, compiled here as C; the paths' is in scalar_paths_*.c. */
#include "film/film.h"

/* Paths (pixels x samples of the batch) handed to a worker at a time: small enough that
 * the workers finish a batch together (a chunk takes well under a millisecond), large
 * enough that taking work is rare. */
#define CPU_CHUNK_PATHS 1024u

/* The workers live as long as the device and wait between batches, so that a batch
 * costs no thread creation; `generation` counts the batches handed out. */
typedef struct {
    RenderParams params;
    SceneView view;
    unsigned scene_features;     /* the loaded scene's kernel features (kernel_features.h) */
    const ScalarPaths *paths;    /* the leanest build of the kernels that has them */
    int64_t *film;
    int film_stale;              /* holds part of a cancelled batch: cleared before the next */
    int threads;
    pthread_t tids[256];
    int started;                 /* workers running (0: the calling thread renders) */
    pthread_mutex_t lock;
    pthread_cond_t go, done;
    unsigned generation;
    int working;                 /* workers still on the current batch */
    int quit;
    /* the batch being rendered */
    uint first_sample, count, chunk_pixels;
    atomic_uint next_chunk;
    atomic_ullong rays;
    const atomic_int *cancel;    /* the Device's, for the workers */
    atomic_int cancelled;        /* a worker saw the cancel before the batch was whole */
    double *phases;              /* --profile: the Device's phase_seconds (under lock);
                                  * NULL: not profiling */
} CpuDevice;

/* Whether the batch is to be dropped; checked before each chunk, so a cancel is seen
 * within a chunk's time (well under a millisecond) on every worker. */
static int cancel_requested(CpuDevice *cd)
{
    if (!cd->cancel || !atomic_load_explicit(cd->cancel, memory_order_relaxed)) return 0;
    atomic_store(&cd->cancelled, 1);
    return 1;
}

/* Renders chunks of the current batch until none is left or the batch is cancelled. */
static void render_chunks(CpuDevice *cd)
{
    /* the pixels a sample covers: the image's, or the list's (batch_pixel) */
    uint n_pixels = cd->params.pixel_list_size ? cd->params.pixel_list_size : cd->params.width * cd->params.height;
    uint64_t rays = 0;
    double t[PHASE_N] = { 0 };
    const ScalarPaths *paths = cd->paths;
    for (;;) {
        if (cancel_requested(cd)) break;
        uint chunk = atomic_fetch_add(&cd->next_chunk, 1u);
        if (chunk >= (n_pixels + cd->chunk_pixels - 1) / cd->chunk_pixels) break;
        uint begin = chunk * cd->chunk_pixels;
        uint end = n_pixels - begin > cd->chunk_pixels ? begin + cd->chunk_pixels : n_pixels;
        for (uint index = begin; index < end; index++) {
            uint pixel = batch_pixel(&cd->view, index);
            for (uint s = 0; s < cd->count; s++) {
                vec3 L;
                if (cd->params.integrator == INTEGRATOR_PATH && cd->phases) {
                    rays += paths->path_timed(&cd->view, pixel, cd->first_sample + s, &L, t);
                } else if (cd->params.integrator == INTEGRATOR_PATH) {
                    rays += paths->path(&cd->view, pixel, cd->first_sample + s, &L);
                } else {
                    /* the classic ray tracer and the auxiliary images: kernels/integrator/whitted.h */
                    uint n = 0;
                    L = paths->whitted(&cd->view, pixel, cd->first_sample + s, &n);
                    rays += n;
                }
                double t0 = cd->phases ? timer_now() : 0.0;
                film_add(cd->film, pixel, L);
                if (cd->phases) t[PHASE_FILM] += timer_now() - t0;
            }
        }
    }
    atomic_fetch_add(&cd->rays, (unsigned long long)rays);
    if (cd->phases) {
        pthread_mutex_lock(&cd->lock);
        for (int i = 0; i < PHASE_N; i++) cd->phases[i] += t[i] / cd->threads;   /* thread time / threads */
        pthread_mutex_unlock(&cd->lock);
    }
}

static void *cpu_worker(void *arg)
{
    CpuDevice *cd = arg;
    unsigned seen = 0;
    for (;;) {
        pthread_mutex_lock(&cd->lock);
        while (cd->generation == seen && !cd->quit) pthread_cond_wait(&cd->go, &cd->lock);
        seen = cd->generation;
        int quit = cd->quit;
        pthread_mutex_unlock(&cd->lock);
        if (quit) return NULL;
        render_chunks(cd);
        pthread_mutex_lock(&cd->lock);
        if (--cd->working == 0) pthread_cond_signal(&cd->done);
        pthread_mutex_unlock(&cd->lock);
    }
}

static Status cpu_load_scene(Device *d, const DeviceScene *scene, Error *err)
{
    CpuDevice *cd = d->impl;
    uint n_pixels = scene->params.width * scene->params.height;
    free(cd->film);
    cd->film = calloc((size_t)n_pixels * 3u, sizeof *cd->film);
    cd->film_stale = 0;
    if (!cd->film) return error_set(err, ST_INTERNAL, "scalar device: out of memory for the film");
    /* The scene arrays are the host's own: this device reads them in place, except the
     * params block, copied so that update_params can replace it. */
    cd->params = scene->params;
    device_scene_view(scene, &cd->view);
    cd->view.params = &cd->params;
    cd->scene_features = kernel_scene_features(scene);
    cd->paths = scalar_paths_pick(cd->scene_features);
    d->counters.kernel_build = cd->paths->name;
    d->n_pixels = n_pixels;
    d->max_in_flight = 1;
    return ST_OK;
}

static Status cpu_update_params(Device *d, const RenderParams *params, const uint *pixel_list, Error *err)
{
    CpuDevice *cd = d->impl;
    if (params->width != cd->params.width || params->height != cd->params.height)
        return error_set(err, ST_INTERNAL, "scalar device: new render parameters for %ux%u pixels, the scene "
                         "was loaded for %ux%u", params->width, params->height, cd->params.width, cd->params.height);
    cd->params = *params;
    cd->view.pixel_list = pixel_list;
    /* new params may ask for more (a background map, media): as ocl_update_params does */
    cd->scene_features |= kernel_params_features(params);
    cd->paths = scalar_paths_pick(cd->scene_features);
    d->counters.kernel_build = cd->paths->name;
    return ST_OK;
}

static Status cpu_render(Device *d, uint first_sample, uint count, Error *err)
{
    CpuDevice *cd = d->impl;
    if (cd->film_stale) memset(cd->film, 0, (size_t)d->n_pixels * 3u * sizeof *cd->film);
    cd->film_stale = 0;
    cd->first_sample = first_sample;
    cd->count = count;
    cd->chunk_pixels = CPU_CHUNK_PATHS / count ? CPU_CHUNK_PATHS / count : 1u;
    atomic_store(&cd->next_chunk, 0u);
    atomic_store(&cd->rays, 0ull);
    atomic_store(&cd->cancelled, 0);
    cd->cancel = d->cancel;
    if (cd->started == 0) {
        render_chunks(cd);   /* no worker could start: work on this thread */
    } else {
        pthread_mutex_lock(&cd->lock);
        cd->working = cd->started;
        cd->generation++;
        pthread_cond_broadcast(&cd->go);
        while (cd->working > 0) pthread_cond_wait(&cd->done, &cd->lock);
        pthread_mutex_unlock(&cd->lock);
    }
    d->counters.rays += atomic_load(&cd->rays);
    if (atomic_load(&cd->cancelled)) {
        /* Part of the batch is in the film: it is dropped whole, so only whole batches
         * count. Cleared before the next batch, not now: after a stop request there is
         * none, and clearing a large film (1.6 GB at 8192 x 8192, most of it pages
         * never touched) took 2 s of the time to stop. */
        cd->film_stale = 1;
        return error_set(err, ST_INTERRUPTED, "scalar device: batch cancelled");
    }
    d->counters.samples += (uint64_t)(cd->params.pixel_list_size ? cd->params.pixel_list_size : d->n_pixels) * count;
    return ST_OK;
}

static Status cpu_take_film(Device *d, int64_t *film, Error *err)
{
    CpuDevice *cd = d->impl;
    size_t n = (size_t)d->n_pixels * 3u;
    for (size_t i = 0; i < n; i++) film[i] += cd->film[i];
    memset(cd->film, 0, n * sizeof *cd->film);
    (void)err;
    return ST_OK;
}

static void cpu_destroy(Device *d)
{
    CpuDevice *cd = d->impl;
    if (cd) {
        pthread_mutex_lock(&cd->lock);
        cd->quit = 1;
        pthread_cond_broadcast(&cd->go);
        pthread_mutex_unlock(&cd->lock);
        for (int i = 0; i < cd->started; i++) pthread_join(cd->tids[i], NULL);
        pthread_cond_destroy(&cd->go);
        pthread_cond_destroy(&cd->done);
        pthread_mutex_destroy(&cd->lock);
        free(cd->film);
    }
    free(cd);
    free(d);
}

static const DeviceOps cpu_ops = {
    .load_scene = cpu_load_scene,
    .update_params = cpu_update_params,
    .render = cpu_render,
    .take_film = cpu_take_film,
    .destroy = cpu_destroy,
};

Status device_scalar_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err)
{
    Device *d = calloc(1, sizeof *d);
    CpuDevice *cd = calloc(1, sizeof *cd);
    if (!d || !cd) {
        free(d);
        free(cd);
        return error_set(err, ST_INTERNAL, "scalar device: out of memory");
    }
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int threads = cfg && cfg->threads > 0 ? cfg->threads : (int)(cores > 0 ? cores : 1);
    cd->threads = threads > 256 ? 256 : threads;
    cd->phases = cfg && cfg->profile ? d->counters.phase_seconds : NULL;
    pthread_mutex_init(&cd->lock, NULL);
    pthread_cond_init(&cd->go, NULL);
    pthread_cond_init(&cd->done, NULL);
    /* fewer workers than asked when threads cannot be created; none: the caller's */
    while (cd->started < cd->threads && pthread_create(&cd->tids[cd->started], NULL, cpu_worker, cd) == 0)
        cd->started++;
    d->ops = &cpu_ops;
    d->desc = *desc;
    snprintf(d->desc.name, sizeof d->desc.name, "scalar (%d thread%s)", cd->threads, cd->threads == 1 ? "" : "s");
    d->impl = cd;
    *out = d;
    return ST_OK;
}
