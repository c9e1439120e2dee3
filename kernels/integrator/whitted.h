/*
 * whitted.h — the classic ray tracer (Whitted 1980, as taught in MIT 6.837 and the
 * courses derived from it), the auxiliary images of the first hit, and the denoiser's
 * feature images (through mirrors and clear glass).
 *
 * One call computes one pixel sample from its camera ray to the end: at every hit the
 * local Phong shading from each point, spot and directional light (with a hard shadow
 * ray), one sample of the area lights, the ambient term and emission; then the mirror
 * and the refracted rays, which are traced in turn. Those rays wait on a private stack
 * (depth first: a ray at depth d pushes at most two rays at depth d + 1, so the stack
 * never holds more than max_depth + 1 of them) instead of being queued between kernel
 * launches as the path tracer's rays are: a sample's ray tree is small, its rays are as
 * coherent as their camera ray, and a single kernel needs no buffers per ray. The
 * design note is in docs/design.md.
 *
 * Units: a delta light's Le is the irradiance across its direction, and the local term
 * is (kd cos + ks max(0, r.wi)^shininess) Le / pi (r: the mirror direction of the view
 * ray). For kd alone this is a Lambertian surface's exact response; a classic-format
 * light of colour c has intensity pi c (host/io/classic_parse.c), which gives the course's
 * formula kd c cos + ks c (r.l)^s exactly.
 */
#ifndef CLPT_WHITTED_H
#define CLPT_WHITTED_H

#include "integrator/raygen.h"
#include "bsdf/bsdf.h"
#include "geom/surface.h"
#include "light/background.h"
#include "light/lights.h"
#include "material/mix.h"
#include "material/texture.h"
#include "sample/rng.h"
#include "accel/traverse.h"
#include "accel/alpha.h"

/* Deepest recursion the private stack allows (max_depth is clamped to it). */
#define WHITTED_STACK 32
/* A mirror or refracted ray whose weight drops below this carries no visible light
 * and is not traced (the classic "adaptive depth control"). */
#define WHITTED_MIN_WEIGHT 1e-4f

typedef struct {
    Ray ray;
    vec3 weight;     /* what its radiance counts for in the pixel */
    uint depth;      /* reflections and refractions since the camera */
} WhittedRay;

/* The camera ray of a pixel sample: through the pixel's centre (strata 0), a uniform
 * point of it (1), or a jittered point of cell (sample mod m^2) of an m x m grid. The
 * lens (and jitter) numbers come from the key of sample + sample_offset; *time is the
 * sample's time in the shutter (camera_time). */
KFN Ray whitted_camera_ray(GLOBAL const RenderParams *p, GLOBAL const MotionKey *motion_keys, uint pixel, uint sample,
                           RngKey *key_out, float *time)
{
    uint x, y;
    RngKey key = rng_key_make(p, params_image_pixel(p, pixel, &x, &y), sample + p->sample_offset);
    uint m = p->strata;
    float jx = 0.5f, jy = 0.5f;
    if (m == 1u) {
        jx = rng_uniform(key, 0u, DIM_PIXEL_X);
        jy = rng_uniform(key, 0u, DIM_PIXEL_Y);
    } else if (m >= 2u) {
        uint cell = sample % (m * m);
        jx = ((float)(cell % m) + rng_uniform(key, 0u, DIM_PIXEL_X)) / (float)m;
        jy = ((float)(cell / m) + rng_uniform(key, 0u, DIM_PIXEL_Y)) / (float)m;
    }
    *key_out = key;
    *time = camera_time(p, key);
    return camera_ray(p, motion_keys, params_film_s(p, x, jx), params_film_t(p, y, jy), key, *time);
}

/* The refracted direction of unit d at a boundary with normal n facing d's side and
 * eta = n_transmitted / n_incident; 0 on total internal reflection. */
KFN int refract_dir(vec3 d, vec3 n, float eta, vec3 *t)
{
    float cos_i = -v3_dot(d, n);
    float inv = 1.0f / eta;
    float k = 1.0f - inv * inv * (1.0f - cos_i * cos_i);
    if (k < 0.0f) return 0;
    *t = v3_norm(v3_add(v3_scale(d, inv), v3_scale(n, inv * cos_i - k_sqrt(k))));
    return 1;
}

