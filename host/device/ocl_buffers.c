/*
 * ocl_buffers.c — the OpenCL device's buffers: the scene's, each wave's (WAVE_BUFFERS,
 * ocl_device.h) and the films, all checked against the device's memory before the
 * first is allocated (device_memory.h).
 */
#include <stddef.h>
#include <stdlib.h>

#include "base/pages.h"
#include "device/device_memory.h"
#include "device/ocl_device.h"

/* WAVE_BUFFERS as a table: where each buffer sits in a WaveSlot and how big it is. */
typedef struct {
    size_t offset, per_path, per_counts;
    const char *what;
} WaveBufferInfo;
#define WAVE_INFO_(field, per_path, per_counts, what) { offsetof(WaveSlot, field), per_path, per_counts, what },
static const WaveBufferInfo wave_buffers[] = { WAVE_BUFFERS(WAVE_INFO_) };
#define WAVE_COUNT_(field, per_path, per_counts, what) +1
enum { WAVE_N = 0 WAVE_BUFFERS(WAVE_COUNT_) };

/* The names the memory check gives each wave's buffers ("wave 2 hits"). */
_Static_assert(WAVE_SLOTS == 2, "one name list per wave slot");
#define WAVE_1_(field, per_path, per_counts, what) "wave 1 " what,
#define WAVE_2_(field, per_path, per_counts, what) "wave 2 " what,
static const char *const wave_names[WAVE_SLOTS][WAVE_N] = { { WAVE_BUFFERS(WAVE_1_) },
                                                            { WAVE_BUFFERS(WAVE_2_) } };

static cl_mem *wave_buffer(WaveSlot *w, int i)
{
    return (cl_mem *)(void *)((char *)w + wave_buffers[i].offset);
}

static uint64_t wave_buffer_bytes(int i, uint64_t wave, uint64_t counts_bytes)
{
    return wave * wave_buffers[i].per_path + counts_bytes * wave_buffers[i].per_counts;
}

static size_t counts_bytes_for(uint bounces)
{
    return (2u * (size_t)bounces + 1u) * QUEUE_COUNT_STRIDE * sizeof(cl_uint);
}

void ocld_release_buffers(OclDevice *od)
{
    /* nothing may still be writing into host memory that is about to be freed */
    if (od->queue) clFinish(od->queue);
    for (int i = 0; i < SCENE_N; i++) ocl_release_mem(&od->scene[i]);
    for (int i = 0; i < WAVE_SLOTS; i++) {
        WaveSlot *w = &od->waves[i];
        ocl_release_event(&w->read);
        for (int j = 0; j < WAVE_N; j++) ocl_release_mem(wave_buffer(w, j));
        free(w->all_counts);
        w->all_counts = NULL;
        w->active = 0;
    }
    for (int i = 0; i < FILM_SLOTS; i++) {
        ocl_release_event(&od->slots[i].read_done);
        ocl_release_mem(&od->slots[i].film);
        free(od->slots[i].host);
        od->slots[i].host = NULL;
    }
    od->head = od->tail = 0;
}

/* A device buffer of `bytes` (at least 16: OpenCL has no empty buffers), filled from
 * `src` when given, its bytes read as `reads` says (ocl_buffer). */
Status ocld_make_buffer(OclDevice *od, cl_mem_flags flags, OclReads reads, size_t bytes, const void *src,
                        const char *what, cl_mem *out, Error *err)
{
    size_t size = bytes < OCL_BUFFER_MIN ? OCL_BUFFER_MIN : bytes;
    if ((cl_ulong)size > od->info.max_alloc)
        return error_set(err, ST_DEVICE,
                         "device '%s': the %s need %.1f MiB, more than the device's largest allocation (%.1f MiB)",
                         od->info.name, what, (double)size / 1048576.0, (double)od->info.max_alloc / 1048576.0);
    const char *call;
    cl_int rc;
    *out = ocl_buffer(od->ctx, od->info.type, flags, reads, bytes, bytes ? src : NULL, &call, &rc);
    if (!*out) {
        ocl_fail(err, &od->info, call, rc);
        error_prefix(err, "allocating %.1f MiB for the %s", (double)size / 1048576.0, what);
        return ST_DEVICE;
    }
    return ST_OK;
}

/* Scene buffer i, from `in`: on a CPU device an array the host made on huge pages (the
 * trees' nodes and leaf lists, base/pages.h) is used in place, as the scalar device
 * reads it; a copy would touch as many huge pages again, which on a VM that hands free
 * memory back to its host costs 11-14 ms per MiB (the dragon's tree is 39 MB;
 * bench/RESULTS.md, "The scene's trees used in place"). Everything else is copied
 * (ocl_buffer). The scene's arrays stay until the next load_scene or the device's end
 * (device.h). */
static Status make_scene_buffer(OclDevice *od, int i, const SceneBufferBytes *in, Error *err)
{
    if (!od->cpu || !pages_on_huge(in->data, in->bytes))
        return ocld_make_buffer(od, CL_MEM_READ_ONLY, OCL_READ_AT_RANDOM, in->bytes, in->data, in->what,
                                &od->scene[i], err);
    /* its size was checked with every other buffer's (ocld_alloc_render) */
    const char *call;
    cl_int rc;
    if ((od->scene[i] = ocl_buffer_in_place(od->ctx, in->bytes, in->data, &call, &rc))) {
        od->bytes_in_place += in->bytes;
        return ST_OK;
    }
    ocl_fail(err, &od->info, call, rc);
    error_prefix(err, "using %.1f MiB of the %s in place", (double)in->bytes / 1048576.0, in->what);
    return ST_DEVICE;
}

/* The large default waves only while they and the scene take at most half the device's
 * memory; else the smaller fallback. */
