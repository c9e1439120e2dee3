/*
 * surface.h — from a hit record to the local geometry the shader needs: position,
 * geometric and shading normals, material, light and surface coordinates; and the
 * robust ray-origin offset that keeps a new ray from hitting the surface it leaves.
 */
#ifndef CLPT_SURFACE_H
#define CLPT_SURFACE_H

#include "util/kmath.h"
#include "geom/instance.h"
#include "geom/intersect.h"
#include "scene_view.h"

typedef struct {
    vec3 p;          /* hit position */
    vec3 err;        /* per coordinate, a bound on |p - the true surface point| (absolute);
                      * spawn_origin moves a new ray's origin off the surface by it */
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
    uint inst;       /* the instance the primitive was hit through (Hit.inst), NO_INDEX
                      * for the world's own */
    vec3 po, ngo;    /* p and ng in the primitive's own (object) space, where its (u, v)
                      * and tangents are defined; p and ng themselves outside instances */
} Surface;

/* A bound on the rounding error of n floating-point operations, relative to the
 * magnitudes they combine: pbrt's gamma(n) = n eps / (1 - n eps), eps = 2^-24 (Pharr,
 * Jakob & Humphreys, "Physically Based Rendering", 4th ed., 6.8.1), written as n times
 * a constant 0.7% above eps, which covers the denominator for any n used here. */
#define K_ROUND_ERR(n) ((float)(n) * 6.0e-8f)

KFN vec3 v3_abs(vec3 a) { return v3(k_fabs(a.x), k_fabs(a.y), k_fabs(a.z)); }

/* The hit on a sphere, projected onto it: centre + radius * n. The point o + t*d has
 * the error of t, which grows with the distance the ray came (a camera 1000 radii away
 * put it beyond any fixed offset: dark rings); the projection's error depends only on
 * the sphere, a few roundings of |centre| + radius (pbrt-v4 re-projects likewise). The
 * bound also covers what a ray leaving the surface needs: sphere_intersect reads the
 * side its origin is on from the sign of |o - centre|^2 - r^2, itself a few roundings
 * of r^2, so 8 roundings rather than pbrt's 5 for the point alone. */
KFN vec3 sphere_point(Sphere sp, vec3 n, vec3 *err)
{
    *err = v3_scale(v3_add(v3_abs(sp.center), v3s(sp.radius)), K_ROUND_ERR(8));
    return v3_madd(sp.center, n, sp.radius);
}

/* |m| v for the linear part of a 3x4 matrix (the sums of magnitudes error bounds need). */
KFN vec3 xform_abs_vector(GLOBAL const float *m, vec3 v)
{
    return v3(k_fabs(m[0]) * v.x + k_fabs(m[1]) * v.y + k_fabs(m[2]) * v.z,
              k_fabs(m[4]) * v.x + k_fabs(m[5]) * v.y + k_fabs(m[6]) * v.z,
              k_fabs(m[8]) * v.x + k_fabs(m[9]) * v.y + k_fabs(m[10]) * v.z);
}

/* The sphere's (u, v) at unit direction n from its centre (kernels/material/texture.h). */
KFN void sphere_uv(vec3 n, float *u, float *v)
{
    *u = 0.5f + k_atan2(n.x, n.z) * (1.0f / K_TWO_PI);
    *v = 1.0f - k_acos(n.y) * K_INV_PI;
}

/* The hit on an ellipsoid, in pbrt-v4's way (PBR 4th ed., 6.2.2 and 6.8.4-6.8.5): the
 * object-space hit of the same ray re-projected onto the unit sphere (n_obj, whose
 * error is sphere_point's for radius 1), carried to the world by M. The world bound
 * adds the rounding of that transform (pbrt's gamma(3) of |M| |p| plus the carried
 * error) and the rounding of M^-1 applied to a new ray's origin: sphere_xform_intersect
 * reads which side the origin is on in object space, where that rounding (4 of |M^-1|
 * |p| and the translation) would cancel an offset smaller than it; |M| of it is its
 * size in the world, and a world offset along the normal by this bound moves the
 * object-space origin along its normal by at least as much (the normal matrix is
 * M^-T). Returns the world point; *n_obj is the object-space unit normal. */
