/* dvec3.h — three doubles, for the host's camera frames: computed in double and rounded
 * to float once, so every device starts from the same float values. */
#ifndef CLPT_DVEC3_H
#define CLPT_DVEC3_H

#include "types.h"

#include <math.h>

typedef struct { double x, y, z; } dvec3;

static inline dvec3 dv3_of(vec3 a) { dvec3 r = { a.x, a.y, a.z }; return r; }
static inline vec3 dv3_to_float(dvec3 a) { vec3 r = { (float)a.x, (float)a.y, (float)a.z }; return r; }
static inline dvec3 dv3_add(dvec3 a, dvec3 b) { dvec3 r = { a.x + b.x, a.y + b.y, a.z + b.z }; return r; }
static inline dvec3 dv3_sub(dvec3 a, dvec3 b) { dvec3 r = { a.x - b.x, a.y - b.y, a.z - b.z }; return r; }
static inline dvec3 dv3_scale(dvec3 a, double s) { dvec3 r = { a.x * s, a.y * s, a.z * s }; return r; }
static inline double dv3_dot(dvec3 a, dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static inline dvec3 dv3_cross(dvec3 a, dvec3 b)
{
    dvec3 r = { a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
    return r;
}

/* a / |a|, or a itself where it has no length. */
static inline dvec3 dv3_norm(dvec3 a)
{
    double l = sqrt(dv3_dot(a, a));
    return l > 0.0 ? dv3_scale(a, 1.0 / l) : a;
}

#endif /* CLPT_DVEC3_H */
