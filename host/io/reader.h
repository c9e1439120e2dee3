/*
 * reader.h — what the scene readers share in telling a problem: where it is (a token's
 * file:line:column, or a JSON path in a glTF file), how an error inside a file that a
 * scene names (an include, a mesh) points back to the line that named it, and warnings
 * given once per kind however often the file repeats them.
 */
#ifndef CLPT_READER_H
#define CLPT_READER_H

#include "base/status.h"
#include "base/strmap.h"
#include "io/lexer.h"
#include "scene/scene.h"

/* "path:line:col" of the token, a heap string; NULL when out of memory. */
char *reader_where(const Lexer *lx, const Token *at);

/* Prefixes err's message with "path:line:col: ", the token's place. */
void reader_annotate(const Lexer *lx, const Token *at, Error *err);

/* Prefixes err's message with "file: jpath: " (jpath: "meshes[2].primitives[0]"). */
void reader_annotate_json(const char *file, const char *jpath, Error *err);

/* Tells where a failure `st` in a file that the lexer's file names came from: a file
 * that cannot be read (ST_IO) gets the place of its `name` in front; any other failure
 * gets " (<how> path:line:col)" of the statement `stmt` after it, how being "included
 * from" or "in the mesh of". Returns st. */
Status reader_note_nested(const Lexer *lx, const Token *name, const Token *stmt, const char *how, Status st,
                          Error *err);

/* A warning given once per `key` ("Shape disk") among those in `seen`: the first adds
 * "path:LINE: <message>" to the scene's warnings (scene_warn), the others nothing.
 * Fails only when memory runs out. */
Status reader_warn_once(Scene *s, StrMap *seen, const Lexer *lx, const Token *at, const char *key, Error *err,
                        const char *fmt, ...) __attribute__((format(printf, 7, 8)));

#endif /* CLPT_READER_H */
