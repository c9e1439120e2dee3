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

#endif /* CLPT_GEOM_INSTANCE_H */
