/*
 * traverse_bvh.h -- closest-hit and any-hit queries through the 8-wide BVH.
 *
 * The BVH (host/accel/bvh.c, BvhNode in types.h) is the other tree of docs/kdtree.md:
 * one ray tests all eight child boxes of a node at once, one float8 operation per slab
 * (the shape of Embree's single-ray BVH8 walk), goes on into the nearest child hit and
 * keeps the others on a stack with their entry distances. Leaves hold
 * the kd-tree's leaf records and are tested by the same code (leaf_test, leaf.h), so a hit
 * has the very t, u and v the kd-tree walk finds for that primitive.
 *
 * The slab planes are picked by the ray's direction signs (near plane, far plane), so
 * an unused lane's box (lo +inf, hi -inf) is missed by every ray, and no min/max
 * swaps are needed. A direction component that is 0 or tiny is replaced by +-1e-30
 * before its reciprocal (as Embree does), which keeps every slab distance a number:
 * (plane - origin) * 1e30 is 0 for a ray in a box's face plane, which counts as inside.
 * The far distance is widened by KD_T_SLACK, like the kd-tree's plane tests, so that
 * rounding never drops a box whose primitive the ray hits on its face: the far planes
 * are scaled by reciprocals widened once per ray, and the closest hit once per node,
 * rather than the result, whose multiply would sit in the chain from a node's loads to
 * the next node (as do the min and max, taken as two levels rather than three). Which
 * boxes are entered may differ by an ulp's worth from the product of the result; every
 * walk still finds the same hit (leaf_test's rule, tested against brute force).
 */
#ifndef CLPT_TRAVERSE_BVH_H
#define CLPT_TRAVERSE_BVH_H

#include "accel/leaf.h"
#include "accel/traverse_kd.h"
#include "geom/instance.h"

#define BVH_TINY 1e-30f

/* The slab test of a node's child boxes in lanes [first, first + W) (vectors VT of W
 * floats, comparisons IT): leaves the lanes whose box the ray enters within [tmin,
 * tmax] as bits in `mask`, and each lane's entry distance in ta. ROW(v, r) puts row r
 * of the boxes (lo x, hi x, lo y, hi y, lo z, hi z) into v: loaded from a float node,
 * or decoded from a compressed top-level node. OpenCL runs the 8 lanes as one float8,
 * and so does C compiled for AVX2 (K_VEC8, compat.h; the scalar device's AVX2 builds);
 * other C runs them as two float4 halves, because without AVX gcc splits 8-wide
 * vectors badly (as triangle_intersect_group, intersect.h); the same operations per
 * lane give the same bits either way. min and max are selects: no NaN reaches them
 * (see above). */
#define BVH_LANES_BODY(ROW, VT, IT, W, STORE, SPLAT, SELECT, BITS)                       \
    VT a, b;                                                                             \
    ROW(a, w->nx);                                                                       \
    ROW(b, 1u - w->nx);                                                                  \
    VT tx = (a - w->ox) * w->ix, ux = (b - w->ox) * w->fx;                               \
    ROW(a, 2u + w->ny);                                                                  \
    ROW(b, 3u - w->ny);                                                                  \
    VT ty = (a - w->oy) * w->iy, uy = (b - w->oy) * w->fy;                               \
    ROW(a, 4u + w->nz);                                                                  \
    ROW(b, 5u - w->nz);                                                                  \
    VT tz = (a - w->oz) * w->iz, uz = (b - w->oz) * w->fz;                               \
    VT lo = SPLAT(w->tmin), hi = SPLAT(tfar);                                            \
    tx = SELECT(tx, ty, ty > tx);                                                        \
    ux = SELECT(ux, uy, uy < ux);                                                        \
    tz = SELECT(tz, lo, lo > tz);                                                        \
    uz = SELECT(uz, hi, hi < uz);                                                        \
    VT tn = SELECT(tx, tz, tz > tx), tf = SELECT(ux, uz, uz < ux);                       \
    IT in_box = tn <= tf;                                                                \
    uint mask = BITS(in_box);                                                            \
    STORE(tn, ta + first);

/* The ray as the slab tests use it (see above). */
typedef struct {
    float ox, oy, oz, ix, iy, iz, tmin;
    float fx, fy, fz;            /* ix, iy, iz widened by KD_T_SLACK: for the far planes */
    uint nx, ny, nz;             /* 1 where the direction is negative: near plane is hi */
} BvhRay;

