/*
 * kdtree.c -- the kd-tree build: exact SAH over every candidate plane, in O(N log N).
 *
 * Wald & Havran, "On building fast kd-trees for ray tracing, and on doing that in
 * O(N log N)" (IEEE RT 2006). Each primitive's box in a node gives, per axis, a start
 * and an end event (or one planar event when the box is flat there). The events of
 * each axis are sorted once, at the root; a node sweeps its three sorted lists to cost
 * every plane, and splitting a node splits its lists into the children's lists in
 * order. Primitives that straddle the split are clipped to each child ("perfect
 * splits": triangles by Sutherland-Hodgman against the child box, spheres and boxes by
 * their bounding box) and only their few new events are sorted and merged in.
 *
 * Event lists live in a per-thread stack ("arena") of 64-bit keys: a node's lists are
 * always at the top; its children's lists are written above and then moved down over
 * it, the child to visit first on top. Build nodes and leaf ids go to per-thread pools
 * that can be rolled back, which is how a non-improving split that did not pay off is
 * retracted. Large subtrees become tasks for the other threads; the tree is flattened
 * afterwards in depth-first order, so the result does not depend on the thread count.
 * Constants and layout: docs/kdtree.md.
 */
#include "accel/kd_build.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/array.h"
#include "base/jobs.h"
#include "base/pages.h"
#include "base/timer.h"
#include "scene/scene.h"

/* reserve_*(&array, &capacity, need): array_reserve (scene.h: doubling, overflow
 * checked) with the element type checked; 0 on success, -1 when out of memory (the
 * array is then unchanged). */
#define DEFINE_RESERVE(name, T)                                                        \
    static int name(T **ptr, size_t *cap, size_t need)                                 \
    {                                                                                  \
        return array_reserve((void **)ptr, cap, need, sizeof **ptr);                   \
    }

DEFINE_RESERVE(reserve_events, Event)
DEFINE_RESERVE(reserve_uints, uint)
DEFINE_RESERVE(reserve_tasks, Task)

static void worker_free(Worker *w)
{
    free(w->side);
    free(w->arena);
    free(w->fresh);
    free(w->sort_tmp);
    free(w->radix_count);
    free(w->both);
    free(w->saved);
    pool_release(&w->nodes, (PoolMark){ NULL, 0 });
    pool_release(&w->ids, (PoolMark){ NULL, 0 });
}

/* The root's sweep and list split take as long as a whole level of nodes below it, and
 * the other threads would only wait for work meanwhile: at the root, the three axes run
 * side by side (each axis's work is independent, and the result is the same bits). */
typedef struct { void (*fn)(void *ctx, int axis); void *ctx; } AxisCall;

static void *axis_zero(void *arg)
{
    AxisCall *c = arg;
    c->fn(c->ctx, 0);
    return NULL;
}

/* fn(ctx, k) for the three axes; with `parallel`, axis 0 on a thread of its own. */
static void for_each_axis(void (*fn)(void *ctx, int axis), void *ctx, int parallel)
{
    AxisCall c = { fn, ctx };
    pthread_t tid;
    int started = parallel && pthread_create(&tid, NULL, axis_zero, &c) == 0;
    if (!started) fn(ctx, 0);
    fn(ctx, 1);
    fn(ctx, 2);
    if (started) pthread_join(tid, NULL);
}

/* Whether a node's axes run side by side: only the root's, and only when there are
 * threads to spare. */
static int axes_in_parallel(const Worker *w, int depth)
{
    return depth == 0 && w->b->threads > 1;
}

/* ------------------------------------------------------------------ SAH sweep */

typedef struct {
    int axis;                   /* -1: no candidate plane */
    float pos;
    int planar_left;            /* primitives lying in the plane go left */
    double cost;                /* in units of SA(node): comparable with the leaf's */
} Split;

static double sah_split_cost(double sa_l, double sa_r, uint nl, uint nr)
{
    double c = KD_COST_TRAVERSAL + sa_l * kd_leaf_cost(nl) + sa_r * kd_leaf_cost(nr);
    return c * ((nl == 0 || nr == 0) ? KD_EMPTY_BONUS : 1.0);
}

/* Costs every plane of axis k strictly inside the node (a plane on the boundary would
 * only cut off a flat, empty cell); keeps the best in *best. */
