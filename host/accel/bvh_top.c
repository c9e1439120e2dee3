/*
 * bvh_top.c — the compressed top level of bvh_top.h.
 *
 * Per node and axis: the origin is the least lower plane of its children (a float of
 * their boxes, so step 0 decodes to it exactly), and the step the least power of two
 * with which 255 steps reach the greatest upper plane once rounded (Ylitie et al. 2017
 * choose the exponent the same way, ceil(log2(extent / 255))). Each lower plane is
 * rounded down to a step and each upper plane up, and then moved one step further
 * while the decoded float does not hold the child's plane: the kernels' decode rounds
 * once, so the check here is on the float the walk will see, not on real numbers.
 */
#include "accel/bvh_top.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The step's exponent is kept at 2^-100 or more: the step and every product stay
 * normal floats, which devices that flush subnormals to zero compute alike. */
#define TOP_E_MIN 27u
#define TOP_E_MAX 254u

float bvh_top_plane(float origin, uint e, uint q)
{
    union { uint u; float f; } step = { e << 23 };
    return origin + (float)q * step.f;
}

/* Steps of the lower (up = 0) or upper (up = 1) plane v from origin with exponent e:
 * the greatest q whose plane is at most v, or the least whose plane is at least v;
 * 256 when no q < 256 reaches it. */
static uint plane_steps(float origin, uint e, float v, int up)
{
    double step = ldexp(1.0, (int)e - 127);
    double r = ((double)v - (double)origin) / step;
    double q0 = up ? ceil(r) : floor(r);
    if (q0 < 0.0) q0 = 0.0;
    if (q0 > 255.0) {
        if (!up) q0 = 255.0;
        else return 256u;
    }
    uint q = (uint)q0;
    if (up) {
        while (q < 256u && bvh_top_plane(origin, e, q) < v) q++;
    } else {
        while (q > 0u && bvh_top_plane(origin, e, q) > v) q--;
    }
    return q;
}

static void put_byte(uint row[2], uint lane, uint q)
{
    row[lane / 4u] |= q << (8u * (lane % 4u));
}

/* One node: n children (lanes 0 .. n-1) of float node nd. */
static void compress_node(const BvhNode *nd, uint n, BvhTopNode *out)
{
    memset(out, 0, sizeof *out);
    out->meta = n << 24 | 127u << 16 | 127u << 8 | 127u;   /* a node without children: never entered */
    for (uint k = 0; n && k < 3u; k++) {
        float lo = INFINITY, hi = -INFINITY;
        for (uint l = 0; l < n; l++) {
            if (nd->box[2u * k][l] < lo) lo = nd->box[2u * k][l];
            if (nd->box[2u * k + 1u][l] > hi) hi = nd->box[2u * k + 1u][l];
        }
        /* the least e with 255 steps >= the extent, then up while a child's upper
         * plane does not fit (the decode's rounding) */
        double extent = (double)hi - (double)lo;
        int x = 0;
        frexp(extent / 255.0, &x);   /* extent / 255 < 2^x */
        uint e = x + 127 < (int)TOP_E_MIN ? TOP_E_MIN : x + 127 > (int)TOP_E_MAX ? TOP_E_MAX : (uint)(x + 127);
        for (;; e++) {
            uint l = 0;
            while (l < n && plane_steps(lo, e, nd->box[2u * k + 1u][l], 1) < 256u) l++;
            if (l == n || e == TOP_E_MAX) break;
        }
        out->origin[k] = lo;
        out->meta = (out->meta & ~(0xffu << (8u * k))) | e << (8u * k);
        for (uint l = 0; l < n; l++) {
            uint ql = plane_steps(lo, e, nd->box[2u * k][l], 0);
            uint qh = plane_steps(lo, e, nd->box[2u * k + 1u][l], 1);
            put_byte(out->q[2u * k], l, ql);
            put_byte(out->q[2u * k + 1u], l, qh > 255u ? 255u : qh);   /* 2^127 steps: +inf */
        }
    }
}

Status bvh_top_compress(const Bvh *top, BvhTopNode **out, Error *err)
{
    BvhTopNode *t = malloc((top->n_nodes ? top->n_nodes : 1u) * sizeof *t);
    if (!t) return error_set(err, ST_INTERNAL, "BVH: out of memory for %u top-level nodes", top->n_nodes);
    for (uint i = 0; i < top->n_nodes; i++) {
        const BvhNode *nd = &top->nodes[i];
        uint n = 0;
        while (n < BVH_WIDTH && nd->kind[n] != BVH_CHILD_NONE) n++;
        compress_node(nd, n, &t[i]);
        for (uint l = 0; l < n; l++) {
            if (nd->kind[l] == BVH_CHILD_INSTANCE && nd->ref[l] < BVH_TOP_INSTANCE) {
                t[i].ref[l] = nd->ref[l] | BVH_TOP_INSTANCE;
            } else if (nd->kind[l] == BVH_CHILD_NODE) {
                t[i].ref[l] = nd->ref[l];
            } else {
                free(t);
                return error_set(err, ST_INTERNAL, "BVH: top-level node %u has a child of kind %u", i, nd->kind[l]);
            }
        }
    }
    *out = t;
    return ST_OK;
}
