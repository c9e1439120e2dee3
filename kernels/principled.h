/*
 * principled.h — the glTF 2.0 metallic-roughness material (the specification's
 * Appendix B reference BRDF) with KHR_materials_transmission / _ior as a rough
 * refraction lobe and KHR_materials_clearcoat as a second GGX layer:
 *
 *   dielectric = F_d * specular + (1 - F_d) * ((1 - t) diffuse + t * base * btdf)
 *   metal      = F_m * specular,              F_m = Schlick(base, V.H)
 *   material   = mix(dielectric, metal, metallic),  F_d = Schlick(F0(ior), V.H)
 *   coated     = (1 - c F_c) material + c F_c clearcoat,  F_c = Schlick(0.04, N.V)
 *
 * F0(ior) = ((ior - 1) / (ior + 1))^2, KHR_materials_ior (0.04 at the default 1.5).
 * specular and clearcoat are GGX D G2 / (4 cos_o cos_i) (microfacet.h), diffuse base/pi,
 * btdf the Walter et al. refraction term through the same facets (or, thin, the
 * reflection lobe mirrored through the surface). Local frame as in microfacet.h.
 *
 * Inside a solid (eta < 1) F_d is Schlick's curve at the angle on the outer, less dense
 * side, and 1 past the critical angle: evaluated at the inner angle Schlick's curve
 * never reaches 1, so light that should be totally reflected inside glass would leave
 * it or (sampled) be lost, and a clear solid would not vanish in a white furnace.
 *
 * Sampling picks a lobe by its share at wo (clearcoat c F_c, specular, diffuse,
 * transmission); the transmission lobe, like pbrt-v4's rough DielectricBxDF, samples a
 * visible facet and reflects from it with probability F_d (always under total internal
 * reflection), refracts otherwise. The whole mixture is then evaluated: its density is
 * the weighted sum.
 */
#ifndef CLPT_PRINCIPLED_H
#define CLPT_PRINCIPLED_H

#include "microfacet.h"

typedef struct {
    vec3 base;
    float metallic, transmission, clearcoat;
    Ggx g, gc;         /* base and clearcoat roughness (alpha at least GGX_SMOOTH_ALPHA) */
    float eta;         /* n_t / n_i for the refraction */
    int thin;
} Principled;

KFN float schlick1(float f0, float c)
{
    float m = 1.0f - k_clamp(c, 0.0f, 1.0f);
    return f0 + (1.0f - f0) * (m * m * m * m * m);
}

/* Reflectance at normal incidence of a boundary with index ratio eta (either way
 * across: the same for eta and 1/eta). */
KFN float principled_f0(float eta)
{
    float r = (eta - 1.0f) / (eta + 1.0f);
    return r * r;
}

/* F_d at cosine c on the incident side of a boundary with eta = n_t / n_i: Schlick's
 * curve, taken at the transmitted angle when the light arrives from the denser side
 * and 1 beyond the critical angle (total internal reflection). */
KFN float principled_fresnel(float eta, float c)
{
    c = k_clamp(c, 0.0f, 1.0f);
    if (eta < 1.0f) {
        float sin2_t = (1.0f - c * c) / (eta * eta);
        if (sin2_t >= 1.0f) return 1.0f;
        c = k_sqrt(1.0f - sin2_t);
    }
    return schlick1(principled_f0(eta), c);
}

/* The lobes' shares at wo: clearcoat, specular, diffuse and the transmission lobe.
 * The transmission lobe reflects from its facet or refracts through it, split by the
 * facet's own F_d, so refraction keeps a share wherever some facet lets light through
 * (beyond the critical angle of the mean surface a rough facet still may). */
KFN void principled_shares(Principled p, vec3 wo, float *w_cc, float *w_spec, float *w_diff, float *w_trans)
{
    float fs = principled_fresnel(p.eta, wo.z);
    *w_cc = p.clearcoat * schlick1(0.04f, wo.z);
    float rest = 1.0f - *w_cc, diel = rest * (1.0f - p.metallic), opaque = diel * (1.0f - p.transmission);
    *w_spec = rest * p.metallic + opaque * fs;
    *w_diff = opaque * (1.0f - fs);
    *w_trans = diel * p.transmission;
}