static void sweep_axis(const Event *e, uint n, uint nprims, int k, const Aabb *box,
                       double inv_sa, Split *best)
{
    int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    double lo = box->lo[k], hi = box->hi[k];
    double a = (double)box->hi[k1] - box->lo[k1], b = (double)box->hi[k2] - box->lo[k2];
    double side = (a + b) * inv_sa, cap = a * b * inv_sa;
    /* One event at a time, without branching on the event type: the plane at a
     * position is costed once its last event (ends, then planar, then starts) has
     * been counted; nl and nr then count the primitives reaching into the left and
     * the right side (one that straddles the plane in both), and `planar` those
     * lying in it. Every event is costed, and the cost used
     * only at the last event of a position, since mispredicted branches would cost
     * more than the arithmetic. */
    uint nl = 0, nr = nprims, planar = 0, starts = 0;
    for (uint i = 0; i < n; i++) {
        uint t = event_type(e[i]);
        uint32_t pk = event_pos(e[i]);
        nr -= (t != EV_START);
        planar += (t == EV_PLANAR);
        starts += (t == EV_START);
        int last = i + 1 == n || event_pos(e[i + 1]) != pk;
        double p = key_float(pk);
        double sa_l = (p - lo) * side + cap, sa_r = (hi - p) * side + cap;
        /* Without primitives in the plane (a branch that is almost always taken the
         * same way) both sides cost the same and the plane's go left, as below. */
        double cl = sah_split_cost(sa_l, sa_r, nl + planar, nr), cr = cl;
        if (planar) cr = sah_split_cost(sa_l, sa_r, nl, nr + planar);
        double c = cl <= cr ? cl : cr;
        if (last && p > lo && p < hi && c < best->cost) {
            best->cost = c;
            best->axis = k;
            best->pos = (float)p;
            best->planar_left = cl <= cr;
        }
        nl += last ? starts + planar : 0;
        starts = last ? 0 : starts;
        planar = last ? 0 : planar;
    }
}

/* ------------------------------------------------------------------ the recursion */

typedef struct {
    size_t off;                 /* lists in the arena: axis 0, 1, 2 back to back */
    uint n[3];
    uint nprims;
    Aabb box;
} NodeLists;

/* The node's global ids in increasing order (neighbouring leaves then read the
 * primitive arrays in a similar order). */
static void collect_ids(const Worker *w, const NodeLists *nl, uint *ids)
{
    const Event *e = w->arena + nl->off;
    uint m = 0;
    for (uint i = 0; i < nl->n[0]; i++)
        if (event_type(e[i]) != EV_END) ids[m++] = w->b->gid[event_prim(e[i])];
    kd_ids_sort(ids, m);
}

static int make_leaf(Worker *w, const NodeLists *nl, BNode *node)
{
    node->axis = KD_LEAF;
    node->count = nl->nprims;
    node->ids = NULL;
    node->id = 0;
    node->child[0] = node->child[1] = NULL;
    if (nl->nprims == 0) return 0;
    uint *ids = nl->nprims == 1 ? &node->id : pool_alloc(&w->ids, nl->nprims * sizeof *ids);
    if (!ids) return -1;
    collect_ids(w, nl, ids);
    if (nl->nprims > 1) node->ids = ids;
    return 0;
}

/* Leaf from ids saved before a tentative split. */
static int make_leaf_from(Worker *w, const uint *ids, uint count, BNode *node)
{
    node->axis = KD_LEAF;
    node->count = count;
    node->ids = NULL;
    node->id = count == 1 ? ids[0] : 0;
    node->child[0] = node->child[1] = NULL;
    if (count > 1) {
        node->ids = pool_alloc(&w->ids, count * sizeof *node->ids);
        if (!node->ids) return -1;
        memcpy(node->ids, ids, count * sizeof *node->ids);
    }
    return 0;
}

/* The straddling primitives' new events: per child (left, right) and axis, a sorted list
 * of up to 2 events per straddling primitive. */
typedef struct { Event *list[2][3]; size_t n[2][3]; } FreshLists;

/* Sets each primitive's side of split s in w->side, counts those wholly on each side in
 * n_side[2] and lists the straddling ones in w->both; returns how many straddle, or -1
 * when memory runs out. */
