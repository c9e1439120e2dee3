/*
 * transmit.h — the answer to a shadow ray (kernels/integrator/path.h, entry.cl's
 * k_shadow): in a scene without media whether anything blocks it; with media the
 * transmittance along it, through the boundaries it passes (MAT_INTERFACE) and the
 * media between them, which scales the contribution waiting on it (PathState.shadow_L).
 * Homogeneous media need no estimator here: exp(-sigma_t d) per channel is exact, so
 * ratio tracking would only add noise.
 */
#ifndef CLPT_TRANSMIT_H
#define CLPT_TRANSMIT_H

#include "accel/alpha.h"
#include "integrator/shade_path.h"
#include "medium/medium.h"

/* The shadow ray r through media, from PathState.shadow_medium: walks its hits in order
 * (cut-out surfaces skipped, as trace_closest_visible does), multiplying the
 * transmittance of each stretch, until the ray's end (the light) or a surface that is
 * not only a boundary (blocked). Returns the rays traced. */
KFN uint shadow_trace_media(const SceneView *sc, GLOBAL PathState *ps, Ray r)
{
    uint med = ps->shadow_medium;
    vec3 tr = v3s(1.0f);
    float len = v3_len(r.d);
    uint n = 0u;
    uint rng = 0u;
    int rng_ready = 0;
    for (;;) {
        Hit h = trace_closest_visible(sc, r);
        n++;
        float t_end = h.prim == NO_INDEX ? r.tmax : h.t;
        if (med != 0u) {
            Medium md = sc->media[med - 1u];
            float dist = (t_end - r.tmin) * len;
            if (md.type == MEDIUM_GRID) {
                /* one stream for all the grid stretches of this shadow ray */
                if (!rng_ready) rng = grid_rng_seed(rng_key_of(ps, sc->params), path_rng_bounce(ps), GRID_TAG_SHADOW);
                rng_ready = 1;
                tr = v3_mul(tr, grid_transmittance(sc, md, v3_madd(r.o, r.d, r.tmin), v3_scale(r.d, 1.0f / len),
                                                   dist, &rng, NULL));
            } else {
                tr = v3_mul(tr, medium_tr(medium_sigma_t(md), dist));
            }
        }
        if (h.prim == NO_INDEX) break;
        /* the material the path sees there: an instance's where it replaces it */
        GLOBAL const Material *m = &sc->materials[hit_material(sc, h)];
        if (!(m->flags & MAT_INTERFACE) || n > MEDIUM_MAX_CROSSINGS) {
            tr = v3s(0.0f);
            break;
        }
        med = medium_beyond(m->medium_in, m->medium_out, med, r.d, hit_geometric_normal(sc, r, h));
        r.tmin = h.t;
    }
    ps->shadow_L = v3_mul(ps->shadow_L, tr);
    shadow_resolve(ps, v3_is_zero(tr));
    return n;
}

/* Resolves the contribution waiting on shadow ray r; returns the rays traced. */
KFN uint shadow_trace(const SceneView *sc, GLOBAL PathState *ps, Ray r)
{
    if (KF_HAS(KF_MEDIA) && sc->params->has_media) return shadow_trace_media(sc, ps, r);
    shadow_resolve(ps, trace_occluded(sc, r));
    return 1u;
}

#endif /* CLPT_TRANSMIT_H */