/* A compressed node's axis k (BvhTopNode, types.h): the bits of 2^(e - 127), e in
 * meta, which a step count q < 2^8 ors into the mantissa. */
#define BVH_TOP_BIAS(meta, k) ((((meta) >> (8u * (k))) & 0xffu) << 23)

/* BVH_LANES_BODY on one float8 (all 8 lanes, first 0) and on a float4 half (lanes first
 * .. first + 3): K_VEC8 (compat.h) says which a float node's test uses. */
#define BVH_LANES8(ROW) BVH_LANES_BODY(ROW, float8, int8, 8, k_store8, k_splat8, k_select8, k_bits8)
#define BVH_ROW8(v, r) k_load8(v, nd->box[r] + first)
#ifdef KERNEL_OPENCL
#if KF_HAS(KF_INSTANCES)
/* A compressed top-level node's row r decoded as bvh_top_plane (host/accel/bvh_top.c)
 * computes the planes it checks: the bytes or'ed into the bias's mantissa, then one add
 * of the offset; no conversion and no multiply in the chain from the node's load to its
 * slab distances (docs/instancing.md). Its eight bytes are one uchar8 load: in memory
 * order, as the C decode's (little-endian devices: x86, NVIDIA). */
#define BVH_TOP_ROW(v, r)                                                                \
    ((v) = as_float8(convert_uint8(vload8(0, (GLOBAL const uchar *)nd->q[r])) |          \
                     (uint8)(BVH_TOP_BIAS(meta, (r) >> 1))) +                            \
           (float8)(nd->offset[(r) >> 1]))
#define BVH_TOP_LANES(ROW) BVH_LANES8(ROW)
#endif
#else
#define K_SPLAT4(x) ((float4){ (x), (x), (x), (x) })
#define k_select4(a, b, m) ((float4)(((int4)(a) & ~(m)) | ((int4)(b) & (m))))
#define BVH_LANES4(ROW) BVH_LANES_BODY(ROW, float4, int4, 4, k_store4, K_SPLAT4, k_select4, k_bits4)
#define BVH_ROW4(v, r) k_load4(v, nd->box[r] + first)
#if KF_HAS(KF_INSTANCES)
/* Lanes first .. first + 3 of a compressed node's row r: bytes 0 .. 3 of one word
 * (k_bytes4: the low byte first, as OpenCL's load reads them on little-endian devices).
 * The top level stays in halves with AVX too: its levels are few. */
KFN_INLINE float4 bvh_top_row4(GLOBAL const BvhTopNode *nd, uint meta, uint r, uint first)
{
    int4 bits = k_bytes4(nd->q[r][first >> 2]) | (int)BVH_TOP_BIAS(meta, r >> 1);
    return (float4)bits + K_SPLAT4(nd->offset[r >> 1]);
}
#define BVH_TOP_ROW(v, r) ((v) = bvh_top_row4(nd, meta, r, first))
#define BVH_TOP_LANES(ROW) BVH_LANES4(ROW)
#endif
#endif

/* The slab test of float node nd's lanes from `first` (all 8 with K_VEC8, else a half). */
KFN_INLINE uint bvh_lanes(GLOBAL const BvhNode *nd, const BvhRay *w, uint first, float tfar, float *ta)
{
#if K_VEC8
    BVH_LANES8(BVH_ROW8)
#else
    BVH_LANES4(BVH_ROW4)
#endif
    return mask;
}
#if KF_HAS(KF_INSTANCES)
/* The same for a compressed top-level node, its rows decoded by BVH_TOP_ROW (all 8 lanes
 * in OpenCL, a half in C). */
KFN_INLINE uint bvh_top_lanes(GLOBAL const BvhTopNode *nd, const BvhRay *w, uint first, float tfar, float *ta)
{
    uint meta = nd->meta;
    BVH_TOP_LANES(BVH_TOP_ROW)
    return mask;
}
#endif

/* Lanes of node nd whose box the ray enters before tmax (bits), their entry distances
 * in ta. */
KFN_INLINE uint bvh_node_test(GLOBAL const BvhNode *nd, const BvhRay *w, float tmax, float *ta)
{
    float tfar = tmax * KD_T_ABOVE;
#if K_VEC8
    return bvh_lanes(nd, w, 0u, tfar, ta);
#else
    return bvh_lanes(nd, w, 0u, tfar, ta) | (bvh_lanes(nd, w, 4u, tfar, ta) << 4);
#endif
}

