/*
 * shade.cl — what happens where a path meets a surface (or escapes): emission with its
 * multiple-importance weight, next-event estimation toward a light (the shadow ray is
 * only written here; traverse.cl answers it), scattering into the next ray, and Russian
 * roulette. One call is one bounce of one path; the caller does the queueing.
 */
#ifndef CLPT_SHADE_CL
#define CLPT_SHADE_CL

#include "bsdf.h"
#include "lights.h"
#include "rng.h"
#include "surface.h"

/* Power heuristic (beta = 2) weight of a strategy with density a against one with b. */
KFN float mis_power(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

KFN vec3 background_radiance(GLOBAL const RenderParams *p, vec3 d)
{
    if (p->bg_type == BG_SKY) {
        float t = 0.5f * (d.y + 1.0f);
        return v3_add(v3_scale(p->bg_color, 1.0f - t), v3_scale(p->bg_zenith, t));
    }
    return p->bg_color;
}

/* Next-event estimation at a diffuse surface: samples a light, and if it is above the
 * surface writes the shadow ray and the contribution it would bring (MIS-weighted
 * against cosine sampling). Returns 1 when a shadow ray was written. */
KFN int shade_light_sample(const SceneView *sc, GLOBAL PathState *ps, Surface s, vec3 n_face,
                           vec3 ng_face, vec3 albedo, GLOBAL Ray *shadow_ray)
{
    uint key = ps->rng_key, b = ps->bounce;
    LightSample ls;
    if (!light_sample(sc, s.p, rng_uniform(key, b, DIM_LIGHT_PICK), rng_uniform(key, b, DIM_LIGHT_U),
                      rng_uniform(key, b, DIM_LIGHT_V), &ls))
        return 0;
    vec3 to = v3_sub(ls.p, s.p);
    float dist = v3_len(to);
    if (!(dist > 0.0f)) return 0;
    vec3 wi = v3_scale(to, 1.0f / dist);
    float cos_s = v3_dot(n_face, wi);
    if (cos_s <= 0.0f || v3_dot(ng_face, wi) <= 0.0f) return 0;
    float bsdf_pdf = cos_s * K_INV_PI;
    float w = mis_power(ls.pdf, bsdf_pdf);
    vec3 f_cos = v3_scale(albedo, K_INV_PI * cos_s * w / ls.pdf);
    ps->shadow_L = v3_mul(v3_mul(ps->throughput, f_cos), ls.Le);
    /* from just above the surface to just before the light: the light itself must not
     * count as an occluder */
    vec3 o = offset_ray_origin(s.p, ng_face);
    vec3 target = offset_ray_origin(ls.p, v3_dot(ls.n, wi) > 0.0f ? v3_neg(ls.n) : ls.n);
    shadow_ray->o = o;
    shadow_ray->d = v3_sub(target, o);
    shadow_ray->tmin = 0.0f;
    shadow_ray->tmax = 0.9999f;
    return 1;
}

/* One bounce. `ray` is the ray that produced `hit`; on SHADE_CONTINUE it is replaced by
 * the next ray. Returns SHADE_CONTINUE and/or SHADE_SHADOW. */
KFN uint shade_path(const SceneView *sc, GLOBAL Ray *ray, Hit hit, GLOBAL PathState *ps,
                    GLOBAL Ray *shadow_ray)
{
    GLOBAL const RenderParams *p = sc->params;
    Ray r = *ray;
    uint key = ps->rng_key, bounce = ps->bounce;

    if (hit.prim == NO_INDEX) {
        ps->radiance = v3_add(ps->radiance, v3_mul(ps->throughput, background_radiance(p, r.d)));
        return 0u;
    }

    Surface s = surface_at(sc, r, hit);
    Material m = sc->materials[s.material];

    if (!v3_is_zero(m.emission) && ((m.flags & MAT_TWO_SIDED) || v3_dot(r.d, s.ng) < 0.0f)) {
        /* emission reached by BSDF sampling is weighted against the light sampling that
         * could have found it too; after a delta bounce only BSDF sampling could */
        float w = 1.0f;
        if (!(ps->flags & PATH_SPECULAR) && s.light != NO_INDEX)
            w = mis_power(ps->bsdf_pdf, light_pdf(sc, s.light, r.o, s.p, s.ng));
        ps->radiance = v3_add(ps->radiance, v3_scale(v3_mul(ps->throughput, m.emission), w));
    }
    if (m.type == MAT_EMISSIVE || bounce >= p->max_depth) return 0u;   /* pure emitters do not reflect */

    /* normals turned toward the side the ray came from */
    int front = v3_dot(r.d, s.ng) < 0.0f;
    vec3 ng_face = front ? s.ng : v3_neg(s.ng);
    vec3 ns_face = front ? s.ns : v3_neg(s.ns);
    uint result = 0u;
    BsdfSample bs;

    if (m.type == MAT_DIFFUSE) {
        if (p->n_lights > 0u && shade_light_sample(sc, ps, s, ns_face, ng_face, m.albedo, shadow_ray))
            result |= SHADE_SHADOW;
        bs = bsdf_sample_diffuse(m.albedo, ns_face, rng_uniform(key, bounce, DIM_BSDF_U),
                                 rng_uniform(key, bounce, DIM_BSDF_V));
    } else if (m.type == MAT_METAL) {
        bs = bsdf_sample_metal(m.albedo, m.fuzz, r.d, ns_face, rng_uniform(key, bounce, DIM_BSDF_U),
                               rng_uniform(key, bounce, DIM_BSDF_V), rng_uniform(key, bounce, DIM_BSDF_W));
    } else {
        bs = bsdf_sample_dielectric(m.ior, r.d, ng_face, front, rng_uniform(key, bounce, DIM_BSDF_LOBE));
    }

    /* a reflected direction must leave on the incoming side, a refracted one on the
     * other; anything else is a sample below the geometric surface and carries nothing */
    float side = v3_dot(bs.wi, ng_face);
    int transmitted = m.type == MAT_DIELECTRIC && side < 0.0f;
    if (side == 0.0f || (side < 0.0f && !transmitted)) return result;

    vec3 thr = v3_mul(ps->throughput, bs.weight);
    ps->bounce = bounce + 1u;
    if (ps->bounce > p->rr_depth) {
        /* Russian roulette: continue with probability q, reweighted by 1/q */
        float q = k_fmin(v3_max_comp(thr), 0.95f);
        if (!(rng_uniform(key, bounce, DIM_ROULETTE) < q)) return result;
        thr = v3_scale(thr, 1.0f / q);
    }
    if (!(v3_max_comp(thr) > 0.0f)) return result;   /* also drops NaN */
    ps->throughput = thr;
    ps->bsdf_pdf = bs.pdf;
    ps->flags = bs.specular ? PATH_SPECULAR : 0u;
    ray->o = offset_ray_origin(s.p, transmitted ? v3_neg(ng_face) : ng_face);
    ray->d = bs.wi;
    ray->tmin = 0.0f;
    ray->tmax = INFINITY;
    return result | SHADE_CONTINUE;
}

/* The answer to a shadow ray: the waiting contribution counts only if nothing blocks. */
KFN void shadow_resolve(GLOBAL PathState *ps, int occluded)
{
    if (!occluded) ps->radiance = v3_add(ps->radiance, ps->shadow_L);
    ps->shadow_L = v3s(0.0f);
}

#endif /* CLPT_SHADE_CL */
