/*
 * kd_inst.c — the prototypes' kd-trees of kd_inst.h.
 *
 * Each prototype is built alone, exactly as a scene of its primitives would be
 * (kd_build with ranges: the same events, the same splits), so a prototype's walk
 * through the shared arrays meets the nodes and leaves its own tree has, only moved.
 * Each tree's leaf data starts on a 64-byte line (16 words), as one tree's data does,
 * so that no row of a triangle group straddles two cache lines more than it would.
 */
#include "accel/kd_inst.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base/pages.h"
#include "base/timer.h"

/* Leaf data words a tree's data is aligned to in the shared array (64 bytes). */
#define KD_PROTO_ALIGN_WORDS 16u

/* Tree t's nodes and leaf data at node `node_at` and word `word_at` of out, its
 * references moved by as much: interior nodes' "above" child (bits 4-31), leaves'
 * record offsets. */
static void append_kd(const KdTree *t, KdTree *out, uint node_at, uint word_at)
{
    for (uint i = 0; i < t->n_nodes; i++) {
        KdNode n = t->nodes[i];
        if ((n.bits & 3u) == KD_LEAF) n.data += word_at;
        else n.bits += node_at << 4;
        out->nodes[node_at + i] = n;
    }
    if (t->n_leaf_prims) memcpy(out->leaf_prims + word_at, t->leaf_prims, t->n_leaf_prims * sizeof *t->leaf_prims);
}

static uint64_t align_words(uint64_t w)
{
    return (w + KD_PROTO_ALIGN_WORDS - 1u) / KD_PROTO_ALIGN_WORDS * KD_PROTO_ALIGN_WORDS;
}

Status kd_build_prototypes(const KdInput *in, const BvhProto *protos, size_t n_protos, Instance *inst,
                           const uint *object, size_t n_inst, int threads, KdTree *out, KdProto **records,
                           KdProtoStats *stats, Error *err)
{
    double t0 = timer_now();
    memset(out, 0, sizeof *out);
    memset(stats, 0, sizeof *stats);
    *records = NULL;
    Status st = ST_OK;
    KdTree *pt = calloc(n_protos + 1, sizeof *pt);
    uint8_t *used = calloc(n_protos + 1, 1);
    KdProto *rec = calloc(n_protos + 1, sizeof *rec);
    if (!pt || !used || !rec) {
        st = error_set(err, ST_INTERNAL, "kd-tree: out of memory for %zu prototypes", n_protos);
        goto done;
    }
    for (size_t i = 0; i < n_inst; i++) used[object[i]] = 1;
    uint64_t nodes = 1u, words = 0u;   /* node 0: the empty leaf of prototypes no instance reaches */
    for (size_t p = 0; p < n_protos && !st; p++) {
        if (!used[p]) continue;
        KdRange none;
        KdInput pin = bvh_proto_input(in, &protos[p], &none);
        st = kd_build(&pin, threads, &pt[p], err);
        nodes += pt[p].n_nodes;
        words = align_words(words) + pt[p].n_leaf_prims;
        stats->n_protos_built++;
        if (pt[p].stats.max_depth > stats->max_depth) stats->max_depth = pt[p].stats.max_depth;
        /* the trees' sums (SAH costs are each its own root's: not summed) */
        const KdStats *k = &pt[p].stats;
        KdStats *sum = &out->stats;
        double filled = (double)(k->n_leaves - k->n_empty_leaves), before = (double)(sum->n_leaves - sum->n_empty_leaves);
        if (filled + before > 0.0)
            sum->mean_prims_per_leaf = (sum->mean_prims_per_leaf * before + k->mean_prims_per_leaf * filled) /
                                       (filled + before);
        sum->n_leaves += k->n_leaves;
        sum->n_empty_leaves += k->n_empty_leaves;
        sum->bytes_corners += k->bytes_corners;
        sum->n_prims += k->n_prims;
        sum->n_skipped += k->n_skipped;
    }
    if (st) goto done;
    /* the "above" index has 28 bits (types.h), the record offset 32 */
    if (nodes >= (1u << 28) || words > UINT32_MAX - 1u) {
        st = error_set(err, ST_INPUT, "kd-tree: the prototypes' %llu nodes and %llu words of leaves do not fit its "
                       "layout", (unsigned long long)nodes, (unsigned long long)words);
        goto done;
    }
    out->nodes = pages_alloc_large(nodes * sizeof *out->nodes);
    out->leaf_prims = pages_alloc_large((words + 1) * sizeof *out->leaf_prims);
    if (!out->nodes || !out->leaf_prims) {
        st = error_set(err, ST_INTERNAL, "kd-tree: out of memory for %llu nodes", (unsigned long long)nodes);
        goto done;
    }
    /* the alignment's gaps are never read; zeroed, so that the buffer hashes the same */
    memset(out->leaf_prims, 0, (words + 1) * sizeof *out->leaf_prims);
    out->nodes[0].data = 0u;
    out->nodes[0].bits = KD_LEAF;
    uint node_at = 1u, word_at = 0u;
    for (size_t p = 0; p < n_protos; p++) {
        if (!used[p]) continue;   /* its record: root 0, the empty leaf, and an empty box */
        word_at = (uint)align_words(word_at);
        append_kd(&pt[p], out, node_at, word_at);
        rec[p].root = node_at;
        rec[p].lo = pt[p].lo;
        rec[p].hi = pt[p].hi;
        node_at += pt[p].n_nodes;
        word_at += pt[p].n_leaf_prims;
    }
    for (size_t i = 0; i < n_inst; i++) inst[i].root = object[i];
    out->n_nodes = (uint)nodes;
    out->n_leaf_prims = (uint)words;
    out->stats.n_nodes = (uint)nodes;
    out->stats.n_leaves++;            /* node 0 */
    out->stats.n_empty_leaves++;
    out->stats.max_depth = stats->max_depth;
    out->stats.bytes = nodes * sizeof(KdNode) + words * sizeof(uint);
    stats->n_nodes = (uint)nodes;
    stats->n_leaf_words = (uint)words;
    stats->bytes = out->stats.bytes + n_protos * sizeof(KdProto);
done:
    if (pt)
        for (size_t p = 0; p < n_protos; p++) kd_free(&pt[p]);
    free(pt);
    free(used);
    if (st) {
        kd_free(out);
        free(rec);
    } else {
        *records = rec;
    }
    stats->build_seconds = timer_now() - t0;
    out->stats.build_seconds = stats->build_seconds;
    return st;
}
