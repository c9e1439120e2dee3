/*
 * motion.h — transforms that move over the shutter (docs/motion.md): a transform given
 * at a time becomes a MotionKey (kernels/types.h), decomposed as pbrt-v4's
 * AnimatedTransform decomposes its two keys, which the kernels interpolate
 * (kernels/geom/motion.h).
 */
#ifndef CLPT_MOTION_H
#define CLPT_MOTION_H

#include "base/status.h"
#include "scene/scene.h"
#include "scene/transform.h"
#include "types.h"

/* The most keys one moving transform may have (a bound on what a scene file makes the
 * kernels search through per path). */
#define MOTION_MAX_KEYS 64u

/* The key of transform m at `time`: m = T R S with T its translation, R the rotation of
 * the polar decomposition of its linear part (a proper rotation: a mirror goes to S)
 * and S = R^T times the linear part, symmetric. Fails (ST_INPUT, no location) when the
 * linear part is singular or not finite. */
Status motion_key_make(const Transform *m, float time, MotionKey *out, Error *err);

/* Flips the sign of each key's quaternion where that makes its arc from the key before
 * the shorter (q and -q are one rotation; slerp takes the arc between them as given). */
void motion_keys_shortest_arcs(MotionKey *keys, size_t n);

/* Gives the scene's last instance a pose m at `time`: its first call makes the
 * instance move (INST_MOTION), with its own transform as its first key at own_time.
 * Fails (ST_INPUT, no location) when time is not after the instance's last key, the
 * instance would have more than MOTION_MAX_KEYS, or m is singular. */
Status scene_add_instance_key(Scene *s, float own_time, float time, const Transform *m, Error *err);

/* The world box over every time of the n keys of a moving transform, of an object box
 * (lo, hi; empty when lo > hi: the result is too). Sampled: 32 times per key interval,
 * the 8 corners under each, then every side widened by the longest step a corner made
 * between samples, which covers the arc between them (a rotation of up to 180 degrees
 * between keys turns a corner through at most pi/32 between samples, where an arc is
 * within 0.05% of its chord; a chord bounds how far the path strays from either end). */
void motion_bounds(const MotionKey *keys, size_t n, const double lo[3], const double hi[3], double wl[3],
                   double wh[3]);

/* The transform of the n keys at `time`, by the kernels' own interpolation (evaluated
 * here in float, as a device does): for tests and for bounds over the shutter. */
Transform motion_transform_at(const MotionKey *keys, size_t n, float time);

/* The mean over the shutter [open, close] of |S(t) a x S(t) b|, S(t) the stretch of the
 * n keys at time t as the kernels interpolate it (linear between keys, held before the
 * first and after the last): the area a parallelogram of edges a, b has at time t under
 * the moving transform, since its rotation and translation change no area. In double,
 * by Simpson's rule on MOTION_AREA_PANELS panels of each stretch of the shutter between
 * key times; exact for a similarity's keys (the area is then quadratic in t), within
 * 1e-6 of the integral for any stretch (test_motion.c). close <= open: the area at open. */
double motion_mean_area(const MotionKey *keys, size_t n, double open, double close, const double a[3],
                        const double b[3]);

#endif /* CLPT_MOTION_H */
