/*
 * entry.cl — every __kernel the renderer launches (the traversal benchmark's are in
 * bench/trace.cl, a program of their own). Each is a thin wrapper: it reads its work index,
 * gathers the scene buffers into a SceneView and calls the per-path stage functions of
 * raygen.h, traverse.h, shade_path.h and film.h, which the scalar C device calls too.
 * Queueing (which paths are still alive) happens here, not in the stage functions.
 *
 * Paths are numbered sample-major over the pixels a sample covers (n_pixels: the
 * image's, or the pixel list's, RenderParams.pixel_list_size): path number p renders
 * pixel batch_pixel(p % n_pixels) (scene_view.h) with sample index p / n_pixels (counted
 * from the batch's first sample), and a wave is a contiguous run of path numbers
 * starting at pixel number `first_pixel`, so every wave of a batch is full whatever the
 * image size, and a pixel left out of the list costs nothing. Each bounce is intersect →
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
#include "film/film.h"
#include "integrator/raygen.h"
#include "integrator/shade_path.h"
#if KF_HAS(KF_PATH_LANES)
#include "integrator/shade_lanes.h"
#endif
#include "accel/traverse.h"
#include "accel/alpha.h"
#include "integrator/whitted.h"
#include "medium/transmit.h"
#include "kernel_args.h"

/* Every kernel the renderer launches is declared KERNEL_SIZE (or KERNEL_SIZE_LANES): the
 * vectoriser hint below, and CLPT_LOCAL_SIZE (set by the renderer, device_ocl.c, when it
 * launches every kernel with that work-group size), so that a driver compiles them for
 * that size once. PoCL compiles a work-group function per kernel and size: for the
 * program binary clpt caches, and again at the first launch unless the sizes match. */
/* Intel's CPU runtime (cl_intel_vec_len_hint) by default runs 8 or 16 work-items as the
 * lanes of one SIMD instruction stream, masked where their branches part. A path's
 * bounces, flights through a medium and BVH walks part at once, so every lane waited for
 * the longest: the fog and smoke scenes of bench/peers.py rendered 8 times slower than
 * with one work-item per stream, the counted wavefront 2-2.6 times, nothing got faster,
 * and the kernels took 1.7-4.6 times longer to build (bench/RESULTS.md, "Intel's CPU
 * runtime"). Length 1 asks for one work-item per stream, as PoCL runs them; where SIMD
 * pays, clpt writes it itself (k_path_lanes, the eight-wide walks). Other compilers do
 * not define the macro and see nothing. */
#ifdef cl_intel_vec_len_hint
#define KERNEL_NO_WI_SIMD __attribute__((intel_vec_len_hint(1)))
#else
#define KERNEL_NO_WI_SIMD
#endif
#ifdef CLPT_LOCAL_SIZE
#define KERNEL_SIZE KERNEL_NO_WI_SIMD __attribute__((reqd_work_group_size(CLPT_LOCAL_SIZE, 1, 1)))
/* k_path_lanes' work-items hold PATH_LANES paths each, so its work-groups are that many
 * times smaller: as many paths per work-group as k_path's. With 64 work-items (512
 * paths) the last work-groups of a wave kept one CPU thread busy while the other
 * waited: 8 made the McGuire box 3.9% faster, cornell-box 4.6%, the dragon 1.3%; 4 was
 * no faster. */
#define KERNEL_SIZE_LANES KERNEL_NO_WI_SIMD __attribute__((reqd_work_group_size(CLPT_LOCAL_SIZE / PATH_LANES, 1, 1)))
#else
#define KERNEL_SIZE KERNEL_NO_WI_SIMD
#define KERNEL_SIZE_LANES KERNEL_NO_WI_SIMD
#endif

/* The view sc at path state ps's time (motion blur: SceneView.time); nothing without
 * KF_MOTION. */
#if KF_HAS(KF_MOTION)
#define SCENE_VIEW_AT_TIME(sc, ps) sc.time = (ps).time
#else
#define SCENE_VIEW_AT_TIME(sc, ps) (void)(ps)
#endif

#if KF_HAS(KF_PATH)
/* Births the wave's paths and queues them all: path i of the wave is path number
 * first_pixel + i of the batch (see the top of this file). */
__kernel KERNEL_SIZE void k_raygen(SCENE_ARGS uint first_pixel, uint first_sample,
                       uint n_pixels, uint n_paths, __global PathState *paths,
                       __global Ray *rays, __global uint *queue)
{
    uint i = (uint)get_global_id(0);
    if (i >= n_paths) return;
    SCENE_VIEW(sc);
    uint p = first_pixel + i;
    raygen_path(sc.params, sc.motion_keys, batch_pixel(&sc, p % n_pixels), first_sample + p / n_pixels, &paths[i], &rays[i]);
    queue[i] = i;
}

