/*
 * rng.h — counter-based random numbers.
 *
 * A random number is a pure function of (seed, pixel, sample index, bounce, dimension):
 * nothing depends on which device, thread or batch computes it, or in which order, so a
 * render is the same image on any device mix. The hash is Chris Wellons' "lowbias32"
 * integer mixer (bias 0.17, hash-prospector), chained over the key's parts.
 */
#ifndef CLPT_RNG_H
#define CLPT_RNG_H

#include "types.h"

/* Dimensions used at each bounce; a bounce has RNG_DIMS_PER_BOUNCE of them. */
enum RngDim {
    DIM_PIXEL_X = 0, DIM_PIXEL_Y, DIM_LENS_U, DIM_LENS_V,   /* camera ray (bounce 0) */
    DIM_LIGHT_PICK, DIM_LIGHT_U, DIM_LIGHT_V,               /* next-event estimation */
    DIM_BSDF_LOBE, DIM_BSDF_U, DIM_BSDF_V, DIM_BSDF_W,      /* scattering */
    DIM_ROULETTE,                                            /* Russian roulette */
    RNG_DIMS_PER_BOUNCE = 16
};

KFN uint rng_hash(uint x)
{
    x ^= x >> 16;
    x *= 0x21f0aaadu;
    x ^= x >> 15;
    x *= 0x735a2d97u;
    x ^= x >> 15;
    return x;
}

/* The per-path part of the key, computed once when the camera ray is born. */
KFN uint rng_path_key(uint seed, uint pixel, uint sample)
{
    return rng_hash(rng_hash(rng_hash(seed ^ 0x9e3779b9u) ^ pixel) + sample);
}

/* Uniform float in [0, 1): 24 random bits, so 1.0f is never returned. */
KFN float rng_uniform(uint path_key, uint bounce, uint dim)
{
    uint h = rng_hash(path_key ^ rng_hash(bounce * (uint)RNG_DIMS_PER_BOUNCE + dim + 0x632be5abu));
    return (float)(h >> 8) * 5.9604645e-8f;
}

#endif /* CLPT_RNG_H */
