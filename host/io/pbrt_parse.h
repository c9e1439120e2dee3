/*
 * pbrt_parse.h — a reader of pbrt-v4 scene files (docs/pbrt.md).
 *
 * The subset most published scenes use: cameras, transforms, attributes, named
 * materials and coordinate systems, includes, the common shapes, materials and lights,
 * mapped onto clpt's own primitives and materials. Directives and parameters clpt does
 * not support become warnings (Scene.warnings, once each, with file:line) and the render
 * goes on; a syntax error or a bad value is an ST_INPUT error at file:line:column.
 * Tokens are read by io/lexer.c (pbrt's tokens are its words, strings and [ ]).
 */
#ifndef CLPT_PBRT_PARSE_H
#define CLPT_PBRT_PARSE_H

#include <stddef.h>

#include "scene/scene.h"

/* 1 when the text's first word (after blanks and # comments) is a pbrt directive. */
int pbrt_detect(const char *text, size_t len);

/* Reads `len` bytes of pbrt-v4 text named `path` into an initialised scene; included
 * files and meshes are found beside `path`, as pbrt finds them beside the main file. */
Status pbrt_load_text(const char *path, const char *text, size_t len, Scene *s, Error *err);

#endif /* CLPT_PBRT_PARSE_H */
