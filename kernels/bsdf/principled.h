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
 * KHR_materials_specular scales the dielectric F_d's ends: F0 = min(F0(ior) specular_color,
 * 1) specular and F90 = specular, so F_d is RGB (where it decides a path's branch,
 * its channels' mean is the probability). Past the critical angle it stays 1.
 *
 * KHR_materials_sheen layers a sheen between the clearcoat and the material:
 *   sheened = f_sheen + material * min(1 - max3(sheen) E(N.V), 1 - max3(sheen) E(N.L))
 * with f_sheen = sheen D_charlie V_charlie, the spec's "Charlie" lobe (Estevez & Kulla
 * 2017; alpha = sheen_roughness^2) and E its directional albedo (sheen_albedo.h, from
 * tools/sheen_albedo.py). The spec's albedo scaling keeps the layers from gaining energy
 * (white furnace <= 1). Below SHEEN_ROUGHNESS_MIN the paper's visibility fit makes a
 * lobe reflecting more than it receives at grazing views, so rougher is used there.
 *
 * Sampling picks a lobe by its share at wo (clearcoat c F_c, sheen, specular, diffuse,
 * transmission); the sheen's is a cosine-weighted hemisphere; the transmission lobe, like pbrt-v4's rough DielectricBxDF, samples a
 * visible facet and reflects from it with probability F_d (always under total internal
 * reflection), refracts otherwise. The whole mixture is then evaluated: its density is
 * the weighted sum.
 *
 * Subsurface scattering (docs/subsurface.md): a share `subsurface` W of the diffuse lobe
 * of a solid refracts into it through the transmission lobe's facets instead, untinted
 * (the colour is the interior medium's, MEDIUM_WALK), so the refracting share is
 * t + (1 - t) W and its tint base t + (1 - t) W. A walk that reaches the surface
 * again from inside leaves it as a Lambertian transmission (shade_path,
 * subsurface_exit_material), not through these lobes.
 *
 * KHR_materials_diffuse_transmission: of the diffuse layer that is left, a share dt
 * passes to the back side as a Lambertian BTDF, the spec's
 *   diffuse layer = mix(base / pi, dt_color / pi on the back side, dt)
 * weighted by (1 - F_d) taken at the facet between wo and wi mirrored through the
 * surface, as the reflected diffuse would be there: with dt_color = base the diffuse
 * layer's energy only changes side (a white diffuse-transmitting sheet in a white furnace
 * returns what the white opaque one does). Sampled as a cosine-weighted lower hemisphere.
 * dt 0 keeps every other material's lobes, shares and densities to the bit.
 */
#ifndef CLPT_PRINCIPLED_H
#define CLPT_PRINCIPLED_H

#include "bsdf/bsdf_base.h"
#include "bsdf/fresnel.h"
#include "bsdf/sheen_albedo.h"

typedef struct {
    vec3 base;
    float metallic, transmission, clearcoat;
    Ggx g, gc;         /* base and clearcoat roughness (alpha at least GGX_SMOOTH_ALPHA) */
    int smooth, cc_smooth;  /* below GGX_SMOOTH_ALPHA: the lobe is a delta lobe */
    float eta;         /* n_t / n_i for the refraction */
    int thin;
    float specular;    /* KHR_materials_specular: F90, and F0's scale ... */
    vec3 specular_color;  /* ... and F0's colour */
    vec3 sheen;        /* KHR_materials_sheen's colour, 0 for none */
    float sheen_roughness;   /* perceptual, at least SHEEN_ROUGHNESS_MIN */
    float subsurface;  /* the diffuse lobe's share that refracts into the solid */
    float diffuse_transmission;  /* the remaining diffuse layer's share sent to the back */
    vec3 dt_color;               /* ... its colour */
} Principled;

/* The share of the dielectric part that refracts (through the transmission lobe): the
 * transmission's and, with subsurface scattering, that much of the diffuse's. */
