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

/* The largest coordinate a compressed child box may have (2^110, about 1.3e33): every
 * step then stays a normal float and the bias a finite one. bvh_inst.c refuses an
 * instance whose world box reaches beyond (or is not finite) before the top level is
 * built, so no child box is "always entered" and none decodes to an infinity. */
#define BVH_TOP_COORD_MAX 0x1p110f

/* The plane a kernel decodes from step q of a node's axis of exponent e (the bias
 * 2^(e - 127), a step of 2^(e - 150); e from 50 to 254) and offset: the float of
 * exponent e and mantissa q, plus the offset (kernels/accel/traverse_bvh.h,
 * BVH_TOP_ROW), exact but for the add's one rounding. */
float bvh_top_plane(float offset, uint e, uint q);

/* 1 when the box lo .. hi is finite and within +-BVH_TOP_COORD_MAX on every axis. */
int bvh_top_box_fits(const float lo[3], const float hi[3]);

/* Writes the nodes of top (an item build over instance boxes, whose children are
 * nodes and instances only) as compressed nodes: *out (malloc'd, top->n_nodes of them,
 * the same indices). Fails only for want of memory, on a child that is neither, or on
 * a child box that bvh_top_box_fits refuses (the build refuses its instance first). */
Status bvh_top_compress(const Bvh *top, BvhTopNode **out, Error *err);

#endif /* CLPT_BVH_TOP_H */