#if KF_HAS(KF_INSTANCES)
/* The same for a compressed top-level node (BvhTopNode, types.h): its children's lanes
 * only (lanes n .. 7 hold no box). */
KFN_INLINE uint bvh_top_test(GLOBAL const BvhTopNode *nd, const BvhRay *w, float tmax, float *ta)
{
    float tfar = tmax * KD_T_ABOVE;
    uint n = nd->meta >> 24;
#ifdef KERNEL_OPENCL
    uint mask = bvh_top_lanes(nd, w, 0u, tfar, ta);
#else
    /* lanes 4 .. 7 only when they hold children (ta is read for entered lanes alone) */
    uint mask = bvh_top_lanes(nd, w, 0u, tfar, ta);
    if (n > 4u) mask |= bvh_top_lanes(nd, w, 4u, tfar, ta) << 4;
#endif
    return mask & ((1u << n) - 1u);
}
#endif

/* The slab tests' reciprocal of direction component d, given inv = 1.0f / d (RayPre's
 * inv_d): inv itself, or for |d| < BVH_TINY (0 included) 1 / +-BVH_TINY, a constant.
 * The same bits as dividing again, without the division: a ray's set-up divided nine
 * times, which on a 2-vCPU Zen 3 held about a tenth of the scalar walk's samples on
 * Sponza, where most rays leave the tree after a few nodes (bench/RESULTS.md).
 * OpenCL divides again, as before that change: with the select, PoCL 3.1 (LLVM 15)
 * on an AVX-512 processor (Zen 4) rendered walks under a top level that missed the
 * world's triangles and boxes, where the scalar device and PoCL on AVX2 hit them
 * (test_instance, test_pbrt; the values are the same, so the cause is in how PoCL
 * built the select, not isolated further). PoCL's walk had gained nothing from it
 * (+0.5%), the scalar device's 4.6-4.8% on Sponza, which it keeps. */
KFN_INLINE float bvh_inv(float d, float inv)
{
#ifdef KERNEL_OPENCL
    float s = (k_as_uint(d) >> 31) ? -BVH_TINY : BVH_TINY;
    (void)inv;
    return 1.0f / (k_fabs(d) < BVH_TINY ? s : d);
#else
    float huge = (k_as_uint(d) >> 31) ? 1.0f / -BVH_TINY : 1.0f / BVH_TINY;
    return k_fabs(d) < BVH_TINY ? huge : inv;
#endif
}

/* Of a node's children entered (the lanes in mask), returns the one to
 * go into: the nearest by entry distance d for a closest-hit query (the first lane of
 * equals), the first for an any-hit query, for which any order will do. Pushes the
 * others as node << 3 | lane with a word each: the bits of the entry distance (lanes
 * NULL: one ray) or lanes[lane] (a packet: the lanes that entered the child), the second
 * nearest last so that it is popped next. Sorting all of them was measured slower: the
 * entries that start beyond the closest hit are skipped on the pop anyway; the second
 * nearest alone made closest-hit diffuse rays 3-11% faster (docs/bvh.md). */
KFN_INLINE uint bvh_push_children(uint ref, uint mask, const float *d, const uint *lanes, int any, uint *st_child,
                                  uint *st_word, int *sp)
{
    uint next = k_lowest_bit(mask), second = BVH_WIDTH;
    if (any != WALK_ANY)
        for (uint m = mask & (mask - 1u); m != 0u; m &= m - 1u) {
            uint l = k_lowest_bit(m);
            if (d[l] < d[next]) {
                second = next;
                next = l;
            } else if (second == BVH_WIDTH || d[l] < d[second]) {
                second = l;
            }
        }
    int n = *sp;
    for (uint m = mask; m != 0u; m &= m - 1u) {
        uint l = k_lowest_bit(m);
        if (l == next || l == second) continue;
        st_child[n] = ref << 3 | l;
        st_word[n] = lanes ? lanes[l] : k_as_uint(d[l]);
        n++;
    }
    if (second != BVH_WIDTH) {
        st_child[n] = ref << 3 | second;
        st_word[n] = lanes ? lanes[second] : k_as_uint(d[second]);
        n++;
    }
    *sp = n;
    return next;
}