static long classify_sides(Worker *w, const NodeLists *nl, const Split *s, uint n_side[2])
{
    int k = s->axis;
    uint32_t pk = float_key(s->pos + 0.0f);
    uint8_t *side = w->side;

    /* By the events of the split axis; a primitive's start precedes its end. */
    const Event *ek = w->arena + nl->off + (k > 0 ? nl->n[0] : 0) + (k > 1 ? nl->n[1] : 0);
    uint8_t in_plane = s->planar_left ? SIDE_LEFT : SIDE_RIGHT;
    for (uint i = 0; i < nl->n[k]; i++) {
        Event e = ek[i];
        uint p = event_prim(e), t = event_type(e);
        uint32_t pos = event_pos(e);
        uint8_t at_start = pos >= pk ? SIDE_RIGHT : SIDE_BOTH;
        uint8_t at_end = pos <= pk ? SIDE_LEFT : side[p];
        uint8_t planar = pos < pk ? SIDE_LEFT : pos > pk ? SIDE_RIGHT : in_plane;
        side[p] = t == EV_START ? at_start : t == EV_END ? at_end : planar;
    }
    uint n_left = 0, n_right = 0, n_both = 0;
    if (reserve_uints(&w->both, &w->both_cap, nl->nprims + 1)) return -1;
    for (uint i = 0; i < nl->n[k]; i++) {
        Event e = ek[i];
        uint p = event_prim(e), counted = event_type(e) != EV_END;
        uint8_t sd = side[p];
        n_left += counted & (sd == SIDE_LEFT);
        n_right += counted & (sd == SIDE_RIGHT);
        w->both[n_both] = p;
        n_both += counted & (sd == SIDE_BOTH);
    }
    n_side[0] = n_left;
    n_side[1] = n_right;
    return n_both;
}

/* Clips the n_both straddling primitives to each child's box and gives each child
 * their events, sorted; one that reaches into a child is counted in n_side there. */
static int clip_straddlers(Worker *w, uint n_both, const Aabb child[2], uint n_side[2], FreshLists *f)
{
    const Build *b = w->b;
    if (reserve_events(&w->fresh, &w->fresh_cap, (size_t)12 * n_both + 1)) return -1;
    for (int c = 0; c < 2; c++)
        for (int j = 0; j < 3; j++) {
            f->list[c][j] = w->fresh + (size_t)(c * 3 + j) * 2 * n_both;
            f->n[c][j] = 0;
        }
    for (uint i = 0; i < n_both; i++) {
        uint p = w->both[i];
        for (int c = 0; c < 2; c++) {
            Aabb clipped = b->bounds[p];
            int inside = b->tri[p] != NO_INDEX ? kd_clip_triangle(&b->triangles[b->tri[p]], &child[c], &clipped)
                                               : kd_box_intersect(&clipped, &child[c]);
            if (!inside) continue;
            n_side[c]++;
            for (int j = 0; j < 3; j++)
                f->n[c][j] += kd_events_emit(f->list[c][j] + f->n[c][j], &clipped, j, p);
        }
    }
    size_t most = 0;
    for (int c = 0; c < 2; c++)
        for (int j = 0; j < 3; j++) most = f->n[c][j] > most ? f->n[c][j] : most;
    if (reserve_events(&w->sort_tmp, &w->sort_tmp_cap, most + 1)) return -1;
    for (int c = 0; c < 2; c++)
        for (int j = 0; j < 3; j++) kd_events_sort(f->list[c][j], w->sort_tmp, w->radix_count, f->n[c][j]);
    return 0;
}

/* One axis of children_write. */
typedef struct {
    const Worker *w;
    const NodeLists *nl;
    const FreshLists *f;
    size_t (*start)[3], (*count)[3];
} ChildrenWrite;

