/*
 * kmath.h — vector algebra and the few transcendental functions the kernels need.
 *
 * The transcendental functions are built from + - * / and sqrt only, so PoCL, a GPU
 * driver and gcc all compute the same bits (see compat.h); their accuracy (a few 1e-7
 * absolute) is far below what a path tracer can see.
 */
#ifndef CLPT_KMATH_H
#define CLPT_KMATH_H

#include "types.h"

#define K_PI 3.14159265358979f
#define K_INV_PI 0.318309886183791f
#define K_TWO_PI 6.28318530717959f

KFN vec3 v3(float x, float y, float z) { vec3 r; r.x = x; r.y = y; r.z = z; return r; }
KFN vec3 v3s(float s) { return v3(s, s, s); }
KFN vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
KFN vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
KFN vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
KFN vec3 v3_scale(vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
KFN vec3 v3_neg(vec3 a) { return v3(-a.x, -a.y, -a.z); }
/* a + b*s, written out so both compilers evaluate the same two roundings. */
KFN vec3 v3_madd(vec3 a, vec3 b, float s) { return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
KFN float v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KFN vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
KFN float v3_len(vec3 a) { return k_sqrt(v3_dot(a, a)); }
KFN vec3 v3_norm(vec3 a) { return v3_scale(a, 1.0f / v3_len(a)); }
KFN float v3_max_comp(vec3 a) { return k_fmax(a.x, k_fmax(a.y, a.z)); }
KFN float v3_get(vec3 a, int axis) { return axis == 0 ? a.x : (axis == 1 ? a.y : a.z); }
KFN float v3_luminance(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
KFN int v3_is_zero(vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }

KFN float k_clamp(float x, float lo, float hi) { return k_fmin(k_fmax(x, lo), hi); }
KFN float k_sqr(float x) { return x * x; }
/* sqrt that treats tiny negative rounding residue as zero */
KFN float k_safe_sqrt(float x) { return k_sqrt(k_fmax(x, 0.0f)); }
KFN float k_copysign(float mag, float sgn)
{
    return k_as_float((k_as_uint(mag) & 0x7fffffffu) | (k_as_uint(sgn) & 0x80000000u));
}

/* sin and cos of x, for |x| up to a few thousand. Cody-Waite reduction by pi/2 and
 * Taylor polynomials on [-pi/4, pi/4] (error below 3e-8 there). */
KFN void k_sincos(float x, float *s, float *c)
{
    float q = k_floor(x * 0.636619772f + 0.5f);
    float r = (x - q * 1.57079625f) - q * 7.54978942e-8f;
    float r2 = r * r;
    float sr = r + r * r2 * (-0.166666667f + r2 * (8.33333333e-3f + r2 * (-1.98412698e-4f + r2 * 2.75573192e-6f)));
    float cr = 1.0f + r2 * (-0.5f + r2 * (4.16666667e-2f + r2 * (-1.38888889e-3f + r2 * 2.48015873e-5f)));
    int quadrant = ((int)q) & 3;
    if (quadrant == 0) { *s = sr; *c = cr; }
    else if (quadrant == 1) { *s = cr; *c = -sr; }
    else if (quadrant == 2) { *s = -sr; *c = -cr; }
    else { *s = -cr; *c = sr; }
}

/* Cube root of x >= 0: a bit-level first guess refined by three Newton steps. */
KFN float k_cbrt(float x)
{
    if (x <= 0.0f) return 0.0f;
    float y = k_as_float(k_as_uint(x) / 3u + 0x2a514067u);
    y = y - (y * y * y - x) / (3.0f * y * y);
    y = y - (y * y * y - x) / (3.0f * y * y);
    y = y - (y * y * y - x) / (3.0f * y * y);
    return y;
}

/* An orthonormal basis around unit n (Duff et al., "Building an Orthonormal Basis,
 * Revisited", JCGT 2017): branch-free and continuous except at n.z == 0 sign flips. */
KFN void k_onb(vec3 n, vec3 *t, vec3 *b)
{
    float sign = k_copysign(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float bb = n.x * n.y * a;
    *t = v3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    *b = v3(bb, sign + n.y * n.y * a, -n.y);
}

/* Local (x along t, y along b, z along n) to world. */
KFN vec3 k_to_world(vec3 v_local, vec3 t, vec3 b, vec3 n)
{
    return v3_add(v3_add(v3_scale(t, v_local.x), v3_scale(b, v_local.y)), v3_scale(n, v_local.z));
}

#endif /* CLPT_KMATH_H */
