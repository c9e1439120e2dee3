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

/* The sampling of t in [0, t_max) (t_max may be infinite) along x0 + t d (d unit
 * length) toward point c; 0 when the ray passes through c (D = 0: the density would
 * be a delta) or the interval is empty. */
KFN int equiangular_begin(vec3 x0, vec3 d, vec3 c, float t_max, Equiangular *e)
{
    vec3 oc = v3_sub(c, x0);
    e->delta = v3_dot(oc, d);
    e->D = v3_len(v3_sub(oc, v3_scale(d, e->delta)));
    if (!(e->D > 0.0f) || !(t_max > 0.0f)) return 0;
    e->theta_a = k_atan2(0.0f - e->delta, e->D);
    e->theta_b = t_max < k_as_float(0x7f800000u) ? k_atan2(t_max - e->delta, e->D) : 1.57079633f;
    return e->theta_b > e->theta_a;
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