static void children_write_axis(void *ctx, int j)
{
    const ChildrenWrite *cw = ctx;
    const NodeLists *nl = cw->nl;
    const FreshLists *f = cw->f;
    const uint8_t *side = cw->w->side;
    const Event *src = cw->w->arena + nl->off + (j > 0 ? nl->n[0] : 0) + (j > 1 ? nl->n[1] : 0);
    Event *dl = cw->w->arena + cw->start[0][j], *dr = cw->w->arena + cw->start[1][j];
    const Event *fl = f->list[0][j], *fr = f->list[1][j];
    size_t nfl = f->n[0][j], nfr = f->n[1][j], il = 0, ir = 0, ml = 0, mr = 0;
    for (uint i = 0; i < nl->n[j]; i++) {
        Event e = src[i];
        uint8_t sd = side[event_prim(e)];
        while (il < nfl && fl[il] < e) dl[ml++] = fl[il++];
        while (ir < nfr && fr[ir] < e) dr[mr++] = fr[ir++];
        dl[ml] = e;
        dr[mr] = e;
        ml += sd == SIDE_LEFT;
        mr += sd == SIDE_RIGHT;
    }
    while (il < nfl) dl[ml++] = fl[il++];
    while (ir < nfr) dr[mr++] = fr[ir++];
    cw->count[0][j] = ml;
    cw->count[1][j] = mr;
}

/* Writes the children's lists above the top of the arena, right child first, each axis
 * in one pass that keeps every event for both children (writing both is cheaper than
 * branching) and merges in the fresh events in order. Each list gets room for all of
 * the node's events of its axis plus its fresh ones; start and count say where each
 * list is and how long. */
static int children_write(Worker *w, const NodeLists *nl, uint n_both, const FreshLists *f,
                          size_t start[2][3], size_t count[2][3], int parallel)
{
    size_t node_size = (size_t)nl->n[0] + nl->n[1] + nl->n[2];
    size_t need = node_size * 2 + 12 * (size_t)n_both + 1;
    if (reserve_events(&w->arena, &w->arena_cap, w->top + need)) return -1;
    size_t room = w->top;
    for (int c = 1; c >= 0; c--)
        for (int j = 0; j < 3; j++) {
            start[c][j] = room;
            room += nl->n[j] + f->n[c][j];
        }
    ChildrenWrite cw = { w, nl, f, start, count };
    for_each_axis(children_write_axis, &cw, parallel);
    return 0;
}

/* Moves the children's lists down over the node's, right child first, and sets their
 * offsets and lengths. Destination ranges come in the same order as the sources, and
 * each ends before the next source begins (the sources have room for at least their
 * events). */
static void children_move_down(Worker *w, const NodeLists *nl, size_t start[2][3], size_t count[2][3],
                               NodeLists *left, NodeLists *right)
{
    size_t dst = nl->off;
    for (int c = 1; c >= 0; c--)
        for (int j = 0; j < 3; j++) {
            memmove(w->arena + dst, w->arena + start[c][j], count[c][j] * sizeof *w->arena);
            dst += count[c][j];
        }
    right->off = nl->off;
    left->off = nl->off + count[1][0] + count[1][1] + count[1][2];
    for (int j = 0; j < 3; j++) {
        right->n[j] = (uint)count[1][j];
        left->n[j] = (uint)count[0][j];
    }
    w->top = dst;
}

/* Splits the node's lists into the children's: on return the right child's lists are
 * at nl->off and the left child's right above them, at the top of the arena. Primitives
 * that straddle the split are clipped to each child's box. */
static int split_lists(Worker *w, const NodeLists *nl, const Split *s, int parallel,
                       NodeLists *left, NodeLists *right)
{
    uint n_side[2];
    long n_both = classify_sides(w, nl, s, n_side);
    if (n_both < 0) return -1;
    Aabb child[2] = { nl->box, nl->box };
    child[0].hi[s->axis] = s->pos;
    child[1].lo[s->axis] = s->pos;
    FreshLists fresh;
    if (clip_straddlers(w, (uint)n_both, child, n_side, &fresh)) return -1;
    size_t start[2][3], count[2][3];
    if (children_write(w, nl, (uint)n_both, &fresh, start, count, parallel)) return -1;
    children_move_down(w, nl, start, count, left, right);
    left->nprims = n_side[0];
    right->nprims = n_side[1];
    left->box = child[0];
    right->box = child[1];
    return 0;
}

