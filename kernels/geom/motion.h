/*
 * motion.h -- a transform that moves over the shutter: its keys (MotionKey, types.h)
 * interpolated at a time as pbrt-v4's AnimatedTransform::Interpolate does (PBR 4th ed.,
 * 3.10.1): each key is M = T R S, decomposed on the host (host/scene/motion.c);
 * between two keys the translation and the stretch are interpolated linearly and the
 * rotation by spherical linear interpolation of the quaternions (Shoemake, "Animating
 * Rotation with Quaternion Curves", 1985), then recomposed. Before the first key the
 * transform is the first key's, after the last the last's. Only + - * / sqrt and the
 * k_* functions of kmath.h: every device computes the same bits (compat.h).
 *
 * And its users (docs/motion.md): the path's time, a moving camera's ray (made in the
 * camera's own space) carried to the world at that time, and a moving instance's M and
 * M^-1 then (geom/instance.h).
 */
#ifndef CLPT_GEOM_MOTION_H
#define CLPT_GEOM_MOTION_H

#include "sample/rng.h"
#include "util/kmath.h"

/* The slerp of unit quaternions a and b (b already on a's side: the host flips keys so
 * that their dot product is >= 0) at u in [0, 1], into q. Nearly equal rotations are
 * interpolated linearly and normalised, where sin(theta) would divide by almost 0. */
KFN void motion_slerp(GLOBAL const float *a, GLOBAL const float *b, float u, float *q)
{
    float c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    float wa = 1.0f - u, wb = u;
    if (c < 0.9995f) {
        float theta = k_acos(k_clamp(c, -1.0f, 1.0f));
        float sa, ca, sb, cb, s, cs;
        k_sincos(theta, &s, &cs);
        k_sincos((1.0f - u) * theta, &sa, &ca);
        k_sincos(u * theta, &sb, &cb);
        wa = sa / s;
        wb = sb / s;
    }
    float len2 = 0.0f;
    for (int i = 0; i < 4; i++) {
        q[i] = wa * a[i] + wb * b[i];
        len2 += q[i] * q[i];
    }
    float inv = 1.0f / k_sqrt(len2);
    for (int i = 0; i < 4; i++) q[i] *= inv;
}

/* The transform of the n keys from keys[0] at `time`, as a 3x4 row-major matrix m
 * (object -> world, as Instance.to_world). */
KFN void motion_at(GLOBAL const MotionKey *keys, uint n, float time, float *m)
{
    uint i = 0u;
    while (i + 2u < n && !(time < keys[i + 1u].time)) i++;
    GLOBAL const MotionKey *k0 = keys + i;
    GLOBAL const MotionKey *k1 = keys + (n > 1u ? i + 1u : i);
    float u = 0.0f;
    if (k1->time > k0->time) u = k_clamp((time - k0->time) / (k1->time - k0->time), 0.0f, 1.0f);
    float q[4];
    motion_slerp(k0->rotate, k1->rotate, u, q);
    float s[6];
    for (int j = 0; j < 6; j++) s[j] = (1.0f - u) * k0->stretch[j] + u * k1->stretch[j];
    /* R from q (x, y, z, w), then R S with S symmetric */
    float x = q[0], y = q[1], z = q[2], w = q[3];
    float r[9] = { 1.0f - 2.0f * (y * y + z * z), 2.0f * (x * y - z * w), 2.0f * (x * z + y * w),
                   2.0f * (x * y + z * w), 1.0f - 2.0f * (x * x + z * z), 2.0f * (y * z - x * w),
                   2.0f * (x * z - y * w), 2.0f * (y * z + x * w), 1.0f - 2.0f * (x * x + y * y) };
    float sm[9] = { s[0], s[1], s[2], s[1], s[3], s[4], s[2], s[4], s[5] };
    for (int row = 0; row < 3; row++)
        for (int col = 0; col < 3; col++)
            m[row * 4 + col] = r[row * 3] * sm[col] + r[row * 3 + 1] * sm[3 + col] + r[row * 3 + 2] * sm[6 + col];
    m[3] = (1.0f - u) * k0->translate.x + u * k1->translate.x;
    m[7] = (1.0f - u) * k0->translate.y + u * k1->translate.y;
    m[11] = (1.0f - u) * k0->translate.z + u * k1->translate.z;
}

