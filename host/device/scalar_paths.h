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

/* The instruction sets a build is compiled for, each a superset of the one before. */
typedef enum {
    SCALAR_ISA_BASE = 0,   /* any processor of the target (on x86-64: SSE2) */
    SCALAR_ISA_AVX2 = 1,   /* x86-64 with AVX2 (-mavx2) */
    SCALAR_ISA_AVX512 = 2  /* x86-64 with AVX-512 F, VL, BW, DQ and CD (-march=x86-64-v4) */
} ScalarIsa;

typedef struct ScalarPaths {
    const char *name;     /* for --profile and the tests: "mesh", "basic", "lean", "all", and with
                           * "-avx2" or "-avx512" for the builds for those */
    unsigned features;    /* the CLPT_FEATURES it was compiled with */
    ScalarIsa isa;        /* the instruction set it was compiled for */
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

/* The builds, leanest first (each file's comment says what it has): triangles and
 * planes of the basic materials (diffuse, metal, dielectric, emissive) without textures,
 * cut-outs, background maps or delta lights; the same with spheres and boxes; every
 * feature but media and instances; every feature. */
extern const ScalarPaths scalar_paths_mesh;
extern const ScalarPaths scalar_paths_basic;
extern const ScalarPaths scalar_paths_lean;
extern const ScalarPaths scalar_paths_all;

/* On x86-64 each build is compiled three times: for any x86-64 processor (SSE2); with
 * -mavx2 for the processors that have AVX2 (Intel since 2013, AMD since 2015), where a
 * BVH node's eight boxes and a group of eight triangles are each tested as one 8-wide
 * vector instead of two 4-wide halves (K_VEC8, kernels/util/compat.h); and for
 * x86-64-v4, the processors with AVX-512 (Intel's servers since 2017, AMD since Zen 4),
 * whose mask registers take the lanes' comparisons and whose 32 vector registers hold
 * a walk's state (the walks up to 33% faster in bench_traverse, docs/design.md). All compute
 * the same IEEE operations per lane without contraction, so they render the same bits;
 * the processor decides which runs (as Cycles and Embree pick their kernels). */
#if defined(__x86_64__)
#define SCALAR_PATHS_HAVE_AVX2 1
extern const ScalarPaths scalar_paths_mesh_avx2;
extern const ScalarPaths scalar_paths_basic_avx2;
extern const ScalarPaths scalar_paths_lean_avx2;
extern const ScalarPaths scalar_paths_all_avx2;
extern const ScalarPaths scalar_paths_mesh_avx512;
extern const ScalarPaths scalar_paths_basic_avx512;
extern const ScalarPaths scalar_paths_lean_avx512;
extern const ScalarPaths scalar_paths_all_avx512;
#else
#define SCALAR_PATHS_HAVE_AVX2 0
#endif

/* Every build in one table, which the pick walks and test_scalar_paths renders with:
 * a row per instruction set from SCALAR_ISA_BASE up (one row where there are no
 * others), each row leanest first, its last build the one of every feature. A new build
 * is a file scalar_paths_NAME.c, its externs above and a column here. */
#define SCALAR_PATHS_ISAS (SCALAR_PATHS_HAVE_AVX2 ? 3 : 1)
#define SCALAR_PATHS_BUILDS 4
extern const ScalarPaths *const scalar_paths_builds[SCALAR_PATHS_ISAS][SCALAR_PATHS_BUILDS];

/* The best instruction set this processor and its operating system run of those the
 * builds were compiled for. */
ScalarIsa scalar_paths_isa_usable(void);

/* Its name for listings: "SSE2", "AVX2", "AVX-512"; "" where there is one build. */
const char *scalar_paths_isa_name(ScalarIsa isa);

/* The leanest build whose features include `features` (kernel_scene_features's, with
 * kernel_params_features's), the build of everything when none is leaner, among the
 * builds for instruction set `isa` (those for SCALAR_ISA_BASE where there are no
 * others). */
const ScalarPaths *scalar_paths_pick_isa(unsigned features, ScalarIsa isa);

/* The same for this processor: the builds for the best instruction set it has. */
const ScalarPaths *scalar_paths_pick(unsigned features);

#endif /* CLPT_SCALAR_PATHS_H */
