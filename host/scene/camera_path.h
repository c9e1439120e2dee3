/*
 * camera_path.h — a camera moved along keys (clpt's `camera_path`, docs/scene-format.md):
 * at each key time an eye, a point looked at, an up direction and a field of view;
 * between keys each is interpolated on its own (scene/keyframes.h), and the scene's
 * camera takes the values of the frame's time (docs/animation.md).
 */
#ifndef CLPT_SCENE_CAMERA_PATH_H
#define CLPT_SCENE_CAMERA_PATH_H

#include <stddef.h>

#include "scene/animation.h"

/* The most keys one path may have: a bound on what a scene file makes the reader keep. */
#define CAMERA_PATH_MAX_KEYS 100000

typedef struct {
    double t;                  /* seconds; increasing from key to key */
    double from[3], at[3], up[3];
    double fov;                /* degrees (ignored by an orthographic camera) */
} CameraKey;

enum CameraPathInterp {
    CAMERA_PATH_LINEAR = 0,    /* straight from key to key */
    CAMERA_PATH_STEP = 1,      /* each key's values held until the next */
    CAMERA_PATH_SMOOTH = 2     /* a Catmull-Rom spline through the keys */
};

/* The path's animation (*out; its `end` the last key's time), which poses a Scene's
 * camera; the n >= 1 keys are copied. ST_INTERNAL without memory. */
Status camera_path_animation(const CameraKey *keys, size_t n, int interp, SceneAnimation **out, Error *err);

#endif /* CLPT_SCENE_CAMERA_PATH_H */
