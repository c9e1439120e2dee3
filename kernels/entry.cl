/*
 * entry.cl — every __kernel of clpt. Each is a thin wrapper: it reads its work index,
 * gathers the scene buffers into a SceneView and calls the per-path stage functions of
 * raygen.cl, traverse.cl, shade.cl and film.cl, which the scalar C device calls too.
 * Queueing (which paths are still alive) happens here, not in the stage functions.
 *
 * Paths are numbered sample-major over the image: path number p renders pixel
 * p % n_pixels with sample index p / n_pixels (counted from the batch's first sample),
 * and a wave is a contiguous run of path numbers starting at pixel `first_pixel`, so
 * every wave of a batch is full whatever the image size. Each bounce is intersect →
 * shade → shadow over the queue of live paths; shade appends survivors to the next
 * queue and counts them, and the host launches the next bounce over exactly that many.
 *
 * k_shade counts into per-wave count slots QUEUE_COUNT_STRIDE uints apart (one per
 * cache line, types.h): at bounce b, slot 2b + 1 counts its shadow rays and slot 2b + 2
 * the paths that go on; the host puts the wave's size in slot 0. Every bounce has its
 * own slots, so a wave's counters are zeroed once and the host can read them back while
 * later bounces run. Each bounce kernel also takes no more work-items than the count of
 * its queue on the device (slot 2b for intersect and shade, 2b + 1 for shadow), so the
 * host may launch it over an upper bound without waiting for the count (GPUs,
 * device_ocl.c) or over exactly the count it read back (CPUs).
 *
 * The host builds the path tracer's kernels and the classic ray tracer's as two programs
 * (CLPT_FEATURES with KF_PATH or KF_WHITTED, types.h; a CPU device's path program has
 * KF_PATH_MEGAKERNEL instead, the path tracer as one kernel, or KF_PATH_LANES, the same
 * eight paths at a time), each on first use: a driver
 * compiles every kernel of a program, so a path-tracer run never waits for k_whitted,
 * nor a whitted run for k_shade. k_film is in both; k_layout only in the whole program
 * (no CLPT_FEATURES: the tests), as PoCL would compile it too in every program for
 * nothing.
 */
#include "film.cl"
#include "raygen.cl"
#include "shade.cl"
#if KF_HAS(KF_PATH_LANES)
#include "shade_lanes.cl"
#endif
#include "traverse.cl"
#include "alpha.h"
#include "whitted.cl"

/* The scene buffers as __kernel parameters, one per line of scene_buffers.h, each
 * followed by a comma (every kernel taking them has parameters after them), and their
 * gathering into a SceneView named sc. */
#define SCENE_ARG_(kind, Type, name, count, what) __global const Type *name,
#define SCENE_ARGS SCENE_BUFFERS(SCENE_ARG_)
#define SCENE_VIEW_SET_(kind, Type, name, count, what) sc.name = name;
#define SCENE_VIEW(sc)                                                                   \
    SceneView sc;                                                                        \
    SCENE_BUFFERS(SCENE_VIEW_SET_)

/* CLPT_LOCAL_SIZE (set by the renderer, device_ocl.c, when it launches every kernel with
 * that work-group size): declared on every kernel the renderer launches, so a driver
 * compiles them for that size once. PoCL compiles a work-group function per kernel and
 * size: for the program binary clpt caches, and again at the first launch unless the
 * sizes match. */
#ifdef CLPT_LOCAL_SIZE
#define KERNEL_SIZE __attribute__((reqd_work_group_size(CLPT_LOCAL_SIZE, 1, 1)))
/* k_path_lanes' work-items hold PATH_LANES paths each, so its work-groups are that many
 * times smaller: as many paths per work-group as k_path's. With 64 work-items (512
 * paths) the last work-groups of a wave kept one CPU thread busy while the other
 * waited: 8 made the McGuire box 3.9% faster, cornell-box 4.6%, the dragon 1.3%; 4 was
 * no faster. */
#define KERNEL_SIZE_LANES __attribute__((reqd_work_group_size(CLPT_LOCAL_SIZE / PATH_LANES, 1, 1)))
#else
#define KERNEL_SIZE
#define KERNEL_SIZE_LANES
#endif

#if KF_HAS(KF_PATH)
/* Births the wave's paths and queues them all: path i of the wave is path number
 * first_pixel + i of the batch (see the top of this file). */
