/*
 * view_camera.h — the viewer's camera moves, on the scene's own camera description
 * (SceneCamera), and its printing as a `camera { ... }` block of the scene format.
 *
 * Every move leaves the description in float, as the scene parser would read it, and
 * the block prints each float with %.9g, which reads back as the same float: a scene
 * with the printed block renders with the very camera the viewer showed.
 */
#ifndef CLPT_VIEW_CAMERA_H
#define CLPT_VIEW_CAMERA_H

#include <stdio.h>

#include "scene/scene.h"

/* Moves the eye and the point looked at together, in world units: `right` and
 * `forward` in the camera's frame (forward is the view direction), `up` along the
 * camera's up vector. */
void view_camera_move(SceneCamera *c, double right, double up, double forward);

/* Turns the view direction by `yaw` degrees to the right and `pitch` degrees up, about
 * the eye, keeping the distance to the point looked at (the default focus). Returns 0,
 * changing nothing, when the new direction would come within about 2.5 degrees of the
 * up vector (the camera's frame would be undefined there). */
int view_camera_turn(SceneCamera *c, double yaw, double pitch);

/* Multiplies the vertical field of view by `factor`, kept within [1, 170] degrees. */
void view_camera_zoom(SceneCamera *c, double factor);

/* Multiplies the focus distance (|at - from| when the scene gives none) by `factor`. */
void view_camera_focus(SceneCamera *c, double factor);

/* Multiplies the aperture by `factor`; a closed aperture opens to `first` when factor
 * > 1, and one below first / 8 closes (a pinhole). */
void view_camera_aperture(SceneCamera *c, double factor, double first);

/* Writes the camera as one scene-format line, `camera { from ... }`, and a newline.
 * Returns 0, or -1 when the description cannot be said in the scene format (the
 * course formats' orthographic and course-basis cameras): a comment line says so and
 * the block then gives the eye, the target and the field of view only. An
 * orthographic camera sized by its width (clpt's format) prints as such. */
int view_camera_print(FILE *f, const SceneCamera *c);

#endif /* CLPT_VIEW_CAMERA_H */
