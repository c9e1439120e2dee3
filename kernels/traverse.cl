/*
 * traverse.cl -- closest-hit and any-hit queries against the scene.
 *
 * Infinite planes are tested one by one; everything else is found through the kd-tree
 * (layout in docs/kdtree.md): the ray is clipped to the root box and walked front to
 * back with a private stack, as pbrt's KdTreeAggregate does. A leaf's primitives are
 * tested against the whole remaining ray, not just the leaf's part of it, so a hit
 * found in a leaf may lie beyond the leaf; the walk stops once the closest hit is no
 * farther than the end of the current leaf, since every cell still on the stack
 * starts there or later. Rays must have tmin >= 0 (every ray of a path tracer does):
 * the near/far order of the children is decided from the origin.
 */
#ifndef CLPT_TRAVERSE_CL
#define CLPT_TRAVERSE_CL

#include "intersect.h"
#include "scene_view.h"

/* Tests global primitive `id` (a sphere, triangle or box: planes are not in the tree)
 * against the ray, whose tmax is the closest hit so far. */
KFN int trace_prim(const SceneView *sc, uint id, const RayPre *rp, Ray ray, Hit *hit)
{
    GLOBAL const RenderParams *pr = sc->params;
    uint first_tri = pr->n_spheres, first_box = first_tri + pr->n_triangles;
    if ((id >= first_tri) & (id < first_box))
        return triangle_intersect(rp, &sc->triangles[id - first_tri], ray, hit);
    if (id < first_tri)
        return sphere_intersect(sc->spheres[id], ray, hit);
    return box_intersect(rp, sc->boxes[id - first_box], ray, hit);
}

/* Clips the ray's [tmin, tmax] to the root box; 0 if nothing is left. The far end is
 * widened by a few ulps (pbrt's 1 + 2*gamma(3)) so that rounding in the slab test
 * cannot cut off a primitive lying on the box's far face. */
KFN int trace_clip_root(GLOBAL const RenderParams *pr, Ray ray, const RayPre *rp,
                        float *t0, float *t1)
{
    /* A NaN (or +inf - inf) in the ray would make every split plane "in the plane" and
     * the walk visit the whole tree; such a ray hits nothing anyway. */
    float s = ray.o.x + ray.o.y + ray.o.z + ray.d.x + ray.d.y + ray.d.z;
    if (!(s == s)) return 0;
    float nx, fx, ny, fy, nz, fz;
    k_slab(pr->bounds_lo.x, pr->bounds_hi.x, ray.o.x, rp->inv_d[0], &nx, &fx);
    k_slab(pr->bounds_lo.y, pr->bounds_hi.y, ray.o.y, rp->inv_d[1], &ny, &fy);
    k_slab(pr->bounds_lo.z, pr->bounds_hi.z, ray.o.z, rp->inv_d[2], &nz, &fz);
    float tn = k_fmax(ray.tmin, k_fmax(nx, k_fmax(ny, nz)));
    float tf = k_fmin(ray.tmax, k_fmin(fx, k_fmin(fy, fz)) * 1.00000036f);
    *t0 = tn;
    *t1 = tf;
    return tn <= tf;
}

/* Relative slack of the traversal's plane-crossing tests: far above the rounding error
 * of the distances compared (about 3 ulps, 4e-7, each), far below any cost. */
#define KD_T_SLACK 1e-6f
#define KD_T_ABOVE (1.0f + KD_T_SLACK)
#define KD_T_BELOW (1.0f - KD_T_SLACK)

/* The kd-tree walk shared by both queries. With `any` set it returns at the first hit;
 * otherwise it keeps the closest one in *best (whose t starts as the ray's tmax). */
