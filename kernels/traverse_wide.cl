/*
 * traverse_wide.cl -- closest-hit and any-hit queries through the 8-wide BVH.
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
 * rounding never drops a box whose primitive the ray hits on its face.
 */
#ifndef CLPT_TRAVERSE_WIDE_CL
#define CLPT_TRAVERSE_WIDE_CL

#include "leaf.h"

#define BVH_TINY 1e-30f

/* The slab test of a node's child boxes in lanes [first, first + W) (vectors VT of W
 * floats, comparisons IT): leaves the lanes whose box the ray enters within [tmin,
 * tmax] as bits in `mask`, and each lane's entry distance in ta. OpenCL runs the 8 lanes
 * as one float8; C runs them as two float4 halves, because without AVX gcc splits
 * 8-wide vectors badly (as triangle_intersect_group, intersect.h); the same operations
 * per lane give the same bits either way. min and max are selects: no NaN reaches them
 * (see above). */
#define BVH_LANES_BODY(VT, IT, W, LOAD, STORE, SPLAT, SELECT, BITS)                      \
    VT a, b;                                                                             \
    LOAD(a, nd->box[w->nx] + first);                                                     \
    LOAD(b, nd->box[1u - w->nx] + first);                                                \
    VT tn = (a - w->ox) * w->ix, tf = (b - w->ox) * w->ix;                               \
    LOAD(a, nd->box[2u + w->ny] + first);                                                \
    LOAD(b, nd->box[3u - w->ny] + first);                                                \
    VT ty = (a - w->oy) * w->iy, uy = (b - w->oy) * w->iy;                               \
    tn = SELECT(tn, ty, ty > tn);                                                        \
    tf = SELECT(tf, uy, uy < tf);                                                        \
    LOAD(a, nd->box[4u + w->nz] + first);                                                \
    LOAD(b, nd->box[5u - w->nz] + first);                                                \
    VT tz = (a - w->oz) * w->iz, uz = (b - w->oz) * w->iz;                               \
    VT lo = SPLAT(w->tmin), hi = SPLAT(tmax);                                            \
    tn = SELECT(tn, tz, tz > tn);                                                        \
    tf = SELECT(tf, uz, uz < tf);                                                        \
    tn = SELECT(tn, lo, lo > tn);                                                        \
    tf = SELECT(tf, hi, hi < tf);                                                        \
    tf = tf * KD_T_ABOVE;                                                                \
    IT in_box = tn <= tf;                                                                \
    uint mask = BITS(in_box);                                                            \
    STORE(tn, ta + first);

/* The ray as the slab tests use it (see above). */
typedef struct {
    float ox, oy, oz, ix, iy, iz, tmin;
    uint nx, ny, nz;             /* 1 where the direction is negative: near plane is hi */
} BvhRay;

#ifdef KERNEL_OPENCL
#define K_SPLAT8(x) ((float8)(x))
KFN_INLINE uint bvh_lanes(GLOBAL const BvhNode *nd, const BvhRay *w, uint first, float tmax, float *ta)
{
    BVH_LANES_BODY(float8, int8, 8, k_load8, k_store8, K_SPLAT8, k_select8, k_bits8)
    return mask;
}
#else
#define K_SPLAT4(x) ((float4){ (x), (x), (x), (x) })
#define k_select4(a, b, m) ((float4)(((int4)(a) & ~(m)) | ((int4)(b) & (m))))
KFN_INLINE uint bvh_lanes(GLOBAL const BvhNode *nd, const BvhRay *w, uint first, float tmax, float *ta)
{
    BVH_LANES_BODY(float4, int4, 4, k_load4, k_store4, K_SPLAT4, k_select4, k_bits4)
    return mask;
}
#endif

/* Lanes of node nd whose box the ray enters before tmax (bits), their entry distances
 * in ta. */
KFN_INLINE uint bvh_node_test(GLOBAL const BvhNode *nd, const BvhRay *w, float tmax, float *ta)
{
#ifdef KERNEL_OPENCL
    return bvh_lanes(nd, w, 0u, tmax, ta);
#else
    return bvh_lanes(nd, w, 0u, tmax, ta) | (bvh_lanes(nd, w, 4u, tmax, ta) << 4);
#endif
}

