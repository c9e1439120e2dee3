/*
 * obj.h — Wavefront OBJ meshes, appended to a scene as triangles.
 *
 * Supported: v (x y z, an optional w or r g b is ignored), vt (u [v [w]]), vn, and f
 * with every index form (i, i/t, i//n, i/t/n), positive and negative (relative)
 * indices; a polygon is split into a fan of triangles (v0 vi vi+1). A triangle whose
 * three corners all carry normals and/or texture coordinates gets a TriShading record
 * (normals made unit length; a zero-length normal drops the normals of that triangle),
 * otherwise its shading index is NO_INDEX. Degenerate triangles are kept as written.
 * `mtllib` reads MTL files (mtl.h; names resolved from the OBJ's folder, without
 * regard to case when the exact name is missing) and `usemtl` gives the faces that
 * follow that material, added to the scene on first use (with its map_Kd path, see
 * scene_set_material_texture); faces before any `usemtl` get the default material.
 * When the caller gives a material, every triangle gets it and `mtllib`/`usemtl` are
 * not read. `o`, `g`, `s`, `l` and `p` are accepted and ignored. `#` comments, blank
 * lines, CRLF line ends and `\` line continuations are accepted.
 *
 * Errors: ST_IO "cannot open 'path': <reason>"; ST_INPUT "path:line:col: expected ...,
 * found '...'" for anything malformed (bad numbers, index 0 or out of range, a face
 * with fewer than 3 vertices, an unknown statement, a usemtl name no mtllib defines);
 * an MTL file that cannot be read is ST_IO prefixed with the mtllib's position.
 */
#ifndef CLPT_OBJ_H
#define CLPT_OBJ_H

#include "scene/mesh_sink.h"

/* Appends the mesh's triangles (and shading records) to the scene, transformed and
 * with materials as the options say (scene/mesh_sink.h). On failure the scene may hold some of
 * the mesh's triangles. */
Status obj_load_with(const char *path, Scene *s, const MeshOptions *o, Error *err);

/* Parses OBJ text already in memory; `path` names it in messages and is the folder
 * MTL files are found from. `text` must be NUL-terminated at text[len]. */
Status obj_parse_with(const char *path, const char *text, size_t len, Scene *s,
                      const MeshOptions *o, Error *err);

/* The same without a transform, every triangle with `material` (NO_INDEX: the MTL's). */
Status obj_load(const char *path, Scene *s, uint material, Error *err);
Status obj_parse(const char *path, const char *text, size_t len, Scene *s, uint material,
                 Error *err);

#endif /* CLPT_OBJ_H */
