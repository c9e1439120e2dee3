/*
 * film.h — the host's image accumulator: per pixel and channel, the sum of every sample's
 * radiance in 64-bit fixed point (units of 2^-FILM_FRAC_BITS, see kernels/film/film.h), and
 * the number of samples every pixel has received. Integer sums make the result
 * independent of the order in which devices and batches are added.
 */
#ifndef CLPT_FILM_H
#define CLPT_FILM_H

#include <stdint.h>

#include "base/status.h"
#include "io/image_write.h"
#include "types.h"

typedef struct {
    uint width, height;
    int64_t *sum;          /* width * height * 3 */
    uint64_t samples;      /* samples per pixel added so far (whole-image batches) */
} Film;

Status film_init(Film *f, uint width, uint height, Error *err);
void film_free(Film *f);
/* Average linear radiance per pixel, top row first, into rgb (width * height * 3). With
 * no samples yet the image is black. */
void film_resolve(const Film *f, float *rgb);
/* The resolved image written to path (atomically, see image_write_styled): the one way
 * a film becomes a file, for the render's output, its progressive rewrites and merge. */
Status film_write(const Film *f, const char *path, const ImageStyle *style, Error *err);

#endif /* CLPT_FILM_H */
