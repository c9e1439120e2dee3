/*
 * bench/trace.cl — trace-only kernels for the traversal benchmark (bench/bench_traverse.c
 * and test_kernels' parity checks): rays from a plain array, no path state. A program of
 * its own, built only by those two (ocl_program_build_source with clpt_bench_kernel_source),
 * so the renderer's source never carries them: each holds whole inlined walks, which
 * took PoCL 2.5 s of every program build when they sat in entry.cl.
 */
#include "accel/traverse.h"
#include "kernel_args.h"

/* The closest hit of rays[i] (any == 0) or whether it hits anything (any == 1), through
 * the given tree (trace_closest as k_intersect, trace_any as k_shadow). */
KFN_INLINE void trace_one_ray(const SceneView *sc, __global const Ray *rays, uint i, int tree, int any,
                              __global Hit *hits, __global uint *occluded)
{
    if (any) occluded[i] = (uint)trace_any_in(sc, tree, rays[i]);
    else hits[i] = trace_closest_in(sc, tree, rays[i]);
}

/* One ray per work-item. */
KFN_INLINE void trace_one_item(const SceneView *sc, __global const Ray *rays, uint n, int tree, int any,
                               __global Hit *hits, __global uint *occluded)
{
    uint i = (uint)get_global_id(0);
    if (i < n) trace_one_ray(sc, rays, i, tree, any, hits, occluded);
}

/* Closest hits (any == 0) or occlusion (any == 1) of rays[2i] and rays[2i+1], walked in
 * turns through the kd-tree (trace_closest2, trace_any2; `tree` is TREE_KD); a last
 * ray without a partner walks alone. */
KFN_INLINE void trace_pair_item(const SceneView *sc, __global const Ray *rays, uint n, int tree, int any,
                                __global Hit *hits, __global uint *occluded)
{
    uint a = 2u * (uint)get_global_id(0), b = a + 1u;
    if (a >= n) return;
    if (!(b < n)) {
        trace_one_ray(sc, rays, a, tree, any, hits, occluded);
    } else if (any) {
        int oa, ob;
        trace_any2(sc, rays[a], rays[b], &oa, &ob);
        occluded[a] = (uint)oa;
        occluded[b] = (uint)ob;
    } else {
        Hit ha, hb;
        trace_closest2(sc, rays[a], rays[b], &ha, &hb);
        hits[a] = ha;
        hits[b] = hb;
    }
}

/* Closest hits (any == 0) or occlusion (any == 1: 1 or 0 in hits[i].prim's place, as
 * occluded[]) of rays[8i .. 8i+7], walked as one packet through the given tree
 * (trace_packet, trace_packet_wide). */
KFN_INLINE void trace_packet_item(const SceneView *sc, __global const Ray *rays, uint n, int tree, int any,
                                  __global Hit *hits, __global uint *occluded)
{
    uint first = TRACE_PACKET * (uint)get_global_id(0);
    if (first >= n) return;
    Ray r[TRACE_PACKET];
    Hit h[TRACE_PACKET];
    uint count = n - first < TRACE_PACKET ? n - first : TRACE_PACKET;
    for (uint l = 0; l < TRACE_PACKET; l++) {
        r[l] = rays[first + (l < count ? l : 0u)];
        /* a short last packet repeats its first ray, whose answer is then not stored */
    }
    if (tree == TREE_BVH) trace_packet_wide(sc, r, any, h);
    else trace_packet(sc, r, any, h);
    for (uint l = 0; l < count; l++) {
        if (any) occluded[first + l] = (uint)(h[l].prim != NO_INDEX);
        else hits[first + l] = h[l];
    }
}

/* Closest hits (any == 0) or occlusion (any == 1) of rays[PATH_LANES i] to
 * rays[PATH_LANES i + PATH_LANES - 1], walked one after another in one work-item through
 * the BVH: the form in which k_path_lanes, the renderer's kernel on CPUs, calls the walk
 * (its lanes' rays in turn). PoCL computes the addresses of a work-item's private
 * arrays, the walk's stack among them, once per item: k_trace_closest_wide pays that
 * per ray. */
KFN_INLINE void trace_lanes_item(const SceneView *sc, __global const Ray *rays, uint n, int tree, int any,
                                 __global Hit *hits, __global uint *occluded)
{
    uint first = PATH_LANES * (uint)get_global_id(0);
    for (uint i = first; i < first + PATH_LANES && i < n; i++)
        trace_one_ray(sc, rays, i, tree, any, hits, occluded);
}

/* Each walk above as a pair of kernels: k_trace_closest<suffix> writes hits[i],
 * k_trace_any<suffix> occluded[i] (1 or 0). */
#define TRACE_KERNELS(suffix, walk, tree)                                                    \
    __kernel void k_trace_closest##suffix(SCENE_ARGS __global const Ray *rays, uint n,       \
                                          __global Hit *hits)                                \
    {                                                                                        \
        SCENE_VIEW(sc);                                                                      \
        walk(&sc, rays, n, tree, 0, hits, 0);                                                \
    }                                                                                        \
    __kernel void k_trace_any##suffix(SCENE_ARGS __global const Ray *rays, uint n,           \
                                      __global uint *occluded)                               \
    {                                                                                        \
        SCENE_VIEW(sc);                                                                      \
        walk(&sc, rays, n, tree, 1, 0, occluded);                                            \
    }

TRACE_KERNELS(, trace_pair_item, TREE_KD)            /* the kd-tree, two rays in turns per item */
TRACE_KERNELS(1, trace_one_item, TREE_KD)            /* the kd-tree, one ray per item */
TRACE_KERNELS(8, trace_packet_item, TREE_KD)         /* the kd-tree, packets of eight */
TRACE_KERNELS(_wide, trace_one_item, TREE_BVH)       /* the BVH, one ray per item */
TRACE_KERNELS(_wide8, trace_packet_item, TREE_BVH)   /* the BVH, packets of eight */
TRACE_KERNELS(_lanes, trace_lanes_item, TREE_BVH)    /* the BVH, eight rays in turn per item */