KFN float principled_eval(Principled p, vec3 wo, vec3 wi, vec3 *f)
{
    *f = v3s(0.0f);
    if (wo.z <= 0.0f || wi.z == 0.0f) return 0.0f;
    float w_cc, w_spec, w_diff, w_trans;
    principled_shares(p, wo, &w_cc, &w_spec, &w_diff, &w_trans);
    float layer = w_cc;                      /* c F_c: the clearcoat's share */
    if (wi.z > 0.0f) {
        float spec, coat = 0.0f, pdf_c = 0.0f;
        float pdf_s = ggx_reflection(p.g, wo, wi, &spec);
        if (p.clearcoat > 0.0f) pdf_c = ggx_reflection(p.gc, wo, wi, &coat);
        vec3 h = v3_norm(v3_add(wo, wi));
        float vh = v3_dot(wo, h);
        float fd = principled_fresnel(p.eta, vh);
        vec3 fm = fresnel_schlick(p.base, vh);
        vec3 mat = v3_add(v3_scale(p.base, (1.0f - p.metallic) * (1.0f - fd) * (1.0f - p.transmission) * K_INV_PI),
                          v3_scale(v3_add(v3_scale(fm, p.metallic), v3s((1.0f - p.metallic) * fd)), spec));
        *f = v3_add(v3_scale(mat, 1.0f - layer), v3s(layer * coat));
        /* the transmission lobe reflects from the facet h with probability F_d */
        return w_cc * pdf_c + (w_spec + w_trans * fd) * pdf_s + w_diff * wi.z * K_INV_PI;
    }
    if (!(w_trans > 0.0f)) return 0.0f;
    float btdf, pdf_t;
    vec3 m;
    if (p.thin) {
        vec3 wr = v3(wi.x, wi.y, -wi.z);
        pdf_t = ggx_reflection(p.g, wo, wr, &btdf);
        m = v3_norm(v3_add(wo, wr));
    } else {
        pdf_t = ggx_refraction(p.g, p.eta, wo, wi, &btdf);
        m = v3_norm(v3_add(v3_scale(wi, p.eta), wo));
        if (m.z < 0.0f) m = v3_neg(m);
    }
    float fd = principled_fresnel(p.eta, v3_dot(wo, m));
    *f = v3_scale(p.base, (1.0f - layer) * (1.0f - p.metallic) * p.transmission * (1.0f - fd) * btdf);
    return w_trans * (1.0f - fd) * pdf_t;
}

/* A direction for wo, *f and the density as principled_eval's (0: failed sample). */
KFN float principled_sample(Principled p, vec3 wo, float u_lobe, float u1, float u2, vec3 *wi, vec3 *f)
{
    *f = v3s(0.0f);
    if (wo.z <= 0.0f) return 0.0f;
    float w_cc, w_spec, w_diff, w_trans;
    principled_shares(p, wo, &w_cc, &w_spec, &w_diff, &w_trans);
    int up = 1;
    float w_up = w_cc + w_spec + w_diff;
    if (u_lobe < w_cc) {
        *wi = mf_reflect(wo, ggx_sample_visible(p.gc, wo, u1, u2));
    } else if (u_lobe < w_cc + w_spec) {
        *wi = mf_reflect(wo, ggx_sample_visible(p.g, wo, u1, u2));
    } else if (u_lobe < w_up || !(w_trans > 0.0f)) {
        *wi = sample_cosine_hemisphere(u1, u2);
    } else {
        vec3 m = ggx_sample_visible(p.g, wo, u1, u2);
        *wi = mf_reflect(wo, m);
        /* the rest of u_lobe, rescaled to [0, 1), chooses reflection from the facet */
        float u_facet = k_fmin((u_lobe - w_up) / w_trans, 0.99999994f);
        if (!(u_facet < principled_fresnel(p.eta, v3_dot(wo, m)))) {
            up = 0;
            if (p.thin) wi->z = -wi->z;
            else if (!mf_refract(wo, m, p.eta, wi)) return 0.0f;
        }
    }
    /* as for the dielectric: a lobe's sample on the other side is lost */
    if (up ? wi->z <= 0.0f : wi->z >= 0.0f) return 0.0f;
    return principled_eval(p, wo, *wi, f);
}

#endif /* CLPT_PRINCIPLED_H */