KFN float principled_refracting(Principled p)
{
    return p.subsurface > 0.0f ? p.transmission + (1.0f - p.transmission) * p.subsurface : p.transmission;
}

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

/* F_d per channel at cosine c on the incident side (see principled_fresnel), with
 * KHR_materials_specular's F0 and F90. At the defaults (1, white) it is
 * principled_fresnel's value to the bit. */
KFN vec3 principled_fresnel_rgb(Principled p, float c)
{
    c = k_clamp(c, 0.0f, 1.0f);
    if (p.eta < 1.0f) {
        float sin2_t = (1.0f - c * c) / (p.eta * p.eta);
        if (sin2_t >= 1.0f) return v3s(1.0f);
        c = k_sqrt(1.0f - sin2_t);
    }
    float m = 1.0f - c, m5 = m * m * m * m * m, f0 = principled_f0(p.eta);
    vec3 c0 = p.specular_color;
    c0 = v3(k_fmin(f0 * c0.x, 1.0f) * p.specular, k_fmin(f0 * c0.y, 1.0f) * p.specular,
            k_fmin(f0 * c0.z, 1.0f) * p.specular);
    return v3(c0.x + (p.specular - c0.x) * m5, c0.y + (p.specular - c0.y) * m5, c0.z + (p.specular - c0.z) * m5);
}

/* The probability that a dielectric facet with reflectance f reflects: the channels'
 * mean, exactly f's value when they agree (so grey materials sample as before). */
KFN float principled_reflect_prob(vec3 f)
{
    return f.x == f.y && f.y == f.z ? f.x : (f.x + f.y + f.z) * (1.0f / 3.0f);
}

/* ---------------------------------------------------------------- sheen */

/* E(mu) of the sheen lobe at roughness r: sheen_albedo_table read bilinearly, its
 * columns spaced in sqrt(mu). */
KFN float sheen_albedo(float mu, float r)
{
    float x = k_sqrt(k_clamp(mu, 0.0f, 1.0f)) * (float)(SHEEN_TABLE_MU - 1);
    float y = k_clamp((r - SHEEN_ROUGHNESS_MIN) / (1.0f - SHEEN_ROUGHNESS_MIN), 0.0f, 1.0f) *
              (float)(SHEEN_TABLE_R - 1);
    int i = (int)k_fmin(x, (float)(SHEEN_TABLE_MU - 2)), j = (int)k_fmin(y, (float)(SHEEN_TABLE_R - 2));
    float fx = x - (float)i, fy = y - (float)j;
    int at = j * SHEEN_TABLE_MU + i;
    float lo = sheen_albedo_table[at] + (sheen_albedo_table[at + 1] - sheen_albedo_table[at]) * fx;
    float hi = sheen_albedo_table[at + SHEEN_TABLE_MU] +
               (sheen_albedo_table[at + SHEEN_TABLE_MU + 1] - sheen_albedo_table[at + SHEEN_TABLE_MU]) * fx;
    return lo + (hi - lo) * fy;
}

/* Estevez & Kulla's fit of the sheen's Lambda (the exponent l(x) of its masking),
 * interpolated between their two roughness ends by (1 - alpha)^2. */
KFN float sheen_l(float x, float alpha)
{
    float t = (1.0f - alpha) * (1.0f - alpha);
    float a = 21.5473f + (25.3245f - 21.5473f) * t, b = 3.82987f + (3.32435f - 3.82987f) * t;
    float c = 0.19823f + (0.16801f - 0.19823f) * t, d = -1.97760f + (-1.27393f + 1.97760f) * t;
    float e = -4.32054f + (-4.85967f + 4.32054f) * t;
    return a / (1.0f + b * k_pow(x, c)) + d * x + e;
}