__kernel KERNEL_SIZE void k_raygen(__global const RenderParams *params, uint first_pixel, uint first_sample,
                       uint n_pixels, uint n_paths, __global PathState *paths,
                       __global Ray *rays, __global uint *queue)
{
    uint i = (uint)get_global_id(0);
    if (i >= n_paths) return;
    uint p = first_pixel + i;
    raygen_path(params, p % n_pixels, first_sample + p / n_pixels, &paths[i], &rays[i]);
    queue[i] = i;
}

/* Closest hit for every queued path. */
__kernel KERNEL_SIZE void k_intersect(SCENE_ARGS __global const uint *queue, uint n,
                          __global const Ray *rays, __global Hit *hits,
                          __global const uint *counts, uint live_slot)
{
    uint i = (uint)get_global_id(0);
    if (i >= n || i >= counts[live_slot * QUEUE_COUNT_STRIDE]) return;
    SCENE_VIEW(sc);
    uint path = queue[i];
    hits[path] = trace_closest_visible(&sc, rays[path]);
}

/* Shades every queued path; count slot `slot` counts the shadow rays, slot + 1 the next
 * queue (see the top of this file). Their order in the queues varies from run to run,
 * the paths' results do not. Slots are reserved per work-group (local atomics, then one
 * global atomic_add per queue), because one global atomic per path made the shared
 * counters the hottest cache line of the whole render on a CPU. No early return: every
 * work-item must reach the barriers. */
