/*
 * keyframes.h — a value that changes over time, given at key times and interpolated
 * between them: the glTF animation sampler's model (glTF 2.0, 3.11 and Appendix C), used
 * by the glTF reader's animations (io/gltf_anim.c) and open to any reader whose keys
 * move a transform or a camera. Time is in seconds; values are doubles.
 *
 * Outside the keys the value holds: before the first key it is the first key's value,
 * after the last the last's (glTF 2.0, 3.11.1: "clamped").
 */
#ifndef CLPT_SCENE_KEYFRAMES_H
#define CLPT_SCENE_KEYFRAMES_H

#include <stddef.h>

enum KeyInterp {
    KEY_LINEAR = 0,     /* linear; a rotation's unit quaternions by spherical linear
                         * interpolation (slerp), the shorter way round */
    KEY_STEP = 1,       /* the value of the last key at or before t */
    KEY_CUBICSPLINE = 2 /* a cubic Hermite spline with a tangent into and out of each key */
};

/* The keys of one animated value. */
typedef struct {
    int interp;           /* enum KeyInterp */
    int width;            /* doubles per value: 3 (a translation, a scale) or 4 */
    int rotation;         /* the values are quaternions (x, y, z, w): LINEAR slerps, and
                           * CUBICSPLINE's result is normalised */
    size_t n;             /* keys, >= 1 */
    const double *times;  /* n key times, strictly increasing */
    const double *values; /* per key: the value (width doubles); CUBICSPLINE: the in-tangent,
                           * the value, the out-tangent (3 * width) */
} KeyTrack;

/* The track's value at time t into out (width doubles). At a key's own time the key's
 * value is returned as it is, bit for bit. */
void key_track_eval(const KeyTrack *k, double t, double *out);

/* Spherical linear interpolation of unit quaternions a and b (x, y, z, w) at u in
 * [0, 1], the shorter way round (b negated when a . b < 0); nearly equal ones are
 * interpolated linearly and normalised, where slerp's 1/sin(theta) would lose digits
 * (Shoemake 1985, "Animating rotation with quaternion curves"). */
void key_slerp(const double *a, const double *b, double u, double *out);

#endif /* CLPT_SCENE_KEYFRAMES_H */
