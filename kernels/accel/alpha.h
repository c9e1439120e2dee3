/*
 * alpha.h — see-through surfaces: glTF's alphaMode MASK and BLEND (principled's
 * alpha_mode), honoured for every ray the path tracer and the classic integrator trace.
 *
 * A hit on a surface whose material is cut out there is skipped, as if the surface were
 * not there: the ray's origin and direction are kept and its tmin is raised to the
 * skipped hit's t, so the next query finds the next surface along the same line (the
 * same primitive is not found again at the same t: the interval is open). Camera and
 * bounce rays (trace_closest_visible) and shadow rays (trace_occluded) skip the same
 * surfaces, so a mask's holes let light through exactly where they show the background.
 *
 * MASK: cut out where alpha < alpha_cutoff (glTF: "rendered fully opaque if alpha >=
 * cutoff, fully transparent otherwise"). BLEND: stochastic opacity, a hit is kept with
 * probability alpha and skipped otherwise, which averages to glTF's "over" blend without
 * sorting. The coin is a hash of the ray (origin, direction), the hit's t and primitive:
 * the rays are the same bits on every device (they come from the counter-based sampler),
 * so the decision is too, and images stay bit-identical across devices; different rays
 * (other samples, bounces, the shadow ray) get independent coins.
 *
 * alpha is the material's `alpha` times its base-colour texture's alpha channel (and
 * the vertex colour's alpha).
 * At most ALPHA_MAX_LAYERS cut-out surfaces are skipped along one ray; the next one
 * then counts as opaque (a bound on the work of a ray through dense foliage).
 */
#ifndef CLPT_ALPHA_H
#define CLPT_ALPHA_H

#include "light/lights.h"
#include "sample/rng.h"
#include "geom/surface.h"
#include "material/texture.h"
#include "accel/traverse.h"

#define ALPHA_MAX_LAYERS 64u

/* Whether the material of the hit's primitive (its instance's, where that replaces
 * it) may be cut out anywhere. A scene without such materials answers from its
 * parameters: the scalar device runs its scenes on a few builds, KF_ALPHA in them all,
 * and the material lookup for every hit cost it 1-3% on an environment-lit scene and a
 * textured glTF (bench/RESULTS.md). */
KFN_INLINE int hit_has_alpha(const SceneView *sc, Hit hit)
{
    if (!KF_HAS(KF_ALPHA) || !sc->params->has_alpha) return 0;
    return (sc->materials[hit_material(sc, hit)].flags & MAT_ALPHA_ANY) != 0u;
}

/* The BLEND coin of a hit: uniform in [0, 1), a hash of the ray's and the hit's bits. */
KFN float alpha_uniform(Ray ray, Hit hit)
{
    uint h = rng_hash(k_as_uint(ray.o.x) ^ 0x3c6ef372u);
    h = rng_hash(h ^ k_as_uint(ray.o.y));
    h = rng_hash(h ^ k_as_uint(ray.o.z));
    h = rng_hash(h ^ k_as_uint(ray.d.x));
    h = rng_hash(h ^ k_as_uint(ray.d.y));
    h = rng_hash(h ^ k_as_uint(ray.d.z));
    h = rng_hash(h ^ k_as_uint(hit.t));
    h = rng_hash(h ^ hit.prim);
    /* instances of one prototype get coins of their own (the world's hits keep theirs) */
    if (hit.inst != NO_INDEX) h = rng_hash(h ^ hit.inst);
    return (float)(h >> 8) * 5.9604645e-8f;
}

/* The opacity of material m at s: alpha times its base-colour texture's alpha, times
 * the vertex colour's alpha where the surface has one (glTF's COLOR_0). */
KFN float material_alpha(const SceneView *sc, Material m, Surface s)
{
    float a = m.texture == NO_INDEX ? m.alpha : m.alpha * texture_alpha(sc, m.texture, s);
    float c[4];
    return surface_color(sc, s, c) ? a * c[3] : a;
}

/* 1 when `hit` (of `ray`) lies where its surface is cut out; 0 for no hit. */
KFN int hit_cut_out(const SceneView *sc, Ray ray, Hit hit)
{
    if (hit.prim == NO_INDEX || !hit_has_alpha(sc, hit)) return 0;
    Surface s = surface_at(sc, ray, hit);
    Material m = sc->materials[s.material];
    float a = material_alpha(sc, m, s);
    if (m.flags & MAT_ALPHA_MASK) return !(a >= m.alpha_cutoff);
    return !(alpha_uniform(ray, hit) < a);
}

/* The nearest hit in (ray.tmin, ray.tmax) that is not cut out (trace_closest with
 * alpha); prim = NO_INDEX when there is none. */
KFN Hit trace_closest_visible(const SceneView *sc, Ray ray)
{
    if (!KF_HAS(KF_ALPHA) || !sc->params->has_alpha) return trace_closest(sc, ray);
    for (uint layer = 0u;; layer++) {
        Hit h = trace_closest(sc, ray);
        if (layer == ALPHA_MAX_LAYERS || !hit_cut_out(sc, ray, h)) return h;
        ray.tmin = h.t;
    }
}

/* 1 if a surface that is not cut out lies in (ray.tmin, ray.tmax): shadow rays. The
 * any-hit walk decides alone when what it finds is opaque everywhere (the usual case,
 * and every scene without alpha); when it finds a see-through material, the hits are
 * walked in order as trace_closest_visible does, since an any-hit query does not say
 * what lies before the surface it found. */
KFN int trace_occluded(const SceneView *sc, Ray ray)
{
    Hit h = trace_any_hit(sc, ray);
    if (h.prim == NO_INDEX) return 0;
    if (!hit_has_alpha(sc, h)) return 1;
    return trace_closest_visible(sc, ray).prim != NO_INDEX;
}

#endif /* CLPT_ALPHA_H */
