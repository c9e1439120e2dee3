/*
 * mesh.h — what the mesh readers (obj.c, ply.c) share: the instance transform, the sink
 * that turns a reader's triangles into scene triangles and shading records, loading a
 * mesh file by its extension, and fast exact number parsing.
 *
 * A reader hands the sink triangles in the file's own coordinates; the sink applies the
 * instance transform (positions by the affine matrix, normals by its inverse transpose,
 * in double, rounded once to float), swaps two corners when the transform mirrors so
 * that the winding normal keeps pointing to the same side of the surface, and appends
 * the triangle (and a TriShading record when the corners carry normals or texture
 * coordinates) to the scene. docs/meshes.md describes the formats and the materials.
 */
#ifndef CLPT_MESH_H
#define CLPT_MESH_H

#include "scene/scene.h"

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

typedef struct {
    /* Material of every triangle, or NO_INDEX to take the materials the file names (an
     * OBJ's MTL files); faces that name none then get default_material, which is a
     * neutral diffuse material added on first use when it is NO_INDEX too. */
    uint material;
    uint default_material;
    Transform xf;
} MeshOptions;

/* Every triangle gets `material` (NO_INDEX: the file's own), no transform. */
MeshOptions mesh_options(uint material);

/* The neutral grey of a mesh that names no material. */
#define MESH_DEFAULT_ALBEDO 0.75f

typedef struct {
    Scene *s;
    Error *err;
    const char *path;            /* the mesh file, for messages */
    Transform xf;
    double nxf[3][3];            /* inverse transpose of xf's linear part */
    int transformed, mirrored;
    size_t first_triangle;       /* the scene's triangle count when the sink opened */
} MeshSink;

/* Fails (ST_INPUT) when the transform is singular or not finite. */
Status mesh_sink_open(MeshSink *k, Scene *s, const Transform *xf, const char *path, Error *err);
/* Makes room for `triangles` more triangles and `shading` more shading records, so a
 * reader that knows its counts grows the arrays once. */
Status mesh_sink_reserve(MeshSink *k, size_t triangles, size_t shading);
/* Appends one triangle. n: three unit normals or NULL; uv: three (u, v) pairs or NULL.
 * A normal that comes out zero (or not finite) after the transform drops the normals of
 * that triangle. */
Status mesh_sink_triangle(MeshSink *k, const vec3 p[3], const vec3 *n, const float *uv,
                          uint material);

/* Loads an OBJ (".obj") or PLY (".ply") file, by its extension in any case, appending
 * its triangles to the scene. ST_INPUT for any other extension. */
Status mesh_load(const char *path, Scene *s, const MeshOptions *o, Error *err);

typedef enum { MESH_NONE = 0, MESH_OBJ, MESH_PLY } MeshKind;
MeshKind mesh_kind(const char *path);

/* A closed, bumpy sphere of radius about 1 around the origin with at least
 * `min_triangles` triangles (a UV sphere whose radius varies with latitude and
 * longitude), every edge shared by exactly two triangles with bit-identical corners,
 * wound so the winding normals point out. For benchmarks and watertightness tests. */
Status mesh_make_sphere(Scene *s, size_t min_triangles, uint material, Error *err);

/* Bounding box of triangles [first, first + n) of the scene; lo > hi when n is 0. */
void mesh_bounds(const Scene *s, size_t first, size_t n, vec3 *lo, vec3 *hi);

/* Parses a number in C float syntax starting exactly at p (no leading space), correctly
 * rounded as strtof does; `end` bounds the fast scan and the text must be NUL-terminated
 * at or after it. Returns the first byte after the number, or NULL when there is no
 * number there or it is not finite. The caller checks what follows. */
const char *mesh_parse_float(const char *p, const char *end, float *out);

/* The file `name` (len bytes, '\' taken as '/') as seen from the folder of the file
 * `beside`; when it does not exist there, each path component is matched without regard
 * to case (the Sponza's MTL names "SP_LUK.JPG" for sp_luk.JPG). Returns a heap string:
 * the matching path, or the path as written when nothing matches; NULL when out of
 * memory. */
char *mesh_resolve_path(const char *beside, const char *name, size_t len);

#endif /* CLPT_MESH_H */
