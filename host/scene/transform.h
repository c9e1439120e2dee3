/*
 * transform.h — affine transforms of meshes and classic-format objects, in double.
 *
 * One type for every place that moves geometry: the mesh instances of our format, the
 * Transform blocks of the classic format and the mesh sink that applies them, so that a
 * rotation or a composition is computed the same way (and rounds the same way) whichever
 * format asked for it.
 */
#ifndef CLPT_TRANSFORM_H
#define CLPT_TRANSFORM_H

#include "types.h"

/* An affine transform: p' = m[.][0..2] * p + m[.][3] (rows x, y, z). */
typedef struct { double m[3][4]; } Transform;

Transform transform_identity(void);
int transform_is_identity(const Transform *t);
/* outer after inner: (outer * inner)(p) = outer(inner(p)). */
Transform transform_compose(const Transform *outer, const Transform *inner);
Transform transform_translate(double x, double y, double z);
Transform transform_scale(double x, double y, double z);
/* Rotation by `degrees` counter-clockwise about the axis (x, y, z), which need not be
 * unit length but must not be zero (the identity is returned for a zero axis). */
Transform transform_rotate(double x, double y, double z, double degrees);
/* Determinant of the linear part. */
double transform_det(const Transform *t);
vec3 transform_point(const Transform *t, vec3 p);
/* The matrix that carries normals: the inverse transpose of the linear part (cofactors
 * over the determinant). Returns 0, leaving n alone, when the linear part is singular
 * or not finite. */
int transform_normal_matrix(const Transform *t, double n[3][3]);
/* The inverse transform; *ok 0 and the identity when the linear part is singular or
 * not finite (the inverse's entries are not checked: they may overflow). */
Transform transform_inverse(const Transform *t, int *ok);
/* The inverse transform into *inv; 0, leaving it alone, when the linear part is
 * singular or not finite. */
int transform_invert(const Transform *t, Transform *inv);

#endif /* CLPT_TRANSFORM_H */
