/*
 * scene_buffers.h — THE list of scene buffers (as Cycles' kernel/data_arrays.h): every
 * buffer the kernels read the scene from, once, in kernel-argument order. Everything
 * that names them all is generated from this list:
 *
 *   kernels/scene_view.h      SceneView, the kernels' view (one pointer per buffer)
 *   kernels/entry.cl          SCENE_ARGS, the __kernel parameters, and SCENE_VIEW, which
 *                             gathers them into a SceneView
 *   host/device/device.h      DeviceScene (what the host hands a device) and
 *                             device_scene_buffer (each buffer's bytes and name)
 *   host/device/device_ocl.c  the upload and the clSetKernelArg positions
 *   host/device/device_scalar.c and the tests: device_scene_view
 *   host/render/checkpoint.c  the render key hashes every buffer
 *
 * A new scene buffer is one line here (plus its count where the line says it lives);
 * the compiler then points at everything that must fill it.
 *
 * SCENE_BUFFERS(X) calls X(kind, Type, name, count, what) once per buffer:
 *   kind   ONE: a single Type, held by value in DeviceScene (the params block);
 *          MANY: an array, which DeviceScene points to (NULL when its count is 0)
 *   Type   the element type, shared with the host through types.h
 *   name   the field name in SceneView and DeviceScene, and the kernel parameter name
 *   count  how many elements: an expression over `ds`, the host's const DeviceScene *
 *          (expanded in host code only; the kernels never see it)
 *   what   what the buffer holds, in words, for messages ("the triangles need ...")
 *
 * Valid C11 and OpenCL C 1.2 (only the C99 preprocessor: no variadic macros).
 */
#ifndef CLPT_SCENE_BUFFERS_H
#define CLPT_SCENE_BUFFERS_H

#include "types.h"

#define SCENE_BUFFERS(X)                                                                     \
    X(ONE,  RenderParams, params,     1u,                        "render parameters")        \
    X(MANY, KdNode,       nodes,      (ds)->params.n_nodes,      "kd-tree nodes")            \
    X(MANY, uint,         leaf_prims, (ds)->params.n_leaf_prims, "kd-tree leaf lists")       \
    X(MANY, BvhNode,      bvh,        (ds)->params.n_bvh_nodes,  "8-wide BVH nodes")         \
    X(MANY, uint,         bvh_leaves, (ds)->n_bvh_leaves,        "8-wide BVH leaf lists")    \
    /* the top level over instances, compressed (types.h); none without instances */     \
    X(MANY, BvhTopNode,   bvh_top,    (ds)->n_bvh_top,           "top-level BVH nodes")      \
    X(MANY, Instance,     instances,  (ds)->params.n_instances,  "instances")                \
    /* --accel kdtree with instances: each prototype's kd-tree (types.h); else none */     \
    X(MANY, KdProto,      kd_protos,  (ds)->n_kd_protos,         "kd-tree prototypes")       \
    /* per instance, its first light (types.h, LIGHT_INSTANCED); none without them */    \
    X(MANY, uint,         instance_lights, (ds)->n_instance_lights, "instanced lights")      \
    X(MANY, Sphere,       spheres,    (ds)->params.n_spheres,    "spheres")                  \
    X(MANY, SphereXform,  sphere_xforms, (ds)->n_sphere_xforms,  "sphere transforms")        \
    X(MANY, Triangle,     triangles,  (ds)->params.n_triangles,  "triangles")                \
    X(MANY, Box,          boxes,      (ds)->params.n_boxes,      "boxes")                    \
    X(MANY, Plane,        planes,     (ds)->params.n_planes,     "planes")                   \
    X(MANY, RevSurface,   revsurfaces, (ds)->params.n_revsurfaces, "surfaces of revolution") \
    X(MANY, float,        rev_points, (ds)->n_rev_points,        "profile control points")   \
    X(MANY, Material,     materials,  (ds)->n_materials,         "materials")                \
    X(MANY, Light,        lights,     (ds)->params.n_lights,     "lights")                   \
    X(MANY, TriShading,   shading,    (ds)->n_shading,           "shading normals")          \
    /* TriShading's side array (types.h): n_shading entries, or none without extras */      \
    X(MANY, uint,         tri_extra_of, (ds)->n_tri_extra_of,    "corner attribute indices") \
    X(MANY, TriExtra,     tri_extras, (ds)->n_tri_extras,        "corner attributes")        \
    X(MANY, Texture,      textures,   (ds)->params.n_textures,   "textures")                 \
    X(MANY, uint,         texels,     (ds)->n_texels,            "texture images")           \
    X(MANY, float,        env_cdf,    (ds)->n_env_cdf,           "environment map distribution") \
    /* the pixels a batch covers when params.pixel_list_size > 0 (batch_pixel) */           \
    X(MANY, uint,         pixel_list, (ds)->params.pixel_list_size, "pixel list")            \
    /* participating media (kernels/medium/), read only where params.has_media */           \
    X(MANY, Medium,       media,      (ds)->params.n_media,      "participating media")    \
    /* heterogeneous media: grids of MEDIUM_GRID media; their densities and majorants */  \
    X(MANY, GridMedium,   grids,      (ds)->params.n_grids,      "density grids")          \
    X(MANY, float,        grid_data,  (ds)->n_grid_data,         "density grid values")    \
    /* the keys of moving transforms (MotionKey; the camera's: Camera.motion_first) */     \
    X(MANY, MotionKey,    motion_keys, (ds)->n_motion_keys,      "motion keys")            \
    /* per instance, its first key when it moves (INST_MOTION); none when none moves */    \
    X(MANY, uint,         instance_motion, (ds)->n_instance_motion, "instance motion")

/* Each buffer's position: SCENE_BUF_nodes ... The scene buffers are the first
 * SCENE_BUF_COUNT arguments of every kernel that takes SCENE_ARGS, in this order. */
#define SCENE_BUFFER_ENUM_(kind, Type, name, count, what) SCENE_BUF_##name,
enum { SCENE_BUFFERS(SCENE_BUFFER_ENUM_) SCENE_BUF_COUNT };
#undef SCENE_BUFFER_ENUM_

#endif /* CLPT_SCENE_BUFFERS_H */
