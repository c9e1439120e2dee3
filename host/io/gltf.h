/*
 * gltf.h — glTF 2.0 scenes (.gltf with external or data: buffers, binary .glb) read
 * into the scene: every mesh primitive of the chosen scene's node tree becomes
 * triangles through the mesh sink (scene/mesh_sink.h), its materials principled
 * materials, KHR_lights_punctual lights delta lights, and (when asked) one of its
 * cameras the scene camera. docs/gltf.md lists what is supported, approximated and
 * ignored. JSON is parsed by cJSON; every accessor, buffer view and buffer range is
 * checked against the data before it is read, and errors name the file and the JSON
 * path of what is wrong.
 */
#ifndef CLPT_GLTF_H
#define CLPT_GLTF_H

#include <stddef.h>

#include "scene/mesh_sink.h"

typedef struct {
    const char *camera;   /* in: the camera to use, by index or name; NULL: the first */
    int has_camera;       /* out: a camera was found and set */
    int has_lights;       /* out: the file has punctual lights or emissive materials */
} GltfView;

/* Reads the glTF file `path` whose `len` bytes are at `data` (a .glb's container or a
 * .gltf's JSON; data[len] must be '\0'), appending its triangles with the transform of
 * `o` and its materials (or o->material for all when it is not NO_INDEX) and lights.
 * With `view`, also sets the scene camera (and the image height from the camera's
 * aspect ratio) from the camera view->camera names. External files are read from
 * beside `path`. Errors: ST_INPUT "path: JSON.PATH: what is wrong", ST_IO for a file
 * that cannot be read. */
Status gltf_parse(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o, GltfView *view,
                  Error *err);

#endif /* CLPT_GLTF_H */
