/*
 * shade_path.h — what happens where a path meets a surface (or escapes): emission with its
 * multiple-importance weight, next-event estimation toward a light (the shadow ray is
 * only written here; traverse.h answers it), scattering into the next ray, and Russian
 * roulette. One call is one bounce of one path; the caller does the queueing.
 */
#ifndef CLPT_SHADE_PATH_H
#define CLPT_SHADE_PATH_H

#include "light/background.h"
#include "bsdf/bsdf.h"
#include "light/lights.h"
#include "material/mix.h"
#include "sample/rng.h"
#include "geom/surface.h"
#include "material/texture.h"

/* --clamp (RenderParams.clamp_indirect > 0): indirect light scaled down so that no
 * channel passes the limit, keeping its hue, as Cycles' "clamp indirect". Indirect is
 * what a surface after the first one reflected: the light samples from the second hit
 * on, and the emission and background that rays from the second hit on find. The first
 * hit's direct light (its light sample, and what its scattered ray finds, the two
 * strategies MIS weighs against each other) and what the camera sees stay whole.
 * Biased (it removes energy), and it removes fireflies: rare paths to a bright light
 * through diffuse bounces. Off (0), the contribution is returned as it was, bit for
 * bit. */
KFN vec3 clamp_indirect(GLOBAL const RenderParams *p, vec3 c)
{
    float limit = p->clamp_indirect, peak = v3_max_comp(c);
    if (!(limit > 0.0f) || !(peak > limit)) return c;
    return v3_scale(c, limit / peak);
}

