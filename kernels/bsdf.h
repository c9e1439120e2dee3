/*
 * bsdf.h — how each material scatters light: sampling a new direction and, for the
 * non-delta lobes, evaluating the BSDF and its density for next-event estimation.
 * Directions point away from the surface; `wo` is toward where the light goes (the
 * previous vertex), n is the shading normal turned to wo's side.
 */
#ifndef CLPT_BSDF_H
#define CLPT_BSDF_H

#include "principled.h"
#include "layered.h"

typedef struct {
    vec3 wi;          /* sampled direction */
    vec3 weight;      /* f * |cos| / pdf */
    float pdf;        /* solid-angle density; 0 for delta lobes */
    int specular;     /* delta (or treated as delta: fuzzy metal) */
    int transmitted;  /* meant to leave on the far side of the surface */
} BsdfSample;

KFN vec3 reflect_dir(vec3 d, vec3 n) { return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n))); }

/* ---------------------------------------------------------------- valid shading normals
 * A shading normal (interpolated, or bent by a normal map) can face away from the
 * viewer while the surface faces it: wo is then below the shading frame's horizon, the
 * lobes evaluated in that frame return 0, and normal-mapped bumps drew black rims. As
 * Cycles does (its kernel's ensure_valid_reflection), such a normal is bent toward ng,
 * within the plane of the two, just far enough that the mirror direction of wo about
 * it leaves above the surface. (The other production answer, microfacet-based normal
 * mapping, Schuessler et al. 2017, replaces each lobe by a two-facet one; more work, and
 * every material's sampling would change.) */

/* How far above the tangent plane the mirror direction must leave, as the cosine with
 * ng, for a view at cosine cos_o: 0.01, or less at grazing views, where no mirror
 * direction need rise above the view's own elevation (Cycles' threshold). */
KFN float valid_reflection_lift(float cos_o) { return k_fmin(0.9f * cos_o, 0.01f); }

/* ns (unit, cosine with ng above 0 or not) bent as above for the incoming direction d;
 * ng is the unit geometric normal on d's side. Returned unchanged when the mirror
 * direction about it already clears the lift.
 *
 * In the frame z = ng, x = ns's part across ng, a normal at angle theta from z has
 * the mirror direction's z = 2 (n.wo)(n.z) - wo.z = rho cos(2 theta - alpha), with
 * (wo.x, wo.z) = rho (sin alpha, cos alpha): a sinusoid in 2 theta. It equals the lift
 * at 2 theta = alpha + beta, cos beta = lift / rho, and is above it between there and
 * theta = 0 (ng itself); as lift < wo.z, beta > |alpha|, so theta stays in (0, pi/2).
 * Its cosine and sine come from those of 2 theta: the larger of the two by the
 * half-angle formula, the other as sin(2 theta) / 2 over it, since 1 - cos(2 theta)
 * loses every digit for the tiny bends of grazing views (a float cos(2 theta) of 1
 * bent such normals all the way to ng). */
