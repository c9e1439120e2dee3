/*
 * bsdf_classic.h — the simple materials: Lambertian (MAT_DIFFUSE), the fuzzy mirror of
 * "Ray Tracing in One Weekend" (MAT_METAL) and the classic ray tracer's Phong material
 * (MAT_PHONG), whose see-through part is the smooth glass of dielectric.h.
 */
#ifndef CLPT_BSDF_CLASSIC_H
#define CLPT_BSDF_CLASSIC_H

#include "bsdf/bsdf_base.h"
#include "bsdf/dielectric.h"

/* Lambertian: f = albedo / pi, cosine-weighted sampling. */
KFN BsdfSample bsdf_sample_diffuse(vec3 albedo, vec3 n, float u1, float u2)
{
    BsdfSample s;
    vec3 t, b;
    k_onb(n, &t, &b);
    vec3 v_local = sample_cosine_hemisphere(u1, u2);
    s.wi = k_to_world(v_local, t, b, n);
    s.pdf = v_local.z * K_INV_PI;
    s.weight = albedo;
    s.specular = 0;
    s.transmitted = 0;
    return s;
}

/* Metal as in "Ray Tracing in One Weekend": the mirror direction moved by a random
 * point of a ball of radius `fuzz`. Its density has no closed form, so it is treated
 * like a delta lobe (no light sampling, emission seen through it counts fully), which
 * keeps the estimator unbiased. */
KFN BsdfSample bsdf_sample_metal(vec3 albedo, float fuzz, vec3 d, vec3 n, float u1, float u2, float u3)
{
    vec3 r = reflect_dir(d, n);
    if (fuzz > 0.0f) r = v3_madd(r, sample_ball(u1, u2, u3), fuzz);
    return bsdf_delta_sample(v3_norm(r), albedo, 0);
}

/* ---------------------------------------------------------------- Phong
 * The modified Phong BRDF (Lafortune & Willems 1994), which conserves energy:
 *     f(wo, wi) = kd / pi + ks (n + 2) / (2 pi) cos^n(alpha),
 * alpha the angle between wi and the mirror direction of wo. With kd + ks <= 1 per
 * channel it never reflects more than it receives. MAT_PHONG adds a perfect mirror
 * (`reflective`, kr) and a smooth refracting part (`transparent`, kt, with Fresnel);
 * phong_lobes scales all four down together when they sum above 1 in some channel, so
 * a classic material (diffuse 1 1 1 plus a specular colour) stays physical. */

typedef struct {
    vec3 kd, ks, kr, kt;      /* scaled so that kd + ks + kr + kt <= 1 per channel */
    float n;                  /* shininess */
    float p_glossy;           /* chance of sampling the kd + ks part ... */
    float p_mirror;           /* ... the mirror ... */
    float p_spec;             /* within the glossy part: the ks lobe rather than kd */
} PhongLobes;                 /* ... and the rest is the refracting part */

KFN PhongLobes phong_lobes(Material m, vec3 kd)
{
    PhongLobes l;
    vec3 sum = v3_add(v3_add(kd, m.specular), v3_add(m.reflective, m.transparent));
    float scale = v3_max_comp(sum) > 1.0f ? 1.0f / v3_max_comp(sum) : 1.0f;
    l.kd = v3_scale(kd, scale);
    l.ks = v3_scale(m.specular, scale);
    l.kr = v3_scale(m.reflective, scale);
    l.kt = v3_scale(m.transparent, scale);
    l.n = k_fmax(m.shininess, 0.0f);
    float wd = v3_luminance(l.kd), ws = v3_luminance(l.ks);
    float wr = v3_luminance(l.kr), wt = v3_luminance(l.kt);
    float total = wd + ws + wr + wt;
    l.p_glossy = total > 0.0f ? (wd + ws) / total : 0.0f;
    l.p_mirror = total > 0.0f ? wr / total : 0.0f;
    l.p_spec = wd + ws > 0.0f ? ws / (wd + ws) : 0.0f;
    return l;
}

/* The kd + ks part: f(wo, wi) into *f and the density with which phong_sample picks wi
 * (choice of the glossy part included) as the return value. `d` is the incoming ray
 * direction (wo = -d), n the shading normal on its side. */
KFN float phong_eval(PhongLobes l, vec3 d, vec3 n, vec3 wi, vec3 *f)
{
    float cos_i = v3_dot(n, wi);
    if (cos_i <= 0.0f) {
        *f = v3s(0.0f);
        return 0.0f;
    }
    float cos_a = k_fmax(v3_dot(reflect_dir(d, n), wi), 0.0f);
    float lobe = k_pow(cos_a, l.n);
    *f = v3_add(v3_scale(l.kd, K_INV_PI), v3_scale(l.ks, (l.n + 2.0f) * (0.5f * K_INV_PI) * lobe));
    float pdf = (1.0f - l.p_spec) * cos_i * K_INV_PI + l.p_spec * (l.n + 1.0f) * (0.5f * K_INV_PI) * lobe;
    return l.p_glossy * pdf;
}