KFN float sheen_lambda(float mu, float alpha)
{
    const float log2e = 1.44269504f;
    mu = k_fabs(mu);
    float l = mu < 0.5f ? sheen_l(mu, alpha) : 2.0f * sheen_l(0.5f, alpha) - sheen_l(1.0f - mu, alpha);
    return k_exp2(l * log2e);
}

/* The Charlie lobe's f (without its colour) for wo, wi on the same side. */
KFN float sheen_lobe(float r, vec3 wo, vec3 wi)
{
    float alpha = r * r;
    vec3 h = v3_norm(v3_add(wo, wi));
    float sin2h = k_fmax(1.0f - h.z * h.z, 0.0f);
    float d = (2.0f + 1.0f / alpha) * k_pow(sin2h, 0.5f / alpha) * (0.5f * K_INV_PI);
    float v = 1.0f / ((1.0f + sheen_lambda(wo.z, alpha) + sheen_lambda(wi.z, alpha)) * 4.0f * wo.z * wi.z);
    return d * v;
}

/* What the sheen leaves of the layers below for the pair wo, wi (|cosines|). */
KFN float sheen_scaling(Principled p, float mu_o, float mu_i)
{
    float s = v3_max_comp(p.sheen);
    if (!(s > 0.0f)) return 1.0f;
    float e = k_fmax(sheen_albedo(mu_o, p.sheen_roughness), sheen_albedo(k_fabs(mu_i), p.sheen_roughness));
    return k_fmax(1.0f - s * e, 0.0f);
}

/* The lobes' shares at wo: clearcoat, specular, diffuse (reflected), diffuse
 * transmission and the transmission lobe.
 * The transmission lobe reflects from its facet or refracts through it, split by the
 * facet's own F_d, so refraction keeps a share wherever some facet lets light through
 * (beyond the critical angle of the mean surface a rough facet still may). */
KFN void principled_shares(Principled p, vec3 wo, float *w_cc, float *w_sheen, float *w_spec, float *w_diff,
                           float *w_dt, float *w_trans)
{
    float fs = principled_reflect_prob(principled_fresnel_rgb(p, wo.z));
    *w_cc = p.clearcoat * schlick1(0.04f, wo.z);
    float rest = 1.0f - *w_cc;
    *w_sheen = 0.0f;
    if (v3_max_comp(p.sheen) > 0.0f) {
        /* the sheen's share is its albedo; the layers below keep the rest */
        *w_sheen = rest * k_fmin(v3_max_comp(p.sheen) * sheen_albedo(wo.z, p.sheen_roughness), 1.0f);
        rest -= *w_sheen;
    }
    float t = principled_refracting(p);
    float diel = rest * (1.0f - p.metallic), opaque = diel * (1.0f - t);
    *w_spec = rest * p.metallic + opaque * fs;
    *w_diff = opaque * (1.0f - fs);
    /* subtracted, so that dt 0 leaves w_diff's bits */
    *w_dt = *w_diff * p.diffuse_transmission;
    *w_diff -= *w_dt;
    *w_trans = diel * t;
}

/* The lobes' shares at one wo (principled_shares), for principled_eval_shares. */
typedef struct {
    float cc, sheen, spec, diff, dt, trans;
} PrincipledShares;

/* principled_eval with the shares at wo already known: principled_sample has them for
 * the direction it samples (computing them again was a third of principled_shares'
 * 5% of a textured glTF render on PoCL, bench/RESULTS.md). wo.z > 0. */
