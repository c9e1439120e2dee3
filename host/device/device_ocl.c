/*
 * device_ocl.c — an OpenCL device rendering batches as a wavefront.
 *
 * The scene is uploaded once. A batch is cut into waves of paths numbered sample-major
 * over the image (entry.cl), so every wave is full whatever the image size. Per wave:
 * k_raygen births every path, then each bounce runs k_intersect → k_shade → k_shadow
 * over the live paths only (k_shade compacts survivors into the other queue and counts
 * them), and k_film adds the wave into the batch's device film. Rays, hits and path
 * states never leave the device.
 *
 * Every launch covers exactly the live paths: the host reads the two counts k_shade
 * wrote before it launches the next bounce. So that the device never waits for that
 * round trip, two waves are in flight, each with its own buffers: while the host waits
 * for wave A's counts, the device runs wave B's bounce, and the other way round. (An
 * earlier design launched each bounce over an upper bound without waiting; on PoCL the
 * surplus work-items unbalanced its threads and it was 2-8% slower than exact launches.)
 * That is the CPUs' way ("counted"). On a GPU a bounce's kernels take tens of
 * microseconds and the round trips dominated (an H200 was idle for half to four fifths
 * of a render), so there a wave is enqueued whole ("bounded", wave_enqueue_all): every
 * bounce over the wave's size, each kernel stopping at the live count k_shade left on
 * the device, and the counts read back once, at the end. And on a CPU a wave is one
 * kernel, k_path ("megakernel", wave_run_paths): each work-item runs its path to the
 * end, as the scalar device does, which on PoCL beat both wavefronts (the counted one
 * stays for --profile, whose phases one kernel cannot separate). --wave-launch
 * overrides.
 * Between batches the films are double buffered: the read-back of batch k runs while
 * batch k + 1's kernels run, and take_film collects it afterwards (at most FILM_SLOTS
 * batches in flight, see device.h).
 *
 * The kernels are two programs, each built when a render first needs it, for the
 * features of the loaded scene (KF_* in kernels/types.h: code for materials, textures,
 * backgrounds, primitives and lights the scene does not have is compiled out, which
 * cuts the CPU time of a cold start on PoCL to a third to a half): the path tracer's
 * and the classic ray tracer's (k_whitted with the AOVs).
 * A program built for more features than a later scene needs is kept for it.
 */
#include <stdlib.h>
#include <string.h>

#include "base/timer.h"
#include "device/kernel_features.h"
#include "device/ocl_device.h"
#include "medium/medium.h"

/* What --stats says of the device's waves: their size and how one is run. */
static void note_waves(Device *d, const OclDevice *od)
{
    d->counters.wave_paths = od->wave_paths;
    d->counters.wave_run = od->integrator != INTEGRATOR_PATH                ? "k_whitted"
                           : od->path_launch == WAVE_LAUNCH_COUNTED         ? "counted bounces"
                           : od->path_launch == WAVE_LAUNCH_BOUNDED         ? "bounded bounces"
                           : od->lanes ? "megakernel k_path_lanes, eight paths per work-item"
                                       : "megakernel k_path";
}

static Status ocl_load_scene(Device *d, const DeviceScene *s, Error *err)
{
    OclDevice *od = d->impl;
    double t0 = timer_now();
    ocld_release_buffers(od);
    const RenderParams *p = &s->params;
    SceneBufferBytes in[SCENE_N];
    for (unsigned i = 0; i < SCENE_N; i++) in[i] = device_scene_buffer(s, i);
    uint n_pixels = p->width * p->height;
    od->max_bounces = path_max_shades(p->max_depth, p->has_media);
    Status st = ocld_alloc_render(od, in, n_pixels, err);
    if (st) return st;
    d->counters.bytes_in_place = od->bytes_in_place;
    od->n_pixels = n_pixels;
    od->batch_pixels = p->pixel_list_size ? p->pixel_list_size : n_pixels;
    /* a program built for an earlier scene serves this one if it has its features */
    od->scene_features = kernel_scene_features(s);
    od->path_launch = s->params.split > 1u ? WAVE_LAUNCH_MEGAKERNEL : od->launch;
    od->lanes_scene = od->cpu && od->path_launch == WAVE_LAUNCH_MEGAKERNEL && kernel_lanes_scene(s, od->scene_features);
    od->lanes = od->lanes_scene && kernel_lanes_params(&s->params);
    for (int i = 0; i < PROG_N; i++) {
        unsigned need = od->scene_features | ocld_program_kernels(od, i);
        if ((od->features[i] & need) != need) ocld_release_program(od, i);
        else if ((st = ocld_set_program_args(od, i, err))) return st;
    }
    d->counters.upload_seconds += timer_now() - t0;
    t0 = timer_now();
    if ((st = ocld_need_program(d, od, p->integrator, err))) return st;
    od->integrator = p->integrator;
    note_waves(d, od);
    d->n_pixels = n_pixels;
    d->max_in_flight = od->n_slots;
    return ST_OK;
}

