/*
 * bsdf.h — how each material scatters light: sampling a new direction and, for the
 * non-delta lobes, evaluating the BSDF and its density for next-event estimation.
 * Directions point away from the surface; `wo` is toward where the light goes (the
 * previous vertex), n is the shading normal turned to wo's side.
 */
#ifndef CLPT_BSDF_H
#define CLPT_BSDF_H

#include "sampling.h"

typedef struct {
    vec3 wi;          /* sampled direction */
    vec3 weight;      /* f * |cos| / pdf */
    float pdf;        /* solid-angle density; 0 for delta lobes */
    int specular;     /* delta (or treated as delta: fuzzy metal) */
} BsdfSample;

KFN vec3 reflect_dir(vec3 d, vec3 n) { return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n))); }

/* Unpolarised Fresnel reflectance of a smooth dielectric boundary; cos_i > 0 is on the
 * incident side, eta = n_transmitted / n_incident. Returns 1 on total internal reflection. */
KFN float fresnel_dielectric(float cos_i, float eta)
{
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;
    float cos_t = k_sqrt(1.0f - sin2_t);
    float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5f * (r_par * r_par + r_perp * r_perp);
}

/* Lambertian: f = albedo / pi, cosine-weighted sampling. */
KFN BsdfSample bsdf_sample_diffuse(vec3 albedo, vec3 n, float u1, float u2)
{
    BsdfSample s;
    vec3 t, b;
    k_onb(n, &t, &b);
    vec3 v_local = sample_cosine_hemisphere(u1, u2);
    s.wi = k_to_world(v_local, t, b, n);
    s.pdf = v_local.z * K_INV_PI;
    s.weight = albedo;
    s.specular = 0;
    return s;
}

/* Metal as in "Ray Tracing in One Weekend": the mirror direction moved by a random
 * point of a ball of radius `fuzz`. Its density has no closed form, so it is treated
 * like a delta lobe (no light sampling, emission seen through it counts fully), which
 * keeps the estimator unbiased. */
KFN BsdfSample bsdf_sample_metal(vec3 albedo, float fuzz, vec3 d, vec3 n, float u1, float u2, float u3)
{
    BsdfSample s;
    vec3 r = reflect_dir(d, n);
    if (fuzz > 0.0f) r = v3_madd(r, sample_ball(u1, u2, u3), fuzz);
    s.wi = v3_norm(r);
    s.weight = albedo;
    s.pdf = 0.0f;
    s.specular = 1;
    return s;
}

/* Smooth glass: reflect with the Fresnel probability, otherwise refract. `d` is the
 * incoming unit direction, n the geometric normal facing the incoming side, `entering`
 * whether d comes from outside (the side the outward normal points to). */
KFN BsdfSample bsdf_sample_dielectric(float ior, vec3 d, vec3 n, int entering, float u)
{
    BsdfSample s;
    float eta = entering ? ior : 1.0f / ior;     /* n_t / n_i */
    float cos_i = -v3_dot(d, n);
    float F = fresnel_dielectric(cos_i, eta);
    if (u < F) {
        s.wi = reflect_dir(d, n);
    } else {
        float inv = 1.0f / eta;
        float cos_t = k_safe_sqrt(1.0f - inv * inv * (1.0f - cos_i * cos_i));
        s.wi = v3_norm(v3_add(v3_scale(d, inv), v3_scale(n, inv * cos_i - cos_t)));
    }
    /* choosing the lobe with probability F (or 1-F) cancels the Fresnel factor; the
     * radiance scaling by eta^2 is left out, as is usual for camera paths that end on
     * lights outside the glass */
    s.weight = v3s(1.0f);
    s.pdf = 0.0f;
    s.specular = 1;
    return s;
}

#endif /* CLPT_BSDF_H */
