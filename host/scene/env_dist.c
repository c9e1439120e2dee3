/* env_dist.c — the environment map's sampling distribution (see env_dist.h). */
#include "scene/env_dist.h"

#include "light/envmap.h" /* env_guide_cells: the kernels' lookups must agree with these tables */

#include <math.h>
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

Status env_dist_build(const uint *texels, uint width, uint height, float **cdf, size_t *n, double *mean, Error *err)
{
    *cdf = NULL;
    *n = 0;
    *mean = 0.0;
    size_t W = width, H = height, cdfs = (H + 1) + H * (W + 1);
    size_t guide_h = env_guide_cells(height), guide_w = env_guide_cells(width);
    size_t count = cdfs + guide_h + H * guide_w;
    double *row = malloc(W * sizeof *row), *row_sum = calloc(H, sizeof *row_sum);
    float *out = malloc(count * sizeof *out);
    if (!row || !row_sum || !out) {
        free(row);
        free(row_sum);
        free(out);
        return error_set(err, ST_INTERNAL, "out of memory building the environment map's distribution");
    }
    double total = 0.0;
    for (size_t j = 0; j < H; j++) {
        /* sin(theta) at the row's centre: the solid angle of its pixels */
        double sin_t = sin(M_PI * ((double)j + 0.5) / (double)H);
        row_sum[j] = 0.0;
        for (size_t i = 0; i < W; i++) {
            row[i] = texel_luminance(texels, j * W + i) * sin_t;
            row_sum[j] += row[i];
        }
        cdf_write(row, W, row_sum[j], out + (H + 1) + j * (W + 1));
        total += row_sum[j];
    }
    cdf_write(row_sum, H, total, out);
    guide_write(out, H, guide_h, out + cdfs);
    for (size_t j = 0; j < H; j++)
        guide_write(out + (H + 1) + j * (W + 1), W, guide_w, out + cdfs + guide_h + j * guide_w);
    free(row);
    free(row_sum);
    /* each pixel spans (2 pi / W) (pi / H) sin(theta) steradians of the 4 pi */
    double m = total * (2.0 * M_PI * M_PI / ((double)W * (double)H)) / (4.0 * M_PI);
    if (!(m > 0.0) || !isfinite(m)) {
        free(out);
        return ST_OK;
    }
    *cdf = out;
    *n = count;
    *mean = m;
    return ST_OK;
}