KFN vec3 sphere_xform_point(GLOBAL const SphereXform *x, Ray ray, float t, vec3 *n_obj, vec3 *err)
{
    Ray r = sphere_xform_ray(x, ray);
    vec3 n = v3_norm(v3_madd(r.o, r.d, t));
    GLOBAL const float *m = x->to_world, *mi = x->to_object;
    vec3 p = xform_point(m, n);
    vec3 trans = v3(k_fabs(m[3]), k_fabs(m[7]), k_fabs(m[11]));
    vec3 trans_i = v3(k_fabs(mi[3]), k_fabs(mi[7]), k_fabs(mi[11]));
    vec3 fwd = v3_scale(v3_add(xform_abs_vector(m, v3_abs(n)), trans), K_ROUND_ERR(3));
    vec3 carried = v3_scale(xform_abs_vector(m, v3s(K_ROUND_ERR(8))), 1.0f + K_ROUND_ERR(3));
    vec3 back = v3_scale(v3_add(xform_abs_vector(mi, v3_abs(p)), trans_i), K_ROUND_ERR(4));
    *err = v3_add(v3_add(fwd, carried), xform_abs_vector(m, back));
    *n_obj = n;
    return p;
}

/* The unit world normal of an ellipsoid at object normal n: M^-T n (the transpose of
 * to_object's linear part). */
KFN vec3 sphere_xform_normal(GLOBAL const SphereXform *x, vec3 n)
{
    GLOBAL const float *mi = x->to_object;
    return v3_norm(v3(mi[0] * n.x + mi[4] * n.y + mi[8] * n.z, mi[1] * n.x + mi[5] * n.y + mi[9] * n.z,
                      mi[2] * n.x + mi[6] * n.y + mi[10] * n.z));
}

/* The error of p = w p0 + u p1 + v p2 (pbrt-v4: gamma(7) of the sum of the terms'
 * magnitudes), plus what the watertight test needs to see that a ray leaving the
 * triangle starts off it: its t is a sum of products of the corners' offsets from the
 * origin, whose rounding is a few ulps of the triangle's extent, whatever the angle
 * (the offset and t both scale with 1 / cos). Without that term a triangle far larger
 * than its distance from the world origin (a disk of radius 1e15 about it) would hit
 * the rays that leave it. */
KFN vec3 triangle_point_error(Triangle tr, float w, float u, float v, vec3 p)
{
    vec3 sum = v3_add(v3_add(v3_abs(v3_scale(tr.p0, w)), v3_abs(v3_scale(tr.p1, u))), v3_abs(v3_scale(tr.p2, v)));
    vec3 e0 = v3_abs(v3_sub(tr.p0, p)), e1 = v3_abs(v3_sub(tr.p1, p)), e2 = v3_abs(v3_sub(tr.p2, p));
    float extent = k_fmax(v3_max_comp(e0), k_fmax(v3_max_comp(e1), v3_max_comp(e2)));
    return v3_add(v3_scale(sum, K_ROUND_ERR(7)), v3s(K_ROUND_ERR(16) * extent));
}

/* The hit on box face `face` with its coordinate along the face's axis set to the
 * face's plane, exactly; the other two keep o + t*d's error, which along the face
 * normal does not count. box_intersect's slab test then sees any origin beyond the
 * plane, however little, on the outer side. */
KFN vec3 box_point(Box b, int face, vec3 p, float t, Ray ray, vec3 *err)
{
    int axis = face >> 1;
    float plane = v3_get((face & 1) ? b.hi : b.lo, axis);
    vec3 e = v3_scale(v3_add(v3_abs(ray.o), v3_abs(v3_scale(ray.d, t))), K_ROUND_ERR(4));
    *err = v3(axis == 0 ? 0.0f : e.x, axis == 1 ? 0.0f : e.y, axis == 2 ? 0.0f : e.z);
    return v3(axis == 0 ? plane : p.x, axis == 1 ? plane : p.y, axis == 2 ? plane : p.z);
}

/* The hit projected onto the plane: o + t*d's error along the normal grows with the
 * distance the ray came, the projection's is a few roundings of dot(|n|, |p|) and the
 * offset; 12 of them also cover plane_intersect's own rounding of offset - dot(n, o)
 * for a ray that leaves. (For an axis-aligned plane the projection is exact.) */
