/*
 * bvh_top.c — the compressed top level of bvh_top.h.
 *
 * Per node and axis: the step is the least power of two with which 255 steps reach from
 * the least lower plane of the children to the greatest upper plane once rounded
 * (Ylitie et al. 2017 choose the exponent the same way, ceil(log2(extent / 255))); the
 * bias is that step times 2^23, the float whose mantissa holds a step count exactly
 * (BvhTopNode, types.h), and the offset is the float that brings the bias down to the
 * least lower plane, rounded down. Each lower plane is rounded down to a step and each
 * upper plane up, and then moved one step further while the decoded float does not hold
 * the child's plane: the kernels' decode rounds once, so the check here is on the float
 * the walk will see, not on real numbers.
 */
#include "accel/bvh_top.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The bias's exponent: from 2^-77 (a step of 2^-100: the bias, every plane's sum and
 * the step stay normal floats, which devices that flush subnormals to zero compute
 * alike) to 2^127 (a step of 2^104, which spans the 2^111 of BVH_TOP_COORD_MAX's box
 * in 255 steps with one to spare for the offset's rounding). */
#define TOP_E_MIN 50u
#define TOP_E_MAX 254u

float bvh_top_plane(float offset, uint e, uint q)
{
    union { uint u; float f; } biased = { e << 23 | q };
    return biased.f + offset;
}

/* Steps of the lower (up = 0) or upper (up = 1) plane v of an axis with offset and
 * exponent e: the greatest q whose plane is at most v, or the least whose plane is at
 * least v; 256 when no q < 256 reaches it. */
static uint plane_steps(float offset, uint e, float v, int up)
{
    double step = ldexp(1.0, (int)e - 150);
    double r = ((double)v - (double)bvh_top_plane(offset, e, 0u)) / step;
    double q0 = up ? ceil(r) : floor(r);
    if (q0 < 0.0) q0 = 0.0;
    if (q0 > 255.0) {
        if (!up) q0 = 255.0;
        else return 256u;
    }
    uint q = (uint)q0;
    if (up) {
        while (q < 256u && bvh_top_plane(offset, e, q) < v) q++;
    } else {
        while (q > 0u && bvh_top_plane(offset, e, q) > v) q--;
    }
    return q;
}

/* The offset with which step 0 of exponent e decodes to lo or just below it. */
static float axis_offset(float lo, uint e)
{
    float offset = (float)((double)lo - ldexp(1.0, (int)e - 127));
    while (bvh_top_plane(offset, e, 0u) > lo) offset = nextafterf(offset, -INFINITY);
    return offset;
}

static void put_byte(uint row[2], uint lane, uint q)
{
    row[lane / 4u] |= q << (8u * (lane % 4u));
}

/* One node: n children (lanes 0 .. n-1) of float node nd, every plane finite and
 * within BVH_TOP_COORD_MAX (bvh_top_compress checks). */
static void compress_node(const BvhNode *nd, uint n, BvhTopNode *out)
{
    memset(out, 0, sizeof *out);
    out->meta = n << 24;   /* a node without children: never entered (its mask is 0) */
    for (uint k = 0; n && k < 3u; k++) {
        float lo = INFINITY, hi = -INFINITY;
        for (uint l = 0; l < n; l++) {
            if (nd->box[2u * k][l] < lo) lo = nd->box[2u * k][l];
            if (nd->box[2u * k + 1u][l] > hi) hi = nd->box[2u * k + 1u][l];
        }
        /* the least e whose step, times 255, is at least the extent, then up while a
         * child's upper plane does not fit (the offset's and the decode's rounding) */
        double extent = (double)hi - (double)lo;
        int x = 0;
        frexp(extent / 255.0, &x);   /* extent / 255 < 2^x */
        uint e = x + 150 < (int)TOP_E_MIN ? TOP_E_MIN : x + 150 > (int)TOP_E_MAX ? TOP_E_MAX : (uint)(x + 150);
        float offset = axis_offset(lo, e);
        for (; e < TOP_E_MAX; e++, offset = axis_offset(lo, e)) {
            uint l = 0;
            while (l < n && plane_steps(offset, e, nd->box[2u * k + 1u][l], 1) < 256u) l++;
            if (l == n) break;
        }
        out->offset[k] = offset;
        out->meta |= e << (8u * k);
        for (uint l = 0; l < n; l++) {
            uint ql = plane_steps(offset, e, nd->box[2u * k][l], 0);
            uint qh = plane_steps(offset, e, nd->box[2u * k + 1u][l], 1);
            put_byte(out->q[2u * k], l, ql);
            put_byte(out->q[2u * k + 1u], l, qh > 255u ? 255u : qh);   /* not reached within the limit */
        }
    }
}

int bvh_top_box_fits(const float lo[3], const float hi[3])
{
    for (int k = 0; k < 3; k++)
        if (!(lo[k] >= -BVH_TOP_COORD_MAX && hi[k] <= BVH_TOP_COORD_MAX)) return 0;
    return 1;
}

Status bvh_top_compress(const Bvh *top, BvhTopNode **out, Error *err)
{
    BvhTopNode *t = malloc((top->n_nodes ? top->n_nodes : 1u) * sizeof *t);
    if (!t) return error_set(err, ST_INTERNAL, "BVH: out of memory for %u top-level nodes", top->n_nodes);
    for (uint i = 0; i < top->n_nodes; i++) {
        const BvhNode *nd = &top->nodes[i];
        uint n = 0;
        while (n < BVH_WIDTH && nd->kind[n] != BVH_CHILD_NONE) n++;
        for (uint l = 0; l < n; l++) {
            float lo[3] = { nd->box[0][l], nd->box[2][l], nd->box[4][l] };
            float hi[3] = { nd->box[1][l], nd->box[3][l], nd->box[5][l] };
            if (!bvh_top_box_fits(lo, hi)) {
                free(t);
                return error_set(err, ST_INTERNAL, "BVH: top-level node %u has a child box beyond +-%g", i,
                                 (double)BVH_TOP_COORD_MAX);
            }
        }
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
