/*
 * nanovdb.h — reads one float grid of a NanoVDB file (.nvdb) into a dense grid that
 * clpt's grid medium holds (docs/media.md#nanovdb-files): pbrt-v4's "nanovdb" medium.
 *
 * Written from the layout NanoVDB documents (its NanoVDB.h, PNanoVDB.h and io/IO.h:
 * the file header, the per-grid metadata, GridData, the tree of a root table, upper
 * 32^3, lower 16^3 and leaf 8^3 nodes), ABI major version 32; no C++ and no NanoVDB code.
 * Codecs: none, and ZIP through zlib; BLOSC is an error.
 *
 * The sparse tree is resampled into a dense grid over its active index bounding box,
 * one cell per voxel, or one cell per k^3 voxels (their mean) when the box holds more
 * than NANOVDB_MAX_CELLS voxels. Memory: 4 bytes a cell, at most 64 MiB, checked
 * before allocating; the file itself is read whole (CLPT_MAX_FILE_BYTES).
 */
#ifndef CLPT_NANOVDB_H
#define CLPT_NANOVDB_H

#include <stddef.h>
#include <stdint.h>

#include "base/status.h"
#include "scene/transform.h"

/* The most cells of a dense grid made from a NanoVDB grid: the same bound as a pbrt
 * "uniformgrid" (2^24 = 256^3 cells, 64 MiB of floats). */
#define NANOVDB_MAX_CELLS (1u << 24)

typedef struct {
    float *density;        /* nx ny nz values, x fastest, cell-centred (docs/media.md) */
    unsigned nx, ny, nz;
    unsigned stride;       /* voxels per cell along each axis: 1, or k when resampled */
    double lo[3], hi[3];   /* the dense grid's box in the grid's index space */
    Transform index_to_world;   /* NanoVDB's map (its double-precision affine part) */
    int64_t bbox_min[3], bbox_max[3];   /* the active voxels' index box, inclusive */
} NanoDense;

/* Reads the grid named `grid_name` from the `len` bytes of the NanoVDB file `path`
 * (which names it in messages). Fails with ST_INPUT and a message
 * "<path>: <what>" (a byte offset where one helps) on a file that is not NanoVDB, of
 * another version, compressed with BLOSC, whose sizes or offsets point past its end,
 * whose grid is not a float fog volume, or that holds no grid of that name; with
 * ST_INTERNAL when memory runs out. On success free out->density. */
Status nanovdb_read_grid(const char *path, const unsigned char *data, size_t len, const char *grid_name,
                         NanoDense *out, Error *err);

/* Whether the file holds a grid named `grid_name` (its metadata only; 0 on a file
 * nanovdb_read_grid would refuse). */
int nanovdb_has_grid(const unsigned char *data, size_t len, const char *grid_name);

#endif /* CLPT_NANOVDB_H */