KFN vec3 plane_point(Plane pl, vec3 p, vec3 *err)
{
    vec3 q = v3_madd(p, pl.normal, -(v3_dot(pl.normal, p) - pl.offset));
    float scale = v3_dot(v3_abs(pl.normal), v3_abs(q)) + k_fabs(pl.offset);
    *err = v3s(K_ROUND_ERR(12) * scale);
    return q;
}

/* The error of the hit o + t*d on a surface of revolution: Newton polishes t to the
 * rounding of floats, a few ulps of |t| and of the surface's size; and a point within
 * REV_RESIDUAL of the surface passes revsurface_intersect's root test, so a ray must
 * leave from farther than that or its own origin could count as a hit. */
KFN vec3 revsurface_point_error(RevSurface rs, Ray ray, float t)
{
    float size = k_fmax(rs.hi.x - rs.lo.x, rs.hi.y - rs.lo.y);
    vec3 e = v3_scale(v3_add(v3_abs(ray.o), v3_abs(v3_scale(ray.d, t))), K_ROUND_ERR(8));
    return v3_add(e, v3s((K_ROUND_ERR(8) + 4.0f * REV_RESIDUAL) * size));
}

/* The unit winding normal (p1 - p0) x (p2 - p0). Past about 1e19 in area its squared
 * length overflows float, and the normal became 0 * inf = NaN: a pbrt disk of radius
 * 1e11 (a fan of 64 such triangles) rendered black. Scaling the cross product by 2^-64
 * first (exact) keeps it finite; the usual case is computed as before. */
#define TRI_NORMAL_SCALE 5.421010862427522e-20f   /* 2^-64 */
KFN vec3 triangle_normal(Triangle tr)
{
    vec3 c = v3_cross(v3_sub(tr.p1, tr.p0), v3_sub(tr.p2, tr.p0));
    if (!(v3_dot(c, c) < K_INF)) c = v3_scale(c, TRI_NORMAL_SCALE);
    return v3_norm(c);
}

/* The surface of hit `hit` on a primitive in the space of `ray` (the world's, or an
 * instance's object space: surface_at). */
KFN Surface surface_local(const SceneView *sc, Ray ray, Hit hit)
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
        if (KF_HAS(KF_SPHERE_XFORM) && sp.xform != 0u) {
            /* (u, v) follow the object space's parameterisation */
            GLOBAL const SphereXform *x = &sc->sphere_xforms[sp.xform - 1u];
            vec3 n_obj;
            s.p = sphere_xform_point(x, ray, hit.t, &n_obj, &s.err);
            s.ng = sphere_xform_normal(x, n_obj);
            sphere_uv(n_obj, &s.u, &s.v);
        } else {
            vec3 n = v3_norm(v3_sub(s.p, sp.center));
            s.p = sphere_point(sp, n, &s.err);
            s.ng = n;
        }
        s.ns = s.ng;
        s.material = sp.material;
        s.light = sp.light;
    } else if (id < first_box) {
        Triangle tr = sc->triangles[id - first_tri];
        float w = 1.0f - hit.u - hit.v;
        /* barycentric interpolation is far more precise than o + t*d for a far hit */
        s.p = v3_add(v3_add(v3_scale(tr.p0, w), v3_scale(tr.p1, hit.u)), v3_scale(tr.p2, hit.v));
        s.err = triangle_point_error(tr, w, hit.u, hit.v, s.p);
        s.ng = triangle_normal(tr);
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
        s.p = box_point(b, face, s.p, hit.t, ray, &s.err);
        s.ng = v3(axis == 0 ? sign : 0.0f, axis == 1 ? sign : 0.0f, axis == 2 ? sign : 0.0f);
        s.ns = s.ng;
        s.material = b.material;
        s.light = b.light;
    } else if (KF_HAS(KF_REVSURFACE) && id < first_plane) {
        /* (u, v) become the angle around the axis (0..1 from +x towards +z, as the
         * course's revolution turns) and the segment's parameter */
        RevSurface rs = sc->revsurfaces[id - first_rev];
        vec3 n = revsurface_normal(rs, sc->rev_points, s.p, hit.u, hit.v);
        s.err = revsurface_point_error(rs, ray, hit.t);
        s.ng = n;
        s.ns = n;
        s.material = rs.material;
        float a = k_atan2(s.p.z - rs.axis_z, s.p.x - rs.axis_x) * (1.0f / K_TWO_PI);
        s.u = a < 0.0f ? a + 1.0f : a;
        s.v = hit.u;
    } else {
        Plane pl = sc->planes[id - first_plane];
        s.p = plane_point(pl, s.p, &s.err);
        s.ng = pl.normal;
        s.ns = pl.normal;
        s.material = pl.material;
    }
    s.inst = NO_INDEX;
    s.po = s.p;
    s.ngo = s.ng;
    return s;
}

