/*
 * scene_view.h — the scene as the kernel stage functions see it: device pointers to
 * every scene buffer of scene_buffers.h, gathered into one private struct by each
 * __kernel wrapper (SCENE_VIEW in entry.cl) or by the scalar C device
 * (device_scene_view), and passed by pointer to the stage functions.
 */
#ifndef CLPT_SCENE_VIEW_H
#define CLPT_SCENE_VIEW_H

#include "scene_buffers.h"
#include "types.h"

#define SCENE_VIEW_FIELD_(kind, Type, name, count, what) GLOBAL const Type *name;
typedef struct {
    SCENE_BUFFERS(SCENE_VIEW_FIELD_)
} SceneView;
#undef SCENE_VIEW_FIELD_

#endif /* CLPT_SCENE_VIEW_H */