/* Samples one of the lobes: u_lobe picks glossy / mirror / refraction (and within the
 * glossy part diffuse or specular, by rescaling it), u1 u2 the direction. `entering`,
 * ns and ng as for bsdf_sample_dielectric (both face the incoming side); u_fresnel
 * chooses reflection or refraction at the refracting part. Only a refracted sample
 * leaves below the geometric surface (a glossy one there is the caller's to drop). */
KFN BsdfSample phong_sample(PhongLobes l, Material m, vec3 d, vec3 ns, vec3 ng, int entering,
                            float u_lobe, float u1, float u2, float u_fresnel)
{
    BsdfSample s;
    if (u_lobe < l.p_glossy) {
        float u = u_lobe / l.p_glossy;
        vec3 t, b;
        if (u < l.p_spec) {
            /* cos^n lobe about the mirror direction: cos(alpha) = u1^(1/(n+1)) */
            vec3 r = reflect_dir(d, ns);
            float cos_a = k_pow(u1, 1.0f / (l.n + 1.0f));
            float sin_a = k_safe_sqrt(1.0f - cos_a * cos_a);
            float sphi, cphi;
            k_sincos(K_TWO_PI * u2, &sphi, &cphi);
            k_onb(r, &t, &b);
            s.wi = v3_norm(k_to_world(v3(sin_a * cphi, sin_a * sphi, cos_a), t, b, r));
        } else {
            k_onb(ns, &t, &b);
            s.wi = k_to_world(sample_cosine_hemisphere(u1, u2), t, b, ns);
        }
        vec3 f;
        s.pdf = phong_eval(l, d, ns, s.wi, &f);
        float cos_i = v3_dot(ns, s.wi);
        s.weight = s.pdf > 0.0f ? v3_scale(f, cos_i / s.pdf) : v3s(0.0f);
        s.specular = 0;
        s.transmitted = 0;
        return s;
    }
    if (u_lobe < l.p_glossy + l.p_mirror)
        return bsdf_delta_sample(bsdf_mirror_dir(d, ns, ng), v3_scale(l.kr, 1.0f / l.p_mirror), 0);
    /* The refracting part, like glass, tinted by kt: the glass sample (a delta lobe) as
     * it is, with kt's weight. Returned whole rather than copied field by field into s:
     * NVIDIA's OpenCL compiler (driver 580.159) at its default optimisation kept the
     * glossy branch's pdf and flag in s on this path (tools/gpu-check.sh found it). */
    BsdfSample g = bsdf_sample_dielectric(m.ior, d, ns, ng, entering, u_fresnel);
    float p_t = 1.0f - l.p_glossy - l.p_mirror;
    g.weight = p_t > 0.0f ? v3_scale(l.kt, 1.0f / p_t) : v3s(0.0f);
    return g;
}

/* ---------------------------------------------------------------- MAT_DIFFUSE */
KFN int diffuse_bsdf_has_density(Material m, vec3 albedo) { return bsdf_density_always(m, albedo); }

KFN vec3 diffuse_bsdf_eval(Material m, BsdfHit h, vec3 wi, float *pdf)
{
    (void)m;
    float c = v3_dot(h.ns, wi);
    if (c <= 0.0f) return bsdf_no_eval(pdf);
    *pdf = c * K_INV_PI;
    return v3_scale(h.albedo, K_INV_PI);
}

KFN BsdfSample diffuse_bsdf_sample(Material m, BsdfHit h, float u_lobe, float u1, float u2, float u3)
{
    (void)m;
    (void)u_lobe;
    (void)u3;
    return bsdf_sample_diffuse(h.albedo, h.ns, u1, u2);
}

/* ---------------------------------------------------------------- MAT_METAL
 * Only a delta lobe, as far as light sampling knows: no density, nothing to evaluate. */
KFN int metal_bsdf_has_density(Material m, vec3 albedo) { return none_bsdf_has_density(m, albedo); }

KFN vec3 metal_bsdf_eval(Material m, BsdfHit h, vec3 wi, float *pdf) { return none_bsdf_eval(m, h, wi, pdf); }

KFN BsdfSample metal_bsdf_sample(Material m, BsdfHit h, float u_lobe, float u1, float u2, float u3)
{
    (void)u_lobe;
    return bsdf_sample_metal(h.albedo, m.fuzz, h.d, h.ns, u1, u2, u3);
}

/* ---------------------------------------------------------------- MAT_PHONG */
KFN int phong_bsdf_has_density(Material m, vec3 albedo) { return phong_lobes(m, albedo).p_glossy > 0.0f; }

KFN vec3 phong_bsdf_eval(Material m, BsdfHit h, vec3 wi, float *pdf)
{
    vec3 f;
    *pdf = phong_eval(phong_lobes(m, h.albedo), h.d, h.ns, wi, &f);
    return f;
}

KFN BsdfSample phong_bsdf_sample(Material m, BsdfHit h, float u_lobe, float u1, float u2, float u3)
{
    return phong_sample(phong_lobes(m, h.albedo), m, h.d, h.ns, h.ng, h.front, u_lobe, u1, u2, u3);
}

#endif /* CLPT_BSDF_CLASSIC_H */