KFN void trace_tree(const SceneView *sc, Ray ray, const RayPre *rp, int any, Hit *best)
{
    float t0, t1;
    if (!trace_clip_root(sc->params, ray, rp, &t0, &t1)) return;
    GLOBAL const KdNode *nodes = sc->nodes;
    uint stack_node[KD_MAX_DEPTH];
    float stack_t0[KD_MAX_DEPTH], stack_t1[KD_MAX_DEPTH];
    int sp = 0;
    uint node = 0;
    for (;;) {
        KdNode n = nodes[node];
        uint axis = n.bits & 3u;
        if (axis != KD_LEAF) {
            float split = k_as_float(n.data);
            float o = rp->org[axis];
            float tp = (split - o) * rp->inv_d[axis];
            /* A ray starting on the plane belongs to the side it is heading into. */
            int below_first = (o < split) | ((o == split) & (rp->dir[axis] <= 0.0f));
            uint above = n.bits >> 2;
            uint first = below_first ? node + 1u : above;
            uint second = below_first ? above : node + 1u;
            /* Choose between: the near child only (the plane is beyond the interval or
             * behind the origin), the far child only (crossed before t0), or both, near
             * first and far pushed. The comparisons with t0 and t1 have a slack of
             * KD_T_SLACK: tp and the ends of the interval are each rounded (a few ulps),
             * and a ray through a vertex or edge lying on the plane must not skip the
             * child holding the triangle it hits. tp is NaN only for a ray lying in the
             * split plane: it is on the boundary of both children for its whole
             * interval. The push slot is written either way: an interior node is at
             * depth <= KD_MAX_DEPTH - 2, so sp stays in range. Compilers turn some of these choices into
             * branches; for coherent rays (camera, shadow) they predict well, and a
             * version made of bit selects only was slower on those and no faster on
             * diffuse rays (docs/kdtree.md). */
            int in_plane = !(tp == tp);
            int crosses = tp > 0.0f && tp <= t1 * KD_T_ABOVE;
            int far_only = crosses && tp < t0 * KD_T_BELOW;
            int both = (crosses && !far_only) || in_plane;
            stack_node[sp] = second;
            stack_t0[sp] = in_plane ? t0 : tp;
            stack_t1[sp] = t1;
            sp += both;
            node = far_only ? second : first;
            t1 = both && !in_plane ? tp : t1;
            continue;
        }
        /* One call site for the primitive test, so that it is inlined. */
        uint count = n.bits >> 2;
        for (uint i = 0; i < count; i++) {
            uint id = count == 1u ? n.data : sc->leaf_prims[n.data + i];
            Ray r = ray;
            r.tmax = best->t;
            Hit h;
            if (trace_prim(sc, id, rp, r, &h)) {
                h.prim = id;
                *best = h;
                if (any) return;
            }
        }
        if ((sp == 0) | (best->t <= t1)) return;
        sp--;
        node = stack_node[sp];
        t0 = stack_t0[sp];
        t1 = stack_t1[sp];
    }
}

/* Nearest hit in (ray.tmin, ray.tmax); prim = NO_INDEX when there is none. */
KFN Hit trace_closest(const SceneView *sc, Ray ray)
{
    GLOBAL const RenderParams *pr = sc->params;
    Hit best;
    best.t = ray.tmax;
    best.prim = NO_INDEX;
    best.u = 0.0f;
    best.v = 0.0f;
    RayPre rp = ray_prepare(ray);
    uint first_plane = pr->n_spheres + pr->n_triangles + pr->n_boxes;
    for (uint i = 0; i < pr->n_planes; i++) {
        Ray r = ray;
        r.tmax = best.t;
        Hit h;
        if (plane_intersect(sc->planes[i], r, &h)) {
            h.prim = first_plane + i;
            best = h;
        }
    }
    trace_tree(sc, ray, &rp, 0, &best);
    return best;
}

/* 1 if anything is hit in (ray.tmin, ray.tmax): shadow rays. */
KFN int trace_any(const SceneView *sc, Ray ray)
{
    GLOBAL const RenderParams *pr = sc->params;
    Hit h;
    for (uint i = 0; i < pr->n_planes; i++)
        if (plane_intersect(sc->planes[i], ray, &h)) return 1;
    RayPre rp = ray_prepare(ray);
    h.t = ray.tmax;
    h.prim = NO_INDEX;
    h.u = 0.0f;
    h.v = 0.0f;
    trace_tree(sc, ray, &rp, 1, &h);
    return h.prim != NO_INDEX;
}

/* ------------------------------------------------------------------ two rays at once */

/* A kd-tree walk is a chain of dependent loads: the next node is known only once the
 * plane test of this one is done, and for incoherent rays the branches of that test are
 * mispredicted about half the time. Walking two independent rays in turns, with the
 * interior step written as bit selects rather than branches, lets the processor overlap
 * the two chains: diffuse rays ran 20-30% faster this way on the scalar C build, and
 * camera rays no slower (docs/kdtree.md). The result of each ray is bit for bit that of
 * trace_closest / trace_any: the same nodes in the same order, the same tests. */
typedef struct {
    uint stack_node[KD_MAX_DEPTH];
    float stack_t0[KD_MAX_DEPTH], stack_t1[KD_MAX_DEPTH];
    int sp;
    int active;         /* still walking */
    int any;            /* any-hit query: stop at the first hit */
    uint node;
    float t0, t1;
    Ray ray;
    RayPre rp;
    Hit best;
} TraceState;

/* b if c is 1, a if c is 0 (c is 0 or 1), by masks: no branch. */
KFN uint k_select_u(uint a, uint b, uint c)
{
    uint m = 0u - c;
    return (a & ~m) | (b & m);
}

KFN float k_select_f(float a, float b, uint c)
{
    return k_as_float(k_select_u(k_as_uint(a), k_as_uint(b), c));
}