KFN float principled_eval_shares(Principled p, PrincipledShares sh, vec3 wo, vec3 wi, vec3 *f)
{
    *f = v3s(0.0f);
    if (wi.z == 0.0f) return 0.0f;
    float w_cc = sh.cc, w_sheen = sh.sheen, w_spec = sh.spec, w_diff = sh.diff, w_dt = sh.dt, w_trans = sh.trans;
    float layer = w_cc;                      /* c F_c: the clearcoat's share */
    float below = sheen_scaling(p, wo.z, wi.z);
    if (wi.z > 0.0f) {
        float spec = 0.0f, coat = 0.0f, pdf_c = 0.0f, pdf_s = 0.0f;
        if (!p.smooth) pdf_s = ggx_reflection(p.g, wo, wi, &spec);
        if (p.clearcoat > 0.0f && !p.cc_smooth) pdf_c = ggx_reflection(p.gc, wo, wi, &coat);
        vec3 h = v3_norm(v3_add(wo, wi));
        float vh = v3_dot(wo, h);
        vec3 fd = principled_fresnel_rgb(p, vh);
        vec3 fm = fresnel_schlick(p.base, vh);
        vec3 mat = v3_add(v3_scale(v3_mul(p.base, v3_sub(v3s(1.0f), fd)),
                                   (1.0f - p.metallic) * (1.0f - principled_refracting(p)) *
                                       (1.0f - p.diffuse_transmission) * K_INV_PI),
                          v3_scale(v3_add(v3_scale(fm, p.metallic), v3_scale(fd, 1.0f - p.metallic)), spec));
        if (w_sheen > 0.0f)
            mat = v3_add(v3_scale(mat, below), v3_scale(p.sheen, sheen_lobe(p.sheen_roughness, wo, wi)));
        *f = v3_add(v3_scale(mat, 1.0f - layer), v3s(layer * coat));
        /* the transmission lobe reflects from the facet h with probability F_d */
        return w_cc * pdf_c + (w_spec + w_trans * principled_reflect_prob(fd)) * pdf_s +
               (w_diff + w_sheen) * wi.z * K_INV_PI;
    }
    vec3 f_dt = v3s(0.0f);
    float pdf_dt = 0.0f;
    if (w_dt > 0.0f) {
        /* Lambertian to the back, its Fresnel weight the reflected diffuse's at wi's mirror */
        vec3 h = v3_norm(v3_add(wo, v3(wi.x, wi.y, -wi.z)));
        vec3 fd = principled_fresnel_rgb(p, v3_dot(wo, h));
        f_dt = v3_scale(v3_mul(p.dt_color, v3_sub(v3s(1.0f), fd)),
                        (1.0f - layer) * (1.0f - p.metallic) * (1.0f - principled_refracting(p)) *
                            p.diffuse_transmission * K_INV_PI);
        if (w_sheen > 0.0f) f_dt = v3_scale(f_dt, below);
        pdf_dt = w_dt * -wi.z * K_INV_PI;
    }
    if (!(w_trans > 0.0f) || p.smooth) {
        *f = f_dt;
        return pdf_dt;
    }
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
    vec3 fd = principled_fresnel_rgb(p, v3_dot(wo, m));
    if (p.subsurface > 0.0f) {
        /* the transmission tinted by the base colour, the subsurface share untinted */
        vec3 tint = v3_add(v3_scale(p.base, p.transmission), v3s((1.0f - p.transmission) * p.subsurface));
        *f = v3_scale(v3_mul(tint, v3_sub(v3s(1.0f), fd)), (1.0f - layer) * (1.0f - p.metallic) * btdf);
    } else {
        *f = v3_scale(v3_mul(p.base, v3_sub(v3s(1.0f), fd)),
                      (1.0f - layer) * (1.0f - p.metallic) * p.transmission * btdf);
    }
    if (w_sheen > 0.0f) *f = v3_scale(*f, below);
    if (w_dt > 0.0f) {
        *f = v3_add(*f, f_dt);
        return w_trans * (1.0f - principled_reflect_prob(fd)) * pdf_t + pdf_dt;
    }
    return w_trans * (1.0f - principled_reflect_prob(fd)) * pdf_t;
}

KFN float principled_eval(Principled p, vec3 wo, vec3 wi, vec3 *f)
{
    *f = v3s(0.0f);
    if (wo.z <= 0.0f || wi.z == 0.0f) return 0.0f;
    PrincipledShares sh;
    principled_shares(p, wo, &sh.cc, &sh.sheen, &sh.spec, &sh.diff, &sh.dt, &sh.trans);
    return principled_eval_shares(p, sh, wo, wi, f);
}