static int task_push(Worker *w, const NodeLists *nl, int depth, int bad, BNode **out)
{
    Build *b = w->b;
    size_t n = (size_t)nl->n[0] + nl->n[1] + nl->n[2];
    Task t = { malloc(n * sizeof(Event) + 1), { nl->n[0], nl->n[1], nl->n[2] }, nl->nprims,
               nl->box, depth, bad, out };
    if (!t.lists) return -1;
    memcpy(t.lists, w->arena + nl->off, n * sizeof(Event));
    pthread_mutex_lock(&b->lock);
    if (b->q_head > 0 && b->q_head + b->q_len == b->q_cap) {
        memmove(b->queue, b->queue + b->q_head, b->q_len * sizeof *b->queue);
        b->q_head = 0;
    }
    if (reserve_tasks(&b->queue, &b->q_cap, b->q_len + 1)) {
        pthread_mutex_unlock(&b->lock);
        free(t.lists);
        return -1;
    }
    b->queue[b->q_head + b->q_len++] = t;
    b->outstanding++;
    pthread_cond_signal(&b->cond);
    pthread_mutex_unlock(&b->lock);
    return 0;
}

/* One axis of best_split: the axis's cheapest plane in best[axis]. */
typedef struct {
    const Worker *w;
    const NodeLists *nl;
    double inv_sa;
    Split best[3];
} AxisSweep;

static void sweep_one_axis(void *ctx, int k)
{
    AxisSweep *as = ctx;
    const NodeLists *nl = as->nl;
    const Event *e = as->w->arena + nl->off + (k > 0 ? nl->n[0] : 0) + (k > 1 ? nl->n[1] : 0);
    if (nl->box.hi[k] > nl->box.lo[k]) sweep_axis(e, nl->n[k], nl->nprims, k, &nl->box, as->inv_sa, &as->best[k]);
}

/* The cheapest plane of the node over the three axes (axis -1 when it is not to be
 * split: no primitive, too deep, or a box without area). On a tie the earlier axis
 * wins, as within an axis the earlier plane does. */
static Split best_split(const Worker *w, const NodeLists *nl, double sa, int depth)
{
    Split best = { -1, 0.0f, 0, INFINITY };
    if (nl->nprims == 0 || depth >= w->b->max_depth || !(sa > 0.0)) return best;
    AxisSweep as = { w, nl, 1.0 / sa, { best, best, best } };
    for_each_axis(sweep_one_axis, &as, axes_in_parallel(w, depth));
    for (int k = 0; k < 3; k++)
        if (as.best[k].cost < best.cost) best = as.best[k];
    return best;
}

static void make_interior(BNode *node, const Split *s)
{
    node->axis = (uint)s->axis;
    node->split = s->pos;
    node->count = 0;
    node->ids = NULL;
    node->child[0] = node->child[1] = NULL;
}

static int build_node(Worker *w, NodeLists nl, int depth, int bad, int tentative,
                      BNode **out, double *cost);

/* Hands the right child to another thread and builds the left one here: the right
 * child's lists are copied out, so the left child's move down over the node's. */
static int build_left_hand_off_right(Worker *w, size_t node_off, NodeLists left, const NodeLists *right,
                                     int depth, int bad, BNode *node, double *cost_l)
{
    if (task_push(w, right, depth, bad, &node->child[1])) return -1;
    size_t n = (size_t)left.n[0] + left.n[1] + left.n[2];
    memmove(w->arena + node_off, w->arena + left.off, n * sizeof *w->arena);
    left.off = node_off;
    w->top = node_off + n;
    return build_node(w, left, depth, bad, 0, &node->child[0], cost_l);
}

/* Builds the subtree of the node whose lists are at the top of the arena and stores it
 * in *out. *cost gets the subtree's cost (with the empty bonus, in absolute area units)
 * when `tentative`; subtrees handed to other threads are built only outside tentative
 * splits, where that cost is not needed. Returns -1 when memory runs out. */
