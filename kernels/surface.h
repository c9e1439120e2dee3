/*
 * surface.h — from a hit record to the local geometry the shader needs: position,
 * geometric and shading normals, material, light and surface coordinates; and the
 * robust ray-origin offset that keeps a new ray from hitting the surface it leaves.
 */
#ifndef CLPT_SURFACE_H
#define CLPT_SURFACE_H

#include "kmath.h"
#include "intersect.h"
#include "scene_view.h"

typedef struct {
    vec3 p;          /* hit position */
    vec3 ng;         /* geometric normal, unit, outward (sphere, box) or by winding */
    vec3 ns;         /* shading normal, unit, on the same side as ng */
    uint material;
    uint light;      /* index in lights[] or NO_INDEX */
    uint prim;       /* global primitive id (textures compute their coordinates from it) */
    float u, v;      /* surface coordinates (triangle barycentrics or texture uv) */
    uint extra;      /* triangles: index in tri_extras (TANGENT, TEXCOORD_1, COLOR_0) or
                      * NO_INDEX; read only through the surface_* functions below */
    float b1, b2;    /* triangles: the hit's barycentrics of p1 and p2, to interpolate
                      * the extras' corners */
} Surface;

KFN Surface surface_at(const SceneView *sc, Ray ray, Hit hit)
{
    GLOBAL const RenderParams *p = sc->params;
    Surface s;
    uint id = hit.prim;
    s.p = v3_madd(ray.o, ray.d, hit.t);
    s.u = hit.u;
    s.v = hit.v;
    s.light = NO_INDEX;
    s.prim = id;
    s.extra = NO_INDEX;
    s.b1 = hit.u;
    s.b2 = hit.v;
    uint first_tri = p->n_spheres, first_box = first_tri + p->n_triangles;
    uint first_rev = first_box + p->n_boxes, first_plane = first_rev + p->n_revsurfaces;
    if (KF_HAS(KF_SPHERES) && id < first_tri) {
        Sphere sp = sc->spheres[id];
        /* p stays o + t*d: projecting it onto the sphere (center + r*n) would round it to
         * the precision of the centre's coordinates, 6e-5 for the One-Weekend ground
         * (r = 1000 at y = -1000), far coarser than the error of t, and the surface
         * would shadow itself in rings */
        vec3 n = v3_norm(v3_sub(s.p, sp.center));
        s.ng = n;
        s.ns = n;
        s.material = sp.material;
        s.light = sp.light;
    } else if (id < first_box) {
        Triangle tr = sc->triangles[id - first_tri];
        float w = 1.0f - hit.u - hit.v;
        /* barycentric interpolation is far more precise than o + t*d for a far hit */
        s.p = v3_add(v3_add(v3_scale(tr.p0, w), v3_scale(tr.p1, hit.u)), v3_scale(tr.p2, hit.v));
        s.ng = v3_norm(v3_cross(v3_sub(tr.p1, tr.p0), v3_sub(tr.p2, tr.p0)));
        s.ns = s.ng;
        s.material = tr.material;
        s.light = tr.light;
        if (tr.shading != NO_INDEX) {
            TriShading sh = sc->shading[tr.shading];
            if (sh.flags & TRI_HAS_NORMALS) {
                vec3 n = v3_add(v3_add(v3_scale(sh.n0, w), v3_scale(sh.n1, hit.u)), v3_scale(sh.n2, hit.v));
                float len = v3_len(n);
                if (len > 0.0f) {
                    n = v3_scale(n, 1.0f / len);
                    s.ns = v3_dot(n, s.ng) < 0.0f ? v3_neg(n) : n;
                }
            }
            if (sh.flags & TRI_HAS_UV) {
                s.u = w * sh.uv0[0] + hit.u * sh.uv1[0] + hit.v * sh.uv2[0];
                s.v = w * sh.uv0[1] + hit.u * sh.uv1[1] + hit.v * sh.uv2[1];
            }
            if (sh.flags & TRI_HAS_EXTRA) s.extra = sc->tri_extra_of[tr.shading];
        }
    } else if (KF_HAS(KF_BOXES) && id < first_rev) {
        Box b = sc->boxes[id - first_box];
        int face = (int)hit.u;                    /* 0:-x 1:+x 2:-y 3:+y 4:-z 5:+z */
        float sign = (face & 1) ? 1.0f : -1.0f;
        int axis = face >> 1;
        s.ng = v3(axis == 0 ? sign : 0.0f, axis == 1 ? sign : 0.0f, axis == 2 ? sign : 0.0f);
        s.ns = s.ng;
        s.material = b.material;
        s.light = b.light;
    } else if (KF_HAS(KF_REVSURFACE) && id < first_plane) {
        /* (u, v) become the angle around the axis (0..1 from +x towards +z, as the
         * course's revolution turns) and the segment's parameter */
        RevSurface rs = sc->revsurfaces[id - first_rev];
        vec3 n = revsurface_normal(rs, sc->rev_points, s.p, hit.u, hit.v);
        s.ng = n;
        s.ns = n;
        s.material = rs.material;
        float a = k_atan2(s.p.z - rs.axis_z, s.p.x - rs.axis_x) * (1.0f / K_TWO_PI);
        s.u = a < 0.0f ? a + 1.0f : a;
        s.v = hit.u;
    } else {
        Plane pl = sc->planes[id - first_plane];
        s.ng = pl.normal;
        s.ns = pl.normal;
        s.material = pl.material;
    }
    return s;
}

