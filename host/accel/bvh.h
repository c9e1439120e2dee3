/*
 * bvh.h — an 8-wide bounding volume hierarchy over the same primitives as the kd-tree.
 *
 * Built with the binned surface area heuristic as a binary tree, then collapsed so that
 * each node holds up to eight children (Embree's BVH8 shape: one ray tests a node's
 * eight boxes with one float8 operation per slab), and flattened into BvhNode records
 * (kernels/types.h) whose leaves use the kd-tree's leaf records (groups of eight
 * triangles). kernels/accel/traverse_bvh.h walks it; docs/kdtree.md says why it exists
 * beside the kd-tree and what it measured.
 */
#ifndef CLPT_BVH_H
#define CLPT_BVH_H

#include <stddef.h>

#include "accel/kdtree.h"
#include "base/status.h"
#include "types.h"

typedef struct {
    double build_seconds;
    uint n_nodes, n_leaves, max_depth;  /* depth in 8-wide nodes, root = 1 */
    uint max_binary_depth;               /* of the binary tree it was collapsed from, root = 0 */
    uint max_stack;                      /* the most entries the walk's stack can hold */
    double mean_prims_per_leaf;
    double sah_cost;                     /* of the binary tree: node visits + leaf groups,
                                          * per unit of the root's area */
    uint n_skipped;                      /* left out: bounds not finite */
} BvhStats;

typedef struct {
    BvhNode *nodes;     uint n_nodes;             /* nodes[0] is the root */
    uint *leaf_prims;   uint n_leaf_prims;
    /* a scene with instances: its top level, compressed (bvh_top.h), whose node 0 is
     * the root, and nodes[] the prototypes' trees; NULL and 0 otherwise */
    BvhTopNode *top;    uint n_top;
    vec3 lo, hi;                                  /* box of every primitive in it */
    BvhStats stats;
} Bvh;

/* Builds the BVH of in's primitives; on success *out owns its arrays (bvh_free). An
 * empty input gives a root without children. Threads: 0 = all cores; the tree is the
 * same for any number. */
Status bvh_build(const KdInput *in, int threads, Bvh *out, Error *err);

/* What bvh_build_with may do differently (docs/instancing.md). */
typedef struct {
    uint stack_budget;        /* stack entries a walk of this tree may use (0: BVH_STACK);
                               * the two levels of an instanced scene share BVH_STACK */
    const float *item_boxes;  /* non-NULL: build over n_items boxes (6 floats each: lo x y z,
                               * hi x y z) instead of in's primitives, each its own leaf, a
                               * BVH_CHILD_INSTANCE child whose ref is the box's index; a
                               * box that is empty or not finite is left out */
    uint n_items;
} BvhOptions;

Status bvh_build_with(const KdInput *in, const BvhOptions *opt, int threads, Bvh *out, Error *err);
void bvh_free(Bvh *b);

#endif /* CLPT_BVH_H */