/* The local Phong term for light arriving along wi with irradiance E (see the top). */
KFN vec3 whitted_phong(vec3 kd, vec3 ks, float shininess, vec3 r, vec3 n, vec3 wi, vec3 E)
{
    vec3 c = v3_scale(kd, v3_dot(n, wi));
    if (!v3_is_zero(ks)) c = v3_madd(c, ks, k_pow(k_fmax(v3_dot(r, wi), 0.0f), shininess));
    return v3_scale(v3_mul(c, E), K_INV_PI);
}

/* Whether light sample ls is blocked from surface s; with shadows off it never is
 * and no ray is traced (the course ray casters cast no shadows). */
KFN int whitted_occluded(const SceneView *sc, Surface s, vec3 ng, LightSample ls, uint *rays)
{
    if (!sc->params->shadows) return 0;
    (*rays)++;
    return trace_occluded(sc, light_shadow_ray(s.p, s.err, ng, ls));
}

/* Direct light at surface point s: every delta light, and one sample of the area lights
 * (random numbers of tree node `node`), each behind its shadow ray (if shadows are on). d is the incoming
 * direction, ns and ng the normals on its side. */
KFN vec3 whitted_direct(const SceneView *sc, Surface s, vec3 d, vec3 ns, vec3 ng, vec3 kd, vec3 ks,
                        float shininess, RngKey key, uint node, uint *rays)
{
    GLOBAL const RenderParams *p = sc->params;
    vec3 L = v3s(0.0f);
    vec3 r = reflect_dir(d, ns);
    for (uint li = p->n_area_lights; li < p->n_lights; li++) {
        LightSample ls;
        if (!light_delta_at(sc->lights[li], s.p, &ls)) continue;
        if (v3_dot(ns, ls.wi) <= 0.0f || v3_dot(ng, ls.wi) <= 0.0f) continue;
        if (whitted_occluded(sc, s, ng, ls, rays)) continue;
        L = v3_add(L, whitted_phong(kd, ks, shininess, r, ns, ls.wi, ls.Le));
    }
    if (p->n_area_lights > 0u) {
        float top = sc->lights[p->n_area_lights - 1u].cdf;
        LightSample ls;
        if (top > 0.0f &&
            light_sample_in(sc, s.p, top, 0, 0, rng_uniform(key, node, DIM_LIGHT_PICK),
                            rng_uniform(key, node, DIM_LIGHT_U), rng_uniform(key, node, DIM_LIGHT_V), &ls) &&
            !ls.delta && v3_dot(ns, ls.wi) > 0.0f && v3_dot(ng, ls.wi) > 0.0f) {
            if (!whitted_occluded(sc, s, ng, ls, rays))
                L = v3_add(L, whitted_phong(kd, ks, shininess, r, ns, ls.wi, v3_scale(ls.Le, 1.0f / ls.pdf)));
        }
    }
    return L;
}

/* Pushes a secondary ray if it still carries something. */
KFN void whitted_push(WhittedRay *stack, int *sp, vec3 o, vec3 dir, vec3 weight, uint depth)
{
    if (!(v3_max_comp(weight) > WHITTED_MIN_WEIGHT)) return;
    WhittedRay e;
    e.ray.o = o;
    e.ray.d = dir;
    e.ray.tmin = 0.0f;
    e.ray.tmax = INFINITY;
    e.weight = weight;
    e.depth = depth;
    stack[*sp] = e;
    (*sp)++;
}

