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

#include "device/device.h"
#include "device/device_memory.h"
#include "device/kernel_features.h"
#include "base/fault.h"
#include "device/ocl_args.h"
#include "device/ocl_program.h"
#include "base/timer.h"

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
    cl_mem paths, rays, hits, shadow_rays, queue_a, queue_b, shadow_queue, counts;
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
    uint max_bounces;       /* bounces 0 .. max_depth: 2 * max_bounces + 1 count slots */
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
    /* The megakernel is k_path_lanes: on a CPU, where it is faster, for a scene and
     * settings it can render (kernel_features.h; on PoCL the envmap scene rendered 11%
     * slower with eight paths per work-item, mesh.scene 19%: most of their lanes would
     * leave the float8 shading). lanes_scene: the loaded scene allows it, whatever the
     * settings. */
    int lanes, lanes_scene;
    uint n_pixels;
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

static void release_kernel(cl_kernel *k)
{
    if (*k) clReleaseKernel(*k);
    *k = NULL;
}

static void release_buffers(OclDevice *od)
{
    /* nothing may still be writing into host memory that is about to be freed */
    if (od->queue) clFinish(od->queue);
    for (int i = 0; i < SCENE_N; i++) release_mem(&od->scene[i]);
    for (int i = 0; i < WAVE_SLOTS; i++) {
        WaveSlot *w = &od->waves[i];
        release_event(&w->read);
        cl_mem *ms[] = { &w->paths, &w->rays, &w->hits, &w->shadow_rays, &w->queue_a, &w->queue_b,
                         &w->shadow_queue, &w->counts };
        for (size_t j = 0; j < sizeof ms / sizeof ms[0]; j++) release_mem(ms[j]);
        free(w->all_counts);
        w->all_counts = NULL;
        w->active = 0;
    }
    for (int i = 0; i < FILM_SLOTS; i++) {
        release_event(&od->slots[i].read_done);
        release_mem(&od->slots[i].film);
        free(od->slots[i].host);
        od->slots[i].host = NULL;
    }
    od->head = od->tail = 0;
}

/* A device buffer of `bytes` (at least 16: OpenCL has no empty buffers), filled from
 * `src` when given. */
