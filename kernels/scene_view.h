/*
 * scene_view.h — the scene as the kernel stage functions see it: device pointers to
 * every scene buffer, gathered into one private struct by each __kernel wrapper (or by
 * the scalar C device) and passed by pointer to the stage functions.
 */
#ifndef CLPT_SCENE_VIEW_H
#define CLPT_SCENE_VIEW_H

#include "types.h"

typedef struct {
    GLOBAL const RenderParams *params;
    GLOBAL const KdNode *nodes;
    GLOBAL const uint *leaf_prims;
    GLOBAL const Sphere *spheres;
    GLOBAL const Triangle *triangles;
    GLOBAL const Box *boxes;
    GLOBAL const Plane *planes;
    GLOBAL const Material *materials;
    GLOBAL const Light *lights;
    GLOBAL const TriShading *shading;
    GLOBAL const Texture *textures;
    GLOBAL const uint *texels;          /* every image texture's texels (Texture.offset) */
    GLOBAL const uint *pixel_mask;      /* per pixel, read when params->use_mask is set */
} SceneView;

#endif /* CLPT_SCENE_VIEW_H */