KFN vec3 shading_normal_valid(vec3 d, vec3 ns, vec3 ng)
{
    vec3 wo = v3_neg(d);
    float oz = v3_dot(wo, ng), nz = v3_dot(ns, ng);
    if (!(oz > 0.0f)) return ns;   /* a grazing hit: no side to keep wo on */
    float lift = valid_reflection_lift(oz);
    if (2.0f * v3_dot(ns, wo) * nz - oz >= lift) return ns;
    vec3 x = v3_sub(ns, v3_scale(ng, nz));
    float lx = v3_len(x);
    if (!(lx > 0.0f)) return ng;   /* ns = -ng: any bend is as good, ng is the least */
    x = v3_scale(x, 1.0f / lx);
    float ox = v3_dot(wo, x);
    float rho = k_sqrt(ox * ox + oz * oz);
    float cb = lift / rho, sb = k_safe_sqrt(1.0f - cb * cb);
    float c2 = (oz * cb - ox * sb) / rho;   /* cos(alpha + beta) */
    float s2 = k_fmax((ox * cb + oz * sb) / rho, 0.0f);
    float c, s;
    if (c2 >= 0.0f) {
        c = k_sqrt(0.5f * (1.0f + c2));
        s = s2 / (2.0f * c);
    } else {
        s = k_sqrt(0.5f * (1.0f - c2));
        c = s2 / (2.0f * s);
    }
    return v3_add(v3_scale(ng, c), v3_scale(x, s));
}

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
    BsdfSample s;
    vec3 r = reflect_dir(d, n);
    if (fuzz > 0.0f) r = v3_madd(r, sample_ball(u1, u2, u3), fuzz);
    s.wi = v3_norm(r);
    s.weight = albedo;
    s.pdf = 0.0f;
    s.specular = 1;
    s.transmitted = 0;
    return s;
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
 * 1, so the glass keeps all it receives, as whitted.cl's refraction does. An ns facing
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
    if (u_lobe < l.p_glossy + l.p_mirror) {
        /* about the shading normal, unless that would go below the surface */
        s.wi = reflect_dir(d, ns);
        if (v3_dot(s.wi, ng) <= 0.0f) s.wi = reflect_dir(d, ng);
        s.weight = v3_scale(l.kr, 1.0f / l.p_mirror);
        s.pdf = 0.0f;
        s.specular = 1;
        s.transmitted = 0;
        return s;
    }
    /* The refracting part, like glass, tinted by kt: the glass sample (a delta lobe) as
     * it is, with kt's weight. Returned whole rather than copied field by field into s:
     * NVIDIA's OpenCL compiler (driver 580.159) at its default optimisation kept the
     * glossy branch's pdf and flag in s on this path (tools/gpu-check.sh found it). */
    BsdfSample g = bsdf_sample_dielectric(m.ior, d, ns, ng, entering, u_fresnel);
    float p_t = 1.0f - l.p_glossy - l.p_mirror;
    g.weight = p_t > 0.0f ? v3_scale(l.kt, 1.0f / p_t) : v3s(0.0f);
    return g;
}

/* ---------------------------------------------------------------- dispatch
 * One entry for each question the integrators ask of any material: its value and
 * density for a given pair of directions (next-event estimation, MIS), and a sampled
 * direction. Arguments throughout: `d` the incoming ray direction (wo = -d), ns the
 * shading normal and ng the geometric normal, both turned to the incoming side,
 * `front` whether d arrives on the outward side (for the index ratio), albedo the
 * material's (textured) colour at the hit. The microfacet lobes work in the frame of
 * k_onb(ns); anisotropy stretches along its first tangent. */

KFN Ggx bsdf_ggx(Material m) { return ggx_make(m.roughness, m.anisotropy); }

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

KFN Dielectric bsdf_dielectric(Material m, int front)
{
    Dielectric g;
    g.g = bsdf_ggx(m);
    g.thin = (m.flags & MAT_THIN) != 0u;
    g.eta = g.thin || front ? m.ior : 1.0f / m.ior;
    return g;
}

/* The principled lobes; alphas below GGX_SMOOTH_ALPHA are raised to it, as the
 * material mixes its lobes by density and has no delta branch. */
