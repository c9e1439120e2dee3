/* camera.h — turns the scene's camera description into the kernels' Camera. */
#ifndef CLPT_CAMERA_H
#define CLPT_CAMERA_H

#include "scene/scene.h"

/* Fails (ST_INPUT) for a degenerate description: from == at, up parallel to the view
 * direction, a field of view outside (0, 180), a non-positive focus distance. */
Status camera_setup(const SceneCamera *desc, uint width, uint height, Camera *out, Error *err);

#endif /* CLPT_CAMERA_H */
