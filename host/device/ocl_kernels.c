/*
 * ocl_kernels.c — the OpenCL device's two programs (the path tracer's, the classic ray
 * tracer's), each built when a render first needs it for the features of the loaded
 * scene, and the arguments of their kernels that stay the same for a scene, set once.
 */
#include <stdio.h>

#include "base/fault.h"
#include "device/kernel_features.h"
#include "device/ocl_device.h"
#include "device/ocl_program.h"

static void release_kernel(cl_kernel *k)
{
    if (*k) clReleaseKernel(*k);
    *k = NULL;
}

Status ocld_set_arg(OclDevice *od, cl_kernel k, cl_uint i, size_t size, const void *value, Error *err)
{
    OCL_TRY("clSetKernelArg", clSetKernelArg(k, i, size, value));
    return ST_OK;
}

static Status set_scene_args(OclDevice *od, cl_kernel k, Error *err)
{
    for (cl_uint i = 0; i < SCENE_N; i++) ARG(k, i, od->scene[i]);
    return ST_OK;
}

/* The kernels of a wave that take the scene buffers: its megakernel, or the four
 * stages of its wavefront; their count. */
static int wave_scene_kernels(const WaveSlot *w, cl_kernel k[4])
{
    if (w->k_path) {
        k[0] = w->k_path;
        return 1;
    }
    k[0] = w->k_raygen;
    k[1] = w->k_intersect;
    k[2] = w->k_shade;
    k[3] = w->k_shadow;
    return 4;
}

/* The arguments of a wave's kernels that name a wave buffer and stay the same for the
 * whole render, one line each: X(kernel, argument, buffer), kernel and buffer being
 * WaveSlot members. The megakernel's list and the wavefront's; the film kernel's one
 * belongs to both. */
#define PATH_FIXED_ARGS(X)                          \
    X(k_path, ARG_PATH_PATHS, paths)                \
    X(k_path, ARG_PATH_RAYS, rays)                  \
    X(k_path, ARG_PATH_SHADOW_RAYS, shadow_rays)    \
    X(k_path, ARG_PATH_COUNTERS, counts)
#define WAVEFRONT_FIXED_ARGS(X)                          \
    X(k_raygen, ARG_RAYGEN_PATHS, paths)                 \
    X(k_raygen, ARG_RAYGEN_RAYS, rays)                   \
    X(k_raygen, ARG_RAYGEN_QUEUE, queue_a)               \
    X(k_intersect, ARG_INTERSECT_RAYS, rays)             \
    X(k_intersect, ARG_INTERSECT_HITS, hits)             \
    X(k_intersect, ARG_INTERSECT_COUNTS, counts)         \
    X(k_intersect, ARG_INTERSECT_PATHS, paths)           \
    X(k_shade, ARG_SHADE_RAYS, rays)                     \
    X(k_shade, ARG_SHADE_HITS, hits)                     \
    X(k_shade, ARG_SHADE_PATHS, paths)                   \
    X(k_shade, ARG_SHADE_SHADOW_RAYS, shadow_rays)       \
    X(k_shade, ARG_SHADE_SHADOW_QUEUE, shadow_queue)     \
    X(k_shade, ARG_SHADE_COUNTS, counts)                 \
    X(k_shadow, ARG_SHADOW_QUEUE, shadow_queue)          \
    X(k_shadow, ARG_SHADOW_RAYS, shadow_rays)            \
    X(k_shadow, ARG_SHADOW_PATHS, paths)                 \
    X(k_shadow, ARG_SHADOW_COUNTS, counts)

/* The arguments of a wave's kernels that stay the same for the whole render, set once
 * after the upload; per launch only queues, counts, positions, the pixels a sample
 * covers and the film change. */
static Status set_fixed_args(OclDevice *od, WaveSlot *w, Error *err)
{
    ARG(w->k_film, ARG_FILM_PATHS, w->paths);
    cl_kernel k[4];
    int n = wave_scene_kernels(w, k);
    for (int i = 0; i < n; i++) {
        Status st = set_scene_args(od, k[i], err);
        if (st) return st;
    }
#define X(kernel, argument, buffer) ARG(w->kernel, argument, w->buffer);
    if (w->k_path) {
        PATH_FIXED_ARGS(X)
    } else {
        WAVEFRONT_FIXED_ARGS(X)
    }
#undef X
    return ST_OK;
}

void ocld_release_program(OclDevice *od, int which)
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
Status ocld_set_program_args(OclDevice *od, int which, Error *err)
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
unsigned ocld_program_kernels(const OclDevice *od, int which)
{
    if (which == PROG_WHITTED) return KF_WHITTED;
    if (od->path_launch != WAVE_LAUNCH_MEGAKERNEL) return KF_PATH;
    return od->lanes ? KF_PATH_LANES : KF_PATH_MEGAKERNEL;
}

/* Builds the program the integrator needs, for the loaded scene's features, unless the
 * one there already has them; its kernels get their fixed arguments. */
Status ocld_need_program(Device *d, OclDevice *od, uint integrator, Error *err)
{
    int which = integrator == INTEGRATOR_PATH ? PROG_PATH : PROG_WHITTED;
    unsigned want = od->scene_features | ocld_program_kernels(od, which);
    if (od->programs[which] && (od->features[which] & want) == want) return ST_OK;
    ocld_release_program(od, which);
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
    if (st == ST_OK) st = ocld_set_program_args(od, which, err);
    if (st) ocld_release_program(od, which);
    return st;
}

/* Sets the scene buffer `b` as the argument of every kernel that takes the scene. */
Status ocld_set_scene_arg(OclDevice *od, unsigned b, Error *err)
{
    for (int i = 0; i < WAVE_SLOTS && od->programs[PROG_PATH]; i++) {
        cl_kernel k[4];
        int n = wave_scene_kernels(&od->waves[i], k);
        for (int j = 0; j < n; j++) ARG(k[j], b, od->scene[b]);
    }
    if (od->programs[PROG_WHITTED]) ARG(od->k_whitted, b, od->scene[b]);
    return ST_OK;
}
