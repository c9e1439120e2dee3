/*
 * envmap.h — the environment map: an equirectangular (latitude-longitude) image of the
 * radiance arriving from every direction, seen by rays that escape the scene, and a
 * light that next-event estimation samples in proportion to its pixels' luminance x
 * sin(theta) (the piecewise-constant 2D distribution of pbrt-v3's InfiniteAreaLight
 * and Mitsuba 3's envmap, built on the host: host/scene/envmap.c).
 *
 * Orientation (Mitsuba 3's envmap, in the map's own frame): the first row is straight
 * up (+y), the last straight down; with phi = 2 pi u, theta = pi v (u from the left
 * edge, v from the top), a pixel's direction is
 *
 *     (sin(theta) sin(phi), cos(theta), -sin(theta) cos(phi))
 *
 * so u = 0 (the left and right edges) looks along -z, u = 1/4 along +x, u = 1/2 (the
 * centre column) along +z, u = 3/4 along -x. `rotate A` turns the map by A degrees
 * about +y, right-handed (+z toward +x): world = R_y(A) map.
 *
 * Lookups are nearest-texel, so what a ray sees is exactly the piecewise-constant
 * function the sampler's density follows (the distribution of a pixel's light is the
 * pixel itself, not a blend of its neighbours).
 *
 * The distribution (RenderParams.bg_light != NO_INDEX; scene buffer env_cdf), for a
 * W x H map: the marginal cdf over rows, H + 1 floats from 0 to 1, then per row j the
 * conditional cdf over its pixels, W + 1 floats at H + 1 + j (W + 1). A pixel's
 * probability is the product of the two cdf steps, its density in (u, v) that times
 * W H, and in solid angle that over 2 pi^2 sin(theta).
 *
 * After the cdfs come their guide tables (the "cutpoint method" of Chen and Asau, 1974):
 * for a cdf of n cells, G = env_guide_cells(n) entries, entry k the cell that holds
 * u = k / G (an integer, exact as a float). A sample u lies between the cells of entries
 * floor(u G) and floor(u G) + 1, and the search runs over those few cells instead of all
 * n: a binary search over a 1024-cell row touched a cache line and mispredicted a branch
 * at most of its ten steps, and the guides made scenes/envmap.scene 7-8% faster on both
 * devices. They find the same cell, so images did not change. The marginal's guide is
 * at H + 1 + H (W + 1), row j's G(H) + j G(W) floats after it.
 *
 * env_cdf holds a second distribution of that layout at RenderParams.env_mis_dist (0
 * when there is none): the map's luminance less its mean over the sphere, at least 0,
 * times sin(theta) (MIS compensation, host/scene/env_dist.h). Light samples that MIS
 * weighs against BSDF sampling draw from it (`mis` set below), and MIS reads their
 * density from it; light sampling alone keeps the map's own.
 * Valid C11 and OpenCL C 1.2.
 */
#ifndef CLPT_ENVMAP_H
#define CLPT_ENVMAP_H

#include "material/texture.h"

/* Direction d (any length) in the map's frame: the world turned back by the rotation. */
KFN vec3 env_to_map(GLOBAL const RenderParams *p, vec3 d)
{
    float c = p->bg_rot_cos, s = p->bg_rot_sin;
    return v3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}

/* The pixel (x, y) of a W x H map a direction falls in, and sin(theta) of the
 * direction. theta and sin(theta) come from the distance to the y axis, not from
 * cos(theta), which rounds to 1 within 3e-4 radians of the poles (a sample there would
 * get density 0). NaN and infinite components land in a valid pixel. */
KFN void env_pixel(GLOBAL const RenderParams *p, Texture tx, vec3 d, uint *x, uint *y, float *sin_theta)
{
    vec3 m = env_to_map(p, d);
    float r = k_sqrt(m.x * m.x + m.z * m.z), len = v3_len(m);
    float u = k_atan2(m.x, -m.z) * (1.0f / K_TWO_PI);
    if (u < 0.0f) u += 1.0f;
    float v = k_atan2(r, m.y) * K_INV_PI;
    *x = (uint)k_clamp(u * (float)tx.width, 0.0f, (float)tx.width - 1.0f);
    *y = (uint)k_clamp(v * (float)tx.height, 0.0f, (float)tx.height - 1.0f);
    *sin_theta = len > 0.0f ? r / len : 0.0f;
}

/* The map's pixel a direction falls in (env_pixel), with the map's texture. */
typedef struct {
    Texture tx;
    uint x, y;
    float sin_theta;
} EnvPixel;

KFN EnvPixel env_find(const SceneView *sc, vec3 d)
{
    EnvPixel e;
    e.tx = sc->textures[sc->params->bg_cubemap];
    env_pixel(sc->params, e.tx, d, &e.x, &e.y, &e.sin_theta);
    return e;
}

/* The radiance of pixel (x, y) of the map tx: its texel times the background colour. */
KFN vec3 env_texel_radiance(const SceneView *sc, Texture tx, uint x, uint y)
{
    return v3_mul(texel_fetch(sc, tx, x, y), sc->params->bg_color);
}

/* The radiance the map sends along -d toward the scene, from direction d. */
KFN vec3 env_radiance(const SceneView *sc, vec3 d)
{
    EnvPixel e = env_find(sc, d);
    return env_texel_radiance(sc, e.tx, e.x, e.y);
}

