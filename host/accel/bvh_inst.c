/*
 * bvh_inst.c — the two-level BVH of bvh_inst.h.
 *
 * The order of the builds follows the walk's one stack (kernels/accel/traverse_bvh.h):
 * a path through the top level leaves its entries on the stack while the walk goes on
 * inside an instance, so the top level is built first, within BVH_TOP_STACK, and every
 * prototype within what its deepest path left (the collapse gives nodes fewer children
 * where a path nears its budget, bvh.c). The top level needs the prototypes' bounds,
 * which come from their primitives' boxes before any prototype is built.
 */
#include "accel/bvh_inst.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh_top.h"
#include "base/pages.h"
#include "base/timer.h"
#include "scene/motion.h"

/* The box of a prototype's primitives (lo > hi when it has none with finite bounds). */
static void proto_bounds(const KdInput *in, const BvhProto *p, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (size_t r = 0; r < p->n_ranges; r++)
        for (uint gid = p->ranges[r].lo; gid < p->ranges[r].hi; gid++) {
            float a[3], b[3];
            if (!kd_prim_box(in, gid, a, b)) continue;
            for (int k = 0; k < 3; k++) {
                if (a[k] < lo[k]) lo[k] = a[k];
                if (b[k] > hi[k]) hi[k] = b[k];
            }
        }
}

/* The world box of instance x over a prototype box: its eight corners under M, in
 * double, widened by 2^-18 of the box's size and position so that the float rounding
 * of the walk's object-space ray (instance.h) cannot put a hit outside it. Written as
 * an empty box (lo > hi) for an empty prototype. A moving instance (keys, its first
 * key, not NULL): the box of motion_bounds, widened as well. */
static void instance_box(const Instance *x, const MotionKey *keys, const double lo[3], const double hi[3],
                         float out[6])
{
    double wl[3] = { INFINITY, INFINITY, INFINITY }, wh[3] = { -INFINITY, -INFINITY, -INFINITY };
    if (!(lo[0] <= hi[0])) {
        for (int k = 0; k < 3; k++) {
            out[k] = INFINITY;
            out[3 + k] = -INFINITY;
        }
        return;
    }
    if (keys) motion_bounds(keys, keys->count, lo, hi, wl, wh);   /* a moving instance */
    for (int c = 0; c < 8 && !keys; c++) {
        double p[3] = { (c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1], (c & 4) ? hi[2] : lo[2] };
        for (int k = 0; k < 3; k++) {
            const float *m = x->to_world + 4 * k;
            double v = (double)m[0] * p[0] + (double)m[1] * p[1] + (double)m[2] * p[2] + (double)m[3];
            if (v < wl[k]) wl[k] = v;
            if (v > wh[k]) wh[k] = v;
        }
    }
    for (int k = 0; k < 3; k++) {
        double pad = 0x1p-18 * (wh[k] - wl[k] + fabs(wl[k]) + fabs(wh[k])) + 0x1p-100;
        out[k] = (float)(wl[k] - pad);
        out[3 + k] = (float)(wh[k] + pad);
        if ((double)out[k] > wl[k] - pad) out[k] = nextafterf(out[k], -INFINITY);
        if ((double)out[3 + k] < wh[k] + pad) out[3 + k] = nextafterf(out[3 + k], INFINITY);
    }
}

/* Appends tree t's nodes and leaves at node `node_at` and word `word_at` of out, its
 * references moved by as much. */
static void append_tree(const Bvh *t, Bvh *out, uint node_at, uint word_at)
{
    for (uint i = 0; i < t->n_nodes; i++) {
        BvhNode nd = t->nodes[i];
        for (uint l = 0; l < BVH_WIDTH; l++) {
            if (nd.kind[l] == BVH_CHILD_NODE) nd.ref[l] += node_at;
            else if (nd.kind[l] != BVH_CHILD_NONE && nd.kind[l] != BVH_CHILD_INSTANCE) nd.ref[l] += word_at;
        }
        out->nodes[node_at + i] = nd;
    }
    if (t->n_leaf_prims) memcpy(out->leaf_prims + word_at, t->leaf_prims, t->n_leaf_prims * sizeof *t->leaf_prims);
}

