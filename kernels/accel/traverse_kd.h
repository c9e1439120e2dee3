/*
 * traverse_kd.h -- the kd-tree walks: one ray (trace_tree), two rays in turns
 * (trace_closest2, trace_any2) and packets of eight (trace_packet).
 *
 * Layout and the reasons for this code's shape are in docs/kdtree.md. The ray is clipped
 * to the root box and walked front to back with a private stack. A leaf's primitives
 * are tested against the whole remaining ray, not just the leaf's part of it, so a hit
 * found in a leaf may lie beyond the leaf; the walk stops once the closest hit is no
 * farther than the end of the current leaf, since every cell still on the stack
 * starts there or later. Rays must have tmin >= 0 (every ray of a path tracer does):
 * the slack of the plane tests is relative to the interval's ends, taken non-negative.
 */
#ifndef CLPT_TRAVERSE_KD_H
#define CLPT_TRAVERSE_KD_H

#include "accel/leaf.h"
#include "geom/intersect.h"
#include "scene_view.h"

/* Clips the ray's [tmin, tmax] to the box LO, HI (vec3 lvalues) of a tree's root,
 * into *t0, *t1; 0 if nothing is left. The far end is widened by a few ulps (pbrt's
 * 1 + 2*gamma(3)) so that rounding in the slab test cannot cut off a primitive lying on
 * the box's far face. One body for the scene's tree (trace_clip_root) and a prototype's
 * (trace_clip_box): a macro rather than one function calling the other, which left gcc
 * three more instructions a ray in the one-level walk (callgrind, the scalar device). */
#define TRACE_CLIP_BODY(LO, HI)                                                          \
    /* A NaN (or +inf - inf) in the ray would make every split plane "in the plane" and \
     * the walk visit the whole tree; such a ray hits nothing anyway. */                \
    float s = ray.o.x + ray.o.y + ray.o.z + ray.d.x + ray.d.y + ray.d.z;                 \
    if (!(s == s)) return 0;                                                             \
    float nx, fx, ny, fy, nz, fz;                                                        \
    k_slab((LO).x, (HI).x, ray.o.x, rp->inv_d[0], &nx, &fx);                             \
    k_slab((LO).y, (HI).y, ray.o.y, rp->inv_d[1], &ny, &fy);                             \
    k_slab((LO).z, (HI).z, ray.o.z, rp->inv_d[2], &nz, &fz);                             \
    float tn = k_fmax(ray.tmin, k_fmax(nx, k_fmax(ny, nz)));                             \
    float tf = k_fmin(ray.tmax, k_fmin(fx, k_fmin(fy, fz)) * 1.00000036f);               \
    *t0 = tn;                                                                            \
    *t1 = tf;                                                                            \
    return tn <= tf;

/* The scene's one tree: its root box is RenderParams.bounds_lo, hi. */
KFN int trace_clip_root(GLOBAL const RenderParams *pr, Ray ray, const RayPre *rp, float *t0, float *t1)
{
    TRACE_CLIP_BODY(pr->bounds_lo, pr->bounds_hi)
}

#if KF_HAS(KF_INSTANCES)
/* A prototype's tree (KdProto): its root box. */
KFN int trace_clip_box(GLOBAL const KdProto *p, Ray ray, const RayPre *rp, float *t0, float *t1)
{
    TRACE_CLIP_BODY(p->lo, p->hi)
}
#endif

/* A kd-tree walk in progress: the node about to be visited, the part [t0, t1] of the
 * ray inside it, and the depth of its stack of cells still to visit (far children,
 * with their parts), which is kept apart: the compilers keep a struct's scalars in
 * registers only when no part of it is indexed by a variable. */
typedef struct {
    uint node;
    float t0, t1;
    int sp;
} KdWalk;

typedef struct {
    uint node[KD_MAX_DEPTH];
    float t0[KD_MAX_DEPTH], t1[KD_MAX_DEPTH];
} KdStack;