/* The params block is written in place (the buffer keeps its size); the pixel list
 * gets a buffer of its own size, set as every kernel's argument. */
static Status ocl_update_params(Device *d, const RenderParams *p, const uint *pixel_list, Error *err)
{
    OclDevice *od = d->impl;
    if (p->width * p->height != od->n_pixels)
        return error_set(err, ST_INTERNAL, "device '%s': new render parameters for %ux%u pixels, the scene was "
                         "loaded for %u pixels", od->info.name, p->width, p->height, od->n_pixels);
    double t0 = timer_now();
    Status st;
    /* every launch so far has read the old block and list */
    OCL_TRY("clFinish", clFinish(od->queue));
    OCL_TRY("clEnqueueWriteBuffer", clEnqueueWriteBuffer(od->queue, od->scene[SCENE_BUF_params], CL_TRUE, 0,
                                                         sizeof *p, p, 0, NULL, NULL));
    ocl_release_mem(&od->scene[SCENE_BUF_pixel_list]);
    size_t list_bytes = pixel_list ? (size_t)p->pixel_list_size * sizeof(uint) : 0;
    if ((st = ocld_make_buffer(od, CL_MEM_READ_ONLY, OCL_READ_IN_ORDER, list_bytes, pixel_list, "pixel list",
                          &od->scene[SCENE_BUF_pixel_list], err)) ||
        (st = ocld_set_scene_arg(od, SCENE_BUF_pixel_list, err)) || (st = ocld_grow_counts(od, path_max_shades(p->max_depth, p->has_media), err)))
        return st;
    od->batch_pixels = p->pixel_list_size ? p->pixel_list_size : od->n_pixels;
    od->max_bounces = path_max_shades(p->max_depth, p->has_media);
    d->counters.upload_seconds += timer_now() - t0;
    od->scene_features |= kernel_params_features(p);
    od->path_launch = p->split > 1u ? WAVE_LAUNCH_MEGAKERNEL : od->launch;
    od->lanes = od->lanes_scene && kernel_lanes_params(p);
    if ((st = ocld_need_program(d, od, p->integrator, err))) return st;
    od->integrator = p->integrator;
    note_waves(d, od);
    return ST_OK;
}

/* Drops a cancelled batch: lets what was enqueued finish (nothing may still write to
 * the film or to the wave buffers), forgets the waves and marks the batch's film to be
 * cleared before the slot's next batch (ocl_render): after a stop request there is
 * none, and clearing a large film (400 MB at 4096 x 4096) is time the stop would wait
 * for. The batches before, with their read-backs, are whole and stay to be taken. */
static Status cancel_batch(OclDevice *od, FilmSlot *fs, Error *err)
{
    OCL_TRY("clFinish", clFinish(od->queue));
    for (int i = 0; i < WAVE_SLOTS; i++) {
        ocl_release_event(&od->waves[i].read);
        od->waves[i].active = 0;
    }
    fs->stale = 1;
    return error_set(err, ST_INTERRUPTED, "device '%s': batch cancelled", od->info.name);
}

