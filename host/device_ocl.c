/*
 * device_ocl.c — an OpenCL device rendering batches as a wavefront.
 *
 * The scene is uploaded once. A batch is cut into waves of `wave_paths` paths, numbered
 * sample-major over the image, so every wave but a batch's last is full. Per wave:
 * k_raygen births every path, then each bounce runs k_intersect → k_shade → k_shadow
 * over the queue of live paths only (k_shade compacts survivors into the other queue),
 * and k_film adds the wave into the batch's device film. Rays, hits and path states
 * never leave the device.
 *
 * The host never waits for the device to go idle inside a batch. The queue lengths stay
 * on the device (entry.cl); the host launches bounce b over an upper bound of its live
 * paths — the exact count of bounce b when its read-back has already arrived, else the
 * count of bounce b - 1 — while the device still works on bounce b - 1, and it stops
 * launching once a count reads zero. Work-items beyond the device-side count return at
 * once. Between batches the films are double buffered: the read-back of batch k runs
 * while batch k + 1's kernels run, and take_film collects it afterwards (at most
 * FILM_SLOTS batches in flight, see device.h).
 */
#include <stdlib.h>
#include <string.h>

#include "device.h"
#include "ocl_program.h"
#include "timer.h"

/* Work-group size for every launch: a multiple of every GPU's SIMD width; the global
 * size is rounded up to it and the kernels ignore the excess work-items. On PoCL 3.1
 * (CPU) sizes 8 to 128 measured the same. */
#define OCL_LOCAL_SIZE 64u
/* Device films: one being rendered into while the previous one is read back. */
#define FILM_SLOTS 2
/* Waves whose count read-backs may still be in flight (for the ray statistics). */
#define COUNT_RING 4

enum { SCENE_PARAMS, SCENE_NODES, SCENE_LEAF_PRIMS, SCENE_SPHERES, SCENE_TRIANGLES,
       SCENE_BOXES, SCENE_PLANES, SCENE_MATERIALS, SCENE_LIGHTS, SCENE_SHADING, SCENE_N };

/* A batch's film on the device and where its read-back lands. */
typedef struct {
    cl_mem film;
    int64_t *host;
    cl_event read_done;     /* the read-back in flight; NULL while the slot is free */
} FilmSlot;

/* The queue lengths of one wave as read back, in the device's layout (entry.cl): slot 2b
 * live paths and slot 2b + 1 shadow rays at bounce b, QUEUE_COUNT_STRIDE apart. */
typedef struct {
    cl_uint *counts;
    cl_event last_read;     /* the wave's last count read-back; NULL when accounted */
    uint n_bounces;
} WaveCounts;

typedef struct {
    OclDeviceInfo info;
    cl_context ctx;
    cl_command_queue queue;
    cl_program program;
    cl_kernel k_raygen, k_intersect, k_shade, k_shadow, k_film;
    cl_mem scene[SCENE_N];
    cl_mem paths, rays, hits, shadow_rays, queue_a, queue_b, shadow_queue, counts;
    FilmSlot slots[FILM_SLOTS];
    uint n_slots;           /* 2, or 1 when two films do not fit the device */
    uint head, tail;        /* batches rendered and taken, counted from 0 */
    WaveCounts ring[COUNT_RING];
    uint ring_next;
    uint max_bounces;       /* bounces 0 .. max_depth: 2 * max_bounces + 1 count slots */
    uint wave_paths;        /* capacity of the wave buffers */
    int has_lights;         /* else no shadow rays: k_shadow is not launched */
    size_t local_size;      /* 0: let the driver choose */
    uint n_pixels;
} OclDevice;

#define OCL_TRY(call_name, expr)                                                       \
    do {                                                                               \
        cl_int rc_ = (expr);                                                           \
        if (rc_ != CL_SUCCESS) return ocl_fail(err, &od->info, call_name, rc_);        \
    } while (0)

static void release_mem(cl_mem *m)
{
    if (*m) clReleaseMemObject(*m);
    *m = NULL;
}

static void release_event(cl_event *e)
{
    if (*e) clReleaseEvent(*e);
    *e = NULL;
}

