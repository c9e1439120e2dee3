/*
 * bvh.c — builds the 8-wide BVH of accel/bvh.h.
 *
 * Two passes. First a binary tree, top down, each node split where the surface area
 * heuristic over 32 centroid bins on each axis is lowest (Wald 2007, "On fast
 * construction of SAH-based bounding volume hierarchies"; pbrt-v4's BVHAggregate):
 * what a node costs is one visit plus its leaves' triangle groups, since a leaf tests
 * its triangles eight at a time. Then the collapse: a node takes its two children and,
 * while it has fewer than eight, replaces the interior child with the largest surface
 * area by that child's two children (Embree's BVH8 from a binary build). The wide nodes
 * are written depth first, a parent before its children, the leaves' records into the
 * leaf data in the kd-tree's layout (kd_leaf_record_write).
 */
#include "accel/bvh.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/timer.h"

#define BVH_BINS 32
#define BVH_MAX_DEPTH 40       /* binary levels; a node this deep becomes a leaf */
/* The walk's stack (BVH_STACK, types.h) holds the children a path leaves behind: at
 * most the sum of (children - 1) over the wide nodes above a leaf. Once that sum nears
 * the stack's size, nodes below take two children (one more entry per binary level, of
 * which there are at most BVH_MAX_DEPTH), so no tree can overflow it. */
#define BVH_MAX_LEAF 32u       /* a larger set is split whatever the SAH says */
/* Subtrees of at least this many primitives may be built by another thread. */
#define BVH_TASK_MIN 32768u
/* SAH costs (relative): a binary node's share of a wide node's visit, the test of one
 * group of eight triangles, and that of one other primitive (a sphere, box or surface
 * of revolution, tested alone). */
#define BVH_COST_NODE 1.0
#define BVH_COST_GROUP 0.4
#define BVH_COST_OTHER 0.2

typedef struct { float lo[3], hi[3]; } Box3;

/* A node of the binary tree: a leaf when count > 0 (its primitives are
 * idx[first .. first + count)), else an interior node with two children. */
typedef struct {
    Box3 box;
    uint child[2];
    uint first, count;
} BinNode;

typedef struct {
    const KdInput *in;
    uint n;                    /* primitives in the tree */
    uint *gid;                 /* per primitive: its global id */
    Box3 *box;                 /* per primitive: its bounds */
    float (*cen)[3];           /* per primitive: its bounds' centre */
    uint *idx;                 /* the primitives in tree order */
    uint first_tri, n_tri;     /* the triangles' global ids */
    BinNode *nodes;            /* room for every node: a binary tree of n leaves has 2n - 1 */
    atomic_uint n_nodes;
    atomic_int spare_threads;  /* threads that may still be started */
} Build;

