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
KFN float v3_min_comp(vec3 a) { return k_fmin(a.x, k_fmin(a.y, a.z)); }
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

/* sin and cos of r in [-pi/4, pi/4]: Taylor polynomials (error below 3e-8), given
 * r2 = r * r; as macros for float and float8 (kernels/integrator/shade_lanes.h) alike. */
#define K_SIN_QUARTER(r, r2)                                                             \
    ((r) + (r) * (r2) * (-0.166666667f + (r2) * (8.33333333e-3f + (r2) * (-1.98412698e-4f + (r2) * 2.75573192e-6f))))
#define K_COS_QUARTER(r2)                                                                \
    (1.0f + (r2) * (-0.5f + (r2) * (4.16666667e-2f + (r2) * (-1.38888889e-3f + (r2) * 2.48015873e-5f))))

KFN void k_sincos_quarter(float r, float *s, float *c)
{
    float r2 = r * r;
    *s = K_SIN_QUARTER(r, r2);
    *c = K_COS_QUARTER(r2);
}

/* sin and cos of x, for |x| up to a few thousand: Cody-Waite reduction by pi/2, then
 * k_sincos_quarter. */
KFN void k_sincos(float x, float *s, float *c)
{
    float q = k_floor(x * 0.636619772f + 0.5f);
    float r = (x - q * 1.57079625f) - q * 7.54978942e-8f;
    float sr, cr;
    k_sincos_quarter(r, &sr, &cr);
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

/* ------------------------------------------------------------------ exp, log, pow
 * For Phong exponents, sRGB decoding and the Phong lobe's sampling. Built from the
 * float's bits and short polynomials, so every compiler gets the same bits; relative
 * error a few 1e-7 (k_pow: that times |y log2 x|). */

/* log2(x) for x > 0 (subnormals included); -inf at 0, NaN below. */
KFN float k_log2(float x)
{
    if (!(x > 0.0f)) return x == 0.0f ? -k_as_float(0x7f800000u) : k_as_float(0x7fc00000u);
    if (x == k_as_float(0x7f800000u)) return x;
    float bias = 0.0f;
    if (x < 1.17549435e-38f) {            /* subnormal: scale into the normal range */
        x *= 16777216.0f;
        bias = -24.0f;
    }
    uint bits = k_as_uint(x);
    int e = (int)((bits >> 23) & 0xffu) - 127;
    float m = k_as_float((bits & 0x007fffffu) | 0x3f800000u);   /* [1, 2) */
    if (m > 1.41421356f) {                 /* centre the mantissa on 1: [0.707, 1.414] */
        m *= 0.5f;
        e += 1;
    }
    /* ln m = 2 atanh(t), t = (m-1)/(m+1), |t| <= 0.1716: the series to t^11 is exact to
     * about 1e-9 */
    float t = (m - 1.0f) / (m + 1.0f);
    float t2 = t * t;
    float ln_m = 2.0f * t * (1.0f + t2 * (0.333333333f + t2 * (0.2f + t2 * (0.142857143f +
                 t2 * (0.111111111f + t2 * 0.0909090909f)))));
    return ((float)e + bias) + ln_m * 1.44269504f;
}

/* 2^y; 0 below the subnormal range, +inf above the float range, NaN for NaN. */
KFN float k_exp2(float y)
{
    if (y != y) return y;
    if (y < -150.0f) return 0.0f;
    if (y >= 128.0f) return k_as_float(0x7f800000u);
    float fi = k_floor(y + 0.5f);
    float x = (y - fi) * 0.693147181f;     /* |x| <= ln2 / 2: Taylor to x^7, error 5e-9 */
    float p = 1.0f + x * (1.0f + x * (0.5f + x * (0.166666667f + x * (4.16666667e-2f +
              x * (8.33333333e-3f + x * (1.38888889e-3f + x * 1.98412698e-4f))))));
    int i = (int)fi;
    /* 2^i from its bits, in two steps where it would leave the normal range */
    if (i > 127) { p *= 2.0f; i -= 1; }
    if (i < -126) { p *= 5.96046448e-8f; i += 24; }
    return p * k_int_as_float((i + 127) << 23);
}

/* x^y for x >= 0 (negative x is treated as 0); 0^0 = 1, as in C. */
KFN float k_pow(float x, float y)
{
    if (y == 0.0f) return 1.0f;
    if (!(x > 0.0f)) return y > 0.0f ? 0.0f : k_as_float(0x7f800000u);
    if (x == 1.0f) return 1.0f;
    return k_exp2(y * k_log2(x));
}

/* ------------------------------------------------------------------ inverse trig
 * For the sphere's (u, v) parameterisation. Absolute error below 1e-6. */

/* atan(x): reduced to |t| <= tan(pi/8) by 1/x and (x-1)/(x+1), then
 * t + t^3 P(t^2) with P of degree 3: a minimax fit of (atan(t) - t) / t^3 on that
 * interval (weighted by t^3, so the error is atan's; tools/fit_poly.py makes the
 * coefficients), error 5e-9 before float rounding. It replaced the Taylor series to
 * t^19, six terms longer for the same accuracy: two atan2 per environment-map
 * lookup made it a tenth of the envmap scene's time. */
KFN float k_atan(float x)
{
    float a = k_fabs(x);
    if (a != a) return x;
    int inverted = a > 1.0f;
    if (inverted) a = 1.0f / a;
    int shifted = a > 0.414213562f;
    float t = shifted ? (a - 1.0f) / (a + 1.0f) : a;
    float t2 = t * t;
    float r = t + t * t2 * (-0.333327567f + t2 * (0.199718793f + t2 * (-0.138244536f + t2 * 0.079025976f)));
    if (shifted) r += 0.785398163f;
    if (inverted) r = 1.57079633f - r;
    return k_copysign(r, x);
}

/* atan2(y, x) in [-pi, pi]; 0 for (0, 0). */
KFN_INLINE_CL float k_atan2(float y, float x)
{
    if (x == 0.0f && y == 0.0f) return 0.0f;
    if (k_fabs(x) >= k_fabs(y)) {
        float r = k_atan(y / x);
        if (x < 0.0f) r += y >= 0.0f ? K_PI : -K_PI;
        return r;
    }
    return (y > 0.0f ? 1.57079633f : -1.57079633f) - k_atan(x / y);
}

/* acos(x) in [0, pi], x clamped to [-1, 1]. */
KFN float k_acos(float x)
{
    x = k_clamp(x, -1.0f, 1.0f);
    return k_atan2(k_safe_sqrt((1.0f - x) * (1.0f + x)), x);
}

/* ------------------------------------------------------------------ colour */

/* The sRGB transfer function's inverse (IEC 61966-2-1): encoded [0,1] to linear. */
KFN float k_srgb_to_linear(float c)
{
    if (c <= 0.04045f) return c * (1.0f / 12.92f);
    return k_pow((c + 0.055f) / 1.055f, 2.4f);
}

/* 0 below e0, 1 above e1, the cubic 3t^2 - 2t^3 between. */
KFN float k_smoothstep(float e0, float e1, float x)
{
    float t = k_clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
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
