/*
 * animation.h — a scene that moves: what a reader leaves behind when asked to keep a
 * file's animation (Scene.keep_animation), so that the frames of `--frames` pose the
 * one loaded scene again and again instead of reading the file again (docs/animation.md).
 *
 * The reader's own state stays behind the interface: the scene layer knows only the
 * animation's time span and how to pose the scene at a time.
 */
#ifndef CLPT_SCENE_ANIMATION_H
#define CLPT_SCENE_ANIMATION_H

#include "base/status.h"

typedef struct SceneAnimation SceneAnimation;
struct SceneAnimation {
    double end;           /* seconds: the last key's time (the animation starts at 0) */
    int camera_only;      /* pose moves the camera alone: a frame keeps the scene's
                           * trees and buffers and renews only the camera's parameters */
    /* Places the scene (a Scene *)'s moving parts (geometry, lights, the camera) as they are at
     * time t, in place of their pose before. Errors as the reader's. */
    Status (*pose)(SceneAnimation *a, void *scene, double t, Error *err);
    /* --shutter: places the scene at time `open` with what moves until `close` given
     * keys over [open, close] (moving instances, camera keys: docs/motion.md) and the
     * camera's shutter set to it, in place of the pose and keys before; NULL where the
     * reader cannot (a camera_path). */
    Status (*pose_shutter)(SceneAnimation *a, void *scene, double open, double close, Error *err);
    void (*free)(SceneAnimation *a);
};

#endif /* CLPT_SCENE_ANIMATION_H */