/* The distribution light samples draw from: with `mis` (the sample is weighted by MIS
 * against BSDF sampling) the compensated one where the map has it, else the map's own. */
KFN GLOBAL const float *env_dist(const SceneView *sc, int mis)
{
    return sc->env_cdf + (mis ? sc->params->env_mis_dist : 0u);
}

/* The solid-angle density with which env_sample picks a direction in pixel (x, y) of
 * the map from distribution `dist` (env_dist), sin_t its sin(theta) (env_pixel). */
KFN float env_pixel_pdf(GLOBAL const float *dist, Texture tx, uint x, uint y, float sin_t)
{
    if (!(sin_t > 0.0f)) return 0.0f;
    GLOBAL const float *marg = dist;
    GLOBAL const float *cond = marg + tx.height + 1u + y * (tx.width + 1u);
    float p_uv = (marg[y + 1u] - marg[y]) * (float)tx.height * ((cond[x + 1u] - cond[x]) * (float)tx.width);
    return p_uv / (2.0f * K_PI * K_PI * sin_t);
}

/* env_radiance of direction d and, in *pdf, the solid-angle density with which
 * env_sample(sc, mis, ...) picks d, its pixel found once (what the renderer asks for
 * both: two atan2 fewer than apart). */
KFN vec3 env_radiance_pdf(const SceneView *sc, vec3 d, int mis, float *pdf)
{
    EnvPixel e = env_find(sc, d);
    *pdf = env_pixel_pdf(env_dist(sc, mis), e.tx, e.x, e.y, e.sin_theta);
    return env_texel_radiance(sc, e.tx, e.x, e.y);
}

/* The density alone (light_pdf_env, for the tests' checks of the sampler). */
KFN float env_pdf(const SceneView *sc, vec3 d, int mis)
{
    float pdf;
    env_radiance_pdf(sc, d, mis, &pdf);
    return pdf;
}

/* The number of guide entries of a cdf of n cells: the largest power of two at most
 * n / 4 (at least 1), so that a search covers about four cells, usually one cache line,
 * and the guides add a quarter to the distribution. A power of two makes u * G exact, so
 * the entry below u is the same on every device and on the host that wrote it. */
KFN uint env_guide_cells(uint n)
{
    uint q = n >> 2;
    return q > 1u ? 1u << k_highest_bit(q) : 1u;
}

/* The cell i in [0, n) of cdf[0..n] (cdf[0] = 0, cdf[n] = 1) holding u in [0, 1): the
 * last i with cdf[i] <= u, which skips cells of zero probability; *frac receives u's
 * place within it, in [0, 1). `guide` is the cdf's guide table (above): the answer
 * lies between the entries around u. */
KFN uint env_cdf_find(GLOBAL const float *cdf, GLOBAL const float *guide, uint n, float u, float *frac)
{
    uint g = env_guide_cells(n);
    uint k = (uint)k_clamp(u * (float)g, 0.0f, (float)(g - 1u));
    uint lo = (uint)guide[k], hi = k + 1u < g ? (uint)guide[k + 1u] : n - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) >> 1;
        if (cdf[mid] <= u) lo = mid; else hi = mid - 1u;
    }
    float step = cdf[lo + 1u] - cdf[lo];
    *frac = step > 0.0f ? k_clamp((u - cdf[lo]) / step, 0.0f, 0.99999994f) : 0.5f;
    return lo;
}

/* A direction drawn from the map's distribution (env_dist(sc, mis)) with (u1, u2) in
 * [0, 1)^2: a row by the marginal cdf, a pixel in it by the row's cdf, a uniform point
 * in the pixel's (u, v) rectangle. Returns the unit direction in the world, and in *Le and *pdf the
 * radiance of the pixel drawn and the solid-angle density of the point, from the pixel
 * and sin(theta) the sample already has, as pbrt-v4's image light. Finding them again
 * from the direction cost two atan2, and where rounding put a direction just across its
 * pixel's edge it paired the neighbour's radiance with this pixel's probability. */
KFN vec3 env_sample(const SceneView *sc, int mis, float u1, float u2, vec3 *Le, float *pdf)
{
    GLOBAL const RenderParams *p = sc->params;
    Texture tx = sc->textures[p->bg_cubemap];
    uint W = tx.width, H = tx.height;
    GLOBAL const float *marg = env_dist(sc, mis), *marg_guide = marg + (H + 1u) + H * (W + 1u);
    float fy, fx;
    uint y = env_cdf_find(marg, marg_guide, H, u1, &fy);
    uint x = env_cdf_find(marg + (H + 1u) + y * (W + 1u), marg_guide + env_guide_cells(H) + y * env_guide_cells(W), W,
                          u2, &fx);
    float u = ((float)x + fx) / (float)W, v = ((float)y + fy) / (float)H;
    float st, ct, sp, cp;
    k_sincos(K_PI * v, &st, &ct);
    k_sincos(K_TWO_PI * u, &sp, &cp);
    *pdf = env_pixel_pdf(marg, tx, x, y, st);
    *Le = env_texel_radiance(sc, tx, x, y);
    vec3 m = v3(st * sp, ct, -st * cp);
    float c = p->bg_rot_cos, s = p->bg_rot_sin;
    return v3(c * m.x + s * m.z, m.y, c * m.z - s * m.x);
}

#endif /* CLPT_ENVMAP_H */
