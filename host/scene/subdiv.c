/* subdiv.c — Loop subdivision with limit positions (subdiv.h). */
#include "scene/subdiv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    uint32_t a, b;       /* a < b */
    uint32_t opp[2];     /* the vertices opposite the edge in its first two triangles */
    uint32_t count;      /* triangles sharing it */
    uint32_t next;       /* next edge with the same `a`, or UINT32_MAX */
} Edge;

typedef struct {
    Edge *e;
    size_t n;
    uint32_t *head;      /* per vertex: its first edge (as the smaller end) */
    uint32_t *tri_edge;  /* per triangle corner k: the edge (k, k+1) */
} EdgeTable;

static void edges_free(EdgeTable *t)
{
    free(t->e);
    free(t->head);
    free(t->tri_edge);
    memset(t, 0, sizeof *t);
}

/* Finds every edge; linear in the triangles (a vertex's edges are few). */
static Status edges_build(EdgeTable *t, size_t n_points, const uint32_t *idx, size_t n_tris, Error *err)
{
    memset(t, 0, sizeof *t);
    t->e = malloc(3 * n_tris * sizeof *t->e + 1);
    t->head = malloc(n_points * sizeof *t->head + 1);
    t->tri_edge = malloc(3 * n_tris * sizeof *t->tri_edge + 1);
    if (!t->e || !t->head || !t->tri_edge) {
        edges_free(t);
        return error_set(err, ST_INTERNAL, "out of memory subdividing a mesh");
    }
    for (size_t i = 0; i < n_points; i++) t->head[i] = UINT32_MAX;
    for (size_t f = 0; f < n_tris; f++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = idx[3 * f + k], b = idx[3 * f + (k + 1) % 3], o = idx[3 * f + (k + 2) % 3];
            if (a > b) {
                uint32_t s = a;
                a = b;
                b = s;
            }
            uint32_t i = t->head[a];
            while (i != UINT32_MAX && t->e[i].b != b) i = t->e[i].next;
            if (i == UINT32_MAX) {
                i = (uint32_t)t->n++;
                t->e[i] = (Edge){ a, b, { o, UINT32_MAX }, 0, t->head[a] };
                t->head[a] = i;
            } else if (t->e[i].count == 1) {
                t->e[i].opp[1] = o;
            }
            t->e[i].count++;
            t->tri_edge[3 * f + k] = i;
        }
    return ST_OK;
}

static double loop_beta(double n)
{
    return n == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * n);
}

/* New positions of the vertices that stay (even: limit = 0) or their limit points
 * (limit = 1), into q (3 per vertex). */
static Status move_vertices(const double *p, size_t n_points, const EdgeTable *t, int limit, double *q, Error *err)
{
    double *sum = calloc(3 * n_points + 1, sizeof *sum), *bsum = calloc(3 * n_points + 1, sizeof *bsum);
    uint32_t *val = calloc(n_points + 1, sizeof *val), *bval = calloc(n_points + 1, sizeof *bval);
    if (!sum || !bsum || !val || !bval) {
        free(sum);
        free(bsum);
        free(val);
        free(bval);
        return error_set(err, ST_INTERNAL, "out of memory subdividing a mesh");
    }
    for (size_t i = 0; i < t->n; i++) {
        const Edge *e = &t->e[i];
        int boundary = e->count != 2;
        for (int c = 0; c < 3; c++) {
            sum[3 * e->a + c] += p[3 * e->b + c];
            sum[3 * e->b + c] += p[3 * e->a + c];
            if (boundary) {
                bsum[3 * e->a + c] += p[3 * e->b + c];
                bsum[3 * e->b + c] += p[3 * e->a + c];
            }
        }
        val[e->a]++;
        val[e->b]++;
        if (boundary) {
            bval[e->a]++;
            bval[e->b]++;
        }
    }
    for (size_t v = 0; v < n_points; v++) {
        const double *pv = p + 3 * v;
        double *o = q + 3 * v;
        if (val[v] == 0) {
            memcpy(o, pv, 3 * sizeof *o);
        } else if (bval[v] == 2) {
            /* on a boundary: only the two boundary neighbours count */
            double w = limit ? 0.2 : 0.125;
            for (int c = 0; c < 3; c++) o[c] = (1 - 2 * w) * pv[c] + w * bsum[3 * v + c];
        } else if (bval[v] > 0) {
            memcpy(o, pv, 3 * sizeof *o);   /* a corner of several boundaries stays */
        } else {
            double n = val[v], beta = loop_beta(n);
            double w = limit ? 1.0 / (n + 3.0 / (8.0 * beta)) : beta;
            for (int c = 0; c < 3; c++) o[c] = (1 - n * w) * pv[c] + w * sum[3 * v + c];
        }
    }
    free(sum);
    free(bsum);
    free(val);
    free(bval);
    return ST_OK;
}