/* Radiance along a camera ray, Whitted style. */
KFN vec3 whitted_radiance(const SceneView *sc, Ray camera, RngKey key, uint *rays)
{
    GLOBAL const RenderParams *p = sc->params;
    uint max_depth = p->max_depth < (uint)(WHITTED_STACK - 1) ? p->max_depth : (uint)(WHITTED_STACK - 1);
    WhittedRay stack[WHITTED_STACK];
    int sp = 0;
    whitted_push(stack, &sp, camera.o, camera.d, v3s(1.0f), 0u);
    vec3 L = v3s(0.0f);
    uint node = 0u;
    while (sp > 0) {
        sp--;
        WhittedRay e = stack[sp];
        Hit hit = trace_closest_visible(sc, e.ray);
        (*rays)++;
        node++;
        vec3 d = e.ray.d;
        if (hit.prim == NO_INDEX) {
            L = v3_add(L, v3_mul(e.weight, background_radiance(sc, d)));
            continue;
        }
        Surface s = surface_at(sc, e.ray, hit);
        Material m = sc->materials[s.material];   /* a mix: its own emission (mix.h) */
        int front = v3_dot(d, s.ng) < 0.0f;
        vec3 ng = front ? s.ng : v3_neg(s.ng);
        vec3 emission = material_emission(sc, m, s);
        if (!v3_is_zero(emission) && ((m.flags & MAT_TWO_SIDED) || front))
            L = v3_add(L, v3_mul(e.weight, emission));
        material_resolve(sc, &m, s, d, ng);
        if (!material_scatters(m.type)) continue;
        s.ns = material_normal(sc, m, s);
        vec3 ns = bsdf_normal(m, d, front ? s.ns : v3_neg(s.ns), ng);

        vec3 kd = material_albedo(sc, m, s, ng);
        material_at(sc, &m, s, ng);
        vec3 kr = v3s(0.0f), kt = v3s(0.0f);
        if (m.type == MAT_PRINCIPLED) {
            /* the classic tracer's reading of glTF: the diffuse share lit directly, the
             * specular as a mirror of the Schlick colour at this angle (with
             * KHR_materials_specular's F0 and F90), transmission as smooth glass tinted
             * by the base colour. It has no sheen layer and no absorption. */
            float c = k_clamp(-v3_dot(d, ns), 0.0f, 1.0f);
            vec3 fd = principled_fresnel_rgb(bsdf_principled(m, kd, front), c), pass = v3_sub(v3s(1.0f), fd);
            float diel = 1.0f - k_clamp(m.metallic, 0.0f, 1.0f), t = k_clamp(m.transmission, 0.0f, 1.0f);
            kr = v3_add(v3_scale(fresnel_schlick(kd, c), 1.0f - diel), v3_scale(fd, diel));
            kt = v3_scale(v3_mul(kd, pass), diel * t);
            kd = v3_scale(v3_mul(kd, pass), diel * (1.0f - t));
            vec3 here = v3_add(v3_mul(p->ambient, kd),
                               whitted_direct(sc, s, d, ns, ng, kd, v3s(0.0f), 0.0f, key, node, rays));
            L = v3_add(L, v3_mul(e.weight, here));
        } else if (m.type == MAT_DIFFUSE || m.type == MAT_PHONG) {
            vec3 ks = m.type == MAT_PHONG ? m.specular : v3s(0.0f);
            vec3 here = v3_add(v3_mul(p->ambient, kd),
                                whitted_direct(sc, s, d, ns, ng, kd, ks, m.shininess, key, node, rays));
            L = v3_add(L, v3_mul(e.weight, here));
            if (m.type == MAT_PHONG) {
                kr = m.reflective;
                kt = m.transparent;
            }
        } else if (m.type == MAT_LAYERED) {
            /* the classic tracer's reading of a coated material: the interface a Fresnel
             * mirror over a base lit directly (diffuse) or a mirror itself (conductor) */
            float c = k_clamp(-v3_dot(d, ns), 0.0f, 1.0f), F = fresnel_dielectric(c, m.ior);
            kr = v3s(F);
            if (m.layer_base == LAYER_BASE_CONDUCTOR) {
                kr = v3_add(kr, v3_scale(conductor_fresnel(bsdf_layered(m, kd).c, c), 1.0f - F));
            } else {
                kd = v3_scale(kd, 1.0f - F);
                vec3 here = v3_add(v3_mul(p->ambient, kd),
                                   whitted_direct(sc, s, d, ns, ng, kd, v3s(0.0f), 0.0f, key, node, rays));
                L = v3_add(L, v3_mul(e.weight, here));
            }
        } else if (m.type == MAT_METAL) {
            kr = kd;
        } else if (m.type == MAT_CONDUCTOR) {
            /* the classic tracer has only mirrors: a rough conductor is its smooth one,
             * coloured by its Fresnel reflectance at this angle */
            kr = conductor_fresnel(bsdf_conductor(m, kd), k_clamp(-v3_dot(d, ns), 0.0f, 1.0f));
        } else {
            kt = v3s(1.0f);
        }
        if (e.depth >= max_depth) continue;

        /* the see-through part splits by Fresnel into more mirror and the refraction */
        vec3 t_dir = d;
        if (!v3_is_zero(kt)) {
            int thin = (m.type == MAT_DIELECTRIC || m.type == MAT_PRINCIPLED) && (m.flags & MAT_THIN);
            float eta = front || thin ? m.ior : 1.0f / m.ior;
            float F = fresnel_dielectric(k_clamp(-v3_dot(d, ns), 0.0f, 1.0f), eta);
            int ok = 1;
            if (thin) {
                /* a thin sheet: both faces reflect, the rest goes straight on */
                F = dielectric_facet_fresnel(bsdf_dielectric(m, front), k_clamp(-v3_dot(d, ns), 0.0f, 1.0f));
            } else {
                ok = refract_dir(d, ns, eta, &t_dir);
                if (ok && v3_dot(t_dir, ng) >= 0.0f) ok = refract_dir(d, ng, eta, &t_dir);
            }
            if (!ok) F = 1.0f;
            kr = v3_add(kr, v3_scale(kt, F));
            kt = v3_scale(kt, 1.0f - F);
        }
        if (!v3_is_zero(kt))
            whitted_push(stack, &sp, spawn_origin(s, v3_neg(ng)), t_dir, v3_mul(e.weight, kt), e.depth + 1u);
        if (!v3_is_zero(kr)) {
            vec3 r_dir = reflect_dir(d, ns);
            if (v3_dot(r_dir, ng) <= 0.0f) r_dir = reflect_dir(d, ng);
            whitted_push(stack, &sp, spawn_origin(s, ng), r_dir, v3_mul(e.weight, kr), e.depth + 1u);
        }
    }
    return L;
}