static void release_buffers(OclDevice *od)
{
    /* events first: a pending read-back must not land in freed memory */
    if (od->queue) clFinish(od->queue);
    for (int i = 0; i < SCENE_N; i++) release_mem(&od->scene[i]);
    release_mem(&od->paths);
    release_mem(&od->rays);
    release_mem(&od->hits);
    release_mem(&od->shadow_rays);
    release_mem(&od->queue_a);
    release_mem(&od->queue_b);
    release_mem(&od->shadow_queue);
    release_mem(&od->counts);
    for (int i = 0; i < FILM_SLOTS; i++) {
        release_event(&od->slots[i].read_done);
        release_mem(&od->slots[i].film);
        free(od->slots[i].host);
        od->slots[i].host = NULL;
    }
    for (int i = 0; i < COUNT_RING; i++) {
        release_event(&od->ring[i].last_read);
        free(od->ring[i].counts);
        od->ring[i].counts = NULL;
    }
    od->head = od->tail = 0;
}

/* A device buffer of `bytes` (at least 16: OpenCL has no empty buffers), filled from
 * `src` when given. */
static Status make_buffer(OclDevice *od, cl_mem_flags flags, size_t bytes, const void *src,
                          const char *what, cl_mem *out, Error *err)
{
    size_t size = bytes < 16 ? 16 : bytes;
    if ((cl_ulong)size > od->info.max_alloc)
        return error_set(err, ST_DEVICE,
                         "device '%s': the %s need %.1f MiB, more than the device's largest allocation (%.1f MiB)",
                         od->info.name, what, (double)size / 1048576.0, (double)od->info.max_alloc / 1048576.0);
    cl_int rc;
    *out = clCreateBuffer(od->ctx, flags | (src && bytes ? CL_MEM_COPY_HOST_PTR : 0), size,
                          src && bytes ? (void *)(uintptr_t)src : NULL, &rc);
    if (rc != CL_SUCCESS) {
        ocl_fail(err, &od->info, "clCreateBuffer", rc);
        error_prefix(err, "allocating %.1f MiB for the %s", (double)size / 1048576.0, what);
        return ST_DEVICE;
    }
    return ST_OK;
}

static Status set_arg(OclDevice *od, cl_kernel k, cl_uint i, size_t size, const void *value, Error *err)
{
    OCL_TRY("clSetKernelArg", clSetKernelArg(k, i, size, value));
    return ST_OK;
}

#define ARG(k, i, v) do { Status st_ = set_arg(od, k, i, sizeof(v), &(v), err); if (st_) return st_; } while (0)

static Status set_scene_args(OclDevice *od, cl_kernel k, Error *err)
{
    for (cl_uint i = 0; i < SCENE_N; i++) ARG(k, i, od->scene[i]);
    return ST_OK;
}

/* The arguments that stay the same for the whole render, set once after the upload;
 * only queues, slots, wave positions and the film change per launch. */
static Status set_fixed_args(OclDevice *od, Error *err)
{
    Status st;
    if ((st = set_scene_args(od, od->k_intersect, err)) || (st = set_scene_args(od, od->k_shade, err)) ||
        (st = set_scene_args(od, od->k_shadow, err)))
        return st;
    cl_kernel k = od->k_raygen;
    ARG(k, 0, od->scene[SCENE_PARAMS]);
    ARG(k, 3, od->n_pixels);
    ARG(k, 5, od->paths);
    ARG(k, 6, od->rays);
    ARG(k, 7, od->queue_a);
    ARG(k, 8, od->counts);
    k = od->k_intersect;
    ARG(k, SCENE_N + 1, od->counts);
    ARG(k, SCENE_N + 3, od->rays);
    ARG(k, SCENE_N + 4, od->hits);
    k = od->k_shade;
    ARG(k, SCENE_N + 1, od->counts);
    ARG(k, SCENE_N + 3, od->rays);
    ARG(k, SCENE_N + 4, od->hits);
    ARG(k, SCENE_N + 5, od->paths);
    ARG(k, SCENE_N + 6, od->shadow_rays);
    ARG(k, SCENE_N + 8, od->shadow_queue);
    k = od->k_shadow;
    ARG(k, SCENE_N + 0, od->shadow_queue);
    ARG(k, SCENE_N + 1, od->counts);
    ARG(k, SCENE_N + 3, od->shadow_rays);
    ARG(k, SCENE_N + 4, od->paths);
    k = od->k_film;
    ARG(k, 0, od->paths);
    ARG(k, 2, od->n_pixels);
    return ST_OK;
}