static void choose_wave(OclDevice *od, const SceneBufferBytes *in, uint n_pixels, size_t counts_bytes)
{
    if (!od->wave_auto) return;
    uint64_t need = 2u * (uint64_t)n_pixels * 3u * sizeof(cl_long);
    for (unsigned i = 0; i < SCENE_N; i++) need += in[i].bytes;
    for (int j = 0; j < WAVE_N; j++) need += WAVE_SLOTS * wave_buffer_bytes(j, od->wave_auto, counts_bytes);
    od->wave_paths = need <= od->info.global_mem / 2u ? od->wave_auto : od->wave_fallback;
}

/* The films, cleared: two when they fit with everything else (the read-back of one
 * batch then overlaps the next), else one (the device waits for each read-back,
 * nothing worse). */
static Status alloc_films(OclDevice *od, size_t film_bytes, Error *err)
{
    Status st;
    cl_long zero = 0;
    for (uint i = 0; i < od->n_slots; i++) {
        FilmSlot *fs = &od->slots[i];
        if ((st = ocld_make_buffer(od, CL_MEM_READ_WRITE, OCL_READ_IN_ORDER, film_bytes, NULL, "film", &fs->film, err))) return st;
        if (!(fs->host = malloc(film_bytes < 16 ? 16 : film_bytes)))
            return error_set(err, ST_INTERNAL, "out of memory for the read-back of the film");
        OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, fs->film, &zero, sizeof zero, 0,
                                                           film_bytes < 16 ? 16 : film_bytes, 0, NULL, NULL));
        fs->stale = 0;
    }
    return ST_OK;
}

/* Uploads the scene buffers `in` and allocates the waves' buffers (for od->max_bounces
 * bounces) and the films of n_pixels pixels; every buffer is checked against the device
 * before the first is allocated. */
Status ocld_alloc_render(OclDevice *od, const SceneBufferBytes *in, uint n_pixels, Error *err)
{
    size_t counts_bytes = counts_bytes_for(od->max_bounces);
    size_t film_bytes = (size_t)n_pixels * 3u * sizeof(cl_long);
    choose_wave(od, in, n_pixels, counts_bytes);
    uint wave = od->wave_paths;
    /* one entry per allocation below: each must fit the largest allocation, all of them
     * the device's memory */
    DeviceBuffer fit[SCENE_N + WAVE_SLOTS * WAVE_N + FILM_SLOTS];
    size_t n_fit = 0;
    for (int i = 0; i < SCENE_N; i++) fit[n_fit++] = (DeviceBuffer){ in[i].what, in[i].bytes };
    for (int i = 0; i < WAVE_SLOTS; i++)
        for (int j = 0; j < WAVE_N; j++)
            fit[n_fit++] = (DeviceBuffer){ wave_names[i][j], wave_buffer_bytes(j, wave, counts_bytes) };
    fit[n_fit++] = (DeviceBuffer){ "film", film_bytes };
    fit[n_fit] = (DeviceBuffer){ "second film", film_bytes };
    Status st;
    if (device_memory_check(od->info.name, od->info.global_mem, od->info.max_alloc, fit, n_fit + 1, NULL) == ST_OK)
        od->n_slots = 2;
    else if ((st = device_memory_check(od->info.name, od->info.global_mem, od->info.max_alloc, fit, n_fit, err)))
        return st;
    else
        od->n_slots = 1;
    od->bytes_in_place = 0;
    for (int i = 0; i < SCENE_N; i++)
        if ((st = make_scene_buffer(od, i, &in[i], err))) return st;
    for (int i = 0; i < WAVE_SLOTS; i++) {
        WaveSlot *w = &od->waves[i];
        for (int j = 0; j < WAVE_N; j++)
            if ((st = ocld_make_buffer(od, CL_MEM_READ_WRITE, OCL_READ_IN_ORDER, wave_buffer_bytes(j, wave, counts_bytes), NULL,
                                       wave_buffers[j].what, wave_buffer(w, j), err)))
                return st;
        if (!(w->all_counts = malloc(counts_bytes)))
            return error_set(err, ST_INTERNAL, "out of memory for the queue counts");
    }
    if ((st = alloc_films(od, film_bytes, err))) return st;
    OCL_TRY("clFinish", clFinish(od->queue));
    od->counts_bounces = od->max_bounces;
    return ST_OK;
}

/* Gives every wave count buffers for `bounces` bounces, when they have room for fewer. */
Status ocld_grow_counts(OclDevice *od, uint bounces, Error *err)
{
    if (bounces <= od->counts_bounces) return ST_OK;
    size_t bytes = counts_bytes_for(bounces);
    Status st;
    for (int i = 0; i < WAVE_SLOTS; i++) {
        WaveSlot *w = &od->waves[i];
        ocl_release_mem(&w->counts);
        if ((st = ocld_make_buffer(od, CL_MEM_READ_WRITE, OCL_READ_IN_ORDER, bytes, NULL, "queue counters", &w->counts, err))) return st;
        if (w->k_shade) ARG(w->k_shade, ARG_SHADE_COUNTS, w->counts);
        if (w->k_intersect) ARG(w->k_intersect, ARG_INTERSECT_COUNTS, w->counts);
        if (w->k_shadow) ARG(w->k_shadow, ARG_SHADOW_COUNTS, w->counts);
        if (w->k_path) ARG(w->k_path, ARG_PATH_COUNTERS, w->counts);
        cl_uint *all = realloc(w->all_counts, bytes);
        if (!all) return error_set(err, ST_INTERNAL, "out of memory for the queue counts");
        w->all_counts = all;
    }
    od->counts_bounces = bounces;
    return ST_OK;
}