/* b if c is 1, a if c is 0 (c is 0 or 1), by masks: no branch. */
KFN_INLINE uint k_select_u(uint a, uint b, uint c)
{
    return a ^ ((a ^ b) & (0u - c));
}

KFN_INLINE float k_select_f(float a, float b, uint c)
{
    return k_as_float(k_select_u(k_as_uint(a), k_as_uint(b), c));
}

/* One interior node n (the walk's current node). The near child is the one the ray
 * enters first, which the sign of its direction along the axis decides (-0 counts as
 * negative: with 1/-0 = -inf a plane beside the origin is then "behind", and the far
 * child, the origin's side, is taken alone). Three cases: the plane lies beyond the
 * interval (near child only), before it (far child only, whatever the sign), or inside
 * it (near child on [t0, tp], far child pushed with [tp, t1]). The comparisons with t0
 * and t1 have a slack of KD_T_SLACK: tp and the ends of the interval are each rounded
 * (a few ulps), and a ray through a vertex or edge lying on the plane must not skip the
 * child holding the triangle it hits. tp is NaN only for a ray lying in the split plane:
 * it is on the boundary of both children for its whole interval, and every comparison
 * with NaN is false, which takes both children with the interval unchanged. The push
 * slot is written in every case and kept only when both children are taken and the far
 * one is not an empty leaf (KD_EMPTY_*: nothing to test there; an interior node is at
 * depth <= KD_MAX_DEPTH - 2, so sp stays in range).
 *
 * With `branch` set the far-only case is a branch, which the processor predicts for
 * coherent rays and which keeps the plane test off the chain of node loads; without it
 * every choice is a bit select, for walks taking turns (TRACE_PAIR), where the other
 * walk's chain hides the longer one. The two compute the same. */
KFN_INLINE void kd_step(const RayPre *rp, KdNode n, KdWalk *w, KdStack *st, int branch)
{
    uint axis = n.bits & 3u;
    float tp = (k_as_float(n.data) - rp->org[axis]) * rp->inv_d[axis];
    uint below = w->node + 1u, above = n.bits >> 4;
    uint near_above = (rp->neg >> axis) & 1u;
    uint near = k_select_u(below, above, near_above);
    uint far = near ^ below ^ above;
    float t0 = w->t0, t1 = w->t1;
    uint far_only = (uint)(tp < t0 * KD_T_BELOW);
    if (branch && far_only) {
        w->node = far;
        return;
    }
    uint both = (uint)!(tp > t1 * KD_T_ABOVE) & (far_only ^ 1u);
    uint far_empty = (n.bits >> (3u - near_above)) & 1u;
    int sp = w->sp;
    st->node[sp] = far;
    st->t0[sp] = tp > t0 ? tp : t0;
    st->t1[sp] = t1;
    w->sp = sp + (int)(both & (far_empty ^ 1u));
    /* Beyond the interval min(tp, t1) is t1: only "both" shortens it. */
    w->t1 = k_select_f(tp < t1 ? tp : t1, t1, far_only);
    w->node = k_select_u(near, far, far_only);
}

/* The visit of leaf n: its primitives (leaf_test; hits carry instance inst, NO_INDEX
 * in a one-level tree); returns 1 when the walk is over:
 * an any-hit query hit, or nothing is left on the stack, or the next cell starts beyond
 * the closest hit. Otherwise pops the next cell.
 *
 * A cell can hold the closest hit if it starts no farther than the closest hit so far:
 * a primitive at the very same t that lies in the next cell alone is the closest hit
 * if its id is lower (the tie rule, leaf_test), and rounding can put the plane between
 * two cells a few ulps either side of a hit on it. So the walk goes on while the next
 * cell starts within KD_T_SLACK of the closest hit, the slack of the plane tests, and
 * finds what the BVH's walk and a test of every primitive find (test_kdtree aims rays at
 * the corners and edges of meshes). Cells on the stack start at or after this one's
 * end, so a hit well short of it ends the walk without looking. */
