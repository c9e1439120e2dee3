/*
 * bvh_collapse.c — the binary tree of bvh.c collapsed into the 8-wide nodes of
 * accel/bvh.h (BvhNode, kernels/types.h) and their leaf records.
 *
 * A wide node takes its binary node's two children and, while it has fewer than eight,
 * replaces the interior child with the largest surface area by that child's two
 * children (Embree's BVH8 from a binary build); a top level over instances is cut by
 * dynamic programming instead, for full nodes (pack_measure). The wide nodes are
 * written depth first, a parent before its children, the leaves' records into the leaf
 * data in the kd-tree's layout (kd_leaf_record_write); the leaves are sorted and
 * written on the threads. docs/bvh.md has the measurements behind the choices.
 */
#include "accel/bvh_build.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "base/jobs.h"
#include "base/pages.h"

/* A leaf's record to write: at `words` in the leaf data, for binary leaf `bin`, whose
 * kind goes to lane `lane` of wide node `node`. */
typedef struct { uint node, lane, bin, words; } LeafSlot;

/* The collapse in three steps: each binary leaf's ids sorted and its record's size
 * (leaves_measure, by ranges of nodes on the threads); the wide nodes, depth first,
 * with the leaves' places in the leaf data (flat_node, on this thread); the records
 * (slots_write, by ranges of leaves on the threads). */
typedef struct {
    BvhBuild *b;
    Bvh *out;
    uint *ids;              /* per primitive, in tree order: its global id, sorted within each leaf */
    uint *node_words;       /* per binary leaf: the words of its record */
    LeafSlot *slots;        /* the records, in the order flat_node meets them */
    size_t n_slots;
    size_t words;
    uint max_pending;       /* the deepest the walk's stack can get */
    uint depth_bound;       /* binary levels a path below any node may still take: BVH_MAX_DEPTH,
                             * or an item build's own depth (a top level is shallow, and its
                             * budget small: docs/instancing.md) */
    float *pack;            /* item builds: per binary node v and i in 1..BVH_WIDTH, at
                             * v * BVH_WIDTH + i - 1, the fewest wide nodes that hold v's
                             * subtree as at most i children of a parent (pack_measure) */
} Flat;

static int uint_cmp(const void *a, const void *b)
{
    uint x = *(const uint *)a, y = *(const uint *)b;
    return (x > y) - (x < y);
}

/* ---- item builds: wide nodes packed full
 *
 * A top level holds one instance a leaf, and the greedy expansion below (largest
 * area first) leaves the nodes above the leaves 2 or 3 wide: a balanced tree of 10,000
 * leaves splits into 4,096 subtrees of 2.4 leaves at its fourth level (a grid of
 * dragons: 4,258 nodes, 3.35 children each). Every node costs the devices 256 bytes,
 * so for item builds the choice of which binary nodes become wide nodes is made by
 * dynamic programming over the binary tree for the fewest wide nodes, as Ylitie et al.
 * (2017, "Efficient incoherent ray traversal on GPUs through compressed wide BVHs")
 * choose it for the least SAH cost: P(v, i), the fewest nodes that hold v's subtree as
 * at most i children of a parent, is 0 for a leaf; for an interior v, the least of
 * 1 + S(v, BVH_WIDTH) (v becomes a node of its own) and S(v, i), where S(v, i) is the
 * least P(c0, j) + P(c1, i - j) (v's slots shared by its two children); each node adds
 * PACK_AREA times its area too. The binary tree, hence which items share a subtree, is
 * the SAH's as before; only its cut changes, so every walk finds the same hits (the
 * tie rule, accel/leaf.h). The grid of dragons: 1,764 nodes (4.7 children each), 2.4
 * times fewer, at the same speed; scenes/instances.scene: 575, against 597. */

