/* curve.c — see curve.h. */
#include "scene/curve.h"

#include <math.h>
#include <string.h>

#include "util/kmath.h"

void curve_bezier_eval(const float *p, unsigned degree, double s, double xy[2], double d[2])
{
    double bx[REV_MAX_DEGREE + 1], by[REV_MAX_DEGREE + 1];
    for (unsigned i = 0; i <= degree; i++) {
        bx[i] = p[2 * i];
        by[i] = p[2 * i + 1];
    }
    double u = 1.0 - s;
    for (unsigned level = degree; level > 1; level--)
        for (unsigned i = 0; i < level; i++) {
            bx[i] = u * bx[i] + s * bx[i + 1];
            by[i] = u * by[i] + s * by[i + 1];
        }
    xy[0] = u * bx[0] + s * bx[1];
    xy[1] = u * by[0] + s * by[1];
    d[0] = degree * (bx[1] - bx[0]);
    d[1] = degree * (by[1] - by[0]);
}

/* Cox-de Boor: the degree-3 basis functions N_{i,3}(t) on the knots t_i = i / (n + 3),
 * i = 0 .. n + 3, from the degree-0 ones, in place (n + 3 entries of room in b). */
static void bspline_basis(size_t n, double t, double *b)
{
    size_t nk = n + 3;        /* intervals [t_i, t_i+1), i = 0 .. nk - 1 */
    double h = 1.0 / (double)nk;
    for (size_t i = 0; i < nk; i++) b[i] = (t >= i * h && t < (i + 1) * h) ? 1.0 : 0.0;
    /* t at the last drawn knot t_n belongs to the piece before it */
    if (t >= n * h) {
        for (size_t i = 0; i < nk; i++) b[i] = 0.0;
        b[n - 1] = 1.0;
    }
    for (size_t k = 1; k <= 3; k++)
        for (size_t i = 0; i + k < nk; i++) {
            double a = (t - i * h) / (k * h), c = ((i + k + 1) * h - t) / (k * h);
            b[i] = a * b[i] + c * b[i + 1];
        }
}

void curve_bspline_eval(const float *p, size_t n, double t, double xy[2], double *basis)
{
    double b[CURVE_MAX_POINTS + 8];
    xy[0] = xy[1] = 0.0;
    if (n + 4 > sizeof b / sizeof b[0]) return;
    bspline_basis(n, t, b);
    for (size_t i = 0; i < n; i++) {
        xy[0] += b[i] * p[2 * i];
        xy[1] += b[i] * p[2 * i + 1];
        if (basis) basis[i] = b[i];
    }
}

void curve_to_segments(CurveKind kind, const float *p, size_t n, float *out, unsigned *n_segments,
                       unsigned *degree)
{
    if (kind == CURVE_BEZIER) {
        memcpy(out, p, 2 * n * sizeof(float));
        *n_segments = 1;
        *degree = (unsigned)(n - 1);
        return;
    }
    /* piece j (control points j .. j+3) of a uniform cubic B-spline is the cubic Bezier
     * (P0 + 4P1 + P2)/6, (2P1 + P2)/3, (P1 + 2P2)/3, (P1 + 4P2 + P3)/6; the last point
     * of a piece is the first of the next, computed once */
    *n_segments = (unsigned)(n - 3);
    *degree = 3;
    for (size_t j = 0; j + 3 < n; j++)
        for (int c = 0; c < 2; c++) {
            double p0 = p[2 * j + c], p1 = p[2 * (j + 1) + c], p2 = p[2 * (j + 2) + c], p3 = p[2 * (j + 3) + c];
            float *o = out + 2 * (3 * j) + c;
            if (j == 0) o[0] = (float)((p0 + 4.0 * p1 + p2) / 6.0);
            o[2] = (float)((2.0 * p1 + p2) / 3.0);
            o[4] = (float)((p1 + 2.0 * p2) / 3.0);
            o[6] = (float)((p1 + 4.0 * p2 + p3) / 6.0);
        }
}