static Status launch(OclDevice *od, cl_kernel k, const char *name, uint n, Error *err)
{
    if (n == 0) return ST_OK;
    size_t local = od->local_size;
    size_t global = local ? ((size_t)n + local - 1) / local * local : (size_t)n;
    cl_int rc = clEnqueueNDRangeKernel(od->queue, k, 1, NULL, &global, local ? &local : NULL, 0, NULL, NULL);
    if (rc != CL_SUCCESS) {
        ocl_fail(err, &od->info, "clEnqueueNDRangeKernel", rc);
        error_prefix(err, "kernel %s over %u items", name, n);
        return ST_DEVICE;
    }
    return ST_OK;
}

/* 1 when the command of `ev` has finished, 0 while it runs; an error when it failed. */
static Status event_done(OclDevice *od, cl_event ev, int *done, Error *err)
{
    cl_int status;
    OCL_TRY("clGetEventInfo", clGetEventInfo(ev, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status, &status, NULL));
    if (status < 0) return ocl_failf(err, &od->info, "a queued command", status, "reported by its event");
    *done = status == CL_COMPLETE;
    return ST_OK;
}

/* Adds the rays of a wave whose counts have arrived to the statistics; with `wait` it
 * waits for them, otherwise a wave still in flight is left for later. */
static Status account_wave(Device *d, WaveCounts *wc, int wait, Error *err)
{
    OclDevice *od = d->impl;
    if (!wc->last_read) return ST_OK;
    if (wait) {
        OCL_TRY("clWaitForEvents", clWaitForEvents(1, &wc->last_read));
    } else {
        int done = 0;
        Status st = event_done(od, wc->last_read, &done, err);
        if (st || !done) return st;
    }
    uint64_t rays = 0;
    for (uint b = 0; b < wc->n_bounces; b++)
        rays += (uint64_t)wc->counts[2 * b * QUEUE_COUNT_STRIDE] + wc->counts[(2 * b + 1) * QUEUE_COUNT_STRIDE];
    d->counters.rays += rays;
    release_event(&wc->last_read);
    return ST_OK;
}