static Status make_buffer(OclDevice *od, cl_mem_flags flags, size_t bytes, const void *src,
                          const char *what, cl_mem *out, Error *err)
{
    size_t size = bytes < OCL_BUFFER_MIN ? OCL_BUFFER_MIN : bytes;
    if ((cl_ulong)size > od->info.max_alloc)
        return error_set(err, ST_DEVICE,
                         "device '%s': the %s need %.1f MiB, more than the device's largest allocation (%.1f MiB)",
                         od->info.name, what, (double)size / 1048576.0, (double)od->info.max_alloc / 1048576.0);
    const char *call;
    cl_int rc;
    *out = ocl_buffer(od->ctx, od->info.type, flags, bytes, bytes ? src : NULL, &call, &rc);
    if (!*out) {
        ocl_fail(err, &od->info, call, rc);
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

/* The arguments of a wave's kernels that stay the same for the whole render, set once
 * after the upload; per launch only queues, counts, positions and the film change. */
static Status set_fixed_args(OclDevice *od, WaveSlot *w, Error *err)
{
    Status st;
    cl_kernel k = w->k_film;
    ARG(k, ARG_FILM_PATHS, w->paths);
    ARG(k, ARG_FILM_N_PIXELS, od->n_pixels);
    if (w->k_path) {
        if ((st = set_scene_args(od, w->k_path, err))) return st;
        k = w->k_path;
        ARG(k, ARG_PATH_N_PIXELS, od->n_pixels);
        ARG(k, ARG_PATH_PATHS, w->paths);
        ARG(k, ARG_PATH_RAYS, w->rays);
        ARG(k, ARG_PATH_SHADOW_RAYS, w->shadow_rays);
        ARG(k, ARG_PATH_COUNTERS, w->counts);
        return ST_OK;
    }
    if ((st = set_scene_args(od, w->k_intersect, err)) || (st = set_scene_args(od, w->k_shade, err)) ||
        (st = set_scene_args(od, w->k_shadow, err)))
        return st;
    k = w->k_raygen;
    ARG(k, ARG_RAYGEN_PARAMS, od->scene[SCENE_BUF_params]);
    ARG(k, ARG_RAYGEN_N_PIXELS, od->n_pixels);
    ARG(k, ARG_RAYGEN_PATHS, w->paths);
    ARG(k, ARG_RAYGEN_RAYS, w->rays);
    ARG(k, ARG_RAYGEN_QUEUE, w->queue_a);
    k = w->k_intersect;
    ARG(k, ARG_INTERSECT_RAYS, w->rays);
    ARG(k, ARG_INTERSECT_HITS, w->hits);
    ARG(k, ARG_INTERSECT_COUNTS, w->counts);
    k = w->k_shade;
    ARG(k, ARG_SHADE_RAYS, w->rays);
    ARG(k, ARG_SHADE_HITS, w->hits);
    ARG(k, ARG_SHADE_PATHS, w->paths);
    ARG(k, ARG_SHADE_SHADOW_RAYS, w->shadow_rays);
    ARG(k, ARG_SHADE_SHADOW_QUEUE, w->shadow_queue);
    ARG(k, ARG_SHADE_COUNTS, w->counts);
    k = w->k_shadow;
    ARG(k, ARG_SHADOW_QUEUE, w->shadow_queue);
    ARG(k, ARG_SHADOW_RAYS, w->shadow_rays);
    ARG(k, ARG_SHADOW_PATHS, w->paths);
    ARG(k, ARG_SHADOW_COUNTS, w->counts);
    return ST_OK;
}

/* --profile: adds the device time of the complete command `e` to its phase. */
static void profile_add(OclDevice *od, cl_event e, int phase)
{
    cl_ulong t0 = 0, t1 = 0;
    if (clGetEventProfilingInfo(e, CL_PROFILING_COMMAND_START, sizeof t0, &t0, NULL) == CL_SUCCESS &&
        clGetEventProfilingInfo(e, CL_PROFILING_COMMAND_END, sizeof t1, &t1, NULL) == CL_SUCCESS && t1 > t0)
        od->phases[phase] += (double)(t1 - t0) * 1e-9;
}

/* --profile: keeps the event of a command just enqueued, to be read when complete
 * (reading it at once would wait, and serialise host and device). */
static void profile_track(OclDevice *od, cl_event e, int phase)
{
    if (od->n_profiled == od->cap_profiled) {
        size_t cap = od->cap_profiled ? 2 * od->cap_profiled : 256;
        ProfiledCommand *p = realloc(od->profiled, cap * sizeof *p);
        if (!p) {
            /* no room to keep it: wait for it now rather than lose its time */
            if (clWaitForEvents(1, &e) == CL_SUCCESS) profile_add(od, e, phase);
            clReleaseEvent(e);
            return;
        }
        od->profiled = p;
        od->cap_profiled = cap;
    }
    od->profiled[od->n_profiled].event = e;
    od->profiled[od->n_profiled++].phase = phase;
}

/* --profile: reads and forgets the tracked commands that are complete (failed ones are
 * forgotten unread). */
static void profile_collect(OclDevice *od)
{
    size_t keep = 0;
    for (size_t i = 0; i < od->n_profiled; i++) {
        ProfiledCommand c = od->profiled[i];
        cl_int status = CL_QUEUED;
        clGetEventInfo(c.event, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status, &status, NULL);
        if (status > CL_COMPLETE) {
            od->profiled[keep++] = c;
            continue;
        }
        if (status == CL_COMPLETE) profile_add(od, c.event, c.phase);
        clReleaseEvent(c.event);
    }
    od->n_profiled = keep;
}

/* The phase of each kernel's time (the classic ray tracer's samples count as shading). */
static int profile_phase_of(const char *kernel)
{
    static const struct { const char *name; int phase; } map[] = {
        { "k_raygen", PHASE_RAYGEN }, { "k_intersect", PHASE_TRAVERSE }, { "k_shade", PHASE_SHADE },
        { "k_shadow", PHASE_SHADOW }, { "k_film", PHASE_FILM },
    };
    /* k_path (a megakernel asked for with --profile) does all of a path's stages at
     * once: its time counts as shading, as the classic ray tracer's does */
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (strcmp(kernel, map[i].name) == 0) return map[i].phase;
    return PHASE_SHADE;
}

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
    if (ev) profile_track(od, ev, profile_phase_of(name));
    return ST_OK;
}

/* n work-items of k in work-groups of the device's size (OCL_LOCAL_SIZE, or the
 * driver's choice). */
static Status launch(OclDevice *od, cl_kernel k, const char *name, uint n, Error *err)
{
    return launch_local(od, k, name, n, od->local_size, err);
}

static void release_program(OclDevice *od, int which)
{
    if (which == PROG_PATH) {
        for (int i = 0; i < WAVE_SLOTS; i++) {
            WaveSlot *w = &od->waves[i];
            cl_kernel *ks[] = { &w->k_raygen, &w->k_intersect, &w->k_shade, &w->k_shadow, &w->k_film, &w->k_path };
            for (size_t j = 0; j < sizeof ks / sizeof ks[0]; j++) release_kernel(ks[j]);
        }
    } else {
        release_kernel(&od->k_whitted);
        release_kernel(&od->k_whitted_film);
    }
    if (od->programs[which]) clReleaseProgram(od->programs[which]);
    od->programs[which] = NULL;
    od->features[which] = 0;
}

/* Sets the arguments of program `which`'s kernels that stay the same for the loaded
 * scene. */
static Status set_program_args(OclDevice *od, int which, Error *err)
{
    Status st;
    if (!od->programs[which]) return ST_OK;
    if (which == PROG_WHITTED) return set_scene_args(od, od->k_whitted, err);
    for (int i = 0; i < WAVE_SLOTS; i++)
        if ((st = set_fixed_args(od, &od->waves[i], err))) return st;
    return ST_OK;
}

/* The kernels program `which` holds (KF_* of kernels/types.h): the classic ray
 * tracer's, or the path tracer's in the form the device launches. */
static unsigned program_kernels(const OclDevice *od, int which)
{
    if (which == PROG_WHITTED) return KF_WHITTED;
    if (od->path_launch != WAVE_LAUNCH_MEGAKERNEL) return KF_PATH;
    return od->lanes ? KF_PATH_LANES : KF_PATH_MEGAKERNEL;
}

/* Builds the program the integrator needs, for the loaded scene's features, unless the
 * one there already has them; its kernels get their fixed arguments. */
static Status need_program(Device *d, OclDevice *od, uint integrator, Error *err)
{
    int which = integrator == INTEGRATOR_PATH ? PROG_PATH : PROG_WHITTED;
    unsigned want = od->scene_features | program_kernels(od, which);
    if (od->programs[which] && (od->features[which] & want) == want) return ST_OK;
    release_program(od, which);
    char options[320];
    const char *fault = fault_build_options(d->desc.index);
    char size[48] = "";
    if (od->local_size) snprintf(size, sizeof size, " -D CLPT_LOCAL_SIZE=%zu", od->local_size);
    if (snprintf(options, sizeof options, "-D CLPT_FEATURES=0x%xu%s%s%s", want, size, fault && fault[0] ? " " : "",
                 fault ? fault : "") >= (int)sizeof options)
        return error_set(err, ST_INTERNAL, "device '%s': build options too long", od->info.name);
    OclProgramStats ps;
    cl_program prog = NULL;
    Status st = ocl_program_build(od->ctx, &od->info, od->kernel_dir, options, &prog, &ps, err);
    if (st) return st;
    od->programs[which] = prog;
    od->features[which] = want;
    d->counters.compile_seconds += ps.seconds;
    d->counters.from_cache = (od->builds++ == 0 || d->counters.from_cache) && ps.from_cache;
    if (which == PROG_PATH) {
        /* each wave has its own kernel objects, so that their fixed arguments are set once */
        for (int i = 0; i < WAVE_SLOTS; i++) {
            WaveSlot *w = &od->waves[i];
            if (want & (KF_PATH_MEGAKERNEL | KF_PATH_LANES)) {
                const char *name = want & KF_PATH_LANES ? "k_path_lanes" : "k_path";
                if ((st = ocl_program_kernel(prog, &od->info, name, &w->k_path, err)) ||
                    (st = ocl_program_kernel(prog, &od->info, "k_film", &w->k_film, err)))
                    break;
                continue;
            }
            if ((st = ocl_program_kernel(prog, &od->info, "k_raygen", &w->k_raygen, err)) ||
                (st = ocl_program_kernel(prog, &od->info, "k_intersect", &w->k_intersect, err)) ||
                (st = ocl_program_kernel(prog, &od->info, "k_shade", &w->k_shade, err)) ||
                (st = ocl_program_kernel(prog, &od->info, "k_shadow", &w->k_shadow, err)) ||
                (st = ocl_program_kernel(prog, &od->info, "k_film", &w->k_film, err)))
                break;
        }
    } else if ((st = ocl_program_kernel(prog, &od->info, "k_whitted", &od->k_whitted, err)) == ST_OK) {
        st = ocl_program_kernel(prog, &od->info, "k_film", &od->k_whitted_film, err);
    }
    if (st == ST_OK) st = set_program_args(od, which, err);
    if (st) release_program(od, which);
    return st;
}

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
    release_buffers(od);
    const RenderParams *p = &s->params;
    SceneBufferBytes in[SCENE_N];
    for (unsigned i = 0; i < SCENE_N; i++) in[i] = device_scene_buffer(s, i);
    uint n_pixels = p->width * p->height;
    if (od->wave_auto) {
        /* the large default waves only while they and the scene take at most half the
         * device's memory; else the smaller fallback */
        uint64_t need = 2u * (uint64_t)n_pixels * 3u * sizeof(cl_long);
        for (unsigned i = 0; i < SCENE_N; i++) need += in[i].bytes;
        need += (uint64_t)WAVE_SLOTS * od->wave_auto *
                (sizeof(PathState) + 2u * sizeof(Ray) + sizeof(Hit) + 3u * sizeof(uint));
        od->wave_paths = need <= od->info.global_mem / 2u ? od->wave_auto : od->wave_fallback;
    }
    uint wave = od->wave_paths;
    od->max_bounces = p->max_depth + 1u;
    od->counts_bounces = od->max_bounces;
    size_t counts_bytes = (2u * (size_t)od->max_bounces + 1u) * QUEUE_COUNT_STRIDE * sizeof(cl_uint);
    size_t film_bytes = (size_t)n_pixels * 3u * sizeof(cl_long);
    /* Every buffer below is checked against the device before the first is allocated:
     * double-buffered films when they fit, else one (the device then waits for each
     * read-back, nothing worse). */
    /* one entry per allocation below: each must fit the largest allocation, all of them
     * the device's memory */
    DeviceBuffer fit[SCENE_N + WAVE_SLOTS * 8 + FILM_SLOTS];
    size_t n_fit = 0;
    for (int i = 0; i < SCENE_N; i++) fit[n_fit++] = (DeviceBuffer){ in[i].what, in[i].bytes };
    static const char *const wave_names[WAVE_SLOTS][5] = {
        { "wave 1 path states", "wave 1 rays", "wave 1 hits", "wave 1 path queues", "wave 1 counters" },
        { "wave 2 path states", "wave 2 rays", "wave 2 hits", "wave 2 path queues", "wave 2 counters" },
    };
    for (int i = 0; i < WAVE_SLOTS; i++) {
        fit[n_fit++] = (DeviceBuffer){ wave_names[i][0], (uint64_t)wave * sizeof(PathState) };
        fit[n_fit++] = (DeviceBuffer){ wave_names[i][1], (uint64_t)wave * sizeof(Ray) };   /* rays */
        fit[n_fit++] = (DeviceBuffer){ wave_names[i][1], (uint64_t)wave * sizeof(Ray) };   /* shadow rays */
        fit[n_fit++] = (DeviceBuffer){ wave_names[i][2], (uint64_t)wave * sizeof(Hit) };
        for (int q = 0; q < 3; q++) fit[n_fit++] = (DeviceBuffer){ wave_names[i][3], (uint64_t)wave * sizeof(uint) };
        fit[n_fit++] = (DeviceBuffer){ wave_names[i][4], counts_bytes };
    }
    fit[n_fit++] = (DeviceBuffer){ "film", film_bytes };
    Status st;
    fit[n_fit] = (DeviceBuffer){ "second film", film_bytes };
    if (device_memory_check(od->info.name, od->info.global_mem, od->info.max_alloc, fit, n_fit + 1, NULL) == ST_OK)
        od->n_slots = 2;
    else if ((st = device_memory_check(od->info.name, od->info.global_mem, od->info.max_alloc, fit, n_fit, err)))
        return st;
    else
        od->n_slots = 1;
    for (int i = 0; i < SCENE_N; i++)
        if ((st = make_buffer(od, CL_MEM_READ_ONLY, in[i].bytes, in[i].data, in[i].what, &od->scene[i], err)))
            return st;
    cl_mem_flags rw = CL_MEM_READ_WRITE;
    for (int i = 0; i < WAVE_SLOTS; i++) {
        WaveSlot *w = &od->waves[i];
        if ((st = make_buffer(od, rw, (size_t)wave * sizeof(PathState), NULL, "path states", &w->paths, err)) ||
            (st = make_buffer(od, rw, (size_t)wave * sizeof(Ray), NULL, "rays", &w->rays, err)) ||
            (st = make_buffer(od, rw, (size_t)wave * sizeof(Hit), NULL, "hits", &w->hits, err)) ||
            (st = make_buffer(od, rw, (size_t)wave * sizeof(Ray), NULL, "shadow rays", &w->shadow_rays, err)) ||
            (st = make_buffer(od, rw, (size_t)wave * sizeof(uint), NULL, "path queue", &w->queue_a, err)) ||
            (st = make_buffer(od, rw, (size_t)wave * sizeof(uint), NULL, "path queue", &w->queue_b, err)) ||
            (st = make_buffer(od, rw, (size_t)wave * sizeof(uint), NULL, "shadow queue", &w->shadow_queue, err)) ||
            (st = make_buffer(od, rw, counts_bytes, NULL, "queue counters", &w->counts, err)))
            return st;
        if (!(w->all_counts = malloc(counts_bytes)))
            return error_set(err, ST_INTERNAL, "out of memory for the queue counts");
    }
    cl_long zero = 0;
    for (uint i = 0; i < od->n_slots; i++) {
        FilmSlot *fs = &od->slots[i];
        if ((st = make_buffer(od, rw, film_bytes, NULL, "film", &fs->film, err))) return st;
        if (!(fs->host = malloc(film_bytes < 16 ? 16 : film_bytes)))
            return error_set(err, ST_INTERNAL, "out of memory for the read-back of the film");
        OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, fs->film, &zero, sizeof zero, 0,
                                                           film_bytes < 16 ? 16 : film_bytes, 0, NULL, NULL));
        fs->stale = 0;
    }
    OCL_TRY("clFinish", clFinish(od->queue));
    od->n_pixels = n_pixels;
    /* a program built for an earlier scene serves this one if it has its features */
    od->scene_features = kernel_scene_features(s);
    od->path_launch = s->params.split > 1u ? WAVE_LAUNCH_MEGAKERNEL : od->launch;
    od->lanes_scene = od->cpu && od->path_launch == WAVE_LAUNCH_MEGAKERNEL && kernel_lanes_scene(s, od->scene_features);
    od->lanes = od->lanes_scene && kernel_lanes_params(&s->params);
    for (int i = 0; i < PROG_N; i++) {
        unsigned need = od->scene_features | program_kernels(od, i);
        if ((od->features[i] & need) != need) release_program(od, i);
        else if ((st = set_program_args(od, i, err))) return st;
    }
    d->counters.upload_seconds += timer_now() - t0;
    t0 = timer_now();
    if ((st = need_program(d, od, p->integrator, err))) return st;
    od->integrator = p->integrator;
    note_waves(d, od);
    d->n_pixels = n_pixels;
    d->max_in_flight = od->n_slots;
    return ST_OK;
}

