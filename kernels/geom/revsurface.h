/*
 * revsurface.h — surfaces of revolution (types.h RevSurface): a profile curve of Bezier
 * segments in the xy plane, revolved about a vertical axis; ray intersection by Newton
 * iteration and the normal from the surface's partial derivatives.
 *
 * In the frame of the axis, a point of the ray o + t*d is at distance r(t) from the axis
 * with r(t)^2 = A t^2 + 2 B t + C, and at height o.y + t d.y. It lies on the surface when
 * some profile point (x(s), y(s)) has the same distance and height:
 *
 *   F(t, s) = ( A t^2 + 2 B t + C - x(s)^2,  o.y + t d.y - y(s) ) = 0.
 *
 * Two unknowns instead of the three of o + t*d = S(s, theta): the angle drops out, and
 * rays along the axis or level with it need no special case. Newton's method solves F
 * from a few starts per segment: the ray is first clipped to the segment's bounding
 * cylinder shell (radius and height range of its control points, which bound the
 * segment, grown by REV_TOL), then REV_STARTS parameters t spread over that clip each
 * start with the profile sample s nearest to the ray point in the (r, y) half-plane,
 * from the ray's entry into the shell. A start converges when its step moves t and s by
 * less than REV_STEP_TOL (relative); two polishing steps follow, and the root counts
 * when 0 <= s <= 1 and |F| is within REV_RESIDUAL. The nearest such root wins
 * (docs/classic-format.md, "Curves and surfaces of revolution").
 */
#ifndef CLPT_REVSURFACE_H
#define CLPT_REVSURFACE_H

#include "util/kmath.h"

#define REV_STARTS 4          /* Newton starts per profile segment */
#define REV_SAMPLES 8         /* profile samples per segment to pick a start's s */
#define REV_ITERATIONS 16     /* Newton steps per start at most */
#define REV_STEP_TOL 1e-5f    /* a converged step moves t and s by less (relative) */
#define REV_TOL 1e-4f         /* the bounding shells' margin, times the surface's size */
#define REV_RESIDUAL 2e-6f    /* accepted |F| of a root: r^2 - x^2 over size^2, and the
                               * height's error over size (a few float roundings) */

/* Point (x, y) and derivative (dx, dy) at s of the Bezier segment whose degree + 1
 * control points are (x, y) pairs at p, by de Casteljau: the last level's two points
 * give both. */
KFN void rev_eval(GLOBAL const float *p, uint degree, float s, float *x, float *y, float *dx, float *dy)
{
    float u = 1.0f - s;
    if (degree == 3u) {
        /* the B-spline pieces: the same steps in scalars, without the private array that
         * OpenCL compilers keep in memory */
        float ax = u * p[0] + s * p[2], ay = u * p[1] + s * p[3];
        float bx1 = u * p[2] + s * p[4], by1 = u * p[3] + s * p[5];
        float cx = u * p[4] + s * p[6], cy = u * p[5] + s * p[7];
        float ex = u * ax + s * bx1, ey = u * ay + s * by1;
        float fx = u * bx1 + s * cx, fy = u * by1 + s * cy;
        *x = u * ex + s * fx;
        *y = u * ey + s * fy;
        *dx = 3.0f * (fx - ex);
        *dy = 3.0f * (fy - ey);
        return;
    }
    float bx[REV_MAX_DEGREE + 1], by[REV_MAX_DEGREE + 1];
    for (uint i = 0; i <= degree; i++) {
        bx[i] = p[2 * i];
        by[i] = p[2 * i + 1];
    }
    for (uint level = degree; level > 1u; level--)
        for (uint i = 0; i < level; i++) {
            bx[i] = u * bx[i] + s * bx[i + 1];
            by[i] = u * by[i] + s * by[i + 1];
        }
    float n = (float)degree;
    *x = u * bx[0] + s * bx[1];
    *y = u * by[0] + s * by[1];
    *dx = n * (bx[1] - bx[0]);
    *dy = n * (by[1] - by[0]);
}

/* The ray's parameter interval [*ta, *tb] inside the shell of radius <= rmax and height
 * lo_y..hi_y (clipped to the caller's interval on entry); 0 when it is empty. */
