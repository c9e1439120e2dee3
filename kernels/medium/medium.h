/*
 * medium.h — homogeneous participating media: transmittance, free-flight distances with
 * one-sample MIS over the RGB channels, and which medium a ray is in after a boundary.
 * docs/media.md derives the estimators; the integrator's use of them is in
 * kernels/medium/medium_path.h.
 *
 * Chromatic media (sigma_t differing by channel) cannot be sampled by one exponential
 * that fits every channel. A distance is therefore drawn from one channel's exponential,
 * the channel chosen with probability proportional to the path's throughput in it, and
 * the estimate divides by the mixture of the three channels' densities (the balance
 * heuristic over the channels, as Cycles and pbrt-v4's spectral MIS do; Miller et al.
 * 2019, sec. 5.3). Every channel is then unbiased, including those whose own
 * exponential would never have reached the sampled point.
 */
#ifndef CLPT_MEDIUM_H
#define CLPT_MEDIUM_H

#include "util/kmath.h"
#include "types.h"

/* Most boundaries (MAT_INTERFACE) a path passes straight through: a path that would
 * pass more ends there, a shadow ray is taken as blocked. A camera ray through a fog box
 * passes two, a bounce in a room whose air is such a box two more; 64 leaves room for
 * nested boundaries while it bounds the wavefront's launches (path_max_shades). */
#define MEDIUM_MAX_CROSSINGS 64u

/* The most steps of subsurface random walks (MEDIUM_WALK) a path takes, all its walks
 * together: each step, and each reflection off the inside of a subsurface surface, is
 * no bounce but counts as a crossing. 256 is Cycles' bound on one walk's steps; a walk
 * cut there ends the path (and loses its light, as Cycles' does). */
#define MEDIUM_MAX_WALK 1024u

/* The most crossings (PathState.crossings) a path of a scene with RenderParams.has_media
 * `has_media` may make: boundaries passed, and in scenes with subsurface walks their
 * steps too. */
KFN uint path_max_crossings(uint has_media)
{
    return MEDIUM_MAX_CROSSINGS + ((has_media & HAS_MEDIA_WALK) ? MEDIUM_MAX_WALK : 0u);
}

/* The most times shade_path runs for one path: once per bounce (0 .. max_depth) and
 * once per crossing, which is no bounce. The wavefront launches that many bounces of a
 * wave at most (host/device/device_ocl.c). */
KFN uint path_max_shades(uint max_depth, uint has_media)
{
    return max_depth + 1u + (has_media ? path_max_crossings(has_media) : 0u);
}

KFN vec3 medium_sigma_t(Medium m) { return v3_add(m.sigma_a, m.sigma_s); }

/* exp(-sigma dist) for one channel: 1 when sigma is 0, whatever the distance (an
 * infinite ray through a clear channel), 0 for an infinite distance otherwise. */
KFN float medium_tr1(float sigma, float dist)
{
    if (!(sigma > 0.0f)) return 1.0f;
    return k_exp2(-sigma * dist * 1.44269504f);
}

/* The transmittance along `dist` of scene length through extinction sigma_t. Channels
 * of equal extinction share one exponential (the same bits: medium_tr1 depends on its
 * arguments alone): a grey fog's three were 7% of its render on PoCL (bench/RESULTS.md,
 * "Fog: the leaves, a grey medium's exponential, and where its variance is"). */
KFN vec3 medium_tr(vec3 sigma_t, float dist)
{
    float x = medium_tr1(sigma_t.x, dist);
    float y = sigma_t.y == sigma_t.x ? x : medium_tr1(sigma_t.y, dist);
    float z = sigma_t.z == sigma_t.x ? x : (sigma_t.z == sigma_t.y ? y : medium_tr1(sigma_t.z, dist));
    return v3(x, y, z);
}

/* The radiance a homogeneous medium emits toward the start of a stretch `dist` long,
 * per channel: the integral of T(t) sigma_a Le dt over [0, dist), which is
 * Le sigma_a (1 - exp(-sigma_t dist)) / sigma_t, in closed form (the emission term of
 * the radiative transfer equation, dL/ds = ... + sigma_a Le, as pbrt-v4's media; PBR
 * 4th ed., sec. 11.1.2). Exact, so the flight adds it whatever distance it samples:
 * no noise, and no random number. Below an optical depth of 1e-3 the series
 * dist (1 - x / 2) keeps the digits that 1 - exp(-x) would lose. */