/* The rounding error of p = M po for an instance (PBR 4th ed., 6.8.5, as
 * sphere_xform_point): the transform's own rounding (gamma(3) of |M| |po| and the
 * translation), po's bound err_o carried by |M|, and the rounding of M^-1 applied to a
 * new ray's origin, since the walk decides which side of a primitive that origin is on
 * in object space (4 roundings of |M^-1| |p| and its translation), as large in the
 * world as |M| makes it. M and M^-1 are m and mi, in private memory: a moving
 * instance's at the path's time, or a static one's copied (instance_point_error). */
KFN_INLINE vec3 instance_point_error_by(const float *m, const float *mi, vec3 po, vec3 err_o, vec3 p)
{
    vec3 trans = v3(k_fabs(m[3]), k_fabs(m[7]), k_fabs(m[11]));
    vec3 trans_i = v3(k_fabs(mi[3]), k_fabs(mi[7]), k_fabs(mi[11]));
    vec3 fwd = v3_scale(v3_add(motion_abs_vector(m, v3_abs(po)), trans), K_ROUND_ERR(3));
    vec3 carried = v3_scale(motion_abs_vector(m, err_o), 1.0f + K_ROUND_ERR(3));
    vec3 back = v3_scale(v3_add(motion_abs_vector(mi, v3_abs(p)), trans_i), K_ROUND_ERR(4));
    return v3_add(v3_add(fwd, carried), motion_abs_vector(m, back));
}

/* instance_point_error_by for a static instance x: its M and M^-1 copied out of global
 * memory, since an OpenCL C 1.2 function takes one address space per pointer (moving
 * instances' M and M^-1 are computed into private memory). */
KFN vec3 instance_point_error(GLOBAL const Instance *x, vec3 po, vec3 err_o, vec3 p)
{
    float m[12], mi[12];
    for (int k = 0; k < 12; k++) {
        m[k] = x->to_world[k];
        mi[k] = x->to_object[k];
    }
    return instance_point_error_by(m, mi, po, err_o, p);
}

/* surface_instanced's carrying to the world for a moving instance: by its M and M^-1
 * at the path's time (geom/instance.h). */
KFN Surface surface_moving_to_world(const SceneView *sc, uint inst, Surface s)
{
    float m[12], mi[12];
    instance_moving_at(sc, inst, m, mi);
    s.p = motion_point(m, s.po);
    s.err = instance_point_error_by(m, mi, s.po, s.err, s.p);
    vec3 ng = instance_normal_moving(mi, s.ngo);
    vec3 ns = instance_normal_moving(mi, s.ns);
    s.ng = ng;
    s.ns = v3_dot(ns, ng) < 0.0f ? v3_neg(ns) : ns;
    return s;
}

/* The surface of a hit through instance hit.inst: found in its object space with the
 * walk's own object-space ray, then carried to the world (position by M, normals by
 * M^-T, the error bound by instance_point_error). The instance's material replaces the
 * primitive's when it names one. M^-T keeps every normal on its side under a mirroring
 * M too, as a mirrored mesh block keeps its triangles' outward sides (its loader swaps
 * two corners; scene_flatten_instances does the same). A prototype's emissive triangle
 * holds its index among its object's emitters as its `light`: the instance's lights
 * start at instance_lights[inst] (types.h, LIGHT_INSTANCED), so that MIS weighs the
 * emission that BSDF sampling finds with the density light sampling had for it. */
