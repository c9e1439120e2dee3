/*
 * device_ocl.c — an OpenCL device rendering batches as a wavefront.
 *
 * The scene is uploaded once. A batch is cut into waves of at most `wave_paths` paths
 * (a range of pixels times a few consecutive sample indices). Per wave: k_raygen births
 * every path, then each bounce runs k_intersect → k_shade → k_shadow over the queue of
 * live paths only (k_shade compacts survivors into the other queue; the host reads the
 * two counts to size the next launches), and k_film adds the wave into the device's
 * fixed-point film. Rays, hits and path states never leave the device.
 */
#include <stdlib.h>
#include <string.h>

#include "device.h"
#include "device_memory.h"
#include "fault.h"
#include "ocl_program.h"
#include "timer.h"

/* Work-group size for every launch: a multiple of every GPU's SIMD width; the global
 * size is rounded up to it and the kernels ignore the excess work-items. */
#define OCL_LOCAL_SIZE 64u

enum { SCENE_PARAMS, SCENE_NODES, SCENE_LEAF_PRIMS, SCENE_SPHERES, SCENE_TRIANGLES,
       SCENE_BOXES, SCENE_PLANES, SCENE_MATERIALS, SCENE_LIGHTS, SCENE_SHADING,
       SCENE_TEXTURES, SCENE_TEXELS, SCENE_PIXEL_MASK, SCENE_N };

typedef struct {
    OclDeviceInfo info;
    cl_context ctx;
    cl_command_queue queue;
    cl_program program;
    cl_kernel k_raygen, k_intersect, k_shade, k_shadow, k_film;
    cl_kernel k_whitted;    /* the classic ray tracer and auxiliary images */
    uint integrator;        /* enum Integrator of the loaded scene */
    cl_mem scene[SCENE_N];
    cl_mem paths, rays, hits, shadow_rays, queue_a, queue_b, shadow_queue, counters, film;
    uint wave_paths;        /* capacity of the wave buffers */
    size_t local_size;      /* 0: let the driver choose */
    uint width, height;
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

static void release_buffers(OclDevice *od)
{
    for (int i = 0; i < SCENE_N; i++) release_mem(&od->scene[i]);
    release_mem(&od->paths);
    release_mem(&od->rays);
    release_mem(&od->hits);
    release_mem(&od->shadow_rays);
    release_mem(&od->queue_a);
    release_mem(&od->queue_b);
    release_mem(&od->shadow_queue);
    release_mem(&od->counters);
    release_mem(&od->film);
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
    /* CL_MEM_COPY_HOST_PTR copies `size` bytes: a source shorter than the 16-byte
     * minimum (a leaf list of one index) goes through a zero-padded copy instead of
     * being read past its end. */
    unsigned char padded[16] = { 0 };
    if (src && bytes && bytes < size) {
        memcpy(padded, src, bytes);
        src = padded;
    }
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
        { s->textures, (size_t)p->n_textures * sizeof(Texture), "textures" },
        { s->texels, s->n_texels * sizeof(uint), "texture images" },
        { s->pixel_mask, s->pixel_mask ? (size_t)p->width * p->height * sizeof(uint) : 0, "pixel mask" },
    };
    uint n_pixels = p->width * p->height;
    uint wave = od->wave_paths;
    size_t film_bytes = (size_t)n_pixels * 3u * sizeof(cl_long);
    /* every buffer below, checked against the device before the first is allocated */
    DeviceBuffer fit[SCENE_N + 5];
    for (int i = 0; i < SCENE_N; i++) fit[i] = (DeviceBuffer){ in[i].what, in[i].bytes };
    fit[SCENE_N + 0] = (DeviceBuffer){ "path states", (uint64_t)wave * sizeof(PathState) };
    fit[SCENE_N + 1] = (DeviceBuffer){ "rays and shadow rays", (uint64_t)wave * 2 * sizeof(Ray) };
    fit[SCENE_N + 2] = (DeviceBuffer){ "hits", (uint64_t)wave * sizeof(Hit) };
    fit[SCENE_N + 3] = (DeviceBuffer){ "path queues", (uint64_t)wave * 3 * sizeof(uint) };
    fit[SCENE_N + 4] = (DeviceBuffer){ "film", film_bytes };
    Status st = device_memory_check(od->info.name, od->info.global_mem, od->info.max_alloc, fit,
                                    SCENE_N + 5, err);
    if (st) return st;
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
        (st = make_buffer(od, CL_MEM_READ_WRITE, 2 * sizeof(cl_uint), NULL, "queue counters", &od->counters, err)) ||
        (st = make_buffer(od, CL_MEM_READ_WRITE, film_bytes, NULL, "film", &od->film, err)))
        return st;
    cl_long zero = 0;
    OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, od->film, &zero, sizeof zero, 0,
                                                       film_bytes < 16 ? 16 : film_bytes, 0, NULL, NULL));
    OCL_TRY("clFinish", clFinish(od->queue));
    if ((st = set_scene_args(od, od->k_intersect, err)) || (st = set_scene_args(od, od->k_shade, err)) ||
        (st = set_scene_args(od, od->k_shadow, err)) || (st = set_scene_args(od, od->k_whitted, err)))
        return st;
    od->integrator = p->integrator;
    od->width = p->width;
    od->height = p->height;
    d->n_pixels = n_pixels;
    d->counters.upload_seconds += timer_now() - t0;
    return ST_OK;
}

