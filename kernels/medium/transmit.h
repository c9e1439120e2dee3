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

/* What a shadow ray carries through the media it crosses: the transmittance so far and
 * the grid media's stream of random numbers. */
typedef struct {
    vec3 tr;
    float len;        /* |r.d|: the rays' t is along the unnormalised direction */
    uint rng;
    int rng_ready;
} ShadowStretches;

/* Multiplies the transmittance by that of the stretch (tmin, t_end) of r in medium med
 * (0: none). */
KFN void shadow_stretch(const SceneView *sc, GLOBAL PathState *ps, Ray r, uint med, float tmin, float t_end,
                        ShadowStretches *st)
{
    if (med == 0u) return;
    Medium md = sc->media[med - 1u];
    float dist = (t_end - tmin) * st->len;
    if (md.type == MEDIUM_GRID) {
        /* one stream for all the grid stretches of this shadow ray */
        if (!st->rng_ready) st->rng = grid_rng_seed(rng_key_of(ps, sc->params), path_rng_bounce(ps), GRID_TAG_SHADOW);
        st->rng_ready = 1;
        st->tr = v3_mul(st->tr, grid_transmittance(sc, md, v3_madd(r.o, r.d, tmin), v3_scale(r.d, 1.0f / st->len),
                                                   dist, &st->rng, NULL));
    } else {
        st->tr = v3_mul(st->tr, medium_tr(medium_sigma_t(md), dist));
    }
}

/* The medium beyond boundary hit h of r (whose tmin is where the stretch before it
 * began), of material m, coming from med. */
KFN uint shadow_beyond(const SceneView *sc, Ray r, Hit h, GLOBAL const Material *m, uint med)
{
    return medium_beyond(m->medium_in, m->medium_out, med, r.d, hit_geometric_normal(sc, r, h));
}

/* The shadow ray r through media, hit by hit: walks its hits in order (cut-out surfaces
 * skipped, as trace_closest_visible does), multiplying the transmittance of each
 * stretch, until the ray's end (the light) or a surface that is not only a boundary
 * (blocked). Returns the rays traced. */
KFN uint shadow_steps(const SceneView *sc, GLOBAL PathState *ps, Ray r, ShadowStretches *st)
{
    uint med = ps->shadow_medium;
    uint n = 0u;
    for (;;) {
        Hit h = trace_closest_visible(sc, r);
        n++;
        shadow_stretch(sc, ps, r, med, r.tmin, h.prim == NO_INDEX ? r.tmax : h.t, st);
        if (h.prim == NO_INDEX) break;
        /* the material the path sees there: an instance's where it replaces it */
        GLOBAL const Material *m = &sc->materials[hit_material(sc, h)];
        if (!(m->flags & MAT_INTERFACE) || n > MEDIUM_MAX_CROSSINGS) {
            st->tr = v3s(0.0f);
            break;
        }
        med = shadow_beyond(sc, r, h, m, med);
        r.tmin = h.t;
    }
    return n;
}

#if KF_HAS(KF_MEDIA)
/* The same from one walk that found the boundaries and what blocks the ray
 * (trace_through): the same stretches, so the same bits. Returns 0, having changed
 * nothing, where that walk cannot say what the hit-by-hit one would: more boundaries
 * than it keeps, or one at the very t of the surface that blocks (which of the two the
 * walk from hit to hit meets first is decided by their ids, and past a boundary it
 * would not see the surface at the same t). */
KFN int shadow_through(const SceneView *sc, GLOBAL PathState *ps, Ray r, const ThroughWalk *tw,
                       ShadowStretches *st)
{
    if (tw->overflow) return 0;
    int blocked = tw->hit.prim != NO_INDEX;
    float t_end = tw->hit.t;
    uint n = 0u;
    for (; n < tw->n && tw->crossing[n].t < t_end; n++) {}
    if (blocked && n < tw->n && tw->crossing[n].t == t_end) return 0;
    if (blocked) {
        st->tr = v3s(0.0f);
        return 1;
    }
    uint med = ps->shadow_medium;
    float tmin = r.tmin;
    for (uint i = 0u; i < n; i++) {
        Hit c = tw->crossing[i];
        if (!(c.t > tmin)) continue;   /* a second primitive at the same t: the walk from there passes it */
        shadow_stretch(sc, ps, r, med, tmin, c.t, st);
        r.tmin = tmin;
        med = shadow_beyond(sc, r, c, &sc->materials[hit_material(sc, c)], med);
        tmin = c.t;
    }
    shadow_stretch(sc, ps, r, med, tmin, r.tmax, st);
    return 1;
}

/* Whether trace_through can walk this scene's shadow rays: not where a surface may be
 * cut out or is one of revolution (ThroughWalk). */
KFN int shadow_walks_through(const SceneView *sc)
{
    if (KF_HAS(KF_ALPHA) && sc->params->has_alpha) return 0;
    if (KF_HAS(KF_REVSURFACE) && sc->params->n_revsurfaces != 0u) return 0;
    return 1;
}
#endif

/* The shadow ray r through media, from PathState.shadow_medium: the transmittance
 * through the boundaries it passes (MAT_INTERFACE) and the media between them, zero
 * where a surface that is more than a boundary blocks it. One walk finds them all
 * (trace_through) where the scene allows it; otherwise, or where that walk cannot
 * answer, the hits are walked one by one. Returns the rays traced. */
KFN uint shadow_trace_media(const SceneView *sc, GLOBAL PathState *ps, Ray r)
{
    ShadowStretches st;
    st.tr = v3s(1.0f);
    st.len = v3_len(r.d);
    st.rng = 0u;
    st.rng_ready = 0;
    uint n = 0u;
    int answered = 0;
#if KF_HAS(KF_MEDIA)
    if (shadow_walks_through(sc)) {
        ThroughWalk tw;
        trace_through(sc, r, &tw);
        n = 1u;
        answered = shadow_through(sc, ps, r, &tw, &st);
    }
#endif
    if (!answered) n += shadow_steps(sc, ps, r, &st);
    ps->shadow_L = v3_mul(ps->shadow_L, st.tr);
    shadow_resolve(ps, v3_is_zero(st.tr));
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