static int build_node(Worker *w, NodeLists nl, int depth, int bad, int tentative,
                      BNode **out, double *cost)
{
    BNode *node = pool_alloc(&w->nodes, sizeof *node);
    if (!node) return -1;
    *out = node;
    double sa = kd_box_half_area(&nl.box);
    double leaf_cost = kd_leaf_cost(nl.nprims);
    *cost = leaf_cost * sa;

    Split best = best_split(w, &nl, sa, depth);
    int improves = best.axis >= 0 && best.cost < leaf_cost;
    if (best.axis < 0 || (!improves && bad >= KD_MAX_BAD_REFINES)) return make_leaf(w, &nl, node);

    /* A non-improving split is tried only if its subtree turns out cheaper than the
     * leaf: keep the leaf's ids and the pools' positions to go back to. */
    int try_bad = !improves;
    size_t saved_at = w->saved_top;
    PoolMark nodes_mark = pool_mark(&w->nodes), ids_mark = pool_mark(&w->ids);
    if (try_bad) {
        if (reserve_uints(&w->saved, &w->saved_cap, saved_at + nl.nprims + 1)) return -1;
        collect_ids(w, &nl, w->saved + saved_at);
        w->saved_top = saved_at + nl.nprims;
        tentative = 1;
    }

    NodeLists left, right;
    if (split_lists(w, &nl, &best, axes_in_parallel(w, depth), &left, &right)) return -1;
    make_interior(node, &best);
    int child_bad = improves ? 0 : bad + 1;
    double cost_l = 0.0, cost_r = 0.0;

    if (!tentative && w->b->threads > 1 && right.nprims >= KD_TASK_MIN_PRIMS)
        return build_left_hand_off_right(w, nl.off, left, &right, depth + 1, child_bad, node, &cost_l);
    if (build_node(w, left, depth + 1, child_bad, tentative, &node->child[0], &cost_l)) return -1;
    w->top = right.off + right.n[0] + right.n[1] + right.n[2];
    if (build_node(w, right, depth + 1, child_bad, tentative, &node->child[1], &cost_r)) return -1;

    double split_cost = KD_COST_TRAVERSAL * sa + cost_l + cost_r;
    if (left.nprims == 0 || right.nprims == 0) split_cost *= KD_EMPTY_BONUS;
    *cost = split_cost;
    if (try_bad) {
        w->saved_top = saved_at;
        if (split_cost >= leaf_cost * sa) {
            /* Retract: the subtree below this split does not beat a leaf. The node
             * itself was allocated before the marks and stays. */
            pool_release(&w->ids, ids_mark);
            pool_release(&w->nodes, nodes_mark);
            *cost = leaf_cost * sa;
            return make_leaf_from(w, w->saved + saved_at, nl.nprims, node);
        }
    }
    return 0;
}

/* Runs queued subtree tasks until none is queued or running. */
static void worker_run(Worker *w)
{
    Build *b = w->b;
    pthread_mutex_lock(&b->lock);
    for (;;) {
        while (b->q_len == 0 && b->outstanding > 0) pthread_cond_wait(&b->cond, &b->lock);
        if (b->q_len == 0) break;
        Task t = b->queue[b->q_head++];
        b->q_len--;
        int skip = b->failed;
        pthread_mutex_unlock(&b->lock);

        int fail = 0;
        if (!skip) {
            size_t n = (size_t)t.n[0] + t.n[1] + t.n[2];
            fail = reserve_events(&w->arena, &w->arena_cap, n + 1);
            if (!fail) {
                memcpy(w->arena, t.lists, n * sizeof *w->arena);
                w->top = n;
                NodeLists nl = { 0, { t.n[0], t.n[1], t.n[2] }, t.nprims, t.box };
                double cost;
                fail = build_node(w, nl, t.depth, t.bad, 0, t.out, &cost);
            }
        }
        free(t.lists);

        pthread_mutex_lock(&b->lock);
        if (fail) b->failed = 1;
        if (--b->outstanding == 0) pthread_cond_broadcast(&b->cond);
    }
    pthread_mutex_unlock(&b->lock);
}

static void *worker_thread(void *arg)
{
    worker_run(arg);
    return NULL;
}

/* ------------------------------------------------------------------ entry points */

/* threads <= 0 means every core; more than 256 would only add idle workers. */
static int threads_resolve(int threads)
{
    if (threads <= 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        threads = n > 0 ? (int)n : 1;
    }
    return threads > 256 ? 256 : threads;
}

static void build_init(Build *b, int threads)
{
    memset(b, 0, sizeof *b);
    pthread_mutex_init(&b->lock, NULL);
    pthread_cond_init(&b->cond, NULL);
    b->threads = threads;
}

