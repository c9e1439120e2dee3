/*
 * env_dist.h — the environment map's sampling distribution (kernels/light/envmap.h reads
 * it): a piecewise-constant 2D distribution over the map's pixels proportional to
 * luminance x sin(theta), as a marginal cdf over rows and a conditional cdf per row.
 */
#ifndef CLPT_ENV_DIST_H
#define CLPT_ENV_DIST_H

#include <stddef.h>

#include "base/status.h"
#include "types.h"

/* Builds the cdfs of a W x H float map (3 floats a texel, as the texels buffer holds
 * them) and their guide tables in the layout of kernels/light/envmap.h: (H + 1) + H (W + 1)
 * floats of cdfs, then G(H) + H G(W) of guides (G = env_guide_cells), in *cdf (freed
 * with free), the count in *n. *mean receives the map's mean luminance over the
 * sphere (solid-angle weighted, unscaled), 0 for a black map, which then has no cdf
 * (*cdf NULL, *n 0): no light to sample. Negative luminance counts as 0. Fails only
 * when memory runs out (ST_INTERNAL). */
Status env_dist_build(const uint *texels, uint width, uint height, float **cdf, size_t *n, double *mean, Error *err);

#endif /* CLPT_ENV_DIST_H */
