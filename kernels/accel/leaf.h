/*
 * leaf.h -- what both trees (the kd-tree of traverse.h, the 8-wide BVH of
 * traverse_bvh.h) do at their leaves, and the planes no tree holds.
 *
 * A leaf record (types.h, written by kd_leaf_record_write in host/accel/kdtree.c) holds
 * its triangles in groups of eight, tested eight at a time, then the other primitives'
 * ids; the same test serves both trees, so a primitive hit through either has the same
 * t, u and v bit for bit.
 */
#ifndef CLPT_LEAF_H
#define CLPT_LEAF_H

#include "geom/intersect.h"
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
    if (KF_HAS(KF_SPHERES) && id < first_tri) {
        Sphere sp = sc->spheres[id];
        if (KF_HAS(KF_SPHERE_XFORM) && sp.xform != 0u)
            return sphere_xform_intersect(&sc->sphere_xforms[sp.xform - 1u], ray, hit);
        return sphere_intersect(sp, ray, hit);
    }
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

/* The float just above x (x > 0 and finite; the smallest one above 0 for 0). */
KFN_INLINE float k_next_up(float x)
{
    return x > 0.0f ? k_as_float(k_as_uint(x) + 1u) : k_as_float(1u);
}

/* The distance up to which a primitive can still be the closest hit: best->t itself,
 * which a primitive at the same t takes only with a lower global id (leaf_test). */
KFN_INLINE float leaf_tmax(const Hit *best)
{
    return best->prim == NO_INDEX ? best->t : k_next_up(best->t);
}

/* Whether a hit at t (<= best->t, which leaf_tmax ensures) on primitive id of instance
 * inst replaces the closest so far: a nearer one always, one at the same t when
 * (prim, inst) is lower. In a scene without instances inst is NO_INDEX throughout, and
 * this is the rule on ids alone that every walk kept before instancing; with instances
 * the same primitive of two instances at the same t is decided by the instance, so the
 * order the walk meets them in still does not matter. */
KFN_INLINE int hit_wins(const Hit *best, float t, uint id, uint inst)
{
    return t < best->t || id < best->prim || (id == best->prim && inst < best->inst);
}

/* best becomes h (t, u, v) on primitive id of instance inst; best's padding is left as
 * hit_none wrote it, so hit buffers compare bit for bit between devices. */
KFN_INLINE void hit_take(Hit *best, Hit h, uint id, uint inst)
{
    best->t = h.t;
    best->u = h.u;
    best->v = h.v;
    best->prim = id;
    best->inst = inst;
}

/* Tests the primitives of leaf n (its record in leaf_data) against the ray (tmax: the
 * closest hit so far, in best->t); returns 1 when an any-hit query hit. The triangles are
 * tested a group at a time (triangle_intersect_group), then the spheres and boxes one by
 * one. The closest hit is the primitive of least t and, of those at the same t (a ray
 * through an edge two triangles share, coplanar triangles), of least global id (a leaf's
 * ids are sorted, so within a leaf that is the first of equals, which is what
 * triangle_intersect_group keeps; across leaves the id decides): a rule
 * that does not depend on the order in which leaves are met, so the single-ray walk and
 * the packet walk (trace_packet_wide), which meet them in different orders, find the same
 * hit bit for bit, and so does the kd-tree's walk (kd_leaf goes on into a cell that
 * starts at the closest hit). (A surface of revolution's t does depend on the hit found
 * before it, revsurface.h.) */
KFN_INLINE int leaf_test(const SceneView *sc, GLOBAL const uint *leaf_data, Ray ray, const RayPre *rp, int any,
                         KdNode n, uint inst, Hit *best)
{
    GLOBAL const uint *g = leaf_data + n.data;
    uint groups = n.bits >> 3;
    float tmax = leaf_tmax(best);
    for (uint i = 0; i < groups; i++, g += KD_GROUP_WORDS) {
        Hit h;
        if (triangle_intersect_group(rp, (GLOBAL const float *)(g + KD_GROUP), ray.tmin, tmax, &h)) {
            uint id = g[h.prim];
            if (hit_wins(best, h.t, id, inst)) {
                hit_take(best, h, id, inst);
                if (any) return 1;
                tmax = k_next_up(h.t);
            }
        }
    }
    if (n.bits & KD_LEAF_OTHERS) {
        uint count = g[0];
        for (uint i = 1; i <= count; i++) {
            uint id = g[i];
            Ray r = ray;
            r.tmax = tmax;
            Hit h;
            if (trace_prim(sc, id, rp, r, &h) && hit_wins(best, h.t, id, inst)) {
                hit_take(best, h, id, inst);
                if (any) return 1;
                tmax = k_next_up(h.t);
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
            hit_take(best, h, first_plane + i, NO_INDEX);
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
    h.inst = NO_INDEX;
    h.flight_stop = 0.0f;
    h.flight_drawn = h.pad2 = 0u;
    return h;
}

#endif /* CLPT_LEAF_H */