/* A direction for wo, *f and the density as principled_eval's (0: failed sample; -1:
 * u_lobe chose a smooth lobe, which principled_sample_smooth samples). */
KFN float principled_sample(Principled p, vec3 wo, float u_lobe, float u1, float u2, vec3 *wi, vec3 *f)
{
    *f = v3s(0.0f);
    if (wo.z <= 0.0f) return 0.0f;
    float w_cc, w_sheen, w_spec, w_diff, w_dt, w_trans;
    principled_shares(p, wo, &w_cc, &w_sheen, &w_spec, &w_diff, &w_dt, &w_trans);
    int up = 1;
    float w_up = w_cc + w_sheen + w_spec + w_diff;
    /* a smooth lobe: the clearcoat, the specular or the transmission lobe (the order
     * of the branches below), which principled_sample_smooth samples */
    if (u_lobe < w_cc ? p.cc_smooth
                      : !(u_lobe < w_cc + w_sheen) && p.smooth &&
                            (u_lobe < w_cc + w_sheen + w_spec || (w_trans > 0.0f && !(u_lobe < w_up + w_dt))))
        return -1.0f;
    if (u_lobe < w_cc) {
        *wi = mf_reflect(wo, ggx_sample_visible(p.gc, wo, u1, u2));
    } else if (u_lobe < w_cc + w_sheen) {
        *wi = sample_cosine_hemisphere(u1, u2);
    } else if (u_lobe < w_cc + w_sheen + w_spec) {
        *wi = mf_reflect(wo, ggx_sample_visible(p.g, wo, u1, u2));
    } else if (u_lobe < w_up || (!(w_trans > 0.0f) && !(w_dt > 0.0f))) {
        *wi = sample_cosine_hemisphere(u1, u2);
    } else if (u_lobe < w_up + w_dt || !(w_trans > 0.0f)) {
        /* the diffuse transmission: the lower hemisphere, cosine-weighted */
        *wi = sample_cosine_hemisphere(u1, u2);
        wi->z = -wi->z;
        up = 0;
    } else {
        vec3 m = ggx_sample_visible(p.g, wo, u1, u2);
        *wi = mf_reflect(wo, m);
        /* the rest of u_lobe, rescaled to [0, 1), chooses reflection from the facet */
        float u_facet = k_fmin((u_lobe - (w_up + w_dt)) / w_trans, 0.99999994f);
        if (!(u_facet < principled_reflect_prob(principled_fresnel_rgb(p, v3_dot(wo, m))))) {
            up = 0;
            if (p.thin) wi->z = -wi->z;
            else if (!mf_refract(wo, m, p.eta, wi)) return 0.0f;
        }
    }
    /* as for the dielectric: a lobe's sample on the other side is lost */
    if (up ? wi->z <= 0.0f : wi->z >= 0.0f) return 0.0f;
    PrincipledShares sh = { w_cc, w_sheen, w_spec, w_diff, w_dt, w_trans };
    return principled_eval_shares(p, sh, wo, *wi, f);
}

/* The sample of a smooth lobe that u_lobe chose (principled_sample returned -1): the
 * mirror direction (the clearcoat, the specular lobe, the transmission lobe's
 * reflection) or the refraction (straight through a thin sheet) of wo about the
 * shading normal, and in *weight f cos over the probability of choosing that
 * direction. The mirror is reached by three lobes (the transmission lobe reflecting
 * with probability F_d), so its weight is its whole reflectance over their summed
 * probability, whichever chose it. Returns whether the direction is the refraction;
 * *weight 0: none (a refraction past the critical angle, which F_d = 1 never
 * chooses but rounding might). */
