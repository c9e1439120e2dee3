/*
 * layout.h — the host's view of the structs the kernels share (kernels/types.h):
 * sizeof and offsetof values in the order kernels/entry.cl's k_layout writes its own.
 * test_kernels compares the two lists entry by entry; test_ocl sizes k_layout's
 * output buffer from it, so that the kernel never writes past the buffer's end (it
 * did, silently, when an entry was added to the kernel and not to a hand-kept count).
 * Add an entry here and in k_layout together.
 */
#ifndef CLPT_TESTS_LAYOUT_H
#define CLPT_TESTS_LAYOUT_H

#include <stddef.h>

#include "types.h"

#define LAYOUT_HOST_VALUES                                                                          \
    {                                                                                               \
        sizeof(vec3), sizeof(Ray), sizeof(Hit), sizeof(KdNode), sizeof(Sphere), sizeof(Triangle),\
        sizeof(TriShading), sizeof(Box), sizeof(Plane), sizeof(Material), sizeof(Light),        \
        sizeof(Camera), sizeof(RenderParams), sizeof(PathState), offsetof(RenderParams, bg_color),\
        offsetof(RenderParams, width), offsetof(RenderParams, bounds_lo), offsetof(PathState, bsdf_pdf),\
        offsetof(Material, albedo), offsetof(Light, position), offsetof(Camera, lens_u),        \
        offsetof(TriShading, uv0), sizeof(Texture), offsetof(Texture, m),                       \
        offsetof(Texture, color1), offsetof(RenderParams, ambient),                             \
        offsetof(RenderParams, strata), offsetof(Material, reflective),                         \
        offsetof(Light, cos_inner), offsetof(Camera, forward),                                  \
        offsetof(RenderParams, shadows), offsetof(RenderParams, normal_miss_grey),              \
        offsetof(Material, roughness), offsetof(Material, k),                                   \
        offsetof(Material, clearcoat_roughness), offsetof(Material, texture_rm),                \
        offsetof(Material, normal_scale),                                                       \
        sizeof(RevSurface), offsetof(RevSurface, axis_x), offsetof(RenderParams, n_revsurfaces),\
        offsetof(RenderParams, bg_light), sizeof(TriExtra), offsetof(TriExtra, uv),             \
        offsetof(Material, absorption), offsetof(Material, sheen_color),                        \
        offsetof(Material, texture_sheen_roughness),                                            \
        offsetof(Material, layer_albedo), offsetof(Material, base_roughness), sizeof(SphereXform),\
        offsetof(SphereXform, to_object), offsetof(Sphere, xform), sizeof(Medium),              \
        offsetof(Medium, sigma_s), offsetof(PathState, medium), offsetof(RenderParams, has_media),\
        offsetof(Material, medium_in), sizeof(GridMedium), offsetof(GridMedium, nx),            \
        offsetof(GridMedium, max_density), offsetof(Medium, emission),                          \
        offsetof(GridMedium, emission_at),                                                      \
        offsetof(GridMedium, temperature_at), sizeof(MotionKey), offsetof(MotionKey, stretch),  \
        offsetof(Camera, motion_keys), offsetof(Material, diffuse_transmission),                \
        offsetof(Material, diffuse_transmission_color), offsetof(GridMedium, minorant_at),      \
        sizeof(KdProto), offsetof(KdProto, hi), offsetof(RenderParams, has_alpha)               \
    }

/* how many values k_layout writes */
#define LAYOUT_VALUES (sizeof((const unsigned[])LAYOUT_HOST_VALUES) / sizeof(unsigned))

#endif