static Status ocl_render(Device *d, uint first_sample, uint count, Error *err)
{
    OclDevice *od = d->impl;
    FilmSlot *fs = &od->slots[od->head % od->n_slots];
    if (fs->read_done)
        return error_set(err, ST_INTERNAL, "device '%s': more than %u batches in flight", od->info.name, od->n_slots);
    /* paths are numbered over the pixels a sample covers (entry.cl); the film holds all */
    uint64_t n_pixels = od->batch_pixels, total = n_pixels * count;
    if (fs->stale) {
        /* in order on the queue: cleared before the batch's kernels add to it */
        cl_long zero = 0;
        OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, fs->film, &zero, sizeof zero, 0,
                                                           (size_t)od->n_pixels * 3u * sizeof(cl_long), 0, NULL, NULL));
        fs->stale = 0;
    }
    /* Waves of equal size, at least two when the batch is big enough to split. */
    uint64_t n_waves = (total + od->wave_paths - 1) / od->wave_paths;
    if (n_waves < WAVE_SLOTS && total >= (uint64_t)WAVE_SLOTS * MIN_SPLIT_PATHS) n_waves = WAVE_SLOTS;
    uint64_t wave = (total + n_waves - 1) / n_waves, next_path = 0;
    od->film = fs->film;
    od->cancel = d->cancel;
    od->rays = 0;
    Status st = ST_OK;
    for (int i = 0; i < WAVE_SLOTS; i++) od->waves[i].active = 0;
    if (od->integrator != INTEGRATOR_PATH) {
        st = ocld_render_whitted(od, first_sample, total, err);
        total = 0;   /* the wave loop below then has nothing to do */
    }
    for (; st == ST_OK;) {
        if (ocld_cancel_requested(od)) {
            st = ST_INTERRUPTED;
            break;
        }
        int any = 0;
        for (int i = 0; i < WAVE_SLOTS && st == ST_OK; i++) {
            WaveSlot *w = &od->waves[i];
            if (w->active) st = ocld_wave_advance(od, w, err);
            if (st == ST_OK && !w->active && next_path < total) {
                uint n = total - next_path < wave ? (uint)(total - next_path) : (uint)wave;
                st = ocld_wave_start(od, w, (uint)(next_path % n_pixels), first_sample + (uint)(next_path / n_pixels), n, err);
                next_path += n;
            }
            any |= w->active;
        }
        if (st != ST_OK || !any) break;
    }
    if (st == ST_INTERRUPTED) return cancel_batch(od, fs, err);
    if (st != ST_OK) {
        for (int i = 0; i < WAVE_SLOTS; i++) ocl_release_event(&od->waves[i].read);
        return st;
    }
    /* The film comes back while the next batch renders; zeroed on the device after. */
    size_t bytes = (size_t)od->n_pixels * 3u * sizeof(cl_long);
    OCL_TRY("clEnqueueReadBuffer", clEnqueueReadBuffer(od->queue, fs->film, CL_FALSE, 0, bytes, fs->host, 0, NULL,
                                                       &fs->read_done));
    cl_long zero = 0;
    cl_event ev = NULL;
    OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, fs->film, &zero, sizeof zero, 0, bytes, 0, NULL,
                                                       od->phases ? &ev : NULL));
    if (ev) ocld_profile_track(od, ev, PHASE_FILM);
    OCL_TRY("clFlush", clFlush(od->queue));
    od->head++;
    d->counters.samples += n_pixels * count;
    d->counters.rays += od->rays;
    return ST_OK;
}

static Status ocl_take_film(Device *d, int64_t *film, Error *err)
{
    OclDevice *od = d->impl;
    FilmSlot *fs = &od->slots[od->tail % od->n_slots];
    if (!fs->read_done) return error_set(err, ST_INTERNAL, "device '%s': no batch to take", od->info.name);
    double t0 = od->phases ? timer_now() : 0.0;
    OCL_TRY("clWaitForEvents", clWaitForEvents(1, &fs->read_done));
    if (od->phases) {
        od->phases[PHASE_HOST_WAIT] += timer_now() - t0;
        ocld_profile_add(od, fs->read_done, PHASE_FILM);
        ocld_profile_collect(od);
    }
    ocl_release_event(&fs->read_done);
    od->tail++;
    size_t n = (size_t)od->n_pixels * 3u;
    for (size_t i = 0; i < n; i++) film[i] += fs->host[i];
    return ST_OK;
}

static void ocl_destroy(Device *d)
{
    OclDevice *od = d->impl;
    if (od) {
        ocld_release_buffers(od);   /* finishes the queue: every tracked command is complete */
        ocld_profile_free(od);
        for (int i = 0; i < PROG_N; i++) ocld_release_program(od, i);
        free(od->kernel_dir);
        if (od->queue) clReleaseCommandQueue(od->queue);
        if (od->ctx) clReleaseContext(od->ctx);
        free(od);
    }
    free(d);
}

static const DeviceOps ocl_ops = {
    .load_scene = ocl_load_scene,
    .update_params = ocl_update_params,
    .render = ocl_render,
    .take_film = ocl_take_film,
    .destroy = ocl_destroy,
};