KFN int rev_clip(float A, float B, float C, float oy, float dy, float rmax, float lo_y, float hi_y,
                 float *ta, float *tb)
{
    if (dy != 0.0f) {
        float t1 = (lo_y - oy) / dy, t2 = (hi_y - oy) / dy;
        *ta = k_fmax(*ta, k_fmin(t1, t2));
        *tb = k_fmin(*tb, k_fmax(t1, t2));
    } else if (!(oy >= lo_y && oy <= hi_y)) {
        return 0;
    }
    float c = C - rmax * rmax;
    if (A > 0.0f) {
        float disc = B * B - A * c;
        if (!(disc >= 0.0f)) return 0;
        float q = k_sqrt(disc);
        *ta = k_fmax(*ta, (-B - q) / A);
        *tb = k_fmin(*tb, (-B + q) / A);
    } else if (!(c <= 0.0f)) {
        return 0;
    }
    return *ta <= *tb;
}

/* Newton's method on F from (t, s); 1 with the root in *t, *s when it converged inside
 * the segment (0 <= s <= 1) to within REV_RESIDUAL (size: the surface's). */
KFN int rev_newton(GLOBAL const float *p, uint degree, float A, float B, float C, float oy, float dy, float size,
                   float w, float *t_io, float *s_io)
{
    float t = *t_io, s = *s_io;
    int pinned = 0;
    for (int it = 0; it < REV_ITERATIONS; it++) {
        float x, y, dx, dydS;
        rev_eval(p, degree, s, &x, &y, &dx, &dydS);
        float f1 = (A * t + 2.0f * B) * t + C - x * x;
        float f2 = oy + t * dy - y;
        float j11 = 2.0f * (A * t + B), j12 = -2.0f * x * dx;
        float j21 = dy, j22 = -dydS;
        float det = j11 * j22 - j12 * j21;
        if (!(k_fabs(det) > 0.0f)) return 0;
        float step_t = (f1 * j22 - j12 * f2) / det;
        float step_s = (j11 * f2 - j21 * f1) / det;
        if (!(k_fabs(step_t) < 1e30f) || !(k_fabs(step_s) < 1e30f)) return 0;
        t -= step_t;
        /* a step may leave the segment: projecting s back keeps the iteration on the
         * polynomial piece it models (beyond [0, 1] it is not the profile) */
        float s_free = s - step_s;
        s = k_clamp(s_free, 0.0f, 1.0f);
        int converged = k_fabs(step_t) <= REV_STEP_TOL * (k_fabs(t) + size) && k_fabs(step_s) <= REV_STEP_TOL;
        /* Give up early on a start that leads elsewhere: t far outside the clip [0, w]
         * (a root there lies outside this segment's shell, where another segment or
         * nothing is), or s pushed past an end of the segment twice running (the root
         * is on a neighbouring piece). Most rays through a shell miss the surface, and
         * these end their starts in 2 or 3 steps instead of REV_ITERATIONS. */
        if (!(t >= -w && t <= 2.0f * w)) return 0;
        pinned = (s_free != s && !converged) ? pinned + 1 : 0;
        if (pinned == 2) return 0;
        if (converged) {
            /* Newton converges quadratically: two more steps take the root from 1e-5 to
             * the rounding of the floats, which a ray leaving the surface needs (its
             * origin is moved off the surface by only 256 ulps, surface.h) */
            for (int polish = 0; polish < 2; polish++) {
                rev_eval(p, degree, s, &x, &y, &dx, &dydS);
                f1 = (A * t + 2.0f * B) * t + C - x * x;
                f2 = oy + t * dy - y;
                j11 = 2.0f * (A * t + B);
                j12 = -2.0f * x * dx;
                j22 = -dydS;
                det = j11 * j22 - j12 * j21;
                if (!(k_fabs(det) > 0.0f)) break;
                t -= (f1 * j22 - j12 * f2) / det;
                s = k_clamp(s - (j11 * f2 - j21 * f1) / det, 0.0f, 1.0f);
            }
            /* a root within the rounding of the floats; an iteration that stalled near
             * the ray's origin, when that lies just off the surface (a ray leaving it),
             * is further away than this and must not count */
            rev_eval(p, degree, s, &x, &y, &dx, &dydS);
            f1 = (A * t + 2.0f * B) * t + C - x * x;
            f2 = oy + t * dy - y;
            if (!(k_fabs(f1) <= REV_RESIDUAL * size * size && k_fabs(f2) <= REV_RESIDUAL * size)) return 0;
            *t_io = t;
            *s_io = s;
            return 1;
        }
    }
    return 0;
}

/* The profile samples s = k / REV_SAMPLES, k = 0 .. REV_SAMPLES, of a segment. */
KFN void rev_samples(GLOBAL const float *p, uint degree, float *sx, float *sy)
{
    for (int k = 0; k <= REV_SAMPLES; k++) {
        float dx, dy;
        rev_eval(p, degree, (float)k * (1.0f / (float)REV_SAMPLES), &sx[k], &sy[k], &dx, &dy);
    }
}