KFN_INLINE float bvh_inv(float d)
{
    float s = (k_as_uint(d) >> 31) ? -BVH_TINY : BVH_TINY;
    return 1.0f / (k_fabs(d) < BVH_TINY ? s : d);
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

/* The walk shared by both queries: with `any` set it returns at the first hit;
 * otherwise it keeps the closest one in *best (whose t starts as the ray's tmax). */
BVH_WALK_FN void trace_wide(const SceneView *sc, Ray ray, const RayPre *rp, int any, Hit *best)
{
    float s = ray.o.x + ray.o.y + ray.o.z + ray.d.x + ray.d.y + ray.d.z;
    if (!(s == s) || sc->params->n_bvh_nodes == 0u) return;
    BvhRay w;
    w.ox = ray.o.x;
    w.oy = ray.o.y;
    w.oz = ray.o.z;
    w.ix = bvh_inv(ray.d.x);
    w.iy = bvh_inv(ray.d.y);
    w.iz = bvh_inv(ray.d.z);
    w.tmin = ray.tmin;
    w.nx = rp->neg & 1u;
    w.ny = (rp->neg >> 1) & 1u;
    w.nz = (rp->neg >> 2) & 1u;
    /* an entry: the child's node and lane (node << 3 | lane; its reference and kind are
     * read back from the node, in cache, on the pop: a third less private memory than
     * keeping them), and its entry distance */
    uint st_child[BVH_STACK];
    float st_t[BVH_STACK];
    int sp = 0;
    uint ref = 0u, kind = BVH_CHILD_NODE;
    for (;;) {
        if (kind == BVH_CHILD_NODE) {
            GLOBAL const BvhNode *nd = sc->bvh + ref;
            float ta[BVH_WIDTH];
            uint mask = bvh_node_test(nd, &w, best->t, ta);
            if (mask) {
                uint l0 = k_lowest_bit(mask);
                if ((mask & (mask - 1u)) == 0u) {   /* one child hit: no stack */
                    ref = nd->ref[l0];
                    kind = nd->kind[l0];
                    continue;
                }
                /* Several children: go on into the nearest (a closest-hit query; the
                 * first lane of equals) or the first (an any-hit query, for which
                 * any order will do), push the others with their entry distances, the
                 * second nearest last so that it is popped next. Sorting all of them
                 * was measured slower: the entries that start beyond the closest hit
                 * are skipped on the pop anyway; the second nearest alone made
                 * closest-hit diffuse rays 3-11% faster (docs/bvh.md). */
                uint next = l0, second = BVH_WIDTH;
                if (!any)
                    for (uint m = mask & (mask - 1u); m != 0u; m &= m - 1u) {
                        uint l = k_lowest_bit(m);
                        if (ta[l] < ta[next]) {
                            second = next;
                            next = l;
                        } else if (second == BVH_WIDTH || ta[l] < ta[second]) {
                            second = l;
                        }
                    }
                for (uint m = mask; m != 0u; m &= m - 1u) {
                    uint l = k_lowest_bit(m);
                    if (l == next || l == second) continue;
                    st_child[sp] = ref << 3 | l;
                    st_t[sp] = ta[l];
                    sp++;
                }
                if (second != BVH_WIDTH) {
                    st_child[sp] = ref << 3 | second;
                    st_t[sp] = ta[second];
                    sp++;
                }
                ref = nd->ref[next];
                kind = nd->kind[next];
                continue;
            }
        } else {
            KdNode leaf;
            leaf.data = ref;
            leaf.bits = kind;
            if (leaf_test(sc, sc->bvh_leaves, ray, rp, any, leaf, best)) return;
        }
        /* the next cell on the stack that starts before the closest hit so far */
        do {
            if (sp == 0) return;
            sp--;
        } while (st_t[sp] > best->t * KD_T_ABOVE);
        GLOBAL const BvhNode *parent = sc->bvh + (st_child[sp] >> 3);
        uint lane = st_child[sp] & 7u;
        ref = parent->ref[lane];
        kind = parent->kind[lane];
    }
}

#endif /* CLPT_TRAVERSE_WIDE_CL */