KFN Principled bsdf_principled(Material m, vec3 albedo, int front)
{
    Principled p;
    p.base = albedo;
    p.metallic = k_clamp(m.metallic, 0.0f, 1.0f);
    p.transmission = k_clamp(m.transmission, 0.0f, 1.0f);
    p.clearcoat = k_clamp(m.clearcoat, 0.0f, 1.0f);
    p.g = bsdf_ggx(m);
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
    return p;
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

/* Whether the material has a lobe with a density (not only delta lobes), so that
 * next-event estimation can reach it. */
KFN int bsdf_has_density(Material m, vec3 albedo)
{
    if (m.type == MAT_DIFFUSE) return 1;
    if (MAT_IS(m, MAT_PHONG)) return phong_lobes(m, albedo).p_glossy > 0.0f;
    if (MAT_IS(m, MAT_CONDUCTOR) || MAT_IS(m, MAT_DIELECTRIC)) return !ggx_smooth(bsdf_ggx(m));
    if (MAT_IS(m, MAT_LAYERED)) {
        /* only a stack of smooth surfaces over a smooth conductor, no medium, is all deltas */
        Layered L = bsdf_layered(m, albedo);
        return !(coat_smooth(L) && base_smooth(L) && !layer_has_medium(L));
    }
    return MAT_IS(m, MAT_PRINCIPLED);
}

/* The shading normal the material's lobes are to see for the incoming direction d
 * (ns and ng on d's side): shading_normal_valid's, except for the Lambertian lobe,
 * which does not look at wo, and the classic Phong, which needs no frame (its mirror
 * falls back to ng itself): their images stay as they were. */
KFN vec3 bsdf_normal(Material m, vec3 d, vec3 ns, vec3 ng)
{
    if (material_has(m.type, MT_KEEPS_NORMAL)) return ns;
    return shading_normal_valid(d, ns, ng);
}

KFN vec3 bsdf_to_local(vec3 w, vec3 t, vec3 b, vec3 n) { return v3(v3_dot(w, t), v3_dot(w, b), v3_dot(w, n)); }

/* f(wo, wi) (no cosine) of the material's non-delta lobes, and in *pdf the density
 * with which bsdf_sample returns wi. Zero for delta-only materials. */
KFN vec3 bsdf_eval(Material m, vec3 albedo, vec3 d, vec3 ns, int front, vec3 wi, float *pdf)
{
    vec3 f = v3s(0.0f);
    *pdf = 0.0f;
    if (m.type == MAT_DIFFUSE) {
        float c = v3_dot(ns, wi);
        if (c <= 0.0f) return f;
        *pdf = c * K_INV_PI;
        return v3_scale(albedo, K_INV_PI);
    }
    if (MAT_IS(m, MAT_PHONG)) {
        *pdf = phong_eval(phong_lobes(m, albedo), d, ns, wi, &f);
        return f;
    }
    if (!bsdf_has_density(m, albedo)) return f;
    vec3 t, b;
    k_onb(ns, &t, &b);
    vec3 wo = bsdf_to_local(v3_neg(d), t, b, ns), wl = bsdf_to_local(wi, t, b, ns);
    /* the last branch is the rough dielectric, the one type left with a density */
    if (MAT_IS(m, MAT_CONDUCTOR)) *pdf = conductor_eval(bsdf_conductor(m, albedo), wo, wl, &f);
    else if (MAT_IS(m, MAT_PRINCIPLED)) *pdf = principled_eval(bsdf_principled(m, albedo, front), wo, wl, &f);
    else if (MAT_IS(m, MAT_LAYERED)) {
        Layered L = bsdf_layered(m, albedo);
        f = layered_f(L, wo, wl);
        *pdf = layered_pdf(L, wo, wl);
    } else if (KF_HAS(KF_MATERIAL(MAT_DIELECTRIC))) *pdf = dielectric_eval(bsdf_dielectric(m, front), wo, wl, &f);
    return f;
}

KFN float bsdf_pdf(Material m, vec3 albedo, vec3 d, vec3 ns, int front, vec3 wi)
{
    float pdf;
    bsdf_eval(m, albedo, d, ns, front, wi, &pdf);
    return pdf;
}

/* A smooth conductor: the mirror direction about ns (about ng where that would go
 * below the surface), weighted by the Fresnel colour. */
KFN BsdfSample bsdf_sample_mirror_conductor(Conductor c, vec3 d, vec3 ns, vec3 ng)
{
    BsdfSample s;
    s.wi = reflect_dir(d, ns);
    if (v3_dot(s.wi, ng) <= 0.0f) s.wi = reflect_dir(d, ng);
    s.weight = conductor_fresnel(c, -v3_dot(d, ns));
    s.pdf = 0.0f;
    s.specular = 1;
    s.transmitted = 0;
    return s;
}

/* A smooth thin sheet: reflect with the sheet's reflectance, else pass straight on. */
KFN BsdfSample bsdf_sample_thin(Dielectric g, vec3 d, vec3 ng, float u)
{
    BsdfSample s;
    float F = dielectric_facet_fresnel(g, -v3_dot(d, ng));
    s.transmitted = !(u < F);
    s.wi = s.transmitted ? d : reflect_dir(d, ng);
    s.weight = v3s(1.0f);
    s.pdf = 0.0f;
    s.specular = 1;
    return s;
}

/* A rough lobe's sample: f cos / pdf, or a failed sample (weight 0, pdf 0). */
KFN BsdfSample bsdf_sample_rough(Material m, vec3 albedo, vec3 d, vec3 ns, int front, float u_lobe, float u1,
                                 float u2)
{
    BsdfSample s;
    /* f and wl are read only where pdf > 0, which some sampler below set; zero for
     * the compiler, which cannot see that when a program has no rough material type */
    vec3 t, b, f = v3s(0.0f), wl = v3s(0.0f);
    k_onb(ns, &t, &b);
    vec3 wo = bsdf_to_local(v3_neg(d), t, b, ns);
    float pdf = 0.0f;
    if (wo.z > 0.0f) {
        if (MAT_IS(m, MAT_CONDUCTOR))
            pdf = conductor_sample(bsdf_conductor(m, albedo), wo, u1, u2, &wl, &f);
        else if (MAT_IS(m, MAT_PRINCIPLED))
            pdf = principled_sample(bsdf_principled(m, albedo, front), wo, u_lobe, u1, u2, &wl, &f);
        else if (KF_HAS(KF_MATERIAL(MAT_DIELECTRIC)))   /* the rough dielectric */
            pdf = dielectric_sample(bsdf_dielectric(m, front), wo, u_lobe, u1, u2, &wl, &f);
    }
    s.specular = 0;
    s.pdf = pdf;
    if (!(pdf > 0.0f)) {
        s.wi = ns;
        s.weight = v3s(0.0f);
        s.pdf = 0.0f;
        s.transmitted = 0;
        return s;
    }
    s.wi = v3_norm(k_to_world(wl, t, b, ns));
    s.transmitted = wl.z < 0.0f;
    s.weight = v3_scale(f, k_fabs(wl.z) / pdf);
    return s;
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
    s.transmitted = 0;
    if (!(v3_max_comp(r.weight) > 0.0f)) {
        s.wi = ns;
        s.weight = v3s(0.0f);
        s.pdf = 0.0f;
        s.specular = 0;
        return s;
    }
    s.wi = v3_norm(k_to_world(r.wi, t, b, ns));
    s.weight = r.weight;
    s.specular = r.delta;
    s.pdf = r.delta ? 0.0f : layered_pdf(L, wo, bsdf_to_local(s.wi, t, b, ns));
    return s;
}

/* A direction for any material. u_lobe picks a lobe, u1 u2 (u3) the direction. */
KFN BsdfSample bsdf_sample(Material m, vec3 albedo, vec3 d, vec3 ns, vec3 ng, int front, float u_lobe, float u1,
                           float u2, float u3)
{
    if (m.type == MAT_DIFFUSE) return bsdf_sample_diffuse(albedo, ns, u1, u2);
    if (MAT_IS(m, MAT_PHONG)) return phong_sample(phong_lobes(m, albedo), m, d, ns, ng, front, u_lobe, u1, u2, u3);
    if (MAT_IS(m, MAT_METAL)) return bsdf_sample_metal(albedo, m.fuzz, d, ns, u1, u2, u3);
    if (MAT_IS(m, MAT_LAYERED)) return bsdf_sample_layered(m, albedo, d, ns, u_lobe, u1, u2);
    if (bsdf_has_density(m, albedo)) return bsdf_sample_rough(m, albedo, d, ns, front, u_lobe, u1, u2);
    if (MAT_IS(m, MAT_CONDUCTOR)) return bsdf_sample_mirror_conductor(bsdf_conductor(m, albedo), d, ns, ng);
    if (m.flags & MAT_THIN) return bsdf_sample_thin(bsdf_dielectric(m, front), d, ng, u_lobe);
    return bsdf_sample_dielectric(m.ior, d, ns, ng, front, u_lobe);
}

#endif /* CLPT_BSDF_H */
