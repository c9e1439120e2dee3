/*
 * sampling.h — warping uniform random numbers into the distributions the integrator
 * draws from. Each function documents the density of what it returns.
 */
#ifndef CLPT_SAMPLING_H
#define CLPT_SAMPLING_H

#include "util/kmath.h"

/* Uniform point on the unit disk, Shirley & Chiu's concentric mapping (keeps
 * stratification and has low distortion). The angle is pi/4 b/a from the x axis or
 * pi/4 a/b from the y axis (phi = pi/2 - that), within pi/4 either way: its sine and
 * cosine need no range reduction, and the second case swaps them, by selects. (Through
 * k_sincos, the random choice between its quadrants 0 and 1 was a mispredicted branch:
 * this function was 8% of a Cornell box render on PoCL.) */
KFN void sample_disk(float u1, float u2, float *x, float *y)
{
    float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
    if (a == 0.0f && b == 0.0f) { *x = 0.0f; *y = 0.0f; return; }
    int about_x = a * a > b * b;
    float r = about_x ? a : b;
    float s, c;
    k_sincos_quarter(0.785398163f * ((about_x ? b : a) / r), &s, &c);
    *x = r * (about_x ? c : s);
    *y = r * (about_x ? s : c);
}

/* Cosine-weighted direction about +z; pdf = z / pi. */
KFN vec3 sample_cosine_hemisphere(float u1, float u2)
{
    float x, y;
    sample_disk(u1, u2, &x, &y);
    return v3(x, y, k_safe_sqrt(1.0f - x * x - y * y));
}

/* Uniform direction on the unit sphere; pdf = 1 / (4 pi). */
KFN vec3 sample_sphere_dir(float u1, float u2)
{
    float z = 1.0f - 2.0f * u1;
    float r = k_safe_sqrt(1.0f - z * z);
    float s, c;
    k_sincos(K_TWO_PI * u2, &s, &c);
    return v3(r * c, r * s, z);
}

/* Uniform point in the unit ball (radius from the cube root keeps it uniform). */
KFN vec3 sample_ball(float u1, float u2, float u3)
{
    return v3_scale(sample_sphere_dir(u1, u2), k_cbrt(u3));
}

/* Uniform point on a triangle as barycentrics (b1, b2) of p1 and p2; pdf = 1 / area. */
KFN void sample_triangle(float u1, float u2, float *b1, float *b2)
{
    float su = k_sqrt(u1);
    *b1 = 1.0f - su;
    *b2 = u2 * su;
}

#endif /* CLPT_SAMPLING_H */
