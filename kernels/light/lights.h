/*
 * lights.h — next-event estimation: choosing a light, sampling it as seen from a
 * shading point, and the density of that choice (for multiple importance sampling
 * against BSDF sampling).
 *
 * Area lights (emissive primitives): a point on the light; densities are per unit solid
 * angle at the shading point and include the probability of choosing the light. The two
 * triangles of a quad lamp (LIGHT_QUAD_*, types.h) are sampled as one parallelogram when
 * the light pair chooses the light (the Sobol sampler). A light
 * emits from its front side (outward for spheres and boxes, the winding normal's side
 * for triangles) unless its material is MAT_TWO_SIDED; a sample of a point whose lit
 * side faces away is rejected.
 * Delta lights (point, spot, directional): the one direction toward the light; `Le` is
 * then the irradiance across that direction (intensity over the attenuation, times the
 * spot's falloff) and `pdf` the probability of choosing the light alone.
 * The environment map (LIGHT_ENV, at most one, last in the list): a direction from its
 * luminance distribution (envmap.h), infinitely far; the density is per solid angle and
 * includes the choice, as for area lights.
 */
#ifndef CLPT_LIGHTS_H
#define CLPT_LIGHTS_H

#include "light/envmap.h"
#include "sample/sampling.h"
#include "scene_view.h"
#include "geom/surface.h"

typedef struct {
    vec3 p;        /* point on the light (directional: unused) */
    vec3 n;        /* its unit normal (area lights) */
    vec3 Le;       /* emitted radiance (area), irradiance across wi (delta lights) */
    vec3 wi;       /* unit direction from the reference point toward the light */
    float dist;    /* distance to p (directional: infinity) */
    float pdf;     /* solid-angle density at the reference point (area), or the
                    * probability of the choice (delta), choice included */
    int delta;     /* a point, spot or directional light */
} LightSample;

/* Whether primitive `prim` (a light) emits toward direction `toward` from a point with
 * outward/winding normal n. */
KFN int light_faces(const SceneView *sc, uint prim, vec3 n, vec3 toward)
{
    Material m = sc->materials[prim_material(sc, prim)];
    return (m.flags & MAT_TWO_SIDED) || v3_dot(n, toward) > 0.0f;
}

/* Chooses a light with probability pick_pdf (binary search of the cdf) and rescales u
 * to a fresh uniform number in [0,1) for the caller's further use. u must be below the
 * cdf of the last light it may choose. */
KFN uint light_choose(const SceneView *sc, float u, float *u_rest)
{
    uint lo = 0u, hi = sc->params->n_lights - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) >> 1;
        if (u < sc->lights[mid].cdf) hi = mid; else lo = mid + 1u;
    }
    Light l = sc->lights[lo];
    float below = l.cdf - l.pick_pdf;
    *u_rest = k_clamp((u - below) / l.pick_pdf, 0.0f, 0.99999994f);
    return lo;
}

/* 1 - cos(theta_max) of the cone a sphere of radius r subtends at distance^2 d2, written
 * as sin^2 / (1 + cos) so that small, far spheres do not cancel to zero. */
KFN float sphere_cone_one_minus_cos(float r, float d2)
{
    float sin2 = r * r / d2;
    float cos_max = k_safe_sqrt(1.0f - sin2);
    return sin2 / (1.0f + cos_max);
}

/* Whether ref is far enough outside sphere sp to sample the cone it subtends. From a
 * point on the sphere itself the cone degenerates (its near intersection is the point),
 * so such points, and points inside, sample the whole surface by area instead. */
KFN int sphere_cone_sampling(Sphere sp, float dc2)
{
    return dc2 > sp.radius * sp.radius * 1.0001f;
}

/* The solid-angle density of a point sampled uniformly by area on a light of area
 * `area` with normal n, seen along `to` (length^2 dist2, 1 / length inv_dist). One
 * function for light_sample_area and light_pdf_area, so that MIS weighs a light
 * sample with the very density it was drawn with. */
