/*
 * gltf_anim.h — a glTF file's animations kept with the file for `--frames`
 * (docs/animation.md): the scene it was read into is posed again at any time of the
 * animation through its SceneAnimation (scene/animation.h), from the file's JSON and
 * buffers kept in memory: no file is read again, and materials and textures stay those
 * the first reading made.
 *
 * Every channel of every animation plays on one timeline from time 0: frame k is at
 * k / fps seconds. Channels move nodes' translation, rotation and scale (LINEAR, with
 * slerp for rotations, STEP and CUBICSPLINE: scene/keyframes.h); those of morph target
 * weights are ignored with a warning. A node's mesh, camera and light move with it.
 */
#ifndef CLPT_GLTF_ANIM_H
#define CLPT_GLTF_ANIM_H

#include "io/gltf.h"
#include "scene/transform.h"

typedef struct GltfAnimated GltfAnimated;

/* gltf_parse, keeping the file and its animations: s->animation is set (freed by
 * scene_free). The scene is placed at the file's own pose (no animation applied).
 * Errors as gltf_parse's, and ST_INPUT for bad animations ("path: animations[0].
 * channels[1].target.node: ...") or a file with none. */
Status gltf_parse_animated(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o,
                           GltfView *view, Error *err);

/* Node `node`'s translation, rotation (x, y, z, w) and scale at time t: the animated
 * parts evaluated, the others the node's own. */
Status gltf_anim_node_trs(GltfAnimated *a, int node, double t, double tr[3], double r[4], double sc[3], Error *err);

/* Node `node`'s world transform at time t, the reader's transform (MeshOptions.xf)
 * included: what motion blur asks at its shutter's times. `a` is s->animation of a
 * scene read by gltf_parse_animated. */
Status gltf_anim_node_world(GltfAnimated *a, int node, double t, Transform *out, Error *err);

#endif /* CLPT_GLTF_ANIM_H */
