/*
 * layered.h — pbrt-v4's coated materials (MAT_LAYERED): a dielectric interface, smooth
 * or GGX, over an opaque base (Lambertian, or a GGX conductor), with a slab of
 * homogeneous medium between them: `thickness` its optical depth along the normal
 * (extinction 1), `albedo` its single-scattering albedo, `g` its Henyey-Greenstein
 * asymmetry. Two-sided, as pbrt's coated BxDFs: seen from either side it is the same.
 *
 * The stack has no closed form. As in Guo, Hasan, Yan and Zhao 2018, "Position-Free
 * Monte Carlo Simulation for Arbitrary Layered BSDFs" (ACM TOG 37(6)), and in its form
 * in pbrt-v4 (LayeredBxDF in src/pbrt/bxdfs.h), the stack is simulated by random walks
 * that only track depth z in the slab and a direction, never a position:
 *  - sampling: refract in (or reflect off the interface and stop), then bounce between
 *    medium, base and the interface's underside until the interface lets the path out,
 *    roulette or max_depth end it; the path's f cos / pdf is an unbiased weight;
 *  - evaluation: n_samples such walks from wo, each joined at every vertex to a
 *    direction refracted in from wi (next-event estimation, power-heuristic MIS with
 *    the walk's own next direction when the interface is rough; unlike pbrt, each
 *    strategy's weight reads the other strategy's density of the same direction);
 *  - density: an estimate of the first internal bounce's (the TRT term) mixed with a
 *    uniform one, pbrt's approximation: it is what MIS weighs with, not the exact
 *    density of the sampler's paths (bsdf_sample's weight does not use it).
 * Each estimate draws its random numbers from a hash of its arguments' bits (wo and wi,
 * or wo and the sampler's numbers), as pbrt seeds its RNG from them: the same question
 * gets the same answer on every device and at every call, so the MIS weights that
 * next-event estimation and a BSDF sample compute for one direction still sum to one.
 *
 * Local frame throughout: z is the surface normal on the viewer's side (wo.z > 0); the
 * interface is at depth z = thickness, the base at 0, the slab between. Transmission
 * through the interface follows pbrt's convention for camera paths (radiance): divided
 * by the square of the index ratio; the importance-mode walks (from wi) leave it out,
 * and the two meet in the middle, so the stack is reciprocal.
 */
#ifndef CLPT_LAYERED_H
#define CLPT_LAYERED_H

#include "bsdf/bsdf_base.h"
#include "bsdf/conductor.h"
#include "bsdf/fresnel.h"
#include "sample/rng.h"

#define LAYER_R 1u        /* which lobes an interface sample may pick: reflection ... */
#define LAYER_T 2u        /* ... transmission */
#define LAYER_RT 3u

typedef struct {
    Ggx g;               /* the interface's roughness */
    float eta;           /* the medium's index over the outside's */
    int conductor;       /* base: a GGX conductor (c), else Lambertian (diffuse) */
    Conductor c;         /* its index relative to the medium, tint 1 */
    vec3 diffuse;
    vec3 albedo;         /* the medium's single-scattering albedo; 0: no scattering */
    float thickness, hg_g;
    uint max_depth, n_samples;
} Layered;

/* One scattering at an interface or in the medium. */
typedef struct {
    vec3 wi, f;
    float pdf;
    int delta;           /* a delta lobe: pdf is a probability, f carries 1/|cos| */
    int ok;              /* 0: no sample (total internal reflection, a facet's back) */
} LayerSample;

/* ---------------------------------------------------------------- the walk's numbers */

KFN uint layer_seed(uint salt, vec3 a, vec3 b)
{
    uint h = rng_hash(salt ^ k_as_uint(a.x));
    h = rng_hash(h ^ k_as_uint(a.y));
    h = rng_hash(h ^ k_as_uint(a.z));
    h = rng_hash(h ^ k_as_uint(b.x));
    h = rng_hash(h ^ k_as_uint(b.y));
    return rng_hash(h ^ k_as_uint(b.z));
}

/* A uniform number in [0, 1): the hash of a Weyl sequence from the seed. */
KFN float layer_rand(uint *state)
{
    *state += 0x9e3779b9u;
    return (float)(rng_hash(*state) >> 8) * RNG_FLOAT_SCALE;
}

