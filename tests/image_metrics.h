/*
 * image_metrics.h — how far an image is from a reference: RMSE over the linear values,
 * and SSIM (Wang et al. 2004, "Image quality assessment: from error visibility to
 * structural similarity") of the luminance. Used by tests/test_denoise.c and
 * bench/bench_denoise.c, with a reader of the PFM files clpt writes.
 */
#ifndef CLPT_IMAGE_METRICS_H
#define CLPT_IMAGE_METRICS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A PFM colour image (clpt's: "PF", little-endian, bottom row first) as RGB floats, top
 * row first; NULL when it cannot be read. */
static inline float *metrics_read_pfm(const char *path, unsigned *w, unsigned *h)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char magic[3] = { 0 };
    double scale = 0.0;
    float *rgb = NULL;
    if (fscanf(f, "%2s %u %u %lf", magic, w, h, &scale) == 4 && !strcmp(magic, "PF") && scale < 0.0 &&
        fgetc(f) == '\n' && *w > 0 && *h > 0 && *w <= 16384 && *h <= 16384) {
        size_t row = (size_t)*w * 3u;
        rgb = malloc(row * *h * sizeof *rgb);
        for (unsigned y = 0; rgb && y < *h; y++)
            if (fread(rgb + (size_t)(*h - 1u - y) * row, sizeof *rgb, row, f) != row) {
                free(rgb);
                rgb = NULL;
            }
    }
    fclose(f);
    return rgb;
}

/* Root mean square difference over every channel of n pixels. */
static inline double metrics_rmse(const float *a, const float *b, size_t n)
{
    double sum = 0.0;
    for (size_t i = 0; i < n * 3u; i++) {
        double d = (double)a[i] - (double)b[i];
        sum += d * d;
    }
    return sqrt(sum / (double)(n * 3u));
}

/* The pixels away from the emitters seen directly: mask[i] = 0 within `radius` pixels of
 * a reference pixel brighter than `bright` in some channel (a lamp and its edge), else
 * 1. A denoiser spreads a lamp's edge over a few pixels, and those few pixels, with
 * values of 10 and more, outweigh the whole rest of an image's squared error; the
 * error of the rest is measured apart (docs/denoise.md). */
static inline void metrics_emitter_mask(const float *ref, unsigned w, unsigned h, float bright, int radius,
                                        unsigned char *mask)
{
    memset(mask, 1, (size_t)w * h);
    for (unsigned y = 0; y < h; y++)
        for (unsigned x = 0; x < w; x++) {
            const float *p = ref + ((size_t)y * w + x) * 3u;
            if (!(p[0] > bright || p[1] > bright || p[2] > bright)) continue;
            for (int dy = -radius; dy <= radius; dy++)
                for (int dx = -radius; dx <= radius; dx++) {
                    long yy = (long)y + dy, xx = (long)x + dx;
                    if (yy >= 0 && yy < (long)h && xx >= 0 && xx < (long)w) mask[(size_t)yy * w + (size_t)xx] = 0;
                }
        }
}

/* metrics_rmse over the pixels whose mask is 1. */
static inline double metrics_rmse_masked(const float *a, const float *b, const unsigned char *mask, size_t n)
{
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < n; i++) {
        if (!mask[i]) continue;
        for (int c = 0; c < 3; c++) {
            double d = (double)a[3 * i + c] - (double)b[3 * i + c];
            sum += d * d;
        }
        count += 3;
    }
    return count ? sqrt(sum / (double)count) : 0.0;
}

/* Whether every value of n pixels is a finite number. */
static inline int metrics_all_finite(const float *a, size_t n)
{
    for (size_t i = 0; i < n * 3u; i++)
        if (!isfinite(a[i])) return 0;
    return 1;
}

/* Luminance (Rec. 709 weights) of the colour clamped to [0, 1]: SSIM's constants assume
 * a known range, and on a display that is it. */
static inline double metrics_luma(const float *p)
{
    double c[3];
    for (int k = 0; k < 3; k++) c[k] = p[k] > 0.0f ? (p[k] < 1.0f ? p[k] : 1.0) : 0.0;
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

/* Mean SSIM over 8x8 windows, 4 pixels apart (range 1: C1 = 0.01^2, C2 = 0.03^2). 1 is
 * identical; noise lowers it. */
static inline double metrics_ssim(const float *a, const float *b, unsigned w, unsigned h)
{
    const double c1 = 0.0001, c2 = 0.0009;
    double total = 0.0;
    size_t windows = 0;
    for (unsigned y0 = 0; y0 + 8 <= h; y0 += 4)
        for (unsigned x0 = 0; x0 + 8 <= w; x0 += 4) {
            double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
            for (unsigned y = y0; y < y0 + 8; y++)
                for (unsigned x = x0; x < x0 + 8; x++) {
                    size_t i = ((size_t)y * w + x) * 3u;
                    double la = metrics_luma(a + i), lb = metrics_luma(b + i);
                    sa += la, sb += lb, saa += la * la, sbb += lb * lb, sab += la * lb;
                }
            double ma = sa / 64, mb = sb / 64;
            double va = saa / 64 - ma * ma, vb = sbb / 64 - mb * mb, cov = sab / 64 - ma * mb;
            total += (2 * ma * mb + c1) * (2 * cov + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            windows++;
        }
    return windows ? total / (double)windows : 1.0;
}

#endif /* CLPT_IMAGE_METRICS_H */
