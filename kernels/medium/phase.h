/*
 * phase.h — the Henyey-Greenstein phase function (Henyey & Greenstein 1941): how a
 * medium scatters light by angle, one parameter g, the mean cosine of the scattering
 * angle (g > 0 forward, g < 0 backward, 0 evenly). It is normalised over the sphere of
 * directions, and sampled exactly, so a phase sample's weight f / pdf is 1.
 *
 * kernels/bsdf/layered.h has its own copy for the medium between a coating's layers,
 * written with pbrt's wo; it is kept as it is so that those materials' images stay the
 * same bits.
 *
 * Directions: `d` is the direction the ray travelled before the scattering point, `wi`
 * the one it leaves in; the scattering angle's cosine is dot(d, wi), 1 when the ray goes
 * straight on. (pbrt writes the same function with wo = -d.)
 */
#ifndef CLPT_PHASE_H
#define CLPT_PHASE_H

#include "util/kmath.h"

#define K_INV_FOUR_PI 0.0795774715459477f

/* The density (per steradian) of leaving at cosine mu from the travel direction. */
KFN float phase_hg_mu(float g, float mu)
{
    float denom = 1.0f + g * g - 2.0f * g * mu;
    /* denom >= (1 - |g|)^2 > 0 for |g| < 1; the clamp guards mu's rounding past 1 */
    denom = k_fmax(denom, 1e-12f);
    return K_INV_FOUR_PI * (1.0f - g * g) / (denom * k_sqrt(denom));
}

/* The phase function's value for travel direction d and new direction wi (both unit);
 * it is also the density of phase_hg_sample's directions. */
KFN float phase_hg(float g, vec3 d, vec3 wi)
{
    return phase_hg_mu(g, k_clamp(v3_dot(d, wi), -1.0f, 1.0f));
}

/* The cosine of a sampled scattering angle: the inverse of the distribution of mu,
 * whose cumulative form is solved for mu in closed form; u = 0 gives -1, u = 1 gives 1.
 * g = 0 is the uniform sphere (the closed form divides by g: media store |g| < 1e-3 as
 * 0, types.h). */
KFN float phase_hg_sample_mu(float g, float u)
{
    if (g == 0.0f) return 2.0f * u - 1.0f;
    float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u);
    return k_clamp((1.0f + g * g - s * s) / (2.0f * g), -1.0f, 1.0f);
}

/* A direction around unit travel direction d with the phase function's density
 * (returned in *pdf, equal to the function's value). */
KFN vec3 phase_hg_sample(float g, vec3 d, float u1, float u2, float *pdf)
{
    float mu = phase_hg_sample_mu(g, u1);
    float sin_t = k_safe_sqrt(1.0f - mu * mu);
    float s, c;
    k_sincos(K_TWO_PI * u2, &s, &c);
    vec3 t, b;
    k_onb(d, &t, &b);
    vec3 wi = v3_norm(k_to_world(v3(sin_t * c, sin_t * s, mu), t, b, d));
    *pdf = phase_hg_mu(g, mu);
    return wi;
}

#endif /* CLPT_PHASE_H */
