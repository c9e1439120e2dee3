/*
 * rng.h — the sample values of a path: counter-based, a pure function of (seed, pixel,
 * sample index, bounce, dimension). Nothing depends on which device, thread or batch
 * computes a value, or in which order, so a render is the same image on any device mix,
 * batch size or resume.
 *
 * Two samplers (RenderParams.sampler, --sampler):
 *
 * SAMPLER_SOBOL (the default): Owen-scrambled Sobol points, padded in 2D, after Burley,
 * "Practical Hash-based Owen Scrambling" (JCGT 9(4), 2020) and pbrt-v4's
 * PaddedSobolSampler. Each 2D pair of dimensions of a bounce (pixel jitter, lens, light
 * position, BSDF direction; see RNG_PAIR_SECOND) is the first two dimensions of the
 * Sobol sequence, a (0,2)-sequence: over the first 2^m samples of a pixel, every
 * elementary interval of area 2^-m holds exactly one point. Each 1D dimension (light
 * pick, lobe choice, roulette) is the first Sobol dimension (van der Corput). Pairs are
 * decorrelated from each other and pixels from pixels by hashing (pixel key, bounce,
 * dimension) into the seeds of an Owen scrambling of the values and a nested uniform
 * scrambling of the sample index (Burley's shuffle), both of which keep those
 * stratification properties. Only Sobol dimensions 0 and 1 are used, so there is no
 * direction-number table: dimension 0 is the bit-reversed index and dimension 1 (the
 * Pascal matrix mod 2) is computed in closed form, rng_sobol1.
 *
 * SAMPLER_INDEPENDENT: independent hashed values, the sampler of clpt before Sobol
 * (the same bits, so earlier images are reproduced): Chris Wellons' "lowbias32" integer
 * mixer (bias 0.17, hash-prospector) chained over the key's parts.
 */
#ifndef CLPT_RNG_H
#define CLPT_RNG_H

#include "types.h"

/* Dimensions used at each bounce; a bounce has RNG_DIMS_PER_BOUNCE of them. */
enum RngDim {
    DIM_PIXEL_X = 0, DIM_PIXEL_Y, DIM_LENS_U, DIM_LENS_V,   /* camera ray (bounce 0) */
    DIM_LIGHT_PICK, DIM_LIGHT_U, DIM_LIGHT_V,               /* next-event estimation (the
                                                             * Sobol sampler picks by
                                                             * DIM_LIGHT_U, shade_path.h) */
    DIM_BSDF_LOBE, DIM_BSDF_U, DIM_BSDF_V, DIM_BSDF_W,      /* scattering */
    DIM_ROULETTE,                                            /* Russian roulette */
    DIM_MEDIUM,                                              /* a medium's channel and
                                                             * free-flight distance
                                                             * (kernels/medium/) */
    DIM_TIME,                                                /* the path's time in the
                                                             * shutter (bounce 0; only
                                                             * scenes that move draw it) */
    RNG_DIMS_PER_BOUNCE = 16
};

/* The second dimension of each 2D pair: the Sobol sampler draws it as Sobol dimension 1
 * of the pattern of the dimension before it, which a 2D warp then sees as one
 * stratified point. Every other dimension is 1D. A new 2D pair is two consecutive
 * enum values with the second added here (all dimensions stay below 32). */
#define RNG_PAIR_SECOND ((1u << DIM_PIXEL_Y) | (1u << DIM_LENS_V) | (1u << DIM_LIGHT_V) | (1u << DIM_BSDF_V))

/* What a path's random numbers are made from: rng_key_make at the camera ray, or
 * rng_key_of from the path state at a later bounce. */
typedef struct {
    uint key;        /* independent: hash of (seed, pixel, sample); sobol: of (seed, pixel) */
    uint sample;     /* sample index within the pixel */
    uint sampler;    /* enum Sampler */
    uint sample_rev; /* sobol: the sample index bit-reversed (rng_key_make, rng_key_of),
                      * which every pattern's shuffle starts from; else 0 */
} RngKey;

/* With first-hit splitting (RenderParams.split = B), the B continuations of camera
 * sample s share its camera ray, whose dimensions raygen_path draws with the key of s
 * (rng_key_make), and part at the first hit: shading draws with rng_key_of, whose index
 * is s B + branch. Over a pixel's samples those indices run through a Sobol pattern's
 * first points in order, so each continuation's dimensions are stratified as B times
 * the samples would be. With B = 1 the index is s, as it always was. */

/* RenderParams.split as a count: 0 (a block filled by hand) means none, as 1 does. */
KFN uint params_split(GLOBAL const RenderParams *p)
{
    return p->split > 1u ? p->split : 1u;
}

/* The integer steps of the sampler, written once for a uint and for the uint8 lanes of
 * kernels/integrator/shade_lanes.h, which must compute the same bits. Each updates its variable. */
