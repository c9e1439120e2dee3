/*
 * scene_load.h — the one loader: reads the input file named on the command line once
 * and hands its bytes to the reader of its format.
 *
 * Three kinds of input make a scene: our format (docs/scene-format.md, io/scene_parse.c),
 * the MIT 6.837 course format (docs/classic-format.md, io/classic_parse.c) and a bare
 * mesh (.obj or .ply, docs/meshes.md), which is shown in a scene made around it
 * (io/mesh_view.c). The file is read into memory once and parsed from there, so it may
 * be a pipe or FIFO (`clpt <(gen-scene)`, `gen-scene | clpt /dev/stdin`); what the scene
 * names (includes, meshes, MTL files, textures) must be regular files.
 */
#ifndef CLPT_SCENE_LOAD_H
#define CLPT_SCENE_LOAD_H

#include <stddef.h>

#include "scene/scene.h"

typedef enum {
    SCENE_FORMAT_AUTO = 0,      /* a mesh by its extension, else told from the content */
    SCENE_FORMAT_CLPT = 1,      /* docs/scene-format.md */
    SCENE_FORMAT_CLASSIC = 2,   /* docs/classic-format.md */
    SCENE_FORMAT_PBRT = 3       /* docs/pbrt.md */
} SceneFormat;

/* What the input turned out to be. */
typedef enum { SCENE_KIND_CLPT = 1, SCENE_KIND_CLASSIC, SCENE_KIND_MESH, SCENE_KIND_PBRT } SceneKind;

/* The kind of input `path` with `len` bytes of `text` is read as: with
 * SCENE_FORMAT_AUTO a mesh when the name ends in .obj or .ply (any case), pbrt-v4 when
 * it ends in .pbrt or its first word is a pbrt directive, else the classic format when
 * classic_detect says so, else ours; otherwise the format given. */
SceneKind scene_load_kind(const char *path, const char *text, size_t len, SceneFormat format);

/* Reads `path` once (a regular file, or a pipe or FIFO read to its end) into an
 * initialised scene, in the given format. *kind (may be NULL) tells what it was: a mesh
 * scene's camera must be fitted again (mesh_view_fit) when the image size changes. */
Status scene_load_file(const char *path, SceneFormat format, Scene *s, SceneKind *kind, Error *err);

/* The same for the file's bytes in memory (text[len] must be '\0'), named `path` in
 * messages; what the scene names is read from beside `path`. */
Status scene_load_bytes(const char *path, const char *text, size_t len, SceneFormat format, Scene *s,
                        SceneKind *kind, Error *err);

#endif /* CLPT_SCENE_LOAD_H */
