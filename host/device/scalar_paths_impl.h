/*
 * scalar_paths_impl.h — one build of the scalar device's per-sample code (scalar_paths.h):
 * the kernel sources compiled as plain C (one source with the OpenCL build, through
 * kernels/util/compat.h) with the features CLPT_FEATURES names.
 *
 * Included once by each scalar_paths_NAME.c, which first defines
 *   CLPT_FEATURES        the kernel features of this build (before anything includes
 *                        kernels/types.h, which otherwise compiles everything)
 *   SCALAR_PATHS         the name of the ScalarPaths it defines (scalar_paths_NAME)
 *   SCALAR_PATHS_LABEL   its name as text ("NAME")
 * and the Makefile compiles each file twice more on x86-64, with -mavx2
 * -DSCALAR_PATHS_AVX2, which appends _avx2 to the name, and with -march=x86-64-v4
 * -DSCALAR_PATHS_AVX512, which appends _avx512 (scalar_paths.h says why).
 * Everything else here is static: each build's copy of the kernels is its own.
 */
#if !defined(CLPT_FEATURES) || !defined(SCALAR_PATHS) || !defined(SCALAR_PATHS_LABEL)
#error "define CLPT_FEATURES, SCALAR_PATHS and SCALAR_PATHS_LABEL before including scalar_paths_impl.h"
#endif

/* The basic materials' feature bits as numbers, for the CLPT_FEATURES of the builds
 * that name them ('mesh', 'basic'), expanded where KF_HAS is used: KF_MAT_* are enum
 * constants, which #if reads as 0 (checked below). */
#define SCALAR_PATHS_MAT_DIFFUSE 0x800u
#define SCALAR_PATHS_MAT_METAL 0x1000u
#define SCALAR_PATHS_MAT_DIELECTRIC 0x2000u
#define SCALAR_PATHS_MAT_EMISSIVE 0x4000u

#define SCALAR_PATHS_PASTE2(a, b) a##b
#define SCALAR_PATHS_PASTE(a, b) SCALAR_PATHS_PASTE2(a, b)
#if defined(SCALAR_PATHS_AVX512)
#if !defined(__AVX512F__) || !defined(__AVX512VL__) || !defined(__AVX512BW__) || !defined(__AVX512DQ__)
#error "SCALAR_PATHS_AVX512: compile with -march=x86-64-v4"
#endif
#define SCALAR_PATHS_BUILD SCALAR_PATHS_PASTE(SCALAR_PATHS, _avx512)
#define SCALAR_PATHS_NAME SCALAR_PATHS_LABEL "-avx512"
#define SCALAR_PATHS_ISA SCALAR_ISA_AVX512
#elif defined(SCALAR_PATHS_AVX2)
#ifndef __AVX2__
#error "SCALAR_PATHS_AVX2: compile with -mavx2"
#endif
#define SCALAR_PATHS_BUILD SCALAR_PATHS_PASTE(SCALAR_PATHS, _avx2)
#define SCALAR_PATHS_NAME SCALAR_PATHS_LABEL "-avx2"
#define SCALAR_PATHS_ISA SCALAR_ISA_AVX2
#else
#define SCALAR_PATHS_BUILD SCALAR_PATHS
#define SCALAR_PATHS_NAME SCALAR_PATHS_LABEL
#define SCALAR_PATHS_ISA SCALAR_ISA_BASE
#endif

#include <string.h>

#include "device/device.h"
#include "device/scalar_paths.h"
#include "base/timer.h"

/* The kernel sources, compiled here as C. */
#include "integrator/raygen.h"
#include "integrator/shade_path.h"
#include "accel/traverse.h"
#include "accel/alpha.h"
#include "integrator/path.h"
#include "integrator/whitted.h"

_Static_assert(SCALAR_PATHS_MAT_DIFFUSE == KF_MAT_DIFFUSE && SCALAR_PATHS_MAT_METAL == KF_MAT_METAL &&
                   SCALAR_PATHS_MAT_DIELECTRIC == KF_MAT_DIELECTRIC && SCALAR_PATHS_MAT_EMISSIVE == KF_MAT_EMISSIVE,
               "scalar_paths_impl.h: the material bits of kernels/types.h");

/* Renders one camera sample's path to its end (path_run, kernels/integrator/path.h, as k_path
 * does); returns the number of rays it traced. */
static uint64_t render_path(const SceneView *sc, uint pixel, uint sample, vec3 *radiance)
{
    PathState ps;
    Ray ray, shadow;
    memset(&shadow, 0, sizeof shadow);   /* written by shade_path only when it traces one */
    uint64_t rays = path_run(sc, pixel, sample, &ps, &ray, &shadow);
    *radiance = ps.radiance;
    return rays;
}

/* render_path with the thread time of each stage added to t[enum DevicePhase]
 * (--profile; the clock reads cost some of the speed): path_run's loop, timed. */
static uint64_t render_path_timed(const SceneView *sc, uint pixel, uint sample, vec3 *radiance, double *t)
{
    PathState path;
    Ray ray_buf, shadow;
    memset(&shadow, 0, sizeof shadow);
    PathState *ps = &path;
    Ray *ray = &ray_buf, *shadow_ray = &shadow;
    double t_last = timer_now();
#define PATH_STAGE_TIMED(phase)            \
    do {                                   \
        double now = timer_now();          \
        t[phase] += now - t_last;          \
        t_last = now;                      \
    } while (0)
    PATH_RUN_BODY(PATH_STAGE_TIMED)
#undef PATH_STAGE_TIMED
    *radiance = ps->radiance;
    return n_rays;
}

static void query_closest(const SceneView *sc, const Ray *ray, Hit *hit) { *hit = trace_closest_visible(sc, *ray); }
static int query_any(const SceneView *sc, const Ray *ray) { return trace_occluded(sc, *ray); }

const ScalarPaths SCALAR_PATHS_BUILD = {
    .name = SCALAR_PATHS_NAME,
    .features = CLPT_FEATURES,
    .isa = SCALAR_PATHS_ISA,
    .path = render_path,
    .path_timed = render_path_timed,
    .whitted = whitted_sample,
    .closest = query_closest,
    .any = query_any,
};