#define RNG_HASH_STEPS(x) (x ^= x >> 16, x *= 0x21f0aaadu, x ^= x >> 15, x *= 0x735a2d97u, x ^= x >> 15)
#define RNG_SWAP_BYTES_STEPS(x) (x = (x << 16) | (x >> 16), x = ((x & 0x00ff00ffu) << 8) | ((x >> 8) & 0x00ff00ffu))
#define RNG_REVERSE_IN_BYTES_STEPS(x)                                                    \
    (x = ((x & 0x0f0f0f0fu) << 4) | ((x >> 4) & 0x0f0f0f0fu),                           \
     x = ((x & 0x33333333u) << 2) | ((x >> 2) & 0x33333333u),                           \
     x = ((x & 0x55555555u) << 1) | ((x >> 1) & 0x55555555u))
#define RNG_LK_PERMUTE_STEPS(x, seed)                                                    \
    (x ^= x * 0x3d20adeau, x += seed, x *= (seed >> 16) | 1u, x ^= x * 0x05526c56u, x ^= x * 0x53a22864u)
#define RNG_SOBOL1_STEPS(i)                                                              \
    (i ^= (i >> 1) & 0x55555555u, i ^= (i >> 2) & 0x33333333u, i ^= (i >> 4) & 0x0f0f0f0fu, \
     i ^= (i >> 8) & 0x00ff00ffu, i ^= (i >> 16) & 0x0000ffffu)
/* a pattern's seed: pixel key + pattern number times the golden ratio (rng_sobol_pattern),
 * and the odd multipliers and offset that make each coordinate's scrambling seed from it
 * (rng_sobol_coord) */
#define RNG_PATTERN_STEP 0x9e3779b9u
#define RNG_COORD0_SEED_MUL 0x297a2d39u
#define RNG_COORD1_SEED_MUL 0x2c1b3c6du
#define RNG_COORD_SEED_ADD 0x68e31da4u
/* 2^-24: the top 24 bits of a 32-bit fixed-point value as a float in [0, 1) */
#define RNG_FLOAT_SCALE 5.9604645e-8f

KFN uint rng_hash(uint x)
{
    RNG_HASH_STEPS(x);
    return x;
}

/* The per-pixel part of the key. */
KFN uint rng_pixel_key(uint seed, uint pixel)
{
    return rng_hash(rng_hash(seed ^ 0x9e3779b9u) ^ pixel);
}

/* The per-path key of the independent sampler. */
KFN uint rng_path_key(uint seed, uint pixel, uint sample)
{
    return rng_hash(rng_pixel_key(seed, pixel) + sample);
}

/* The bits of x in reverse order. The byte order is reversed by one instruction where
 * the compiler has it (clang, and gcc for the C build: bswap on x86; OpenCL compilers
 * of other families are not promised the builtin), then the bits within each byte by
 * three mask-and-shift steps. The sampler reverses bits about ten times a bounce. */
KFN uint rng_reverse_bits(uint x)
{
#if defined(__clang__) || (!defined(KERNEL_OPENCL) && defined(__GNUC__))
    x = __builtin_bswap32(x);
#else
    RNG_SWAP_BYTES_STEPS(x);
#endif
    RNG_REVERSE_IN_BYTES_STEPS(x);
    return x;
}

/* A random permutation of 32-bit words, chosen by seed, in which each bit is flipped
 * depending only on the bits below it: applied to bit-reversed values it is an Owen
 * scrambling. Nathan Vegdahl's improvement of the Laine-Karras hash, as pbrt-v4's
 * FastOwenScrambler. */
KFN uint rng_lk_permute(uint x, uint seed)
{
    RNG_LK_PERMUTE_STEPS(x, seed);
    return x;
}

/* Owen scrambling of a 32-bit fixed-point value in [0, 1). */
KFN uint rng_owen_scramble(uint v, uint seed)
{
    return rng_reverse_bits(rng_lk_permute(rng_reverse_bits(v), seed));
}

/* Sobol dimension 1 of point `index`, as 32-bit fixed point, before bit reversal: its
 * generator matrix is Pascal's triangle mod 2, so (Lucas) output digit j is the parity
 * of the index bits at positions k that contain j as a bit mask; five butterfly steps
 * of that superset sum give every digit at once, digit j at bit j. */
KFN uint rng_sobol1_reversed(uint index)
{
    RNG_SOBOL1_STEPS(index);
    return index;
}

/* Unscrambled Sobol point `index` in dimension 0 (van der Corput) or 1, as 32-bit
 * fixed point (value / 2^32). */
KFN uint rng_sobol(uint index, uint dim)
{
    return rng_reverse_bits(dim ? rng_sobol1_reversed(index) : index);
}

/* The seed of the shuffled, scrambled 2D pattern that dimension `first` (a 1D
 * dimension, or the first of a pair) of a bounce draws from: one hash of the pixel key
 * offset by the pattern's number times the golden ratio (the pixel keys are hashes
 * already, and this is the hot path of every sample). */