KFN int principled_sample_smooth(Principled p, vec3 wo, float u_lobe, vec3 *wi, vec3 *weight)
{
    float w_cc, w_sheen, w_spec, w_diff, w_dt, w_trans;
    principled_shares(p, wo, &w_cc, &w_sheen, &w_spec, &w_diff, &w_dt, &w_trans);
    *wi = v3(-wo.x, -wo.y, wo.z);
    if (u_lobe < w_cc) {
        /* the clearcoat reflects its share c F_c, white: f cos / P = 1 */
        *weight = v3s(1.0f);
        return 0;
    }
    vec3 fd = principled_fresnel_rgb(p, wo.z);
    float reflect_t = principled_reflect_prob(fd), layer = w_cc;
    float w_up = w_cc + w_sheen + w_spec + w_diff;
    float u_facet = w_trans > 0.0f ? k_fmin((u_lobe - (w_up + w_dt)) / w_trans, 0.99999994f) : 0.0f;
    if (u_lobe < w_cc + w_sheen + w_spec || u_facet < reflect_t) {
        vec3 r = v3_add(v3_scale(fresnel_schlick(p.base, wo.z), p.metallic), v3_scale(fd, 1.0f - p.metallic));
        float below = w_sheen > 0.0f ? sheen_scaling(p, wo.z, wo.z) : 1.0f;
        *weight = v3_scale(r, (1.0f - layer) * below / (w_spec + w_trans * reflect_t));
        return 0;
    }
    if (p.thin) {
        *wi = v3_neg(wo);
    } else if (!mf_refract(wo, v3(0.0f, 0.0f, 1.0f), p.eta, wi)) {
        *weight = v3s(0.0f);
        return 1;
    }
    /* principled_eval's transmission lobe, whose btdf integrates to 1 when smooth */
    vec3 tint = p.subsurface > 0.0f ? v3_add(v3_scale(p.base, p.transmission), v3s((1.0f - p.transmission) * p.subsurface))
                                    : v3_scale(p.base, p.transmission);
    float below = w_sheen > 0.0f ? sheen_scaling(p, wo.z, k_fabs(wi->z)) : 1.0f;
    *weight = v3_scale(v3_mul(tint, v3_sub(v3s(1.0f), fd)),
                       (1.0f - layer) * (1.0f - p.metallic) * below / (w_trans * (1.0f - reflect_t)));
    return 1;
}

/* The principled lobes. Alphas below GGX_SMOOTH_ALPHA make their lobes delta lobes
 * (smooth, cc_smooth), sampled by principled_sample_smooth and left out of
 * principled_eval, as the conductor and the dielectric do: at alpha 1e-3 a point
 * light's highlight in a roughness-0 sphere was a spot of GGX density 3e5 that a few
 * camera samples hit, fireflies of thousands in a pixel (the glTF material spheres,
 * bench/RESULTS.md). The alphas are still raised to it, for the GGX functions' sake. */
