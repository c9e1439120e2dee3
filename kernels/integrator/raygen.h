/*
 * raygen.h — where a path is born: the camera ray through a jittered point of its pixel
 * (box filter), from a point on the thin lens when the aperture is open; or, for an
 * orthographic camera, the parallel ray through that point of the view rectangle; from a
 * moving camera, at a time in the shutter (geom/motion.h).
 */
#ifndef CLPT_RAYGEN_H
#define CLPT_RAYGEN_H

#include "geom/motion.h"
#include "sample/rng.h"
#include "sample/sampling.h"

/* Film pixel `pixel` as the whole image's pixel: its column *x and row *y there, and
 * its index, which keys its samples' random numbers. Without a crop it is `pixel`; with
 * one, the film is a window of the image (RenderParams.crop_left ...), and a window
 * pixel's samples are the ones the whole render gives that pixel. */
KFN uint params_image_pixel(GLOBAL const RenderParams *p, uint pixel, uint *x, uint *y)
{
    *x = p->crop_left + pixel % p->width;
    *y = p->crop_top + pixel / p->width;
    return *y * (p->crop_left + p->width + p->crop_right) + *x;
}

/* The film position (s, t) in [0,1]^2 of point (jx, jy) of image pixel (x, y): over
 * the whole image's size, so that a crop sees what the whole image sees there. */
KFN float params_film_s(GLOBAL const RenderParams *p, uint x, float jx)
{
    return ((float)x + jx) / (float)(p->crop_left + p->width + p->crop_right);
}

KFN float params_film_t(GLOBAL const RenderParams *p, uint y, float jy)
{
    return ((float)y + jy) / (float)(p->crop_top + p->height + p->crop_bottom);
}

/* The ray through film position (s, t) of the camera as prepared (see Camera in
 * types.h): in the world, or in a moving camera's own space; `key` gives the lens
 * sample when the aperture is open. */
KFN Ray camera_ray_still(GLOBAL const RenderParams *p, float s, float t, RngKey key)
{
    const Camera cam = p->camera;
    Ray ray;
    vec3 target = v3_sub(v3_madd(cam.corner, cam.horizontal, s), v3_scale(cam.vertical, t));
    ray.tmin = 0.0f;
    ray.tmax = INFINITY;
    if (cam.type == CAMERA_ORTHOGRAPHIC) {
        ray.o = target;
        ray.d = cam.forward;
        return ray;
    }
    vec3 origin = cam.origin;
    if (cam.lens_radius > 0.0f) {
        float lu, lv, lx, ly;
        rng_uniform2(key, 0u, DIM_LENS_U, &lu, &lv);
        sample_disk(lu, lv, &lx, &ly);
        origin = v3_madd(v3_madd(origin, cam.lens_u, lx * cam.lens_radius), cam.lens_v, ly * cam.lens_radius);
    }
    ray.o = origin;
    ray.d = v3_norm(v3_sub(target, origin));
    return ray;
}

/* The camera ray through film position (s, t) in the world: a moving camera's
 * (KF_MOTION, Camera.motion_keys; geom/motion.h) at `time` (camera_time), from its keys
 * in motion_keys (which a still camera does not read: NULL will do). */
KFN Ray camera_ray(GLOBAL const RenderParams *p, GLOBAL const MotionKey *motion_keys, float s, float t, RngKey key,
                   float time)
{
    Ray ray = camera_ray_still(p, s, t, key);
    if (KF_HAS(KF_MOTION) && p->camera.motion_keys) ray = camera_ray_at(p, motion_keys, time, ray);
    return ray;
}

/* The path integrator's camera ray for sample `sample` of pixel `pixel` (its index in the
 * image, or in the pixel list), with the sample's key and time: one function, so that
 * the denoiser's emission feature (INTEGRATOR_FEATURE_EMISSION) traces the very rays
 * the image's paths start with. */
KFN Ray path_camera_ray(GLOBAL const RenderParams *p, GLOBAL const MotionKey *motion_keys, uint pixel, uint sample,
                        RngKey *key_out, float *time)
{
    uint x, y;
    RngKey key = rng_key_make(p, params_image_pixel(p, pixel, &x, &y), sample);
    float jx, jy;
    rng_uniform2(key, 0u, DIM_PIXEL_X, &jx, &jy);
    *key_out = key;
    *time = camera_time(p, key);
    return camera_ray(p, motion_keys, params_film_s(p, x, jx), params_film_t(p, y, jy), key, *time);
}

KFN void raygen_path(GLOBAL const RenderParams *p, GLOBAL const MotionKey *motion_keys, uint pixel, uint sample,
                     GLOBAL PathState *ps, GLOBAL Ray *ray)
{
    /* the noise threshold's halves: sample s of the batch is the pixel's sample
     * step s + offset (host/render/adaptive.c); no step leaves the index as it is */
    if (p->sample_step > 1u) sample = sample * p->sample_step + p->sample_offset;
    RngKey key;
    float time;
    *ray = path_camera_ray(p, motion_keys, pixel, sample, &key, &time);

    ps->throughput = v3s(1.0f);
    ps->radiance = v3s(0.0f);
    ps->shadow_L = v3s(0.0f);
    ps->pixel = pixel;
    ps->sample = sample;
    ps->bounce = 0u;
    ps->bsdf_pdf = 0.0f;
    ps->flags = PATH_SPECULAR;  /* what the camera sees directly gets full weight */
    ps->rng_key = key.key;
    ps->branch = 0u;
    ps->medium = p->camera_medium;   /* 0 (vacuum) in scenes without media */
    ps->shadow_medium = 0u;
    ps->crossings = 0u;
    ps->time = time;
}

/* Restarts the path of a camera sample as its next continuation from the first hit
 * (first-hit splitting, RenderParams.split): the state raygen_path gave it, but with the
 * radiance gathered so far and the next branch. The caller shades the first hit again,
 * which for a later branch samples a light and scatters (or crosses the boundary of a
 * medium) but adds no emission (shade_path). The camera is in vacuum wherever a render
 * splits (host/render/render_scene.c), so the path starts there again, with no
 * boundary crossed. */
KFN void path_branch_next(GLOBAL PathState *ps)
{
    ps->throughput = v3s(1.0f);
    ps->shadow_L = v3s(0.0f);
    ps->bounce = 0u;
    ps->bsdf_pdf = 0.0f;
    ps->flags = PATH_SPECULAR;
    ps->branch = ps->branch + 1u;
    ps->medium = 0u;
    ps->shadow_medium = 0u;
    ps->crossings = 0u;
}

#endif /* CLPT_RAYGEN_H */
