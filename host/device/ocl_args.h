/*
 * ocl_args.h — the argument positions of the kernels of kernels/entry.cl, by name, for
 * clSetKernelArg. Kernels taking SCENE_ARGS have the scene buffers first, at
 * SCENE_BUF_params ... (kernels/scene_buffers.h), then their own arguments, named here
 * in signature order. tests/test_ocl.c compares every name with the kernel's own
 * (clGetKernelArgInfo), so a signature changed without this file fails there, not as a
 * wrong image.
 */
#ifndef CLPT_OCL_ARGS_H
#define CLPT_OCL_ARGS_H

#include "scene_buffers.h"

#define SCENE_N SCENE_BUF_COUNT
enum { ARG_RAYGEN_FIRST_PIXEL = SCENE_N, ARG_RAYGEN_FIRST_SAMPLE, ARG_RAYGEN_N_PIXELS, ARG_RAYGEN_N_PATHS,
       ARG_RAYGEN_PATHS, ARG_RAYGEN_RAYS, ARG_RAYGEN_QUEUE };
enum { ARG_INTERSECT_QUEUE = SCENE_N, ARG_INTERSECT_N, ARG_INTERSECT_RAYS, ARG_INTERSECT_HITS,
       ARG_INTERSECT_COUNTS, ARG_INTERSECT_LIVE_SLOT, ARG_INTERSECT_PATHS };
enum { ARG_SHADE_QUEUE = SCENE_N, ARG_SHADE_N, ARG_SHADE_RAYS, ARG_SHADE_HITS, ARG_SHADE_PATHS,
       ARG_SHADE_SHADOW_RAYS, ARG_SHADE_NEXT_QUEUE, ARG_SHADE_SHADOW_QUEUE, ARG_SHADE_COUNTS,
       ARG_SHADE_SLOT };
enum { ARG_SHADOW_QUEUE = SCENE_N, ARG_SHADOW_N, ARG_SHADOW_RAYS, ARG_SHADOW_PATHS, ARG_SHADOW_COUNTS,
       ARG_SHADOW_LIVE_SLOT };
enum { ARG_PATH_FIRST_PIXEL = SCENE_N, ARG_PATH_FIRST_SAMPLE, ARG_PATH_N_PIXELS, ARG_PATH_N_PATHS, ARG_PATH_PATHS,
       ARG_PATH_RAYS, ARG_PATH_SHADOW_RAYS, ARG_PATH_COUNTERS };
enum { ARG_FILM_PATHS, ARG_FILM_N_PIXELS, ARG_FILM_N_PATHS, ARG_FILM_FILM };
enum { ARG_WHITTED_FIRST_PIXEL = SCENE_N, ARG_WHITTED_FIRST_SAMPLE, ARG_WHITTED_N_PIXELS, ARG_WHITTED_N_PATHS,
       ARG_WHITTED_PATHS, ARG_WHITTED_COUNTERS };

#endif /* CLPT_OCL_ARGS_H */
