/*
 * ocl_device.h — the OpenCL device's state, shared by the files that implement it (not
 * included outside host/device/): device_ocl.c (the DeviceOps: loading a scene, a
 * batch's waves, taking films), ocl_buffers.c (the device buffers), ocl_kernels.c (the
 * programs and the kernels' fixed arguments), ocl_waves.c (how a wave is launched:
 * counted, bounded or as a megakernel) and ocl_profile.c (--profile's device times).
 * device_ocl.c's head comment is the design.
 */
#ifndef CLPT_OCL_DEVICE_H
#define CLPT_OCL_DEVICE_H

#include <stdatomic.h>

#include "device/device.h"
#include "device/ocl.h"
#include "device/ocl_args.h"

/* Work-group size for every launch: a multiple of every GPU's SIMD width; the global
 * size is rounded up to it and the kernels ignore the excess work-items. On PoCL 3.1
 * (CPU) sizes 8 to 128 measured the same. */
#define OCL_LOCAL_SIZE 64u
/* Device films: one being rendered into while the previous one is read back. */
#define FILM_SLOTS 2
/* Waves in flight, each with its own path buffers. */
#define WAVE_SLOTS 2
/* A batch smaller than two waves is still split in two (the second wave hides the
 * first one's round trips), unless the halves would be smaller than this. */
#define MIN_SPLIT_PATHS 4096u

/* The buffers of one wave in flight, listed once: X(field, bytes per path of the wave,
 * times the bytes of the queue counters, what an error calls them). The size estimate,
 * the memory check, the allocations and the release all come from this list. */
#define WAVE_BUFFERS(X)                                                                  \
    X(paths, sizeof(PathState), 0, "path states")                                        \
    X(rays, sizeof(Ray), 0, "rays")                                                      \
    X(hits, sizeof(Hit), 0, "hits")                                                      \
    X(shadow_rays, sizeof(Ray), 0, "shadow rays")                                        \
    X(queue_a, sizeof(cl_uint), 0, "path queue")                                         \
    X(queue_b, sizeof(cl_uint), 0, "path queue")                                         \
    X(shadow_queue, sizeof(cl_uint), 0, "shadow queue")                                  \
    X(counts, 0, 1, "queue counters")
#define WAVE_BUFFER_FIELD_(field, per_path, per_counts, what) cl_mem field;

/* The two programs (kernels/entry.cl). */
enum { PROG_PATH, PROG_WHITTED, PROG_N };

/* A batch's film on the device and where its read-back lands. */
typedef struct {
    cl_mem film;
    int64_t *host;
    cl_event read_done;     /* the read-back in flight; NULL while the slot is free */
    int stale;              /* holds part of a cancelled batch: cleared before the next */
} FilmSlot;

/* One wave in flight: its buffers, its kernels (arguments that never change are set
 * once), and where it is. */
typedef struct {
    WAVE_BUFFERS(WAVE_BUFFER_FIELD_)
    cl_kernel k_raygen, k_intersect, k_shade, k_shadow, k_film;
    cl_kernel k_path;       /* the megakernel, instead of the four above */
    int active;
    uint first_pixel, first_sample, n_paths;
    uint bounce;            /* the bounce whose counts are on their way back */
    uint live;              /* paths that entered it */
    cl_mem cur, next;       /* its queue, and the queue it fills */
    cl_event read;          /* the read-back of its counts */
    cl_uint got[QUEUE_COUNT_STRIDE + 1];   /* count slots 2b + 1 and 2b + 2 */
    cl_uint *all_counts;    /* bounded launches: every count slot of the wave, read back
                             * once at its end (for the ray count) */
} WaveSlot;

/* --profile: a command whose device time is read once it is complete. */
typedef struct {
    cl_event event;
    int phase;              /* enum DevicePhase */
} ProfiledCommand;