/* The surface's point and unit normal at (s, theta) of the segment at p (frame of the
 * axis), with revsurface_normal's fallback where the cross product vanishes. */
static void revolve(const float *p, unsigned degree, double s, double theta, double q[3], double n[3])
{
    double xy[2], d[2];
    curve_bezier_eval(p, degree, s, xy, d);
    double c = cos(theta), sn = sin(theta);
    q[0] = xy[0] * c;
    q[1] = xy[1];
    q[2] = xy[0] * sn;
    n[0] = d[1] * q[0];
    n[1] = -xy[0] * d[0];
    n[2] = d[1] * q[2];
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0)) {
        n[0] = d[1];
        n[1] = -d[0];
        n[2] = 0.0;
        len = sqrt(n[0] * n[0] + n[1] * n[1]);
        if (!(len > 0.0)) {
            n[0] = n[2] = 0.0;
            n[1] = len = 1.0;
        }
    }
    for (int k = 0; k < 3; k++) n[k] /= len;
}

/* n through the normal matrix nm, unit length. */
static vec3 normal_through(double nm[3][3], const double n[3])
{
    double v[3];
    for (int i = 0; i < 3; i++) v[i] = nm[i][0] * n[0] + nm[i][1] * n[1] + nm[i][2] * n[2];
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(len > 0.0)) return v3(0.0f, 1.0f, 0.0f);
    return v3((float)(v[0] / len), (float)(v[1] / len), (float)(v[2] / len));
}

/* One triangle of the mesh: corners a, b, c (world) with normals na, nb, nc; flip
 * reverses the winding (a mirroring transform). */
static Status mesh_tri(Scene *s, const vec3 p[3], const vec3 n[3], int flip, uint material, Error *err)
{
    int i1 = flip ? 2 : 1, i2 = flip ? 1 : 2;
    TriShading sh = { .n0 = n[0], .n1 = n[i1], .n2 = n[i2], .flags = TRI_HAS_NORMALS };
    uint si;
    Status st = scene_add_shading(s, sh, &si, err);
    if (st) return st;
    Triangle t = { .p0 = p[0], .p1 = p[i1], .p2 = p[i2], .material = material, .shading = si };
    return scene_add_triangle(s, t, err);
}

Status curve_mesh_revsurface(Scene *s, const float *xy, unsigned n_segments, unsigned degree, const Transform *m,
                             uint material, unsigned steps, unsigned around, Error *err)
{
    double nm[3][3];
    if (!transform_normal_matrix(m, nm)) return error_set(err, ST_INTERNAL, "singular transform");
    int flip = transform_det(m) < 0.0;
    for (unsigned seg = 0; seg < n_segments; seg++) {
        const float *p = xy + 2u * seg * degree;
        for (unsigned i = 0; i < steps; i++)
            for (unsigned j = 0; j < around; j++) {
                /* corners 0 (s, th), 1 (s + ds, th), 2 (s + ds, th + dth), 3 (s, th + dth):
                 * (0 1 2) and (0 2 3) turn like dP/ds x dP/dtheta */
                vec3 p4[4], n4[4];
                for (int k = 0; k < 4; k++) {
                    double sv = (double)(i + (k == 1 || k == 2)) / steps;
                    double th = 2.0 * M_PI * (double)((j + (k >= 2)) % around) / around;
                    double q[3], n[3];
                    revolve(p, degree, sv, th, q, n);
                    p4[k] = transform_point(m, v3((float)q[0], (float)q[1], (float)q[2]));
                    n4[k] = normal_through(nm, n);
                }
                vec3 ta[3] = { p4[0], p4[1], p4[2] }, na[3] = { n4[0], n4[1], n4[2] };
                vec3 tb[3] = { p4[0], p4[2], p4[3] }, nb[3] = { n4[0], n4[2], n4[3] };
                Status st = mesh_tri(s, ta, na, flip, material, err);
                if (!st) st = mesh_tri(s, tb, nb, flip, material, err);
                if (st) return st;
            }
    }
    return ST_OK;
}
