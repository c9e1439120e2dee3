/*
 * kd_build.h — the kd-tree build's shared state (not included outside host/accel/):
 * kdtree.c (the recursion and the threads), kd_events.c (the sweep events),
 * kd_clip.c (boxes and clipped triangles), kd_input.c (the primitives' boxes) and
 * kd_flatten.c (the tree laid out for the kernels). kdtree.c's head comment is the
 * design.
 */
#ifndef CLPT_KD_BUILD_H
#define CLPT_KD_BUILD_H

#include <pthread.h>
#include <stdint.h>
#include <string.h>

#include "accel/kdtree.h"
#include "base/pool.h"
#include "base/status.h"

/* Cost factor of a split that leaves one child empty (Wald & Havran's lambda). */
#ifndef KD_EMPTY_BONUS
#define KD_EMPTY_BONUS 0.8
#endif
/* Consecutive splits whose estimated cost is not below the leaf's that are tried
 * before giving up (pbrt's badRefines); kept only if the subtree beats the leaf. */
#ifndef KD_MAX_BAD_REFINES
#define KD_MAX_BAD_REFINES 1
#endif
/* Subtrees with at least this many primitives are handed to other threads. */
#ifndef KD_TASK_MIN_PRIMS
#define KD_TASK_MIN_PRIMS 2048
#endif

typedef uint64_t Event;
enum { EV_END = 0, EV_PLANAR = 1, EV_START = 2 };
enum { SIDE_LEFT = 0, SIDE_RIGHT = 1, SIDE_BOTH = 2 };

typedef struct { float lo[3], hi[3]; } Aabb;

/* Float to unsigned with the same order (-0 is normalised to +0 by the callers). */
static inline uint32_t float_key(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

static inline float key_float(uint32_t k)
{
    uint32_t u = (k & 0x80000000u) ? (k & 0x7fffffffu) : ~k;
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* Ordered by position, then end < planar < start (the sweep relies on it), then
 * primitive: a total order, so any correct sort gives the same lists. */
static inline Event event_make(float pos, uint type, uint prim)
{
    return ((uint64_t)float_key(pos + 0.0f) << 32) | ((uint64_t)type << 30) | prim;
}
static inline uint32_t event_pos(Event e) { return (uint32_t)(e >> 32); }
static inline uint event_type(Event e) { return (uint)(e >> 30) & 3u; }
static inline uint event_prim(Event e) { return (uint)e & KD_MAX_PRIMS; }

#define RADIX_BIG_BITS 16
#define RADIX_BUCKETS (1u << RADIX_BIG_BITS)

typedef struct BNode {
    uint axis;                  /* 0..2, or KD_LEAF */
    float split;
    uint count;                 /* leaf: number of ids */
    uint *ids;                  /* leaf: sorted global ids (count > 1) */
    uint id;                    /* leaf: the id when count == 1 */
    struct BNode *child[2];     /* below, above */
} BNode;

typedef struct {
    Event *lists;               /* the three axes' lists, back to back (malloc) */
    uint n[3], nprims;
    Aabb box;
    int depth, bad;
    BNode **out;
} Task;

typedef struct Build Build;

typedef struct {
    Build *b;
    uint8_t *side;                  /* per primitive: SIDE_* for the node being split */
    Event *arena;  size_t arena_cap, top;
    Event *fresh;  size_t fresh_cap;
    Event *sort_tmp; size_t sort_tmp_cap;
    size_t *radix_count;            /* RADIX_BUCKETS counters */
    uint *both;    size_t both_cap;
    uint *saved;   size_t saved_cap, saved_top;   /* a tentative node's ids, for retraction */
    Pool nodes, ids;
} Worker;

struct Build {
    uint n_prims;
    uint *gid;                  /* global id of each primitive */
    uint *tri;                  /* triangle index, or NO_INDEX for spheres and boxes */
    Aabb *bounds;               /* box of each whole primitive */
    const Triangle *triangles;
    int max_depth;
    int threads;

    pthread_mutex_t lock;
    pthread_cond_t cond;
    Worker *workers;  int n_workers;
    Task *queue;  size_t q_head, q_len, q_cap;
    int outstanding;            /* queued + running tasks */
    int failed;
};

/* kd_events.c */
size_t kd_events_emit(Event *out, const Aabb *b, int k, uint prim);
void kd_events_sort(Event *a, Event *tmp, size_t *count, size_t n);
void kd_events_sort_by_prim_order(Event *a, Event *tmp, size_t *count, size_t n);
void kd_ids_sort(uint *ids, uint n);

/* kd_clip.c */
double kd_box_half_area(const Aabb *b);
int kd_box_intersect(Aabb *b, const Aabb *with);
Aabb kd_triangle_bounds(const Triangle *t);
int kd_clip_triangle(const Triangle *t, const Aabb *c, Aabb *out);

/* kd_input.c */
Status kd_gather(Build *b, const KdInput *in, uint *skipped, Error *err);

/* kd_flatten.c */
Status kd_flatten(const BNode *root, const Aabb *root_box, const KdInput *in, int threads, KdTree *t,
                  Error *err);

#endif /* CLPT_KD_BUILD_H */