/* In a program of k_path_lanes alone the walk is one function that its closest-hit and
 * any-hit queries call: inlined into both, it made PoCL's cold build of cornell-box.scene
 * a third longer (3.2 s against 2.4 s on a 2.5 GHz Xeon) at the same speed. Everything
 * else keeps it inlined (k_path: as a call it rendered one-weekend 13% slower, the
 * envmap scene 9%; the C device, the tests' and the benchmark's programs). */
#if KF_HAS(KF_PATH_LANES) && !KF_HAS(KF_PATH_MEGAKERNEL)
#define BVH_WALK_FN KFN_CALL_CL
#else
#define BVH_WALK_FN KFN_INLINE
#endif

/* The slab tests' view of a ray. */
KFN_INLINE BvhRay bvh_ray(Ray ray, const RayPre *rp)
{
    BvhRay w;
    w.ox = ray.o.x;
    w.oy = ray.o.y;
    w.oz = ray.o.z;
    w.ix = bvh_inv(ray.d.x, rp->inv_d[0]);
    w.iy = bvh_inv(ray.d.y, rp->inv_d[1]);
    w.iz = bvh_inv(ray.d.z, rp->inv_d[2]);
    w.tmin = ray.tmin;
    w.fx = w.ix * KD_T_ABOVE;
    w.fy = w.iy * KD_T_ABOVE;
    w.fz = w.iz * KD_T_ABOVE;
    w.nx = rp->neg & 1u;
    w.ny = (rp->neg >> 1) & 1u;
    w.nz = (rp->neg >> 2) & 1u;
    return w;
}

/* A stack entry that is no child but the way back out of an instance: pushed when the
 * walk enters one, so the entries pushed inside it (in object space) are popped first,
 * and popping it puts the world ray back. No node index reaches it (29 bits). */
#define BVH_STACK_LEAVE 0xffffffffu

/* The walk shared by both queries: with `any` set it returns at the first hit;
 * otherwise it keeps the closest one in *best (whose t starts as the ray's tmax).
 * With instances (KF_INSTANCES) the tree has two levels in one walk, as Embree's
 * instance traversal has: the top level's instance children (BVH_CHILD_INSTANCE) lead,
 * with the ray carried into the instance's object space, to its prototype's root, and
 * the stack holds both levels' entries, with a BVH_STACK_LEAVE between them. Entry
 * distances and the closest hit are in the world ray's t throughout (instance.h), so
 * an entry pushed in the world is skipped by a hit found in an instance as usual. The
 * top level's nodes are compressed (BvhTopNode, sc->bvh_top, decoded by bvh_top_test):
 * `top` says which level the walk is in, and so which array a stack entry's node is
 * in (the top level's entries lie below a BVH_STACK_LEAVE, the prototype's above). The
 * builds keep both levels' stack depths within BVH_STACK together (host/accel/bvh_inst.c).
 * Under --accel kdtree (a scene with kd nodes and instances) the prototypes are
 * kd-trees instead (KdProto): an instance is walked whole by trace_kd_proto, with the
 * kd walk's own stack, and the walk goes on in the top level; no BVH_STACK_LEAVE. */