/* One level: even vertices keep their indices, edge vertices follow them. */
static Status subdivide_once(SubdivMesh *m, Error *err)
{
    EdgeTable t;
    Status st = edges_build(&t, m->n_points, m->idx, m->n_tris, err);
    if (st) return st;
    size_t np = m->n_points + t.n, nt = 4 * m->n_tris;
    double *q = malloc(3 * np * sizeof *q);
    uint32_t *idx = malloc(3 * nt * sizeof *idx);
    if (!q || !idx || (st = move_vertices(m->p, m->n_points, &t, 0, q, err))) {
        free(q);
        free(idx);
        edges_free(&t);
        return st ? st : error_set(err, ST_INTERNAL, "out of memory subdividing a mesh");
    }
    for (size_t i = 0; i < t.n; i++) {
        const Edge *e = &t.e[i];
        double *o = q + 3 * (m->n_points + i);
        for (int c = 0; c < 3; c++) {
            double a = m->p[3 * e->a + c], b = m->p[3 * e->b + c];
            o[c] = e->count == 2 ? 0.375 * (a + b) + 0.125 * (m->p[3 * e->opp[0] + c] + m->p[3 * e->opp[1] + c])
                                 : 0.5 * (a + b);
        }
    }
    for (size_t f = 0; f < m->n_tris; f++) {
        uint32_t v[3], e[3];
        for (int k = 0; k < 3; k++) {
            v[k] = m->idx[3 * f + k];
            e[k] = (uint32_t)(m->n_points + t.tri_edge[3 * f + k]);   /* edge k -> k+1 */
        }
        uint32_t *o = idx + 12 * f;
        uint32_t tris[12] = { v[0], e[0], e[2], v[1], e[1], e[0], v[2], e[2], e[1], e[0], e[1], e[2] };
        memcpy(o, tris, sizeof tris);
    }
    edges_free(&t);
    free(m->p);
    free(m->idx);
    m->p = q;
    m->idx = idx;
    m->n_points = np;
    m->n_tris = nt;
    return ST_OK;
}

static void vertex_normals(SubdivMesh *m)
{
    memset(m->n, 0, 3 * m->n_points * sizeof *m->n);
    for (size_t f = 0; f < m->n_tris; f++) {
        const uint32_t *v = m->idx + 3 * f;
        const double *a = m->p + 3 * v[0], *b = m->p + 3 * v[1], *c = m->p + 3 * v[2];
        double e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] }, e2[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
        double n[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++) m->n[3 * v[k] + d] += n[d];
    }
    for (size_t i = 0; i < m->n_points; i++) {
        double *n = m->n + 3 * i, l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (l > 0 && isfinite(l))
            for (int d = 0; d < 3; d++) n[d] /= l;
        else
            n[0] = n[1] = n[2] = 0;
    }
}

Status subdiv_loop(const double *p, size_t n_points, const uint32_t *idx, size_t n_tris, int levels,
                   size_t max_tris, SubdivMesh *out, Error *err)
{
    memset(out, 0, sizeof *out);
    if (levels < 0) levels = 0;
    size_t tris = n_tris;
    for (int l = 0; l < levels; l++) {
        if (tris > max_tris / 4)
            return error_set(err, ST_INPUT, "Loop subdivision to level %d of %zu triangles makes more than %zu "
                             "triangles", levels, n_tris, max_tris);
        tris *= 4;
    }
    if (tris > max_tris || n_points > UINT32_MAX / 4)
        return error_set(err, ST_INPUT, "a subdivision mesh of more than %zu triangles", max_tris);
    out->p = malloc(3 * n_points * sizeof *out->p + 1);
    out->idx = malloc(3 * n_tris * sizeof *out->idx + 1);
    if (!out->p || !out->idx) {
        subdiv_free(out);
        return error_set(err, ST_INTERNAL, "out of memory subdividing a mesh");
    }
    memcpy(out->p, p, 3 * n_points * sizeof *p);
    memcpy(out->idx, idx, 3 * n_tris * sizeof *idx);
    out->n_points = n_points;
    out->n_tris = n_tris;
    Status st = ST_OK;
    for (int l = 0; l < levels && !st; l++) st = subdivide_once(out, err);
    EdgeTable t;
    double *q = NULL;
    if (!st) st = edges_build(&t, out->n_points, out->idx, out->n_tris, err);
    if (!st) {
        q = malloc(3 * out->n_points * sizeof *q + 1);
        st = q ? move_vertices(out->p, out->n_points, &t, 1, q, err)
               : error_set(err, ST_INTERNAL, "out of memory subdividing a mesh");
        edges_free(&t);
    }
    if (!st) {
        free(out->p);
        out->p = q;
        out->n = malloc(3 * out->n_points * sizeof *out->n + 1);
        if (!out->n) st = error_set(err, ST_INTERNAL, "out of memory subdividing a mesh");
        else vertex_normals(out);
    } else {
        free(q);
    }
    if (st) subdiv_free(out);
    return st;
}

void subdiv_free(SubdivMesh *m)
{
    free(m->p);
    free(m->n);
    free(m->idx);
    memset(m, 0, sizeof *m);
}
