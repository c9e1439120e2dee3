/*
 * octa_env.h — pbrt-v4's environment maps (ImageInfiniteLight) made clpt's: a square
 * image in the equal-area octahedral parameterisation (Clarberg, "Fast Equal-Area
 * Mapping of the (Hemi)Sphere using SIMD", JGT 2008; pbrt-v4's EqualAreaSquareToSphere
 * and EqualAreaSphereToSquare) resampled into an equirectangular float map in
 * kernels/light/envmap.h's orientation, which then becomes the background by
 * scene_set_envmap (importance-sampled, MIS-weighted, as a `background { map ... }`).
 *
 * The square: (u, v) in [0, 1]^2, u along the image's columns, v down its rows (pbrt's
 * image (x, y) with y = 0 the first row); the centre is +z, the corners -z, the
 * diamond between the edges' midpoints z = 0. Every texel covers the same solid angle.
 */
#ifndef CLPT_OCTA_ENV_H
#define CLPT_OCTA_ENV_H

#include "base/status.h"
#include "scene/scene.h"

/* The heights of the resampled map (its width is twice that): N rows for an N x N
 * square, at least OCTA_ENV_MIN_HEIGHT (small squares still get sharp diamonds' edges)
 * and at most OCTA_ENV_MAX_HEIGHT (a 2048 x 4096 float map is 96 MB). */
#define OCTA_ENV_MIN_HEIGHT 64u
#define OCTA_ENV_MAX_HEIGHT 2048u

/* The unit direction of square point (u, v) (each in [0, 1]). */
void octa_square_to_sphere(double u, double v, double d[3]);
/* The square point of direction d (unit length): octa_square_to_sphere's inverse. */
void octa_sphere_to_square(const double d[3], double *u, double *v);

/* Bilinear lookup of the n x n square `rgb` (3 floats a texel, top row first) at (u, v):
 * texel (x, y) has its centre at ((x + 0.5)/n, (y + 0.5)/n), and a neighbour past an
 * edge is found as the sphere has it (pbrt's WrapMode::OctahedralSphere): across the
 * left or right edge at the mirrored row, across the top or bottom at the mirrored
 * column. */
void octa_lookup(const float *rgb, uint n, double u, double v, float out[3]);

/* Makes the n x n octahedral map `rgb` the background of s, as an environment map of
 * 2 H x H texels (H = n within the bounds above) scaled by `scale`: the texel in world
 * direction d takes octa_lookup at the square point of light_from_world d (a 3x3
 * row-major matrix, the inverse of the light's transform's linear part; the result is
 * normalised), negative values as 0. pbrt-v4 looks up the nearest texel; the bilinear
 * resampling here blurs the map by about a texel. Fails only when memory runs
 * out or the texels would pass the texture buffer's limit. */
Status octa_env_set(Scene *s, const float *rgb, uint n, const double light_from_world[9], float scale,
                    Error *err);

#endif /* CLPT_OCTA_ENV_H */
