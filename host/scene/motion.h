/*
 * motion.h — transforms that move over the shutter (docs/motion.md): a transform given
 * at a time becomes a MotionKey (kernels/types.h), decomposed as pbrt-v4's
 * AnimatedTransform decomposes its two keys, which the kernels interpolate
 * (kernels/geom/motion.h).
 */
#ifndef CLPT_MOTION_H
#define CLPT_MOTION_H

#include "base/status.h"
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

/* The transform of the n keys at `time`, by the kernels' own interpolation (evaluated
 * here in float, as a device does): for tests and for bounds over the shutter. */
Transform motion_transform_at(const MotionKey *keys, size_t n, float time);

#endif /* CLPT_MOTION_H */