/* The albedo image's value at surface s of (resolved) material m: its diffuse colour,
 * 1 for glass (as Open Image Denoise's documentation advises for dielectrics), 0 for
 * what does not scatter (a lamp). */
KFN vec3 aov_albedo_at(const SceneView *sc, Material m, Surface s, vec3 ng)
{
    if (!material_scatters(m.type)) return v3s(0.0f);
    if (m.type == MAT_DIELECTRIC) return v3s(1.0f);
    return material_albedo(sc, m, s, ng);
}

/* An auxiliary image's value at the first hit (enum Integrator). */
KFN vec3 whitted_aov(const SceneView *sc, Ray ray, uint mode, uint *rays)
{
    Hit hit = trace_closest_visible(sc, ray);
    (*rays)++;
    if (hit.prim == NO_INDEX)
        return v3s(mode == INTEGRATOR_AOV_NORMAL && sc->params->normal_miss_grey ? 0.5f : 0.0f);
    Surface s = surface_at(sc, ray, hit);
    if (mode == INTEGRATOR_AOV_NORMAL) return v3_scale(v3_add(s.ns, v3s(1.0f)), 0.5f);
    if (mode == INTEGRATOR_AOV_DEPTH) return v3(hit.t * v3_len(ray.d), 1.0f, 0.0f);
    vec3 ng = v3_dot(ray.d, s.ng) < 0.0f ? s.ng : v3_neg(s.ng);
    Material m = sc->materials[s.material];
    material_resolve(sc, &m, s, ray.d, ng);
    return aov_albedo_at(sc, m, s, ng);
}

/* How many perfectly specular surfaces in a row the denoiser's features pass through;
 * the surface after them gives its own, specular or not. */
#define FEATURE_SPECULAR_DEPTH 8u

/* Each channel of c limited to 0..1 (OIDN's range for the albedo; NaN becomes 0). */
KFN vec3 feature_unit(vec3 c)
{
    return v3(k_clamp(c.x, 0.0f, 1.0f), k_clamp(c.y, 0.0f, 1.0f), k_clamp(c.z, 0.0f, 1.0f));
}

/* The denoiser's albedo at the first surface that is not perfectly specular: the albedo
 * image's (aov_albedo_at), except on metals, where Open Image Denoise's documentation
 * (the RT filter's "Albedo" section) asks for the reflectivity at normal incidence: a
 * rough conductor's Fresnel colour at cos = 1 times its tint, and for the coated
 * conductor the same seen through its clear coat, F + (1 - F) F0 with the coat's own F
 * at normal incidence (as feature_specular_next weighs the smooth one). A conductor's
 * tint is 1 unless given, so without this every metal looks white to the denoiser,
 * whatever its colour and however dark (iron and titanium reflect about 55%). */
