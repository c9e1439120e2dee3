/*
 * subdiv.h — Loop subdivision of a triangle mesh (pbrt-v4's "loopsubdiv" shape).
 *
 * Each level splits every triangle in four with Loop's rules (Loop 1987; Warren's
 * beta = 3/16 at valence 3, 3/(8n) otherwise; boundary edges and vertices by the cubic
 * B-spline rules); after the last level every vertex moves to its limit position
 * (gamma = 1 / (n + 3/(8 beta)) inside, 3/5 and 1/5 on a boundary), as pbrt does
 * (pbrt's boundary weights, not the cubic B-spline's 4/6 and 1/6, so that boundaries
 * land where pbrt puts them). An
 * edge shared by more than two triangles is treated as a boundary. The vertices of a
 * level keep their indices in the next, so vertex i of the result is the limit point
 * of control vertex i. Normals are the area-weighted mean of the final faces' normals.
 */
#ifndef CLPT_SUBDIV_H
#define CLPT_SUBDIV_H

#include <stddef.h>
#include <stdint.h>

#include "base/status.h"

typedef struct {
    double *p;        /* 3 per vertex */
    double *n;        /* 3 per vertex, unit (zero where the faces cancel) */
    size_t n_points;
    uint32_t *idx;    /* 3 per triangle */
    size_t n_tris;
} SubdivMesh;

/* Subdivides `levels` times (0: only the limit positions). Every index must be below
 * n_points (the caller checks). ST_INPUT when the result would exceed max_tris
 * triangles (checked before allocating), ST_INTERNAL when memory runs out. */
Status subdiv_loop(const double *p, size_t n_points, const uint32_t *idx, size_t n_tris, int levels,
                   size_t max_tris, SubdivMesh *out, Error *err);
void subdiv_free(SubdivMesh *m);

#endif /* CLPT_SUBDIV_H */
