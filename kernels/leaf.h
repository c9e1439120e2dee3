/*
 * leaf.h -- what both trees (the kd-tree of traverse.cl, the 8-wide BVH of
 * traverse_wide.cl) do at their leaves, and the planes no tree holds.
 *
 * A leaf record (types.h, written by kd_leaf_record_write in host/accel/kdtree.c) holds
 * its triangles in groups of eight, tested eight at a time, then the other primitives'
 * ids; the same test serves both trees, so a primitive hit through either has the same
 * t, u and v bit for bit.
 */
#ifndef CLPT_LEAF_H
#define CLPT_LEAF_H

#include "intersect.h"
#include "scene_view.h"

/* Tests global primitive `id` (a sphere, triangle, box or surface of revolution: planes
 * are not in the tree) against the ray, whose tmax is the closest hit so far. The walk
 * tests triangles by leaf group and calls this for the others. */
KFN_INLINE int trace_prim(const SceneView *sc, uint id, const RayPre *rp, Ray ray, Hit *hit)
{
    GLOBAL const RenderParams *pr = sc->params;
    uint first_tri = pr->n_spheres, first_box = first_tri + pr->n_triangles;
    uint first_rev = first_box + pr->n_boxes;
    if ((id >= first_tri) & (id < first_box))
        return triangle_intersect(rp, &sc->triangles[id - first_tri], ray, hit);
    if (KF_HAS(KF_SPHERES) && id < first_tri)
        return sphere_intersect(sc->spheres[id], ray, hit);
    if (KF_HAS(KF_BOXES) && id < first_rev)
        return box_intersect(rp, sc->boxes[id - first_box], ray, hit);
    if (!KF_HAS(KF_REVSURFACE)) return 0;
    return revsurface_intersect(sc->revsurfaces[id - first_rev], sc->rev_points, ray, hit);
}

/* Relative slack of the traversal's plane-crossing tests: far above the rounding error
 * of the distances compared (about 3 ulps, 4e-7, each), far below any cost. */
#define KD_T_SLACK 1e-6f
#define KD_T_ABOVE (1.0f + KD_T_SLACK)
#define KD_T_BELOW (1.0f - KD_T_SLACK)

/* Tests the primitives of leaf n (its record in leaf_data) against the ray (tmax: the closest hit so far, in
 * best->t); returns 1 when an any-hit query hit. The triangles are tested a group at a
 * time (triangle_intersect_group: the nearest lane hit, the first of equals, which is
 * what testing them one by one in lane order gives), then the spheres and boxes one by
 * one. */
KFN_INLINE int leaf_test(const SceneView *sc, GLOBAL const uint *leaf_data, Ray ray, const RayPre *rp, int any,
                         KdNode n, Hit *best)
{
    GLOBAL const uint *g = leaf_data + n.data;
    uint groups = n.bits >> 3;
    for (uint i = 0; i < groups; i++, g += KD_GROUP_WORDS) {
        Hit h;
        if (triangle_intersect_group(rp, (GLOBAL const float *)(g + KD_GROUP), ray.tmin, best->t, &h)) {
            h.prim = g[h.prim];
            *best = h;
            if (any) return 1;
        }
    }
    if (n.bits & KD_LEAF_OTHERS) {
        uint count = g[0];
        for (uint i = 1; i <= count; i++) {
            uint id = g[i];
            Ray r = ray;
            r.tmax = best->t;
            Hit h;
            if (trace_prim(sc, id, rp, r, &h)) {
                h.prim = id;
                *best = h;
                if (any) return 1;
            }
        }
    }
    return 0;
}

/* The infinite planes (not in any tree) against the ray, whose tmax is best->t: the
 * closest one into *best, or with `any` set the first one hit, and then 1. */
KFN_INLINE int trace_planes(const SceneView *sc, Ray ray, int any, Hit *best)
{
    GLOBAL const RenderParams *pr = sc->params;
    uint first_plane = pr->n_spheres + pr->n_triangles + pr->n_boxes + pr->n_revsurfaces;
    for (uint i = 0; i < (KF_HAS(KF_PLANES) ? pr->n_planes : 0u); i++) {
        Ray r = ray;
        r.tmax = best->t;
        Hit h;
        if (plane_intersect(sc->planes[i], r, &h)) {
            h.prim = first_plane + i;
            *best = h;
            if (any) return 1;
        }
    }
    return 0;
}

KFN_INLINE Hit hit_none(Ray ray)
{
    Hit h;
    h.t = ray.tmax;
    h.prim = NO_INDEX;
    h.u = 0.0f;
    h.v = 0.0f;
    return h;
}

#endif /* CLPT_LEAF_H */
