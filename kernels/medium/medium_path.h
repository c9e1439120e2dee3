/*
 * medium_path.h — a path's bounce where it travels through a medium: the flight to the
 * next surface (or a stop inside the medium), next-event estimation from a point in
 * the medium with MIS against phase sampling, the phase function's new direction, and
 * boundaries that rays pass straight through. shade_path (kernels/integrator/shade_path.h)
 * calls these first, and only where RenderParams.has_media (KF_MEDIA); it includes this
 * file after the helpers it shares with it (mis_power, shadow_resolve).
 *
 * The estimator and its proof of unbiasedness are in docs/media.md: a free-flight
 * distance by one-sample MIS over the channels (medium.h), weight T sigma_s / pdf at a
 * stop and T / P(pass) at the surface; every medium stop is a bounce, with the
 * dimensions of a bounce (rng.h) and Russian roulette as at a surface.
 */
#ifndef CLPT_MEDIUM_PATH_H
#define CLPT_MEDIUM_PATH_H

#include "medium/medium.h"
#include "medium/grid.h"
#include "medium/phase.h"
#include "light/lights.h"
#include "sample/rng.h"
#include "geom/surface.h"

/* The bounce whose random numbers path ps draws: each boundary passed straight through
 * moves it on by one, so the flight after a boundary does not reuse the numbers that
 * decided the flight before it (which, being conditioned on having got there, are no
 * longer uniform). 0 extra in scenes without boundaries. */
KFN uint path_rng_bounce(GLOBAL const PathState *ps)
{
    return ps->bounce + ps->crossings;
}

/* Next-event estimation from point x in the medium (travel direction d, phase g): the
 * same light sample as at a surface (shade_light_sample), with the phase function in
 * place of the BSDF and its cosine; MIS against phase sampling for area lights and the
 * environment map. The transmittance to the light is the shadow ray's to find
 * (transmit.h). Returns 1 when a shadow ray was written. */
KFN int medium_light_sample(const SceneView *sc, GLOBAL PathState *ps, vec3 x, vec3 d, float g, RngKey key,
                            uint rb, GLOBAL Ray *shadow_ray)
{
    GLOBAL const RenderParams *p = sc->params;
    float lu, lv;
    rng_uniform2(key, rb, DIM_LIGHT_U, &lu, &lv);
    int reuse = key.sampler == SAMPLER_SOBOL;
    float u_pick = reuse ? 0.0f : rng_uniform(key, rb, DIM_LIGHT_PICK);
    LightSample ls;
    if (!light_sample(sc, x, reuse, u_pick, lu, lv, &ls)) return 0;
    if (!ls.delta && p->mis_mode == MIS_BSDF_ONLY) return 0;
    float ph = phase_hg(g, d, ls.wi);
    float w = ls.delta || p->mis_mode == MIS_LIGHT_ONLY ? 1.0f : mis_power(ls.pdf, ph);
    ps->shadow_L = v3_mul(v3_scale(ps->throughput, ph * w / ls.pdf), ls.Le);
    ps->shadow_medium = ps->medium;
    if (!p->shadows) {
        /* shadows off: the light counts as visible, through the medium too */
        shadow_resolve(ps, 0);
        return 0;
    }
    *shadow_ray = light_shadow_ray(x, v3s(0.0f), ls.wi, ls);
    return 1;
}

/* The path stopped at x inside its medium (phase g) and its throughput already holds
 * the stop's weight: a light sample, then a new direction from the phase function
 * (weight 1: it is sampled exactly), Russian roulette as at a surface. Returns the
 * bounce's SHADE_* result. */
KFN uint medium_scatter(const SceneView *sc, GLOBAL Ray *ray, vec3 x, float g, GLOBAL PathState *ps,
                        GLOBAL Ray *shadow_ray, RngKey key, uint rb)
{
    GLOBAL const RenderParams *p = sc->params;
    uint bounce = ps->bounce;
    if (bounce >= p->max_depth) return 0u;
    vec3 d = v3_norm(ray->d);
    uint result = 0u;
    if (p->n_lights > 0u && medium_light_sample(sc, ps, x, d, g, key, rb, shadow_ray)) result |= SHADE_SHADOW;
    float u1, u2;
    rng_uniform2(key, rb, DIM_BSDF_U, &u1, &u2);
    float pdf;
    vec3 wi = phase_hg_sample(g, d, u1, u2, &pdf);
    vec3 thr = ps->throughput;
    ps->bounce = bounce + 1u;
    if (ps->bounce > p->rr_depth) {
        float q = k_fmin(v3_max_comp(thr) * (float)params_split(p), 0.95f);
        if (!(rng_uniform(key, rb, DIM_ROULETTE) < q)) return result;
        thr = v3_scale(thr, 1.0f / q);
    }
    if (!(v3_max_comp(thr) > 0.0f)) return result;
    ps->throughput = thr;
    ps->bsdf_pdf = pdf;
    ps->flags = 0u;
    ray->o = x;
    ray->d = wi;
    ray->tmin = 0.0f;
    ray->tmax = INFINITY;
    return result | SHADE_CONTINUE;
}

/* The flight of ray *ray through the path's medium up to `hit` (without end when it
 * escaped). A distance is drawn (medium.h): past the surface, the throughput takes
 * T / P(pass) and 0 is returned (the caller shades the surface, or the escape);
 * before it, the path stops there (weight T sigma_s / pdf) and scatters, and 1 is
 * returned with the bounce's result in *result (0 when the path ended there). A
 * medium that only absorbs needs no distance: the throughput takes T, exactly. */
