/*
 * mesh_sink.h — where the mesh readers (obj.c, ply.c) and the classic format's meshes
 * put their triangles, and the options a mesh is read with.
 *
 * A reader hands the sink triangles in the file's own coordinates; the sink applies the
 * instance transform (positions by the affine matrix, normals by its inverse transpose,
 * in double, rounded once to float), swaps two corners when the transform mirrors so
 * that the winding normal keeps pointing to the same side of the surface, refuses a
 * triangle the kernels could not intersect in float (a corner that is not finite, or
 * corners so far apart that their differences overflow), naming the mesh file, and
 * appends the triangle (and a TriShading record when the corners carry normals or
 * texture coordinates) to the scene. docs/meshes.md describes the formats and the
 * materials. This is the scene layer: it reads no file (io/mesh_load.h does).
 */
#ifndef CLPT_MESH_SINK_H
#define CLPT_MESH_SINK_H

#include "scene/scene.h"
#include "scene/transform.h"

typedef struct {
    /* Material of every triangle, or NO_INDEX to take the materials the file names (an
     * OBJ's MTL files); faces that name none then get default_material, which is a
     * neutral diffuse material added on first use when it is NO_INDEX too. */
    uint material;
    uint default_material;
    Transform xf;
    /* Faces without normals get smooth ones over the faces sharing each vertex index
     * (mesh_smooth_normals; OBJ only, MIT 6.837 Fall 2019's convention). */
    int smooth_by_index;
    /* The file's meshes are copied wherever it places them, never made objects with
     * instances (a glTF read inside an object: instances nest one level deep). */
    int no_instances;
} MeshOptions;

/* Every triangle gets `material` (NO_INDEX: the file's own), no transform. */
MeshOptions mesh_options(uint material);

/* The neutral grey of a mesh that names no material. */
#define MESH_DEFAULT_ALBEDO 0.75f

/* *material, when it is NO_INDEX, becomes a new diffuse material of that grey: the mesh
 * readers add it only once a triangle needs it, so that a file that names its materials
 * leaves no unused one in the scene. */
Status mesh_default_material(Scene *s, uint *material, Error *err);

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
/* mesh_sink_triangle with corner attributes (glTF's TANGENT, TEXCOORD_1, COLOR_0), or
 * extra NULL: extra's fields in the file's coordinates, by corner. Tangents go through
 * the transform's linear part (they lie along the surface) and are normalised, their w
 * reduced to a sign and flipped by a mirroring transform (the bitangent cross(n, t) w
 * must keep pointing where the file meant); a tangent that comes out zero or not
 * finite, or a colour or uv that is not finite, drops that attribute of the triangle. */
Status mesh_sink_triangle_extra(MeshSink *k, const vec3 p[3], const vec3 *n, const float *uv,
                                const TriExtra *extra, uint material);

/* A closed, bumpy sphere of radius about 1 around the origin with at least
 * `min_triangles` triangles (a UV sphere whose radius varies with latitude and
 * longitude), every edge shared by exactly two triangles with bit-identical corners,
 * wound so the winding normals point out. For benchmarks and watertightness tests. */
Status mesh_make_sphere(Scene *s, size_t min_triangles, uint material, Error *err);

/* Bounding box of triangles [first, first + n) of the scene; lo > hi when n is 0. */
void mesh_bounds(const Scene *s, size_t first, size_t n, vec3 *lo, vec3 *hi);

/* Gives triangles [first, n_triangles) that have no normals smooth ones, as MIT 6.837
 * Fall 2019's OBJ loader does: at each corner the normalised sum of the unit winding
 * normals of those triangles whose corner has the same key (each face counts the same).
 * keys[3 (i - first) + j] < n_keys is the key of corner j of triangle i: the file's
 * vertex index, so that faces which share no vertex stay faceted ("If sharp edges
 * required, build OBJ with no shared vertices", the course's Mesh.cpp). A triangle
 * whose corner sum cancels out stays flat. Linear time; fails only when memory runs
 * out (ST_INTERNAL). */
Status mesh_smooth_normals(Scene *s, size_t first, const uint *keys, uint n_keys, Error *err);

#endif /* CLPT_MESH_SINK_H */