/* The top level over the instances' world boxes (built first: its depth sets the
 * prototypes' budget). */
static Status build_top(const KdInput *in, const BvhProto *protos, size_t n_protos, const Instance *inst,
                        const uint *object, size_t n_inst, const BvhMotion *motion, int threads, Bvh *top, BvhLevels *lv, Error *err)
{
    double (*pb)[6] = malloc((n_protos + 1) * sizeof *pb);
    float *boxes = malloc((n_inst + 1) * 6 * sizeof *boxes);
    if (!pb || !boxes) {
        free(pb);
        free(boxes);
        return error_set(err, ST_INTERNAL, "BVH: out of memory for %zu instances", n_inst);
    }
    for (size_t p = 0; p < n_protos; p++) proto_bounds(in, &protos[p], pb[p], pb[p] + 3);
    for (size_t i = 0; i < n_inst; i++) {
        const MotionKey *keys = motion && motion->inst_motion && motion->inst_motion[i] != NO_INDEX
                                    ? motion->keys + motion->inst_motion[i]
                                    : NULL;
        float *b = boxes + 6 * i;
        instance_box(&inst[i], keys, pb[object[i]], pb[object[i]] + 3, b);
        int empty = !(b[0] <= b[3]);
        lv->n_inst_skipped += empty;
        if (!empty && !bvh_top_box_fits(b, b + 3)) {
            /* the compressed nodes hold finite boxes within 2^110 (bvh_top.h): none is
             * left "always entered", none decodes to an infinity */
            float far = 0.0f;
            for (int k = 0; k < 6; k++) far = isnan(b[k]) ? INFINITY : fmaxf(far, fabsf(b[k]));
            lv->inst_beyond = (uint)i;
            lv->inst_beyond_at = far;
            free(pb);
            free(boxes);
            return error_set(err, ST_INPUT, "BVH: instance %zu's world box reaches %g, beyond the top level's %g",
                             i, (double)far, (double)BVH_TOP_COORD_MAX);
        }
    }
    BvhOptions opt = { BVH_TOP_STACK, boxes, (uint)n_inst };
    Status st = bvh_build_with(in, &opt, threads, top, err);
    free(pb);
    free(boxes);
    return st;
}

KdInput bvh_proto_input(const KdInput *in, const BvhProto *proto, KdRange *none)
{
    KdInput pin = *in;
    pin.ranges = proto->ranges;
    pin.n_ranges = proto->n_ranges;
    /* an empty range list would mean every primitive: an empty prototype has none */
    if (pin.n_ranges == 0) {
        *none = (KdRange){ 0u, 0u };
        pin.ranges = none;
        pin.n_ranges = 1;
    }
    return pin;
}

