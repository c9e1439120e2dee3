/*
 * microfacet.h — the GGX (Trowbridge-Reitz) microfacet model and the rough conductor
 * and dielectric BSDFs built on it.
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

#include "sampling.h"

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

/* ---------------------------------------------------------------- Fresnel */

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

/* ---------------------------------------------------------------- conductor
 * f = D G2 F / (4 cos_o cos_i); sampled by a visible normal and mirror reflection:
 * pdf = D_wo(m) / (4 wo.m). The Fresnel term is given per facet by the caller's `fr`
 * (complex index or Schlick). */
typedef struct {
    Ggx g;
    vec3 eta, k;       /* complex index per channel (unless schlick) */
    vec3 f0;           /* schlick: reflectance at normal incidence */
    vec3 tint;         /* multiplies the Fresnel term (albedo or its texture) */
    int schlick;
} Conductor;

KFN vec3 conductor_fresnel(Conductor c, float cos_i)
{
    vec3 f = c.schlick ? fresnel_schlick(c.f0, cos_i)
                       : v3(fresnel_conductor1(cos_i, c.eta.x, c.k.x), fresnel_conductor1(cos_i, c.eta.y, c.k.y),
                            fresnel_conductor1(cos_i, c.eta.z, c.k.z));
    return v3_mul(f, c.tint);
}

/* f(wo, wi) into *f, the sampling density as the return value (0 and f = 0 below). */
KFN float conductor_eval(Conductor c, vec3 wo, vec3 wi, vec3 *f)
{
    *f = v3s(0.0f);
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    vec3 h = v3_add(wo, wi);
    float len = v3_len(h);
    if (!(len > 0.0f)) return 0.0f;
    h = v3_scale(h, 1.0f / len);
    float oh = v3_dot(wo, h);
    if (oh <= 0.0f) return 0.0f;
    float d = ggx_d(c.g, h);
    *f = v3_scale(conductor_fresnel(c, oh), d * ggx_g2(c.g, wo, wi) / (4.0f * wo.z * wi.z));
    return ggx_d_visible(c.g, wo, h) / (4.0f * oh);
}

/* A direction for wo; *f and the density as conductor_eval's. wi.z <= 0 (a facet that
 * reflects below the surface) is a failed sample: pdf 0. */
KFN float conductor_sample(Conductor c, vec3 wo, float u1, float u2, vec3 *wi, vec3 *f)
{
    vec3 m = ggx_sample_visible(c.g, wo, u1, u2);
    *wi = mf_reflect(wo, m);
    return conductor_eval(c, wo, *wi, f);
}

/* ---------------------------------------------------------------- dielectric
 * Walter et al. 2007. wo.z > 0 is on the incident side, eta = n_t / n_i across the
 * surface. A visible normal m is sampled; reflection with probability F(wo.m), else
 * refraction through m. Reflection: f = D G2 F / (4 cos_o cos_i); transmission:
 * f = (1 - F) D G2 |wi.m| |wo.m| / (|cos_i| cos_o (wi.m + wo.m / eta)^2) (without the
 * 1/eta^2 radiance scaling, as the smooth glass: camera paths, lights outside). A thin
 * sheet (`thin`) sends the transmitted part straight through: the reflection lobe
 * mirrored to the other side, with the sheet's two interfaces' total reflectance
 * R + T^2 R / (1 - R^2) (pbrt-v4's ThinDielectricBxDF, made rough). */
typedef struct {
    Ggx g;
    float eta;
    int thin;
} Dielectric;

/* Reflectance of one facet at cosine c (thin: both faces of the sheet). */
KFN float dielectric_facet_fresnel(Dielectric d, float c)
{
    float r = fresnel_dielectric(c, d.eta);
    if (d.thin && r < 1.0f) r += (1.0f - r) * (1.0f - r) * r / (1.0f - r * r);
    return r;
}

KFN float dielectric_eval(Dielectric d, vec3 wo, vec3 wi, vec3 *f)
{
    *f = v3s(0.0f);
    if (wo.z <= 0.0f || wi.z == 0.0f) return 0.0f;
    int reflect = wi.z > 0.0f;
    vec3 m;
    vec3 wr = wi;
    if (reflect || d.thin) {
        if (!reflect) wr.z = -wr.z;    /* thin: the mirrored reflection */
        m = v3_add(wo, wr);
    } else {
        m = v3_add(v3_scale(wi, d.eta), wo);
    }
    float len = v3_len(m);
    if (!(len > 0.0f)) return 0.0f;
    m = v3_scale(m, 1.0f / len);
    if (m.z < 0.0f) m = v3_neg(m);
    float om = v3_dot(wo, m), im = v3_dot(wr, m);
    /* facets seen from their back by either direction contribute nothing */
    if (om <= 0.0f || (reflect || d.thin ? im <= 0.0f : im >= 0.0f)) return 0.0f;
    float F = dielectric_facet_fresnel(d, om);
    float D = ggx_d(d.g, m), G = ggx_g2(d.g, wo, wr);
    float dv = ggx_d_visible(d.g, wo, m);
    if (reflect || d.thin) {
        float p = reflect ? F : 1.0f - F;
        *f = v3s(p * D * G / (4.0f * wo.z * k_fabs(wr.z)));
        return p * dv / (4.0f * om);
    }
    float denom = im + om / d.eta;
    denom = denom * denom;
    if (!(denom > 0.0f)) return 0.0f;
    *f = v3s((1.0f - F) * D * G * k_fabs(im) * om / (k_fabs(wi.z) * wo.z * denom));
    return (1.0f - F) * dv * k_fabs(im) / denom;
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

/* GGX reflection without Fresnel: D G2 / (4 cos_o cos_i) into *brdf, the density of
 * reflecting about a visible normal as the return value. */
KFN float ggx_reflection(Ggx g, vec3 wo, vec3 wi, float *brdf)
{
    *brdf = 0.0f;
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    vec3 h = v3_add(wo, wi);
    float len = v3_len(h);
    if (!(len > 0.0f)) return 0.0f;
    h = v3_scale(h, 1.0f / len);
    float oh = v3_dot(wo, h);
    if (oh <= 0.0f) return 0.0f;
    *brdf = ggx_d(g, h) * ggx_g2(g, wo, wi) / (4.0f * wo.z * wi.z);
    return ggx_d_visible(g, wo, h) / (4.0f * oh);
}

/* A direction for wo, *f and the density as dielectric_eval's (0: failed sample). */
KFN float dielectric_sample(Dielectric d, vec3 wo, float u_lobe, float u1, float u2, vec3 *wi, vec3 *f)
{
    vec3 m = ggx_sample_visible(d.g, wo, u1, u2);
    float om = v3_dot(wo, m);
    float F = dielectric_facet_fresnel(d, om);
    int reflect = u_lobe < F;
    *wi = mf_reflect(wo, m);
    *f = v3s(0.0f);
    if (!reflect) {
        if (d.thin) wi->z = -wi->z;
        else if (!mf_refract(wo, m, d.eta, wi)) return 0.0f;
    }
    /* a lobe's sample on the other lobe's side is lost, not the other lobe's: the
     * densities of dielectric_eval count each lobe on its own side only */
    if (reflect ? wi->z <= 0.0f : wi->z >= 0.0f) return 0.0f;
    return dielectric_eval(d, wo, *wi, f);
}

#endif /* CLPT_MICROFACET_H */
