/*
 * noise.h — Perlin's gradient noise (K. Perlin, "Improving noise", SIGGRAPH 2002: the
 * quintic fade 6t^5 - 15t^4 + 10t^3 and his permutation of 0..255), with the gradient
 * choice and the finite-difference derivative of pbrt-v4 (Pharr, Jakob, Humphreys,
 * "Physically Based Rendering", 4th ed., sec. 10.6.1), so that a pbrt-v4 "cloud"
 * medium baked by clpt has pbrt's density (docs/media.md#clouds).
 */
#ifndef CLPT_NOISE_H
#define CLPT_NOISE_H

/* Noise in [-1, 1] (about), 0 at every integer lattice point; period 256 an axis. */
float noise3(float x, float y, float z);

/* pbrt-v4's DNoise: the forward difference (step 0.01) of noise3 along each axis. */
void noise3_gradient(float x, float y, float z, float out[3]);

#endif /* CLPT_NOISE_H */
