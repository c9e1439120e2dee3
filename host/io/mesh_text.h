/*
 * mesh_text.h — what the text mesh readers (obj.c, ply.c's ascii bodies, mtl.c) share:
 * fast exact number parsing and finding the files a mesh names beside it.
 */
#ifndef CLPT_MESH_TEXT_H
#define CLPT_MESH_TEXT_H

#include <stddef.h>

/* Parses a number in C float syntax starting exactly at p (no leading space), correctly
 * rounded as strtof does; `end` bounds the fast scan and the text must be NUL-terminated
 * at or after it. Returns the first byte after the number, or NULL when there is no
 * number there or it is not finite. The caller checks what follows. */
const char *mesh_parse_float(const char *p, const char *end, float *out);

/* The file `name` (len bytes, '\' taken as '/') as seen from the folder of the file
 * `beside`; when it does not exist there, each path component is matched without regard
 * to case (the Sponza's MTL names "SP_LUK.JPG" for sp_luk.JPG). Returns a heap string:
 * the matching path, or the path as written when nothing matches; NULL when out of
 * memory. */
char *mesh_resolve_path(const char *beside, const char *name, size_t len);

#endif /* CLPT_MESH_TEXT_H */