KFN float light_pdf_by_area(float area, vec3 n, vec3 to, float dist2, float inv_dist)
{
    float cos_l = k_fabs(v3_dot(n, to)) * inv_dist;
    if (cos_l <= 0.0f || area <= 0.0f) return 0.0f;
    return dist2 / (cos_l * area);
}

/* Moving light l (types.h, LIGHT_MOVING) as its instance places it at the path's time
 * (SceneView.time): the LIGHT_INSTANCED record of that moment. Its instance's M and
 * M^-1 come from instance_moving_at, the function a ray entering the instance and
 * surface_at use, so a light sample lies on the surface a ray then hits and its density
 * is the one MIS reads for that hit (light_pdf). The map is affine, so a point drawn
 * uniformly on the object's triangle (or parallelogram) and mapped is uniform on the
 * world's, of density 1 / (its area then): 0.5 |M e1 x M e2|. A sphere (its instance a
 * similarity at every key, host/scene/scene_lights.c) has centre M c and radius
 * |M x| r, x the first axis. The normal is M^-T n, as surface_moving_to_world turns
 * a hit's. */
KFN Light light_moving_at(const SceneView *sc, Light l)
{
    float m[12], mi[12];
    instance_moving_at(sc, light_instance(l), m, mi);
    l.type = LIGHT_INSTANCED;
    l.position = motion_point(m, l.position);
    if (l.prim < sc->params->n_spheres) {
        /* the radius, and the area a point on or inside the sphere samples by */
        float s = k_sqrt(m[0] * m[0] + m[4] * m[4] + m[8] * m[8]);
        l.atten0 *= s;
        l.area *= s * s;
        return l;
    }
    l.direction = motion_vector(m, l.direction);
    l.intensity = motion_vector(m, l.intensity);
    vec3 c = v3_cross(l.direction, l.intensity);
    l.area = 0.5f * k_sqrt(v3_dot(c, c));
    l.normal = instance_normal_moving(mi, l.normal);
    return l;
}

/* Light li as the path sees it: its record, or a moving light placed at the path's
 * time (light_moving_at). */
KFN Light light_seen(const SceneView *sc, uint li)
{
    Light l = sc->lights[li];
    if (KF_HAS(KF_MOTION) && l.type == LIGHT_MOVING) return light_moving_at(sc, l);
    return l;
}

/* The sphere that sphere light l is: its primitive, or the world sphere an instanced
 * light's record holds (types.h, LIGHT_INSTANCED: centre in position, radius in atten0). */
KFN Sphere light_sphere(const SceneView *sc, Light l)
{
    Sphere sp = sc->spheres[l.prim];
    if (KF_HAS(KF_INSTANCES) && l.type == LIGHT_INSTANCED) {
        sp.center = l.position;
        sp.radius = l.atten0;
    }
    return sp;
}

/* Solid-angle density at ref of area light l (as the path sees it, light_seen)
 * producing point x (normal n), the choice of the light excluded. */
KFN float light_pdf_area_of(const SceneView *sc, Light l, vec3 ref, vec3 x, vec3 n)
{
    vec3 to = v3_sub(x, ref);
    float dist2 = v3_dot(to, to);
    if (KF_HAS(KF_SPHERES) && l.prim < sc->params->n_spheres) {
        Sphere sp = light_sphere(sc, l);
        vec3 wc = v3_sub(sp.center, ref);
        float dc2 = v3_dot(wc, wc);
        if (sphere_cone_sampling(sp, dc2))
            return 1.0f / (K_TWO_PI * sphere_cone_one_minus_cos(sp.radius, dc2));
    }
    return light_pdf_by_area(l.area, n, to, dist2, 1.0f / k_sqrt(dist2));
}

/* The same for light li. */
KFN float light_pdf_area(const SceneView *sc, uint li, vec3 ref, vec3 x, vec3 n)
{
    return light_pdf_area_of(sc, light_seen(sc, li), ref, x, n);
}

/* The same with the choice of the light among all lights included (for MIS). */
KFN float light_pdf(const SceneView *sc, uint li, vec3 ref, vec3 x, vec3 n)
{
    float pick = sc->lights[li].pick_pdf;
    /* the light of an ellipsoid an instance makes of a sphere has no power, so it is
     * never chosen, and no sphere to read a density from (host/scene/scene_lights.c) */
    if (KF_HAS(KF_INSTANCES) && !(pick > 0.0f)) return 0.0f;
    return pick * light_pdf_area(sc, li, ref, x, n);
}