KFN_INLINE int kd_leaf(const SceneView *sc, Ray ray, const RayPre *rp, int any, KdNode n, KdWalk *w,
                       const KdStack *st, Hit *best, uint inst)
{
    if (leaf_test(sc, sc->leaf_prims, ray, rp, any, n, inst, best)) return 1;
    float reach = best->t * KD_T_ABOVE;
    if ((w->sp == 0) | (reach < w->t1)) return 1;
    int sp = w->sp - 1;
    if (st->t0[sp] > reach) return 1;
    w->sp = sp;
    w->node = st->node[sp];
    w->t0 = st->t0[sp];
    w->t1 = st->t1[sp];
    return 0;
}

/* The ray clipped to the root box: 0 when it misses the box. */
KFN_INLINE int kd_walk_begin(const SceneView *sc, Ray ray, const RayPre *rp, KdWalk *w)
{
    w->node = 0u;
    w->sp = 0;
    return trace_clip_root(sc->params, ray, rp, &w->t0, &w->t1);
}

/* The kd-tree walk shared by both queries. With `any` set it returns at the first hit;
 * otherwise it keeps the closest one in *best (whose t starts as the ray's tmax). */
KFN_INLINE void trace_tree(const SceneView *sc, Ray ray, const RayPre *rp, int any, Hit *best)
{
    KdWalk w;
    KdStack st;
    if (!kd_walk_begin(sc, ray, rp, &w)) return;
    GLOBAL const KdNode *nodes = sc->nodes;
    for (;;) {
        KdNode n = nodes[w.node];
        if ((n.bits & 3u) != KD_LEAF) kd_step(rp, n, &w, &st, 1);
        else if (kd_leaf(sc, ray, rp, any, n, &w, &st, best, NO_INDEX)) return;
    }
}

#if KF_HAS(KF_INSTANCES)
/* The walk of a prototype's kd-tree (KdProto p: --accel kdtree in a scene with
 * instances, docs/instancing.md) for the ray already in its object space, from the
 * top level's walk (trace_wide) when it enters instance inst (NO_INDEX: the world's
 * own primitives). It is trace_tree's walk from the prototype's root and box, with
 * its own stack (KD_MAX_DEPTH entries, which the prototype's build keeps to, as every
 * kd-tree's): the top level's entries stay on trace_wide's stack, untouched. The ray's
 * t is the world's (instance.h), so the walk ends where the closest hit so far, in any
 * instance, ends it, and its cells end there too: a prototype's primitive at that very
 * t is still tested (KD_T_ABOVE), which the tie rule may give it. */
KFN_INLINE void trace_kd_proto(const SceneView *sc, GLOBAL const KdProto *p, Ray ray, const RayPre *rp, int any,
                               uint inst, Hit *best)
{
    KdWalk w;
    KdStack st;
    w.node = p->root;
    w.sp = 0;
    if (!trace_clip_box(p, ray, rp, &w.t0, &w.t1)) return;
    w.t1 = k_fmin(w.t1, best->t * KD_T_ABOVE);
    if (!(w.t0 <= w.t1)) return;
    GLOBAL const KdNode *nodes = sc->nodes;
    for (;;) {
        KdNode n = nodes[w.node];
        if ((n.bits & 3u) != KD_LEAF) kd_step(rp, n, &w, &st, 1);
        else if (kd_leaf(sc, ray, rp, any, n, &w, &st, best, inst)) return;
    }
}
#endif

/* ------------------------------------------------------------------ two rays at once */

/* A kd-tree walk is a chain of dependent loads: the next node is known only once the
 * plane test of this one is done, and for incoherent rays the branches of that test are
 * mispredicted often. Walking two independent rays in turns, with the interior step
 * written as bit selects rather than branches, lets the processor overlap the two
 * chains. On PoCL that pays only for incoherent rays of large meshes and costs camera
 * and shadow rays 15-25% (docs/kdtree.md); the renderer walks one ray per work-item,
 * the benchmark times both. The result of each ray is bit for bit that of
 * trace_closest / trace_any: the same nodes in the same order, the same tests.
 * Everything is inlined so that the walks' scalars stay in registers. */
