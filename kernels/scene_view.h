/*
 * scene_view.h — the scene as the kernel stage functions see it: device pointers to
 * every scene buffer of scene_buffers.h, gathered into one private struct by each
 * __kernel wrapper (SCENE_VIEW in entry.cl) or by the scalar C device
 * (device_scene_view), and passed by pointer to the stage functions; and the time the
 * path it serves sees the scene at (motion blur).
 */
#ifndef CLPT_SCENE_VIEW_H
#define CLPT_SCENE_VIEW_H

#include "scene_buffers.h"
#include "types.h"

#define SCENE_VIEW_FIELD_(kind, Type, name, count, what) GLOBAL const Type *name;
typedef struct {
    SCENE_BUFFERS(SCENE_VIEW_FIELD_)
    /* the time the scene is seen at: a path's (PathState.time), set by the stage that
     * runs the path where the scene moves (Camera.moving, docs/motion.md), so that its
     * rays walk moving instances where they are then; 0 otherwise */
    float time;
} SceneView;
#undef SCENE_VIEW_FIELD_

/* The film pixel of a batch's pixel number `index` (in [0, pixels a sample covers)):
 * itself, or with a pixel list (RenderParams.pixel_list_size) the listed pixel, so that
 * the waves of a batch hold only the pixels still rendering and a pixel left out costs
 * nothing. A pixel's random numbers are keyed by the pixel and its sample index, never
 * by its place in the batch, so a listed pixel computes the bits it computes unlisted. */
KFN uint batch_pixel(const SceneView *sc, uint index)
{
    return sc->params->pixel_list_size ? sc->pixel_list[index] : index;
}

#endif /* CLPT_SCENE_VIEW_H */