/* The density with which light sampling (light_sample(sc, ..., mis, ...)) picks
 * direction d toward the environment map (the choice of the map among all lights
 * included); 0 when the map is no light. MIS in shade_path computes the same value
 * from env_radiance_pdf's lookup; the tests check light samples against this. */
KFN float light_pdf_env(const SceneView *sc, vec3 d, int mis)
{
    uint li = sc->params->bg_light;
    return !KF_HAS(KF_ENV_MAP) || li == NO_INDEX || sc->params->bg_type != BG_MAP
               ? 0.0f
               : sc->lights[li].pick_pdf * env_pdf(sc, d, mis);
}

/* The share of a spot light's intensity sent at cosine c from its axis (enum
 * SpotFalloff). */
KFN float spot_falloff(Light l, float c)
{
    if (l.spot_falloff == SPOT_GLTF) {
        float t = k_clamp((c - l.cos_outer) / k_fmax(l.cos_inner - l.cos_outer, 1e-3f), 0.0f, 1.0f);
        return t * t;
    }
    return l.cos_inner > l.cos_outer ? k_smoothstep(l.cos_outer, l.cos_inner, c) : (c >= l.cos_outer ? 1.0f : 0.0f);
}

/* The light of delta light l arriving at ref: direction, distance and irradiance
 * across the direction. Returns 0 when none arrives (outside a spot's cone, ref on
 * the light, or l is the environment map, which is no delta light). */
KFN int light_delta_at(Light l, vec3 ref, LightSample *ls)
{
    if (l.type == LIGHT_ENV) return 0;
    ls->delta = 1;
    ls->n = v3s(0.0f);
    if (light_has(l.type, LT_INFINITE)) {
        ls->wi = v3_neg(l.direction);
        ls->dist = k_as_float(0x7f800000u);
        ls->p = ref;
        ls->Le = l.intensity;
        return 1;
    }
    vec3 to = v3_sub(l.position, ref);
    float d2 = v3_dot(to, to);
    float dist = k_sqrt(d2);
    float atten = l.atten0 + l.atten1 * dist + l.atten2 * d2;
    if (!(dist > 0.0f) || !(atten > 0.0f)) return 0;
    ls->wi = v3_scale(to, 1.0f / dist);
    ls->dist = dist;
    ls->p = l.position;
    float scale = 1.0f / atten;
    if (light_has(l.type, LT_CONE)) scale *= spot_falloff(l, -v3_dot(ls->wi, l.direction));
    ls->Le = v3_scale(l.intensity, scale);
    return scale > 0.0f;
}

/* Samples a point on area light li as seen from ref, with u_rest (the rest of the
 * choice number) choosing a box's face; pdf excludes the choice of the light. With
 * `reuse` set u_rest is u1 (light_sample_in), and a box's face is chosen from it
 * before the rest of it, rescaled, takes its place. Returns 0 if the sample is useless
 * (degenerate light, ref on the light's plane). */
