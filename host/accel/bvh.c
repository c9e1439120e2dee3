/*
 * bvh.c — builds the 8-wide BVH of accel/bvh.h.
 *
 * Two passes. First a binary tree, top down, each node split where the surface area
 * heuristic over 32 centroid bins on each axis is lowest (Wald 2007, "On fast
 * construction of SAH-based bounding volume hierarchies"; pbrt-v4's BVHAggregate):
 * what a node costs is one visit plus its leaves' triangle groups, since a leaf tests
 * its triangles eight at a time. Then the collapse into 8-wide nodes and leaf records
 * (bvh_collapse.c, whose head comment tells how). With several threads, the top of the
 * binary tree is built first, its large nodes' passes cut into ranges, and the
 * subtrees below it by the threads (build_tree); the collapse sorts and writes the
 * leaves on the threads too. The state both files share is accel/bvh_build.h.
 * docs/bvh.md has the measurements behind the choices.
 */
#include "accel/bvh_build.h"

#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/jobs.h"
#include "base/timer.h"

#define BVH_BINS 32
#define BVH_MAX_LEAF 32u       /* a larger set is split whatever the SAH says */
/* The deepest a binary tree gets: BVH_MAX_DEPTH, or in an item build (one item a leaf)
 * that plus the halving of at most 2^32 items that the bins could not split. */
#define BVH_TREE_DEPTH (BVH_MAX_DEPTH + 33)
/* With several threads, the top of the tree is built first, on this thread, and each
 * subtree below it of at most 1 / (BVH_SUBTREES_PER_THREAD threads) of the primitives
 * waits; then the threads take the waiting subtrees, largest first. */
#define BVH_SUBTREES_PER_THREAD 4u
/* Fewer primitives than this are built on one thread: starting threads costs more. */
#define BVH_THREADS_MIN 32768u
/* A node of the top with at least this many primitives bins them on all threads. */
#define BVH_PASS_MIN 65536u
/* SAH costs (relative): a binary node's share of a wide node's visit, the test of one
 * group of eight triangles, and that of one other primitive (a sphere, box or surface
 * of revolution, tested alone). */
#define BVH_COST_NODE 1.0
#define BVH_COST_GROUP 0.4
#define BVH_COST_OTHER 0.2

static Box3 box3_empty(void)
{
    Box3 b = { { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    return b;
}

/* b grown to hold a: each bound replaced where a's is beyond it. Written as selects,
 * which compile to minss / maxss, not as branches: in the binning they mispredicted
 * at random and held half of the build's time. Ties (0 and -0) keep b's. */
static void box3_grow(Box3 *b, const Box3 *a)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = a->lo[k] < b->lo[k] ? a->lo[k] : b->lo[k];
        b->hi[k] = a->hi[k] > b->hi[k] ? a->hi[k] : b->hi[k];
    }
}

/* Primitives of a set: triangles (tested in groups of eight) and the others. */
typedef struct { uint tri, other; } Count;

static double groups_of(uint n) { return (double)((n + 7u) / 8u); }

/* What testing a leaf of these primitives costs. */
static double leaf_tests(Count c) { return BVH_COST_GROUP * groups_of(c.tri) + BVH_COST_OTHER * c.other; }

static int is_tri(const BvhBuild *b, const PrimRef *r) { return !b->opt->item_boxes && r->gid - b->first_tri < b->n_tri; }

/* The centre of a primitive's bounds on axis k: what the bins and the partition sort by. */
static float centre(const PrimRef *r, int k) { return 0.5f * r->box.lo[k] + 0.5f * r->box.hi[k]; }

static void count_add(Count *c, Count a)
{
    c->tri += a.tri;
    c->other += a.other;
}

static uint node_new(BvhBuild *b) { return atomic_fetch_add(&b->n_nodes, 1u); }

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

/* The bins of one range of primitives on the axes that can split (a centre extent
 * above 0). */
typedef struct {
    Box3 box[3][BVH_BINS];
    Count n[3][BVH_BINS];
} Bins;

typedef struct {
    float lo[3], scale[3];  /* bin_of's arguments per axis */
    int axes[3], n_axes;
} BinAxes;

