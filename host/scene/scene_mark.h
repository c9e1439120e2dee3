/*
 * scene_mark.h — a reader that places geometry again (an animation's next frame: the
 * glTF reader's nodes at a new pose) first takes the scene back to where it stood
 * before its placement: the triangles with their shading records and extras, the
 * objects and instances, and the delta lights added since the mark are dropped. What
 * the reader keeps between placements (materials, textures, the camera, spheres and
 * everything else) is left as it is.
 *
 * The scene's arrays must only have grown past the mark since it was taken, as they do
 * while a reader runs and as render_scene_prepare leaves them (its --accel kdtree
 * flattening drops only objects' own primitives, made after a mark taken before them).
 */
#ifndef CLPT_SCENE_MARK_H
#define CLPT_SCENE_MARK_H

#include "scene/scene.h"

typedef struct {
    size_t triangles, shading, tri_extras, tri_extra_of;
    size_t objects, instances, delta_lights;
} SceneMark;

void scene_mark(const Scene *s, SceneMark *m);

/* Drops what was added since *m (objects' names freed and unregistered). ST_INTERNAL
 * without memory (the object names' map is rebuilt). */
Status scene_rewind(Scene *s, const SceneMark *m, Error *err);

#endif /* CLPT_SCENE_MARK_H */
