/* film.c — the host's fixed-point accumulator and its conversion to radiance. */
#include "render/film.h"

#include "base/fault.h"

#include <stdlib.h>
#include <string.h>

Status film_init(Film *f, uint width, uint height, Error *err)
{
    memset(f, 0, sizeof *f);
    if (!fault_alloc_fails("film")) f->sum = calloc((size_t)width * height * 3u, sizeof *f->sum);
    if (!f->sum)
        return error_set(err, ST_INTERNAL, "out of memory for a %ux%u film", width, height);
    f->width = width;
    f->height = height;
    return ST_OK;
}

void film_free(Film *f)
{
    free(f->sum);
    memset(f, 0, sizeof *f);
}

void film_resolve(const Film *f, float *rgb)
{
    size_t n = (size_t)f->width * f->height * 3u;
    /* in double: a pixel's sum can exceed float's 24-bit mantissa by far */
    double scale = f->samples ? 1.0 / ((double)(1u << FILM_FRAC_BITS) * (double)f->samples) : 0.0;
    for (size_t i = 0; i < n; i++) rgb[i] = (float)((double)f->sum[i] * scale);
}

Status film_write(const Film *f, const char *path, const ImageStyle *style, Error *err)
{
    size_t n = (size_t)f->width * f->height * 3u;
    float *rgb = malloc(n * sizeof *rgb);
    if (!rgb) return error_set(err, ST_INTERNAL, "out of memory resolving the image");
    film_resolve(f, rgb);
    Status st = image_write_styled(path, rgb, f->width, f->height, style, err);
    free(rgb);
    return st;
}