typedef struct {
    Ray ray;
    Hit best;
    int any;            /* any-hit query: stop at the first hit */
    int active;         /* still walking */
} TraceRay;

/* The planes, then the ray clipped to the root box, as trace_closest and trace_any do. */
KFN_INLINE void trace_ray_begin(const SceneView *sc, Ray ray, int any, TraceRay *t, RayPre *rp, KdWalk *w)
{
    t->ray = ray;
    t->any = any;
    t->best = hit_none(ray);
    t->active = 0;
    w->node = 0u;
    w->sp = 0;
    w->t0 = w->t1 = 0.0f;
    if (trace_planes(sc, ray, any, &t->best)) return;
    ray_prepare(ray, rp);
    t->active = kd_walk_begin(sc, ray, rp, w);
}

/* The rest of one walk, alone. */
KFN_INLINE void trace_ray_finish(const SceneView *sc, TraceRay *t, const RayPre *rp, KdWalk *w, KdStack *st)
{
    GLOBAL const KdNode *nodes = sc->nodes;
    while (t->active) {
        KdNode n = nodes[w->node];
        if ((n.bits & 3u) != KD_LEAF) kd_step(rp, n, w, st, 1);
        else t->active = !kd_leaf(sc, t->ray, rp, t->any, n, w, st, &t->best, NO_INDEX);
    }
}

/* Both rays' walks in turns while both are active, then the other one's rest. */
#define TRACE_PAIR(sc, a, pa, wa, sa, b, pb, wb, sb)                                     \
    do {                                                                                 \
        GLOBAL const KdNode *nodes_ = (sc)->nodes;                                       \
        while ((a).active & (b).active) {                                                \
            KdNode na = nodes_[(wa).node], nb = nodes_[(wb).node];                       \
            uint la = (uint)((na.bits & 3u) == KD_LEAF), lb = (uint)((nb.bits & 3u) == KD_LEAF); \
            if ((la | lb) == 0u) {                                                       \
                kd_step(&(pa), na, &(wa), &(sa), 0);                                     \
                kd_step(&(pb), nb, &(wb), &(sb), 0);                                     \
                continue;                                                                \
            }                                                                            \
            if (la) (a).active = !kd_leaf(sc, (a).ray, &(pa), (a).any, na, &(wa), &(sa), &(a).best, NO_INDEX); \
            else kd_step(&(pa), na, &(wa), &(sa), 0);                                    \
            if (lb) (b).active = !kd_leaf(sc, (b).ray, &(pb), (b).any, nb, &(wb), &(sb), &(b).best, NO_INDEX); \
            else kd_step(&(pb), nb, &(wb), &(sb), 0);                                    \
        }                                                                                \
        trace_ray_finish(sc, &(a), &(pa), &(wa), &(sa));                                 \
        trace_ray_finish(sc, &(b), &(pb), &(wb), &(sb));                                 \
    } while (0)

/* Two rays walked in turns: their closest hits, or with any set, any hit each. */
KFN void trace_pair(const SceneView *sc, Ray ra, Ray rb, int any, Hit *ha, Hit *hb)
{
    TraceRay a, b;
    RayPre pa, pb;
    KdWalk wa, wb;
    KdStack sa, sb;
    trace_ray_begin(sc, ra, any, &a, &pa, &wa);
    trace_ray_begin(sc, rb, any, &b, &pb, &wb);
    TRACE_PAIR(sc, a, pa, wa, sa, b, pb, wb, sb);
    *ha = a.best;
    *hb = b.best;
}

/* trace_closest of two rays. */
KFN void trace_closest2(const SceneView *sc, Ray ra, Ray rb, Hit *ha, Hit *hb) { trace_pair(sc, ra, rb, 0, ha, hb); }