KFN vec3 motion_point(const float *m, vec3 p)
{
    return v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
              m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

KFN vec3 motion_vector(const float *m, vec3 d)
{
    return v3(m[0] * d.x + m[1] * d.y + m[2] * d.z, m[4] * d.x + m[5] * d.y + m[6] * d.z,
              m[8] * d.x + m[9] * d.y + m[10] * d.z);
}

/* |m| v: the linear part's magnitudes times v (error bounds, geom/surface.h). */
KFN vec3 motion_abs_vector(const float *m, vec3 v)
{
    return v3(k_fabs(m[0]) * v.x + k_fabs(m[1]) * v.y + k_fabs(m[2]) * v.z,
              k_fabs(m[4]) * v.x + k_fabs(m[5]) * v.y + k_fabs(m[6]) * v.z,
              k_fabs(m[8]) * v.x + k_fabs(m[9]) * v.y + k_fabs(m[10]) * v.z);
}

/* The time of a camera sample: uniform over the shutter, from the sampler's DIM_TIME,
 * which only a scene that moves (Camera.moving) draws, so every other scene keeps its
 * random numbers and its bits; 0 there. */
KFN float camera_time(GLOBAL const RenderParams *p, RngKey key)
{
    if (!KF_HAS(KF_MOTION) || !p->camera.moving) return 0.0f;
    float open = p->camera.shutter_open, close = p->camera.shutter_close;
    if (!(close > open)) return open;
    return open + (close - open) * rng_uniform(key, 0u, DIM_TIME);
}

/* A moving camera's ray (made in the camera's space) in the world at `time`: origin
 * and direction by the camera's transform then, the direction renormalised (a camera's
 * keys are rigid, up to rounding and a mirror). */
KFN Ray camera_ray_at(GLOBAL const RenderParams *p, GLOBAL const MotionKey *motion_keys, float time, Ray ray)
{
    float m[12];
    motion_at(motion_keys + p->camera.motion_first, p->camera.motion_keys, time, m);
    ray.o = motion_point(m, ray.o);
    ray.d = v3_norm(motion_vector(m, ray.d));
    return ray;
}

/* The inverse of the affine 3x4 m into mi (cofactors over the determinant, in float:
 * every device rounds the same steps). A singular m gives non-finite entries, which the
 * walk's NaN check turns into a miss. */
KFN void motion_invert(const float *m, float *mi)
{
    float c00 = m[5] * m[10] - m[6] * m[9], c01 = m[6] * m[8] - m[4] * m[10], c02 = m[4] * m[9] - m[5] * m[8];
    float inv = 1.0f / (m[0] * c00 + m[1] * c01 + m[2] * c02);
    mi[0] = c00 * inv;
    mi[1] = (m[2] * m[9] - m[1] * m[10]) * inv;
    mi[2] = (m[1] * m[6] - m[2] * m[5]) * inv;
    mi[4] = c01 * inv;
    mi[5] = (m[0] * m[10] - m[2] * m[8]) * inv;
    mi[6] = (m[2] * m[4] - m[0] * m[6]) * inv;
    mi[8] = c02 * inv;
    mi[9] = (m[1] * m[8] - m[0] * m[9]) * inv;
    mi[10] = (m[0] * m[5] - m[1] * m[4]) * inv;
    for (int r = 0; r < 3; r++)
        mi[4 * r + 3] = -(mi[4 * r] * m[3] + mi[4 * r + 1] * m[7] + mi[4 * r + 2] * m[11]);
}

/* A moving instance's M and M^-1 at `time` (Instance.flags INST_MOTION): its keys
 * interpolated, then inverted. */
KFN void motion_instance_at(GLOBAL const MotionKey *keys, float time, float *m, float *mi)
{
    motion_at(keys, keys->count, time, m);
    motion_invert(m, mi);
}

#endif /* CLPT_GEOM_MOTION_H */
