/*
 * ocl_waves.c — how the OpenCL device runs a wave of paths (the launch strategies of
 * device_ocl.c's head comment): counted bounces, each launched over exactly the live
 * paths once their count is back (CPUs with --profile); bounded bounces, the whole wave
 * enqueued at once (GPUs); or one megakernel launch (CPUs); and the classic ray
 * tracer's waves.
 */
#include "base/timer.h"
#include "device/ocl_device.h"

/* n work-items of kernel k (named for errors and --profile) in work-groups of `local`
 * (0: the driver's choice); the global size is rounded up to it and the kernels ignore
 * the excess. */
static Status launch_local(OclDevice *od, cl_kernel k, const char *name, uint n, size_t local, Error *err)
{
    if (n == 0) return ST_OK;
    size_t global = local ? ((size_t)n + local - 1) / local * local : (size_t)n;
    cl_event ev = NULL;
    cl_int rc = clEnqueueNDRangeKernel(od->queue, k, 1, NULL, &global, local ? &local : NULL, 0, NULL,
                                       od->phases ? &ev : NULL);
    if (rc != CL_SUCCESS) {
        ocl_fail(err, &od->info, "clEnqueueNDRangeKernel", rc);
        error_prefix(err, "kernel %s over %u items", name, n);
        return ST_DEVICE;
    }
    if (ev) ocld_profile_track(od, ev, ocld_profile_phase_of(name));
    return ST_OK;
}

/* n work-items of k in work-groups of the device's size (OCL_LOCAL_SIZE, or the
 * driver's choice). */
static Status launch(OclDevice *od, cl_kernel k, const char *name, uint n, Error *err)
{
    return launch_local(od, k, name, n, od->local_size, err);
}

/* k_intersect and k_shade of bounce b of wave w over `n` work-items (the live paths, or
 * an upper bound: the kernels stop at the count in slot 2b); k_shade counts into slots
 * 2b + 1 and 2b + 2. */
static Status bounce_kernels(OclDevice *od, WaveSlot *w, uint b, uint n, Error *err)
{
    Status st;
    cl_uint live_slot = 2u * b, slot = 2u * b + 1u;
    cl_kernel k = w->k_intersect;
    ARG(k, ARG_INTERSECT_QUEUE, w->cur);
    ARG(k, ARG_INTERSECT_N, n);
    ARG(k, ARG_INTERSECT_LIVE_SLOT, live_slot);
    if ((st = launch(od, k, "k_intersect", n, err))) return st;
    k = w->k_shade;
    ARG(k, ARG_SHADE_QUEUE, w->cur);
    ARG(k, ARG_SHADE_N, n);
    ARG(k, ARG_SHADE_NEXT_QUEUE, w->next);
    ARG(k, ARG_SHADE_SLOT, slot);
    return launch(od, k, "k_shade", n, err);
}

/* Launches bounce b of wave w over its `n` live paths, then the read-back of the two
 * counts k_shade leaves: the bounce's shadow rays and the next bounce's live paths. */
static Status bounce_launch(OclDevice *od, WaveSlot *w, uint b, uint n, Error *err)
{
    Status st;
    cl_uint slot = 2u * b + 1u;
    if ((st = bounce_kernels(od, w, b, n, err))) return st;
    OCL_TRY("clEnqueueReadBuffer",
            clEnqueueReadBuffer(od->queue, w->counts, CL_FALSE, (size_t)slot * QUEUE_COUNT_STRIDE * sizeof(cl_uint),
                                sizeof w->got, w->got, 0, NULL, &w->read));
    OCL_TRY("clFlush", clFlush(od->queue));
    w->bounce = b;
    w->live = n;
    return ST_OK;
}

/* Adds the finished wave's paths into the batch's film (k_film: one work-item per pixel
 * the wave covers). */
static Status wave_film(OclDevice *od, WaveSlot *w, Error *err)
{
    cl_kernel k = w->k_film;
    ARG(k, ARG_FILM_N_PIXELS, od->batch_pixels);
    ARG(k, ARG_FILM_N_PATHS, w->n_paths);
    ARG(k, ARG_FILM_FILM, od->film);
    return launch(od, k, "k_film", w->n_paths < od->batch_pixels ? w->n_paths : od->batch_pixels, err);
}

/* GPUs: enqueues every bounce of the wave at once, each launch over the wave's size,
 * the kernels stopping at the live count k_shade left on the device (entry.cl); then
 * k_film and one read-back of all the counts. On a GPU a bounce's kernels take tens of
 * microseconds, and waiting for each bounce's counts (the CPU way, bounce_launch) left
 * an H200 idle for half to four fifths of a render (bench/RESULTS.md); the work-items
 * past the count cost next to nothing there. */