static void build_free(Build *b)
{
    for (int i = 0; i < b->n_workers; i++) worker_free(&b->workers[i]);
    free(b->workers);
    for (size_t i = 0; i < b->q_len; i++) free(b->queue[b->q_head + i].lists);
    free(b->queue);
    free(b->gid);
    free(b->tri);
    free(b->bounds);
    pthread_mutex_destroy(&b->lock);
    pthread_cond_destroy(&b->cond);
}

static Aabb root_box(const Build *b)
{
    Aabb root = b->bounds[0];
    for (uint i = 1; i < b->n_prims; i++)
        for (int k = 0; k < 3; k++) {
            root.lo[k] = fminf(root.lo[k], b->bounds[i].lo[k]);
            root.hi[k] = fmaxf(root.hi[k], b->bounds[i].hi[k]);
        }
    return root;
}

/* Deepest level a node may be split at: round(8 + 1.3 floor(log2 N)), as in pbrt
 * (docs/kdtree.md). */
static int depth_limit(uint n_prims)
{
    int log2n = 0;
    while ((2u << log2n) <= n_prims && log2n < 31) log2n++;
    int d = (int)lround(8.0 + 1.3 * log2n);
    return d > KD_MAX_DEPTH - 1 ? KD_MAX_DEPTH - 1 : d;
}

/* One worker per thread, each with its own side array and radix counters. */
static Status workers_create(Build *b, Error *err)
{
    b->workers = calloc((size_t)b->threads, sizeof *b->workers);
    if (!b->workers) return error_set(err, ST_INTERNAL, "kd-tree: out of memory");
    b->n_workers = b->threads;
    for (int i = 0; i < b->threads; i++) {
        Worker *w = &b->workers[i];
        w->b = b;
        w->side = malloc(b->n_prims);
        w->radix_count = malloc(RADIX_BUCKETS * sizeof *w->radix_count);
        if (!w->side || !w->radix_count) return error_set(err, ST_INTERNAL, "kd-tree: out of memory");
    }
    return ST_OK;
}

/* One axis of the root's events: emitted in primitive order, then sorted. */
typedef struct { const Build *b; int axis; Event *list; size_t n; int failed; } AxisJob;

static void *axis_job(void *arg)
{
    AxisJob *j = arg;
    size_t m = 0;
    for (uint i = 0; i < j->b->n_prims; i++) m += kd_events_emit(j->list + m, &j->b->bounds[i], j->axis, i);
    Event *tmp = malloc(j->n * sizeof *tmp + 1);
    size_t *count = malloc(RADIX_BUCKETS * sizeof *count);
    if (tmp && count) kd_events_sort_by_prim_order(j->list, tmp, count, j->n);
    else j->failed = 1;
    free(tmp);
    free(count);
    return NULL;
}

/* The root's sorted event lists, at the bottom of worker 0's arena, described by *nl.
 * The arena gets room for three times the root's events: the children's lists are
 * written above their parent's. With more than one thread, each axis is done on a
 * thread of its own (three on two cores take two thirds of the time that two on one
 * core and one on the other do). */
static Status root_events(Build *b, const Aabb *root, NodeLists *nl, Error *err)
{
    Worker *w = &b->workers[0];
    size_t n_ev[3] = { 0, 0, 0 };
    for (uint i = 0; i < b->n_prims; i++)
        for (int k = 0; k < 3; k++) n_ev[k] += b->bounds[i].lo[k] == b->bounds[i].hi[k] ? 1 : 2;
    size_t total_ev = n_ev[0] + n_ev[1] + n_ev[2];
    if (reserve_events(&w->arena, &w->arena_cap, total_ev * 3 + 1))
        return error_set(err, ST_INTERNAL, "kd-tree: out of memory for %zu events", total_ev);
    AxisJob jobs[3];
    Event *ev = w->arena;
    for (int k = 0; k < 3; k++) {
        jobs[k] = (AxisJob){ b, k, ev, n_ev[k], 0 };
        ev += n_ev[k];
    }
    if (b->threads > 1)
        jobs_run(axis_job, jobs, sizeof *jobs, 3);
    else
        for (int k = 0; k < 3; k++) axis_job(&jobs[k]);
    if (jobs[0].failed || jobs[1].failed || jobs[2].failed)
        return error_set(err, ST_INTERNAL, "kd-tree: out of memory sorting events");
    w->top = total_ev;
    *nl = (NodeLists){ 0, { (uint)n_ev[0], (uint)n_ev[1], (uint)n_ev[2] }, b->n_prims, *root };
    return ST_OK;
}

