/*
 * microfacet.h — the GGX (Trowbridge-Reitz) distribution of microfacet normals: its
 * density, masking-shadowing, visible-normal sampling, and its reflection and
 * refraction terms without Fresnel. The lobes built on it are in conductor.h,
 * dielectric.h, principled.h and layered.h.
 *
 * Everything here works in a local frame: z is the shading normal turned to the side
 * the light leaves toward (wo.z > 0 for the caller's wo), x and y the tangents; alpha_x
 * and alpha_y are the roughnesses along them (alpha = roughness^2). Masking-shadowing
 * is Smith's height-correlated form (Heitz 2014, "Understanding the Masking-Shadowing
 * Function"); directions are sampled from the distribution of normals visible from wo
 * (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4)), so the
 * weight f cos / pdf of a reflection is G2 / G1 times Fresnel, never large.
 * Rough refraction follows Walter et al. 2007, "Microfacet Models for Refraction
 * through Rough Surfaces", in the form of pbrt-v4's DielectricBxDF.
 */
#ifndef CLPT_MICROFACET_H
#define CLPT_MICROFACET_H

#include "sample/sampling.h"

/* Below this alpha a surface is treated as smooth (a delta lobe): the GGX density
 * would overflow float and no light sample could hit its lobe anyway (pbrt-v4 uses the
 * same bound). */
#define GGX_SMOOTH_ALPHA 1e-3f

typedef struct {
    float ax, ay;
} Ggx;

/* alpha from the perceptual roughness in [0, 1] and an anisotropy in [0, 1) that
 * stretches the lobe along x (the way glTF's KHR_materials_anisotropy and Disney's
 * model write it: aspect = sqrt(1 - 0.9 anisotropy)). */
KFN Ggx ggx_make(float roughness, float anisotropy)
{
    Ggx g;
    float a = roughness * roughness;
    float aspect = k_sqrt(1.0f - 0.9f * anisotropy);
    g.ax = k_fmax(a / aspect, 0.0f);
    g.ay = k_fmax(a * aspect, 0.0f);
    return g;
}

KFN int ggx_smooth(Ggx g) { return k_fmax(g.ax, g.ay) < GGX_SMOOTH_ALPHA; }

/* D(m): the density of microfacet normals m (m.z > 0) per projected area. */
KFN float ggx_d(Ggx g, vec3 m)
{
    if (m.z <= 0.0f) return 0.0f;
    float x = m.x / g.ax, y = m.y / g.ay;
    float e = x * x + y * y + m.z * m.z;
    return 1.0f / (K_PI * g.ax * g.ay * e * e);
}

/* Smith's Lambda(w) for GGX. */
KFN float ggx_lambda(Ggx g, vec3 w)
{
    float z2 = w.z * w.z;
    if (z2 <= 0.0f) return 0.0f;
    float t2 = (g.ax * g.ax * w.x * w.x + g.ay * g.ay * w.y * w.y) / z2;
    return 0.5f * (k_sqrt(1.0f + t2) - 1.0f);
}

KFN float ggx_g1(Ggx g, vec3 w) { return 1.0f / (1.0f + ggx_lambda(g, w)); }

/* Height-correlated masking-shadowing of the pair. */
KFN float ggx_g2(Ggx g, vec3 wo, vec3 wi) { return 1.0f / (1.0f + ggx_lambda(g, wo) + ggx_lambda(g, wi)); }

/* D_wo(m) = G1(wo) max(0, wo.m) D(m) / wo.z: the density of the visible normals. */
KFN float ggx_d_visible(Ggx g, vec3 wo, vec3 m)
{
    float c = v3_dot(wo, m);
    if (c <= 0.0f || wo.z <= 0.0f) return 0.0f;
    return ggx_g1(g, wo) * c * ggx_d(g, m) / wo.z;
}