static void bins_clear(Bins *bins)
{
    memset(bins->n, 0, sizeof bins->n);
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < BVH_BINS; i++) bins->box[k][i] = box3_empty();
}

/* ref[first .. first + n) into cleared bins, all axes in one pass. */
static void bins_fill(const BvhBuild *b, uint first, uint n, const BinAxes *ax, Bins *bins)
{
    for (const PrimRef *r = b->ref + first, *end = r + n; r < end; r++) {
        int tri = is_tri(b, r);
        for (int a = 0; a < ax->n_axes; a++) {
            int k = ax->axes[a], bi = bin_of(centre(r, k), ax->lo[k], ax->scale[k]);
            if (tri) bins->n[k][bi].tri++;
            else bins->n[k][bi].other++;
            box3_grow(&bins->box[k][bi], &r->box);
        }
    }
}

/* The bins of the range that follows `into`'s added to it: what one pass over both
 * ranges in order gives (box3_grow keeps the earlier of equal bounds). */
static void bins_merge(Bins *into, const Bins *next, const BinAxes *ax)
{
    for (int a = 0; a < ax->n_axes; a++)
        for (int i = 0, k = ax->axes[a]; i < BVH_BINS; i++) {
            box3_grow(&into->box[k][i], &next->box[k][i]);
            count_add(&into->n[k][i], next->n[k][i]);
        }
}

/* A pass over part of a node's primitives on a thread of its own. */
typedef struct RangeJob {
    const BvhBuild *b;
    uint first, n;
    const BinAxes *ax;     /* binning: the axes; NULL for bounds */
    Bins bins;             /* binning's result */
    Box3 box, cb;          /* bounds' result: of the boxes and of their centres */
    Count count;
} RangeJob;

static void range_bounds(const BvhBuild *b, uint first, uint n, Box3 *box, Box3 *cb, Count *count)
{
    for (const PrimRef *r = b->ref + first, *end = r + n; r < end; r++) {
        if (is_tri(b, r)) count->tri++;
        else count->other++;
        box3_grow(box, &r->box);
        Box3 c = { { centre(r, 0), centre(r, 1), centre(r, 2) }, { centre(r, 0), centre(r, 1), centre(r, 2) } };
        box3_grow(cb, &c);
    }
}

static void *range_run(void *arg)
{
    RangeJob *j = arg;
    if (j->ax) {
        bins_clear(&j->bins);
        bins_fill(j->b, j->first, j->n, j->ax, &j->bins);
    } else {
        j->box = j->cb = box3_empty();
        j->count = (Count){ 0, 0 };
        range_bounds(j->b, j->first, j->n, &j->box, &j->cb, &j->count);
    }
    return NULL;
}

/* ref[first .. first + n) cut into `threads` ranges, each passed over (bounds, or bins
 * with `ax`) on a thread of its own; the results are merged in range order, so they are
 * the bits of one pass. */
static void ranges_run(const BvhBuild *b, uint first, uint n, int threads, const BinAxes *ax, RangeJob *jobs)
{
    for (int i = 0; i < threads; i++) {
        uint lo = (uint)((uint64_t)n * (uint)i / (uint)threads), hi = (uint)((uint64_t)n * (uint)(i + 1) / (uint)threads);
        jobs[i].b = b;
        jobs[i].first = first + lo;
        jobs[i].n = hi - lo;
        jobs[i].ax = ax;
    }
    jobs_run(range_run, jobs, sizeof *jobs, threads);
}

/* The cheapest of the 31 bin boundaries on each axis for ref[first .. first + n),
 * whose centres span cb, binned on `threads` threads; cost +inf when every centre is
 * the same point. */