/* Each node also costs its area over the root's, times this: among cuts of nearly as
 * few nodes, a shallow one of little SAH. A deep top level spends the walk's stack,
 * which the prototypes then lack (host/accel/bvh_inst.c: their nodes fall back to two
 * children). By node count alone the grid of 10,000 dragons' top level was 11 nodes
 * deep and left the dragon 75 entries, against 96, which made it 15,757 nodes, not
 * 12,140; at 1 its top level took 46 entries, at 64 40, at 256 39 (instances.scene 46,
 * 39, 32; the greedy's 31 and 29), for 1,756, 1,763 and 1,764 nodes (567, 572, 575). */
#define PACK_AREA 256.0
static float pack_split(const float *pack, uint c0, uint c1, uint i, uint *best_j)
{
    float best = INFINITY;
    for (uint j = 1; j < i; j++) {
        float c = pack[(size_t)c0 * BVH_WIDTH + j - 1u] + pack[(size_t)c1 * BVH_WIDTH + (i - j) - 1u];
        if (c < best) {
            best = c;
            *best_j = j;
        }
    }
    return best;
}

/* Fills P (Flat.pack) for binary node v's subtree, children first. */
static void pack_measure(const BvhBuild *b, float *pack, uint v, double root_area)
{
    const BinNode *c = &b->nodes[v];
    float *p = pack + (size_t)v * BVH_WIDTH;
    if (c->count > 0 || c->child[0] == NO_INDEX) {
        for (uint i = 0; i < BVH_WIDTH; i++) p[i] = 0.0f;
        return;
    }
    pack_measure(b, pack, c->child[0], root_area);
    pack_measure(b, pack, c->child[1], root_area);
    uint j;
    float own = (float)(1.0 + PACK_AREA * box3_half_area(&c->box) / root_area) +
                pack_split(pack, c->child[0], c->child[1], BVH_WIDTH, &j);
    p[0] = own;
    for (uint i = 2; i <= BVH_WIDTH; i++) {
        float split = pack_split(pack, c->child[0], c->child[1], i, &j);
        p[i - 1u] = split < own ? split : own;
    }
}

/* The children binary node v makes with at most i slots: itself, or (when sharing
 * them among its two children is no worse) theirs. */
static void pack_kids(const BvhBuild *b, const float *pack, uint v, uint i, uint *kids, int *n)
{
    const BinNode *c = &b->nodes[v];
    uint j = 1u;
    if (i < 2u || c->count > 0 || c->child[0] == NO_INDEX ||
        pack_split(pack, c->child[0], c->child[1], i, &j) > pack[(size_t)v * BVH_WIDTH]) {
        kids[(*n)++] = v;
        return;
    }
    pack_kids(b, pack, c->child[0], j, kids, n);
    pack_kids(b, pack, c->child[1], i - j, kids, n);
}

/* Up to `width` binary nodes under binary interior node `bn` (or bn itself when it is
 * a leaf) that become one wide node's children; returns how many. */
static int wide_children(const BvhBuild *b, const float *pack, uint bn, int width, uint *kids)
{
    int n = 0;
    if (b->nodes[bn].count > 0 || b->nodes[bn].child[0] == NO_INDEX) {
        kids[n++] = bn;
        return n;
    }
    if (pack) {
        uint j = 1u;
        pack_split(pack, b->nodes[bn].child[0], b->nodes[bn].child[1], (uint)width, &j);
        pack_kids(b, pack, b->nodes[bn].child[0], j, kids, &n);
        pack_kids(b, pack, b->nodes[bn].child[1], (uint)width - j, kids, &n);
        return n;
    }
    kids[n++] = b->nodes[bn].child[0];
    kids[n++] = b->nodes[bn].child[1];
    while (n < width) {
        int pick = -1;
        double pick_area = -1.0;
        for (int i = 0; i < n; i++) {
            const BinNode *c = &b->nodes[kids[i]];
            if (c->count > 0) continue;
            double a = box3_half_area(&c->box);
            if (a > pick_area) {
                pick_area = a;
                pick = i;
            }
        }
        if (pick < 0) break;
        uint c = kids[pick];
        kids[pick] = b->nodes[c].child[0];
        kids[n++] = b->nodes[c].child[1];
    }
    return n;
}

