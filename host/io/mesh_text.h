/*
 * mesh_text.h — what the text mesh readers (obj.c, ply.c's ascii bodies, mtl.c) share:
 * fast exact number parsing (the files a mesh names are found by io/path.h).
 */
#ifndef CLPT_MESH_TEXT_H
#define CLPT_MESH_TEXT_H

#include <stddef.h>

/* Parses a number in C float syntax starting exactly at p (no leading space), correctly
 * rounded as strtof does; `end` bounds the fast scan and the text must be NUL-terminated
 * at or after it. Returns the first byte after the number, or NULL when there is no
 * number there or it is not finite. The caller checks what follows. */
const char *mesh_parse_float(const char *p, const char *end, float *out);

#endif /* CLPT_MESH_TEXT_H */