KFN Surface surface_instanced(const SceneView *sc, Ray ray, Hit hit)
{
    GLOBAL const Instance *x = sc->instances + hit.inst;
    Surface s = surface_local(sc, instance_ray_seen(sc, hit.inst, x, ray), hit);
    s.inst = hit.inst;
    if (s.light != NO_INDEX) {
        uint first = sc->instance_lights[hit.inst];
        s.light = first == NO_INDEX ? NO_INDEX : first + s.light;
    }
    if (x->material != NO_INDEX) s.material = x->material;
    if (INSTANCE_MOVES(x)) return surface_moving_to_world(sc, hit.inst, s);
    if (x->flags & INST_IDENTITY) return s;
    s.p = xform_point(x->to_world, s.po);
    s.err = instance_point_error(x, s.po, s.err, s.p);
    vec3 ng = instance_normal(x, s.ngo);
    vec3 ns = instance_normal(x, s.ns);
    s.ng = ng;
    s.ns = v3_dot(ns, ng) < 0.0f ? v3_neg(ns) : ns;
    return s;
}

/* Whether s (a Surface or Hit) was found through an instance. A scene without
 * instances answers no whatever inst holds, so a hit made by hand (the tests') needs
 * no instance. */
#define SURFACE_INSTANCED(sc, s) (KF_HAS(KF_INSTANCES) && (s).inst != NO_INDEX && (sc)->params->n_instances != 0u)

/* The material of primitive `prim` as stored (in its object's space: an instance may
 * replace it, hit_material). */
KFN uint prim_material(const SceneView *sc, uint prim)
{
    GLOBAL const RenderParams *p = sc->params;
    uint first_tri = p->n_spheres, first_box = first_tri + p->n_triangles;
    uint first_rev = first_box + p->n_boxes, first_plane = first_rev + p->n_revsurfaces;
    if (prim < first_tri) return sc->spheres[prim].material;
    if (prim < first_box) return sc->triangles[prim - first_tri].material;
    if (prim < first_rev) return sc->boxes[prim - first_box].material;
    if (prim < first_plane) return sc->revsurfaces[prim - first_rev].material;
    return sc->planes[prim - first_plane].material;
}

/* The material a hit shows: its primitive's, or its instance's where that replaces it,
 * as surface_at gives it, without the rest of the surface. Every query that decides by
 * the material alone (cut-outs, a shadow ray's boundaries) asks this, so that it sees
 * what the path sees. */
KFN uint hit_material(const SceneView *sc, Hit hit)
{
    if (SURFACE_INSTANCED(sc, hit) && sc->instances[hit.inst].material != NO_INDEX)
        return sc->instances[hit.inst].material;
    return prim_material(sc, hit.prim);
}

/* The surface at a hit of ray (world space). */
KFN Surface surface_at(const SceneView *sc, Ray ray, Hit hit)
{
    if (SURFACE_INSTANCED(sc, hit)) return surface_instanced(sc, ray, hit);
    return surface_local(sc, ray, hit);
}

/* surface_at(sc, ray, hit).ng, the same bits: for a triangle outside any instance (a
 * medium's boundary, mostly) its winding normal alone, without the point, its error
 * bound, the shading normal and the texture coordinates that a shadow ray crossing the
 * boundary has no use for. */
KFN vec3 hit_geometric_normal(const SceneView *sc, Ray ray, Hit hit)
{
    uint first_tri = sc->params->n_spheres;
    if (!SURFACE_INSTANCED(sc, hit) && hit.prim >= first_tri && hit.prim - first_tri < sc->params->n_triangles)
        return triangle_normal(sc->triangles[hit.prim - first_tri]);
    return surface_at(sc, ray, hit).ng;
}

/* An object-space vector of surface s (a tangent) in the world: M v through its
 * instance, v itself outside one. */