/* The parameter of the sample nearest to (r, y) in the (distance from the axis, height)
 * half-plane. */
KFN float rev_nearest_s(const float *sx, const float *sy, float r, float y)
{
    float best_s = 0.0f, best_d = K_INF;
    for (int k = 0; k <= REV_SAMPLES; k++) {
        float d = k_sqr(k_fabs(sx[k]) - r) + k_sqr(sy[k] - y);
        if (d < best_d) {
            best_d = d;
            best_s = (float)k * (1.0f / (float)REV_SAMPLES);
        }
    }
    return best_s;
}

/* Ray against the surface; on a hit, hit->u is the segment's parameter s and hit->v the
 * segment index (as a float), for rev_normal. */
KFN int revsurface_intersect(RevSurface rs, GLOBAL const float *points, Ray ray, Hit *hit)
{
    float ox = ray.o.x - rs.axis_x, oz = ray.o.z - rs.axis_z, oy = ray.o.y, dy = ray.d.y;
    float A = ray.d.x * ray.d.x + ray.d.z * ray.d.z;
    float B = ox * ray.d.x + oz * ray.d.z;
    float C = ox * ox + oz * oz;
    float size = k_fmax(rs.hi.x - rs.lo.x, rs.hi.y - rs.lo.y);
    float tol = REV_TOL * size;
    float best = ray.tmax;
    int found = 0;
    for (uint seg = 0; seg < rs.n_segments; seg++) {
        GLOBAL const float *p = points + 2u * (rs.first + seg * rs.degree);
        float rmax = 0.0f, lo_y = p[1], hi_y = p[1];
        for (uint i = 0; i <= rs.degree; i++) {
            rmax = k_fmax(rmax, k_fabs(p[2 * i]));
            lo_y = k_fmin(lo_y, p[2 * i + 1]);
            hi_y = k_fmax(hi_y, p[2 * i + 1]);
        }
        /* the shell grown by the tolerance: a silhouette hit may lie just outside */
        float ta = ray.tmin, tb = best;
        if (!rev_clip(A, B, C, oy, dy, rmax + tol, lo_y - tol, hi_y + tol, &ta, &tb)) continue;
        /* Newton works from the ray's entry into the shell, o' = o + ta d: from a far
         * origin, C and A t^2 + 2 B t would be large and cancel to the small r^2, which
         * loses the digits the hit point needs */
        float px = ox + ta * ray.d.x, pz = oz + ta * ray.d.z, py = oy + ta * dy;
        float B2 = px * ray.d.x + pz * ray.d.z, C2 = px * px + pz * pz;
        float sx[REV_SAMPLES + 1], sy[REV_SAMPLES + 1];
        rev_samples(p, rs.degree, sx, sy);
        for (int k = 0; k < REV_STARTS; k++) {
            float t = (tb - ta) * (((float)k + 0.5f) * (1.0f / (float)REV_STARTS));
            float r = k_safe_sqrt((A * t + 2.0f * B2) * t + C2);
            float s = rev_nearest_s(sx, sy, r, py + t * dy);
            if (!rev_newton(p, rs.degree, A, B2, C2, py, dy, size, tb - ta, &t, &s)) continue;
            t += ta;
            if (t > ray.tmin && t < best) {
                best = t;
                hit->t = t;
                hit->u = s;
                hit->v = (float)seg;
                found = 1;
            }
        }
    }
    return found;
}

/* The unit normal at point q of the surface hit at (segment, s): dP/ds x dP/dtheta,
 * which is (y' qx, -x x', y' qz) in the frame of the axis (qx, qz the offsets from it);
 * for a profile drawn upward at x > 0 it points away from the axis. Where it vanishes
 * (on the axis, or at a cusp) the profile's own normal at theta = 0 stands in. */
KFN vec3 revsurface_normal(RevSurface rs, GLOBAL const float *points, vec3 q, float s, float seg)
{
    GLOBAL const float *p = points + 2u * (rs.first + (uint)seg * rs.degree);
    float x, y, dx, dy;
    rev_eval(p, rs.degree, s, &x, &y, &dx, &dy);
    vec3 n = v3(dy * (q.x - rs.axis_x), -x * dx, dy * (q.z - rs.axis_z));
    float len = v3_len(n);
    if (!(len > 0.0f)) {
        n = v3(dy, -dx, 0.0f);
        len = v3_len(n);
        if (!(len > 0.0f)) return v3(0.0f, 1.0f, 0.0f);
    }
    return v3_scale(n, 1.0f / len);
}

#endif /* CLPT_REVSURFACE_H */