static Status ocl_setup(Device *d, OclDevice *od, const DeviceConfig *cfg, Error *err)
{
    cl_int rc;
    cl_context_properties props[] = { CL_CONTEXT_PLATFORM, (cl_context_properties)od->info.platform, 0 };
    od->ctx = clCreateContext(props, 1, &od->info.id, NULL, NULL, &rc);
    if (rc != CL_SUCCESS) return ocl_fail(err, &od->info, "clCreateContext", rc);
    int profile = cfg && cfg->profile;
    od->queue = clCreateCommandQueue(od->ctx, od->info.id, profile ? CL_QUEUE_PROFILING_ENABLE : 0, &rc);
    od->phases = profile ? d->counters.phase_seconds : NULL;
    if (rc != CL_SUCCESS) return ocl_fail(err, &od->info, "clCreateCommandQueue", rc);
    /* the programs are built by load_scene, which knows what the scene needs */
    if (cfg && cfg->kernel_dir && !(od->kernel_dir = strdup(cfg->kernel_dir)))
        return error_set(err, ST_INTERNAL, "out of memory opening device '%s'", od->info.name);
    int gpu = (od->info.type & CL_DEVICE_TYPE_GPU) != 0;
    /* A GPU needs about a million paths in flight to hide memory latency, and larger
     * waves cost fewer launches per path: on an H200, 2^22 paths rendered 6-28% faster
     * than 2^20 with bounded launches and 11-41% with counted ones (1024x1024 renders,
     * bench/RESULTS.md). 2^22 paths take about 650 MB a wave, so only GPUs with 8 GiB or
     * more get them. A CPU is full with far fewer, but each wave ends with its threads
     * waiting for the slowest work-group and for the host, and that wait grows with the
     * threads: 2^16 paths per compute unit (a power of two, at most 2^21). On 2 cores
     * 2^16, 2^17 and 2^18 paths measured the same (2^14 a few percent and 2^12 a tenth
     * slower); on 16 cores (PoCL 5.0, a Xeon) 2^20 rendered 14-31% faster than 2^16
     * and 2^21 the same as 2^20 (bench/RESULTS.md). */
    uint gpu_wave = od->info.global_mem >= (8ull << 30) ? (1u << 22) : (1u << 20);
    uint cpu_wave = 1u << 16;
    while (cpu_wave < (1u << 21) && (cpu_wave >> 16) * 2u <= od->info.compute_units) cpu_wave <<= 1;
    od->wave_fallback = gpu ? 1u << 20 : 1u << 16;
    uint wave_default = gpu ? gpu_wave : cpu_wave;
    od->wave_paths = cfg && cfg->wave_paths ? cfg->wave_paths : wave_default;
    od->wave_auto = cfg && cfg->wave_paths ? 0u : (wave_default > od->wave_fallback ? wave_default : 0u);
    od->local_size = od->info.max_work_group >= OCL_LOCAL_SIZE ? OCL_LOCAL_SIZE : 0;
    od->cpu = (od->info.type & CL_DEVICE_TYPE_CPU) != 0;
    od->launch = cfg && cfg->wave_launch ? cfg->wave_launch
                 : gpu ? WAVE_LAUNCH_BOUNDED : profile ? WAVE_LAUNCH_COUNTED : WAVE_LAUNCH_MEGAKERNEL;
    return ST_OK;
}

/* The OpenCL description of the device `desc` lists (its handles are opaque outside
 * this file), with the memory sizes the listing reports (they may carry a test cap). */
static Status ocl_find(const DeviceDesc *desc, OclDeviceInfo *info, Error *err)
{
    OclDeviceInfo *all = NULL;
    size_t n = 0;
    Status st = ocl_enumerate(&all, &n, err);
    if (st) return st;
    size_t i = 0;
    while (i < n && all[i].id != (cl_device_id)desc->ocl_device) i++;
    if (i == n) {
        free(all);
        return error_set(err, ST_DEVICE, "device '%s': no longer listed by OpenCL", desc->name);
    }
    *info = all[i];
    info->global_mem = desc->global_mem;
    info->max_alloc = desc->max_alloc;
    free(all);
    return ST_OK;
}

Status device_ocl_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err)
{
    Device *d = calloc(1, sizeof *d);
    OclDevice *od = calloc(1, sizeof *od);
    if (!d || !od) {
        free(d);
        free(od);
        return error_set(err, ST_INTERNAL, "out of memory opening device '%s'", desc->name);
    }
    d->ops = &ocl_ops;
    d->desc = *desc;
    d->impl = od;
    Status st = ocl_find(desc, &od->info, err);
    if (st == ST_OK) st = ocl_setup(d, od, cfg, err);
    if (st) {
        ocl_destroy(d);
        return st;
    }
    *out = d;
    return ST_OK;
}
