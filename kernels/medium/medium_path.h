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
#include "medium/equiangular.h"
#include "light/lights.h"
#include "sample/rng.h"
#include "geom/surface.h"
#include "accel/alpha.h"

/* Whether a path that reaches a surface of material m (resolved) from behind is a
 * subsurface walk leaving its solid (docs/subsurface.md). */
KFN int subsurface_exits(Material m)
{
    return MAT_IS(m, MAT_PRINCIPLED) && m.subsurface > 0.0f && !(m.flags & MAT_THIN);
}

/* The surface a subsurface walk leaves through: Lambertian, white (the colour is the
 * walk's), as Cycles' random walk leaves; the albedo inversion (host/scene/subsurface.c)
 * assumes a boundary without Fresnel reflection inside, as this one. Its emission was
 * added already. The host compiles MAT_DIFFUSE into every scene with subsurface
 * (kernel_features.c). */
KFN Material subsurface_exit_material(Material m)
{
    Material d = m;
    d.type = MAT_DIFFUSE;
    d.albedo = v3s(1.0f);
    d.texture = NO_INDEX;
    d.texture_normal = NO_INDEX;
    d.flags = 0u;
    return d;
}

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
    if (!light_sample(sc, x, p->mis_mode == MIS_BOTH, reuse, u_pick, lu, lv, &ls)) return 0;
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
 * the stop's weight: a light sample (unless the flight's segment estimate took this
 * bounce's, light_done), then a new direction from the phase function (weight 1: it is
 * sampled exactly), Russian roulette as at a surface. Returns the bounce's SHADE_*
 * result.
 *
 * A stop of a subsurface walk (`walk`: a MEDIUM_WALK medium, docs/subsurface.md) is no
 * bounce: it counts as a crossing (which gives the next step fresh random numbers),
 * samples no light (the closed surface around it would block the shadow ray) and takes
 * Russian roulette by the throughput alone, without the 0.95 cap: a walk in a white
 * medium keeps its weight 1 and is never cut, however long, until MEDIUM_MAX_WALK. */
