/* env_dist.c — the environment map's sampling distribution (see env_dist.h). */
#include "scene/env_dist.h"

#include "light/envmap.h" /* env_guide_cells: the kernels' lookups must agree with these tables */

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Luminance of texel i (Rec. 709 weights, as v3_luminance), negative as 0. */
static double texel_luminance(const uint *texels, size_t i)
{
    float c[3];
    memcpy(c, texels + 3u * i, sizeof c);
    double y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    return y > 0.0 ? y : 0.0;
}

/* Writes the cdf of n weights (summing to `total` > 0) into out[0..n], in double and
 * then rounded: rounding is monotone, so the floats never decrease; the ends are
 * exactly 0 and 1. A zero total gives the uniform cdf. */
static void cdf_write(const double *w, size_t n, double total, float *out)
{
    double acc = 0.0;
    out[0] = 0.0f;
    for (size_t i = 0; i < n; i++) {
        acc += w[i];
        out[i + 1] = total > 0.0 ? (float)(acc / total) : (float)((double)(i + 1) / (double)n);
    }
    out[n] = 1.0f;
}

/* Writes the guide table of cdf[0..n] (kernels/light/envmap.h) into out[0..g): entry k the
 * last cell i < n with cdf[i] <= k / g, the cell env_cdf_find finds for u = k / g. */
static void guide_write(const float *cdf, size_t n, size_t g, float *out)
{
    size_t i = 0;
    for (size_t k = 0; k < g; k++) {
        float u = (float)k / (float)g; /* exact: g is a power of two */
        while (i + 1 < n && cdf[i + 1] <= u) i++;
        out[k] = (float)i;
    }
}

/* Writes one distribution of the W x H map into out (env_dist_floats(W, H) floats: the
 * cdfs, then their guides), the weight of a pixel its luminance less `level` (at least
 * 0) times sin(theta) at its row's centre, the solid angle of its pixels. row and
 * row_sum are scratch of W and H doubles. Returns the weights' total. */
static double dist_write(const uint *texels, size_t W, size_t H, double level, double *row, double *row_sum,
                         float *out)
{
    size_t cdfs = (H + 1) + H * (W + 1), guide_h = env_guide_cells((uint)H), guide_w = env_guide_cells((uint)W);
    double total = 0.0;
    for (size_t j = 0; j < H; j++) {
        double sin_t = sin(M_PI * ((double)j + 0.5) / (double)H);
        row_sum[j] = 0.0;
        for (size_t i = 0; i < W; i++) {
            double y = texel_luminance(texels, j * W + i) - level;
            row[i] = (y > 0.0 ? y : 0.0) * sin_t;
            row_sum[j] += row[i];
        }
        cdf_write(row, W, row_sum[j], out + (H + 1) + j * (W + 1));
        total += row_sum[j];
    }
    cdf_write(row_sum, H, total, out);
    guide_write(out, H, guide_h, out + cdfs);
    for (size_t j = 0; j < H; j++)
        guide_write(out + (H + 1) + j * (W + 1), W, guide_w, out + cdfs + guide_h + j * guide_w);
    return total;
}

size_t env_dist_floats(uint width, uint height)
{
    size_t W = width, H = height;
    return (H + 1) + H * (W + 1) + env_guide_cells(height) + H * env_guide_cells(width);
}

Status env_dist_build(const uint *texels, uint width, uint height, EnvDist *out, Error *err)
{
    memset(out, 0, sizeof *out);
    size_t W = width, H = height, one = env_dist_floats(width, height);
    double *row = malloc(W * sizeof *row), *row_sum = calloc(H, sizeof *row_sum);
    float *cdf = malloc(2 * one * sizeof *cdf);
    if (!row || !row_sum || !cdf) {
        free(row);
        free(row_sum);
        free(cdf);
        return error_set(err, ST_INTERNAL, "out of memory building the environment map's distribution");
    }
    double total = dist_write(texels, W, H, 0.0, row, row_sum, cdf);
    /* each pixel spans (2 pi / W) (pi / H) sin(theta) steradians of the 4 pi */
    double m = total * (2.0 * M_PI * M_PI / ((double)W * (double)H)) / (4.0 * M_PI);
    if (!(m > 0.0) || !isfinite(m)) {
        free(row);
        free(row_sum);
        free(cdf);
        return ST_OK;
    }
    /* The compensated distribution (env_dist.h): luminance less its mean over the sphere,
     * the sum of the weights above over that of sin(theta) alone, raised by a millionth
     * so that a constant map's pixels, which the mean's rounding may leave a few ulps
     * above it, are left out (no compensated distribution) rather than sampled by that
     * rounding alone. */
    double sin_sum = 0.0;
    for (size_t j = 0; j < H; j++) sin_sum += (double)W * sin(M_PI * ((double)j + 0.5) / (double)H);
    double level = total / sin_sum * (1.0 + 1e-6);
    double comp = one <= UINT32_MAX ? dist_write(texels, W, H, level, row, row_sum, cdf + one) : 0.0;
    free(row);
    free(row_sum);
    out->n = comp > 0.0 && isfinite(comp) ? 2 * one : one;
    if (out->n == one) {
        /* no compensated distribution: give its room back */
        float *shrunk = realloc(cdf, one * sizeof *cdf);
        if (shrunk) cdf = shrunk;
    }
    out->cdf = cdf;
    out->mis_offset = out->n > one ? one : 0;
    out->mean = m;
    return ST_OK;
}