static Box3 box3_empty(void)
{
    Box3 b = { { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    return b;
}

static void box3_grow(Box3 *b, const Box3 *a)
{
    for (int k = 0; k < 3; k++) {
        if (a->lo[k] < b->lo[k]) b->lo[k] = a->lo[k];
        if (a->hi[k] > b->hi[k]) b->hi[k] = a->hi[k];
    }
}

static double box3_half_area(const Box3 *b)
{
    double dx = (double)b->hi[0] - b->lo[0], dy = (double)b->hi[1] - b->lo[1], dz = (double)b->hi[2] - b->lo[2];
    if (!(dx >= 0.0 && dy >= 0.0 && dz >= 0.0)) return 0.0;
    return dx * dy + dy * dz + dz * dx;
}

/* Primitives of a set: triangles (tested in groups of eight) and the others. */
typedef struct { uint tri, other; } Count;

static double groups_of(uint n) { return (double)((n + 7u) / 8u); }

/* What testing a leaf of these primitives costs. */
static double leaf_tests(Count c) { return BVH_COST_GROUP * groups_of(c.tri) + BVH_COST_OTHER * c.other; }

static int is_tri(const Build *b, uint p) { return b->gid[p] - b->first_tri < b->n_tri; }

static void count_add(Count *c, Count a)
{
    c->tri += a.tri;
    c->other += a.other;
}

static uint node_new(Build *b) { return atomic_fetch_add(&b->n_nodes, 1u); }

/* One more thread for a subtree, if one is spare. */
static int thread_take(Build *b)
{
    int v = atomic_load(&b->spare_threads);
    while (v > 0)
        if (atomic_compare_exchange_weak(&b->spare_threads, &v, v - 1)) return 1;
    return 0;
}

typedef struct { int axis, bin; double cost; } BinSplit;

/* The bin of centre coordinate c on an axis whose centres start at lo, `scale` bins per
 * unit: clamped as a float before it becomes an int, because a subnormal extent makes
 * scale infinite (and c - lo = 0 then gives NaN), and converting either to int is
 * undefined (the scene fuzzer found it with a quad 81e-45 thick). best_split and the
 * partition share it, so that the two sides are exactly what the cost counted. */
static int bin_of(float c, float lo, float scale)
{
    float f = (c - lo) * scale;
    return f > 0.0f ? (f < (float)BVH_BINS ? (int)f : BVH_BINS - 1) : 0;
}

/* The cheapest of the 31 bin boundaries on each axis for idx[first .. first + n),
 * whose centres span cb; cost +inf when every centre is the same point. */
static BinSplit best_split(const Build *b, uint first, uint n, const Box3 *cb)
{
    BinSplit best = { -1, 0, INFINITY };
    for (int k = 0; k < 3; k++) {
        float ext = cb->hi[k] - cb->lo[k];
        if (!(ext > 0.0f)) continue;
        float scale = (float)BVH_BINS / ext;
        Box3 bin_box[BVH_BINS];
        Count bin_n[BVH_BINS];
        memset(bin_n, 0, sizeof bin_n);
        for (int i = 0; i < BVH_BINS; i++) bin_box[i] = box3_empty();
        for (uint i = first; i < first + n; i++) {
            uint p = b->idx[i];
            int bi = bin_of(b->cen[p][k], cb->lo[k], scale);
            if (is_tri(b, p)) bin_n[bi].tri++;
            else bin_n[bi].other++;
            box3_grow(&bin_box[bi], &b->box[p]);
        }
        /* areas and counts to the right of each boundary, then a sweep from the left */
        double right_area[BVH_BINS];
        Count right_n[BVH_BINS];
        Box3 acc = box3_empty();
        Count cnt = { 0, 0 };
        for (int i = BVH_BINS - 1; i > 0; i--) {
            box3_grow(&acc, &bin_box[i]);
            count_add(&cnt, bin_n[i]);
            right_area[i] = box3_half_area(&acc);
            right_n[i] = cnt;
        }
        acc = box3_empty();
        cnt = (Count){ 0, 0 };
        for (int i = 0; i < BVH_BINS - 1; i++) {
            box3_grow(&acc, &bin_box[i]);
            count_add(&cnt, bin_n[i]);
            Count r = right_n[i + 1];
            if (cnt.tri + cnt.other == 0 || r.tri + r.other == 0) continue;
            double c = box3_half_area(&acc) * leaf_tests(cnt) + right_area[i + 1] * leaf_tests(r);
            if (c < best.cost) {
                best.cost = c;
                best.axis = k;
                best.bin = i;
            }
        }
    }
    return best;
}

typedef struct {
    Build *b;
    uint first, n;
    int depth;
    uint node;
} Task;

static uint build_node(Build *b, uint first, uint n, int depth);

static void *task_run(void *arg)
{
    Task *t = arg;
    t->node = build_node(t->b, t->first, t->n, t->depth);
    return NULL;
}

/* Builds the subtree of idx[first .. first + n) at binary depth `depth`; returns its
 * node. The split depends on the primitives alone, so the tree is the same whichever
 * threads built which subtree (only the binary nodes' numbering differs, and the wide
 * nodes are numbered by walking the tree). */
static uint build_node(Build *b, uint first, uint n, int depth)
{
    uint me = node_new(b);
    Box3 box = box3_empty(), cb = box3_empty();
    Count count = { 0, 0 };
    for (uint i = first; i < first + n; i++) {
        uint p = b->idx[i];
        if (is_tri(b, p)) count.tri++;
        else count.other++;
        box3_grow(&box, &b->box[p]);
        Box3 c = { { b->cen[p][0], b->cen[p][1], b->cen[p][2] }, { b->cen[p][0], b->cen[p][1], b->cen[p][2] } };
        box3_grow(&cb, &c);
    }
    b->nodes[me].box = box;
    double area = box3_half_area(&box);
    BinSplit s = n > 1 && depth < BVH_MAX_DEPTH ? best_split(b, first, n, &cb)
                                                : (BinSplit){ -1, 0, INFINITY };
    double leaf_cost = leaf_tests(count) * area;
    double split_cost = BVH_COST_NODE * area + s.cost;
    if (s.axis < 0 || (n <= BVH_MAX_LEAF && leaf_cost <= split_cost)) {
        b->nodes[me].first = first;
        b->nodes[me].count = n;
        b->nodes[me].child[0] = b->nodes[me].child[1] = NO_INDEX;
        return me;
    }
    /* partition by the chosen bin boundary (the binning's own bin_of) */
    int k = s.axis;
    float scale = (float)BVH_BINS / (cb.hi[k] - cb.lo[k]);
    uint lo = first, hi = first + n;
    while (lo < hi) {
        uint p = b->idx[lo];
        int bi = bin_of(b->cen[p][k], cb.lo[k], scale);
        if (bi <= s.bin) {
            lo++;
        } else {
            b->idx[lo] = b->idx[--hi];
            b->idx[hi] = p;
        }
    }
    uint nl = lo - first;
    b->nodes[me].count = 0;
    Task left = { b, first, nl, depth + 1, NO_INDEX };
    pthread_t tid;
    int spawned = nl >= BVH_TASK_MIN && n - nl >= BVH_TASK_MIN && thread_take(b);
    if (spawned && pthread_create(&tid, NULL, task_run, &left) != 0) {
        atomic_fetch_add(&b->spare_threads, 1);
        spawned = 0;
    }
    if (!spawned) task_run(&left);
    uint r = build_node(b, lo, n - nl, depth + 1);
    if (spawned) {
        pthread_join(tid, NULL);
        atomic_fetch_add(&b->spare_threads, 1);
    }
    b->nodes[me].child[0] = left.node;
    b->nodes[me].child[1] = r;
    return me;
}

/* The binary tree's leaves, deepest leaf and SAH cost (relative to the root's area). */
static void tree_stats(const Build *b, uint root, BvhStats *st)
{
    uint stack[BVH_MAX_DEPTH + 2], depth[BVH_MAX_DEPTH + 2];
    int sp = 0;
    double sah = 0.0;
    stack[sp] = root;
    depth[sp++] = 0;
    while (sp) {
        sp--;
        const BinNode *c = &b->nodes[stack[sp]];
        uint d = depth[sp];
        double area = box3_half_area(&c->box);
        if (c->count > 0 || c->child[0] == NO_INDEX) {
            st->n_leaves++;
            Count cnt = { 0, 0 };
            for (uint i = c->first; i < c->first + c->count; i++) {
                if (is_tri(b, b->idx[i])) cnt.tri++;
                else cnt.other++;
            }
            sah += leaf_tests(cnt) * area;
            if (d > st->max_binary_depth) st->max_binary_depth = d;
            continue;
        }
        sah += BVH_COST_NODE * area;
        for (int k = 0; k < 2; k++) {
            stack[sp] = c->child[k];
            depth[sp++] = d + 1;
        }
    }
    double root_area = box3_half_area(&b->nodes[root].box);
    st->sah_cost = root_area > 0.0 ? sah / root_area : 0.0;
}

/* ------------------------------------------------------------------ collapse */

typedef struct {
    Build *b;
    Bvh *out;
    uint *ids;              /* a leaf's sorted global ids, scratch */
    size_t words;
    uint max_pending;       /* the deepest the walk's stack can get */
} Flat;

static int uint_cmp(const void *a, const void *b)
{
    uint x = *(const uint *)a, y = *(const uint *)b;
    return (x > y) - (x < y);
}

/* Up to `width` binary nodes under binary interior node `bn` (or bn itself when it is
 * a leaf) that become one wide node's children; returns how many. */
static int wide_children(const Build *b, uint bn, int width, uint *kids)
{
    int n = 0;
    if (b->nodes[bn].count > 0 || b->nodes[bn].child[0] == NO_INDEX) {
        kids[n++] = bn;
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
    Build *b = f->b;
    BvhNode *w = &f->out->nodes[me];
    if (depth > f->out->stats.max_depth) f->out->stats.max_depth = depth;
    uint kids[BVH_WIDTH];
    int width = pending + (BVH_WIDTH - 1u) <= BVH_STACK - BVH_MAX_DEPTH ? (int)BVH_WIDTH : 2;
    int n = b->n ? wide_children(b, bn, width, kids) : 0;
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
        if (c->count > 0) {
            for (uint j = 0; j < c->count; j++) f->ids[j] = b->gid[b->idx[c->first + j]];
            qsort(f->ids, c->count, sizeof *f->ids, uint_cmp);
            w->ref[i] = (uint)f->words;
            w->kind[i] = kd_leaf_record_write(b->in, f->ids, c->count, f->out->leaf_prims + f->words);
            f->words += kd_leaf_record_words(b->in, f->ids, c->count);
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

/* Words of leaf data all leaves need. */
static size_t leaf_data_words(Build *b, uint *ids)
{
    size_t words = 0;
    uint n_nodes = atomic_load(&b->n_nodes);
    for (uint i = 0; i < n_nodes; i++) {
        const BinNode *c = &b->nodes[i];
        if (c->count == 0) continue;
        for (uint j = 0; j < c->count; j++) ids[j] = b->gid[b->idx[c->first + j]];
        qsort(ids, c->count, sizeof *ids, uint_cmp);
        words += kd_leaf_record_words(b->in, ids, c->count);
    }
    return words;
}

static void build_free(Build *b)
{
    free(b->gid);
    free(b->box);
    free(b->cen);
    free(b->idx);
    free(b->nodes);
}

/* The primitives with finite bounds: their global ids, bounds and centres. */
static Status gather(Build *b, size_t total, Error *err)
{
    b->gid = malloc((total + 1) * sizeof *b->gid);
    b->box = malloc((total + 1) * sizeof *b->box);
    b->cen = malloc((total + 1) * sizeof *b->cen);
    b->idx = malloc((total + 1) * sizeof *b->idx);
    b->nodes = malloc((2 * total + 1) * sizeof *b->nodes);
    if (!b->gid || !b->box || !b->cen || !b->idx || !b->nodes)
        return error_set(err, ST_INTERNAL, "BVH: out of memory for %zu primitives", total);
    for (uint gid = 0; gid < (uint)total; gid++) {
        Box3 a;
        if (!kd_prim_box(b->in, gid, a.lo, a.hi)) continue;
        b->gid[b->n] = gid;
        b->box[b->n] = a;
        for (int k = 0; k < 3; k++) b->cen[b->n][k] = 0.5f * a.lo[k] + 0.5f * a.hi[k];
        b->idx[b->n] = b->n;
        b->n++;
    }
    return ST_OK;
}

/* The wide nodes and leaf records of the binary tree under root. */
static Status collapse(Build *b, uint root, Bvh *out, Error *err)
{
    uint *ids = malloc((b->n + 1) * sizeof *ids);
    if (!ids) return error_set(err, ST_INTERNAL, "BVH: out of memory for %u primitives", b->n);
    size_t words = leaf_data_words(b, ids);
    /* every wide node but the root stands for a binary interior node */
    size_t max_nodes = (size_t)atomic_load(&b->n_nodes) + 1;
    /* the walk's stack keeps a node index in 29 bits */
    if (words > UINT32_MAX - 1 || max_nodes > (1u << 29)) {
        free(ids);
        return error_set(err, ST_INTERNAL, "BVH: %zu nodes and %zu words of leaf data do not fit its layout", max_nodes, words);
    }
    out->nodes = aligned_alloc(64, max_nodes * sizeof *out->nodes);
    out->leaf_prims = aligned_alloc(64, ((words + 1) * sizeof *out->leaf_prims + 63) / 64 * 64);
    if (!out->nodes || !out->leaf_prims) {
        free(ids);
        return error_set(err, ST_INTERNAL, "BVH: out of memory for %zu nodes", max_nodes);
    }
    Flat f = { b, out, ids, 0, 0 };
    out->n_nodes = 1;
    flat_node(&f, root, 0u, 1u, 0u);
    free(ids);
    out->n_leaf_prims = (uint)f.words;
    out->stats.max_stack = f.max_pending;
    if (f.max_pending > BVH_STACK)
        return error_set(err, ST_INTERNAL, "BVH: a path leaves %u children on the walk's stack, more than its %u",
                         f.max_pending, BVH_STACK);
    return ST_OK;
}

Status bvh_build(const KdInput *in, int threads, Bvh *out, Error *err)
{
    double t0 = timer_now();
    memset(out, 0, sizeof *out);
    size_t total = in->n_spheres + in->n_triangles + in->n_boxes + in->n_revs;
    if (total > KD_MAX_PRIMS)
        return error_set(err, ST_INPUT, "BVH: %zu primitives, more than the %u supported", total, KD_MAX_PRIMS);
    if (threads <= 0) {
        long nc = sysconf(_SC_NPROCESSORS_ONLN);
        threads = nc > 0 ? (int)nc : 1;
    }
    Build b;
    memset(&b, 0, sizeof b);
    b.in = in;
    b.first_tri = (uint)in->n_spheres;
    b.n_tri = (uint)in->n_triangles;
    atomic_init(&b.n_nodes, 0u);
    atomic_init(&b.spare_threads, threads - 1);
    Status st = gather(&b, total, err);
    if (st == ST_OK) {
        out->stats.n_skipped = (uint)(total - b.n);
        uint root = build_node(&b, 0, b.n, 0);
        tree_stats(&b, root, &out->stats);
        if (b.n) {
            const Box3 *rb = &b.nodes[root].box;
            out->lo = (vec3){ rb->lo[0], rb->lo[1], rb->lo[2] };
            out->hi = (vec3){ rb->hi[0], rb->hi[1], rb->hi[2] };
        }
        st = collapse(&b, root, out, err);
    }
    build_free(&b);
    if (st != ST_OK) {
        bvh_free(out);
        return st;
    }
    out->stats.n_nodes = out->n_nodes;
    out->stats.mean_prims_per_leaf = out->stats.n_leaves ? (double)b.n / out->stats.n_leaves : 0.0;
    out->stats.build_seconds = timer_now() - t0;
    return ST_OK;
}

void bvh_free(Bvh *b)
{
    free(b->nodes);
    free(b->leaf_prims);
    b->nodes = NULL;
    b->leaf_prims = NULL;
    b->n_nodes = b->n_leaf_prims = 0;
}