static Status ocl_load_scene(Device *d, const DeviceScene *s, Error *err)
{
    OclDevice *od = d->impl;
    double t0 = timer_now();
    release_buffers(od);
    const RenderParams *p = &s->params;
    struct { const void *src; size_t bytes; const char *what; } in[SCENE_N] = {
        { p, sizeof *p, "render parameters" },
        { s->nodes, (size_t)p->n_nodes * sizeof(KdNode), "kd-tree nodes" },
        { s->leaf_prims, (size_t)p->n_leaf_prims * sizeof(uint), "kd-tree leaf lists" },
        { s->spheres, (size_t)p->n_spheres * sizeof(Sphere), "spheres" },
        { s->triangles, (size_t)p->n_triangles * sizeof(Triangle), "triangles" },
        { s->boxes, (size_t)p->n_boxes * sizeof(Box), "boxes" },
        { s->planes, (size_t)p->n_planes * sizeof(Plane), "planes" },
        { s->materials, (size_t)s->n_materials * sizeof(Material), "materials" },
        { s->lights, (size_t)p->n_lights * sizeof(Light), "lights" },
        { s->shading, (size_t)s->n_shading * sizeof(TriShading), "shading normals" },
    };
    cl_ulong total = 0;
    for (int i = 0; i < SCENE_N; i++) total += in[i].bytes;
    uint n_pixels = p->width * p->height;
    uint wave = od->wave_paths;
    od->max_bounces = p->max_depth + 1u;
    size_t counts_bytes = (2u * (size_t)od->max_bounces + 1u) * QUEUE_COUNT_STRIDE * sizeof(cl_uint);
    size_t film_bytes = (size_t)n_pixels * 3u * sizeof(cl_long);
    cl_ulong wave_bytes = (cl_ulong)wave * (sizeof(PathState) + 2 * sizeof(Ray) + sizeof(Hit) + 3 * sizeof(uint));
    /* Double-buffered films when they fit, else one: the device then waits for each
     * read-back, nothing worse. */
    od->n_slots = total + 2 * (cl_ulong)film_bytes + wave_bytes <= od->info.global_mem ? 2 : 1;
    if (total + film_bytes + wave_bytes > od->info.global_mem)
        return error_set(err, ST_DEVICE,
                         "device '%s': the scene (%.1f MiB), film (%.1f MiB) and path buffers (%.1f MiB) "
                         "do not fit its %.1f MiB of memory",
                         od->info.name, (double)total / 1048576.0, (double)film_bytes / 1048576.0,
                         (double)wave_bytes / 1048576.0, (double)od->info.global_mem / 1048576.0);
    Status st;
    for (int i = 0; i < SCENE_N; i++)
        if ((st = make_buffer(od, CL_MEM_READ_ONLY, in[i].bytes, in[i].src, in[i].what, &od->scene[i], err)))
            return st;
    if ((st = make_buffer(od, CL_MEM_READ_WRITE, (size_t)wave * sizeof(PathState), NULL, "path states", &od->paths, err)) ||
        (st = make_buffer(od, CL_MEM_READ_WRITE, (size_t)wave * sizeof(Ray), NULL, "rays", &od->rays, err)) ||
        (st = make_buffer(od, CL_MEM_READ_WRITE, (size_t)wave * sizeof(Hit), NULL, "hits", &od->hits, err)) ||
        (st = make_buffer(od, CL_MEM_READ_WRITE, (size_t)wave * sizeof(Ray), NULL, "shadow rays", &od->shadow_rays, err)) ||
        (st = make_buffer(od, CL_MEM_READ_WRITE, (size_t)wave * sizeof(uint), NULL, "path queue", &od->queue_a, err)) ||
        (st = make_buffer(od, CL_MEM_READ_WRITE, (size_t)wave * sizeof(uint), NULL, "path queue", &od->queue_b, err)) ||
        (st = make_buffer(od, CL_MEM_READ_WRITE, (size_t)wave * sizeof(uint), NULL, "shadow queue", &od->shadow_queue, err)) ||
        (st = make_buffer(od, CL_MEM_READ_WRITE, counts_bytes, NULL, "queue counters", &od->counts, err)))
        return st;
    cl_long zero = 0;
    for (uint i = 0; i < od->n_slots; i++) {
        FilmSlot *fs = &od->slots[i];
        if ((st = make_buffer(od, CL_MEM_READ_WRITE, film_bytes, NULL, "film", &fs->film, err))) return st;
        if (!(fs->host = malloc(film_bytes < 16 ? 16 : film_bytes)))
            return error_set(err, ST_INTERNAL, "out of memory for the read-back of the film");
        OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, fs->film, &zero, sizeof zero, 0,
                                                           film_bytes < 16 ? 16 : film_bytes, 0, NULL, NULL));
    }
    for (int i = 0; i < COUNT_RING; i++)
        if (!(od->ring[i].counts = calloc(counts_bytes, 1)))
            return error_set(err, ST_INTERNAL, "out of memory for queue counters");
    OCL_TRY("clFinish", clFinish(od->queue));
    od->n_pixels = n_pixels;
    od->has_lights = p->n_lights > 0;
    if ((st = set_fixed_args(od, err))) return st;
    d->n_pixels = n_pixels;
    d->max_in_flight = od->n_slots;
    d->counters.upload_seconds += timer_now() - t0;
    return ST_OK;
}

/* One wave: path numbers [first_pixel, first_pixel + n_paths) counted from pixel 0 of
 * sample `first_sample` (entry.cl), added into `film`. */
