/*
 * scene_param.h — a loaded scene's parameters by path, for --set KEY=VALUE and the
 * library's clpt_scene_set (docs/scene-format.md, "Parameters by path"):
 *
 *   camera.from|eye, camera.at|look_at, camera.up    three numbers "0,1,5"
 *   camera.fov, camera.aperture, camera.focus        one number (a perspective camera)
 *   camera.width                                     one number (an orthographic one)
 *   image.width|height|spp|depth|seed|split          an integer
 *   background.color                                 a colour
 *   material.NAME.PARAM   albedo, emission, specular, eta, k, ... (colours: one number
 *                         or three) and ior, roughness, metallic, ... (one number), of
 *                         every material named NAME
 *   light.N.PARAM         intensity, position, direction of the N-th point, spot or
 *                         directional light (from 0, in file order)
 *
 * Whatever format the scene was read from: the readers all fill the same Scene.
 */
#ifndef CLPT_SCENE_PARAM_H
#define CLPT_SCENE_PARAM_H

#include "scene/scene.h"

/* Sets parameter `key` of s to `value`. ST_USAGE, saying what was expected (and the
 * nearest known name when one is close), for an unknown path or a bad value; s is then
 * unchanged. */
Status scene_param_set(Scene *s, const char *key, const char *value, Error *err);

#endif /* CLPT_SCENE_PARAM_H */