/* Writes wide node `me` for binary node bn and, depth first, the nodes below it;
 * `pending` children are left behind on the walk's stack above it. */
static void flat_node(Flat *f, uint bn, uint me, uint depth, uint pending)
{
    BvhBuild *b = f->b;
    BvhNode *w = &f->out->nodes[me];
    if (depth > f->out->stats.max_depth) f->out->stats.max_depth = depth;
    uint kids[BVH_WIDTH];
    int width = pending + (BVH_WIDTH - 1u) + f->depth_bound <= b->budget ? (int)BVH_WIDTH : 2;
    int n = b->n ? wide_children(b, f->pack, bn, width, kids) : 0;
    if (n > 1) pending += (uint)n - 1u;
    if (pending > f->max_pending) f->max_pending = pending;
    for (uint i = 0; i < BVH_WIDTH; i++) {
        for (int k = 0; k < 3; k++) {
            w->box[2 * k][i] = INFINITY;
            w->box[2 * k + 1][i] = -INFINITY;
        }
        w->ref[i] = 0u;
        w->kind[i] = BVH_CHILD_NONE;
    }
    uint interior[BVH_WIDTH];
    int n_interior = 0;
    for (int i = 0; i < n; i++) {
        const BinNode *c = &b->nodes[kids[i]];
        for (int k = 0; k < 3; k++) {
            w->box[2 * k][i] = c->box.lo[k];
            w->box[2 * k + 1][i] = c->box.hi[k];
        }
        if (c->count > 0 && one_per_leaf(b)) {
            w->kind[i] = BVH_CHILD_INSTANCE;
            w->ref[i] = b->ref[c->first].gid;
        } else if (c->count > 0) {
            w->ref[i] = (uint)f->words;
            f->slots[f->n_slots++] = (LeafSlot){ me, (uint)i, kids[i], (uint)f->words };
            f->words += f->node_words[kids[i]];
        } else {
            w->kind[i] = BVH_CHILD_NODE;
            w->ref[i] = f->out->n_nodes++;
            interior[n_interior++] = (uint)i;
        }
    }
    for (int j = 0; j < n_interior; j++) {
        uint i = interior[j];
        uint kid = kids[i];
        flat_node(f, kid, w->ref[i], depth + 1, pending);
        w = &f->out->nodes[me];
    }
}

/* Fewer binary nodes or leaves than this are measured or written on one thread. */
#define BVH_COLLAPSE_PASS_MIN 2048u

/* Binary nodes [first, end): each leaf's ids sorted, its record's words, their sum. */
typedef struct { Flat *f; uint first, end; size_t words; } MeasureJob;

static void *leaves_measure(void *arg)
{
    MeasureJob *j = arg;
    const BvhBuild *b = j->f->b;
    j->words = 0;
    for (uint i = j->first; i < j->end; i++) {
        const BinNode *c = &b->nodes[i];
        if (c->count == 0 || one_per_leaf(b)) continue;
        uint *ids = j->f->ids + c->first;
        for (uint k = 0; k < c->count; k++) ids[k] = b->ref[c->first + k].gid;
        qsort(ids, c->count, sizeof *ids, uint_cmp);
        j->f->node_words[i] = (uint)kd_leaf_record_words(b->in, ids, c->count);
        j->words += j->f->node_words[i];
    }
    return NULL;
}

/* Slots [first, end): their records written, their kinds set. */
typedef struct { Flat *f; size_t first, end; } WriteJob;

