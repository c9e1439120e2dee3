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
#include "geom/surface.h"
#include "scene_view.h"

/* The queries a walk answers (the walks' `any` argument): the closest hit; any hit (a
 * shadow ray in a scene without media); and the closest hit that is not a boundary
 * between media, with the boundaries crossed before it (WALK_THROUGH, ThroughWalk
 * below: a shadow ray through media, kernels/medium/transmit.h). */
#define WALK_CLOSEST 0
#define WALK_ANY 1
#define WALK_THROUGH 2

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

#if KF_HAS(KF_MEDIA)
/* What a WALK_THROUGH walk finds. A shadow ray through media needs the boundaries
 * (MAT_INTERFACE surfaces) it crosses, in order, up to the light or the first surface
 * that blocks it; walking from hit to hit takes one walk per boundary, each testing
 * again the leaves around the boundary it starts from. This walk finds them all at
 * once: `hit` is what a closest-hit walk would find if boundaries were not there (the
 * tree's walks cull by its t, and get a pointer to it: it is the first member), and the
 * boundaries hit before it are kept, nearest first, in `crossing`. Every hit of a
 * primitive counts, not only its first (a sphere's or box's far side: the walk tests
 * them again from the hit found). A primitive found twice at the same t (a kd-tree
 * cell's neighbour holds it too) is kept once. More than THROUGH_MAX boundaries set
 * `overflow`, and the caller walks hit by hit instead. Cut-out surfaces and surfaces of
 * revolution (whose t depends on the walk's tmax) are not supported: the caller does
 * not ask for such scenes. */
#define THROUGH_MAX 8u
typedef struct {
    Hit hit;
    Hit crossing[THROUGH_MAX];
    uint n;
    uint overflow;
} ThroughWalk;

/* Whether primitive id (of instance inst) is a boundary between media, nothing else. */
KFN_INLINE int prim_is_crossing(const SceneView *sc, uint id, uint inst)
{
    Hit h;
    h.prim = id;
    h.inst = inst;
    return (sc->materials[hit_material(sc, h)].flags & MAT_INTERFACE) != 0u;
}

/* Whether crossing a comes before b: by t, then (prim, inst), the closest-hit walk's
 * tie rule (hit_wins). */
KFN_INLINE int crossing_before(Hit a, Hit b)
{
    return a.t < b.t || (a.t == b.t && (a.prim < b.prim || (a.prim == b.prim && a.inst < b.inst)));
}

/* Keeps boundary hit h (on primitive id of instance inst) in the ThroughWalk that
 * `best` is the first member of, in order. */
KFN_INLINE void through_keep(Hit *best, Hit h, uint id, uint inst)
{
    ThroughWalk *tw = (ThroughWalk *)best;
    Hit c = *best;   /* hit_none's padding, so that every word is set */
    hit_take(&c, h, id, inst);
    h = c;
    uint i = tw->n;
    while (i > 0u && crossing_before(h, tw->crossing[i - 1u])) i--;
    if (i > 0u && tw->crossing[i - 1u].t == h.t && tw->crossing[i - 1u].prim == id && tw->crossing[i - 1u].inst == inst)
        return;
    if (tw->n == THROUGH_MAX) {
        tw->overflow = 1u;
        return;
    }
    for (uint j = tw->n; j > i; j--) tw->crossing[j] = tw->crossing[j - 1u];
    tw->crossing[i] = h;
    tw->n++;
}

/* The rest of a triangle group for a WALK_THROUGH walk, whose nearest hit in
 * (tmin, *tmax) is h: boundaries are kept and the group tested again beyond each, until
 * a surface that is not one, which becomes the closest hit if it wins (and shortens
 * *tmax). The lanes at a boundary's very t are passed over, as a walk from that
 * boundary would pass them (its interval is open). */
KFN_INLINE void leaf_group_through(const SceneView *sc, GLOBAL const uint *g, const RayPre *rp, Hit h, uint inst,
                                   Hit *best, float *tmax)
{
    for (;;) {
        uint id = g[h.prim];
        if (!prim_is_crossing(sc, id, inst)) {
            if (hit_wins(best, h.t, id, inst)) {
                hit_take(best, h, id, inst);
                *tmax = k_next_up(h.t);
            }
            return;
        }
        through_keep(best, h, id, inst);
        if (!triangle_intersect_group(rp, (GLOBAL const float *)(g + KD_GROUP), h.t, *tmax, &h)) return;
    }
}

/* The same for primitive id, not a triangle of a group, whose nearest hit is h: a
 * sphere or box that is a boundary is crossed again at its far side. */
KFN_INLINE void leaf_prim_through(const SceneView *sc, uint id, Ray ray, const RayPre *rp, Hit h, uint inst,
                                  Hit *best, float *tmax)
{
    if (!prim_is_crossing(sc, id, inst)) {
        if (hit_wins(best, h.t, id, inst)) {
            hit_take(best, h, id, inst);
            *tmax = k_next_up(h.t);
        }
        return;
    }
    through_keep(best, h, id, inst);
    Ray r = ray;
    r.tmin = h.t;
    r.tmax = *tmax;
    if (trace_prim(sc, id, rp, r, &h)) through_keep(best, h, id, inst);
}
#endif

/* Tests the primitives of leaf n (its record in leaf_data) against the ray (tmax: the
 * closest hit so far, in best->t); returns 1 when an any-hit query hit. The triangles are
 * tested a group at a time (triangle_intersect_group), then the spheres and boxes one by
 * one; `any` is the query (WALK_CLOSEST, WALK_ANY or WALK_THROUGH). The closest hit is
 * the primitive of least t and, of those at the same t (a ray through an edge two
 * triangles share, coplanar triangles), of least global id (a leaf's
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
#if KF_HAS(KF_MEDIA)
            if (any == WALK_THROUGH) {
                leaf_group_through(sc, g, rp, h, inst, best, &tmax);
                continue;
            }
#endif
            uint id = g[h.prim];
            if (hit_wins(best, h.t, id, inst)) {
                hit_take(best, h, id, inst);
                if (any == WALK_ANY) return 1;
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
#if KF_HAS(KF_MEDIA)
            if (any == WALK_THROUGH) {
                if (trace_prim(sc, id, rp, r, &h)) leaf_prim_through(sc, id, ray, rp, h, inst, best, &tmax);
                continue;
            }
#endif
            if (trace_prim(sc, id, rp, r, &h) && hit_wins(best, h.t, id, inst)) {
                hit_take(best, h, id, inst);
                if (any == WALK_ANY) return 1;
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
#if KF_HAS(KF_MEDIA)
            if (any == WALK_THROUGH && prim_is_crossing(sc, first_plane + i, NO_INDEX)) {
                through_keep(best, h, first_plane + i, NO_INDEX);
                continue;
            }
#endif
            hit_take(best, h, first_plane + i, NO_INDEX);
            if (any == WALK_ANY) return 1;
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