/* medium_flight through a grid medium (grid.h): delta tracking to a stop or past the
 * surface, or, for a medium that only absorbs, ratio tracking's transmittance (an
 * unbiased estimate, where the homogeneous media have the exact value). */
KFN int medium_flight_grid(const SceneView *sc, GLOBAL Ray *ray, Hit hit, GLOBAL PathState *ps,
                           GLOBAL Ray *shadow_ray, uint *result, Medium md)
{
    Ray r = *ray;
    float len = v3_len(r.d);
    float dist = hit.prim == NO_INDEX ? INFINITY : (hit.t - r.tmin) * len;
    vec3 d = v3_scale(r.d, 1.0f / len);
    vec3 x = v3_madd(r.o, r.d, r.tmin);
    RngKey key = rng_key_of(ps, sc->params);
    uint rb = path_rng_bounce(ps);
    uint rng = grid_rng_seed(key, rb, GRID_TAG_FLIGHT);
    *result = 0u;
    vec3 emitted = v3s(0.0f);
    if (v3_is_zero(md.sigma_s)) {
        vec3 tr = grid_transmittance(sc, md, x, d, dist, &rng, &emitted);
        if (md.emissive) ps->radiance = v3_add(ps->radiance, v3_mul(ps->throughput, emitted));
        ps->throughput = v3_mul(ps->throughput, tr);
        return !(v3_max_comp(ps->throughput) > 0.0f);
    }
    vec3 thr = ps->throughput;
    float ts;
    int ev = grid_track(sc, md, x, d, dist, &thr, rng_uniform(key, rb, DIM_MEDIUM), &rng, &ts, &emitted);
    /* emitted already carries the path's throughput (grid_track's weights start from it) */
    if (md.emissive) ps->radiance = v3_add(ps->radiance, emitted);
    if (ev == GRID_ENDED || !(v3_max_comp(thr) > 0.0f)) return 1;
    ps->throughput = thr;
    if (ev == GRID_PASSED) return 0;
    *result = medium_scatter(sc, ray, v3_madd(x, d, ts), md.g, ps, shadow_ray, key, rb);
    return 1;
}

KFN int medium_flight(const SceneView *sc, GLOBAL Ray *ray, Hit hit, GLOBAL PathState *ps, GLOBAL Ray *shadow_ray,
                      uint *result)
{
    Ray r = *ray;
    Medium md = sc->media[ps->medium - 1u];
    if (md.type == MEDIUM_GRID) return medium_flight_grid(sc, ray, hit, ps, shadow_ray, result, md);
    vec3 sigma_t = medium_sigma_t(md);
    float len = v3_len(r.d);
    float dist = hit.prim == NO_INDEX ? INFINITY : (hit.t - r.tmin) * len;
    *result = 0u;
    /* the emission along the whole stretch, exactly, before the flight decides where
     * the path goes on (docs/media.md, "Emission") */
    if (md.emissive) ps->radiance = v3_add(ps->radiance, v3_mul(ps->throughput, medium_emitted(md, sigma_t, dist)));
    if (v3_is_zero(md.sigma_s)) {
        ps->throughput = v3_mul(ps->throughput, medium_tr(sigma_t, dist));
        return !(v3_max_comp(ps->throughput) > 0.0f);
    }
    RngKey key = rng_key_of(ps, sc->params);
    uint rb = path_rng_bounce(ps);
    vec3 pc = medium_channel_pdf(ps->throughput);
    float u;
    int c = medium_pick_channel(pc, rng_uniform(key, rb, DIM_MEDIUM), &u);
    float ts = medium_sample_exp(v3_get(sigma_t, c), u);
    if (!(ts < dist)) {
        vec3 tr = medium_tr(sigma_t, dist);
        float pass = medium_pass_prob(pc, tr);
        if (!(pass > 0.0f)) return 1;   /* only where the transmittance underflows */
        ps->throughput = v3_scale(v3_mul(ps->throughput, tr), 1.0f / pass);
        return 0;
    }
    vec3 tr = medium_tr(sigma_t, ts);
    float pdf = medium_stop_pdf(pc, sigma_t, tr);
    vec3 thr = v3_scale(v3_mul(v3_mul(ps->throughput, tr), md.sigma_s), 1.0f / pdf);
    if (!(pdf > 0.0f) || !(v3_max_comp(thr) > 0.0f)) return 1;
    ps->throughput = thr;
    *result = medium_scatter(sc, ray, v3_madd(r.o, r.d, r.tmin + ts / len), md.g, ps, shadow_ray, key, rb);
    return 1;
}

/* A hit on a boundary that is no surface (MAT_INTERFACE): the ray goes on along the
 * same line from the hit, in the medium beyond it. Its origin stays where the path last
 * scattered, which the MIS weight of a light it reaches is computed from; only tmin
 * moves up to the hit (the interval is open, so the same boundary is not found again,
 * as kernels/accel/alpha.h skips cut-out surfaces). Not a bounce. */
KFN uint medium_cross(GLOBAL Ray *ray, Hit hit, Surface s, Material m, GLOBAL PathState *ps)
{
    ps->medium = medium_beyond(m.medium_in, m.medium_out, ps->medium, ray->d, s.ng);
    ps->crossings = ps->crossings + 1u;
    if (ps->crossings > MEDIUM_MAX_CROSSINGS) return 0u;
    ray->tmin = hit.t;
    return SHADE_CONTINUE;
}

#endif /* CLPT_MEDIUM_PATH_H */