/* Builds the tree below the root: worker 0 (this thread) starts at the root and the
 * other workers wait for the subtrees it hands out; all return when none is left. */
static Status subtrees_build(Build *b, NodeLists root, BNode **out, Error *err)
{
    pthread_t *tid = calloc((size_t)b->threads, sizeof *tid);
    if (!tid) return error_set(err, ST_INTERNAL, "kd-tree: out of memory");
    b->outstanding = 1;
    int n_started = 0;
    for (int i = 1; i < b->threads; i++)
        if (pthread_create(&tid[i], NULL, worker_thread, &b->workers[i]) == 0) n_started = i;
        else break;
    if (n_started == 0) b->threads = 1;
    double cost;
    int fail = build_node(&b->workers[0], root, 0, 0, 0, out, &cost);
    pthread_mutex_lock(&b->lock);   /* as worker_run ends a task: the others may be running */
    if (fail) b->failed = 1;
    if (--b->outstanding == 0) pthread_cond_broadcast(&b->cond);
    pthread_mutex_unlock(&b->lock);
    worker_run(&b->workers[0]);
    for (int i = 1; i <= n_started; i++) pthread_join(tid[i], NULL);
    free(tid);
    /* every worker has returned (joined): failed is read without the lock */
    if (b->failed) return error_set(err, ST_INTERNAL, "kd-tree: out of memory building the tree");
    return ST_OK;
}

/* The tree over the gathered primitives (at least one). */
static Status build_tree(Build *b, const KdInput *in, KdTree *out, Error *err)
{
    Aabb root = root_box(b);
    b->max_depth = depth_limit(b->n_prims);
    NodeLists nl;
    BNode *root_node = NULL;
    Status st;
    if ((st = workers_create(b, err))) return st;
    if ((st = root_events(b, &root, &nl, err))) return st;
    if ((st = subtrees_build(b, nl, &root_node, err))) return st;
    if ((st = kd_flatten(root_node, &root, in, b->threads, out, err))) return st;
    out->lo = (vec3){ root.lo[0], root.lo[1], root.lo[2] };
    out->hi = (vec3){ root.hi[0], root.hi[1], root.hi[2] };
    out->stats.leaf_sah_cost = kd_leaf_cost(b->n_prims);
    return ST_OK;
}

static Status build_single_leaf(KdTree *out, Error *err)
{
    out->nodes = malloc(sizeof *out->nodes);
    out->leaf_prims = malloc(sizeof *out->leaf_prims);
    if (!out->nodes || !out->leaf_prims) return error_set(err, ST_INTERNAL, "kd-tree: out of memory");
    out->nodes[0].data = 0;
    out->nodes[0].bits = KD_LEAF;
    out->n_nodes = 1;
    out->n_leaf_prims = 0;
    out->stats.n_nodes = 1;
    out->stats.n_leaves = 1;
    out->stats.n_empty_leaves = 1;
    out->stats.bytes = sizeof(KdNode);
    return ST_OK;
}

/* Gathers the primitives' bounds, builds the tree (or a single empty leaf when no
 * primitive is left), flattens it and fills in the statistics. */
Status kd_build(const KdInput *in, int threads, KdTree *out, Error *err)
{
    double t_start = timer_now();
    memset(out, 0, sizeof *out);
    Build b;
    build_init(&b, threads_resolve(threads));
    Status st = kd_gather(&b, in, &out->stats.n_skipped, err);
    if (st == ST_OK) {
        out->stats.n_prims = b.n_prims;
        st = b.n_prims == 0 ? build_single_leaf(out, err) : build_tree(&b, in, out, err);
    }
    build_free(&b);
    if (st != ST_OK) kd_free(out);
    out->stats.build_seconds = timer_now() - t_start;
    return st;
}

void kd_free(KdTree *t)
{
    free(t->nodes);
    free(t->leaf_prims);
    t->nodes = NULL;
    t->leaf_prims = NULL;
    t->n_nodes = 0;
    t->n_leaf_prims = 0;
}

