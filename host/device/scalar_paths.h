/*
 * scalar_paths.h — the scalar device's per-sample code (a path to its end, timed or not,
 * and a whitted sample), compiled more than once with different kernel features.
 *
 * The OpenCL device builds each scene's program with only the features the scene has
 * (-D CLPT_FEATURES, kernels/types.h); C code is compiled once, so the scalar device
 * ships a few builds of the same kernel source and picks the leanest one whose features
 * cover the scene's. Without that, every scene pays for the code of the rarest ones:
 * participating media (the checks at each bounce of shade_path) and instancing (the BVH
 * walk's second level) made the scalar device 14% slower on scenes that have neither
 * (docs/design.md, "One kernel source, two compilers", has the numbers).
 * A switch only removes code a scene cannot reach, so every build renders the same bits.
 *
 * Each build is a file scalar_paths_NAME.c that sets CLPT_FEATURES and includes
 * scalar_paths_impl.h, which defines its ScalarPaths.
 */
#ifndef CLPT_SCALAR_PATHS_H
#define CLPT_SCALAR_PATHS_H

#include <stdint.h>

#include "scene_view.h"

typedef struct ScalarPaths {
    const char *name;     /* for --profile and the tests: "basic", "lean", "all", and with
                           * "-avx2" for the builds for AVX2 */
    unsigned features;    /* the CLPT_FEATURES it was compiled with */
    int avx2;             /* 1: compiled for x86-64 processors with AVX2 (-mavx2) */
    /* one camera sample's path to its end (path_run, kernels/integrator/path.h, as k_path
     * runs it): its radiance; returns the rays it traced */
    uint64_t (*path)(const SceneView *sc, uint pixel, uint sample, vec3 *radiance);
    /* ... with the thread time of each stage added to t[enum DevicePhase] (--profile) */
    uint64_t (*path_timed)(const SceneView *sc, uint pixel, uint sample, vec3 *radiance, double *t);
    /* the classic ray tracer's and the auxiliary images' sample (kernels/integrator/whitted.h) */
    vec3 (*whitted)(const SceneView *sc, uint pixel, uint sample, uint *rays);
    /* the closest-hit and any-hit queries of the renderer (trace_closest_visible,
     * trace_occluded, kernels/accel/alpha.h), alone: bench_traverse times the scalar
     * device's walk. The ray and the hit by address: a Ray passed by value goes through
     * the stack, where its copy cost a fifth of a walk that misses (bench_traverse) */
    void (*closest)(const SceneView *sc, const Ray *ray, Hit *hit);
    int (*any)(const SceneView *sc, const Ray *ray);
} ScalarPaths;

/* The builds, leanest first (each file's comment says what it has): the basic materials
 * (diffuse, metal, dielectric, emissive) without textures, cut-outs, background maps or
 * delta lights; every feature but media and instances; every feature. */
extern const ScalarPaths scalar_paths_basic;
extern const ScalarPaths scalar_paths_lean;
extern const ScalarPaths scalar_paths_all;

/* On x86-64 each build is compiled twice: for any x86-64 processor (SSE2), and with
 * -mavx2 for the processors that have AVX2 (Intel since 2013, AMD since 2015), where a
 * BVH node's eight boxes and a group of eight triangles are each tested as one 8-wide
 * vector instead of two 4-wide halves (K_VEC8, kernels/util/compat.h). Both compute
 * the same IEEE operations per lane without contraction, so they render the same bits;
 * the processor decides which runs (as Cycles and Embree pick their kernels). */
#if defined(__x86_64__)
#define SCALAR_PATHS_HAVE_AVX2 1
extern const ScalarPaths scalar_paths_basic_avx2;
extern const ScalarPaths scalar_paths_lean_avx2;
extern const ScalarPaths scalar_paths_all_avx2;
#else
#define SCALAR_PATHS_HAVE_AVX2 0
#endif

/* 1 when this processor and its operating system run the AVX2 builds. */
int scalar_paths_avx2_usable(void);

/* The leanest build whose features include `features` (kernel_scene_features's, with
 * kernel_params_features's), the build of everything when none is leaner: for AVX2
 * when `avx2` is set and there are such builds. */
const ScalarPaths *scalar_paths_pick_isa(unsigned features, int avx2);

/* The same for this processor: the AVX2 builds where it has AVX2. */
const ScalarPaths *scalar_paths_pick(unsigned features);

#endif /* CLPT_SCALAR_PATHS_H */
