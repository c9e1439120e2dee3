/*
 * bsdf.h — how any material scatters light: one entry for each question the integrators
 * ask of a material, dispatched over MATERIAL_TYPES (types.h) to the functions of its
 * lobe family (bsdf_base.h says what each family provides). Arguments throughout: `d`
 * the incoming ray direction (wo = -d), ns the shading normal and ng the geometric
 * normal, both turned to the incoming side, `front` whether d arrives on the outward
 * side (for the index ratio), albedo the material's (textured) colour at the hit.
 * A type whose code is not compiled in (KF_MAT_*) drops out of every dispatch.
 */
#ifndef CLPT_BSDF_H
#define CLPT_BSDF_H

#include "bsdf/bsdf_base.h"
#include "bsdf/bsdf_classic.h"
#include "bsdf/conductor.h"
#include "bsdf/dielectric.h"
#include "bsdf/principled.h"
#include "bsdf/layered.h"

/* Whether the material has a lobe with a density (not only delta lobes), so that
 * next-event estimation can reach it. */
KFN int bsdf_has_density(Material m, vec3 albedo)
{
#define BSDF_HAS_DENSITY_(name, value, bit, traits, lobes) \
    if (MAT_IS(m, name)) return lobes##_bsdf_has_density(m, albedo);
    MATERIAL_TYPES(BSDF_HAS_DENSITY_)
#undef BSDF_HAS_DENSITY_
    return 0;
}

/* The shading normal the material's lobes are to see for the incoming direction d
 * (ns and ng on d's side): shading_normal_valid's, except for the types that keep the
 * normal as it is (MT_KEEPS_NORMAL: the Lambertian lobe, which does not look at wo, and
 * the classic Phong, which needs no frame, its mirror falling back to ng itself), whose
 * images stay as they were. */
KFN vec3 bsdf_normal(Material m, vec3 d, vec3 ns, vec3 ng)
{
    if (material_has(m.type, MT_KEEPS_NORMAL)) return ns;
    return shading_normal_valid(d, ns, ng);
}

KFN BsdfHit bsdf_hit(vec3 albedo, vec3 d, vec3 ns, vec3 ng, int front)
{
    BsdfHit h;
    h.d = d;
    h.ns = ns;
    h.ng = ng;
    h.albedo = albedo;
    h.front = front;
    return h;
}

/* f(wo, wi) (no cosine) of the material's non-delta lobes, and in *pdf the density
 * with which bsdf_sample returns wi. Zero for delta-only materials. */
KFN vec3 bsdf_eval(Material m, vec3 albedo, vec3 d, vec3 ns, int front, vec3 wi, float *pdf)
{
    BsdfHit h = bsdf_hit(albedo, d, ns, ns, front);
#define BSDF_EVAL_(name, value, bit, traits, lobes) \
    if (MAT_IS(m, name)) return lobes##_bsdf_eval(m, h, wi, pdf);
    MATERIAL_TYPES(BSDF_EVAL_)
#undef BSDF_EVAL_
    return bsdf_no_eval(pdf);
}

KFN float bsdf_pdf(Material m, vec3 albedo, vec3 d, vec3 ns, int front, vec3 wi)
{
    float pdf;
    bsdf_eval(m, albedo, d, ns, front, wi, &pdf);
    return pdf;
}

/* A direction for any material. u_lobe picks a lobe, u1 u2 (u3) the direction. */
KFN BsdfSample bsdf_sample(Material m, vec3 albedo, vec3 d, vec3 ns, vec3 ng, int front, float u_lobe, float u1,
                           float u2, float u3)
{
    BsdfHit h = bsdf_hit(albedo, d, ns, ng, front);
#define BSDF_SAMPLE_(name, value, bit, traits, lobes) \
    if (MAT_IS(m, name)) return lobes##_bsdf_sample(m, h, u_lobe, u1, u2, u3);
    MATERIAL_TYPES(BSDF_SAMPLE_)
#undef BSDF_SAMPLE_
    return bsdf_failed(ns);
}

#endif /* CLPT_BSDF_H */
