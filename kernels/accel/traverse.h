/*
 * traverse.h -- the closest-hit and any-hit queries the integrators ask, through the
 * scene's tree: infinite planes one by one (leaf.h), everything else through the kd-tree
 * (traverse_kd.h, docs/kdtree.md) or the 8-wide BVH (traverse_bvh.h). Variants of a walk
 * are named traverse_<tree>.h; each holds its tree's shapes of a walk (one ray, packets of
 * eight, and for the kd-tree two rays in turns), and every shape gives each ray the
 * bits the one-ray walk gives it.
 */
#ifndef CLPT_TRAVERSE_H
#define CLPT_TRAVERSE_H

#include "accel/leaf.h"
#include "accel/traverse_bvh.h"
#include "accel/traverse_kd.h"
#include "geom/intersect.h"
#include "scene_view.h"

#if TRACE_PACKET != WIDE_PACKET
#error "the kd-tree's and the BVH's packets are of the same size (k_trace_closest8, k_trace_closest_wide8)"
#endif

/* Which tree holds the scene: the kd-tree (TREE_KD) or the 8-wide BVH (TREE_BVH). A
 * program compiled for one (CLPT_FEATURES with KF_KDTREE or KF_BVH alone) knows it at
 * compile time; otherwise the scene says, by having BVH nodes or instances: under
 * --accel kdtree a scene with instances is walked from the BVH's top level, whose
 * instances lead to kd-trees (trace_wide, docs/instancing.md). */
#define TREE_KD 0
#define TREE_BVH 1
KFN_INLINE int trace_tree_kind(const SceneView *sc)
{
    if (!KF_HAS(KF_BVH)) return TREE_KD;
    if (!KF_HAS(KF_KDTREE)) return TREE_BVH;
#if KF_HAS(KF_INSTANCES)
    return (sc->params->n_bvh_nodes | sc->params->n_instances) != 0u ? TREE_BVH : TREE_KD;
#else
    return sc->params->n_bvh_nodes != 0u ? TREE_BVH : TREE_KD;   /* the programs without instances: as before */
#endif
}

/* The walk of the given tree (which, when it is the BVH, must be there). */
KFN_INLINE void trace_walk(const SceneView *sc, int tree, Ray ray, const RayPre *rp, int any, Hit *best)
{
    if (KF_HAS(KF_BVH) && tree == TREE_BVH) trace_wide(sc, ray, rp, any, best);
    else if (KF_HAS(KF_KDTREE)) trace_tree(sc, ray, rp, any, best);
}

/* Nearest hit in (ray.tmin, ray.tmax) through the given tree; prim = NO_INDEX when
 * there is none. */
KFN Hit trace_closest_in(const SceneView *sc, int tree, Ray ray)
{
    Hit best = hit_none(ray);
    trace_planes(sc, ray, WALK_CLOSEST, &best);
    RayPre rp;
    ray_prepare(ray, &rp);
    trace_walk(sc, tree, ray, &rp, WALK_CLOSEST, &best);
    return best;
}

/* The first hit found in (ray.tmin, ray.tmax) through the given tree, not necessarily
 * the closest; prim = NO_INDEX when there is none. */
KFN Hit trace_any_hit_in(const SceneView *sc, int tree, Ray ray)
{
    Hit h = hit_none(ray);
    if (trace_planes(sc, ray, WALK_ANY, &h)) return h;
    RayPre rp;
    ray_prepare(ray, &rp);
    trace_walk(sc, tree, ray, &rp, WALK_ANY, &h);
    return h;
}

#if KF_HAS(KF_MEDIA)
/* The closest hit in (ray.tmin, ray.tmax) that is not a boundary between media, and the
 * boundaries before it, in one walk (ThroughWalk, leaf.h): a shadow ray through media.
 * Not for scenes with cut-out surfaces or surfaces of revolution. A call on OpenCL
 * (KFN_CALL_CL): its walk is a second copy of the tree's walk, and inlined where shadow
 * rays are answered it made a media program's cold build 1.3 s longer
 * (bench/RESULTS.md, "A shadow ray through media in one walk"). */
KFN_CALL_CL void trace_through(const SceneView *sc, Ray ray, ThroughWalk *tw)
{
    tw->hit = hit_none(ray);
    tw->n = 0u;
    tw->overflow = 0u;
    trace_planes(sc, ray, WALK_THROUGH, &tw->hit);
    RayPre rp;
    ray_prepare(ray, &rp);
    trace_walk(sc, trace_tree_kind(sc), ray, &rp, WALK_THROUGH, &tw->hit);
}
#endif

/* The queries the renderer asks, through the scene's tree. */
KFN Hit trace_closest(const SceneView *sc, Ray ray)
{
    return trace_closest_in(sc, trace_tree_kind(sc), ray);
}

KFN Hit trace_any_hit(const SceneView *sc, Ray ray)
{
    return trace_any_hit_in(sc, trace_tree_kind(sc), ray);
}

/* 1 if anything is hit in (ray.tmin, ray.tmax): shadow rays. */
KFN int trace_any_in(const SceneView *sc, int tree, Ray ray)
{
    return trace_any_hit_in(sc, tree, ray).prim != NO_INDEX;
}

KFN int trace_any(const SceneView *sc, Ray ray)
{
    return trace_any_in(sc, trace_tree_kind(sc), ray);
}

#endif /* CLPT_TRAVERSE_H */