static Status wave_enqueue_all(OclDevice *od, WaveSlot *w, Error *err)
{
    Status st;
    uint n = w->n_paths;
    for (uint b = 0; b < od->max_bounces; b++) {
        cl_uint slot = 2u * b + 1u;
        if ((st = bounce_kernels(od, w, b, n, err))) return st;
        cl_kernel k = w->k_shadow;
        ARG(k, ARG_SHADOW_N, n);
        ARG(k, ARG_SHADOW_LIVE_SLOT, slot);
        if ((st = launch(od, k, "k_shadow", n, err))) return st;
        cl_mem t = w->cur;
        w->cur = w->next;
        w->next = t;
    }
    if ((st = wave_film(od, w, err))) return st;
    OCL_TRY("clEnqueueReadBuffer",
            clEnqueueReadBuffer(od->queue, w->counts, CL_FALSE, 0,
                                (2u * (size_t)od->max_bounces + 1u) * QUEUE_COUNT_STRIDE * sizeof(cl_uint),
                                w->all_counts, 0, NULL, &w->read));
    OCL_TRY("clFlush", clFlush(od->queue));
    return ST_OK;
}

/* CPUs: the wave as one k_path launch (each work-item runs its path to the end), then
 * k_film and the read-back of its ray count. */
static Status wave_run_paths(OclDevice *od, WaveSlot *w, Error *err)
{
    Status st;
    cl_kernel k = w->k_path;
    ARG(k, ARG_PATH_FIRST_PIXEL, w->first_pixel);
    ARG(k, ARG_PATH_FIRST_SAMPLE, w->first_sample);
    ARG(k, ARG_PATH_N_PIXELS, od->batch_pixels);
    ARG(k, ARG_PATH_N_PATHS, w->n_paths);
    /* k_path_lanes: work-groups of as many paths as k_path's (KERNEL_SIZE_LANES) */
    uint items = od->lanes ? (w->n_paths + PATH_LANES - 1u) / PATH_LANES : w->n_paths;
    size_t local = od->lanes ? od->local_size / PATH_LANES : od->local_size;
    if ((st = launch_local(od, k, "k_path", items, local, err)) || (st = wave_film(od, w, err))) return st;
    OCL_TRY("clEnqueueReadBuffer", clEnqueueReadBuffer(od->queue, w->counts, CL_FALSE, 0, sizeof w->got, w->got, 0,
                                                       NULL, &w->read));
    OCL_TRY("clFlush", clFlush(od->queue));
    return ST_OK;
}

/* Starts a wave of path numbers [first_pixel, first_pixel + n_paths) counted from pixel
 * number 0 of sample first_sample (entry.cl; od->batch_pixels to a sample). */
Status ocld_wave_start(OclDevice *od, WaveSlot *w, uint first_pixel, uint first_sample, uint n_paths, Error *err)
{
    Status st;
    cl_uint zero = 0;
    cl_event ev = NULL;
    OCL_TRY("clEnqueueFillBuffer",
            clEnqueueFillBuffer(od->queue, w->counts, &zero, sizeof zero, 0,
                                (2u * (size_t)od->max_bounces + 1u) * QUEUE_COUNT_STRIDE * sizeof zero, 0, NULL,
                                od->phases ? &ev : NULL));
    if (ev) ocld_profile_track(od, ev, PHASE_QUEUES);
    w->first_pixel = first_pixel;
    w->first_sample = first_sample;
    w->n_paths = n_paths;
    w->active = 1;
    if (od->path_launch == WAVE_LAUNCH_MEGAKERNEL) return wave_run_paths(od, w, err);
    cl_uint size = n_paths;   /* count slot 0: the paths entering bounce 0 */
    OCL_TRY("clEnqueueFillBuffer",
            clEnqueueFillBuffer(od->queue, w->counts, &size, sizeof size, 0, sizeof size, 0, NULL, NULL));
    cl_kernel k = w->k_raygen;
    ARG(k, ARG_RAYGEN_FIRST_PIXEL, first_pixel);
    ARG(k, ARG_RAYGEN_FIRST_SAMPLE, first_sample);
    ARG(k, ARG_RAYGEN_N_PIXELS, od->batch_pixels);
    ARG(k, ARG_RAYGEN_N_PATHS, n_paths);
    if ((st = launch(od, k, "k_raygen", n_paths, err))) return st;
    w->cur = w->queue_a;
    w->next = w->queue_b;
    return od->path_launch == WAVE_LAUNCH_BOUNDED ? wave_enqueue_all(od, w, err) : bounce_launch(od, w, 0, n_paths, err);
}

