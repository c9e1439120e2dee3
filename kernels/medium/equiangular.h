/*
 * equiangular.h — equiangular sampling of a distance along a ray toward a point: Kulla
 * and Fajardo, "Importance sampling techniques for path tracing in participating
 * media", EGSR 2012, sec. 4.1. The in-scattered light of a point light falls off as
 * 1 / r(t)^2 along the ray, r(t)^2 = D^2 + (t - delta)^2 (delta the ray's distance of
 * closest approach, D the light's distance from the ray there); sampling t uniformly
 * in the angle subtended at the light, theta = atan((t - delta) / D), has a density
 * proportional to exactly that factor, which free-flight sampling does not follow (it
 * leaves fireflies at the stops nearest a light inside a medium). Used by
 * medium_path.h's next-event estimation toward point and spot lights, by one-sample
 * MIS against free-flight sampling (docs/media.md).
 */
#ifndef CLPT_EQUIANGULAR_H
#define CLPT_EQUIANGULAR_H

#include "util/kmath.h"
#include "types.h"

typedef struct {
    float delta;          /* the ray's distance to its point closest to the light */
    float D;              /* the light's distance from the ray */
    float theta_a, theta_b;   /* the angles at the light of t = 0 and of t = t_max */
} Equiangular;

/* The sampling of t in [t_min, t_max) (t_max may be infinite) along x0 + t d (d unit
 * length) toward point c; 0 when the ray passes through c (D = 0: the density would
 * be a delta) or the interval is empty. */
KFN int equiangular_begin(vec3 x0, vec3 d, vec3 c, float t_min, float t_max, Equiangular *e)
{
    vec3 oc = v3_sub(c, x0);
    e->delta = v3_dot(oc, d);
    e->D = v3_len(v3_sub(oc, v3_scale(d, e->delta)));
    if (!(e->D > 0.0f) || !(t_max > t_min)) return 0;
    e->theta_a = k_atan2(t_min - e->delta, e->D);
    e->theta_b = t_max < k_as_float(0x7f800000u) ? k_atan2(t_max - e->delta, e->D) : 1.57079633f;
    return e->theta_b > e->theta_a;
}

/* Whether w (from the apex) is inside the cone of unit axis a and cosine cos_outer. */
KFN int equiangular_in_cone(vec3 w, vec3 a, float cos_outer)
{
    return v3_dot(w, a) >= cos_outer * v3_len(w);
}

/* The part [*lo, *hi) of [0, t_max) where the ray x0 + t d is inside a spot light's
 * cone (apex c, unit axis a, cosine cos_outer > 0, a convex cone, so one interval):
 * outside it the light sends nothing, and equiangular samples there would be wasted.
 * The interval's ends are among 0, t_max and the roots of (w.a)^2 = cos^2 |w|^2,
 * w = x0 + t d - c; each piece between them is tested at a point inside it, and the
 * result is widened by a little, so that rounding can only make it longer (a longer
 * interval stays unbiased; MIS covers the rest anyway). Returns 0 when the ray misses
 * the cone. */
KFN int equiangular_cone_clip(vec3 x0, vec3 d, vec3 c, vec3 a, float cos_outer, float t_max, float *lo, float *hi)
{
    vec3 co = v3_sub(x0, c);
    float da = v3_dot(d, a), ca = v3_dot(co, a), c2 = cos_outer * cos_outer;
    float A = da * da - c2, B = 2.0f * (da * ca - c2 * v3_dot(d, co)), C = ca * ca - c2 * v3_dot(co, co);
    float pts[4];
    int n = 0;
    pts[n++] = 0.0f;
    float disc = B * B - 4.0f * A * C;
    if (k_fabs(A) > 1e-7f && disc >= 0.0f) {
        float q = -0.5f * (B + k_copysign(k_sqrt(disc), B));
        float r1 = q / A, r2 = q != 0.0f ? C / q : r1;
        float rl = k_fmin(r1, r2), rh = k_fmax(r1, r2);
        if (rl > 0.0f && rl < t_max) pts[n++] = rl;
        if (rh > 0.0f && rh < t_max && rh > pts[n - 1]) pts[n++] = rh;
    } else if (!(k_fabs(A) > 1e-7f) && B != 0.0f) {
        float r = -C / B;
        if (r > 0.0f && r < t_max) pts[n++] = r;
    }
    pts[n] = t_max;
    float first = -1.0f, last = -1.0f;
    for (int i = 0; i < n; i++) {
        float m = pts[i + 1] < k_as_float(0x7f800000u) ? 0.5f * (pts[i] + pts[i + 1]) : 2.0f * pts[i] + 1.0f;
        if (equiangular_in_cone(v3_add(co, v3_scale(d, m)), a, cos_outer)) {
            if (first < 0.0f) first = pts[i];
            last = pts[i + 1];
        }
    }
    if (first < 0.0f) return 0;
    float slack = 1e-3f * (v3_len(co) + first);
    *lo = k_fmax(first - slack, 0.0f);
    *hi = last < k_as_float(0x7f800000u) ? k_fmin(last + 1e-3f * (v3_len(co) + last), t_max) : t_max;
    return 1;
}

/* The distance of uniform u: delta + D tan(theta_a + u (theta_b - theta_a)). */
KFN float equiangular_sample(Equiangular e, float u)
{
    float s, c;
    k_sincos(e.theta_a + u * (e.theta_b - e.theta_a), &s, &c);
    return e.delta + e.D * s / c;
}

/* The density of distance t: D / ((theta_b - theta_a) (D^2 + (t - delta)^2)). */
KFN float equiangular_pdf(Equiangular e, float t)
{
    float s = t - e.delta;
    return e.D / ((e.theta_b - e.theta_a) * (e.D * e.D + s * s));
}

#endif /* CLPT_EQUIANGULAR_H */