KFN int light_sample_area(const SceneView *sc, uint li, vec3 ref, int reuse, float u_rest, float u1, float u2,
                          LightSample *ls)
{
    GLOBAL const RenderParams *p = sc->params;
    Light l = light_seen(sc, li);
    uint first_tri = p->n_spheres, first_box = first_tri + p->n_triangles;
    ls->Le = sc->materials[prim_material(sc, l.prim)].emission;
    ls->delta = 0;

    if (KF_HAS(KF_SPHERES) && l.prim < first_tri) {
        Sphere sp = light_sphere(sc, l);
        vec3 wc = v3_sub(sp.center, ref);
        float dc2 = v3_dot(wc, wc);
        if (sphere_cone_sampling(sp, dc2)) {
            /* outside: uniform over the cone of directions that see the sphere */
            float dc = k_sqrt(dc2);
            vec3 w = v3_scale(wc, 1.0f / dc);
            float omc = sphere_cone_one_minus_cos(sp.radius, dc2);
            float x = u1 * omc;                          /* 1 - cos(theta) */
            float cos_t = 1.0f - x;
            float sin_t = k_safe_sqrt(x * (2.0f - x));
            float sphi, cphi;
            k_sincos(K_TWO_PI * u2, &sphi, &cphi);
            vec3 t, b;
            k_onb(w, &t, &b);
            vec3 dir = k_to_world(v3(sin_t * cphi, sin_t * sphi, cos_t), t, b, w);
            float ds = dc * cos_t - k_safe_sqrt(sp.radius * sp.radius - dc2 * sin_t * sin_t);
            vec3 n = v3_norm(v3_sub(v3_madd(ref, dir, ds), sp.center));
            ls->n = n;
            ls->p = v3_madd(sp.center, n, sp.radius);
        } else {
            /* on or inside the sphere: uniform over the whole surface */
            vec3 n = sample_sphere_dir(u1, u2);
            ls->n = n;
            ls->p = v3_madd(sp.center, n, sp.radius);
        }
    } else if (l.prim < first_box) {
        if (KF_HAS(KF_INSTANCES) && l.type == LIGHT_INSTANCED) {
            /* the world triangle (types.h): the corner and edges the record holds. A
             * quad's half samples the whole parallelogram, as below, with or without
             * the light pair: the two halves together then cover it uniformly. */
            float s1, s2;    /* along the first edge and the second */
            if (l.quad != LIGHT_QUAD_NONE) {
                s1 = (l.quad == LIGHT_QUAD_SECOND ? 0.5f : 0.0f) + 0.5f * u1;
                s2 = u2;
            } else {
                sample_triangle(u1, u2, &s1, &s2);
            }
            ls->p = v3_add(l.position, v3_add(v3_scale(l.direction, s1), v3_scale(l.intensity, s2)));
        } else if (reuse && l.quad != LIGHT_QUAD_NONE) {
            /* half of a parallelogram (types.h): the rest of the choice number, u1, is
             * the coordinate along the edge, the first half's on [0, 1/2) and the
             * second's on [1/2, 1), so the pair's points cover the quad uniformly and
             * stay stratified over all of it. The point may lie in the other half,
             * which has the same plane, area, choice probability and emission. */
            float sq = (l.quad == LIGHT_QUAD_SECOND ? 0.5f : 0.0f) + 0.5f * u1;
            ls->p = v3_add(l.position, v3_add(v3_scale(l.direction, sq), v3_scale(l.intensity, u2)));
        } else {
            Triangle tr = sc->triangles[l.prim - first_tri];
            float b1, b2;
            sample_triangle(u1, u2, &b1, &b2);
            ls->p = v3_add(v3_add(v3_scale(tr.p0, 1.0f - b1 - b2), v3_scale(tr.p1, b1)), v3_scale(tr.p2, b2));
        }
        ls->n = l.normal;
    } else {
        /* a box: a face chosen by area with the rest of the choice number, then a uniform
         * point on it */
        Box bx = sc->boxes[l.prim - first_box];
        vec3 e = v3_sub(bx.hi, bx.lo);
        float ax = e.y * e.z, ay = e.x * e.z, az = e.x * e.y;
        float pick = u_rest * (ax + ay + az);
        int axis = pick < ax ? 0 : (pick < ax + ay ? 1 : 2);
        float face_area = axis == 0 ? ax : (axis == 1 ? ay : az);
        float below = axis == 0 ? 0.0f : (axis == 1 ? ax : ax + ay);
        float side = (pick - below) / face_area;         /* uniform in [0,1): which of the pair */
        int upper = side >= 0.5f;
        if (reuse) u1 = k_clamp(upper ? 2.0f * side - 1.0f : 2.0f * side, 0.0f, 0.99999994f);
        float c0 = upper ? 1.0f : 0.0f;
        vec3 q = v3(bx.lo.x + e.x * (axis == 0 ? c0 : u1),
                    bx.lo.y + e.y * (axis == 1 ? c0 : (axis == 0 ? u1 : u2)),
                    bx.lo.z + e.z * (axis == 2 ? c0 : u2));
        float sign = upper ? 1.0f : -1.0f;
        ls->p = q;
        ls->n = v3(axis == 0 ? sign : 0.0f, axis == 1 ? sign : 0.0f, axis == 2 ? sign : 0.0f);
    }
    vec3 to = v3_sub(ls->p, ref);
    float dist2 = v3_dot(to, to);
    ls->dist = k_sqrt(dist2);
    if (!(ls->dist > 0.0f)) return 0;
    float inv_dist = 1.0f / ls->dist;
    ls->wi = v3_scale(to, inv_dist);
    /* a sphere sampled by its cone has its own density; every other area light is
     * sampled by area, whose density needs no second square root or division */
    ls->pdf = KF_HAS(KF_SPHERES) && l.prim < first_tri ? light_pdf_area_of(sc, l, ref, ls->p, ls->n)
                                                       : light_pdf_by_area(l.area, ls->n, to, dist2, inv_dist);
    return ls->pdf > 0.0f && light_faces(sc, l.prim, ls->n, v3_sub(ref, ls->p));
}

