/*
 * film.h — where a finished path's radiance lands: added to its pixel as 64-bit fixed
 * point. Integer addition is associative, so the image is the same bits whatever the
 * grouping of samples into batches, devices and threads (see docs/design.md).
 */
#ifndef CLPT_FILM_H
#define CLPT_FILM_H

#include "types.h"

/* One sample's radiance in film units (2^-FILM_FRAC_BITS). NaN, negative and infinite
 * values are dropped or clamped here, so a single bad sample cannot poison a pixel. */
KFN kint64 film_fixed(float v)
{
    if (!(v > 0.0f)) return (kint64)0;
    v = k_fmin(v, FILM_MAX_SAMPLE);
    return (kint64)(v * (float)(1u << FILM_FRAC_BITS) + 0.5f);
}

KFN void film_add(GLOBAL kint64 *film, uint pixel, vec3 radiance)
{
    film[3u * pixel + 0u] += film_fixed(radiance.x);
    film[3u * pixel + 1u] += film_fixed(radiance.y);
    film[3u * pixel + 2u] += film_fixed(radiance.z);
}

#endif /* CLPT_FILM_H */
