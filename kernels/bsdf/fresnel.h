/*
 * fresnel.h — how much light a smooth boundary reflects: the exact unpolarised
 * reflectance of a dielectric and of a conductor (complex index), and Schlick's
 * approximation. Shared by every lobe family and the classic ray tracer.
 */
#ifndef CLPT_FRESNEL_H
#define CLPT_FRESNEL_H

#include "util/kmath.h"

/* Unpolarised Fresnel reflectance of a smooth dielectric boundary; cos_i > 0 is on the
 * incident side, eta = n_transmitted / n_incident. Returns 1 on total internal reflection. */
KFN float fresnel_dielectric(float cos_i, float eta)
{
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;
    float cos_t = k_sqrt(1.0f - sin2_t);
    float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5f * (r_par * r_par + r_perp * r_perp);
}

/* Unpolarised reflectance of a conductor with complex index eta + i k (relative to the
 * outside medium) for one channel (pbrt-v3's FrConductor, exact for real cos_i). */
KFN float fresnel_conductor1(float cos_i, float eta, float k)
{
    cos_i = k_clamp(cos_i, 0.0f, 1.0f);
    float c2 = cos_i * cos_i, s2 = 1.0f - c2;
    float e2 = eta * eta, k2 = k * k;
    float t0 = e2 - k2 - s2;
    float a2b2 = k_sqrt(t0 * t0 + 4.0f * e2 * k2);
    float a = k_safe_sqrt(0.5f * (a2b2 + t0));
    float t1 = a2b2 + c2, t2 = 2.0f * a * cos_i;
    float rs = t1 + t2 > 0.0f ? (t1 - t2) / (t1 + t2) : 1.0f;
    float t3 = c2 * a2b2 + s2 * s2, t4 = t2 * s2;
    float rp = t3 + t4 > 0.0f ? rs * (t3 - t4) / (t3 + t4) : rs;
    return k_clamp(0.5f * (rs + rp), 0.0f, 1.0f);
}

/* Schlick's approximation from the reflectance at normal incidence. */
KFN vec3 fresnel_schlick(vec3 f0, float cos_i)
{
    float m = 1.0f - k_clamp(cos_i, 0.0f, 1.0f);
    float m5 = m * m * m * m * m;
    return v3_add(f0, v3_scale(v3_sub(v3s(1.0f), f0), m5));
}

#endif /* CLPT_FRESNEL_H */
