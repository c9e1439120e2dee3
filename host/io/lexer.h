/*
 * lexer.h — a tokenizer for line-oriented text formats, with file:line:column positions.
 *
 * Tokens are separated by whitespace; `#` starts a comment that runs to the end of the
 * line. The token kinds are:
 *   - words: any run of bytes other than whitespace, control characters and  { } [ ] " #
 *     (keywords, names and numbers are all words; the parser decides which it wants);
 *   - strings: "..." on one line, with the escapes \" and \\ only;
 *   - the punctuation { } [ ], each a token of its own, so `sphere{` is two tokens.
 *
 * The lexer owns a private copy of the whole text. Strings are unescaped in place, so a
 * token's text stays valid (and unchanged) until lex_close; no token is ever allocated.
 * Token text is NOT NUL-terminated: use tok_is / tok_copy / lex_float and friends.
 *
 * Lines and columns start at 1; a column counts bytes (a tab is one column).
 * Every error message starts with "path:line:col: " and is an ST_INPUT error, except
 * a file that cannot be read (ST_IO, "cannot open 'path': <reason>", or "cannot read
 * 'path': ..." when it is not a regular file).
 */
#ifndef CLPT_LEXER_H
#define CLPT_LEXER_H

#include <stddef.h>

#include "base/status.h"
#include "types.h"

typedef enum {
    TOK_EOF = 0,
    TOK_WORD,
    TOK_STRING,
    TOK_LBRACE,     /* { */
    TOK_RBRACE,     /* } */
    TOK_LBRACKET,   /* [ */
    TOK_RBRACKET    /* ] */
} TokenKind;

typedef struct {
    TokenKind kind;
    const char *text;    /* the word, or the string's unescaped contents; not terminated */
    size_t len;
    uint line, col;
} Token;

typedef struct {
    char *path;          /* as given, for messages */
    char *src;           /* the text, NUL-terminated copy */
    size_t len, pos;
    uint line;
    size_t line_start;   /* offset of the current line's first byte */
    Token back;          /* the token given back by lex_unread, when has_back */
    int has_back;
} Lexer;

/* Reads the whole file. ST_IO "cannot open 'path': <strerror>" when it cannot, and
 * "cannot read 'path': it is a directory, not a file" (a device, a pipe: not a regular
 * file) when it is not a regular file, found without blocking on a FIFO; ST_INPUT when
 * it is larger than CLPT_MAX_FILE_BYTES (limit.h), checked before reading. A UTF-8 byte
 * order mark at the start is dropped, here and in every function below that takes text. */
Status lex_open_file(Lexer *lx, const char *path, Error *err);
/* Lexes `len` bytes of `text` (copied), reported under the name `path`. */
Status lex_open_text(Lexer *lx, const char *path, const char *text, size_t len, Error *err);
void lex_close(Lexer *lx);
/* Reads a whole regular file into a NUL-terminated heap buffer (*data, *len without the
 * NUL); the same errors as lex_open_file. Used by loaders that do their own lexing. */
Status lex_read_file(const char *path, char **data, size_t *len, Error *err);
/* The same, but a pipe or FIFO is read too (to its end, once): for the scene named on
 * the command line, which may be `<(gen-scene)` or /dev/stdin. */
Status lex_read_input(const char *path, char **data, size_t *len, Error *err);
/* The checks of lex_read_file without the reading, for files another library opens by
 * name (texture images): ST_OK when `path` is a regular file clpt may read. */
Status lex_check_file(const char *path, Error *err);

/* A scene load's budget of input text: between lex_load_begin and lex_load_end every
 * file that lex_read_file, lex_read_input and lex_open_file read on this thread counts
 * (a .gz file inflated), and one that would take the total past the budget fails with
 * ST_INPUT "'PATH': reading it takes this load's input to more than N bytes (the files
 * of one scene together, .gz files inflated; CLPT_MAX_LOAD_BYTES sets the budget)",
 * inflation stopping there. The budget is CLPT_MAX_LOAD_BYTES (base/limit.h) or the
 * environment variable of that name, a whole number of bytes; lex_load_begin fails
 * with ST_USAGE on another value. Loads nest (a mesh file's load within a scene's):
 * only the outermost begins and ends the count. Outside a load only each file's own
 * limit applies. */
Status lex_load_begin(Error *err);
void lex_load_end(void);
/* The bytes the files of this thread's load in progress have taken so far (0 outside
 * a load): what budgets that grow with a scene's size are measured against. */
uint64_t lex_load_bytes(void);
/* Counts `bytes` of text a caller holds in memory (the scene handed to scene_load_bytes)
 * against the load's budget, as if read from `path`; the budget's error past it. */
Status lex_load_count(const char *path, uint64_t bytes, Error *err);

/* 3 when text starts with a UTF-8 byte order mark (EF BB BF), else 0. */
size_t lex_bom_length(const char *text, size_t len);

/* The next token (TOK_EOF at the end, repeatedly): the one given back by lex_unread, if
 * any, else the next in the text. Fails on an unterminated string,
 * an unknown escape or a control character. */
Status lex_next(Lexer *lx, Token *tok, Error *err);

/* Gives `tok` back: the next lex_next returns it again (a reader that looked one token
 * ahead). One token of push-back; `tok` must be the last token this lexer returned. */
void lex_unread(Lexer *lx, const Token *tok);

/* 1 if the token is the word `word` (strings never match: "camera" is not a keyword). */
int tok_is(const Token *tok, const char *word);
/* A heap-allocated, NUL-terminated copy of the token text; NULL when out of memory. */
char *tok_copy(const Token *tok);
/* Writes a short printable rendering of the token into buf, for messages: the word,
 * the string in quotes, or "end of file"; long tokens are cut with "...", control
 * bytes and bytes that are not UTF-8 shown as \xNN. */
void tok_describe(const Token *tok, char *buf, size_t size);

/* ST_INPUT "path:line:col: expected <what>, found '<token>'" at the token; for readers
 * with their own line scanning (OBJ, MTL) that make a word into a Token for messages. */
Status tok_expected(const char *path, const Token *tok, const char *what, Error *err);
/* The same for a token of the lexer's file. */
Status lex_expected(const Lexer *lx, const Token *tok, const char *what, Error *err);
/* ST_INPUT "path:line:col: <message>" at the token, with a printf-style message. */
Status lex_error_at(const Lexer *lx, const Token *tok, Error *err, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Parses the token as a whole number in C float syntax (integers too) into *out.
 * Returns 0 on success, -1 when it is not a word, not entirely a number, or not finite
 * (nan, inf, or out of float range). */
int tok_float(const Token *tok, float *out);
/* Parses the token as an unsigned decimal integer (optional '+', digits only) into
 * *out. Returns 0 on success, -1 when it is not one or exceeds 2^64 - 1. */
int tok_uint(const Token *tok, unsigned long long *out);

#endif /* CLPT_LEXER_H */