KFN vec3 feature_albedo_at(const SceneView *sc, Material m, Surface s, vec3 ng, vec3 kd)
{
    if (m.type == MAT_CONDUCTOR) return conductor_fresnel(bsdf_conductor(m, kd), 1.0f);
    if (m.type == MAT_LAYERED && m.layer_base == LAYER_BASE_CONDUCTOR) {
        float F = fresnel_dielectric(1.0f, m.ior);
        return v3_add(v3s(F), v3_scale(conductor_fresnel(bsdf_layered(m, kd).c, 1.0f), 1.0f - F));
    }
    return aov_albedo_at(sc, m, s, ng);
}

/* Whether the features go on past surface s of (resolved) material m, seen along d: only
 * when m is perfectly specular (no lobe with a density, bsdf_has_density, and for the
 * classic metal no fuzz), and then along one lobe chosen without random numbers:
 *   - smooth glass: the larger of its two parts by the Fresnel reflectance F at this
 *     angle (both faces of a thin sheet), as whitted_radiance splits them, weighted by
 *     it: the refracted ray (straight on through a thin sheet) with 1 - F where F < 1/2,
 *     else the mirror ray with F (near grazing angles, total internal reflection);
 *   - a classic Phong material that is only mirror and see-through: the larger of the
 *     two by luminance, weighted by its colour;
 *   - metal, smooth conductors, a smooth coat over a smooth conductor: the mirror ray,
 *     weighted by the reflectance the classic tracer gives it (whitted_radiance).
 * *next and *weight receive the ray and what it multiplies the albedo by. */
KFN int feature_specular_next(Material m, Surface s, vec3 d, vec3 ng, vec3 kd, Ray *next, vec3 *weight)
{
    if (!material_scatters(m.type) || m.type == MAT_PRINCIPLED || bsdf_has_density(m, kd)) return 0;
    if (m.type == MAT_METAL && m.fuzz > 0.0f) return 0;
    int front = v3_dot(d, s.ng) < 0.0f;
    vec3 ns = bsdf_normal(m, d, front ? s.ns : v3_neg(s.ns), ng);
    float c = k_clamp(-v3_dot(d, ns), 0.0f, 1.0f);
    int transmit = 0;
    vec3 w = v3s(1.0f);
    int thin = m.type == MAT_DIELECTRIC && (m.flags & MAT_THIN);
    if (m.type == MAT_DIELECTRIC) {
        float F = thin ? dielectric_facet_fresnel(bsdf_dielectric(m, front), c)
                       : fresnel_dielectric(c, front ? m.ior : 1.0f / m.ior);
        transmit = F < 0.5f;
        w = v3s(transmit ? 1.0f - F : F);
    } else if (m.type == MAT_PHONG) {
        PhongLobes l = phong_lobes(m, kd);
        transmit = v3_luminance(l.kt) > v3_luminance(l.kr);
        w = transmit ? l.kt : l.kr;
    } else if (m.type == MAT_METAL) {
        w = kd;
    } else if (m.type == MAT_CONDUCTOR) {
        w = conductor_fresnel(bsdf_conductor(m, kd), c);
    } else if (m.type == MAT_LAYERED) {
        float F = fresnel_dielectric(c, m.ior);
        w = v3_add(v3s(F), v3_scale(conductor_fresnel(bsdf_layered(m, kd).c, c), 1.0f - F));
    }
    if (v3_is_zero(w)) return 0;
    vec3 dir = d;
    if (transmit && !thin) {
        /* as whitted_radiance refracts: through the shading normal, else the geometric one */
        float eta = front ? m.ior : 1.0f / m.ior;
        transmit = refract_dir(d, ns, eta, &dir);
        if (transmit && v3_dot(dir, ng) >= 0.0f) transmit = refract_dir(d, ng, eta, &dir);
    }
    if (!transmit) {
        dir = reflect_dir(d, ns);
        if (v3_dot(dir, ng) <= 0.0f) dir = reflect_dir(d, ng);
    }
    next->o = spawn_origin(s, transmit ? v3_neg(ng) : ng);
    next->d = dir;
    next->tmin = 0.0f;
    next->tmax = INFINITY;
    *weight = w;
    return 1;
}