static BinSplit best_split(const BvhBuild *b, uint first, uint n, const Box3 *cb, int threads, RangeJob *jobs)
{
    BinSplit best = { -1, 0, INFINITY };
    BinAxes ax = { .n_axes = 0 };
    for (int k = 0; k < 3; k++) {
        float ext = cb->hi[k] - cb->lo[k];
        if (!(ext > 0.0f)) continue;
        ax.lo[k] = cb->lo[k];
        ax.scale[k] = (float)BVH_BINS / ext;
        ax.axes[ax.n_axes++] = k;
    }
    if (ax.n_axes == 0) return best;
    Bins one, *bins = &one;
    if (threads > 1) {
        ranges_run(b, first, n, threads, &ax, jobs);
        for (int i = 1; i < threads; i++) bins_merge(&jobs[0].bins, &jobs[i].bins, &ax);
        bins = &jobs[0].bins;
    } else {
        bins_clear(&one);
        bins_fill(b, first, n, &ax, &one);
    }
    for (int a = 0; a < ax.n_axes; a++) {
        int k = ax.axes[a];
        /* areas and counts to the right of each boundary, then a sweep from the left */
        double right_area[BVH_BINS];
        Count right_n[BVH_BINS];
        Box3 acc = box3_empty();
        Count cnt = { 0, 0 };
        for (int i = BVH_BINS - 1; i > 0; i--) {
            box3_grow(&acc, &bins->box[k][i]);
            count_add(&cnt, bins->n[k][i]);
            right_area[i] = box3_half_area(&acc);
            right_n[i] = cnt;
        }
        acc = box3_empty();
        cnt = (Count){ 0, 0 };
        for (int i = 0; i < BVH_BINS - 1; i++) {
            box3_grow(&acc, &bins->box[k][i]);
            count_add(&cnt, bins->n[k][i]);
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

/* A subtree to build: ref[first .. first + n) as node `node`, at binary depth `depth`. */
typedef struct Subtree {
    uint node, first, n;
    int depth;
} Subtree;

static void build_node(BvhBuild *b, Subtree t, int may_wait);

/* Builds subtree t now, or, when may_wait and it is small enough, puts it on the
 * waiting list for the threads. */
static void build_or_wait(BvhBuild *b, Subtree t, int may_wait)
{
    if (!may_wait || t.n > b->defer_at_most) {
        build_node(b, t, may_wait);
        return;
    }
    if (b->n_waiting == b->cap_waiting) {
        size_t cap = b->cap_waiting ? 2 * b->cap_waiting : 8; /* grows in test_kdtree too */
        Subtree *w = realloc(b->waiting, cap * sizeof *w);
        if (!w) {
            build_node(b, t, 0); /* correct, only slower */
            return;
        }
        b->waiting = w;
        b->cap_waiting = cap;
    }
    b->waiting[b->n_waiting++] = t;
}

/* Builds subtree t (its node is numbered already); below the top (may_wait), the
 * subtrees small enough wait (build_or_wait). The split depends on the primitives
 * alone, so the tree is the same whichever threads built which subtree (only the
 * binary nodes' numbering differs, and the wide nodes are numbered by walking the
 * tree). */
static void build_node(BvhBuild *b, Subtree t, int may_wait)
{
    uint me = t.node, first = t.first, n = t.n;
    int depth = t.depth;
    Box3 box = box3_empty(), cb = box3_empty();
    Count count = { 0, 0 };
    /* the top's large nodes: their passes on all threads (the others wait anyway) */
    int threads = may_wait && b->range_jobs ? jobs_threads(b->threads, n, BVH_PASS_MIN) : 1;
    RangeJob *jobs = b->range_jobs;
    if (threads > 1) {
        ranges_run(b, first, n, threads, NULL, jobs);
        for (int i = 0; i < threads; i++) {
            box3_grow(&box, &jobs[i].box);
            box3_grow(&cb, &jobs[i].cb);
            count_add(&count, jobs[i].count);
        }
    } else {
        range_bounds(b, first, n, &box, &cb, &count);
    }
    b->nodes[me].box = box;
    double area = box3_half_area(&box);
    BinSplit s = n > 1 && depth < BVH_MAX_DEPTH ? best_split(b, first, n, &cb, threads, jobs)
                                                : (BinSplit){ -1, 0, INFINITY };
    double leaf_cost = leaf_tests(count) * area;
    double split_cost = BVH_COST_NODE * area + s.cost;
    int median = 0;
    if (one_per_leaf(b) && n > 1) {
        /* items at one point, or past the depth the bins may go: halves in order */
        median = s.axis < 0;
    } else if (s.axis < 0 || (n <= BVH_MAX_LEAF && leaf_cost <= split_cost)) {
        b->nodes[me].first = first;
        b->nodes[me].count = n;
        b->nodes[me].child[0] = b->nodes[me].child[1] = NO_INDEX;
        return;
    }
    /* partition by the chosen bin boundary (the binning's own bin_of) */
    int k = median ? 0 : s.axis;
    float scale = median ? 0.0f : (float)BVH_BINS / (cb.hi[k] - cb.lo[k]);
    uint lo = median ? first + n / 2u : first, hi = first + n;
    while (!median && lo < hi) {
        PrimRef r = b->ref[lo];
        int bi = bin_of(centre(&r, k), cb.lo[k], scale);
        if (bi <= s.bin) {
            lo++;
        } else {
            b->ref[lo] = b->ref[--hi];
            b->ref[hi] = r;
        }
    }
    uint nl = lo - first;
    uint left = node_new(b), right = node_new(b);
    b->nodes[me].count = 0;
    b->nodes[me].child[0] = left;
    b->nodes[me].child[1] = right;
    build_or_wait(b, (Subtree){ left, first, nl, depth + 1 }, may_wait);
    build_or_wait(b, (Subtree){ right, lo, n - nl, depth + 1 }, may_wait);
}

/* Larger subtrees first: the last to start are the shortest. */
static int subtree_larger(const void *a, const void *b)
{
    const Subtree *x = a, *y = b;
    if (x->n != y->n) return x->n < y->n ? 1 : -1;
    return (x->first > y->first) - (x->first < y->first);
}

/* One thread's share of the waiting subtrees: the next one until none is left. */
static void *waiting_run(void *arg)
{
    BvhBuild *b = *(BvhBuild **)arg;
    for (size_t i; (i = atomic_fetch_add(&b->next_waiting, 1)) < b->n_waiting;) build_node(b, b->waiting[i], 0);
    return NULL;
}

/* The binary tree of all b->n primitives on b->threads threads; returns its root. */
static uint build_tree(BvhBuild *b)
{
    uint root = node_new(b);
    int threads = b->threads;
    /* the top's passes run on the threads from BVH_PASS_MIN primitives; without
     * memory for them, on this thread (the same tree) */
    if (threads > 1 && b->n >= BVH_PASS_MIN) b->range_jobs = malloc((size_t)threads * sizeof *b->range_jobs);
    b->defer_at_most = threads > 1 ? b->n / (BVH_SUBTREES_PER_THREAD * (uint)threads) : 0u;
    build_node(b, (Subtree){ root, 0u, b->n, 0 }, threads > 1);
    if (b->n_waiting == 0) return root;
    qsort(b->waiting, b->n_waiting, sizeof *b->waiting, subtree_larger);
    int n_jobs = (size_t)threads < b->n_waiting ? threads : (int)b->n_waiting;
    BvhBuild *jobs[JOBS_MAX];
    for (int i = 0; i < n_jobs; i++) jobs[i] = b;
    jobs_run(waiting_run, jobs, sizeof *jobs, n_jobs);
    return root;
}

/* The binary tree's leaves, deepest leaf and SAH cost (relative to the root's area). */
static void tree_stats(const BvhBuild *b, uint root, BvhStats *st)
{
    uint stack[BVH_TREE_DEPTH + 2], depth[BVH_TREE_DEPTH + 2];
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
                if (is_tri(b, &b->ref[i])) cnt.tri++;
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

static void build_free(BvhBuild *b)
{
    free(b->ref);
    free(b->nodes);
    free(b->waiting);
    free(b->range_jobs);
}

/* The record of gid (a primitive, or in an item build an item's box) when its bounds
 * are finite and not empty. */
static int prim_ref(const BvhBuild *b, uint gid, PrimRef *r)
{
    Box3 a;
    if (one_per_leaf(b)) {
        const float *q = b->opt->item_boxes + 6u * (size_t)gid;
        for (int k = 0; k < 3; k++) {
            a.lo[k] = q[k];
            a.hi[k] = q[3 + k];
            if (!(isfinite(a.lo[k]) && isfinite(a.hi[k]) && a.lo[k] <= a.hi[k])) return 0;
        }
    } else if (!kd_prim_box(b->in, gid, a.lo, a.hi)) {
        return 0;
    }
    *r = (PrimRef){ a, gid, 0u };
    return 1;
}

/* The primitives with finite bounds (of in's ranges, when it has them): their records,
 * in global id order. */
static Status gather(BvhBuild *b, size_t total, Error *err)
{
    b->ref = malloc((total + 1) * sizeof *b->ref);
    b->nodes = malloc((2 * total + 1) * sizeof *b->nodes);
    if (!b->ref || !b->nodes)
        return error_set(err, ST_INTERNAL, "BVH: out of memory for %zu primitives", total);
    /* one thread: on several, the dragon's 0.05 s did not shorten (first touches of
     * the new memory, not the boxes, take the time) */
    size_t n_ranges = one_per_leaf(b) ? 0 : b->in->n_ranges;
    KdRange all = { 0u, (uint)total };
    const KdRange *ranges = n_ranges ? b->in->ranges : &all;
    for (size_t i = 0; i < (n_ranges ? n_ranges : 1u); i++)
        for (uint gid = ranges[i].lo; gid < ranges[i].hi; gid++)
            if (prim_ref(b, gid, &b->ref[b->n])) b->n++;
    return ST_OK;
}

Status bvh_build(const KdInput *in, int threads, Bvh *out, Error *err)
{
    BvhOptions opt = { 0u, NULL, 0u };
    return bvh_build_with(in, &opt, threads, out, err);
}

/* The number of primitives (or items) a build takes, before any is left out. */
static size_t build_total(const KdInput *in, const BvhOptions *opt)
{
    if (opt->item_boxes) return opt->n_items;
    if (in->n_ranges == 0) return in->n_spheres + in->n_triangles + in->n_boxes + in->n_revs;
    size_t total = 0;
    for (size_t i = 0; i < in->n_ranges; i++) total += in->ranges[i].hi - in->ranges[i].lo;
    return total;
}

Status bvh_build_with(const KdInput *in, const BvhOptions *opt, int threads, Bvh *out, Error *err)
{
    double t0 = timer_now();
    memset(out, 0, sizeof *out);
    size_t total = build_total(in, opt);
    if (total > KD_MAX_PRIMS)
        return error_set(err, ST_INPUT, "BVH: %zu primitives, more than the %u supported", total, KD_MAX_PRIMS);
    if (threads <= 0) {
        long nc = sysconf(_SC_NPROCESSORS_ONLN);
        threads = nc > 0 ? (int)nc : 1;
    }
    BvhBuild b;
    memset(&b, 0, sizeof b);
    b.in = in;
    b.opt = opt;
    b.budget = opt->stack_budget ? opt->stack_budget : BVH_STACK;
    b.first_tri = (uint)in->n_spheres;
    b.n_tri = (uint)in->n_triangles;
    atomic_init(&b.n_nodes, 0u);
    atomic_init(&b.next_waiting, 0);
    b.threads = jobs_threads(threads, total, BVH_THREADS_MIN);
    Status st = gather(&b, total, err);
    if (st == ST_OK) {
        out->stats.n_skipped = (uint)(total - b.n);
        uint root = build_tree(&b);
        tree_stats(&b, root, &out->stats);
        if (b.n) {
            const Box3 *rb = &b.nodes[root].box;
            out->lo = (vec3){ rb->lo[0], rb->lo[1], rb->lo[2] };
            out->hi = (vec3){ rb->hi[0], rb->hi[1], rb->hi[2] };
        }
        st = bvh_collapse(&b, root, out, err);
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

/* Alike kd_free by design: each tree owns a node array of its own node type and a
 * leaf list; a shared helper would need a common struct for two layouts the kernels
 * read differently. */
void bvh_free(Bvh *b)
{
    free(b->nodes);
    free(b->leaf_prims);
    free(b->top);
    b->nodes = NULL;
    b->leaf_prims = NULL;
    b->top = NULL;
    b->n_nodes = b->n_leaf_prims = b->n_top = 0;
}