/* Waits for the counts of the wave's last bounce, then launches its shadow rays and
 * its next bounce, or, when no path is left, adds the wave into the film. */
Status ocld_wave_advance(OclDevice *od, WaveSlot *w, Error *err)
{
    Status st;
    double t0 = od->phases ? timer_now() : 0.0;
    cl_int rc = clWaitForEvents(1, &w->read);
    if (od->phases) {
        od->phases[PHASE_HOST_WAIT] += timer_now() - t0;
        if (rc == CL_SUCCESS) ocld_profile_add(od, w->read, PHASE_QUEUES);
    }
    ocl_release_event(&w->read);
    if (rc != CL_SUCCESS) return ocl_fail(err, &od->info, "clWaitForEvents", rc);
    if (od->path_launch == WAVE_LAUNCH_MEGAKERNEL) {
        od->rays += (uint64_t)w->got[0] + ((uint64_t)w->got[QUEUE_COUNT_STRIDE] << 32);
        w->active = 0;
        return ST_OK;
    }
    if (od->path_launch == WAVE_LAUNCH_BOUNDED) {
        /* the whole wave ran; its counts say how many rays it traced */
        for (uint b = 0; b < od->max_bounces; b++)
            od->rays += (uint64_t)w->all_counts[2u * b * QUEUE_COUNT_STRIDE] +
                        w->all_counts[(2u * b + 1u) * QUEUE_COUNT_STRIDE];
        w->active = 0;
        return ST_OK;
    }
    uint shadows = w->got[0], next = w->got[QUEUE_COUNT_STRIDE];
    od->rays += (uint64_t)w->live + shadows;
    cl_uint shadow_slot = 2u * w->bounce + 1u;
    cl_kernel k = w->k_shadow;
    ARG(k, ARG_SHADOW_N, shadows);
    ARG(k, ARG_SHADOW_LIVE_SLOT, shadow_slot);
    if ((st = launch(od, k, "k_shadow", shadows, err))) return st;
    if (next > 0 && w->bounce + 1u < od->max_bounces) {
        cl_mem t = w->cur;
        w->cur = w->next;
        w->next = t;
        return bounce_launch(od, w, w->bounce + 1u, next, err);
    }
    w->active = 0;
    return wave_film(od, w, err);
}

/* The classic ray tracer's batch (kernels/integrator/whitted.h): per wave, one k_whitted launch
 * computes every sample whole and counts its rays, then k_film adds the wave as for the
 * path tracer. Waves are numbered as in entry.cl. */
Status ocld_render_whitted(OclDevice *od, uint first_sample, uint64_t total, Error *err)
{
    WaveSlot *w = &od->waves[0];
    Status st;
    for (uint64_t next_path = 0; next_path < total;) {
        if (ocld_cancel_requested(od)) return ST_INTERRUPTED;
        uint n = total - next_path < od->wave_paths ? (uint)(total - next_path) : od->wave_paths;
        uint first_pixel = (uint)(next_path % od->batch_pixels);
        uint sample = first_sample + (uint)(next_path / od->batch_pixels);
        cl_uint zero = 0, count = 0;
        OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, w->counts, &zero, sizeof zero, 0,
                                                           sizeof zero, 0, NULL, NULL));
        cl_kernel k = od->k_whitted;
        ARG(k, ARG_WHITTED_FIRST_PIXEL, first_pixel);
        ARG(k, ARG_WHITTED_FIRST_SAMPLE, sample);
        ARG(k, ARG_WHITTED_N_PIXELS, od->batch_pixels);
        ARG(k, ARG_WHITTED_N_PATHS, n);
        ARG(k, ARG_WHITTED_PATHS, w->paths);
        ARG(k, ARG_WHITTED_COUNTERS, w->counts);
        if ((st = launch(od, k, "k_whitted", n, err))) return st;
        k = od->k_whitted_film;
        ARG(k, ARG_FILM_PATHS, w->paths);
        ARG(k, ARG_FILM_N_PIXELS, od->batch_pixels);
        ARG(k, ARG_FILM_N_PATHS, n);
        ARG(k, ARG_FILM_FILM, od->film);
        if ((st = launch(od, k, "k_film", n < od->batch_pixels ? n : od->batch_pixels, err))) return st;
        OCL_TRY("clEnqueueReadBuffer", clEnqueueReadBuffer(od->queue, w->counts, CL_TRUE, 0, sizeof count, &count,
                                                           0, NULL, NULL));
        od->rays += count;
        next_path += n;
    }
    return ST_OK;
}