/* At most this many delta lights are chosen among by what each sends to the shading
 * point (light_choose_delta); a scene with more keeps the choice by power alone, whose
 * cost does not grow with the lights. */
#define LIGHT_DELTA_LOCAL_MAX 16u

/* What delta light l sends to ref, occlusion aside: the sum of the channels of its
 * irradiance across the direction to it (attenuation and a spot's falloff included). */
KFN float light_delta_weight(Light l, vec3 ref)
{
    LightSample t;
    if (!light_delta_at(l, ref, &t)) return 0.0f;
    return t.Le.x + t.Le.y + t.Le.z;
}

/* Having chosen light li of the delta lights' group by its power, chooses again within
 * the group in proportion to light_delta_weight at ref, with uniform u; returns the
 * light's index and sets *pick to the probability of choosing it among all lights. A
 * light that sends nothing to ref is never chosen, and adds nothing there. Why: a
 * sun's share of the power is pi r^2 E over the scene's bounding sphere
 * (scene_lights.c), and on a large floor it took 91% of the choices from a lamp that
 * lit a third of the floor near the camera, whose light then came in few, heavy
 * samples (bench/RESULTS.md, "Cycles on the glTF files"); what a delta light sends to
 * a point costs a division to know, so the choice among a few is made where the point
 * is. With one delta light, more than LIGHT_DELTA_LOCAL_MAX, or weights that sum to
 * nothing finite, li stays, with its power share. A ray never hits a delta light, so
 * no MIS weight needs these probabilities again. */
KFN uint light_choose_delta(const SceneView *sc, vec3 ref, uint li, float u, float *pick)
{
    GLOBAL const RenderParams *p = sc->params;
    uint first = p->n_area_lights;
    uint n = p->n_lights - first - (p->bg_light != NO_INDEX ? 1u : 0u);
    *pick = sc->lights[li].pick_pdf;
    if (n < 2u || n > LIGHT_DELTA_LOCAL_MAX) return li;
    float total = 0.0f;
    for (uint i = 0; i < n; i++) total += light_delta_weight(sc->lights[first + i], ref);
    if (!(total > 0.0f) || !(total < k_as_float(0x7f800000u))) return li;
    float group = sc->lights[first + n - 1u].cdf - (first > 0u ? sc->lights[first - 1u].cdf : 0.0f);
    float target = u * total, acc = 0.0f, w_chosen = 0.0f;
    uint chosen = li;
    for (uint i = 0; i < n; i++) {
        float w = light_delta_weight(sc->lights[first + i], ref);
        if (!(w > 0.0f)) continue;
        chosen = first + i;
        w_chosen = w;
        acc += w;
        if (target < acc) break;
    }
    *pick = group * (w_chosen / total);
    return chosen;
}

