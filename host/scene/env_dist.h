/*
 * env_dist.h — the environment map's sampling distributions (kernels/light/envmap.h reads
 * them): piecewise-constant 2D distributions over the map's pixels, each a marginal cdf
 * over rows and a conditional cdf per row, proportional to luminance x sin(theta) and
 * to its MIS-compensated form (below).
 */
#ifndef CLPT_ENV_DIST_H
#define CLPT_ENV_DIST_H

#include <stddef.h>

#include "base/status.h"
#include "types.h"

/* A map's distributions, as the scene keeps them and the kernels read them: the map's
 * own (luminance x sin(theta)) at 0, and at mis_offset the compensated one, which
 * next-event estimation draws from when MIS weighs its samples against BSDF sampling:
 * luminance less its mean over the sphere (at least 0) x sin(theta). Karlik, Sik,
 * Vevoda, Skrivan and Krivanek, "MIS Compensation: Optimizing Sampling Techniques in
 * Multiple Importance Sampling" (SIGGRAPH Asia 2019), and pbrt-v4's image infinite
 * light: where a map is near its mean, BSDF sampling finds its light well, and light
 * sampling spent there only dilutes its samples of the bright parts. BSDF sampling
 * covers every direction the compensated distribution leaves out, so the MIS sum stays
 * unbiased; light sampling weighted alone (RenderParams.mis_mode's light-only switch,
 * which the tests set) keeps the full one. A map at its mean everywhere (a constant one) has no compensated
 * distribution: mis_offset is 0, the full one serves both. */
typedef struct {
    float *cdf;         /* n floats (free with free); NULL for a black map: no light */
    size_t n;           /* env_dist_floats(W, H) for one distribution, twice that for two */
    size_t mis_offset;  /* where the compensated distribution starts, or 0 */
    double mean;        /* the map's mean luminance over the sphere (solid-angle
                         * weighted, unscaled), 0 for a black map */
} EnvDist;

/* The floats of one distribution of a W x H map in the layout of kernels/light/envmap.h:
 * (H + 1) + H (W + 1) of cdfs, then G(H) + H G(W) of guides (G = env_guide_cells). */
size_t env_dist_floats(uint width, uint height);

/* Builds the distributions of a W x H float map (3 floats a texel, as the texels buffer
 * holds them) into *out. Negative luminance counts as 0. Fails only when memory runs
 * out (ST_INTERNAL). */
Status env_dist_build(const uint *texels, uint width, uint height, EnvDist *out, Error *err);

#endif /* CLPT_ENV_DIST_H */