/* The classic ray tracer's wave (kernels/whitted.cl): one k_whitted launch computes
 * every sample whole, then k_film adds them as for the path tracer. */
static Status render_wave_whitted(OclDevice *od, uint first_pixel, uint wave_pixels, uint first_sample,
                                  uint layers, uint64_t *rays, Error *err)
{
    uint n_paths = wave_pixels * layers;
    Status st;
    cl_uint zero = 0, count = 0;
    OCL_TRY("clEnqueueWriteBuffer", clEnqueueWriteBuffer(od->queue, od->counters, CL_FALSE, 0, sizeof zero,
                                                         &zero, 0, NULL, NULL));
    cl_kernel k = od->k_whitted;
    ARG(k, SCENE_N + 0, first_pixel);
    ARG(k, SCENE_N + 1, wave_pixels);
    ARG(k, SCENE_N + 2, first_sample);
    ARG(k, SCENE_N + 3, n_paths);
    ARG(k, SCENE_N + 4, od->paths);
    ARG(k, SCENE_N + 5, od->counters);
    if ((st = launch(od, k, "k_whitted", n_paths, err))) return st;
    k = od->k_film;
    ARG(k, 0, od->paths);
    ARG(k, 1, first_pixel);
    ARG(k, 2, wave_pixels);
    ARG(k, 3, layers);
    ARG(k, 4, od->film);
    if ((st = launch(od, k, "k_film", wave_pixels, err))) return st;
    OCL_TRY("clEnqueueReadBuffer", clEnqueueReadBuffer(od->queue, od->counters, CL_TRUE, 0, sizeof count,
                                                       &count, 0, NULL, NULL));
    *rays += count;
    return ST_OK;
}

/* One wave: pixels [first_pixel, first_pixel + wave_pixels) x samples
 * [first_sample, first_sample + layers). Returns the number of rays traced. */
static Status render_wave(OclDevice *od, uint first_pixel, uint wave_pixels, uint first_sample,
                          uint layers, uint64_t *rays, Error *err)
{
    if (od->integrator != INTEGRATOR_PATH)
        return render_wave_whitted(od, first_pixel, wave_pixels, first_sample, layers, rays, err);
    uint n_paths = wave_pixels * layers;
    Status st;
    cl_kernel k = od->k_raygen;
    ARG(k, 0, od->scene[SCENE_PARAMS]);
    ARG(k, 1, first_pixel);
    ARG(k, 2, wave_pixels);
    ARG(k, 3, first_sample);
    ARG(k, 4, n_paths);
    ARG(k, 5, od->paths);
    ARG(k, 6, od->rays);
    ARG(k, 7, od->queue_a);
    if ((st = launch(od, k, "k_raygen", n_paths, err))) return st;

    cl_mem cur = od->queue_a, next = od->queue_b;
    uint n = n_paths;
    while (n > 0) {
        k = od->k_intersect;
        ARG(k, SCENE_N + 0, cur);
        ARG(k, SCENE_N + 1, n);
        ARG(k, SCENE_N + 2, od->rays);
        ARG(k, SCENE_N + 3, od->hits);
        if ((st = launch(od, k, "k_intersect", n, err))) return st;

        cl_uint zero2[2] = { 0, 0 };
        OCL_TRY("clEnqueueWriteBuffer", clEnqueueWriteBuffer(od->queue, od->counters, CL_FALSE, 0,
                                                             sizeof zero2, zero2, 0, NULL, NULL));
        k = od->k_shade;
        ARG(k, SCENE_N + 0, cur);
        ARG(k, SCENE_N + 1, n);
        ARG(k, SCENE_N + 2, od->rays);
        ARG(k, SCENE_N + 3, od->hits);
        ARG(k, SCENE_N + 4, od->paths);
        ARG(k, SCENE_N + 5, od->shadow_rays);
        ARG(k, SCENE_N + 6, next);
        ARG(k, SCENE_N + 7, od->shadow_queue);
        ARG(k, SCENE_N + 8, od->counters);
        if ((st = launch(od, k, "k_shade", n, err))) return st;

        cl_uint counts[2];
        OCL_TRY("clEnqueueReadBuffer", clEnqueueReadBuffer(od->queue, od->counters, CL_TRUE, 0,
                                                           sizeof counts, counts, 0, NULL, NULL));
        *rays += n;
        if (counts[1] > 0) {
            k = od->k_shadow;
            ARG(k, SCENE_N + 0, od->shadow_queue);
            ARG(k, SCENE_N + 1, counts[1]);
            ARG(k, SCENE_N + 2, od->shadow_rays);
            ARG(k, SCENE_N + 3, od->paths);
            if ((st = launch(od, k, "k_shadow", counts[1], err))) return st;
            *rays += counts[1];
        }
        cl_mem t = cur;
        cur = next;
        next = t;
        n = counts[0];
    }

    k = od->k_film;
    ARG(k, 0, od->paths);
    ARG(k, 1, first_pixel);
    ARG(k, 2, wave_pixels);
    ARG(k, 3, layers);
    ARG(k, 4, od->film);
    return launch(od, k, "k_film", wave_pixels, err);
}