/* Closest hit for every queued path. */
__kernel KERNEL_SIZE void k_intersect(SCENE_ARGS __global const uint *queue, uint n,
                          __global const Ray *rays, __global Hit *hits,
                          __global const uint *counts, uint live_slot, __global const PathState *paths)
{
    uint i = (uint)get_global_id(0);
    if (i >= n || i >= counts[live_slot * QUEUE_COUNT_STRIDE]) return;
    SCENE_VIEW(sc);
    uint path = queue[i];
    SCENE_VIEW_AT_TIME(sc, paths[path]);
    hits[path] = trace_flight(&sc, rays[path], &paths[path]);
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
        SCENE_VIEW_AT_TIME(sc, paths[path]);
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
    SCENE_VIEW_AT_TIME(sc, paths[path]);
    shadow_trace(&sc, &paths[path], shadow_rays[path]);   /* through media too */
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
#include "integrator/path.h"

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
        n_rays = path_run(&sc, batch_pixel(&sc, p % n_pixels), first_sample + p / n_pixels, &paths[i], &rays[i],
                          &shadow_rays[i]);
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
    /* first-hit splitting (shade_path.h), as path_run: each lane's camera ray and first hit,
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
        raygen_path(sc->params, sc->motion_keys, batch_pixel(sc, p % n_pixels), first_sample + p / n_pixels, &paths[i], &rays[i]);
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

/* k_path with PATH_LANES paths per work-item (kernels/integrator/shade_lanes.h): work-item i runs
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
 * one of wave path j (its PathState.pixel, which raygen_path and k_whitted set), and
 * adds every path of the wave on that pixel (j, j + n_pixels, ...), so no two
 * work-items touch the same film entry; launched over min(n_paths, n_pixels)
 * work-items. */
__kernel KERNEL_SIZE void k_film(__global const PathState *paths, uint n_pixels, uint n_paths,
                     __global long *film)
{
    uint j = (uint)get_global_id(0);
    if (j >= n_paths || j >= n_pixels) return;
    uint pixel = paths[j].pixel;
    for (uint i = j; i < n_paths; i += n_pixels) film_add(film, pixel, paths[i].radiance);
}

/* Writes sizeof and offsetof of the shared structs, for the host to compare with its
 * own layout (tests/test_kernels.c): a mismatch would silently corrupt every buffer.
 * tests/layout.h lists the host's values in this order, and the tests size the output
 * buffer from that list: add an entry there and here together. */
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
    out[i++] = (uint)sizeof(Medium);
    out[i++] = (uint)__builtin_offsetof(Medium, sigma_s);
    out[i++] = (uint)__builtin_offsetof(PathState, medium);
    out[i++] = (uint)__builtin_offsetof(RenderParams, has_media);
    out[i++] = (uint)__builtin_offsetof(Material, medium_in);
    out[i++] = (uint)sizeof(GridMedium);
    out[i++] = (uint)__builtin_offsetof(GridMedium, nx);
    out[i++] = (uint)__builtin_offsetof(GridMedium, max_density);
    out[i++] = (uint)__builtin_offsetof(Medium, emission);
    out[i++] = (uint)__builtin_offsetof(GridMedium, emission_at);
    out[i++] = (uint)__builtin_offsetof(GridMedium, temperature_at);
    out[i++] = (uint)sizeof(MotionKey);
    out[i++] = (uint)__builtin_offsetof(MotionKey, stretch);
    out[i++] = (uint)__builtin_offsetof(Camera, motion_keys);
    out[i++] = (uint)__builtin_offsetof(Material, diffuse_transmission);
    out[i++] = (uint)__builtin_offsetof(Material, diffuse_transmission_color);
    out[i++] = (uint)__builtin_offsetof(GridMedium, minorant_at);
    out[i++] = (uint)sizeof(KdProto);
    out[i++] = (uint)__builtin_offsetof(KdProto, hi);
    out[i++] = (uint)__builtin_offsetof(RenderParams, has_alpha);
}
#endif

/* ---------------------------------------------------------------- classic ray tracer
 * The whitted integrator and the auxiliary images (kernels/integrator/whitted.h): one work-item
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
        uint p = first_pixel + i, pixel = batch_pixel(&sc, p % n_pixels);
        paths[i].pixel = pixel;
        paths[i].radiance = whitted_sample(&sc, pixel, first_sample + p / n_pixels, &rays);
    }
    if (rays) atomic_add(&group_rays, rays);
    barrier(CLK_LOCAL_MEM_FENCE);
    if (get_local_id(0) == 0 && group_rays) atomic_add(&counters[0], group_rays);
}
#endif /* KF_HAS(KF_WHITTED) */