KFN vec3 surface_vector_to_world(const SceneView *sc, Surface s, vec3 v)
{
    if (!SURFACE_INSTANCED(sc, s)) return v;
    GLOBAL const Instance *x = sc->instances + s.inst;
    if (INSTANCE_MOVES(x)) {
        float m[12], mi[12];
        instance_moving_at(sc, s.inst, m, mi);
        return motion_vector(m, v);
    }
    return (x->flags & INST_IDENTITY) ? v : xform_vector(x->to_world, v);
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

/* The per-vertex attribute `which` (EXTRA_UV1: 2 floats, EXTRA_COLOR or
 * EXTRA_TANGENT: 4) at s, into out; 0 where the surface has none. */
KFN int surface_extra_at(const SceneView *sc, Surface s, uint which, float *out)
{
    GLOBAL const TriExtra *e = surface_extra(sc, s, which);
    if (!e) return 0;
    if (which == EXTRA_UV1) extra_lerp(&e->uv[0][0], 2u, 2u, s, out);
    else if (which == EXTRA_COLOR) extra_lerp(&e->color[0][0], 4u, 4u, s, out);
    else extra_lerp(&e->tangent[0][0], 4u, 4u, s, out);
    return 1;
}

/* The second uv set (TEXCOORD_1) at s; 0 where the surface has none. */
KFN int surface_uv1(const SceneView *sc, Surface s, float *u, float *v)
{
    float uv[2];
    if (!surface_extra_at(sc, s, EXTRA_UV1, uv)) return 0;
    *u = uv[0];
    *v = uv[1];
    return 1;
}

/* The vertex colour (COLOR_0, linear RGBA) at s; 0 where the surface has none. */
KFN int surface_color(const SceneView *sc, Surface s, float *rgba) { return surface_extra_at(sc, s, EXTRA_COLOR, rgba); }

/* The given tangent (TANGENT) at s, not normalised, and its bitangent sign (+1 or -1,
 * the sign of the interpolated w); 0 where the surface has none. */
KFN int surface_tangent(const SceneView *sc, Surface s, vec3 *t, float *sign)
{
    float q[4];
    if (!surface_extra_at(sc, s, EXTRA_TANGENT, q)) return 0;
    *t = v3(q[0], q[1], q[2]);
    *sign = q[3] < 0.0f ? -1.0f : 1.0f;
    return 1;
}

/* How far spawn_offset moves a point along its unit normal n: the point's error
 * along n, dot(|n|, err), so that the origin is off the surface whatever the
 * rounding put it; plus 2^-20 of dot(|n|, |p|) and of that distance, which cover
 * the rounding of p + n * distance (half an ulp per coordinate, 2^-24 of it) with
 * room to spare, and 2^-100 so that a point at the origin moves too. After pbrt-v4's
 * OffsetRayOrigin (Pharr, Jakob & Humphreys, PBR 4th ed., 6.8.6), which pushes each
 * coordinate one float further instead of the relative margin; the margin needs no
 * bit arithmetic, so kernels/integrator/shade_lanes.h repeats it lane by lane as written. The
 * earlier offset, a fixed 256 ulps of each coordinate (Wächter & Binder, Ray Tracing
 * Gems ch. 6), did not follow the error: it fell short for a sphere seen from 1000
 * radii (dark rings) and was 15% of a sphere 1e-4 across, whose coordinates are near
 * 0 where it became a fixed 1.5e-5. */
#define SPAWN_MARGIN 9.5367431640625e-07f   /* 2^-20 */
#define SPAWN_FLOOR 7.888609052210118e-31f  /* 2^-100 */
KFN float spawn_distance(vec3 p, vec3 err, vec3 n)
{
    vec3 an = v3_abs(n);
    float d = v3_dot(an, err);
    return d + SPAWN_MARGIN * (v3_dot(an, v3_abs(p)) + d) + SPAWN_FLOOR;
}

/* A point just off the surface at p (error bound err) on the side unit vector n
 * points to: where a ray leaving the surface there starts. */
KFN vec3 spawn_offset(vec3 p, vec3 err, vec3 n)
{
    return v3_madd(p, n, spawn_distance(p, err, n));
}

/* The origin of a ray leaving surface s on the side of its geometric normal n (either
 * way round: the face the ray leaves through). */
KFN vec3 spawn_origin(Surface s, vec3 n)
{
    return spawn_offset(s.p, s.err, n);
}

#endif /* CLPT_SURFACE_H */