KFN float layer_power(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    if (a2 > 3.0e38f) return 1.0f;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

KFN float layer_exp(float x) { return k_exp2(x * 1.44269504f); }

/* Transmittance across a depth difference dz along w (extinction 1). */
KFN float layer_tr(float dz, vec3 w)
{
    if (k_fabs(dz) <= 1.17549435e-38f) return 1.0f;
    return layer_exp(-k_fabs(dz / w.z));
}

KFN int layer_has_medium(Layered L) { return L.albedo.x > 0.0f || L.albedo.y > 0.0f || L.albedo.z > 0.0f; }

KFN LayerSample layer_fail(void)
{
    LayerSample s;
    s.wi = v3(0.0f, 0.0f, 1.0f);
    s.f = v3s(0.0f);
    s.pdf = 0.0f;
    s.delta = 0;
    s.ok = 0;
    return s;
}

/* ---------------------------------------------------------------- the interface
 * A dielectric seen from either side: wo below (wo.z < 0) is the medium's side; both
 * directions are turned over so that the GGX helpers see wo above, with the index
 * ratio etap of the side wi goes to over wo's. */

KFN int coat_smooth(Layered L) { return ggx_smooth(L.g) || L.eta == 1.0f; }

/* The choice probability of the lobe `reflect` among those `flags` allows. */
KFN float coat_lobe_prob(float F, int reflect, uint flags)
{
    float pr = (flags & LAYER_R) ? F : 0.0f, pt = (flags & LAYER_T) ? 1.0f - F : 0.0f;
    if (!(pr + pt > 0.0f)) return 0.0f;
    return (reflect ? pr : pt) / (pr + pt);
}

KFN LayerSample coat_sample(Layered L, vec3 wo, float uc, float u1, float u2, int radiance, uint flags)
{
    LayerSample s = layer_fail();
    float sg = wo.z > 0.0f ? 1.0f : -1.0f;
    vec3 w = v3_scale(wo, sg);
    float etap = wo.z > 0.0f ? L.eta : 1.0f / L.eta;
    vec3 m = v3(0.0f, 0.0f, 1.0f);
    if (!coat_smooth(L)) m = ggx_sample_visible(L.g, w, u1, u2);
    float om = v3_dot(w, m);
    if (!(om > 0.0f)) return s;
    float F = fresnel_dielectric(om, etap);
    float p_r = coat_lobe_prob(F, 1, flags);
    int reflect = uc < p_r;
    float p = reflect ? p_r : coat_lobe_prob(F, 0, flags);
    if (!(p > 0.0f)) return s;
    vec3 wi;
    if (reflect) {
        wi = mf_reflect(w, m);
        if (wi.z <= 0.0f) return s;
    } else if (!mf_refract(w, m, etap, &wi) || wi.z >= 0.0f) {
        return s;
    }
    if (coat_smooth(L)) {
        float t = reflect ? F : (1.0f - F) / (radiance ? etap * etap : 1.0f);
        s.f = v3s(t / k_fabs(wi.z));
        s.pdf = p;
        s.delta = 1;
    } else {
        float D = ggx_d(L.g, m), G = ggx_g2(L.g, w, wi), dv = ggx_d_visible(L.g, w, m);
        if (reflect) {
            s.f = v3s(F * D * G / (4.0f * w.z * wi.z));
            s.pdf = p * dv / (4.0f * om);
        } else {
            float im = v3_dot(wi, m), denom = k_sqr(im + om / etap);
            float t = (1.0f - F) * D * G * k_fabs(im) * om / (k_fabs(wi.z) * w.z * denom);
            s.f = v3s(radiance ? t / (etap * etap) : t);
            s.pdf = p * dv * k_fabs(im) / denom;
        }
    }
    s.wi = v3_scale(wi, sg);
    s.ok = s.pdf > 0.0f;
    return s;
}

/* f(wo, wi) of the rough interface (both lobes), and in *pdf coat_sample's density of
 * picking wi among the lobes `flags` allows. A smooth interface: 0 (only deltas). */
KFN vec3 coat_eval(Layered L, vec3 wo, vec3 wi, int radiance, uint flags, float *pdf)
{
    *pdf = 0.0f;
    if (coat_smooth(L) || wo.z == 0.0f || wi.z == 0.0f) return v3s(0.0f);
    float sg = wo.z > 0.0f ? 1.0f : -1.0f;
    vec3 w = v3_scale(wo, sg), v = v3_scale(wi, sg);
    float etap = wo.z > 0.0f ? L.eta : 1.0f / L.eta;
    int reflect = v.z > 0.0f;
    vec3 m = reflect ? v3_add(w, v) : v3_add(v3_scale(v, etap), w);
    float len = v3_len(m);
    if (!(len > 0.0f)) return v3s(0.0f);
    m = v3_scale(m, 1.0f / len);
    if (m.z < 0.0f) m = v3_neg(m);
    float om = v3_dot(w, m), im = v3_dot(v, m);
    /* facets seen from their back by either direction contribute nothing */
    if (om <= 0.0f || (reflect ? im <= 0.0f : im >= 0.0f)) return v3s(0.0f);
    float F = fresnel_dielectric(om, etap);
    float D = ggx_d(L.g, m), G = ggx_g2(L.g, w, v), dv = ggx_d_visible(L.g, w, m);
    float p = coat_lobe_prob(F, reflect, flags);
    if (reflect) {
        *pdf = p * dv / (4.0f * om);
        return v3s(F * D * G / (4.0f * w.z * v.z));
    }
    float denom = k_sqr(im + om / etap);
    if (!(denom > 0.0f)) return v3s(0.0f);
    *pdf = p * dv * k_fabs(im) / denom;
    float t = (1.0f - F) * D * G * k_fabs(im) * om / (k_fabs(v.z) * w.z * denom);
    return v3s(radiance ? t / (etap * etap) : t);
}

/* ---------------------------------------------------------------- the base
 * Opaque, reflecting upward: wo.z > 0 on entry (a walk reaches it going down). */

KFN int base_smooth(Layered L) { return L.conductor && ggx_smooth(L.c.g); }

KFN LayerSample base_sample(Layered L, vec3 wo, float u1, float u2)
{
    LayerSample s = layer_fail();
    if (!(wo.z > 0.0f)) return s;
    if (!L.conductor) {
        s.wi = sample_cosine_hemisphere(u1, u2);
        s.f = v3_scale(L.diffuse, K_INV_PI);
        s.pdf = s.wi.z * K_INV_PI;
    } else if (base_smooth(L)) {
        s.wi = v3(-wo.x, -wo.y, wo.z);
        s.f = v3_scale(conductor_fresnel(L.c, wo.z), 1.0f / wo.z);
        s.pdf = 1.0f;
        s.delta = 1;
    } else {
        s.pdf = conductor_sample(L.c, wo, u1, u2, &s.wi, &s.f);
    }
    s.ok = s.pdf > 0.0f;
    return s;
}

KFN vec3 base_eval(Layered L, vec3 wo, vec3 wi, float *pdf)
{
    *pdf = 0.0f;
    if (!(wo.z > 0.0f && wi.z > 0.0f) || base_smooth(L)) return v3s(0.0f);
    if (!L.conductor) {
        *pdf = wi.z * K_INV_PI;
        return v3_scale(L.diffuse, K_INV_PI);
    }
    vec3 f;
    *pdf = conductor_eval(L.c, wo, wi, &f);
    return f;
}

/* ---------------------------------------------------------------- the medium
 * Henyey-Greenstein with wo pointing away from the scattering point, as all
 * directions here: forward scattering (g > 0) favours wi = -wo. */

KFN float hg_phase(float g, vec3 wo, vec3 wi)
{
    float c = -v3_dot(wo, wi);   /* cosine between travel before and after */
    float denom = 1.0f + g * g - 2.0f * g * c;
    return 0.25f * K_INV_PI * (1.0f - g * g) / (denom * k_safe_sqrt(denom));
}

KFN LayerSample hg_sample(float g, vec3 wo, float u1, float u2)
{
    LayerSample s = layer_fail();
    g = k_clamp(g, -0.99f, 0.99f);
    float c;   /* cosine to the travel direction -wo, inverted from HG's cdf */
    if (k_fabs(g) < 1e-3f) {
        c = 1.0f - 2.0f * u1;
    } else {
        float q = (1.0f - g * g) / (1.0f - g + 2.0f * g * u1);
        c = (1.0f + g * g - q * q) / (2.0f * g);
    }
    c = k_clamp(c, -1.0f, 1.0f);
    float sn = k_safe_sqrt(1.0f - c * c), sp, cp;
    k_sincos(K_TWO_PI * u2, &sp, &cp);
    vec3 d = v3_neg(wo), t, b;
    k_onb(d, &t, &b);
    s.wi = v3_norm(k_to_world(v3(sn * cp, sn * sp, c), t, b, d));
    s.pdf = hg_phase(g, wo, s.wi);
    s.f = v3s(s.pdf);
    s.ok = s.pdf > 0.0f && s.wi.z != 0.0f;
    return s;
}

/* Depth of a free flight from z along w: an exponential distance, its vertical part. */
KFN float layer_flight(float z, vec3 w, float u)
{
    float dz = -k_log2(1.0f - u) * 0.693147181f * k_fabs(w.z);
    return w.z > 0.0f ? z + dz : z - dz;
}

/* ---------------------------------------------------------------- evaluation */

/* The density with which the walk's wis (sampled from wi, transmission only) would be
 * the direction -w, w going up inside: the other strategy's density in the MIS of a
 * path's exit. pbrt-v4 weighs with the density of the reverse, -w to wi, there (a
 * density over the directions outside, not over w); the weights of the two ways to one
 * direction then do not sum to one, and its estimate of f comes out above the true
 * value: against an independent particle simulation of rough coats (test_bsdf), 2 to
 * 10% over a Lambertian base as the coat's alpha goes from 0.09 to 0.55, up to 18% over
 * a rough conductor, while this weight agrees within noise (docs/pbrt.md has the
 * table). -DCLPT_LAYERED_PBRT_EXIT_PDF puts pbrt's weight back, for comparisons with
 * pbrt-v4's images only. */
KFN float layer_wis_pdf(Layered L, vec3 wi, vec3 w)
{
    float p;
#ifdef CLPT_LAYERED_PBRT_EXIT_PDF
    coat_eval(L, v3_neg(w), wi, 1, LAYER_T, &p);
#else
    coat_eval(L, wi, v3_neg(w), 0, LAYER_T, &p);
#endif
    return p;
}

/* The NEE and exit terms of one walk from wo toward wi (both above; wis the direction
 * refracted in from wi, sampled once per walk); the body of pbrt's LayeredBxDF::f loop
 * for an opaque base, so exit is always through the interface at z = thickness. */
KFN vec3 layered_walk(Layered L, vec3 wi, LayerSample wos, LayerSample wis, uint *rng)
{
    vec3 f = v3s(0.0f);
    float top = L.thickness;
    int medium = layer_has_medium(L), rough_top = !coat_smooth(L), rough_base = !base_smooth(L);
    vec3 beta = v3_scale(wos.f, k_fabs(wos.wi.z) / wos.pdf);
    vec3 wis_w = v3_scale(wis.f, 1.0f / wis.pdf);   /* the exit's f / pdf through wis */
    vec3 w = wos.wi;
    float z = top, pe;
    for (uint depth = 0u; depth < L.max_depth; depth++) {
        /* roulette on faint paths, after a few bounces */
        if (depth > 3u && v3_max_comp(beta) < 0.25f) {
            float q = k_fmax(0.0f, 1.0f - v3_max_comp(beta));
            if (layer_rand(rng) < q) break;
            beta = v3_scale(beta, 1.0f / (1.0f - q));
        }
        if (!medium) {
            z = z == top ? 0.0f : top;
            beta = v3_scale(beta, layer_tr(top, w));
        } else {
            float zp = layer_flight(z, w, layer_rand(rng));
            if (zp == z) continue;
            if (0.0f < zp && zp < top) {
                /* scattered in the medium: toward wis, then on along the phase function */
                float ph = hg_phase(L.hg_g, v3_neg(w), v3_neg(wis.wi));
                float wt = rough_top ? layer_power(wis.pdf, ph) : 1.0f;
                f = v3_add(f, v3_mul(v3_mul(beta, L.albedo), v3_scale(wis_w, ph * wt * layer_tr(zp - top, wis.wi))));
                float ua = layer_rand(rng), ub = layer_rand(rng);
                LayerSample ps = hg_sample(L.hg_g, v3_neg(w), ua, ub);
                if (!ps.ok) continue;
                beta = v3_mul(beta, L.albedo);   /* HG is sampled exactly: p / pdf = 1 */
                w = ps.wi;
                z = zp;
                if (w.z > 0.0f && rough_top) {
                    vec3 fe = coat_eval(L, v3_neg(w), wi, 1, LAYER_T, &pe);
                    float wt2 = layer_power(ps.pdf, layer_wis_pdf(L, wi, w));
                    f = v3_add(f, v3_mul(beta, v3_scale(fe, wt2 * layer_tr(zp - top, w))));
                }
                continue;
            }
            z = k_clamp(zp, 0.0f, top);
        }
        float uc = layer_rand(rng), u1 = layer_rand(rng), u2 = layer_rand(rng);
        if (z == top) {
            /* back down off the interface's underside */
            LayerSample bs = coat_sample(L, v3_neg(w), uc, u1, u2, 1, LAYER_R);
            if (!bs.ok) break;
            beta = v3_mul(beta, v3_scale(bs.f, k_fabs(bs.wi.z) / bs.pdf));
            w = bs.wi;
            continue;
        }
        /* at the base: toward wis, then a sampled bounce, and from it out toward wi */
        if (rough_base) {
            float pb;
            vec3 fb = base_eval(L, v3_neg(w), v3_neg(wis.wi), &pb);
            float wt = rough_top ? layer_power(wis.pdf, pb) : 1.0f;
            float s = k_fabs(wis.wi.z) * wt * layer_tr(top, wis.wi);
            f = v3_add(f, v3_mul(v3_mul(beta, fb), v3_scale(wis_w, s)));
        }
        LayerSample bs = base_sample(L, v3_neg(w), u1, u2);
        if (!bs.ok) break;
        beta = v3_mul(beta, v3_scale(bs.f, k_fabs(bs.wi.z) / bs.pdf));
        w = bs.wi;
        if (rough_top) {
            vec3 fe = coat_eval(L, v3_neg(w), wi, 1, LAYER_T, &pe);
            float wt = rough_base ? layer_power(bs.pdf, layer_wis_pdf(L, wi, w)) : 1.0f;
            f = v3_add(f, v3_mul(beta, v3_scale(fe, wt * layer_tr(top, w))));
        }
    }
    return f;
}

/* The two ends of one walk, both refracted into the layer by the interface: wo's as
 * radiance, wi's as importance, three numbers of *rng each; 0 where either fails. */
KFN int layer_walk_ends(Layered L, vec3 wo, vec3 wi, uint *rng, LayerSample *wos, LayerSample *wis)
{
    float a = layer_rand(rng), b = layer_rand(rng), c = layer_rand(rng);
    *wos = coat_sample(L, wo, a, b, c, 1, LAYER_T);
    a = layer_rand(rng), b = layer_rand(rng), c = layer_rand(rng);
    *wis = coat_sample(L, wi, a, b, c, 0, LAYER_T);
    return wos->ok && wis->ok;
}

/* f(wo, wi), estimated: the interface's own reflection plus n_samples walks. */
KFN vec3 layered_f(Layered L, vec3 wo, vec3 wi)
{
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return v3s(0.0f);
    float pdf;
    vec3 f = v3_scale(coat_eval(L, wo, wi, 1, LAYER_RT, &pdf), (float)L.n_samples);
    uint rng = layer_seed(0x1a7e4edu, wo, wi);
    for (uint i = 0u; i < L.n_samples; i++) {
        LayerSample wos, wis;
        if (!layer_walk_ends(L, wo, wi, &rng, &wos, &wis)) continue;
        f = v3_add(f, layered_walk(L, wi, wos, wis, &rng));
    }
    return v3_scale(f, 1.0f / (float)L.n_samples);
}

/* The density MIS weighs with, estimated: the interface's reflection, and one bounce
 * at the base between refractions in and out (pbrt's TRT estimate, MIS-combined from
 * both ends when both are rough), mixed 9 : 1 with the uniform sphere so that it is
 * never 0 where the walk can go. */
KFN float layered_pdf(Layered L, vec3 wo, vec3 wi)
{
    if (!(wo.z > 0.0f && wi.z > 0.0f)) return 0.0f;
    float sum, p;
    coat_eval(L, wo, wi, 1, LAYER_R, &sum);
    sum *= (float)L.n_samples;
    uint rng = layer_seed(0x9df3c11u, wi, wo);
    for (uint i = 0u; i < L.n_samples; i++) {
        LayerSample wos, wis;
        if (!layer_walk_ends(L, wo, wi, &rng, &wos, &wis)) continue;
        if (coat_smooth(L)) {
            base_eval(L, v3_neg(wos.wi), v3_neg(wis.wi), &p);
            sum += p;
            continue;
        }
        float a = layer_rand(&rng), b = layer_rand(&rng);
        LayerSample rs = base_sample(L, v3_neg(wos.wi), a, b);
        if (!rs.ok) continue;
        if (base_smooth(L)) {
            coat_eval(L, v3_neg(rs.wi), wi, 1, LAYER_RT, &p);
            sum += p;
            continue;
        }
        float pr, pt;
        base_eval(L, v3_neg(wos.wi), v3_neg(wis.wi), &pr);
        sum += layer_power(wis.pdf, pr) * pr;
        coat_eval(L, v3_neg(rs.wi), wi, 1, LAYER_RT, &pt);
        sum += layer_power(rs.pdf, pt) * pt;
    }
    return 0.1f * 0.25f * K_INV_PI + 0.9f * sum / (float)L.n_samples;
}

/* ---------------------------------------------------------------- sampling */

typedef struct {
    vec3 wi;             /* the path's direction out */
    vec3 weight;         /* its f cos / pdf; 0 when the walk found no way out */
    int delta;           /* every scattering on the path was a delta */
} LayeredSample;

KFN LayeredSample layered_out(vec3 wi, vec3 weight, int delta)
{
    LayeredSample r;
    r.wi = wi;
    r.weight = weight;
    r.delta = delta;
    return r;
}

/* A path through the stack from wo (pbrt's LayeredBxDF::Sample_f). pbrt keeps the
 * path's f and pdf apart; here only their ratio beta is kept, as a product of a few
 * hundred densities (max_depth) can underflow a float. */
KFN LayeredSample layered_sample(Layered L, vec3 wo, float uc, float u1, float u2)
{
    LayeredSample none = layered_out(v3(0.0f, 0.0f, 1.0f), v3s(0.0f), 0);
    if (!(wo.z > 0.0f)) return none;
    LayerSample bs = coat_sample(L, wo, uc, u1, u2, 1, LAYER_RT);
    if (!bs.ok) return none;
    vec3 beta = v3_scale(bs.f, k_fabs(bs.wi.z) / bs.pdf);
    if (bs.wi.z > 0.0f) return layered_out(bs.wi, beta, bs.delta);   /* reflected off the interface */
    uint rng = layer_seed(0x5e7d1a3u, wo, v3(uc, u1, u2));
    int medium = layer_has_medium(L), delta = bs.delta;
    float top = L.thickness, z = top;
    vec3 w = bs.wi;
    for (uint depth = 0u; depth < L.max_depth; depth++) {
        float rr = v3_max_comp(beta);
        if (depth > 3u && rr < 0.25f) {
            float q = k_fmax(0.0f, 1.0f - rr);
            if (layer_rand(&rng) < q) return none;
            beta = v3_scale(beta, 1.0f / (1.0f - q));
        }
        if (w.z == 0.0f) return none;
        if (medium) {
            float zp = layer_flight(z, w, layer_rand(&rng));
            if (zp == z) return none;
            if (0.0f < zp && zp < top) {
                /* scattered: Henyey-Greenstein is sampled exactly, p / pdf = 1 */
                float a = layer_rand(&rng), b = layer_rand(&rng);
                LayerSample ps = hg_sample(L.hg_g, v3_neg(w), a, b);
                if (!ps.ok) return none;
                beta = v3_mul(beta, L.albedo);
                delta = 0;
                w = ps.wi;
                z = zp;
                continue;
            }
            z = k_clamp(zp, 0.0f, top);
        } else {
            z = z == top ? 0.0f : top;
            beta = v3_scale(beta, layer_tr(top, w));
        }
        float c = layer_rand(&rng), a = layer_rand(&rng), b = layer_rand(&rng);
        bs = z == top ? coat_sample(L, v3_neg(w), c, a, b, 1, LAYER_RT) : base_sample(L, v3_neg(w), a, b);
        if (!bs.ok) return none;
        beta = v3_mul(beta, v3_scale(bs.f, k_fabs(bs.wi.z) / bs.pdf));
        delta = delta && bs.delta;
        w = bs.wi;
        if (z == top && w.z > 0.0f) return layered_out(w, beta, delta);   /* out through the interface */
    }
    return none;
}

/* The coated material's stack; the conductor base's index is relative to the medium
 * under the interface (pbrt-v4's CoatedConductorMaterial divides by its index too). */
KFN Layered bsdf_layered(Material m, vec3 albedo)
{
    Layered L;
    L.g = bsdf_ggx(m);
    L.eta = m.ior > 0.0f ? m.ior : 1.0f;
    L.conductor = m.layer_base == LAYER_BASE_CONDUCTOR;
    L.c.g = ggx_make(m.base_roughness, m.base_anisotropy);
    L.c.eta = v3_scale(m.eta, 1.0f / L.eta);
    L.c.k = v3_scale(m.k, 1.0f / L.eta);
    L.c.f0 = v3s(0.0f);
    L.c.tint = albedo;
    L.c.schlick = 0;
    L.diffuse = albedo;
    L.albedo = m.layer_albedo;
    L.thickness = k_fmax(m.layer_thickness, 1.17549435e-38f);
    L.hg_g = m.layer_g;
    /* bounded: the walks are loops of at most this many steps */
    L.max_depth = m.layer_depth < 256u ? m.layer_depth : 256u;
    L.n_samples = m.layer_samples < 1u ? 1u : m.layer_samples < 64u ? m.layer_samples : 64u;
    return L;
}

/* A path through a coated material's stack (layered.h). Its weight is the walk's own f
 * cos / pdf; the density handed on for MIS is layered_pdf's estimate for the direction
 * as bsdf_eval would see it (world, then local again), so that the MIS weights of next-event
 * estimation and of this sample for one direction are computed from the same number. */
KFN BsdfSample bsdf_sample_layered(Material m, vec3 albedo, vec3 d, vec3 ns, float u_lobe, float u1, float u2)
{
    BsdfSample s;
    vec3 t, b;
    k_onb(ns, &t, &b);
    Layered L = bsdf_layered(m, albedo);
    vec3 wo = bsdf_to_local(v3_neg(d), t, b, ns);
    LayeredSample r = layered_sample(L, wo, u_lobe, u1, u2);
    if (!(v3_max_comp(r.weight) > 0.0f)) return bsdf_failed(ns);
    s.transmitted = 0;
    s.wi = v3_norm(k_to_world(r.wi, t, b, ns));
    s.weight = r.weight;
    s.specular = r.delta;
    s.pdf = r.delta ? 0.0f : layered_pdf(L, wo, bsdf_to_local(s.wi, t, b, ns));
    return s;
}

/* ---------------------------------------------------------------- MAT_LAYERED */
KFN int layered_bsdf_has_density(Material m, vec3 albedo)
{
    /* only a stack of smooth surfaces over a smooth conductor, no medium, is all deltas */
    Layered L = bsdf_layered(m, albedo);
    return !(coat_smooth(L) && base_smooth(L) && !layer_has_medium(L));
}

KFN vec3 layered_bsdf_eval(Material m, BsdfHit h, vec3 wi, float *pdf)
{
    if (!layered_bsdf_has_density(m, h.albedo)) return bsdf_no_eval(pdf);
    vec3 wo;
    BsdfFrame F = bsdf_hit_frame(h, &wo);
    vec3 wl = bsdf_frame_local(F, wi);
    Layered L = bsdf_layered(m, h.albedo);
    vec3 f = layered_f(L, wo, wl);
    *pdf = layered_pdf(L, wo, wl);
    return f;
}

KFN BsdfSample layered_bsdf_sample(Material m, BsdfHit h, float u_lobe, float u1, float u2, float u3)
{
    (void)u3;
    return bsdf_sample_layered(m, h.albedo, h.d, h.ns, u_lobe, u1, u2);
}

#endif /* CLPT_LAYERED_H */
