/*
 * bvh_top.h — the top level over instances in compressed nodes (BvhTopNode,
 * kernels/types.h; docs/instancing.md, Memory per instance).
 *
 * The top level is built as any BVH (bvh_inst.c) and then written as 96-byte nodes
 * whose child boxes are 8-bit steps from the node's corner, rounded outwards and
 * checked against the very float decode the kernels do, so every child box holds its
 * instance's float box and the walk finds the same hits.
 */
#ifndef CLPT_BVH_TOP_H
#define CLPT_BVH_TOP_H

#include "accel/bvh.h"
#include "base/status.h"
#include "types.h"

/* The plane a kernel decodes from step q of a node whose axis starts at origin with
 * a step of 2^(e - 127) (e: a biased float exponent, 1 .. 254): the one expression
 * the kernels evaluate (kernels/accel/traverse_bvh.h, bvh_top_rows), exact but for
 * the add's one rounding. */
float bvh_top_plane(float origin, uint e, uint q);

/* Writes the nodes of top (an item build over instance boxes, whose children are
 * nodes and instances only) as compressed nodes: *out (malloc'd, top->n_nodes of them,
 * the same indices). Fails only for want of memory, or on a child that is neither. */
Status bvh_top_compress(const Bvh *top, BvhTopNode **out, Error *err);

#endif /* CLPT_BVH_TOP_H */