KFN float medium_emitted1(float sigma_a, float sigma_t, float le, float dist)
{
    if (!(sigma_a > 0.0f) || !(le > 0.0f)) return 0.0f;
    float x = sigma_t * dist;
    float len = x < 1e-3f ? dist * (1.0f - 0.5f * x) : (1.0f - medium_tr1(sigma_t, dist)) / sigma_t;
    return le * sigma_a * len;
}

KFN vec3 medium_emitted(Medium m, vec3 sigma_t, float dist)
{
    return v3(medium_emitted1(m.sigma_a.x, sigma_t.x, m.emission.x, dist),
              medium_emitted1(m.sigma_a.y, sigma_t.y, m.emission.y, dist),
              medium_emitted1(m.sigma_a.z, sigma_t.z, m.emission.z, dist));
}

/* The channel probabilities for the distance sampling: proportional to the path's
 * throughput (a channel that carries nothing is never chosen, so the distances follow
 * the channels that matter); uniform if the throughput is no use (0 or not finite). */
KFN vec3 medium_channel_pdf(vec3 throughput)
{
    float sum = throughput.x + throughput.y + throughput.z;
    if (!(sum > 0.0f) || !(sum < k_as_float(0x7f800000u))) return v3s(1.0f / 3.0f);
    return v3_scale(throughput, 1.0f / sum);
}

/* Picks a channel with probabilities pc by u and returns it; *u_rest is what is left of
 * u, rescaled to [0, 1), so that one stratified number chooses both the channel and
 * the distance. A channel of probability 0 is never returned. */
KFN int medium_pick_channel(vec3 pc, float u, float *u_rest)
{
    float c0 = pc.x, c1 = pc.x + pc.y;
    int c = u < c0 ? 0 : (u < c1 || !(pc.z > 0.0f) ? 1 : 2);
    if (c == 1 && !(pc.y > 0.0f)) c = pc.z > 0.0f ? 2 : 0;
    float lo = c == 0 ? 0.0f : (c == 1 ? c0 : c1);
    float p = v3_get(pc, c);
    *u_rest = k_clamp((u - lo) / p, 0.0f, 0.99999994f);
    return c;
}

/* A free-flight distance from the exponential of extinction sigma (per unit length):
 * -ln(1 - u) / sigma; infinite for a clear channel. */
KFN float medium_sample_exp(float sigma, float u)
{
    if (!(sigma > 0.0f)) return k_as_float(0x7f800000u);
    return -k_log2(1.0f - u) * 0.693147181f / sigma;
}

/* The mixture density of reaching distance t and stopping there (sum over channels of
 * pc_c sigma_c T_c(t)), given tr = T(t). */
KFN float medium_stop_pdf(vec3 pc, vec3 sigma_t, vec3 tr)
{
    return pc.x * sigma_t.x * tr.x + pc.y * sigma_t.y * tr.y + pc.z * sigma_t.z * tr.z;
}

/* 1 - exp(-sigma dist) for one channel, the series sigma dist (1 - x / 2) below an
 * optical depth of 1e-3, where the difference would lose its digits. */
KFN float medium_absorbed1(float sigma, float dist)
{
    if (!(sigma > 0.0f)) return 0.0f;
    float x = sigma * dist;
    return x < 1e-3f ? x * (1.0f - 0.5f * x) : 1.0f - medium_tr1(sigma, dist);
}

/* The mixture probability of stopping before distance dist (1 - P(pass), computed
 * without the cancellation of a thin medium). */
KFN float medium_stop_prob(vec3 pc, vec3 sigma_t, float dist)
{
    return pc.x * medium_absorbed1(sigma_t.x, dist) + pc.y * medium_absorbed1(sigma_t.y, dist) +
           pc.z * medium_absorbed1(sigma_t.z, dist);
}

/* The mixture probability of flying past a distance whose transmittance is tr. */
KFN float medium_pass_prob(vec3 pc, vec3 tr)
{
    return pc.x * tr.x + pc.y * tr.y + pc.z * tr.z;
}

/* The medium beyond a surface bounding media medium_in / medium_out (Material) for a
 * ray leaving along dir (geometric normal ng, outward): the boundary rule of pbrt-v4,
 * where the medium is what the last boundary crossed says. A surface whose two sides
 * are the same medium is no boundary, and the ray keeps the medium it had. */
KFN uint medium_beyond(uint medium_in, uint medium_out, uint current, vec3 dir, vec3 ng)
{
    if (medium_in == medium_out) return current;
    return v3_dot(dir, ng) < 0.0f ? medium_in : medium_out;
}

#endif /* CLPT_MEDIUM_H */
