/*
 * classic_parse.h — scenes of the MIT 6.837 family (the format of the course's ray
 * casting and ray tracing assignments and of the courses derived from it), documented in
 * docs/classic-format.md, and telling it from ours (io/scene_load.c chooses).
 *
 * A classic scene becomes an ordinary Scene: Phong materials (MAT_PHONG), point, spot and
 * directional lights, an ambient light, spheres, planes, triangles and OBJ meshes with
 * their transforms applied, and the settings that make it render the way the course's
 * reference ray tracer does (the whitted integrator, one sample per pixel, 8-bit output
 * without the sRGB curve). Errors name file:line:column.
 */
#ifndef CLPT_CLASSIC_PARSE_H
#define CLPT_CLASSIC_PARSE_H

#include <stddef.h>

#include "scene/scene.h"

/* 1 when the text's first word (after blanks and # comments) is a top-level keyword of
 * the classic format (PerspectiveCamera, OrthographicCamera, Lights, Background,
 * Materials, Group), else 0. */
int classic_detect(const char *text, size_t len);

/* Reads a classic scene file (a regular file: io/scene_load.h reads the command line's
 * input, which may be a pipe) into an initialised scene. */
Status classic_load(const char *path, Scene *s, Error *err);
/* The same for `len` bytes of text in memory (copied), named `path` in messages; meshes
 * and textures are still read from disk, beside `path`. */
Status classic_load_text(const char *path, const char *text, size_t len, Scene *s, Error *err);

#endif /* CLPT_CLASSIC_PARSE_H */
