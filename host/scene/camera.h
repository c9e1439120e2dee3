/* camera.h — turns the scene's camera description into the kernels' Camera. */
#ifndef CLPT_CAMERA_H
#define CLPT_CAMERA_H

#include "scene/scene.h"

/* Fails (ST_INPUT) for a degenerate description: from == at, up parallel to the view
 * direction, a field of view outside (0, 180), a non-positive focus distance or
 * orthographic view size. */
Status camera_setup(const SceneCamera *desc, uint width, uint height, Camera *out, Error *err);

/* A moving camera (scene->n_camera_keys > 0, docs/motion.md): *out as camera_setup
 * makes it but in the camera's own space (the frame of its first pose: from at the
 * origin, right, up and back along the axes), its shutter, and its keys from
 * motion_first in *keys (malloc'd, freed by the caller; Camera.motion_keys of them):
 * each pose's frame, the camera block's then each camera_key's. A still camera gets
 * camera_setup's camera and no keys (*keys NULL). Fails (ST_INPUT) as camera_setup for
 * any pose. */
Status camera_setup_moving(const Scene *scene, uint width, uint height, uint motion_first, Camera *out,
                           MotionKey **keys, Error *err);

/* The shortest focus distance single precision renders from `from`: the kernels build
 * a ray's direction as a point on the plane in focus minus the eye, in float, so a
 * plane closer than 2^-12 of the eye's largest coordinate loses more than a pixel's
 * worth of direction at 4096 pixels (and below 2^-60 its squares leave the normal
 * floats). A pinhole camera moves its plane out to a precise distance (the image does
 * not depend on it); a lens camera with a shorter focus is refused. */
double camera_min_focus(vec3 from);
/* The focus distance camera_setup uses (see camera_min_focus). */
double camera_focus(const SceneCamera *desc);

#endif /* CLPT_CAMERA_H */