/* A normal from D_wo (wo.z > 0), Heitz 2018 listing 1. */
KFN vec3 ggx_sample_visible(Ggx g, vec3 wo, float u1, float u2)
{
    vec3 vh = v3_norm(v3(g.ax * wo.x, g.ay * wo.y, wo.z));   /* the hemisphere configuration */
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0f ? v3_scale(v3(-vh.y, vh.x, 0.0f), 1.0f / k_sqrt(lensq)) : v3(1.0f, 0.0f, 0.0f);
    vec3 t2 = v3_cross(vh, t1);
    float r = k_sqrt(u1), s, c;
    k_sincos(K_TWO_PI * u2, &s, &c);
    float p1 = r * c, p2 = r * s;
    float h = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - h) * k_safe_sqrt(1.0f - p1 * p1) + h * p2;
    vec3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)), v3_scale(vh, k_safe_sqrt(1.0f - p1 * p1 - p2 * p2)));
    return v3_norm(v3(g.ax * nh.x, g.ay * nh.y, k_fmax(nh.z, 1e-6f)));
}

KFN vec3 mf_reflect(vec3 w, vec3 m) { return v3_sub(v3_scale(m, 2.0f * v3_dot(w, m)), w); }

/* Refraction of w (pointing away, on m's side: w.m > 0) through a facet m, eta =
 * n_t / n_i. Returns 0 on total internal reflection. */
KFN int mf_refract(vec3 w, vec3 m, float eta, vec3 *wt)
{
    float cos_i = v3_dot(w, m);
    float sin2_t = k_fmax(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return 0;
    float cos_t = k_sqrt(1.0f - sin2_t);
    *wt = v3_norm(v3_add(v3_scale(w, -1.0f / eta), v3_scale(m, cos_i / eta - cos_t)));
    return 1;
}

/* The refraction part alone, without its Fresnel factor: the BTDF D G2 |wi.m| wo.m /
 * (|cos_i| cos_o (wi.m + wo.m / eta)^2) into *btdf and the density of refracting through
 * a visible normal as the return value (0 for wi.z >= 0 or a back-facing facet). The
 * principled material mixes it by its own weights. */
KFN float ggx_refraction(Ggx g, float eta, vec3 wo, vec3 wi, float *btdf)
{
    *btdf = 0.0f;
    if (wo.z <= 0.0f || wi.z >= 0.0f) return 0.0f;
    vec3 m = v3_add(v3_scale(wi, eta), wo);
    float len = v3_len(m);
    if (!(len > 0.0f)) return 0.0f;
    m = v3_scale(m, 1.0f / len);
    if (m.z < 0.0f) m = v3_neg(m);
    float om = v3_dot(wo, m), im = v3_dot(wi, m);
    if (om <= 0.0f || im >= 0.0f) return 0.0f;
    float denom = im + om / eta;
    denom = denom * denom;
    if (!(denom > 0.0f)) return 0.0f;
    *btdf = ggx_d(g, m) * ggx_g2(g, wo, wi) * k_fabs(im) * om / (k_fabs(wi.z) * wo.z * denom);
    return ggx_d_visible(g, wo, m) * k_fabs(im) / denom;
}

/* GGX reflection without Fresnel: D G2 / (4 cos_o cos_i) into *brdf, wo's cosine with
 * the half vector into *oh (for the caller's Fresnel term; 0 where wi does not reflect
 * wo), the density of reflecting about a visible normal as the return value. */
KFN float ggx_reflection_oh(Ggx g, vec3 wo, vec3 wi, float *brdf, float *oh)
{
    *brdf = 0.0f;
    *oh = 0.0f;
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    vec3 h = v3_add(wo, wi);
    float len = v3_len(h);
    if (!(len > 0.0f)) return 0.0f;
    h = v3_scale(h, 1.0f / len);
    float c = v3_dot(wo, h);
    if (c <= 0.0f) return 0.0f;
    *oh = c;
    *brdf = ggx_d(g, h) * ggx_g2(g, wo, wi) / (4.0f * wo.z * wi.z);
    return ggx_d_visible(g, wo, h) / (4.0f * c);
}

KFN float ggx_reflection(Ggx g, vec3 wo, vec3 wi, float *brdf)
{
    float oh;
    return ggx_reflection_oh(g, wo, wi, brdf, &oh);
}

#endif /* CLPT_MICROFACET_H */