/* The planes, then the ray clipped to the root box, as trace_closest and trace_any do. */
KFN void trace_state_begin(const SceneView *sc, Ray ray, int any, TraceState *s)
{
    GLOBAL const RenderParams *pr = sc->params;
    s->ray = ray;
    s->any = any;
    s->best.t = ray.tmax;
    s->best.prim = NO_INDEX;
    s->best.u = 0.0f;
    s->best.v = 0.0f;
    s->sp = 0;
    s->node = 0u;
    uint first_plane = pr->n_spheres + pr->n_triangles + pr->n_boxes;
    for (uint i = 0; i < pr->n_planes; i++) {
        Ray r = ray;
        r.tmax = any ? ray.tmax : s->best.t;
        Hit h;
        if (plane_intersect(sc->planes[i], r, &h)) {
            h.prim = first_plane + i;
            if (any) {
                s->best.prim = h.prim;
                s->active = 0;
                return;
            }
            s->best = h;
        }
    }
    s->rp = ray_prepare(ray);
    s->active = trace_clip_root(pr, ray, &s->rp, &s->t0, &s->t1);
}

/* One interior step; returns 1, with the node in *leaf, when the walk is at a leaf. */
KFN int trace_state_interior(const SceneView *sc, TraceState *s, KdNode *leaf)
{
    KdNode n = sc->nodes[s->node];
    uint axis = n.bits & 3u;
    if (axis == KD_LEAF) {
        *leaf = n;
        return 1;
    }
    float split = k_as_float(n.data);
    float o = s->rp.org[axis];
    float tp = (split - o) * s->rp.inv_d[axis];
    uint below_first = (uint)(o < split) | ((uint)(o == split) & (uint)(s->rp.dir[axis] <= 0.0f));
    uint above = n.bits >> 2, below = s->node + 1u;
    uint first = k_select_u(above, below, below_first);
    uint second = first ^ above ^ below;
    uint in_plane = (uint)!(tp == tp);
    uint crosses = (uint)(tp > 0.0f) & (uint)(tp <= s->t1 * KD_T_ABOVE);
    uint far_only = crosses & (uint)(tp < s->t0 * KD_T_BELOW);
    uint both = (crosses & (far_only ^ 1u)) | in_plane;
    int sp = s->sp;
    s->stack_node[sp] = second;
    s->stack_t0[sp] = k_select_f(tp, s->t0, in_plane);
    s->stack_t1[sp] = s->t1;
    s->sp = sp + (int)both;
    s->node = k_select_u(first, second, far_only);
    s->t1 = k_select_f(s->t1, tp, both & (in_plane ^ 1u));
    return 0;
}

/* The leaf's primitives, then the next cell from the stack (or the end of the walk). */
KFN void trace_state_leaf(const SceneView *sc, TraceState *s, KdNode n)
{
    uint count = n.bits >> 2;
    for (uint i = 0; i < count; i++) {
        uint id = count == 1u ? n.data : sc->leaf_prims[n.data + i];
        Ray r = s->ray;
        r.tmax = s->best.t;
        Hit h;
        if (trace_prim(sc, id, &s->rp, r, &h)) {
            h.prim = id;
            s->best = h;
            if (s->any) {
                s->active = 0;
                return;
            }
        }
    }
    if ((s->sp == 0) | (s->best.t <= s->t1)) {
        s->active = 0;
        return;
    }
    s->sp--;
    s->node = s->stack_node[s->sp];
    s->t0 = s->stack_t0[s->sp];
    s->t1 = s->stack_t1[s->sp];
}

KFN void trace_state_finish(const SceneView *sc, TraceState *s)
{
    KdNode leaf;
    while (s->active)
        if (trace_state_interior(sc, s, &leaf)) trace_state_leaf(sc, s, leaf);
}

/* Walks both in turns while both are active, then finishes the other. */
KFN void trace_pair(const SceneView *sc, TraceState *a, TraceState *b)
{
    KdNode la, lb;
    la.data = lb.data = 0u;
    la.bits = lb.bits = KD_LEAF;
    while (a->active & b->active) {
        int at_a = trace_state_interior(sc, a, &la);
        int at_b = trace_state_interior(sc, b, &lb);
        if (at_a) trace_state_leaf(sc, a, la);
        if (at_b) trace_state_leaf(sc, b, lb);
    }
    trace_state_finish(sc, a);
    trace_state_finish(sc, b);
}

/* trace_closest of two rays. */
KFN void trace_closest2(const SceneView *sc, Ray ra, Ray rb, Hit *ha, Hit *hb)
{
    TraceState a, b;
    trace_state_begin(sc, ra, 0, &a);
    trace_state_begin(sc, rb, 0, &b);
    trace_pair(sc, &a, &b);
    *ha = a.best;
    *hb = b.best;
}

/* trace_any of two rays. */
KFN void trace_any2(const SceneView *sc, Ray ra, Ray rb, int *oa, int *ob)
{
    TraceState a, b;
    trace_state_begin(sc, ra, 1, &a);
    trace_state_begin(sc, rb, 1, &b);
    trace_pair(sc, &a, &b);
    *oa = a.best.prim != NO_INDEX;
    *ob = b.best.prim != NO_INDEX;
}

#endif /* CLPT_TRAVERSE_CL */