/* Power heuristic (beta = 2) weight of a strategy with density a against one with b. */
KFN float mis_power(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* The answer to a shadow ray: the waiting contribution counts only if nothing blocks. */
KFN void shadow_resolve(GLOBAL PathState *ps, int occluded)
{
    if (!occluded) ps->radiance = v3_add(ps->radiance, ps->shadow_L);
    ps->shadow_L = v3s(0.0f);
}

/* Next-event estimation at a surface with a non-delta lobe (bsdf_has_density): samples
 * a light, and if it is on a side the BSDF scatters to (above the surface, or below it
 * for a transmitting lobe) writes the shadow ray and the contribution it would bring:
 * MIS-weighted against BSDF sampling for an area light (unless the test switch
 * mis_mode says otherwise), fully for a delta light, which BSDF sampling cannot find.
 * `d` is the incoming ray direction, n_face and ng_face the shading and geometric
 * normals on its side, `front` whether it arrives on the outward side. Returns 1 when a
 * shadow ray was written; with shadows off the contribution is added at once instead. */
KFN int shade_light_sample(const SceneView *sc, GLOBAL PathState *ps, Surface s, vec3 d, vec3 n_face,
                           vec3 ng_face, Material m, vec3 albedo, int front, GLOBAL Ray *shadow_ray)
{
    RngKey key = rng_key_of(ps, sc->params);
    /* path_rng_bounce (kernels/medium/medium_path.h), defined below */
    uint b = KF_HAS(KF_MEDIA) ? ps->bounce + ps->crossings : ps->bounce;
    uint mis_mode = sc->params->mis_mode;
    LightSample ls;
    float lu, lv;
    rng_uniform2(key, b, DIM_LIGHT_U, &lu, &lv);
    /* Sobol points choose the light by the pair's first coordinate and reuse its rest
     * (light_sample_in), so the pair stays stratified over all the lights together: on
     * the dragon of ../shared/peers, whose lamp is two triangles, 1.6 times less squared
     * error at 16 spp than with a choice number of its own. Independent values keep
     * their own dimension for the choice, and with it clpt's earlier images. */
    int reuse = key.sampler == SAMPLER_SOBOL;
    float u_pick = reuse ? 0.0f : rng_uniform(key, b, DIM_LIGHT_PICK);
    if (!light_sample(sc, s.p, mis_mode == MIS_BOTH, reuse, u_pick, lu, lv, &ls))
        return 0;
    if (!ls.delta && mis_mode == MIS_BSDF_ONLY) return 0;
    vec3 wi = ls.wi;
    float cos_s = v3_dot(n_face, wi), cos_g = v3_dot(ng_face, wi);
    /* both normals must agree on the side: a direction between them is a shading-normal
     * artefact, lit from the wrong side */
    int below = cos_s < 0.0f;
    if (cos_s == 0.0f || (below ? cos_g >= 0.0f : cos_g <= 0.0f)) return 0;
    if (below && !material_transmits(m.type)) return 0;
    float bsdf_pdf;
    vec3 f = bsdf_eval(m, albedo, d, n_face, front, wi, &bsdf_pdf);
    if (below) cos_s = -cos_s;
    float w = ls.delta || mis_mode == MIS_LIGHT_ONLY ? 1.0f : mis_power(ls.pdf, bsdf_pdf);
    vec3 f_cos = v3_scale(f, cos_s * w / ls.pdf);
    ps->shadow_L = v3_mul(v3_mul(ps->throughput, f_cos), ls.Le);
    if (b >= 1u) ps->shadow_L = clamp_indirect(sc->params, ps->shadow_L);
    if (!sc->params->shadows) {
        /* shadows off: the light counts as visible, so no shadow ray is traced */
        shadow_resolve(ps, 0);
        return 0;
    }
    *shadow_ray = light_shadow_ray(s.p, s.err, below ? v3_neg(ng_face) : ng_face, ls);
    return 1;
}

/* A path that escaped along ray r: the background's radiance. An environment map that
 * light sampling could have found too is weighted by MIS, as emission below; other
 * backgrounds are no light that next-event estimation samples, so what BSDF sampling
 * finds of them counts fully. */
KFN_INLINE void shade_escape(const SceneView *sc, Ray r, GLOBAL PathState *ps)
{
    GLOBAL const RenderParams *p = sc->params;
    float w = 1.0f;
    vec3 Le;
    if (!(ps->flags & PATH_SPECULAR) && KF_HAS(KF_ENV_MAP) && p->bg_type == BG_MAP && p->bg_light != NO_INDEX) {
        /* the map's radiance and its light-sampling density from one lookup of the
         * direction's pixel (light_pdf_env's value; the compensated distribution's,
         * which next-event estimation draws from where MIS weighs, envmap.h) */
        float env_pdf_d;
        Le = env_radiance_pdf(sc, r.d, 1, &env_pdf_d);
        float light_pdf = sc->lights[p->bg_light].pick_pdf * env_pdf_d;
        w = p->mis_mode == MIS_BOTH ? mis_power(ps->bsdf_pdf, light_pdf)
                                    : (p->mis_mode == MIS_BSDF_ONLY ? 1.0f : 0.0f);
    } else {
        Le = background_radiance(sc, r.d);
    }
    vec3 c = v3_scale(v3_mul(ps->throughput, Le), w);
    if (ps->bounce >= 2u) c = clamp_indirect(p, c);   /* the ray of a later hit than the first */
    ps->radiance = v3_add(ps->radiance, c);
}

/* The emission of surface s (material m) that ray r reached: emission found by BSDF
 * sampling is weighted against the light sampling that could have found it too; after a
 * delta bounce only BSDF sampling could. */
KFN_INLINE void shade_emission(const SceneView *sc, Ray r, Surface s, Material m, GLOBAL PathState *ps)
{
    GLOBAL const RenderParams *p = sc->params;
    vec3 emission = material_emission(sc, m, s);
    if (!v3_is_zero(emission) && ((m.flags & MAT_TWO_SIDED) || v3_dot(r.d, s.ng) < 0.0f)) {
        float w = 1.0f;
        if (!(ps->flags & PATH_SPECULAR) && s.light != NO_INDEX)
            w = p->mis_mode == MIS_BOTH ? mis_power(ps->bsdf_pdf, light_pdf(sc, s.light, r.o, s.p, s.ng))
                                        : (p->mis_mode == MIS_BSDF_ONLY ? 1.0f : 0.0f);
        vec3 c = v3_scale(v3_mul(ps->throughput, emission), w);
        if (ps->bounce >= 2u) c = clamp_indirect(p, c);   /* the ray of a later hit than the first */
        ps->radiance = v3_add(ps->radiance, c);
    }
}

/* Beer-Lambert absorption inside a solid (KHR_materials_volume): a segment that ends on
 * the back of a surface whose material absorbs ran inside that material, so the path
 * keeps exp(-sigma_a t) of its throughput per channel, t the segment's length. Exact
 * for closed, non-nested meshes; a volume inside another (or overlapping it) is
 * charged only the material of the surface the segment ends on, and a path leaving an
 * open mesh by escaping is not charged at all. A mix's own (zero) absorption is read. */
KFN void shade_absorb(Ray r, Hit hit, Surface s, Material m, GLOBAL PathState *ps)
{
    if (!material_absorbs(m.type) || (m.flags & MAT_THIN) || v3_is_zero(m.absorption) ||
        !(v3_dot(r.d, s.ng) > 0.0f))
        return;
    const float log2e = 1.44269504f;
    float t = -hit.t * v3_len(r.d) * log2e;
    vec3 a = m.absorption;
    ps->throughput = v3_mul(ps->throughput, v3(k_exp2(a.x * t), k_exp2(a.y * t), k_exp2(a.z * t)));
}

/* the medium's part of a bounce, which uses mis_power and shadow_resolve above */
#include "medium/medium_path.h"

/* One bounce. `ray` is the ray that produced `hit`; on SHADE_CONTINUE it is replaced by
 * the next ray. Returns SHADE_CONTINUE and/or SHADE_SHADOW, and SHADE_SCATTERED when
 * the surface scattered.
 *
 * First-hit splitting (RenderParams.split = B > 1): a camera sample whose first hit
 * scatters is shaded there B times, each time with a light sample and a continuation
 * of its own, weighted 1/B; the caller restarts the path (path_branch_next) and shades
 * the first hit again for each later branch, which does not add the hit's emission
 * again (the first branch did) and draws its own random numbers (rng_key_of).
 * Unbiased: the mean of B estimates of what the first hit reflects. Worth it where the
 * camera ray costs much and carries little of the error: on the peers' dragon the
 * camera rays take 30% of the time, and sharing them between continuations left the
 * error of twice the samples (bench/RESULTS.md). */
/* In a program of the megakernel alone, shade_path is inlined into path_run (entry.cl),
 * itself a call, so that PoCL compiles it once and not into each of the three copies it
 * makes of a kernel's body: the envmap scene rendered 6-7% faster on PoCL and every
 * such program built faster (bench/RESULTS.md). Everywhere else it is a call on CPUs. */
#if KF_HAS(KF_PATH_MEGAKERNEL) && !KF_HAS(KF_PATH) && !KF_HAS(KF_PATH_LANES) && defined(KERNEL_OPENCL)
#define SHADE_PATH_FN KFN_INLINE
#else
#define SHADE_PATH_FN KFN_CALL_CL
#endif
SHADE_PATH_FN uint shade_path(const SceneView *sc, GLOBAL Ray *ray, Hit hit, GLOBAL PathState *ps,
                    GLOBAL Ray *shadow_ray)
{
    GLOBAL const RenderParams *p = sc->params;
    Ray r = *ray;
    RngKey key = rng_key_of(ps, p);
    uint bounce = ps->bounce;
    uint rb = KF_HAS(KF_MEDIA) ? path_rng_bounce(ps) : bounce;   /* past the boundaries crossed */
    /* the camera ray's hit: what first-hit splitting shades once per branch (a surface
     * reached through a boundary, not scattered at, is a later hit) */
    uint crossings = KF_HAS(KF_MEDIA) ? ps->crossings : 0u;
    int first_hit = bounce == 0u && crossings == 0u;

    /* in a medium, the flight to the hit may stop short of it (kernels/medium/) */
    uint medium_result;
    if (KF_HAS(KF_MEDIA) && ps->medium != 0u && medium_flight(sc, ray, hit, ps, shadow_ray, &medium_result))
        return medium_result;

    if (hit.prim == NO_INDEX) {
        shade_escape(sc, r, ps);
        return 0u;
    }

    /* a medium's boundary is crossed knowing its material and normal alone */
    uint boundary = KF_HAS(KF_MEDIA) ? hit_material(sc, hit) : NO_INDEX;
    if (boundary != NO_INDEX && (sc->materials[boundary].flags & MAT_INTERFACE)) {
        GLOBAL const Material *bm = &sc->materials[boundary];
        uint crossed = medium_cross(ray, hit, hit_geometric_normal(sc, r, hit), bm->medium_in, bm->medium_out, ps,
                                    path_max_crossings(p->has_media));
        /* the camera ray's first hit is a medium's boundary: each branch crosses it and
         * flies on through the medium with its own numbers, weighted 1/B (the camera
         * ray decides that its first hit is a boundary, whatever the numbers) */
        if (crossed && first_hit && p->split > 1u) {
            ps->throughput = v3_scale(ps->throughput, 1.0f / (float)p->split);
            crossed |= SHADE_SCATTERED;
        }
        return crossed;
    }
    Surface s = surface_at(sc, r, hit);
    Material m = sc->materials[s.material];   /* a mix: its own emission (mix.h) */
    shade_absorb(r, hit, s, m, ps);
    int later_branch = first_hit && ps->branch != 0u;
    if (!later_branch) shade_emission(sc, r, s, m, ps);
    if (bounce >= p->max_depth) return 0u;
    if (first_hit && p->split > 1u) ps->throughput = v3_scale(ps->throughput, 1.0f / (float)p->split);

    /* normals turned toward the side the ray came from */
    int front = v3_dot(r.d, s.ng) < 0.0f;
    vec3 ng_face = front ? s.ng : v3_neg(s.ng);
    uint medium_in = m.medium_in, medium_out = m.medium_out;   /* the stored material's */
    material_resolve(sc, &m, s, r.d, ng_face);
    if (!material_scatters(m.type)) return 0u;   /* pure emitters do not reflect */
    int exiting = KF_HAS(KF_MEDIA) && (p->has_media & HAS_MEDIA_WALK) && !front && subsurface_exits(m);
    if (exiting) {
        /* a subsurface walk reaching its surface from inside leaves through it as a
         * Lambertian transmission (docs/subsurface.md): shaded as a white diffuse
         * surface seen from outside, so that its light sample and its new direction
         * are on the outside, and the medium beyond is the exterior */
        m = subsurface_exit_material(m);
        front = 1;
        ng_face = s.ng;
        r.d = v3_neg(r.d);
    }
    s.ns = material_normal(sc, m, s);
    vec3 ns_face = bsdf_normal(m, r.d, front ? s.ns : v3_neg(s.ns), ng_face);
    uint result = SHADE_SCATTERED;
    BsdfSample bs;

    vec3 albedo = exiting ? v3s(1.0f) : material_albedo(sc, m, s, ng_face);
    material_at(sc, &m, s, ng_face);

    if (p->n_lights > 0u && bsdf_has_density(m, albedo) &&
        shade_light_sample(sc, ps, s, r.d, ns_face, ng_face, m, albedo, front, shadow_ray)) {
        result |= SHADE_SHADOW;
        if (KF_HAS(KF_MEDIA))
            ps->shadow_medium = medium_beyond(medium_in, medium_out, ps->medium, shadow_ray->d, s.ng);
    }
    /* a diffuse sample uses only the 2D pair: the other dimensions are left undrawn */
    int two_d = m.type == MAT_DIFFUSE;
    float bu, bv;
    rng_uniform2(key, rb, DIM_BSDF_U, &bu, &bv);
    bs = bsdf_sample(m, albedo, r.d, ns_face, ng_face, front, two_d ? 0.0f : rng_uniform(key, rb, DIM_BSDF_LOBE),
                     bu, bv, two_d ? 0.0f : rng_uniform(key, rb, DIM_BSDF_W));

    /* a reflected direction must leave on the incoming side, a transmitted one on the
     * other; anything else is a sample below the geometric surface and carries nothing */
    float side = v3_dot(bs.wi, ng_face);
    int transmitted = bs.transmitted;
    if (side == 0.0f || (side < 0.0f) != (transmitted != 0)) return result;

    vec3 thr = v3_mul(ps->throughput, bs.weight);
    ps->bounce = bounce + 1u;
    if (ps->bounce > p->rr_depth) {
        /* Russian roulette: continue with probability q, reweighted by 1/q; decided on
         * the throughput before first-hit splitting's weight 1/split, which every path
         * this far carries, so that a continuation is cut no more often than an
         * unsplit path */
        float q = k_fmin(v3_max_comp(thr) * (float)params_split(p), 0.95f);
        if (!(rng_uniform(key, rb, DIM_ROULETTE) < q)) return result;
        thr = v3_scale(thr, 1.0f / q);
    }
    if (!(v3_max_comp(thr) > 0.0f)) return result;   /* also drops NaN */
    ps->throughput = thr;
    ps->bsdf_pdf = bs.pdf;
    ps->flags = bs.specular ? PATH_SPECULAR : 0u;
    if (KF_HAS(KF_MEDIA)) ps->medium = medium_beyond(medium_in, medium_out, ps->medium, bs.wi, s.ng);
    ray->o = spawn_origin(s, transmitted ? v3_neg(ng_face) : ng_face);
    ray->d = bs.wi;
    ray->tmin = 0.0f;
    ray->tmax = INFINITY;
    return result | SHADE_CONTINUE;
}

#endif /* CLPT_SHADE_PATH_H */
