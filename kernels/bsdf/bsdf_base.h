/*
 * bsdf_base.h — what every lobe family shares: the sample it returns, the mirror
 * direction, the valid shading normal, the local frame of the microfacet lobes, and the
 * family of types with no lobes at all.
 *
 * A lobe family (bsdf_classic.h, conductor.h, dielectric.h, principled.h, layered.h)
 * gives each of its material types, under the stem its line of MATERIAL_TYPES names
 * (types.h), three functions that kernels/bsdf/bsdf.h dispatches to:
 *   int <stem>_bsdf_has_density(Material m, vec3 albedo)
 *       whether the material has a lobe with a density (not only delta lobes), so that
 *       next-event estimation can reach it;
 *   vec3 <stem>_bsdf_eval(Material m, BsdfHit h, vec3 wi, float *pdf)
 *       f(wo, wi) (no cosine) of its non-delta lobes, and in *pdf the density with
 *       which <stem>_bsdf_sample returns wi; zero for delta-only materials;
 *   BsdfSample <stem>_bsdf_sample(Material m, BsdfHit h, float u_lobe, float u1,
 *                                 float u2, float u3)
 *       a direction: u_lobe picks a lobe, u1 u2 (u3) the direction.
 * Directions point away from the surface; `wo` is toward where the light goes (the
 * previous vertex).
 */
#ifndef CLPT_BSDF_BASE_H
#define CLPT_BSDF_BASE_H

#include "bsdf/microfacet.h"

typedef struct {
    vec3 wi;          /* sampled direction */
    vec3 weight;      /* f * |cos| / pdf */
    float pdf;        /* solid-angle density; 0 for delta lobes */
    int specular;     /* delta (or treated as delta: fuzzy metal) */
    int transmitted;  /* meant to leave on the far side of the surface */
} BsdfSample;

/* The hit as a lobe family sees it. */
typedef struct {
    vec3 d;           /* the incoming ray's direction (wo = -d) */
    vec3 ns;          /* the shading normal turned to the incoming side (bsdf_normal's) */
    vec3 ng;          /* the geometric normal, on the same side (not read by _eval) */
    vec3 albedo;      /* the material's (textured) colour at the hit */
    int front;        /* whether d arrives on the outward side (for the index ratio) */
} BsdfHit;

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

/* ---------------------------------------------------------------- the local frame
 * The microfacet lobes work in the frame of k_onb(ns); anisotropy stretches along its
 * first tangent. */
typedef struct {
    vec3 t, b, n;
} BsdfFrame;

KFN BsdfFrame bsdf_frame(vec3 ns)
{
    BsdfFrame F;
    k_onb(ns, &F.t, &F.b);
    F.n = ns;
    return F;
}

KFN vec3 bsdf_to_local(vec3 w, vec3 t, vec3 b, vec3 n) { return v3(v3_dot(w, t), v3_dot(w, b), v3_dot(w, n)); }

KFN vec3 bsdf_frame_local(BsdfFrame F, vec3 w) { return bsdf_to_local(w, F.t, F.b, F.n); }

KFN Ggx bsdf_ggx(Material m) { return ggx_make(m.roughness, m.anisotropy); }

/* Whether a GGX type (conductor, dielectric) is rough: below GGX_SMOOTH_ALPHA its lobes
 * are delta lobes, with no density. */
KFN int bsdf_ggx_rough(Material m) { return !ggx_smooth(bsdf_ggx(m)); }

/* The has_density of the families whose every material has a lobe with a density
 * (diffuse, principled). */
KFN int bsdf_density_always(Material m, vec3 albedo)
{
    (void)m;
    (void)albedo;
    return 1;
}

/* The has_density of the GGX families (conductor, dielectric): rough ones only. */
KFN int bsdf_density_if_rough(Material m, vec3 albedo)
{
    (void)albedo;
    return bsdf_ggx_rough(m);
}

/* A sample that failed: no direction, no weight. */
KFN BsdfSample bsdf_failed(vec3 ns)
{
    BsdfSample s;
    s.wi = ns;
    s.weight = v3s(0.0f);
    s.pdf = 0.0f;
    s.specular = 0;
    s.transmitted = 0;
    return s;
}

/* A delta lobe's sample: direction wi, weight (f cos over the lobe's choice), no
 * density. */
KFN BsdfSample bsdf_delta_sample(vec3 wi, vec3 weight, int transmitted)
{
    BsdfSample s;
    s.wi = wi;
    s.weight = weight;
    s.pdf = 0.0f;
    s.specular = 1;
    s.transmitted = transmitted;
    return s;
}

/* The mirror direction of d about the shading normal ns, or about the geometric
 * normal ng where the first would go below the surface. */
KFN vec3 bsdf_mirror_dir(vec3 d, vec3 ns, vec3 ng)
{
    vec3 wi = reflect_dir(d, ns);
    return v3_dot(wi, ng) <= 0.0f ? reflect_dir(d, ng) : wi;
}

/* The frame of the hit's shading normal, and in *wo the direction back along the ray
 * in it: where every lobe with a density starts. */
KFN BsdfFrame bsdf_hit_frame(BsdfHit h, vec3 *wo)
{
    BsdfFrame F = bsdf_frame(h.ns);
    *wo = bsdf_frame_local(F, v3_neg(h.d));
    return F;
}

/* A rough lobe's sample from its local direction wl, f and density pdf (0: failed): f
 * cos / pdf in world space. */
KFN BsdfSample bsdf_rough_sample(BsdfFrame F, float pdf, vec3 wl, vec3 f)
{
    if (!(pdf > 0.0f)) return bsdf_failed(F.n);
    BsdfSample s;
    s.specular = 0;
    s.pdf = pdf;
    s.wi = v3_norm(k_to_world(wl, F.t, F.b, F.n));
    s.transmitted = wl.z < 0.0f;
    s.weight = v3_scale(f, k_fabs(wl.z) / pdf);
    return s;
}

/* No lobe with a density: f 0, density 0. */
KFN vec3 bsdf_no_eval(float *pdf)
{
    *pdf = 0.0f;
    return v3s(0.0f);
}

/* ---------------------------------------------------------------- no lobes
 * A pure emitter (MAT_EMISSIVE), and a mix (MAT_MIX), which material_resolve
 * replaces by a material that scatters before anything asks. */
KFN int none_bsdf_has_density(Material m, vec3 albedo)
{
    (void)m;
    (void)albedo;
    return 0;
}

KFN vec3 none_bsdf_eval(Material m, BsdfHit h, vec3 wi, float *pdf)
{
    (void)m;
    (void)h;
    (void)wi;
    return bsdf_no_eval(pdf);
}

KFN BsdfSample none_bsdf_sample(Material m, BsdfHit h, float u_lobe, float u1, float u2, float u3)
{
    (void)m;
    (void)u_lobe;
    (void)u1;
    (void)u2;
    (void)u3;
    return bsdf_failed(h.ns);
}

#endif /* CLPT_BSDF_BASE_H */