/* Gives every wave count buffers for `bounces` bounces, when they have room for fewer. */
static Status grow_counts(OclDevice *od, uint bounces, Error *err)
{
    if (bounces <= od->counts_bounces) return ST_OK;
    size_t bytes = (2u * (size_t)bounces + 1u) * QUEUE_COUNT_STRIDE * sizeof(cl_uint);
    Status st;
    for (int i = 0; i < WAVE_SLOTS; i++) {
        WaveSlot *w = &od->waves[i];
        release_mem(&w->counts);
        if ((st = make_buffer(od, CL_MEM_READ_WRITE, bytes, NULL, "queue counters", &w->counts, err))) return st;
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

/* Sets the scene buffer `b` as the argument of every kernel that takes the scene. */
static Status set_scene_arg(OclDevice *od, unsigned b, Error *err)
{
    for (int i = 0; i < WAVE_SLOTS && od->programs[PROG_PATH]; i++) {
        WaveSlot *w = &od->waves[i];
        if (w->k_path) {
            ARG(w->k_path, b, od->scene[b]);
            continue;
        }
        ARG(w->k_intersect, b, od->scene[b]);
        ARG(w->k_shade, b, od->scene[b]);
        ARG(w->k_shadow, b, od->scene[b]);
    }
    if (od->programs[PROG_WHITTED]) ARG(od->k_whitted, b, od->scene[b]);
    return ST_OK;
}

/* The params block is written in place (the buffer keeps its size); the pixel mask
 * gets a buffer of its own size, set as every kernel's argument. */
static Status ocl_update_params(Device *d, const RenderParams *p, const uint *pixel_mask, Error *err)
{
    OclDevice *od = d->impl;
    if (p->width * p->height != od->n_pixels)
        return error_set(err, ST_INTERNAL, "device '%s': new render parameters for %ux%u pixels, the scene was "
                         "loaded for %u pixels", od->info.name, p->width, p->height, od->n_pixels);
    double t0 = timer_now();
    Status st;
    /* every launch so far has read the old block and mask */
    OCL_TRY("clFinish", clFinish(od->queue));
    OCL_TRY("clEnqueueWriteBuffer", clEnqueueWriteBuffer(od->queue, od->scene[SCENE_BUF_params], CL_TRUE, 0,
                                                         sizeof *p, p, 0, NULL, NULL));
    release_mem(&od->scene[SCENE_BUF_pixel_mask]);
    size_t mask_bytes = pixel_mask ? (size_t)od->n_pixels * sizeof(uint) : 0;
    if ((st = make_buffer(od, CL_MEM_READ_ONLY, mask_bytes, pixel_mask, "pixel mask",
                          &od->scene[SCENE_BUF_pixel_mask], err)) ||
        (st = set_scene_arg(od, SCENE_BUF_pixel_mask, err)) || (st = grow_counts(od, p->max_depth + 1u, err)))
        return st;
    od->max_bounces = p->max_depth + 1u;
    d->counters.upload_seconds += timer_now() - t0;
    od->scene_features |= kernel_params_features(p);
    od->path_launch = p->split > 1u ? WAVE_LAUNCH_MEGAKERNEL : od->launch;
    od->lanes = od->lanes_scene && kernel_lanes_params(p);
    if ((st = need_program(d, od, p->integrator, err))) return st;
    od->integrator = p->integrator;
    note_waves(d, od);
    return ST_OK;
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
    ARG(k, ARG_FILM_FIRST_PIXEL, w->first_pixel);
    ARG(k, ARG_FILM_N_PATHS, w->n_paths);
    ARG(k, ARG_FILM_FILM, od->film);
    return launch(od, k, "k_film", w->n_paths < od->n_pixels ? w->n_paths : od->n_pixels, err);
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
 * 0 of sample first_sample (entry.cl). */
static Status wave_start(OclDevice *od, WaveSlot *w, uint first_pixel, uint first_sample, uint n_paths, Error *err)
{
    Status st;
    cl_uint zero = 0;
    cl_event ev = NULL;
    OCL_TRY("clEnqueueFillBuffer",
            clEnqueueFillBuffer(od->queue, w->counts, &zero, sizeof zero, 0,
                                (2u * (size_t)od->max_bounces + 1u) * QUEUE_COUNT_STRIDE * sizeof zero, 0, NULL,
                                od->phases ? &ev : NULL));
    if (ev) profile_track(od, ev, PHASE_QUEUES);
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
    ARG(k, ARG_RAYGEN_N_PATHS, n_paths);
    if ((st = launch(od, k, "k_raygen", n_paths, err))) return st;
    w->cur = w->queue_a;
    w->next = w->queue_b;
    return od->path_launch == WAVE_LAUNCH_BOUNDED ? wave_enqueue_all(od, w, err) : bounce_launch(od, w, 0, n_paths, err);
}

/* Waits for the counts of the wave's last bounce, then launches its shadow rays and
 * its next bounce, or, when no path is left, adds the wave into the film. */
static Status wave_advance(OclDevice *od, WaveSlot *w, Error *err)
{
    Status st;
    double t0 = od->phases ? timer_now() : 0.0;
    cl_int rc = clWaitForEvents(1, &w->read);
    if (od->phases) {
        od->phases[PHASE_HOST_WAIT] += timer_now() - t0;
        if (rc == CL_SUCCESS) profile_add(od, w->read, PHASE_QUEUES);
    }
    release_event(&w->read);
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

/* Whether the batch is to be dropped: checked before each launch step of a wave (a
 * bounce of a wave, or a whole megakernel wave, takes milliseconds), so a cancel is
 * seen about that quickly. */
static int cancel_requested(const OclDevice *od)
{
    return od->cancel && atomic_load_explicit(od->cancel, memory_order_relaxed);
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
        release_event(&od->waves[i].read);
        od->waves[i].active = 0;
    }
    fs->stale = 1;
    return error_set(err, ST_INTERRUPTED, "device '%s': batch cancelled", od->info.name);
}

/* The classic ray tracer's batch (kernels/integrator/whitted.h): per wave, one k_whitted launch
 * computes every sample whole and counts its rays, then k_film adds the wave as for the
 * path tracer. Waves are numbered as in entry.cl. */
static Status render_whitted(OclDevice *od, uint first_sample, uint64_t total, Error *err)
{
    WaveSlot *w = &od->waves[0];
    Status st;
    for (uint64_t next_path = 0; next_path < total;) {
        if (cancel_requested(od)) return ST_INTERRUPTED;
        uint n = total - next_path < od->wave_paths ? (uint)(total - next_path) : od->wave_paths;
        uint first_pixel = (uint)(next_path % od->n_pixels), sample = first_sample + (uint)(next_path / od->n_pixels);
        cl_uint zero = 0, count = 0;
        OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, w->counts, &zero, sizeof zero, 0,
                                                           sizeof zero, 0, NULL, NULL));
        cl_kernel k = od->k_whitted;
        ARG(k, ARG_WHITTED_FIRST_PIXEL, first_pixel);
        ARG(k, ARG_WHITTED_FIRST_SAMPLE, sample);
        ARG(k, ARG_WHITTED_N_PIXELS, od->n_pixels);
        ARG(k, ARG_WHITTED_N_PATHS, n);
        ARG(k, ARG_WHITTED_PATHS, w->paths);
        ARG(k, ARG_WHITTED_COUNTERS, w->counts);
        if ((st = launch(od, k, "k_whitted", n, err))) return st;
        k = od->k_whitted_film;
        ARG(k, ARG_FILM_PATHS, w->paths);
        ARG(k, ARG_FILM_N_PIXELS, od->n_pixels);
        ARG(k, ARG_FILM_FIRST_PIXEL, first_pixel);
        ARG(k, ARG_FILM_N_PATHS, n);
        ARG(k, ARG_FILM_FILM, od->film);
        if ((st = launch(od, k, "k_film", n < od->n_pixels ? n : od->n_pixels, err))) return st;
        OCL_TRY("clEnqueueReadBuffer", clEnqueueReadBuffer(od->queue, w->counts, CL_TRUE, 0, sizeof count, &count,
                                                           0, NULL, NULL));
        od->rays += count;
        next_path += n;
    }
    return ST_OK;
}

static Status ocl_render(Device *d, uint first_sample, uint count, Error *err)
{
    OclDevice *od = d->impl;
    FilmSlot *fs = &od->slots[od->head % od->n_slots];
    if (fs->read_done)
        return error_set(err, ST_INTERNAL, "device '%s': more than %u batches in flight", od->info.name, od->n_slots);
    uint64_t n_pixels = od->n_pixels, total = n_pixels * count;
    if (fs->stale) {
        /* in order on the queue: cleared before the batch's kernels add to it */
        cl_long zero = 0;
        OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, fs->film, &zero, sizeof zero, 0,
                                                           (size_t)n_pixels * 3u * sizeof(cl_long), 0, NULL, NULL));
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
        st = render_whitted(od, first_sample, total, err);
        total = 0;   /* the wave loop below then has nothing to do */
    }
    for (; st == ST_OK;) {
        if (cancel_requested(od)) {
            st = ST_INTERRUPTED;
            break;
        }
        int any = 0;
        for (int i = 0; i < WAVE_SLOTS && st == ST_OK; i++) {
            WaveSlot *w = &od->waves[i];
            if (w->active) st = wave_advance(od, w, err);
            if (st == ST_OK && !w->active && next_path < total) {
                uint n = total - next_path < wave ? (uint)(total - next_path) : (uint)wave;
                st = wave_start(od, w, (uint)(next_path % n_pixels), first_sample + (uint)(next_path / n_pixels), n, err);
                next_path += n;
            }
            any |= w->active;
        }
        if (st != ST_OK || !any) break;
    }
    if (st == ST_INTERRUPTED) return cancel_batch(od, fs, err);
    if (st != ST_OK) {
        for (int i = 0; i < WAVE_SLOTS; i++) release_event(&od->waves[i].read);
        return st;
    }
    /* The film comes back while the next batch renders; zeroed on the device after. */
    size_t bytes = (size_t)n_pixels * 3u * sizeof(cl_long);
    OCL_TRY("clEnqueueReadBuffer", clEnqueueReadBuffer(od->queue, fs->film, CL_FALSE, 0, bytes, fs->host, 0, NULL,
                                                       &fs->read_done));
    cl_long zero = 0;
    cl_event ev = NULL;
    OCL_TRY("clEnqueueFillBuffer", clEnqueueFillBuffer(od->queue, fs->film, &zero, sizeof zero, 0, bytes, 0, NULL,
                                                       od->phases ? &ev : NULL));
    if (ev) profile_track(od, ev, PHASE_FILM);
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
        profile_add(od, fs->read_done, PHASE_FILM);
        profile_collect(od);
    }
    release_event(&fs->read_done);
    od->tail++;
    size_t n = (size_t)od->n_pixels * 3u;
    for (size_t i = 0; i < n; i++) film[i] += fs->host[i];
    return ST_OK;
}

static void ocl_destroy(Device *d)
{
    OclDevice *od = d->impl;
    if (od) {
        release_buffers(od);   /* finishes the queue: every tracked command is complete */
        profile_collect(od);
        for (size_t i = 0; i < od->n_profiled; i++) clReleaseEvent(od->profiled[i].event);
        free(od->profiled);
        for (int i = 0; i < PROG_N; i++) release_program(od, i);
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