BVH_WALK_FN void trace_wide(const SceneView *sc, Ray ray, const RayPre *rp, int any, Hit *best)
{
    float s = ray.o.x + ray.o.y + ray.o.z + ray.d.x + ray.d.y + ray.d.z;
#if KF_HAS(KF_INSTANCES)
    if (!(s == s) || (sc->params->n_bvh_nodes | sc->params->n_instances) == 0u) return;
#else
    if (!(s == s) || sc->params->n_bvh_nodes == 0u) return;
#endif
    BvhRay w = bvh_ray(ray, rp);
#if KF_HAS(KF_INSTANCES)
    int top = sc->params->n_instances != 0u;   /* walking the top level's nodes */
#if KF_HAS(KF_KDTREE)
    /* the prototypes are kd-trees (--accel kdtree): the scene has kd nodes */
    int kd_protos = sc->params->n_nodes != 0u;
#endif
    BvhRay w_world = w;
    Ray oray = ray;              /* the ray in the space being walked, and its constants */
    RayPre orp = *rp;
    uint inst = NO_INDEX;        /* the instance being walked (NO_INDEX: the world) */
#define TW_RAY oray
#define TW_RP (&orp)
#define TW_INST inst
#else
#define TW_RAY ray
#define TW_RP rp
#define TW_INST NO_INDEX
#endif
    /* an entry: the child's node and lane (node << 3 | lane; its reference and kind are
     * read back from the node, in cache, on the pop: a third less private memory than
     * keeping them), and its entry distance's bits */
    uint st_child[BVH_STACK];
    uint st_t[BVH_STACK];
    int sp = 0;
    uint ref = 0u, kind = BVH_CHILD_NODE;
    for (;;) {
        /* down through nodes until a leaf, or a node none of whose boxes the ray enters */
        while (kind == BVH_CHILD_NODE) {
            float ta[BVH_WIDTH];
#if KF_HAS(KF_INSTANCES)
            if (top) {
                GLOBAL const BvhTopNode *tn = sc->bvh_top + ref;
                uint tmask = bvh_top_test(tn, &w, best->t, ta);
                if (!tmask) break;
                uint tnext = k_lowest_bit(tmask);
                if (tmask & (tmask - 1u))
                    tnext = bvh_push_children(ref, tmask, ta, 0, any, st_child, st_t, &sp);
                ref = tn->ref[tnext];
                kind = (ref & BVH_TOP_INSTANCE) ? BVH_CHILD_INSTANCE : BVH_CHILD_NODE;
                ref &= ~BVH_TOP_INSTANCE;
                continue;
            }
#endif
            GLOBAL const BvhNode *nd = sc->bvh + ref;
            uint mask = bvh_node_test(nd, &w, best->t, ta);
            if (!mask) break;
            uint next = k_lowest_bit(mask);
            if (mask & (mask - 1u))   /* several children: bvh_push_children */
                next = bvh_push_children(ref, mask, ta, 0, any, st_child, st_t, &sp);
            ref = nd->ref[next];
            kind = nd->kind[next];
        }
#if KF_HAS(KF_INSTANCES) && KF_HAS(KF_KDTREE)
        if (kind == BVH_CHILD_INSTANCE && kd_protos) {
            /* the instance's kd-tree, walked whole in its object space; then on in the
             * top level, whose entries are on this stack still */
            GLOBAL const Instance *x = sc->instances + ref;
            oray = instance_ray_seen(sc, ref, x, ray);
            ray_prepare(oray, &orp);
            trace_kd_proto(sc, sc->kd_protos + x->root, oray, &orp, any, (x->flags & INST_WORLD) ? NO_INDEX : ref,
                           best);
            if (any == WALK_ANY && best->prim != NO_INDEX) return;
            kind = BVH_CHILD_NODE;   /* nothing for the leaf test below: on to the pop */
        } else
#endif
#if KF_HAS(KF_INSTANCES)
        if (kind == BVH_CHILD_INSTANCE) {
            /* into the instance: its object space, its prototype's root */
            GLOBAL const Instance *x = sc->instances + ref;
            st_child[sp] = BVH_STACK_LEAVE;
            st_t[sp] = 0u;
            sp++;
            top = 0;
            inst = (x->flags & INST_WORLD) ? NO_INDEX : ref;
            oray = instance_ray_seen(sc, ref, x, ray);
            ray_prepare(oray, &orp);
            w = bvh_ray(oray, &orp);
            ref = x->root;
            kind = BVH_CHILD_NODE;
            continue;
        }
#endif
        if (kind != BVH_CHILD_NODE) {
            KdNode leaf;
            leaf.data = ref;
            leaf.bits = kind;
            if (leaf_test(sc, sc->bvh_leaves, TW_RAY, TW_RP, any, leaf, TW_INST, best)) return;
        }
        /* the next cell on the stack that starts before the closest hit so far */
        for (;;) {
            if (sp == 0) return;
            sp--;
#if KF_HAS(KF_INSTANCES)
            if (st_child[sp] == BVH_STACK_LEAVE) {
                /* back out of the instance into the world */
                w = w_world;
                oray = ray;
                orp = *rp;
                inst = NO_INDEX;
                top = 1;
                continue;
            }
#endif
            if (!(k_as_float(st_t[sp]) > best->t * KD_T_ABOVE)) break;
        }
#if KF_HAS(KF_INSTANCES)
        if (top) {
            ref = sc->bvh_top[st_child[sp] >> 3].ref[st_child[sp] & 7u];
            kind = (ref & BVH_TOP_INSTANCE) ? BVH_CHILD_INSTANCE : BVH_CHILD_NODE;
            ref &= ~BVH_TOP_INSTANCE;
            continue;
        }
#endif
        GLOBAL const BvhNode *parent = sc->bvh + (st_child[sp] >> 3);
        uint lane = st_child[sp] & 7u;
        ref = parent->ref[lane];
        kind = parent->kind[lane];
    }
#undef TW_RAY
#undef TW_RP
#undef TW_INST
}