/* Corner attribute `a` (three corners of `n` floats, `stride` apart) at s's
 * barycentrics, into out[0 .. n), weighted as surface_at weights the normals. */
KFN void extra_lerp(GLOBAL const float *a, uint stride, uint n, Surface s, float *out)
{
    float w = 1.0f - s.b1 - s.b2;
    for (uint j = 0u; j < n; j++) out[j] = w * a[j] + s.b1 * a[stride + j] + s.b2 * a[2u * stride + j];
}

/* The extras of s that have all of `flags` (EXTRA_*), or NULL. */
KFN GLOBAL const TriExtra *surface_extra(const SceneView *sc, Surface s, uint flags)
{
    if (s.extra == NO_INDEX) return 0;
    GLOBAL const TriExtra *e = sc->tri_extras + s.extra;
    return (e->flags & flags) == flags ? e : 0;
}

/* The second uv set (TEXCOORD_1) at s; 0 where the surface has none. */
KFN int surface_uv1(const SceneView *sc, Surface s, float *u, float *v)
{
    GLOBAL const TriExtra *e = surface_extra(sc, s, EXTRA_UV1);
    if (!e) return 0;
    float uv[2];
    extra_lerp(&e->uv[0][0], 2u, 2u, s, uv);
    *u = uv[0];
    *v = uv[1];
    return 1;
}

/* The vertex colour (COLOR_0, linear RGBA) at s; 0 where the surface has none. */
KFN int surface_color(const SceneView *sc, Surface s, float *rgba)
{
    GLOBAL const TriExtra *e = surface_extra(sc, s, EXTRA_COLOR);
    if (!e) return 0;
    extra_lerp(&e->color[0][0], 4u, 4u, s, rgba);
    return 1;
}

/* The given tangent (TANGENT) at s, not normalised, and its bitangent sign (+1 or -1,
 * the sign of the interpolated w); 0 where the surface has none. */
KFN int surface_tangent(const SceneView *sc, Surface s, vec3 *t, float *sign)
{
    GLOBAL const TriExtra *e = surface_extra(sc, s, EXTRA_TANGENT);
    if (!e) return 0;
    float q[4];
    extra_lerp(&e->tangent[0][0], 4u, 4u, s, q);
    *t = v3(q[0], q[1], q[2]);
    *sign = q[3] < 0.0f ? -1.0f : 1.0f;
    return 1;
}

/* A point just off the surface at p on the side n points to. The offset is a fixed
 * number of float ulps of p (integer arithmetic on the bit pattern), so it scales with
 * the magnitude of the coordinates instead of a global epsilon; near the origin, where
 * ulps vanish, a small absolute offset takes over. After Wächter & Binder, "A Fast and
 * Robust Method for Avoiding Self-Intersection", Ray Tracing Gems, ch. 6 (2019). */
#define RAY_OFFSET_ULPS 256.0f           /* ulps along a unit normal, away from 0 ... */
#define RAY_OFFSET_NEAR_ZERO 0.03125f     /* ... except within this of 0, where ... */
#define RAY_OFFSET_ABS 1.52587890625e-5f  /* ... it moves this far (kernels/shade_lanes.cl too) */
KFN float offset_coord(float p, float n)
{
    int ulps = (int)(RAY_OFFSET_ULPS * n);
    float moved = k_int_as_float(k_as_int(p) + (p < 0.0f ? -ulps : ulps));
    return k_fabs(p) < RAY_OFFSET_NEAR_ZERO ? p + RAY_OFFSET_ABS * n : moved;
}

KFN vec3 offset_ray_origin(vec3 p, vec3 n)
{
    return v3(offset_coord(p.x, n.x), offset_coord(p.y, n.y), offset_coord(p.z, n.z));
}

#endif /* CLPT_SURFACE_H */
