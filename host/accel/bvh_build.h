/*
 * bvh_build.h — the BVH build's shared state (not included outside host/accel/):
 * bvh.c (the binary SAH tree and its threads) and bvh_collapse.c (the binary tree
 * collapsed into the 8-wide nodes and leaf records of accel/bvh.h). bvh.c's head
 * comment is the design.
 */
#ifndef CLPT_BVH_BUILD_H
#define CLPT_BVH_BUILD_H

#include <stdatomic.h>
#include <stddef.h>

#include "accel/bvh.h"
#include "base/status.h"

#define BVH_MAX_DEPTH 40       /* binary levels; a node this deep becomes a leaf */
/* The walk's stack (BVH_STACK, types.h) holds the children a path leaves behind: at
 * most the sum of (children - 1) over the wide nodes above a leaf. Once that sum nears
 * the stack's size, nodes below take two children (one more entry per binary level, of
 * which there are at most BVH_MAX_DEPTH), so no tree can overflow it (bvh_collapse.c). */

typedef struct { float lo[3], hi[3]; } Box3;

/* Half the surface area of b (0 when it is empty): what the SAH weighs a node by. */
static inline double box3_half_area(const Box3 *b)
{
    double dx = (double)b->hi[0] - b->lo[0], dy = (double)b->hi[1] - b->lo[1], dz = (double)b->hi[2] - b->lo[2];
    if (!(dx >= 0.0 && dy >= 0.0 && dz >= 0.0)) return 0.0;
    return dx * dy + dy * dz + dz * dx;
}

/* A node of the binary tree: a leaf when count > 0 (its primitives are
 * ref[first .. first + count)), else an interior node with two children. */
typedef struct {
    Box3 box;
    uint child[2];
    uint first, count;
} BinNode;

/* A primitive as the build moves it: its bounds and global id, 32 bytes. The build
 * partitions these records themselves, not indices to them, so that every pass over a
 * node reads memory in order: with an index array, each pass over a large node
 * gathered boxes from all over the scene's 28 MB of bounds and centres (the dragon's
 * binary tree took 0.9 s on two threads). */
typedef struct {
    Box3 box;
    uint gid;
    uint pad;
} PrimRef;

typedef struct {
    const KdInput *in;
    const BvhOptions *opt;     /* item builds (instances): opt->item_boxes */
    uint budget;               /* the walk's stack entries this tree may use */
    uint n;                    /* primitives in the tree */
    PrimRef *ref;              /* the primitives, in tree order once built */
    uint first_tri, n_tri;     /* the triangles' global ids */
    BinNode *nodes;            /* room for every node: a binary tree of n leaves has 2n - 1 */
    atomic_uint n_nodes;
    int threads;               /* threads the build may use */
    struct RangeJob *range_jobs; /* the top's passes on `threads` threads (the calling thread's) */
    uint defer_at_most;        /* subtrees of at most this many primitives wait (0: none) */
    struct Subtree *waiting;   /* those subtrees, their nodes already numbered */
    size_t n_waiting, cap_waiting;
    atomic_size_t next_waiting; /* the next one a thread takes */
} BvhBuild;

/* An item build (instances) puts every item in a leaf of its own. */
static inline int one_per_leaf(const BvhBuild *b) { return b->opt->item_boxes != NULL; }

/* bvh_collapse.c: the wide nodes and leaf records of b's binary tree under root into
 * *out (its nodes and leaf data allocated here, its max_stack statistic set). */
Status bvh_collapse(BvhBuild *b, uint root, Bvh *out, Error *err);

#endif /* CLPT_BVH_BUILD_H */