/* Chooses a light among the first ones whose cdf reaches `cdf_top` (1: all of them;
 * the area lights' total: only those) and samples it from ref. The pdf includes the
 * choice. Returns 0 if the sample carries no light.
 *
 * With `reuse` set the light is chosen by u1, and the rest of it, rescaled to [0,1),
 * takes u1's place on the light (u_pick is unused): a stratified 2D point (u1, u2)
 * stays stratified over all the lights together, as one light, where a separate choice
 * number would give each light an unstratified share of the points. The rest loses
 * one of u1's 24 bits for each halving of the light's choice probability: a light
 * chosen once in 8192 samples still gets 2048 positions along u1. Without `reuse`
 * u_pick chooses, as for independent samples, where there is no stratification to
 * keep.
 *
 * `mis` says that MIS weighs the sample against BSDF sampling, which finds what it
 * leaves out: the environment map is then sampled from its compensated distribution
 * (kernels/light/envmap.h). */
KFN int light_sample_in(const SceneView *sc, vec3 ref, float cdf_top, int mis, int reuse, float u_pick, float u1,
                        float u2, LightSample *ls)
{
    float u_rest;
    uint li = light_choose(sc, (reuse ? u1 : u_pick) * cdf_top, &u_rest);
    if (reuse) u1 = u_rest;
    Light l = sc->lights[li];
    float choice = l.pick_pdf / cdf_top;
    if (KF_HAS(KF_ENV_MAP) && l.type == LIGHT_ENV) {
        /* the environment map: a direction from its distribution, infinitely far */
        float pdf;
        ls->wi = env_sample(sc, mis, u1, u2, &ls->Le, &pdf);
        ls->pdf = choice * pdf;
        ls->p = ref;
        ls->n = v3s(0.0f);
        ls->dist = k_as_float(0x7f800000u);
        ls->delta = 0;
        return ls->pdf > 0.0f;
    }
    if (KF_HAS(KF_DELTA_LIGHTS) && light_is_delta(l.type)) {
        /* the group of delta lights by power, then one of them by what it sends to ref,
         * with the rest of the choice number (a delta light needs no point on it) */
        float pick;
        li = light_choose_delta(sc, ref, li, u_rest, &pick);
        if (!light_delta_at(sc->lights[li], ref, ls)) return 0;
        ls->pdf = pick / cdf_top;
        return ls->pdf > 0.0f;
    }
    if (!light_sample_area(sc, li, ref, reuse, u_rest, u1, u2, ls)) return 0;
    ls->pdf *= choice;
    return ls->pdf > 0.0f;
}

/* Samples any light (next-event estimation of the path integrator; `mis` as above). */
KFN int light_sample(const SceneView *sc, vec3 ref, int mis, int reuse, float u_pick, float u1, float u2,
                     LightSample *ls)
{
    return light_sample_in(sc, ref, 1.0f, mis, reuse, u_pick, u1, u2, ls);
}

/* The shadow ray from surface point p (error bound p_err, geometric normal ng turned
 * toward the light) to the light sample: from just above the surface to just before an
 * area light, which must not count as its own occluder; to a point light; or off to
 * infinity (a directional light, the environment map). The light's point is taken as
 * a few roundings of its coordinates off its surface (barycentrics on a triangle,
 * centre + r n on a sphere), and the ray stops 1e-4 of the way short of it besides. */
KFN Ray light_shadow_ray(vec3 p, vec3 p_err, vec3 ng, LightSample ls)
{
    Ray r;
    r.o = spawn_offset(p, p_err, ng);
    r.tmin = 0.0f;
    if (!(ls.dist < k_as_float(0x7f800000u))) {
        r.d = ls.wi;
        r.tmax = k_as_float(0x7f800000u);
    } else if (ls.delta) {
        r.d = v3_sub(ls.p, r.o);
        r.tmax = 1.0f;
    } else {
        vec3 side = v3_dot(ls.n, ls.wi) > 0.0f ? v3_neg(ls.n) : ls.n;
        vec3 target = spawn_offset(ls.p, v3_scale(v3_abs(ls.p), K_ROUND_ERR(8)), side);
        r.d = v3_sub(target, r.o);
        r.tmax = 0.9999f;
    }
    return r;
}

#endif /* CLPT_LIGHTS_H */