/* trace_any of two rays. */
KFN void trace_any2(const SceneView *sc, Ray ra, Ray rb, int *oa, int *ob)
{
    Hit ha, hb;
    trace_pair(sc, ra, rb, 1, &ha, &hb);
    *oa = ha.prim != NO_INDEX;
    *ob = hb.prim != NO_INDEX;
}

/* ------------------------------------------------------------------ eight rays at once */

/* A packet walk for coherent rays (camera rays through neighbouring pixels, shadow rays
 * from neighbouring points toward one light): eight rays whose directions have the same
 * signs go down the tree together, one node load and one float8 plane test for all of
 * them, and part ways only in the leaves, where each ray still in the walk tests the
 * primitives alone. Each lane keeps exactly its single walk (kd_step): a lane is in the
 * packet's mask at a node if and only if its own walk visits that node, with the same
 * [t0, t1]. The near child comes first for every lane alike (the shared signs), so a
 * lane that goes to the far child alone merely waits out the near subtree, masked; a
 * cell is pushed with the lanes that will visit it, in the order their own walks would
 * push it. So every lane meets the same leaves in the same order with the same closest
 * hit so far, and stops where its walk stops: its hit is bit for bit trace_closest's
 * (trace_any's), which test_kdtree checks in C and bench_traverse on PoCL. Rays whose
 * signs differ from the others' are walked one after the other instead. */
#define TRACE_PACKET 8   /* as WIDE_PACKET (traverse.h checks) */

typedef struct {
    uint node[KD_MAX_DEPTH];
    uint lanes[KD_MAX_DEPTH];            /* bit l: lane l visits the cell */
    float8 t0[KD_MAX_DEPTH], t1[KD_MAX_DEPTH];
} KdPacketStack;

/* The packet walk from the lanes' clipped intervals (w[l].t0, t1) over the lanes in
 * `lanes`, all of whose directions have the sign bits `neg`. */
