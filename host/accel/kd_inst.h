/*
 * kd_inst.h — the kd-tree as prototype trees, for scenes with instances under
 * --accel kdtree (docs/instancing.md, docs/kdtree.md).
 *
 * The top level stays the BVH's compressed tree over the instances (bvh_inst.h,
 * bvh_build_top_level); each prototype (an object, and the world's own primitives as
 * one more) gets its own SAH kd-tree over its primitives in its object space, built by
 * kd_build over the prototype's ranges. The trees are written one after the other into
 * one node array and one leaf array, the kernels' `nodes` and `leaf_prims`, each moved
 * to where it lies (interior nodes' "above" indices, leaves' record offsets), and each
 * is found by its KdProto record (kernels/types.h): root node and root box.
 */
#ifndef CLPT_KD_INST_H
#define CLPT_KD_INST_H

#include "accel/bvh_inst.h"
#include "accel/kdtree.h"

/* The prototypes' trees together, for --stats. */
typedef struct {
    uint n_protos_built;       /* prototypes some instance reaches */
    uint n_nodes, n_leaf_words; /* of all the trees together (KdNode: 8 bytes; words: 4) */
    uint max_depth;            /* the deepest leaf of any of them (root 0): the kd walk's
                                * stack holds KD_MAX_DEPTH, which every build stays within */
    size_t bytes;              /* nodes, leaf data and KdProto records */
    double build_seconds;      /* the prototypes' builds (the top level's is its own) */
} KdProtoStats;

/* Builds the kd-tree of every prototype some instance reaches (object[i]: instance i's
 * prototype) over its ranges, into out's node and leaf arrays, and *records: one KdProto
 * per prototype (n_protos of them; a prototype no instance reaches gets an empty leaf's
 * record). Sets each instance's root to its prototype's index. On success out and
 * *records are the caller's (kd_free, free); out->lo, hi are left 0 (each tree's box is
 * in its record). Threads: 0 = all cores. */
Status kd_build_prototypes(const KdInput *in, const BvhProto *protos, size_t n_protos, Instance *inst,
                           const uint *object, size_t n_inst, int threads, KdTree *out, KdProto **records,
                           KdProtoStats *stats, Error *err);

#endif /* CLPT_KD_INST_H */