__kernel KERNEL_SIZE void k_shade(SCENE_ARGS __global const uint *queue, uint n, __global Ray *rays,
                      __global const Hit *hits, __global PathState *paths,
                      __global Ray *shadow_rays, __global uint *next_queue,
                      __global uint *shadow_queue, __global uint *counts, uint slot)
{
    __local uint group_count[2];
    __local uint group_base[2];
    uint i = (uint)get_global_id(0);
    uint lid = (uint)get_local_id(0);
    if (lid == 0u) {
        group_count[0] = 0u;
        group_count[1] = 0u;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    uint r = 0u, path = 0u;
    if (i < n && i < counts[(slot - 1u) * QUEUE_COUNT_STRIDE]) {
        SCENE_VIEW(sc);
        path = queue[i];
        r = shade_path(&sc, &rays[path], hits[path], &paths[path], &shadow_rays[path]);
    }
    uint slot_next = 0u, slot_shadow = 0u;
    if (r & SHADE_CONTINUE) slot_next = atomic_inc(&group_count[0]);
    if (r & SHADE_SHADOW) slot_shadow = atomic_inc(&group_count[1]);
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lid == 0u) {
        group_base[0] = group_count[0] ? atomic_add(&counts[(slot + 1u) * QUEUE_COUNT_STRIDE], group_count[0]) : 0u;
        group_base[1] = group_count[1] ? atomic_add(&counts[slot * QUEUE_COUNT_STRIDE], group_count[1]) : 0u;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    if (r & SHADE_CONTINUE) next_queue[group_base[0] + slot_next] = path;
    if (r & SHADE_SHADOW) shadow_queue[group_base[1] + slot_shadow] = path;
}

/* Any-hit test of every queued shadow ray, resolving the waiting contributions. */
__kernel KERNEL_SIZE void k_shadow(SCENE_ARGS __global const uint *shadow_queue, uint n,
                       __global const Ray *shadow_rays, __global PathState *paths,
                       __global const uint *counts, uint live_slot)
{
    uint i = (uint)get_global_id(0);
    if (i >= n || i >= counts[live_slot * QUEUE_COUNT_STRIDE]) return;
    SCENE_VIEW(sc);
    uint path = shadow_queue[i];
    shadow_resolve(&paths[path], trace_occluded(&sc, shadow_rays[path]));
}

#endif /* KF_HAS(KF_PATH) */

#if KF_HAS(KF_PATH_MEGAKERNEL) || KF_HAS(KF_PATH_LANES)
/* Adds a work-item's n_rays to the 64-bit ray count of the megakernels, counters[0] with
 * the carry in counters[QUEUE_COUNT_STRIDE] (the adder whose addition wraps the low word
 * carries), one global atomic per work-group. Every work-item of the group calls it
 * (a barrier); group_rays, the group's sum, starts at 0 behind a barrier. */
KFN_INLINE void add_group_rays(__local uint *group_rays, uint n_rays, __global uint *counters)
{
    if (n_rays) atomic_add(group_rays, n_rays);
    barrier(CLK_LOCAL_MEM_FENCE);
    uint sum = *group_rays;
    if (get_local_id(0) == 0u && sum) {
        uint old = atomic_add(&counters[0], sum);
        if (old + sum < old) atomic_inc(&counters[QUEUE_COUNT_STRIDE]);
    }
}
#endif

#if KF_HAS(KF_PATH_MEGAKERNEL)
#include "path.cl"

/* The path tracer as one kernel, the CPUs' form: each work-item runs its path from
 * birth to end, calling the stage functions in the wavefront's order (the scalar
 * device's loop, device_scalar.c), so a path computes the same bits either way. On
 * PoCL this beat the counted wavefront by 3-13% on every bench scene: a path's state
 * stays in the cache, and there are no queues, atomics or barriers per bounce
 * (bench/RESULTS.md). Adds its
 * rays to counters[0], carrying into counters[QUEUE_COUNT_STRIDE] (a 64-bit count from
 * 32-bit atomics: the adder whose addition wraps the low word carries). */
__kernel KERNEL_SIZE void k_path(SCENE_ARGS uint first_pixel, uint first_sample, uint n_pixels, uint n_paths,
                                 __global PathState *paths, __global Ray *rays, __global Ray *shadow_rays,
                                 __global uint *counters)
{
    __local uint group_rays;
    uint i = (uint)get_global_id(0);
    if (get_local_id(0) == 0u) group_rays = 0u;
    barrier(CLK_LOCAL_MEM_FENCE);
    uint n_rays = 0u;
    if (i < n_paths) {
        SCENE_VIEW(sc);
        uint p = first_pixel + i;
        n_rays = path_run(&sc, p % n_pixels, first_sample + p / n_pixels, &paths[i], &rays[i], &shadow_rays[i]);
    }
    add_group_rays(&group_rays, n_rays, counters);
}

#endif /* KF_HAS(KF_PATH_MEGAKERNEL) */

#if KF_HAS(KF_PATH_LANES)
/* path_run for PATH_LANES paths at once: the paths first .. first + PATH_LANES - 1 below
 * n_paths. A call on CPUs, as path_run is and for the same reasons: PoCL built the
 * Cornell box's program in 1.7 s instead of 2.0 s, and rendered it 10-15% faster. */
KFN_CALL_CL uint path_run_lanes(const SceneView *sc, uint first, uint first_pixel, uint first_sample,
                                uint n_pixels, uint n_paths, __global PathState *paths, __global Ray *rays,
                                __global Ray *shadow_rays)
{
    uint n_rays = 0u;
    uint path[PATH_LANES];
    Hit hits[PATH_LANES];
    uint result[PATH_LANES];
    /* first-hit splitting (shade.cl), as path_run: each lane's camera ray and first hit,
     * and the continuations it still has to go */
    Ray first_ray[PATH_LANES];
    Hit first_hit[PATH_LANES];
    uint split[PATH_LANES];
    uint live = 0u;
    for (uint l = 0; l < PATH_LANES; l++) {
        uint i = first + l;
        path[l] = i;
        split[l] = 0u;
        if (i >= n_paths) continue;
        uint p = first_pixel + i;
        raygen_path(sc->params, p % n_pixels, first_sample + p / n_pixels, &paths[i], &rays[i]);
        first_ray[l] = rays[i];
        live |= 1u << l;
    }
    uint first_shade = live, restarted = 0u;
    while (live) {
        for (uint l = 0; l < PATH_LANES; l++) {
            if (!(live & ~restarted & (1u << l))) continue;
            hits[l] = trace_closest_visible(sc, rays[path[l]]);
            n_rays++;
            if (first_shade & (1u << l)) first_hit[l] = hits[l];
        }
        restarted = 0u;
        shade_lanes(sc, live, path, hits, rays, paths, shadow_rays, result);
        for (uint l = 0; l < PATH_LANES; l++) {
            if (!(live & (1u << l))) continue;
            uint i = path[l];
            if ((first_shade & (1u << l)) && (result[l] & SHADE_SCATTERED)) split[l] = params_split(sc->params) - 1u;
            if (result[l] & SHADE_SHADOW) {
                shadow_resolve(&paths[i], trace_occluded(sc, shadow_rays[i]));
                n_rays++;
            }
            if (result[l] & SHADE_CONTINUE) continue;
            if (split[l] == 0u) {
                live &= ~(1u << l);
                continue;
            }
            split[l]--;
            path_branch_next(&paths[i]);
            rays[i] = first_ray[l];
            hits[l] = first_hit[l];
            restarted |= 1u << l;
        }
        first_shade = 0u;
    }
    return n_rays;
}

/* k_path with PATH_LANES paths per work-item (kernels/shade_lanes.cl): work-item i runs
 * wave paths PATH_LANES i to PATH_LANES i + PATH_LANES - 1, tracing each live one's
 * rays in turn and shading them together, until all have ended. Each path computes the
 * bits it computes in k_path. Launched over ceil(n_paths / PATH_LANES) work-items. */
__kernel KERNEL_SIZE_LANES void k_path_lanes(SCENE_ARGS uint first_pixel, uint first_sample, uint n_pixels, uint n_paths,
                                       __global PathState *paths, __global Ray *rays, __global Ray *shadow_rays,
                                       __global uint *counters)
{
    __local uint group_rays;
    uint first = PATH_LANES * (uint)get_global_id(0);
    if (get_local_id(0) == 0u) group_rays = 0u;
    barrier(CLK_LOCAL_MEM_FENCE);
    uint n_rays = 0u;
    if (first < n_paths) {
        SCENE_VIEW(sc);
        n_rays = path_run_lanes(&sc, first, first_pixel, first_sample, n_pixels, n_paths, paths, rays, shadow_rays);
    }
    add_group_rays(&group_rays, n_rays, counters);
}
#endif /* KF_HAS(KF_PATH_LANES) */

/* Adds the finished wave of n_paths paths to the film. Work-item j owns one pixel, the
 * one of wave path j, and adds every path of the wave on that pixel (j, j + n_pixels,
 * ...), so no two work-items touch the same film entry; launched over
 * min(n_paths, n_pixels) work-items. */
__kernel KERNEL_SIZE void k_film(__global const PathState *paths, uint first_pixel, uint n_pixels,
                     uint n_paths, __global long *film)
{
    uint j = (uint)get_global_id(0);
    if (j >= n_paths || j >= n_pixels) return;
    uint pixel = (first_pixel + j) % n_pixels;
    for (uint i = j; i < n_paths; i += n_pixels) film_add(film, pixel, paths[i].radiance);
}

/* Writes sizeof and offsetof of the shared structs, for the host to compare with its
 * own layout (tests/test_kernels.c): a mismatch would silently corrupt every buffer.
 * tests/test_ocl.c's LAYOUT_VALUES is the number of values written here: its buffer
 * holds exactly that many. */
#if KF_HAS(KF_PATH) && KF_HAS(KF_WHITTED)
__kernel void k_layout(__global uint *out)
{
    if (get_global_id(0) != 0) return;
    uint i = 0;
    out[i++] = (uint)sizeof(vec3);
    out[i++] = (uint)sizeof(Ray);
    out[i++] = (uint)sizeof(Hit);
    out[i++] = (uint)sizeof(KdNode);
    out[i++] = (uint)sizeof(Sphere);
    out[i++] = (uint)sizeof(Triangle);
    out[i++] = (uint)sizeof(TriShading);
    out[i++] = (uint)sizeof(Box);
    out[i++] = (uint)sizeof(Plane);
    out[i++] = (uint)sizeof(Material);
    out[i++] = (uint)sizeof(Light);
    out[i++] = (uint)sizeof(Camera);
    out[i++] = (uint)sizeof(RenderParams);
    out[i++] = (uint)sizeof(PathState);
    out[i++] = (uint)__builtin_offsetof(RenderParams, bg_color);
    out[i++] = (uint)__builtin_offsetof(RenderParams, width);
    out[i++] = (uint)__builtin_offsetof(RenderParams, bounds_lo);
    out[i++] = (uint)__builtin_offsetof(PathState, bsdf_pdf);
    out[i++] = (uint)__builtin_offsetof(Material, albedo);
    out[i++] = (uint)__builtin_offsetof(Light, position);
    out[i++] = (uint)__builtin_offsetof(Camera, lens_u);
    out[i++] = (uint)__builtin_offsetof(TriShading, uv0);
    out[i++] = (uint)sizeof(Texture);
    out[i++] = (uint)__builtin_offsetof(Texture, m);
    out[i++] = (uint)__builtin_offsetof(Texture, color1);
    out[i++] = (uint)__builtin_offsetof(RenderParams, ambient);
    out[i++] = (uint)__builtin_offsetof(RenderParams, strata);
    out[i++] = (uint)__builtin_offsetof(Material, reflective);
    out[i++] = (uint)__builtin_offsetof(Light, cos_inner);
    out[i++] = (uint)__builtin_offsetof(Camera, forward);
    out[i++] = (uint)__builtin_offsetof(RenderParams, shadows);
    out[i++] = (uint)__builtin_offsetof(RenderParams, normal_miss_grey);
    out[i++] = (uint)__builtin_offsetof(Material, roughness);
    out[i++] = (uint)__builtin_offsetof(Material, k);
    out[i++] = (uint)__builtin_offsetof(Material, clearcoat_roughness);
    out[i++] = (uint)__builtin_offsetof(Material, texture_rm);
    out[i++] = (uint)__builtin_offsetof(Material, normal_scale);
    out[i++] = (uint)sizeof(RevSurface);
    out[i++] = (uint)__builtin_offsetof(RevSurface, axis_x);
    out[i++] = (uint)__builtin_offsetof(RenderParams, n_revsurfaces);
    out[i++] = (uint)__builtin_offsetof(RenderParams, bg_light);
    out[i++] = (uint)sizeof(TriExtra);
    out[i++] = (uint)__builtin_offsetof(TriExtra, uv);
    out[i++] = (uint)__builtin_offsetof(Material, absorption);
    out[i++] = (uint)__builtin_offsetof(Material, sheen_color);
    out[i++] = (uint)__builtin_offsetof(Material, texture_sheen_roughness);
    out[i++] = (uint)__builtin_offsetof(Material, layer_albedo);
    out[i++] = (uint)__builtin_offsetof(Material, base_roughness);
    out[i++] = (uint)sizeof(SphereXform);
    out[i++] = (uint)__builtin_offsetof(SphereXform, to_object);
    out[i++] = (uint)__builtin_offsetof(Sphere, xform);
}
#endif

/* ---------------------------------------------------------------- classic ray tracer
 * The whitted integrator and the auxiliary images (kernels/whitted.cl): one work-item
 * computes one pixel sample whole, with its own stack of mirror and refracted rays, and
 * leaves the radiance in its path state for k_film. Path numbers are sample-major as in
 * k_raygen: work-item i is path first_pixel + i of sample first_sample. counters[0]
 * receives the number of rays traced (summed per work-group first). No early return:
 * every work-item must reach the barriers. */
#if KF_HAS(KF_WHITTED)
__kernel KERNEL_SIZE void k_whitted(SCENE_ARGS uint first_pixel, uint first_sample, uint n_pixels, uint n_paths,
                        __global PathState *paths, __global uint *counters)
{
    __local uint group_rays;
    uint i = (uint)get_global_id(0);
    if (get_local_id(0) == 0) group_rays = 0u;
    barrier(CLK_LOCAL_MEM_FENCE);
    uint rays = 0u;
    if (i < n_paths) {
        SCENE_VIEW(sc);
        uint p = first_pixel + i;
        paths[i].radiance = whitted_sample(&sc, p % n_pixels, first_sample + p / n_pixels, &rays);
    }
    if (rays) atomic_add(&group_rays, rays);
    barrier(CLK_LOCAL_MEM_FENCE);
    if (get_local_id(0) == 0 && group_rays) atomic_add(&counters[0], group_rays);
}
#endif /* KF_HAS(KF_WHITTED) */

/* ------------------------------------------------------------------------------------
 * Trace-only kernels for the traversal benchmark (bench/bench_traverse.c): rays from a
 * plain array, no path state. Kept apart from the render kernels above, and compiled
 * only when the benchmark asks (-D CLPT_BENCH_KERNELS): each holds whole inlined walks,
 * which took PoCL 2.5 s of every program build.
 * ------------------------------------------------------------------------------------ */
#ifdef CLPT_BENCH_KERNELS

/* Closest hits of rays[2i] and rays[2i+1], walked in turns (trace_closest2). */
__kernel void k_trace_closest(SCENE_ARGS __global const Ray *rays, uint n, __global Hit *hits)
{
    uint a = 2u * (uint)get_global_id(0), b = a + 1u;
    if (a >= n) return;
    SCENE_VIEW(sc);
    if (b < n) {
        Hit ha, hb;
        trace_closest2(&sc, rays[a], rays[b], &ha, &hb);
        hits[a] = ha;
        hits[b] = hb;
    } else {
        hits[a] = trace_closest_in(&sc, TREE_KD, rays[a]);
    }
}

/* Whether rays[2i] and rays[2i+1] hit anything, into occluded[] (1 or 0). */
__kernel void k_trace_any(SCENE_ARGS __global const Ray *rays, uint n, __global uint *occluded)
{
    uint a = 2u * (uint)get_global_id(0), b = a + 1u;
    if (a >= n) return;
    SCENE_VIEW(sc);
    if (b < n) {
        int oa, ob;
        trace_any2(&sc, rays[a], rays[b], &oa, &ob);
        occluded[a] = (uint)oa;
        occluded[b] = (uint)ob;
    } else {
        occluded[a] = (uint)trace_any_in(&sc, TREE_KD, rays[a]);
    }
}

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

__kernel void k_trace_closest1(SCENE_ARGS __global const Ray *rays, uint n, __global Hit *hits)
{
    SCENE_VIEW(sc);
    trace_one_item(&sc, rays, n, TREE_KD, 0, hits, 0);
}

__kernel void k_trace_any1(SCENE_ARGS __global const Ray *rays, uint n, __global uint *occluded)
{
    SCENE_VIEW(sc);
    trace_one_item(&sc, rays, n, TREE_KD, 1, 0, occluded);
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

__kernel void k_trace_closest8(SCENE_ARGS __global const Ray *rays, uint n, __global Hit *hits)
{
    SCENE_VIEW(sc);
    trace_packet_item(&sc, rays, n, TREE_KD, 0, hits, 0);
}

__kernel void k_trace_any8(SCENE_ARGS __global const Ray *rays, uint n, __global uint *occluded)
{
    SCENE_VIEW(sc);
    trace_packet_item(&sc, rays, n, TREE_KD, 1, 0, occluded);
}

/* The same through the 8-wide BVH (trace_packet_wide). */
__kernel void k_trace_closest_wide8(SCENE_ARGS __global const Ray *rays, uint n, __global Hit *hits)
{
    SCENE_VIEW(sc);
    trace_packet_item(&sc, rays, n, TREE_BVH, 0, hits, 0);
}

__kernel void k_trace_any_wide8(SCENE_ARGS __global const Ray *rays, uint n, __global uint *occluded)
{
    SCENE_VIEW(sc);
    trace_packet_item(&sc, rays, n, TREE_BVH, 1, 0, occluded);
}

/* The same through the 8-wide BVH. */
__kernel void k_trace_closest_wide(SCENE_ARGS __global const Ray *rays, uint n, __global Hit *hits)
{
    SCENE_VIEW(sc);
    trace_one_item(&sc, rays, n, TREE_BVH, 0, hits, 0);
}

__kernel void k_trace_any_wide(SCENE_ARGS __global const Ray *rays, uint n, __global uint *occluded)
{
    SCENE_VIEW(sc);
    trace_one_item(&sc, rays, n, TREE_BVH, 1, 0, occluded);
}

/* Closest hits (any == 0) or occlusion (any == 1) of rays[PATH_LANES i] to
 * rays[PATH_LANES i + PATH_LANES - 1], walked one after another in one work-item through
 * the BVH: the form in which k_path_lanes, the renderer's kernel on CPUs, calls the walk
 * (its lanes' rays in turn). PoCL computes the addresses of a work-item's private
 * arrays, the walk's stack among them, once per item: k_trace_closest_wide pays that
 * per ray. */
KFN_INLINE void trace_lanes_item(const SceneView *sc, __global const Ray *rays, uint n, int any,
                                 __global Hit *hits, __global uint *occluded)
{
    uint first = PATH_LANES * (uint)get_global_id(0);
    for (uint i = first; i < first + PATH_LANES && i < n; i++)
        trace_one_ray(sc, rays, i, TREE_BVH, any, hits, occluded);
}

__kernel void k_trace_closest_lanes(SCENE_ARGS __global const Ray *rays, uint n, __global Hit *hits)
{
    SCENE_VIEW(sc);
    trace_lanes_item(&sc, rays, n, 0, hits, 0);
}

__kernel void k_trace_any_lanes(SCENE_ARGS __global const Ray *rays, uint n, __global uint *occluded)
{
    SCENE_VIEW(sc);
    trace_lanes_item(&sc, rays, n, 1, 0, occluded);
}
#endif /* CLPT_BENCH_KERNELS */
