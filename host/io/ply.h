/*
 * ply.h — Stanford PLY meshes, appended to a scene as triangles.
 *
 * Formats: ascii, binary_little_endian and binary_big_endian (version 1.0). The
 * `vertex` element must have x, y, z (any numeric type); nx ny nz give per-vertex
 * normals and u v, s t, texture_u texture_v or texture_s texture_t texture
 * coordinates, all optional. The `face` element's `vertex_indices` (or `vertex_index`)
 * list, of any count and index type, gives polygons, split into fans (v0 vi vi+1).
 * Every other element and property (vertex colours, confidence, per-face lists, edges,
 * tristrips ...) is read and skipped wherever it appears, lists included. Elements may
 * come in any order.
 *
 * Errors (ST_INPUT) name the file and the place: "path:line:col" in the header and in
 * ascii data, "path: byte offset N" in binary data, with the element, record and
 * property. The counts of the header are checked against the size of the file before
 * anything is allocated, so a corrupt count cannot ask for gigabytes. Vertex indices
 * are checked against the vertex count; a face with fewer than 3 corners is an error.
 */
#ifndef CLPT_PLY_H
#define CLPT_PLY_H

#include "scene/mesh_sink.h"

/* Appends the mesh's triangles to the scene, transformed as the options say; every
 * triangle gets o->material, or the default material (scene/mesh_sink.h) when it is NO_INDEX. */
Status ply_load(const char *path, Scene *s, const MeshOptions *o, Error *err);

/* Parses PLY data already in memory (len bytes, with a NUL at data[len]); `path`
 * names it in messages. */
Status ply_parse(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o,
                 Error *err);

#endif /* CLPT_PLY_H */
