/*
 * conductor.h — metals with a complex index of refraction (MAT_CONDUCTOR): the GGX
 * reflection lobe with the conductor's Fresnel colour, or Schlick's from F0 (MAT_F0);
 * smooth, a Fresnel-coloured mirror. The coated material's conductor base uses the
 * same lobe (layered.h).
 */
#ifndef CLPT_CONDUCTOR_H
#define CLPT_CONDUCTOR_H

#include "bsdf/bsdf_base.h"
#include "bsdf/fresnel.h"

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
    float brdf, oh;
    float pdf = ggx_reflection_oh(c.g, wo, wi, &brdf, &oh);
    *f = oh > 0.0f ? v3_scale(conductor_fresnel(c, oh), brdf) : v3s(0.0f);
    return pdf;
}

/* A direction for wo; *f and the density as conductor_eval's. wi.z <= 0 (a facet that
 * reflects below the surface) is a failed sample: pdf 0. */
KFN float conductor_sample(Conductor c, vec3 wo, float u1, float u2, vec3 *wi, vec3 *f)
{
    vec3 m = ggx_sample_visible(c.g, wo, u1, u2);
    *wi = mf_reflect(wo, m);
    return conductor_eval(c, wo, *wi, f);
}

KFN Conductor bsdf_conductor(Material m, vec3 albedo)
{
    Conductor c;
    c.g = bsdf_ggx(m);
    c.eta = m.eta;
    c.k = m.k;
    c.f0 = m.specular;
    c.tint = albedo;
    c.schlick = (m.flags & MAT_F0) != 0u;
    return c;
}

/* A smooth conductor: the mirror direction about ns (about ng where that would go
 * below the surface), weighted by the Fresnel colour. */
KFN BsdfSample bsdf_sample_mirror_conductor(Conductor c, vec3 d, vec3 ns, vec3 ng)
{
    return bsdf_delta_sample(bsdf_mirror_dir(d, ns, ng), conductor_fresnel(c, -v3_dot(d, ns)), 0);
}

/* ---------------------------------------------------------------- MAT_CONDUCTOR
 * The entry points bsdf.h dispatches to. Every lobe family's eval and sample have the
 * same frame-in, frame-out shape (dielectric.h's too) by design: only the family's
 * own lobe call differs, and OpenCL C has no function pointers to share the rest. */
KFN int conductor_bsdf_has_density(Material m, vec3 albedo) { return bsdf_density_if_rough(m, albedo); }

KFN vec3 conductor_bsdf_eval(Material m, BsdfHit h, vec3 wi, float *pdf)
{
    if (!conductor_bsdf_has_density(m, h.albedo)) return bsdf_no_eval(pdf);
    vec3 wo, f;
    BsdfFrame F = bsdf_hit_frame(h, &wo);
    *pdf = conductor_eval(bsdf_conductor(m, h.albedo), wo, bsdf_frame_local(F, wi), &f);
    return f;
}

KFN BsdfSample conductor_bsdf_sample(Material m, BsdfHit h, float u_lobe, float u1, float u2, float u3)
{
    (void)u_lobe;
    (void)u3;
    if (!conductor_bsdf_has_density(m, h.albedo))
        return bsdf_sample_mirror_conductor(bsdf_conductor(m, h.albedo), h.d, h.ns, h.ng);
    vec3 wo, f = v3s(0.0f), wl = v3s(0.0f);
    BsdfFrame F = bsdf_hit_frame(h, &wo);
    float pdf = wo.z > 0.0f ? conductor_sample(bsdf_conductor(m, h.albedo), wo, u1, u2, &wl, &f) : 0.0f;
    return bsdf_rough_sample(F, pdf, wl, f);
}

#endif /* CLPT_CONDUCTOR_H */
