/*
 * bvh_inst.h — the 8-wide BVH in two levels, for scenes with instances
 * (docs/instancing.md).
 *
 * Each prototype (an object, and the world's own primitives as one more) gets a BVH of
 * its primitives in its own space; a top-level BVH holds the instances' world boxes, one
 * instance a leaf (BVH_CHILD_INSTANCE). All of them are written into one node array and
 * one leaf array, the top level first (node 0 is its root), so the kernels' scene
 * buffers are the ones a one-level scene has, plus the instance records.
 */
#ifndef CLPT_BVH_INST_H
#define CLPT_BVH_INST_H

#include "accel/bvh.h"

/* The walk's stack entries the top level may use; the prototypes get what is left of
 * BVH_STACK after the deepest top-level path and one entry to come back out. */
#define BVH_TOP_STACK 64u

/* A prototype: its primitives, as ranges of global ids. */
typedef struct {
    const KdRange *ranges;  size_t n_ranges;
} BvhProto;

/* The scene's input narrowed to prototype proto's primitives, for either tree's build;
 * *none holds the empty range an empty prototype is given (no ranges would mean every
 * primitive), so it must live as long as the result. */
KdInput bvh_proto_input(const KdInput *in, const BvhProto *proto, KdRange *none);

/* The two levels, for --stats. */
typedef struct {
    BvhStats top;                  /* the top level's tree */
    uint n_protos_built;           /* prototypes some instance reaches */
    uint top_nodes, proto_nodes;   /* nodes of each level (BvhTopNode, 96 bytes; BvhNode, 256) */
    uint proto_leaf_words;         /* leaf data of the prototypes (32-bit words) */
    uint max_proto_stack;          /* the deepest prototype walk's stack */
    uint n_inst_skipped;           /* instances of an empty prototype, left out */
    uint inst_beyond;              /* when the build refused one: an instance whose world box
                                    * bvh_top_box_fits refuses (NO_INDEX: none) */
    float inst_beyond_at;          /* and the farthest coordinate of that box */
} BvhLevels;

/* Where moving instances' keys are (docs/motion.md): instance i moves when
 * inst_motion is not NULL and inst_motion[i] is not NO_INDEX, its keys from
 * keys[inst_motion[i]] (MotionKey.count of them). */
typedef struct {
    const uint *inst_motion;
    const MotionKey *keys;
} BvhMotion;

/* Builds the prototypes protos[0 .. n_protos) and the top level over inst[0 .. n_inst)
 * (object[i]: instance i's prototype), filling each instance's root. A moving
 * instance's box bounds it over all its keys' times (motion_bounds, scene/motion.h).
 * An instance whose world box is not finite or reaches beyond BVH_TOP_COORD_MAX
 * (bvh_top.h) is refused: ST_INPUT, its index in lv->inst_beyond for the caller's
 * message.
 * On success *out owns one node array and one leaf array (bvh_free); out->lo, hi bound
 * the world. Threads: 0 = all cores. */
Status bvh_build_instanced(const KdInput *in, const BvhProto *protos, size_t n_protos, Instance *inst,
                           const uint *object, size_t n_inst, const BvhMotion *motion, int threads, Bvh *out, BvhLevels *lv, Error *err);

/* The top level alone, as bvh_build_instanced builds it (the same boxes, the same
 * refusals), for prototypes of another kind: the kd-trees of --accel kdtree
 * (accel/kd_inst.h). *out owns the compressed top level (top, n_top) and nothing else
 * (no nodes, no leaves); out->lo, hi bound the world. Instance roots are left as they
 * are: the caller fills them. */
Status bvh_build_top_level(const KdInput *in, const BvhProto *protos, size_t n_protos, const Instance *inst,
                           const uint *object, size_t n_inst, const BvhMotion *motion, int threads, Bvh *out,
                           BvhLevels *lv, Error *err);

#endif /* CLPT_BVH_INST_H */