KFN uint rng_sobol_pattern(uint pixel_key, uint bounce, uint first)
{
    return rng_hash(pixel_key + (bounce * (uint)RNG_DIMS_PER_BOUNCE + first) * RNG_PATTERN_STEP);
}

/* The key of sample `sample` of `pixel` under the render's sampler. */
KFN RngKey rng_key_make(GLOBAL const RenderParams *p, uint pixel, uint sample)
{
    RngKey k;
    k.sampler = p->sampler;
    k.sample = sample;
    k.key = k.sampler == SAMPLER_SOBOL ? rng_pixel_key(p->seed, pixel) : rng_path_key(p->seed, pixel, sample);
    k.sample_rev = k.sampler == SAMPLER_SOBOL ? rng_reverse_bits(sample) : 0u;
    return k;
}

/* The key of a path born by raygen_path (which stored key.key in rng_key). */
KFN RngKey rng_key_of(GLOBAL const PathState *ps, GLOBAL const RenderParams *p)
{
    RngKey k;
    k.sampler = p->sampler;
    k.sample = ps->sample * params_split(p) + ps->branch;
    /* independent values: a key per continuation, the camera sample's for the first */
    k.key = k.sampler == SAMPLER_SOBOL || ps->branch == 0u ? ps->rng_key
                                                          : rng_hash(ps->rng_key ^ (ps->branch * RNG_PATTERN_STEP));
    k.sample_rev = k.sampler == SAMPLER_SOBOL ? rng_reverse_bits(k.sample) : 0u;
    return k;
}

/* The sample index after the pattern's shuffle: rng_owen_scramble(sample, pattern)
 * from the key's reversed index (one reversal fewer per pattern). */
KFN uint rng_sobol_index(RngKey k, uint pattern)
{
    return rng_reverse_bits(rng_lk_permute(k.sample_rev, pattern));
}

/* Coordinate `coord` (0 or 1) of the pattern's point `index` (the sample index after
 * the pattern's shuffle), 32-bit fixed point. The values' scrambling seeds are other odd
 * multiples of the pattern seed (bijections, so as uniform over pixels as it; they
 * scramble values, not the index). rng_owen_scramble of rng_sobol, with the two bit
 * reversals that cancel left out. */
KFN uint rng_sobol_coord(uint index, uint pattern, uint coord)
{
    uint digits = coord ? rng_sobol1_reversed(index) : index;
    return rng_reverse_bits(
        rng_lk_permute(digits, pattern * (coord ? RNG_COORD1_SEED_MUL : RNG_COORD0_SEED_MUL) + RNG_COORD_SEED_ADD));
}

/* The Sobol sampler's value for (key, bounce, dim), 32-bit fixed point: coordinate
 * `coord` of the shuffled, scrambled 2D pattern the dimension belongs to. */
KFN uint rng_sobol_bits(RngKey k, uint bounce, uint dim)
{
    uint coord = (RNG_PAIR_SECOND >> dim) & 1u;
    uint pattern = rng_sobol_pattern(k.key, bounce, dim - coord);
    return rng_sobol_coord(rng_sobol_index(k, pattern), pattern, coord);
}

/* 32-bit fixed point to a uniform float in [0, 1): the top 24 bits, so 1.0f is never
 * returned. */
KFN float rng_to_float(uint h)
{
    return (float)(h >> 8) * RNG_FLOAT_SCALE;
}

KFN_INLINE_CL float rng_uniform(RngKey k, uint bounce, uint dim)
{
    uint h = k.sampler == SAMPLER_SOBOL
                 ? rng_sobol_bits(k, bounce, dim)
                 : rng_hash(k.key ^ rng_hash(bounce * (uint)RNG_DIMS_PER_BOUNCE + dim + 0x632be5abu));
    return rng_to_float(h);
}

/* rng_uniform of both dimensions of a 2D pair, `first` and first + 1, the same bits: the
 * Sobol sampler computes the pair's pattern seed and shuffled index once for the two,
 * which takes a third off what a pair costs (the sampler was 12-18% of a render).
 * Always inlined: PoCL left it a call that saved five registers and realigned the
 * stack each time, 8.5% of the McGuire Cornell box's samples; inlined, that box
 * renders 3% faster on PoCL and 5% on the scalar device. */
KFN_INLINE void rng_uniform2(RngKey k, uint bounce, uint first, float *u, float *v)
{
    if (k.sampler != SAMPLER_SOBOL) {
        *u = rng_uniform(k, bounce, first);
        *v = rng_uniform(k, bounce, first + 1u);
        return;
    }
    uint pattern = rng_sobol_pattern(k.key, bounce, first);
    uint index = rng_sobol_index(k, pattern);
    *u = rng_to_float(rng_sobol_coord(index, pattern, 0u));
    *v = rng_to_float(rng_sobol_coord(index, pattern, 1u));
}

#endif /* CLPT_RNG_H */
