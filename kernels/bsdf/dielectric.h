/*
 * dielectric.h — glass (MAT_DIELECTRIC): smooth, a Fresnel mirror or a refraction; a
 * thin sheet (MAT_THIN) that lets the refracted part pass straight on; rough, the GGX
 * reflection and refraction of Walter et al. 2007.
 */
#ifndef CLPT_DIELECTRIC_H
#define CLPT_DIELECTRIC_H

#include "bsdf/bsdf_base.h"
#include "bsdf/fresnel.h"

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

/* Smooth glass: reflect with the Fresnel probability, otherwise refract, about the
 * shading normal ns, as Mitsuba, Cycles and pbrt do. `d` is the incoming unit
 * direction, ns and ng the shading and geometric normals facing the incoming side,
 * `entering` whether d comes from outside (the side the outward normal points to).
 *
 * About ng instead, a tessellated sphere with interpolated normals was a faceted
 * polyhedron to its light: near the rim, refracted rays met the next facet beyond the
 * critical angle and circled inside by total internal reflection past any depth limit
 * (0.9922 in a white furnace at depth 16, the rim's pixels down to 0.71, where the
 * analytic sphere renders 1; test_bsdf's test_furnace_mesh_glass). A direction that
 * would leave on the wrong side of the geometric surface (a refraction above it, at a
 * grazing exit through a normal tilted from ng; a mirror below it) is taken about ng,
 * with a total internal reflection there reflecting: every sample goes on with weight
 * 1, so the glass keeps all it receives, as whitted.h's refraction does. An ns facing
 * away from d (one bsdf_normal did not bend: Phong's) is replaced by ng. */
KFN BsdfSample bsdf_sample_dielectric(float ior, vec3 d, vec3 ns, vec3 ng, int entering, float u)
{
    BsdfSample s;
    float eta = entering ? ior : 1.0f / ior;     /* n_t / n_i */
    vec3 wo = v3_neg(d);
    if (!(v3_dot(wo, ns) > 0.0f)) ns = ng;
    float F = fresnel_dielectric(v3_dot(wo, ns), eta);
    s.transmitted = !(u < F);
    if (u < F) {
        s.wi = reflect_dir(d, ns);
        if (v3_dot(s.wi, ng) <= 0.0f) s.wi = reflect_dir(d, ng);
    } else if (!mf_refract(wo, ns, eta, &s.wi) || !(v3_dot(s.wi, ng) < 0.0f)) {
        /* (mf_refract fails only by rounding here: F is 1 where it would) */
        s.transmitted = mf_refract(wo, ng, eta, &s.wi);
        if (!s.transmitted) s.wi = reflect_dir(d, ng);
    }
    /* choosing the lobe with probability F (or 1-F) cancels the Fresnel factor; the
     * radiance scaling by eta^2 is left out, as is usual for camera paths that end on
     * lights outside the glass */
    s.weight = v3s(1.0f);
    s.pdf = 0.0f;
    s.specular = 1;
    return s;
}

KFN Dielectric bsdf_dielectric(Material m, int front)
{
    Dielectric g;
    g.g = bsdf_ggx(m);
    g.thin = (m.flags & MAT_THIN) != 0u;
    g.eta = g.thin || front ? m.ior : 1.0f / m.ior;
    return g;
}


/* A smooth thin sheet: reflect with the sheet's reflectance, else pass straight on. */
KFN BsdfSample bsdf_sample_thin(Dielectric g, vec3 d, vec3 ng, float u)
{
    float F = dielectric_facet_fresnel(g, -v3_dot(d, ng));
    int transmitted = !(u < F);
    return bsdf_delta_sample(transmitted ? d : reflect_dir(d, ng), v3s(1.0f), transmitted);
}

/* ---------------------------------------------------------------- MAT_DIELECTRIC
 * The entry points bsdf.h dispatches to, shaped as conductor.h's by design. */
KFN int dielectric_bsdf_has_density(Material m, vec3 albedo) { return bsdf_density_if_rough(m, albedo); }

KFN vec3 dielectric_bsdf_eval(Material m, BsdfHit h, vec3 wi, float *pdf)
{
    if (!dielectric_bsdf_has_density(m, h.albedo)) return bsdf_no_eval(pdf);
    vec3 wo, f;
    BsdfFrame F = bsdf_hit_frame(h, &wo);
    *pdf = dielectric_eval(bsdf_dielectric(m, h.front), wo, bsdf_frame_local(F, wi), &f);
    return f;
}

KFN BsdfSample dielectric_bsdf_sample(Material m, BsdfHit h, float u_lobe, float u1, float u2, float u3)
{
    (void)u3;
    if (dielectric_bsdf_has_density(m, h.albedo)) {
        vec3 wo, f = v3s(0.0f), wl = v3s(0.0f);
        BsdfFrame F = bsdf_hit_frame(h, &wo);
        float pdf = wo.z > 0.0f ? dielectric_sample(bsdf_dielectric(m, h.front), wo, u_lobe, u1, u2, &wl, &f) : 0.0f;
        return bsdf_rough_sample(F, pdf, wl, f);
    }
    if (m.flags & MAT_THIN) return bsdf_sample_thin(bsdf_dielectric(m, h.front), h.d, h.ng, u_lobe);
    return bsdf_sample_dielectric(m.ior, h.d, h.ns, h.ng, h.front, u_lobe);
}

#endif /* CLPT_DIELECTRIC_H */