typedef struct {
    OclDeviceInfo info;
    cl_context ctx;
    cl_command_queue queue;
    cl_program programs[PROG_N];    /* NULL until first needed */
    unsigned features[PROG_N];      /* the CLPT_FEATURES each was built with */
    unsigned scene_features;        /* what the loaded scene needs besides KF_PATH/KF_WHITTED */
    int builds;                     /* programs built so far (for counters.from_cache) */
    char *kernel_dir;               /* DeviceConfig's, kept for the builds */
    cl_kernel k_whitted;    /* the classic ray tracer (kernels/integrator/whitted.h) */
    cl_kernel k_whitted_film;       /* k_film of the whitted program */
    uint integrator;        /* enum Integrator of the loaded scene */
    cl_mem scene[SCENE_N];
    WaveSlot waves[WAVE_SLOTS];
    FilmSlot slots[FILM_SLOTS];
    uint n_slots;           /* 2, or 1 when two films do not fit the device */
    uint head, tail;        /* batches rendered and taken, counted from 0 */
    uint max_bounces;       /* bounces 0 .. max_depth, and a launch per boundary a path
                             * may pass in media (path_max_shades): 2 * max_bounces + 1
                             * count slots */
    uint counts_bounces;    /* the bounces the wave count buffers have room for */
    uint wave_paths;        /* capacity of each wave's buffers */
    uint wave_auto;         /* a large default wave, used where it fits (load_scene); 0 if none */
    uint wave_fallback;     /* the default wave where wave_auto does not fit */
    size_t local_size;      /* 0: let the driver choose */
    int launch;             /* enum WaveLaunch, never AUTO: how a wave is launched */
    int path_launch;        /* how this render's path waves are: launch, or the megakernel
                             * with first-hit splitting, which only the megakernels do
                             * (RenderParams.split; path_run keeps the first hit) */
    int cpu;                /* a CPU device: the megakernel may take eight paths at a time */
    uint64_t bytes_in_place;    /* of the loaded scene's buffers, used in place (ocl_buffers.c) */
    /* The megakernel is k_path_lanes: on a CPU, where it is faster, for a scene and
     * settings it can render (kernel_features.h; on PoCL the envmap scene rendered 11%
     * slower with eight paths per work-item, mesh.scene 19%: most of their lanes would
     * leave the float8 shading). lanes_scene: the loaded scene allows it, whatever the
     * settings. */
    int lanes, lanes_scene;
    uint n_pixels;          /* the film's */
    uint batch_pixels;      /* the pixels each sample of a batch covers: n_pixels, or the
                             * pixel list's (RenderParams.pixel_list_size) */
    const atomic_int *cancel;   /* the Device's, while a batch renders */
    cl_mem film;            /* the film the batch being rendered goes to */
    uint64_t rays;          /* rays of the batch being rendered */
    double *phases;         /* --profile: the Device's phase_seconds; NULL: not profiling */
    ProfiledCommand *profiled;      /* commands enqueued and not yet read */
    size_t n_profiled, cap_profiled;
} OclDevice;

#define OCL_TRY(call_name, expr)                                                       \
    do {                                                                               \
        cl_int rc_ = (expr);                                                           \
        if (rc_ != CL_SUCCESS) return ocl_fail(err, &od->info, call_name, rc_);        \
    } while (0)

static inline void ocl_release_mem(cl_mem *m)
{
    if (*m) clReleaseMemObject(*m);
    *m = NULL;
}

static inline void ocl_release_event(cl_event *e)
{
    if (*e) clReleaseEvent(*e);
    *e = NULL;
}

/* Whether the batch is to be dropped: checked before each launch step of a wave (a
 * bounce of a wave, or a whole megakernel wave, takes milliseconds), so a cancel is
 * seen about that quickly. */
static inline int ocld_cancel_requested(const OclDevice *od)
{
    return od->cancel && atomic_load_explicit(od->cancel, memory_order_relaxed);
}

/* clSetKernelArg, failing with the device's name; ARG sets argument i of kernel k to
 * the value v and returns from the caller (which has od and err) on failure. */
Status ocld_set_arg(OclDevice *od, cl_kernel k, cl_uint i, size_t size, const void *value, Error *err);
#define ARG(k, i, v) do { Status st_ = ocld_set_arg(od, k, i, sizeof(v), &(v), err); if (st_) return st_; } while (0)

/* ocl_buffers.c */
Status ocld_make_buffer(OclDevice *od, cl_mem_flags flags, OclReads reads, size_t bytes, const void *src,
                        const char *what, cl_mem *out, Error *err);
Status ocld_alloc_render(OclDevice *od, const SceneBufferBytes *in, uint n_pixels, Error *err);
Status ocld_grow_counts(OclDevice *od, uint bounces, Error *err);
void ocld_release_buffers(OclDevice *od);

/* ocl_kernels.c */
unsigned ocld_program_kernels(const OclDevice *od, int which);
Status ocld_need_program(Device *d, OclDevice *od, uint integrator, Error *err);
Status ocld_set_program_args(OclDevice *od, int which, Error *err);
Status ocld_set_scene_arg(OclDevice *od, unsigned b, Error *err);
void ocld_release_program(OclDevice *od, int which);

/* ocl_waves.c */
Status ocld_wave_start(OclDevice *od, WaveSlot *w, uint first_pixel, uint first_sample, uint n_paths, Error *err);
Status ocld_wave_advance(OclDevice *od, WaveSlot *w, Error *err);
Status ocld_render_whitted(OclDevice *od, uint first_sample, uint64_t total, Error *err);

/* ocl_profile.c */
void ocld_profile_add(OclDevice *od, cl_event e, int phase);
void ocld_profile_track(OclDevice *od, cl_event e, int phase);
void ocld_profile_collect(OclDevice *od);
void ocld_profile_free(OclDevice *od);
int ocld_profile_phase_of(const char *kernel);

#endif /* CLPT_OCL_DEVICE_H */