static Status ocl_render(Device *d, uint first_sample, uint count, Error *err)
{
    OclDevice *od = d->impl;
    uint n_pixels = d->n_pixels;
    uint64_t rays = 0;
    Status st;
    if (n_pixels >= od->wave_paths) {
        /* big image: waves of one sample over a range of pixels */
        for (uint s = 0; s < count; s++)
            for (uint p0 = 0; p0 < n_pixels; p0 += od->wave_paths) {
                uint np = n_pixels - p0 < od->wave_paths ? n_pixels - p0 : od->wave_paths;
                if ((st = render_wave(od, p0, np, first_sample + s, 1, &rays, err))) return st;
            }
    } else {
        /* small image: several samples of every pixel per wave */
        uint max_layers = od->wave_paths / n_pixels;
        for (uint s = 0; s < count;) {
            uint layers = count - s < max_layers ? count - s : max_layers;
            if ((st = render_wave(od, 0, n_pixels, first_sample + s, layers, &rays, err))) return st;
            s += layers;
        }
    }
    OCL_TRY("clFinish", clFinish(od->queue));
    d->counters.rays += rays;
    d->counters.samples += (uint64_t)n_pixels * count;
    return ST_OK;
}

static Status ocl_take_film(Device *d, int64_t *film, Error *err)
{
    OclDevice *od = d->impl;
    size_t n = (size_t)d->n_pixels * 3u;
    cl_long *tmp = malloc(n * sizeof *tmp);
    if (!tmp) return error_set(err, ST_INTERNAL, "out of memory reading the film back");
    cl_int rc = clEnqueueReadBuffer(od->queue, od->film, CL_TRUE, 0, n * sizeof *tmp, tmp, 0, NULL, NULL);
    if (rc == CL_SUCCESS) {
        cl_long zero = 0;
        rc = clEnqueueFillBuffer(od->queue, od->film, &zero, sizeof zero, 0, n * sizeof *tmp, 0, NULL, NULL);
        if (rc != CL_SUCCESS) {
            free(tmp);
            return ocl_fail(err, &od->info, "clEnqueueFillBuffer", rc);
        }
    } else {
        free(tmp);
        return ocl_fail(err, &od->info, "clEnqueueReadBuffer", rc);
    }
    for (size_t i = 0; i < n; i++) film[i] += tmp[i];
    free(tmp);
    return ST_OK;
}

static void ocl_destroy(Device *d)
{
    OclDevice *od = d->impl;
    if (od) {
        release_buffers(od);
        cl_kernel ks[] = { od->k_raygen, od->k_intersect, od->k_shade, od->k_shadow, od->k_film, od->k_whitted };
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
    Status st = ocl_program_build(od->ctx, &od->info, cfg ? cfg->kernel_dir : NULL,
                                  fault_build_options(d->desc.index), &od->program, &ps, err);
    if (st) return st;
    d->counters.compile_seconds = ps.seconds;
    d->counters.from_cache = ps.from_cache;
    if ((st = ocl_program_kernel(od->program, &od->info, "k_raygen", &od->k_raygen, err)) ||
        (st = ocl_program_kernel(od->program, &od->info, "k_intersect", &od->k_intersect, err)) ||
        (st = ocl_program_kernel(od->program, &od->info, "k_shade", &od->k_shade, err)) ||
        (st = ocl_program_kernel(od->program, &od->info, "k_shadow", &od->k_shadow, err)) ||
        (st = ocl_program_kernel(od->program, &od->info, "k_film", &od->k_film, err)) ||
        (st = ocl_program_kernel(od->program, &od->info, "k_whitted", &od->k_whitted, err)))
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
