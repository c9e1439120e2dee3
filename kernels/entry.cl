/*
 * entry.cl — every __kernel of clpt. Each is a thin wrapper: it reads its work index,
 * gathers the scene buffers into a SceneView and calls the per-path stage functions of
 * raygen.cl, traverse.cl, shade.cl and film.cl, which the scalar C device calls too.
 * Queueing (which paths are still alive) happens here, not in the stage functions.
 */
#include "types.h"

/* Writes sizeof and offsetof of the shared structs, for the host to compare with its
 * own layout (tests/test_kernels.c): a mismatch would silently corrupt every buffer. */
__kernel void k_layout(__global uint *out)
{
    if (get_global_id(0) != 0) return;
    uint i = 0;
    out[i++] = (uint)sizeof(vec3);
    out[i++] = (uint)sizeof(Ray);
    out[i++] = (uint)sizeof(Hit);
    out[i++] = (uint)sizeof(KdNode);
    out[i++] = (uint)sizeof(Sphere);
    out[i++] = (uint)sizeof(Triangle);
    out[i++] = (uint)sizeof(TriShading);
    out[i++] = (uint)sizeof(Box);
    out[i++] = (uint)sizeof(Plane);
    out[i++] = (uint)sizeof(Material);
    out[i++] = (uint)sizeof(Light);
    out[i++] = (uint)sizeof(Camera);
    out[i++] = (uint)sizeof(RenderParams);
    out[i++] = (uint)sizeof(PathState);
    out[i++] = (uint)offsetof(RenderParams, bg_color);
    out[i++] = (uint)offsetof(RenderParams, width);
    out[i++] = (uint)offsetof(RenderParams, bounds_lo);
    out[i++] = (uint)offsetof(PathState, bsdf_pdf);
    out[i++] = (uint)offsetof(Material, albedo);
    out[i++] = (uint)offsetof(Light, position);
    out[i++] = (uint)offsetof(Camera, lens_u);
    out[i++] = (uint)offsetof(TriShading, uv0);
}