/* A feature image of the denoiser (INTEGRATOR_FEATURE_*) along a camera ray: the albedo
 * and the shading normal (as (n + 1) / 2) of the first surface that is not perfectly
 * specular, seen through up to FEATURE_SPECULAR_DEPTH mirrors and clear glass, as Open
 * Image Denoise's documentation recommends for its auxiliary images; the albedo times
 * the weights of the specular surfaces passed (feature_specular_next). A ray that
 * escapes gives the environment's colour (clamped to 0..1) as albedo and no normal. */
KFN vec3 whitted_feature(const SceneView *sc, Ray ray, uint mode, uint *rays)
{
    vec3 tint = v3s(1.0f);
    for (uint bounce = 0u;; bounce++) {
        Hit hit = trace_closest_visible(sc, ray);
        (*rays)++;
        if (hit.prim == NO_INDEX) {
            if (mode == INTEGRATOR_FEATURE_NORMAL) return v3s(sc->params->normal_miss_grey ? 0.5f : 0.0f);
            return feature_unit(v3_mul(tint, background_radiance(sc, ray.d)));
        }
        Surface s = surface_at(sc, ray, hit);
        vec3 ng = v3_dot(ray.d, s.ng) < 0.0f ? s.ng : v3_neg(s.ng);
        Material m = sc->materials[s.material];
        material_resolve(sc, &m, s, ray.d, ng);
        vec3 kd = material_albedo(sc, m, s, ng), w;
        Ray next;
        if (bounce < FEATURE_SPECULAR_DEPTH && feature_specular_next(m, s, ray.d, ng, kd, &next, &w)) {
            tint = v3_mul(tint, w);
            ray = next;
            continue;
        }
        if (mode == INTEGRATOR_FEATURE_NORMAL) return v3_scale(v3_add(material_normal(sc, m, s), v3s(1.0f)), 0.5f);
        return feature_unit(v3_mul(tint, feature_albedo_at(sc, m, s, ng, kd)));
    }
}

/* The denoiser's emission feature (INTEGRATOR_FEATURE_EMISSION) along a camera ray of
 * the path integrator: the emission of the first surface it meets, as shade_emission
 * counts it there (front faces, or both of a two-sided emitter; a mix's own emission;
 * full weight, since what the camera sees directly takes no MIS), or the background's
 * radiance where it escapes, as shade_escape counts it at the first bounce. It has no
 * noise but the pixel's coverage: the path's first-hit emission for the same samples. */
KFN vec3 feature_emission(const SceneView *sc, Ray ray, uint *rays)
{
    Hit hit = trace_closest_visible(sc, ray);
    (*rays)++;
    if (hit.prim == NO_INDEX) return background_radiance(sc, ray.d);
    Surface s = surface_at(sc, ray, hit);
    Material m = sc->materials[s.material];
    if (!(m.flags & MAT_TWO_SIDED) && v3_dot(ray.d, s.ng) >= 0.0f) return v3s(0.0f);
    return material_emission(sc, m, s);
}

/* One pixel sample of the whitted integrator or of an auxiliary image; *rays counts
 * what it traced. */
KFN vec3 whitted_sample(const SceneView *sc, uint pixel, uint sample, uint *rays)
{
    GLOBAL const RenderParams *p = sc->params;
    *rays = 0u;
    RngKey key;
    float time;
    Ray r = p->integrator == INTEGRATOR_FEATURE_EMISSION
                ? path_camera_ray(p, sc->motion_keys, pixel, sample, &key, &time)
                : whitted_camera_ray(p, sc->motion_keys, pixel, sample, &key, &time);
#if KF_HAS(KF_MOTION)
    /* the scene as it is at the sample's time (SceneView.time) */
    SceneView at_time;
    if (p->camera.moving) {
        at_time = *sc;
        at_time.time = time;
        sc = &at_time;
    }
#endif
    if (p->integrator == INTEGRATOR_WHITTED) return whitted_radiance(sc, r, key, rays);
    if (p->integrator == INTEGRATOR_FEATURE_EMISSION) return feature_emission(sc, r, rays);
    if (p->integrator >= INTEGRATOR_FEATURE_NORMAL) return whitted_feature(sc, r, p->integrator, rays);
    return whitted_aov(sc, r, p->integrator, rays);
}

#endif /* CLPT_WHITTED_H */