KFN_INLINE void trace_packet_walk(const SceneView *sc, TraceRay *tr, const RayPre *rp, const KdWalk *w,
                                  uint lanes, uint neg)
{
    float a[TRACE_PACKET * 8];          /* org x y z, inv_d x y z, t0, t1 per lane */
    for (uint l = 0; l < TRACE_PACKET; l++) {
        int on = (int)((lanes >> l) & 1u);
        for (uint k = 0; k < 3u; k++) {
            a[k * TRACE_PACKET + l] = on ? rp[l].org[k] : 0.0f;
            a[(3u + k) * TRACE_PACKET + l] = on ? rp[l].inv_d[k] : 0.0f;
        }
        a[6u * TRACE_PACKET + l] = on ? w[l].t0 : 0.0f;
        a[7u * TRACE_PACKET + l] = on ? w[l].t1 : 0.0f;
    }
    float8 org0, org1, org2, inv0, inv1, inv2, t0, t1;
    k_load8(org0, a);
    k_load8(org1, a + TRACE_PACKET);
    k_load8(org2, a + 2 * TRACE_PACKET);
    k_load8(inv0, a + 3 * TRACE_PACKET);
    k_load8(inv1, a + 4 * TRACE_PACKET);
    k_load8(inv2, a + 5 * TRACE_PACKET);
    k_load8(t0, a + 6 * TRACE_PACKET);
    k_load8(t1, a + 7 * TRACE_PACKET);
    GLOBAL const KdNode *nodes = sc->nodes;
    KdPacketStack st;
    int sp = 0;
    uint node = 0u, done = 0u;
    /* each lane's closest hit so far with the slack, and the lanes whose next pop is
     * the one after a leaf, which kd_leaf checks against it */
    float reach[TRACE_PACKET] = { 0.0f };
    uint after_leaf = 0u;
    for (;;) {
        KdNode n = nodes[node];
        if ((n.bits & 3u) != KD_LEAF) {
            /* kd_step for every lane: the same operations, lane by lane */
            uint axis = n.bits & 3u;
            float8 o = axis == 0u ? org0 : (axis == 1u ? org1 : org2);
            float8 iv = axis == 0u ? inv0 : (axis == 1u ? inv1 : inv2);
            float8 tp = (k_as_float(n.data) - o) * iv;
            uint below = node + 1u, above = n.bits >> 4;
            uint near_above = (neg >> axis) & 1u;
            uint near = near_above ? above : below, far = near ^ below ^ above;
            uint far_only = k_bits8(tp < t0 * KD_T_BELOW) & lanes;
            uint both = ~k_bits8(tp > t1 * KD_T_ABOVE) & ~far_only & lanes;
            uint far_empty = (n.bits >> (3u - near_above)) & 1u;
            uint to_near = lanes & ~far_only;
            uint to_far = far_only | (far_empty ? 0u : both);
            /* the far cell starts at tp where the lane crosses the plane inside its
             * interval ("both"); a far-only lane keeps t0 (tp lies before it) */
            float8 t0_far = k_select8(t0, tp, tp > t0);
            if (to_near == 0u) {
                node = far;
                lanes = to_far;
                t0 = t0_far;
                continue;
            }
            if (to_far) {
                st.node[sp] = far;
                st.lanes[sp] = to_far;
                st.t0[sp] = t0_far;
                st.t1[sp] = t1;
                sp++;
            }
            node = near;
            lanes = to_near;
            t1 = k_select8(t1, tp, tp < t1);
            continue;
        }
        /* kd_leaf for every lane in the leaf: a lane is done when its any-hit query
         * hit or its closest hit is well short of the cell's end, and otherwise when the
         * next cell it would visit starts beyond its closest hit (below) */
        float end[TRACE_PACKET];
        k_store8(t1, end);
        for (uint l = 0; l < TRACE_PACKET; l++) {
            if (!((lanes >> l) & 1u)) continue;
            if (leaf_test(sc, sc->leaf_prims, tr[l].ray, &rp[l], tr[l].any, n, NO_INDEX, &tr[l].best))
                done |= 1u << l;
            reach[l] = tr[l].best.t * KD_T_ABOVE;
            if (reach[l] < end[l]) done |= 1u << l;
        }
        after_leaf = (after_leaf | lanes) & ~done;
        for (;;) {
            if (sp == 0) return;
            sp--;
            lanes = st.lanes[sp] & ~done;
            float8 r;
            k_load8(r, reach);
            uint beyond = k_bits8(st.t0[sp] > r) & lanes & after_leaf;
            done |= beyond;
            lanes &= ~beyond;
            after_leaf &= ~lanes;
            if (lanes) break;
        }
        node = st.node[sp];
        t0 = st.t0[sp];
        t1 = st.t1[sp];
    }
}

/* trace_closest (any == 0) or trace_any_hit (any == 1) of 8 rays: hits[l] is bit for
 * bit what the single walk gives rays[l]. */
KFN_INLINE void trace_packet(const SceneView *sc, const Ray *rays, int any, Hit *hits)
{
    TraceRay tr[TRACE_PACKET];
    RayPre rp[TRACE_PACKET];
    KdWalk w[TRACE_PACKET];
    uint lanes = 0u, neg = 0u, mixed = 0u;
    for (uint l = 0; l < TRACE_PACKET; l++) {
        trace_ray_begin(sc, rays[l], any, &tr[l], &rp[l], &w[l]);
        if (!tr[l].active) continue;
        if (lanes == 0u) neg = rp[l].neg;
        mixed |= rp[l].neg ^ neg;
        lanes |= 1u << l;
    }
    if (mixed) {
        KdStack st;
        for (uint l = 0; l < TRACE_PACKET; l++) trace_ray_finish(sc, &tr[l], &rp[l], &w[l], &st);
    } else if (lanes) {
        trace_packet_walk(sc, tr, rp, w, lanes, neg);
    }
    for (uint l = 0; l < TRACE_PACKET; l++) hits[l] = tr[l].best;
}

#endif /* CLPT_TRAVERSE_KD_H */