Status bvh_build_instanced(const KdInput *in, const BvhProto *protos, size_t n_protos, Instance *inst,
                           const uint *object, size_t n_inst, const BvhMotion *motion, int threads, Bvh *out, BvhLevels *lv, Error *err)
{
    double t0 = timer_now();
    memset(out, 0, sizeof *out);
    memset(lv, 0, sizeof *lv);
    lv->inst_beyond = NO_INDEX;
    Bvh top;
    Status st = build_top(in, protos, n_protos, inst, object, n_inst, motion, threads, &top, lv, err);
    if (st) return st;
    Bvh *pt = calloc(n_protos + 1, sizeof *pt);
    uint8_t *used = calloc(n_protos + 1, 1);
    if (!pt || !used) {
        st = error_set(err, ST_INTERNAL, "BVH: out of memory for %zu prototypes", n_protos);
        goto done;
    }
    for (size_t i = 0; i < n_inst; i++) used[object[i]] = 1;
    /* what the top level's deepest path left, and the entry that leads back out */
    BvhOptions opt = { BVH_STACK - 1u - top.stats.max_stack, NULL, 0u };
    /* the top level goes to its own compressed array; nodes[] holds the prototypes */
    uint64_t nodes = 0u, words = top.n_leaf_prims;
    for (size_t p = 0; p < n_protos && !st; p++) {
        if (!used[p]) continue;
        KdRange none;
        KdInput pin = bvh_proto_input(in, &protos[p], &none);
        st = bvh_build_with(&pin, &opt, threads, &pt[p], err);
        nodes += pt[p].n_nodes;
        words += pt[p].n_leaf_prims;
        lv->n_protos_built++;
        if (pt[p].stats.max_stack > lv->max_proto_stack) lv->max_proto_stack = pt[p].stats.max_stack;
    }
    if (st) goto done;
    if (nodes >= (1u << 29) || words > UINT32_MAX - 1u) {
        st = error_set(err, ST_INPUT, "BVH: the two levels' %llu nodes and %llu words of leaves do not fit its layout",
                       (unsigned long long)nodes, (unsigned long long)words);
        goto done;
    }
    out->nodes = pages_alloc_large(nodes * sizeof *out->nodes);
    out->leaf_prims = pages_alloc_large((words + 1) * sizeof *out->leaf_prims);
    if (!out->nodes || !out->leaf_prims) {
        st = error_set(err, ST_INTERNAL, "BVH: out of memory for %llu nodes", (unsigned long long)nodes);
        goto done;
    }
    if ((st = bvh_top_compress(&top, &out->top, err))) goto done;
    out->n_top = top.n_nodes;
    if (top.n_leaf_prims) memcpy(out->leaf_prims, top.leaf_prims, top.n_leaf_prims * sizeof *top.leaf_prims);
    uint node_at = 0u, word_at = top.n_leaf_prims;
    uint *root = calloc(n_protos + 1, sizeof *root);
    if (!root) {
        st = error_set(err, ST_INTERNAL, "BVH: out of memory for %zu prototypes", n_protos);
        goto done;
    }
    for (size_t p = 0; p < n_protos; p++) {
        if (!used[p]) continue;
        append_tree(&pt[p], out, node_at, word_at);
        root[p] = node_at;
        node_at += pt[p].n_nodes;
        word_at += pt[p].n_leaf_prims;
    }
    for (size_t i = 0; i < n_inst; i++) inst[i].root = root[object[i]];
    free(root);
    out->n_nodes = (uint)nodes;
    out->n_leaf_prims = (uint)words;
    out->lo = top.lo;
    out->hi = top.hi;
    out->stats = top.stats;
    out->stats.n_nodes = (uint)nodes + top.n_nodes;   /* both levels' */
    lv->top = top.stats;
    lv->top_nodes = top.n_nodes;
    lv->proto_nodes = (uint)nodes;
    lv->proto_leaf_words = (uint)(words - top.n_leaf_prims);
done:
    bvh_free(&top);
    if (pt)
        for (size_t p = 0; p < n_protos; p++) bvh_free(&pt[p]);
    free(pt);
    free(used);
    if (st) bvh_free(out);
    else out->stats.build_seconds = timer_now() - t0;
    return st;
}

Status bvh_build_top_level(const KdInput *in, const BvhProto *protos, size_t n_protos, const Instance *inst,
                           const uint *object, size_t n_inst, const BvhMotion *motion, int threads, Bvh *out,
                           BvhLevels *lv, Error *err)
{
    double t0 = timer_now();
    memset(out, 0, sizeof *out);
    memset(lv, 0, sizeof *lv);
    lv->inst_beyond = NO_INDEX;
    Bvh top;
    Status st = build_top(in, protos, n_protos, inst, object, n_inst, motion, threads, &top, lv, err);
    if (st) return st;
    if ((st = bvh_top_compress(&top, &out->top, err)) == ST_OK) {
        out->n_top = top.n_nodes;
        out->lo = top.lo;
        out->hi = top.hi;
        out->stats = top.stats;
        out->stats.build_seconds = timer_now() - t0;
        lv->top = top.stats;
        lv->top_nodes = top.n_nodes;
    }
    bvh_free(&top);
    if (st) bvh_free(out);
    return st;
}