KFN uint medium_scatter(const SceneView *sc, GLOBAL Ray *ray, vec3 x, float g, uint walk, GLOBAL PathState *ps,
                        GLOBAL Ray *shadow_ray, RngKey key, uint rb, int light_done)
{
    GLOBAL const RenderParams *p = sc->params;
    uint bounce = ps->bounce;
    if (walk ? ps->crossings >= path_max_crossings(p->has_media) : bounce >= p->max_depth) return 0u;
    vec3 d = v3_norm(ray->d);
    uint result = 0u;
    if (!walk && !light_done && p->n_lights > 0u && medium_light_sample(sc, ps, x, d, g, key, rb, shadow_ray))
        result |= SHADE_SHADOW;
    float u1, u2;
    rng_uniform2(key, rb, DIM_BSDF_U, &u1, &u2);
    float pdf;
    vec3 wi = phase_hg_sample(g, d, u1, u2, &pdf);
    vec3 thr = ps->throughput;
    if (walk) {
        ps->crossings = ps->crossings + 1u;
        float q = k_fmin(v3_max_comp(thr), 1.0f);
        if (!(rng_uniform(key, rb, DIM_ROULETTE) < q)) return result;
        thr = v3_scale(thr, 1.0f / q);
    } else if ((ps->bounce = bounce + 1u) > p->rr_depth) {
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

/* The point or spot light that this bounce's light sample picks (the same choice and
 * numbers as light_sample, so a stop's own light sample would pick it too): 1 with it
 * and its choice probability, 0 for any other kind of light. */
KFN int medium_pick_point_light(const SceneView *sc, RngKey key, uint rb, Light *l, float *choice)
{
    if (!KF_HAS(KF_DELTA_LIGHTS) || sc->params->n_lights == 0u) return 0;
    float lu, lv, u_rest;
    rng_uniform2(key, rb, DIM_LIGHT_U, &lu, &lv);
    float u = key.sampler == SAMPLER_SOBOL ? lu : rng_uniform(key, rb, DIM_LIGHT_PICK);
    Light lt = sc->lights[light_choose(sc, u * 1.0f, &u_rest)];
    if (lt.type == LIGHT_ENV || !light_is_delta(lt.type) || light_has(lt.type, LT_INFINITE)) return 0;
    *l = lt;
    *choice = lt.pick_pdf / 1.0f;
    return 1;
}

/* Next-event estimation toward point or spot light l over a whole stretch [0, dist) of a
 * homogeneous scattering medium, from x0 along unit d, for a path of throughput beta
 * that stopped somewhere in it (probability p_stop): the point is drawn by one-sample
 * MIS (balance heuristic, Veach 1997 sec. 9.2.4) between equiangular sampling toward
 * the light and free-flight sampling, each with probability 1/2 (by lv, rescaled;
 * MIS_BSDF_ONLY leaves the light sample at the stop, free-flight sampling alone), and
 * the estimate beta T(t) sigma_s p Le / (choice pdf_mix(t) p_stop) has the expectation of
 * the light's single scattering along the stretch; the path's own stop then takes no
 * light sample for this light (light_done). Returns 1 when a shadow ray was written. */
KFN int medium_segment_light(const SceneView *sc, GLOBAL PathState *ps, Medium md, vec3 x0, vec3 d, float dist,
                             vec3 pc, float p_stop, Light l, float choice, float lv, GLOBAL Ray *shadow_ray)
{
    vec3 sigma_t = medium_sigma_t(md);
    Equiangular e;
    e.delta = e.D = e.theta_a = e.theta_b = 0.0f;   /* unused unless c_eq > 0 */
    /* the share of equiangular samples: 1/2, or 1 for MIS_LIGHT_ONLY (the tests'
     * "light strategy only"); 0 where the ray passes through the light */
    float t_lo = 0.0f, t_hi = dist;
    int lit = !light_has(l.type, LT_CONE) || !(l.cos_outer > 0.0f) ||
              equiangular_cone_clip(x0, d, l.position, l.direction, l.cos_outer, dist, &t_lo, &t_hi);
    float c_eq = !lit || !equiangular_begin(x0, d, l.position, t_lo, t_hi, &e) ? 0.0f
                 : (sc->params->mis_mode == MIS_LIGHT_ONLY ? 1.0f : 0.5f);
    float t;
    if (lv < c_eq) {
        t = equiangular_sample(e, lv / c_eq);
    } else {
        float u = k_fmin((lv - c_eq) / (1.0f - c_eq), 0.99999994f), u_rest;
        int c = medium_pick_channel(pc, u, &u_rest);
        t = medium_sample_exp(v3_get(sigma_t, c), u_rest);
    }
    if (!(t >= 0.0f && t < dist)) return 0;
    vec3 tr = medium_tr(sigma_t, t);
    float p_free = medium_stop_pdf(pc, sigma_t, tr);
    /* 0 outside the cone's part (a free-flight point there); an equiangular point is
     * inside it but for rounding */
    float pdf = p_free;
    if (c_eq > 0.0f) {
        float p_eq = lv < c_eq || (t >= t_lo && t < t_hi) ? equiangular_pdf(e, t) : 0.0f;
        pdf = c_eq * p_eq + (1.0f - c_eq) * p_free;
    }
    vec3 x = v3_madd(x0, d, t);
    LightSample ls;
    if (!(pdf > 0.0f) || !light_delta_at(l, x, &ls)) return 0;
    float ph = phase_hg(md.g, d, ls.wi);
    vec3 w = v3_scale(v3_mul(tr, md.sigma_s), ph / (choice * pdf * p_stop));
    ps->shadow_L = v3_mul(v3_mul(ps->throughput, w), ls.Le);
    ps->shadow_medium = ps->medium;
    if (!sc->params->shadows) {
        /* shadows off: the light counts as visible, through the medium too */
        shadow_resolve(ps, 0);
        return 0;
    }
    *shadow_ray = light_shadow_ray(x, v3s(0.0f), ls.wi, ls);
    return 1;
}

/* The distance (scene length) at which a flight through homogeneous extinction sigma_t
 * stops, drawn for bounce rb by one-sample MIS over the channels (pc: their
 * probabilities, medium_channel_pdf): one function for medium_flight and for
 * medium_walk_tmax, which must draw the same bits. */
KFN float medium_flight_stop(vec3 sigma_t, vec3 pc, RngKey key, uint rb)
{
    float u;
    int c = medium_pick_channel(pc, rng_uniform(key, rb, DIM_MEDIUM), &u);
    return medium_sample_exp(v3_get(sigma_t, c), u);
}

/* Whether a stop in homogeneous medium md takes its point or spot light's sample over
 * the whole stretch to the surface (medium_segment_light), and that light. */
KFN int medium_takes_segment(const SceneView *sc, Medium md, GLOBAL const PathState *ps, RngKey key, uint rb,
                             Light *l, float *choice)
{
    return !(md.flags & MEDIUM_WALK) && ps->bounce < sc->params->max_depth &&
           sc->params->mis_mode != MIS_BSDF_ONLY && medium_pick_point_light(sc, key, rb, l, choice);
}

/* How far the closest-hit walk for path ps's ray must look: in a homogeneous medium
 * that scatters, medium_flight needs the surface only where it lies before the distance
 * the flight stops at, so that distance is drawn here, before the walk (into *stop,
 * *drawn = 1), and the walk stops looking just past it, skipping every node beyond.
 * Everywhere else, the ray's own tmax (*drawn = 0): outside media, in grids (tracked
 * along the stretch), in media that emit or only absorb (the whole stretch's emission
 * or transmittance), where the stop takes a point light's sample over the whole
 * stretch (medium_takes_segment), and in scenes with surfaces of revolution, whose
 * Newton search divides the ray's interval up to its tmax (revsurface.h), so that a
 * shorter interval finds their hits with other rounding.
 *
 * The same hit, so the same bits: every other primitive's hit distance does not depend
 * on tmax, and the margin of 2^-12 (relative, twice) is far above the rounding of
 * medium_flight's distance (hit.t - tmin) len, so every surface that distance puts
 * before the stop is found; one found beyond it, or none, means a stop at the same
 * distance as the whole walk's hit would (tests/test_kernels.c, test_flight_walk). */
KFN float medium_walk_tmax(const SceneView *sc, Ray ray, GLOBAL const PathState *ps, float *stop, uint *drawn)
{
    *drawn = 0u;
    if (ps->medium == 0u) return ray.tmax;
    if (KF_HAS(KF_REVSURFACE) && sc->params->n_revsurfaces != 0u) return ray.tmax;
    Medium md = sc->media[ps->medium - 1u];
    if (md.type == MEDIUM_GRID || (md.flags & MEDIUM_EMISSIVE) || v3_is_zero(md.sigma_s)) return ray.tmax;
    RngKey key = rng_key_of(ps, sc->params);
    uint rb = path_rng_bounce(ps);
    Light pl;
    float choice;
    if (medium_takes_segment(sc, md, ps, key, rb, &pl, &choice)) return ray.tmax;
    float ts = medium_flight_stop(medium_sigma_t(md), medium_channel_pdf(ps->throughput), key, rb);
    *stop = ts;
    *drawn = 1u;
    const float margin = 1.0f + 1.0f / 4096.0f;
    float t = (ray.tmin + ts / v3_len(ray.d) * margin) * margin;
    return t < ray.tmax ? t : ray.tmax;
}

/* The closest hit of path ps's ray, as far as shade_path needs it (medium_walk_tmax),
 * with the flight's stop when it was drawn for the walk. */
KFN Hit trace_flight(const SceneView *sc, Ray ray, GLOBAL const PathState *ps)
{
    if (!KF_HAS(KF_MEDIA)) return trace_closest_visible(sc, ray);
    float stop = 0.0f;
    uint drawn;
    ray.tmax = medium_walk_tmax(sc, ray, ps, &stop, &drawn);
    Hit h = trace_closest_visible(sc, ray);
    h.flight_stop = stop;
    h.flight_drawn = drawn;
    return h;
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
        if (md.flags & MEDIUM_EMISSIVE) ps->radiance = v3_add(ps->radiance, v3_mul(ps->throughput, emitted));
        ps->throughput = v3_mul(ps->throughput, tr);
        return !(v3_max_comp(ps->throughput) > 0.0f);
    }
    vec3 thr = ps->throughput;
    float ts;
    int ev = grid_track(sc, md, x, d, dist, &thr, rng_uniform(key, rb, DIM_MEDIUM), &rng, &ts, &emitted);
    /* emitted already carries the path's throughput (grid_track's weights start from it) */
    if (md.flags & MEDIUM_EMISSIVE) ps->radiance = v3_add(ps->radiance, emitted);
    if (ev == GRID_ENDED || !(v3_max_comp(thr) > 0.0f)) return 1;
    ps->throughput = thr;
    if (ev == GRID_PASSED) return 0;
    *result = medium_scatter(sc, ray, v3_madd(x, d, ts), md.g, md.flags & MEDIUM_WALK, ps, shadow_ray, key, rb, 0);
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
    if (md.flags & MEDIUM_EMISSIVE) ps->radiance = v3_add(ps->radiance, v3_mul(ps->throughput, medium_emitted(md, sigma_t, dist)));
    if (v3_is_zero(md.sigma_s)) {
        ps->throughput = v3_mul(ps->throughput, medium_tr(sigma_t, dist));
        return !(v3_max_comp(ps->throughput) > 0.0f);
    }
    RngKey key = rng_key_of(ps, sc->params);
    uint rb = path_rng_bounce(ps);
    vec3 pc = medium_channel_pdf(ps->throughput);
    float ts = hit.flight_drawn ? hit.flight_stop : medium_flight_stop(sigma_t, pc, key, rb);
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
    /* a point or spot light's sample is taken over the whole stretch, by equiangular
     * and free-flight sampling together (medium_segment_light), in place of the stop's */
    Light pl;
    float choice;
    int segment = !hit.flight_drawn && medium_takes_segment(sc, md, ps, key, rb, &pl, &choice);
    uint shadow = 0u;
    if (segment) {
        float lu, lv;
        rng_uniform2(key, rb, DIM_LIGHT_U, &lu, &lv);
        vec3 x0 = v3_madd(r.o, r.d, r.tmin), d = v3_scale(r.d, 1.0f / len);
        float p_stop = medium_stop_prob(pc, sigma_t, dist);
        if (p_stop > 0.0f && medium_segment_light(sc, ps, md, x0, d, dist, pc, p_stop, pl, choice, lv, shadow_ray))
            shadow = SHADE_SHADOW;
    }
    ps->throughput = thr;
    *result = medium_scatter(sc, ray, v3_madd(r.o, r.d, r.tmin + ts / len), md.g, md.flags & MEDIUM_WALK, ps,
                             shadow_ray, key, rb, segment) |
              shadow;
    return 1;
}

/* A hit on a boundary that is no surface (MAT_INTERFACE): the ray goes on along the
 * same line from the hit, in the medium beyond it. Its origin stays where the path last
 * scattered, which the MIS weight of a light it reaches is computed from; only tmin
 * moves up to the hit (the interval is open, so the same boundary is not found again,
 * as kernels/accel/alpha.h skips cut-out surfaces). Not a bounce. */
KFN uint medium_cross(GLOBAL Ray *ray, Hit hit, vec3 ng, uint medium_in, uint medium_out, GLOBAL PathState *ps,
                      uint max_crossings)
{
    ps->medium = medium_beyond(medium_in, medium_out, ps->medium, ray->d, ng);
    ps->crossings = ps->crossings + 1u;
    if (ps->crossings > max_crossings) return 0u;
    ray->tmin = hit.t;
    return SHADE_CONTINUE;
}

#endif /* CLPT_MEDIUM_PATH_H */