/* ------------------------------------------------------------------ eight rays at once */

/* A packet walk for coherent rays through the BVH (camera rays through neighbouring
 * pixels, shadow rays from neighbouring points toward one light): eight rays whose
 * directions have the same signs go down the tree together. A node's boxes are loaded
 * once for all of them and each box is tested against the eight rays as one float8, with
 * each lane's own slab arithmetic (the same operations as bvh_lanes, so a lane enters a
 * box exactly when its single walk would at the same tmax). The packet goes into the
 * child that its nearest lane enters first and keeps the others on a stack with the
 * lanes that entered them; on the pop the box is tested again against the lanes'
 * closest hits so far. In the leaves each lane still in the walk tests the primitives
 * alone (leaf_test). */
#define WIDE_PACKET 8

typedef struct {
    float8 ox, oy, oz, ix, iy, iz, tmin;
    float8 fx, fy, fz;
    uint nx, ny, nz;
} BvhPacket;

/* The lanes of `lanes` that enter child c of node nd within [tmin, tmax]; *lead gets
 * the entry distance of the lowest of them. */
KFN_INLINE uint bvh_child_lanes(GLOBAL const BvhNode *nd, uint c, const BvhPacket *p, const float8 *tfar,
                                uint lanes, float *lead)
{
    float8 tx = (nd->box[p->nx][c] - p->ox) * p->ix, ux = (nd->box[1u - p->nx][c] - p->ox) * p->fx;
    float8 ty = (nd->box[2u + p->ny][c] - p->oy) * p->iy, uy = (nd->box[3u - p->ny][c] - p->oy) * p->fy;
    float8 tz = (nd->box[4u + p->nz][c] - p->oz) * p->iz, uz = (nd->box[5u - p->nz][c] - p->oz) * p->fz;
    tx = k_select8(tx, ty, ty > tx);
    ux = k_select8(ux, uy, uy < ux);
    tz = k_select8(tz, p->tmin, p->tmin > tz);
    uz = k_select8(uz, *tfar, *tfar < uz);
    float8 tn = k_select8(tx, tz, tz > tx), tf = k_select8(ux, uz, uz < ux);
    uint m = k_bits8(tn <= tf) & lanes;
    if (m) {
        float ta[WIDE_PACKET];
        k_store8(tn, ta);
        *lead = ta[k_lowest_bit(m)];
    }
    return m;
}

/* The packet walk of rays[l] for the lanes l in `lanes`, all of whose directions have
 * the sign bits `neg`; best[l] holds each lane's closest hit so far (its t the ray's
 * tmax at the start). */
