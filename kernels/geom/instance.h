/*
 * instance.h -- rays into an instance's object space, and a surface found there carried
 * back to the world (docs/instancing.md).
 *
 * The ray's origin and direction are both mapped by M^-1 and the direction is not
 * renormalised, so the map is affine along the ray and a point's t is the same in both
 * spaces: hits of different instances, and of the world's own primitives, compare by t
 * as they are (the tie rule in accel/leaf.h). The same function serves the walk and
 * surface_at, so a surface is computed from the very object-space ray its hit was
 * found with.
 */
#ifndef CLPT_GEOM_INSTANCE_H
#define CLPT_GEOM_INSTANCE_H

#include "geom/intersect.h"
#include "geom/motion.h"
#include "scene_view.h"

/* The world ray in instance x's object space (unchanged for the identity). */
KFN Ray instance_ray(GLOBAL const Instance *x, Ray ray)
{
    if (x->flags & INST_IDENTITY) return ray;
    Ray r = ray;
    r.o = xform_point(x->to_object, ray.o);
    r.d = xform_vector(x->to_object, ray.d);
    return r;
}

/* The object-space vector n as a world normal: M^-T n, the transpose of to_object's
 * linear part, normalised. Normals of a non-uniform scale bend the other way from the
 * surface's tangents, which is why they are not mapped by M. */
KFN vec3 instance_normal(GLOBAL const Instance *x, vec3 n)
{
    GLOBAL const float *mi = x->to_object;
    return v3_norm(v3(mi[0] * n.x + mi[4] * n.y + mi[8] * n.z, mi[1] * n.x + mi[5] * n.y + mi[9] * n.z,
                      mi[2] * n.x + mi[6] * n.y + mi[10] * n.z));
}

/* ------------------------------------------------------------------ moving instances
 * An instance flagged INST_MOTION (docs/motion.md) has no one M: the path's time
 * (SceneView.time) picks it from the instance's keys (geom/motion.h), and the walk and
 * surface_at compute it the same way, so a surface is found from the very ray the walk
 * used. Its record's matrices (the first key's pose) are not read. */

/* Whether instance x moves (only a program with KF_MOTION has such instances). */
#define INSTANCE_MOVES(x) (KF_HAS(KF_MOTION) && ((x)->flags & INST_MOTION) != 0u)

/* Moving instance i's M and M^-1 at the path's time. */
KFN void instance_moving_at(const SceneView *sc, uint i, float *m, float *mi)
{
    motion_instance_at(sc->motion_keys + sc->instance_motion[i], sc->time, m, mi);
}

/* The world ray in the object space of instance i (x, its record) as the path sees it:
 * instance_ray, or by a moving instance's M^-1 at the path's time. */
KFN Ray instance_ray_seen(const SceneView *sc, uint i, GLOBAL const Instance *x, Ray ray)
{
    if (!INSTANCE_MOVES(x)) return instance_ray(x, ray);
    float m[12], mi[12];
    instance_moving_at(sc, i, m, mi);
    Ray r = ray;
    r.o = motion_point(mi, ray.o);
    r.d = motion_vector(mi, ray.d);
    return r;
}

/* instance_normal for a moving instance's M^-1 (mi, private). */
KFN vec3 instance_normal_moving(const float *mi, vec3 n)
{
    return v3_norm(v3(mi[0] * n.x + mi[4] * n.y + mi[8] * n.z, mi[1] * n.x + mi[5] * n.y + mi[9] * n.z,
                      mi[2] * n.x + mi[6] * n.y + mi[10] * n.z));
}

#endif /* CLPT_GEOM_INSTANCE_H */
