/*
 * curve.h — the profile curves of Tsinghua's PA2/PA3 scene format (BezierCurve,
 * BsplineCurve) and the surfaces of revolution made from them (RevSurface): evaluation,
 * conversion to the Bezier segments the kernels intersect (types.h RevSurface), and a
 * triangle mesh of a revolved profile (for transforms the kernels cannot take, and to
 * check the exact surface against).
 *
 * A BezierCurve of n control points is one Bezier curve of degree n - 1. A BsplineCurve
 * is the course's uniform cubic B-spline: n control points, knots t_i = i / (n + 3) for
 * i = 0 .. n + 3 (the starter code's i / (n' + k + 1) with n' = n - 1 and k = 3), drawn
 * over [t_3, t_n], which is n - 3 polynomial pieces; each piece is stored as the cubic
 * Bezier segment it equals.
 */
#ifndef CLPT_CURVE_H
#define CLPT_CURVE_H

#include <stddef.h>

#include "base/status.h"
#include "scene/scene.h"
#include "scene/transform.h"

typedef enum { CURVE_BEZIER = 0, CURVE_BSPLINE = 1 } CurveKind;

/* Fewest control points of each kind (the course's starter code: 4 for both, and a
 * BezierCurve's count must be 3k + 1), and the most a Bezier profile may have (its
 * degree is bounded by REV_MAX_DEGREE: the kernels evaluate it in private memory). */
#define CURVE_MIN_POINTS 4u
#define CURVE_MAX_BEZIER_POINTS (REV_MAX_DEGREE + 1u)
/* The most control points of any curve: a bound on what one profile may cost a ray
 * (each B-spline piece is searched), checked as the points are read. */
#define CURVE_MAX_POINTS 4096u

/* Point and derivative at s in [0, 1] of the Bezier curve of `degree` whose control
 * points are (x, y) pairs at p (de Casteljau, in double). */
void curve_bezier_eval(const float *p, unsigned degree, double s, double xy[2], double d[2]);

/* The course's B-spline of n control points (x, y pairs at p) at parameter t in
 * [t_3, t_n] (see the top), by the Cox-de Boor recursion on its knots; basis, when not
 * NULL, receives the n basis functions' values at t. */
void curve_bspline_eval(const float *p, size_t n, double t, double xy[2], double *basis);

/* The Bezier segments equal to the curve: *n_segments segments of *degree sharing end
 * points, n_segments * degree + 1 (x, y) pairs written to out (room for 6n floats). */
void curve_to_segments(CurveKind kind, const float *p, size_t n, float *out, unsigned *n_segments,
                       unsigned *degree);

/* Appends a mesh of the surface of revolution whose profile is n_segments Bezier
 * segments of `degree` ((x, y) pairs at xy, as curve_to_segments writes them), revolved
 * about the y axis and then carried by m: `steps` rows per segment by `around` columns
 * of quads split in two, with the surface's normals (dP/ds x dP/dtheta, as
 * revsurface_normal) as shading normals and each triangle wound so that its geometric
 * normal agrees with them. */
Status curve_mesh_revsurface(Scene *s, const float *xy, unsigned n_segments, unsigned degree, const Transform *m,
                             uint material, unsigned steps, unsigned around, Error *err);

#endif /* CLPT_CURVE_H */