KFN_INLINE void trace_wide_packet_walk(const SceneView *sc, const Ray *rays, const RayPre *rp, int any, uint lanes,
                                       uint neg, Hit *best)
{
    float a[WIDE_PACKET * 7];
    float tfar_a[WIDE_PACKET];   /* each lane's closest hit so far, widened as tfar in bvh_lanes */
    for (uint l = 0; l < WIDE_PACKET; l++) {
        int on = (int)((lanes >> l) & 1u);
        a[0 * WIDE_PACKET + l] = on ? rays[l].o.x : 0.0f;
        a[1 * WIDE_PACKET + l] = on ? rays[l].o.y : 0.0f;
        a[2 * WIDE_PACKET + l] = on ? rays[l].o.z : 0.0f;
        a[3 * WIDE_PACKET + l] = on ? bvh_inv(rays[l].d.x, rp[l].inv_d[0]) : 1.0f;
        a[4 * WIDE_PACKET + l] = on ? bvh_inv(rays[l].d.y, rp[l].inv_d[1]) : 1.0f;
        a[5 * WIDE_PACKET + l] = on ? bvh_inv(rays[l].d.z, rp[l].inv_d[2]) : 1.0f;
        a[6 * WIDE_PACKET + l] = on ? rays[l].tmin : 0.0f;
        tfar_a[l] = best[l].t * KD_T_ABOVE;
    }
    BvhPacket p;
    k_load8(p.ox, a);
    k_load8(p.oy, a + WIDE_PACKET);
    k_load8(p.oz, a + 2 * WIDE_PACKET);
    k_load8(p.ix, a + 3 * WIDE_PACKET);
    k_load8(p.iy, a + 4 * WIDE_PACKET);
    k_load8(p.iz, a + 5 * WIDE_PACKET);
    k_load8(p.tmin, a + 6 * WIDE_PACKET);
    p.fx = p.ix * KD_T_ABOVE;
    p.fy = p.iy * KD_T_ABOVE;
    p.fz = p.iz * KD_T_ABOVE;
    p.nx = neg & 1u;
    p.ny = (neg >> 1) & 1u;
    p.nz = (neg >> 2) & 1u;
    uint st_child[BVH_STACK];
    uint st_lanes[BVH_STACK];
    int sp = 0;
    uint ref = 0u, kind = BVH_CHILD_NODE, done = 0u;
    for (;;) {
        if (kind == BVH_CHILD_NODE) {
            GLOBAL const BvhNode *nd = sc->bvh + ref;
            float8 tfar;
            k_load8(tfar, tfar_a);
            uint cm[BVH_WIDTH];
            float ct[BVH_WIDTH];
            uint hit = 0u;
            for (uint c = 0; c < BVH_WIDTH; c++) {
                if (nd->kind[c] == BVH_CHILD_NONE) break;
                cm[c] = bvh_child_lanes(nd, c, &p, &tfar, lanes, &ct[c]);
                if (cm[c]) hit |= 1u << c;
            }
            if (hit) {
                uint next = bvh_push_children(ref, hit, ct, cm, any, st_child, st_lanes, &sp);
                lanes = cm[next];
                kind = nd->kind[next];
                ref = nd->ref[next];
                continue;
            }
        } else {
            KdNode leaf;
            leaf.data = ref;
            leaf.bits = kind;
            for (uint m = lanes; m != 0u; m &= m - 1u) {
                uint l = k_lowest_bit(m);
                if (leaf_test(sc, sc->bvh_leaves, rays[l], &rp[l], any, leaf, NO_INDEX, &best[l])) done |= 1u << l;
                tfar_a[l] = best[l].t * KD_T_ABOVE;
            }
        }
        /* the next entry on the stack that a lane not yet done still enters */
        for (;;) {
            if (sp == 0) return;
            sp--;
            lanes = st_lanes[sp] & ~done;
            if (!lanes) continue;
            GLOBAL const BvhNode *parent = sc->bvh + (st_child[sp] >> 3);
            uint c = st_child[sp] & 7u;
            float8 tfar;
            k_load8(tfar, tfar_a);
            float lead;
            lanes = bvh_child_lanes(parent, c, &p, &tfar, lanes, &lead);
            if (!lanes) continue;
            ref = parent->ref[c];
            kind = parent->kind[c];
            break;
        }
    }
}

/* trace_closest (any == 0) or trace_any_hit (any == 1) of 8 rays through the BVH
 * (trace_wide_packet_walk). Rays whose signs differ from the others' are walked one
 * after the other instead. */
KFN_INLINE void trace_packet_wide(const SceneView *sc, const Ray *rays, int any, Hit *hits)
{
    RayPre rp[WIDE_PACKET];
    uint lanes = 0u, neg = 0u, mixed = 0u;
    for (uint l = 0; l < WIDE_PACKET; l++) {
        Ray ray = rays[l];
        hits[l] = hit_none(ray);
        if (trace_planes(sc, ray, any, &hits[l]) && any) continue;
        float s = ray.o.x + ray.o.y + ray.o.z + ray.d.x + ray.d.y + ray.d.z;
        if (!(s == s) || sc->params->n_bvh_nodes == 0u) continue;
        ray_prepare(ray, &rp[l]);
        if (lanes == 0u) neg = rp[l].neg;
        mixed |= rp[l].neg ^ neg;
        lanes |= 1u << l;
    }
    /* the packet walk has one level: a scene with instances walks its rays one by one */
#if KF_HAS(KF_INSTANCES)
    if (sc->params->n_instances != 0u) mixed = 1u;
#endif
    if (mixed) {
        for (uint l = 0; l < WIDE_PACKET; l++)
            if ((lanes >> l) & 1u) trace_wide(sc, rays[l], &rp[l], any, &hits[l]);
    } else if (lanes) {
        trace_wide_packet_walk(sc, rays, rp, any, lanes, neg, hits);
    }
}

#endif /* CLPT_TRAVERSE_BVH_H */
