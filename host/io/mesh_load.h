/*
 * mesh_load.h — reading a mesh file by its extension: the OBJ reader (obj.c) or the PLY
 * reader (ply.c), which write into the mesh sink (scene/mesh_sink.h).
 */
#ifndef CLPT_MESH_LOAD_H
#define CLPT_MESH_LOAD_H

#include "scene/mesh_sink.h"

/* Loads an OBJ (".obj"), PLY (".ply") or glTF (".gltf", ".glb"; io/gltf.h) file, by its extension in any case, appending
 * its triangles to the scene. ST_INPUT for any other extension. */
Status mesh_load(const char *path, Scene *s, const MeshOptions *o, Error *err);

/* The same for the file's bytes already in memory (data[len] must be '\0'), named
 * `path`, whose extension still chooses the reader; an OBJ's MTL files are read from
 * beside `path`. */
Status mesh_parse(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o, Error *err);

/* A reader of a mesh file's bytes in memory: obj_parse_with, ply_parse, mesh_parse. */
typedef Status (*MeshParseFn)(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o,
                              Error *err);

/* The file read whole (lex_read_file: limits, .gz inflated) and given to `parse`: how
 * every mesh reader loads from disk. */
Status mesh_read_with(const char *path, MeshParseFn parse, Scene *s, const MeshOptions *o, Error *err);

typedef enum { MESH_NONE = 0, MESH_OBJ, MESH_PLY, MESH_GLTF } MeshKind;
MeshKind mesh_kind(const char *path);

#endif /* CLPT_MESH_LOAD_H */