static void *slots_write(void *arg)
{
    const WriteJob *j = arg;
    const Flat *f = j->f;
    for (size_t i = j->first; i < j->end; i++) {
        LeafSlot s = f->slots[i];
        const BinNode *c = &f->b->nodes[s.bin];
        f->out->nodes[s.node].kind[s.lane] =
            kd_leaf_record_write(f->b->in, f->ids + c->first, c->count, f->out->leaf_prims + s.words);
    }
    return NULL;
}

/* The wide nodes and leaf records of the binary tree under root. */
Status bvh_collapse(BvhBuild *b, uint root, Bvh *out, Error *err)
{
    uint n_bin = atomic_load(&b->n_nodes);
    Flat f = { b, out, malloc((b->n + 1) * sizeof(uint)), malloc(((size_t)n_bin + 1) * sizeof(uint)),
               malloc((b->n + 1) * sizeof(LeafSlot)), 0, 0, 0,
               one_per_leaf(b) ? out->stats.max_binary_depth : BVH_MAX_DEPTH, NULL };
    Status st = ST_OK;
    if (one_per_leaf(b) && b->n) f.pack = malloc(((size_t)n_bin + 1) * BVH_WIDTH * sizeof *f.pack);
    if (!f.ids || !f.node_words || !f.slots || (one_per_leaf(b) && b->n && !f.pack)) {
        st = error_set(err, ST_INTERNAL, "BVH: out of memory for %u primitives", b->n);
        goto done;
    }
    if (f.pack) pack_measure(b, f.pack, root, fmax(box3_half_area(&b->nodes[root].box), 1e-300));
    int n_jobs = jobs_threads(b->threads, n_bin, BVH_COLLAPSE_PASS_MIN);
    MeasureJob measure[JOBS_MAX];
    for (int i = 0; i < n_jobs; i++)
        measure[i] = (MeasureJob){ &f, (uint)((uint64_t)n_bin * (uint)i / (uint)n_jobs),
                                   (uint)((uint64_t)n_bin * (uint)(i + 1) / (uint)n_jobs), 0 };
    jobs_run(leaves_measure, measure, sizeof *measure, n_jobs);
    size_t words = 0;
    for (int i = 0; i < n_jobs; i++) words += measure[i].words;
    /* every wide node but the root stands for a binary interior node */
    size_t max_nodes = (size_t)n_bin + 1;
    /* the walk's stack keeps a node index in 29 bits */
    if (words > UINT32_MAX - 1 || max_nodes > (1u << 29)) {
        st = error_set(err, ST_INTERNAL, "BVH: %zu nodes and %zu words of leaf data do not fit its layout", max_nodes,
                       words);
        goto done;
    }
    /* the walk reads both at random: on huge pages when large (base/pages.h) */
    out->nodes = pages_alloc_large(max_nodes * sizeof *out->nodes);
    out->leaf_prims = pages_alloc_large((words + 1) * sizeof *out->leaf_prims);
    if (!out->nodes || !out->leaf_prims) {
        st = error_set(err, ST_INTERNAL, "BVH: out of memory for %zu nodes", max_nodes);
        goto done;
    }
    out->n_nodes = 1;
    flat_node(&f, root, 0u, 1u, 0u);
    n_jobs = jobs_threads(b->threads, f.n_slots, BVH_COLLAPSE_PASS_MIN);
    WriteJob write[JOBS_MAX];
    for (int i = 0; i < n_jobs; i++)
        write[i] = (WriteJob){ &f, f.n_slots * (size_t)i / (size_t)n_jobs, f.n_slots * (size_t)(i + 1) / (size_t)n_jobs };
    jobs_run(slots_write, write, sizeof *write, n_jobs);
    out->n_leaf_prims = (uint)f.words;
    out->stats.max_stack = f.max_pending;
    if (f.max_pending > b->budget)
        st = error_set(err, ST_INTERNAL, "BVH: a path leaves %u children on the walk's stack, more than its %u",
                       f.max_pending, b->budget);
done:
    free(f.pack);
    free(f.ids);
    free(f.node_words);
    free(f.slots);
    return st;
}
