/*
 * obj.h — Wavefront OBJ meshes, appended to a scene as triangles.
 *
 * Supported: v (x y z, an optional w or r g b is ignored), vt (u [v [w]]), vn, and f
 * with every index form (i, i/t, i//n, i/t/n), positive and negative (relative)
 * indices; a polygon is split into a fan of triangles (v0 vi vi+1). A triangle whose
 * three corners all carry normals and/or texture coordinates gets a TriShading record
 * (normals made unit length; a zero-length normal drops the normals of that triangle),
 * otherwise its shading index is NO_INDEX. Degenerate triangles are kept as written.
 * `o`, `g`, `s`, `usemtl`, `mtllib`, `l` and `p` are accepted and ignored: every
 * triangle gets the one material given by the caller (materials from MTL files come
 * with the meshes work). `#` comments, blank lines, CRLF line ends and `\` line
 * continuations are accepted.
 *
 * Errors: ST_IO "cannot open 'path': <reason>"; ST_INPUT "path:line:col: expected ...,
 * found '...'" for anything malformed (bad numbers, index 0 or out of range, a face
 * with fewer than 3 vertices, an unknown statement).
 */
#ifndef CLPT_OBJ_H
#define CLPT_OBJ_H

#include "scene.h"

/* Appends the mesh's triangles (and shading records) to the scene, all with
 * `material`. On failure the scene may hold some of the mesh's triangles. */
Status obj_load(const char *path, Scene *s, uint material, Error *err);

/* Parses OBJ text already in memory; `path` names it in messages. `text` must be
 * NUL-terminated at text[len]. */
Status obj_parse(const char *path, const char *text, size_t len, Scene *s, uint material,
                 Error *err);

#endif /* CLPT_OBJ_H */
