/* scene_options.h — the command line's settings applied to a loaded scene, shared by
 * the program (main.c) and the library (api/), so that both render the same scene from
 * the same flags. */
#ifndef CLPT_SCENE_OPTIONS_H
#define CLPT_SCENE_OPTIONS_H

#include "option_values.h"
#include "scene/scene.h"

/* What the load needs of the flags (--camera, whether --width/--height replace the
 * file's size), set in an initialised scene before it is read. ST_USAGE when --camera
 * is given for a file that is not glTF. */
Status scene_options_before_load(const Options *o, Scene *s, Error *err);

/* The overrides (--set, then --spp, --width ... --shadows) applied to the loaded scene and checked
 * against it: the size's limits, --sample-range within the samples, --adaptive with
 * the whitted integrator. A bare mesh (`bare_mesh`) gets the camera that frames it for
 * the final size; then --set camera.*, --lookat and --fov change the camera, and
 * --crop or --pixel-bounds the window rendered, checked against that size. */
Status scene_options_apply(const Options *o, Scene *s, int bare_mesh, Error *err);

/* --set camera.*, --lookat and --fov again, on a camera an animation's frame has just
 * placed (docs/animation.md): the flags hold for every frame. */
Status scene_options_apply_camera(const Options *o, Scene *s, Error *err);

#endif /* CLPT_SCENE_OPTIONS_H */
