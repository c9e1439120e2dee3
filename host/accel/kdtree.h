/*
 * kdtree.h — the kd-tree over a scene's spheres, triangles and boxes.
 *
 * Built on the host with the surface area heuristic and flattened into the node array
 * and primitive-id array the kernels traverse (KdNode in kernels/types.h; the layout,
 * the SAH constants and the termination rules are in docs/kdtree.md). Infinite planes
 * are not in the tree. Primitive ids are global ids (spheres, then triangles, then
 * boxes: see RenderParams).
 */
#ifndef CLPT_KDTREE_H
#define CLPT_KDTREE_H

#include <stddef.h>

#include "base/status.h"
#include "types.h"

/* Surface area heuristic costs of one traversal step and one primitive test (relative
 * units; docs/kdtree.md says how they were chosen). */
#ifndef KD_COST_TRAVERSAL
#define KD_COST_TRAVERSAL 1.0
#endif
#ifndef KD_COST_INTERSECT
#define KD_COST_INTERSECT 0.075
#endif

#ifndef KD_GROUPED_COST
#define KD_GROUPED_COST 1
#endif

/* SAH cost of testing a leaf of n primitives: its triangles are tested KD_GROUP at a
 * time, so a leaf costs per group of KD_GROUP, each lane at KD_COST_INTERSECT. */
static inline double kd_leaf_cost(unsigned n)
{
    if (!KD_GROUPED_COST) return KD_COST_INTERSECT * n;
    return KD_COST_INTERSECT * KD_GROUP * (double)((n + KD_GROUP - 1u) / KD_GROUP);
}

/* Most primitives a tree holds: the kd build's primitive indices share a 64-bit event
 * key with the position and the event type. */
#define KD_MAX_PRIMS ((1u << 30) - 1u)

/* Global primitive ids [lo, hi): part of a KdInput (an object's primitives). */
typedef struct { uint lo, hi; } KdRange;

typedef struct {
    const Sphere *spheres;     size_t n_spheres;
    const Triangle *triangles; size_t n_triangles;
    const Box *boxes;          size_t n_boxes;
    const RevSurface *revs;    size_t n_revs;    /* after the boxes in the id space */
    const SphereXform *sphere_xforms; size_t n_sphere_xforms;   /* Sphere.xform's targets */
    /* A prototype's build (an object of an instanced scene, docs/instancing.md): the
     * tree holds the primitives of these ranges (increasing, disjoint) rather than all
     * of them (0 ranges). Both trees take them. */
    const KdRange *ranges;     size_t n_ranges;
} KdInput;

typedef struct {
    double build_seconds;
    uint n_nodes, n_leaves, n_empty_leaves;
    uint max_depth;                /* deepest leaf, root = 0 */
    double mean_prims_per_leaf;    /* over non-empty leaves */
    double sah_cost;               /* expected cost of a random ray through the root box */
    double sah_cost_bonus;         /* the same with the empty-space bonus: what the build minimises */
    double leaf_sah_cost;          /* the same for a single leaf holding every primitive */
    size_t bytes;                  /* nodes + leaf data (ids and the triangles' corners) */
    size_t bytes_corners;          /* of which the copies of the triangles' corners */
    uint n_prims;                  /* primitives in the tree */
    uint n_skipped;                /* left out: bounds not finite (NaN or inf coordinates) */
} KdStats;

typedef struct {
    KdNode *nodes;      uint n_nodes;        /* nodes[0] is the root */
    uint *leaf_prims;   uint n_leaf_prims;
    vec3 lo, hi;                              /* box of the root */
    KdStats stats;
} KdTree;

/* Builds the tree; on success *out owns its arrays (release with kd_free). An empty
 * input gives a single empty leaf. Threads: 0 = all cores. */
Status kd_build(const KdInput *in, int threads, KdTree *out, Error *err);
void kd_free(KdTree *t);

/* The primitive ids of leaf `node` (at most cap of them) into out; returns how many
 * (0 for an interior node). */
uint kd_leaf_ids(const KdTree *t, uint node, uint *out, uint cap);

/* Primitive gid's bounds (global ids, as KdInput orders them); 0 when they are not
 * finite, which leaves the primitive out of any tree. */
int kd_prim_box(const KdInput *in, uint gid, float lo[3], float hi[3]);

/* A leaf record in the leaf data (the layout of types.h, shared by the 8-wide BVH of
 * accel/bvh.h): its size in words for `count` sorted global ids, and writing it at
 * out, which returns the leaf's KdNode bits (KD_LEAF, KD_LEAF_OTHERS, groups << 3). */
size_t kd_leaf_record_words(const KdInput *in, const uint *ids, uint count);
uint kd_leaf_record_write(const KdInput *in, const uint *ids, uint count, uint *out);

#endif /* CLPT_KDTREE_H */