static Status render_wave(Device *d, cl_mem film, uint first_pixel, uint first_sample, uint n_paths, Error *err)
{
    OclDevice *od = d->impl;
    Status st;
    WaveCounts *wc = &od->ring[od->ring_next];
    od->ring_next = (od->ring_next + 1) % COUNT_RING;
    if ((st = account_wave(d, wc, 1, err))) return st;
    cl_uint *hc = wc->counts;
    hc[0] = n_paths;

    cl_uint zero = 0;
    OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, od->counts, &zero, sizeof zero, 0,
                                                       (2u * (size_t)od->max_bounces + 1u) * QUEUE_COUNT_STRIDE *
                                                           sizeof zero, 0, NULL, NULL));
    cl_kernel k = od->k_raygen;
    ARG(k, 1, first_pixel);
    ARG(k, 2, first_sample);
    ARG(k, 4, n_paths);
    if ((st = launch(od, k, "k_raygen", n_paths, err))) return st;

    cl_mem cur = od->queue_a, next = od->queue_b;
    cl_event prev = NULL, ev = NULL;
    uint bound = n_paths, b = 0;
    for (;;) {
        cl_uint slot = 2u * b, shadow_slot = 2u * b + 1u;
        k = od->k_intersect;
        ARG(k, SCENE_N + 0, cur);
        ARG(k, SCENE_N + 2, slot);
        if ((st = launch(od, k, "k_intersect", bound, err))) goto fail;
        k = od->k_shade;
        ARG(k, SCENE_N + 0, cur);
        ARG(k, SCENE_N + 2, slot);
        ARG(k, SCENE_N + 7, next);
        if ((st = launch(od, k, "k_shade", bound, err))) goto fail;
        /* without lights there are no shadow rays (and each launch costs PoCL some
         * tens of microseconds) */
        k = od->k_shadow;
        ARG(k, SCENE_N + 2, shadow_slot);
        if (od->has_lights && (st = launch(od, k, "k_shadow", bound, err))) goto fail;
        /* slots 2b + 1 and 2b + 2: the shadow rays of this bounce, the live paths of the next */
        size_t at = shadow_slot * QUEUE_COUNT_STRIDE;
        cl_int rc = clEnqueueReadBuffer(od->queue, od->counts, CL_FALSE, at * sizeof(cl_uint),
                                        (QUEUE_COUNT_STRIDE + 1) * sizeof(cl_uint), &hc[at], 0, NULL, &ev);
        if (rc == CL_SUCCESS) rc = clFlush(od->queue);
        if (rc != CL_SUCCESS) {
            st = ocl_fail(err, &od->info, "clEnqueueReadBuffer", rc);
            goto fail;
        }
        b++;
        /* While the device runs bounce b - 1, learn how many paths bounce b - 2 left
         * alive: a bound for bounce b, unless bounce b's own count is already in. */
        if (prev) {
            rc = clWaitForEvents(1, &prev);
            release_event(&prev);
            if (rc != CL_SUCCESS) {
                st = ocl_fail(err, &od->info, "clWaitForEvents", rc);
                goto fail;
            }
        }
        prev = ev;
        ev = NULL;
        int have_next = 0;
        if ((st = event_done(od, prev, &have_next, err))) goto fail;
        bound = have_next ? hc[2u * b * QUEUE_COUNT_STRIDE] : hc[2u * (b - 1u) * QUEUE_COUNT_STRIDE];
        if (bound == 0 || b >= od->max_bounces) break;
        cl_mem t = cur;
        cur = next;
        next = t;
    }
    wc->last_read = prev;
    wc->n_bounces = b;

    k = od->k_film;
    ARG(k, 1, first_pixel);
    ARG(k, 3, n_paths);
    ARG(k, 4, film);
    return launch(od, k, "k_film", n_paths < od->n_pixels ? n_paths : od->n_pixels, err);

fail:
    release_event(&prev);
    release_event(&ev);
    return st;
}

static Status ocl_render(Device *d, uint first_sample, uint count, Error *err)
{
    OclDevice *od = d->impl;
    FilmSlot *fs = &od->slots[od->head % od->n_slots];
    if (fs->read_done)
        return error_set(err, ST_INTERNAL, "device '%s': more than %u batches in flight", od->info.name, od->n_slots);
    uint64_t n_pixels = od->n_pixels, total = n_pixels * count;
    Status st;
    for (uint64_t p0 = 0; p0 < total; p0 += od->wave_paths) {
        uint n = total - p0 < od->wave_paths ? (uint)(total - p0) : od->wave_paths;
        if ((st = render_wave(d, fs->film, (uint)(p0 % n_pixels), first_sample + (uint)(p0 / n_pixels), n, err)))
            return st;
    }
    /* The film comes back while the next batch renders; zeroed on the device after. */
    size_t bytes = (size_t)n_pixels * 3u * sizeof(cl_long);
    OCL_TRY("clEnqueueReadBuffer", clEnqueueReadBuffer(od->queue, fs->film, CL_FALSE, 0, bytes, fs->host, 0, NULL,
                                                       &fs->read_done));
    cl_long zero = 0;
    OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, fs->film, &zero, sizeof zero, 0, bytes, 0, NULL, NULL));
    OCL_TRY("clFlush", clFlush(od->queue));
    od->head++;
    d->counters.samples += n_pixels * count;
    return ST_OK;
}

