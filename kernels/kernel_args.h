/*
 * kernel_args.h — the scene buffers as __kernel parameters and their gathering into a
 * SceneView, for every OpenCL program of clpt (entry.cl, bench/trace.cl): one line per
 * buffer of scene_buffers.h, so a new buffer reaches every kernel with no edit here.
 */
#ifndef CLPT_KERNEL_ARGS_H
#define CLPT_KERNEL_ARGS_H

#include "scene_buffers.h"
#include "scene_view.h"

/* The scene buffers as __kernel parameters, one per line of scene_buffers.h, each
 * followed by a comma (every kernel taking them has parameters after them), and their
 * gathering into a SceneView named sc. */
#define SCENE_ARG_(kind, Type, name, count, what) __global const Type *name,
#define SCENE_ARGS SCENE_BUFFERS(SCENE_ARG_)
#define SCENE_VIEW_SET_(kind, Type, name, count, what) sc.name = name;
#define SCENE_VIEW(sc)                                                                   \
    SceneView sc;                                                                        \
    SCENE_BUFFERS(SCENE_VIEW_SET_)                                                       \
    sc.time = 0.0f;

#endif /* CLPT_KERNEL_ARGS_H */