KFN Principled bsdf_principled(Material m, vec3 albedo, int front)
{
    Principled p;
    p.base = albedo;
    p.metallic = k_clamp(m.metallic, 0.0f, 1.0f);
    p.transmission = k_clamp(m.transmission, 0.0f, 1.0f);
    p.clearcoat = k_clamp(m.clearcoat, 0.0f, 1.0f);
    p.g = bsdf_ggx(m);
    p.smooth = ggx_smooth(p.g);
    p.cc_smooth = m.clearcoat_roughness * m.clearcoat_roughness < GGX_SMOOTH_ALPHA;
    p.g.ax = k_fmax(p.g.ax, GGX_SMOOTH_ALPHA);
    p.g.ay = k_fmax(p.g.ay, GGX_SMOOTH_ALPHA);
    float ac = k_fmax(m.clearcoat_roughness * m.clearcoat_roughness, GGX_SMOOTH_ALPHA);
    p.gc.ax = ac;
    p.gc.ay = ac;
    p.thin = (m.flags & MAT_THIN) != 0u;
    p.eta = p.thin || front ? m.ior : 1.0f / m.ior;
    p.specular = k_clamp(m.specular_factor, 0.0f, 1.0f);
    p.specular_color = v3(k_fmax(m.specular_color.x, 0.0f), k_fmax(m.specular_color.y, 0.0f),
                          k_fmax(m.specular_color.z, 0.0f));
    /* a sheen brighter than white would reflect more than it receives */
    p.sheen = v3(k_clamp(m.sheen_color.x, 0.0f, 1.0f), k_clamp(m.sheen_color.y, 0.0f, 1.0f),
                 k_clamp(m.sheen_color.z, 0.0f, 1.0f));
    p.sheen_roughness = k_clamp(m.sheen_roughness, SHEEN_ROUGHNESS_MIN, 1.0f);
    p.subsurface = p.thin ? 0.0f : k_clamp(m.subsurface, 0.0f, 1.0f);
    p.diffuse_transmission = k_clamp(m.diffuse_transmission, 0.0f, 1.0f);
    /* a tint brighter than white would pass on more than it receives */
    p.dt_color = v3(k_clamp(m.diffuse_transmission_color.x, 0.0f, 1.0f),
                    k_clamp(m.diffuse_transmission_color.y, 0.0f, 1.0f),
                    k_clamp(m.diffuse_transmission_color.z, 0.0f, 1.0f));
    return p;
}

/* ---------------------------------------------------------------- MAT_PRINCIPLED */
/* A lobe with a density: any but a smooth metal with no rough clearcoat and no sheen
 * (read from the material's fields as bsdf_principled clamps them, without building the
 * lobes, which shading builds again). */
KFN int principled_bsdf_has_density(Material m, vec3 albedo)
{
    (void)albedo;
    int rough_coat = m.clearcoat > 0.0f && !(m.clearcoat_roughness * m.clearcoat_roughness < GGX_SMOOTH_ALPHA);
    return !ggx_smooth(bsdf_ggx(m)) || !(m.metallic >= 1.0f) || rough_coat || v3_max_comp(m.sheen_color) > 0.0f;
}

KFN vec3 principled_bsdf_eval(Material m, BsdfHit h, vec3 wi, float *pdf)
{
    vec3 wo, f;
    BsdfFrame F = bsdf_hit_frame(h, &wo);
    *pdf = principled_eval(bsdf_principled(m, h.albedo, h.front), wo, bsdf_frame_local(F, wi), &f);
    return f;
}

KFN BsdfSample principled_bsdf_sample(Material m, BsdfHit h, float u_lobe, float u1, float u2, float u3)
{
    (void)u3;
    vec3 wo, f = v3s(0.0f), wl = v3s(0.0f);
    BsdfFrame F = bsdf_hit_frame(h, &wo);
    Principled p = bsdf_principled(m, h.albedo, h.front);
    float pdf = wo.z > 0.0f ? principled_sample(p, wo, u_lobe, u1, u2, &wl, &f) : 0.0f;
    if (pdf < 0.0f) {
        vec3 weight;
        int transmitted = principled_sample_smooth(p, wo, u_lobe, &wl, &weight);
        if (v3_is_zero(weight)) return bsdf_failed(F.n);
        vec3 wi = v3_norm(k_to_world(wl, F.t, F.b, F.n));
        /* a direction on the wrong side of the geometric surface is taken about ng, as
         * the dielectric does (bsdf_sample_dielectric) */
        if (transmitted ? !(v3_dot(wi, h.ng) < 0.0f) : !(v3_dot(wi, h.ng) > 0.0f)) {
            if (transmitted) return bsdf_failed(F.n);
            wi = reflect_dir(h.d, h.ng);
        }
        return bsdf_delta_sample(wi, weight, transmitted);
    }
    return bsdf_rough_sample(F, pdf, wl, f);
}

#endif /* CLPT_PRINCIPLED_H */
