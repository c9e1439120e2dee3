/* reader.c — places, nested files and warnings for the scene readers (reader.h). */
#include "io/reader.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char *reader_where(const Lexer *lx, const Token *at)
{
    int n = snprintf(NULL, 0, "%s:%u:%u", lx->path, at->line, at->col);
    char *w = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (w) snprintf(w, (size_t)n + 1, "%s:%u:%u", lx->path, at->line, at->col);
    return w;
}

void reader_annotate(const Lexer *lx, const Token *at, Error *err)
{
    error_prefix(err, "%s:%u:%u", lx->path, at->line, at->col);
}

void reader_annotate_json(const char *file, const char *jpath, Error *err)
{
    error_prefix(err, "%s: %s", file, jpath);
}

Status reader_note_nested(const Lexer *lx, const Token *name, const Token *stmt, const char *how, Status st,
                          Error *err)
{
    if (st == ST_IO)
        reader_annotate(lx, name, err);
    else if (st)
        error_append(err, " (%s %s:%u:%u)", how, lx->path, stmt->line, stmt->col);
    return st;
}

Status reader_warn_once(Scene *s, StrMap *seen, const Lexer *lx, const Token *at, const char *key, Error *err,
                        const char *fmt, ...)
{
    uint32_t dummy;
    size_t kl = strlen(key);
    if (strmap_find(seen, key, kl, &dummy)) return ST_OK;
    if (strmap_add(seen, key, kl, 1)) return error_set(err, ST_INTERNAL, "out of memory");
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return scene_warn(s, err, "%s:%u: %s", lx->path, at->line, msg);
}