static Status ocl_take_film(Device *d, int64_t *film, Error *err)
{
    OclDevice *od = d->impl;
    FilmSlot *fs = &od->slots[od->tail % od->n_slots];
    if (!fs->read_done) return error_set(err, ST_INTERNAL, "device '%s': no batch to take", od->info.name);
    OCL_TRY("clWaitForEvents", clWaitForEvents(1, &fs->read_done));
    release_event(&fs->read_done);
    od->tail++;
    size_t n = (size_t)od->n_pixels * 3u;
    for (size_t i = 0; i < n; i++) film[i] += fs->host[i];
    /* Every wave of this batch is done; with nothing else in flight, so is every wave. */
    int idle = od->head == od->tail;
    for (int i = 0; i < COUNT_RING; i++) {
        Status st = account_wave(d, &od->ring[i], idle, err);
        if (st) return st;
    }
    return ST_OK;
}

static void ocl_destroy(Device *d)
{
    OclDevice *od = d->impl;
    if (od) {
        release_buffers(od);
        cl_kernel ks[] = { od->k_raygen, od->k_intersect, od->k_shade, od->k_shadow, od->k_film };
        for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++)
            if (ks[i]) clReleaseKernel(ks[i]);
        if (od->program) clReleaseProgram(od->program);
        if (od->queue) clReleaseCommandQueue(od->queue);
        if (od->ctx) clReleaseContext(od->ctx);
        free(od);
    }
    free(d);
}

static const DeviceOps ocl_ops = { ocl_load_scene, ocl_render, ocl_take_film, ocl_destroy };

static Status ocl_setup(Device *d, OclDevice *od, const DeviceConfig *cfg, Error *err)
{
    cl_int rc;
    cl_context_properties props[] = { CL_CONTEXT_PLATFORM, (cl_context_properties)od->info.platform, 0 };
    od->ctx = clCreateContext(props, 1, &od->info.id, NULL, NULL, &rc);
    if (rc != CL_SUCCESS) return ocl_fail(err, &od->info, "clCreateContext", rc);
    od->queue = clCreateCommandQueue(od->ctx, od->info.id, 0, &rc);
    if (rc != CL_SUCCESS) return ocl_fail(err, &od->info, "clCreateCommandQueue", rc);
    OclProgramStats ps;
    Status st = ocl_program_build(od->ctx, &od->info, cfg ? cfg->kernel_dir : NULL, NULL, &od->program, &ps, err);
    if (st) return st;
    d->counters.compile_seconds = ps.seconds;
    d->counters.from_cache = ps.from_cache;
    if ((st = ocl_program_kernel(od->program, &od->info, "k_raygen", &od->k_raygen, err)) ||
        (st = ocl_program_kernel(od->program, &od->info, "k_intersect", &od->k_intersect, err)) ||
        (st = ocl_program_kernel(od->program, &od->info, "k_shade", &od->k_shade, err)) ||
        (st = ocl_program_kernel(od->program, &od->info, "k_shadow", &od->k_shadow, err)) ||
        (st = ocl_program_kernel(od->program, &od->info, "k_film", &od->k_film, err)))
        return st;
    int gpu = (od->info.type & CL_DEVICE_TYPE_GPU) != 0;
    /* A GPU needs about a million paths in flight to hide memory latency; a CPU is full
     * with far fewer, and smaller waves stay in its caches. */
    od->wave_paths = cfg && cfg->wave_paths ? cfg->wave_paths : (gpu ? (1u << 20) : (1u << 16));
    od->local_size = od->info.max_work_group >= OCL_LOCAL_SIZE ? OCL_LOCAL_SIZE : 0;
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
    od->info = desc->ocl;
    Status st = ocl_setup(d, od, cfg, err);
    if (st) {
        ocl_destroy(d);
        return st;
    }
    *out = d;
    return ST_OK;
}
