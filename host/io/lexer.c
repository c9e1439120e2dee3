/* lexer.c — whitespace-separated tokens with positions (see lexer.h). */
#include "io/lexer.h"

#include "base/limit.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

/* Some Windows editors start text files with a UTF-8 byte order mark: it is no part of
 * the text, and left in it would be an invisible first "word". */
size_t lex_bom_length(const char *text, size_t len)
{
    return len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
}

Status lex_open_text(Lexer *lx, const char *path, const char *text, size_t len, Error *err)
{
    memset(lx, 0, sizeof *lx);
    size_t skip = lex_bom_length(text, len);
    text += skip;
    len -= skip;
    size_t plen = strlen(path);
    lx->path = malloc(plen + 1);
    lx->src = malloc(len + 1);
    if (!lx->path || !lx->src) {
        lex_close(lx);
        return error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
    }
    memcpy(lx->path, path, plen + 1);
    memcpy(lx->src, text, len);
    lx->src[len] = '\0';
    lx->len = len;
    lx->line = 1;
    return ST_OK;
}

/* Opens path for reading and checks what it is, without blocking: a FIFO is opened with
 * O_NONBLOCK (a plain open would wait for a writer). Only a regular file, or a pipe or
 * FIFO when `allow_pipe`, is returned open. */
static Status open_input(const char *path, int allow_pipe, int *fd_out, struct stat *sb, Error *err)
{
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return error_set(err, ST_IO, "cannot open '%s': %s", path, strerror(errno));
    const char *what = NULL;
    if (fstat(fd, sb) != 0) {
        int e = errno;
        close(fd);
        return error_set(err, ST_IO, "cannot open '%s': %s", path, strerror(e));
    }
    if (S_ISDIR(sb->st_mode)) what = "it is a directory, not a file";
    /* /dev/zero or /dev/urandom would be read until memory runs out */
    else if (S_ISCHR(sb->st_mode) || S_ISBLK(sb->st_mode)) what = "it is a device, not a file";
    else if ((S_ISFIFO(sb->st_mode) || S_ISSOCK(sb->st_mode)) && !allow_pipe)
        what = "it is a pipe, not a regular file (only the scene itself may be a pipe; meshes, textures, "
               "includes and MTL files are read from regular files)";
    else if (!S_ISREG(sb->st_mode) && !S_ISFIFO(sb->st_mode) && !S_ISSOCK(sb->st_mode))
        what = "it is not a regular file";
    if (what) {
        close(fd);
        return error_set(err, ST_IO, "cannot read '%s': %s", path, what);
    }
    int flags = fcntl(fd, F_GETFL);
    if (flags >= 0) fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
    *fd_out = fd;
    return ST_OK;
}

Status lex_check_file(const char *path, Error *err)
{
    int fd;
    struct stat sb;
    Status st = open_input(path, 0, &fd, &sb, err);
    if (st) return st;
    close(fd);
    return limit_file_size(path, (uint64_t)sb.st_size, err);
}

/* The scene load in progress on this thread (lex_load_begin): how deeply loads nest,
 * the bytes its files took so far (at most the budget) and its budget. Thread-local:
 * a load reads its files on one thread, and each thread may load its own scene. */
static _Thread_local struct {
    int depth;
    uint64_t used, budget;
} lex_load;

Status lex_load_begin(Error *err)
{
    if (lex_load.depth++ > 0) return ST_OK;
    lex_load.used = 0;
    lex_load.budget = CLPT_MAX_LOAD_BYTES;
    const char *env = getenv("CLPT_MAX_LOAD_BYTES");
    if (env && *env) {
        char *end;
        errno = 0;
        unsigned long long v = strtoull(env, &end, 10);
        if (*end || errno || !(env[0] >= '0' && env[0] <= '9')) {
            lex_load.depth = 0;
            return error_set(err, ST_USAGE, "CLPT_MAX_LOAD_BYTES='%.64s': expected a whole number of bytes", env);
        }
        lex_load.budget = v;
    }
    return ST_OK;
}

void lex_load_end(void)
{
    if (lex_load.depth > 0) lex_load.depth--;
}

uint64_t lex_load_bytes(void) { return lex_load.depth ? lex_load.used : 0; }

/* The most bytes the next file may take: its own limit, and within a load what is left
 * of the load's budget. */
static uint64_t read_limit(void)
{
    uint64_t left = lex_load.depth ? lex_load.budget - lex_load.used : CLPT_MAX_FILE_BYTES;
    return left < CLPT_MAX_FILE_BYTES ? left : CLPT_MAX_FILE_BYTES;
}

/* The error for a file found to take `bytes`, more than read_limit(). */
static Status over_limit(const char *path, uint64_t bytes, Error *err)
{
    if (bytes > CLPT_MAX_FILE_BYTES) return limit_file_size(path, bytes, err);
    return error_set(err, ST_INPUT, "'%s': reading it takes this load's input to more than %llu bytes (the files "
                     "of one scene together, .gz files inflated; CLPT_MAX_LOAD_BYTES sets the budget)", path,
                     (unsigned long long)lex_load.budget);
}

Status lex_load_count(const char *path, uint64_t bytes, Error *err)
{
    if (!lex_load.depth) return ST_OK;
    if (bytes > read_limit()) return over_limit(path, bytes, err);
    lex_load.used += bytes;
    return ST_OK;
}

/* Only the name says a file is compressed: a glTF .bin or a binary PLY may well start
 * with gzip's magic bytes by chance. */
static int ends_in_gz(const char *path)
{
    size_t n = strlen(path);
    return n >= 3 && strcmp(path + n - 3, ".gz") == 0;
}

/* Inflates the gzip data `in` (one member or several concatenated, as gzip -c a b
 * writes them) into a new buffer with room for a NUL after it. The output is checked
 * against `limit` (read_limit) before each growth, so that a small file that inflates to
 * terabytes stops at the same limit as a large plain file instead of exhausting memory. */
static Status gunzip(const char *path, const char *in, size_t in_len, uint64_t limit, char **out, size_t *out_len,
                     Error *err)
{
    *out = NULL;
    *out_len = 0;
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (inflateInit2(&zs, 15 + 16) != Z_OK)
        return error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
    /* text compresses about 4:1; a first guess that big saves most of the regrowth */
    uint64_t guess = (uint64_t)in_len * 4 < ((uint64_t)1 << 16) ? (uint64_t)1 << 16 : (uint64_t)in_len * 4;
    size_t cap = guess > limit + 2 ? (size_t)(limit + 2) : (size_t)guess, n = 0;
    char *buf = malloc(cap);
    Status st = ST_OK;
    if (!buf) {
        st = error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
        goto done;
    }
    size_t used = 0; /* input bytes consumed; zlib's avail_in is a uInt, so fed in slices */
    for (;;) {
        if (cap - n < 2) {
            /* the buffer never outgrows the limit and its NUL: full, the data is over it */
            if (n > limit) {
                st = over_limit(path, n, err);
                goto done;
            }
            size_t want = (uint64_t)cap * 2 > limit + 2 ? (size_t)(limit + 2) : cap * 2;
            char *grown = realloc(buf, want);
            if (!grown) {
                st = error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
                goto done;
            }
            buf = grown;
            cap = want;
        }
        size_t in_slice = in_len - used > UINT_MAX ? UINT_MAX : in_len - used;
        size_t out_slice = cap - 1 - n > UINT_MAX ? UINT_MAX : cap - 1 - n;
        zs.next_in = (Bytef *)(in + used);
        zs.avail_in = (uInt)in_slice;
        zs.next_out = (Bytef *)(buf + n);
        zs.avail_out = (uInt)out_slice;
        int rc = inflate(&zs, Z_NO_FLUSH);
        used += in_slice - zs.avail_in;
        n += out_slice - zs.avail_out;
        if (rc == Z_STREAM_END) {
            /* another member may follow; anything else after the end is left unread, as
             * gzip itself does with trailing zeros */
            if (used + 2 <= in_len && (unsigned char)in[used] == 0x1f && (unsigned char)in[used + 1] == 0x8b) {
                inflateReset(&zs);
                continue;
            }
            break;
        }
        if (rc == Z_BUF_ERROR && used == in_len) {
            st = error_set(err, ST_INPUT, "'%s': the gzip data is cut short", path);
            goto done;
        }
        if (rc == Z_MEM_ERROR) {
            st = error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
            goto done;
        }
        if (rc != Z_OK && rc != Z_BUF_ERROR) {
            st = error_set(err, ST_INPUT, "'%s': not valid gzip data (zlib: %s)", path,
                           zs.msg ? zs.msg : "unknown error");
            goto done;
        }
        if (n > limit) {
            st = over_limit(path, n, err);
            goto done;
        }
    }
    if (n > limit) {
        st = over_limit(path, n, err);
        goto done;
    }
    *out = buf;
    *out_len = n;
    buf = NULL;
done:
    free(buf);
    inflateEnd(&zs);
    return st;
}

/* lex_read_file and lex_read_input: the whole file in one buffer, read once. */
static Status read_whole(const char *path, int allow_pipe, char **data, size_t *len, Error *err)
{
    *data = NULL;
    *len = 0;
    int fd;
    struct stat sb;
    Status st = open_input(path, allow_pipe, &fd, &sb, err);
    if (st) return st;
    size_t cap = 1 << 16, n = 0;
    uint64_t limit = read_limit();
    if (S_ISREG(sb.st_mode)) {
        if ((uint64_t)sb.st_size > limit) {
            close(fd);
            return over_limit(path, (uint64_t)sb.st_size, err);
        }
        /* the whole file and the NUL in one allocation */
        if ((uint64_t)sb.st_size + 2 > cap) cap = (size_t)sb.st_size + 2;
    }
    char *buf = malloc(cap);
    if (!buf) {
        close(fd);
        return error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
    }
    for (;;) {
        if (n > limit) {
            free(buf);
            close(fd);
            return over_limit(path, n, err);
        }
        if (cap - n < 2) {
            char *grown = cap <= ((size_t)-1) / 2 ? realloc(buf, cap * 2) : NULL;
            if (!grown) {
                free(buf);
                close(fd);
                return error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
            }
            buf = grown;
            cap *= 2;
        }
        /* A FIFO opened before its writer reads as ended: poll waits for the writer's
         * data or its hanging up, as a blocking open would, while this reader keeps the
         * FIFO (and what a quick writer left in it) open. */
        struct pollfd pfd = { fd, POLLIN, 0 };
        if (S_ISFIFO(sb.st_mode) && poll(&pfd, 1, -1) < 0 && errno == EINTR) continue;
        ssize_t got = read(fd, buf + n, cap - 1 - n);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) {
            int e = errno;
            free(buf);
            close(fd);
            return error_set(err, ST_IO, "cannot read '%s': %s", path, strerror(e));
        }
        if (got == 0) break;
        n += (size_t)got;
    }
    close(fd);
    if (ends_in_gz(path)) {
        char *raw = buf;
        st = gunzip(path, raw, n, limit, &buf, &n, err);
        free(raw);
        if (st) return st;
    }
    size_t skip = lex_bom_length(buf, n);
    if (skip) memmove(buf, buf + skip, n - skip);
    n -= skip;
    buf[n] = '\0';
    if (lex_load.depth) lex_load.used += n;
    *data = buf;
    *len = n;
    return ST_OK;
}

Status lex_read_file(const char *path, char **data, size_t *len, Error *err)
{
    return read_whole(path, 0, data, len, err);
}

Status lex_read_input(const char *path, char **data, size_t *len, Error *err)
{
    return read_whole(path, 1, data, len, err);
}

Status lex_open_file(Lexer *lx, const char *path, Error *err)
{
    memset(lx, 0, sizeof *lx);
    char *data;
    size_t len;
    Status st = lex_read_file(path, &data, &len, err);
    if (st) return st;
    size_t plen = strlen(path);
    lx->path = malloc(plen + 1);
    if (!lx->path) {
        free(data);
        return error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
    }
    memcpy(lx->path, path, plen + 1);
    lx->src = data;
    lx->len = len;
    lx->line = 1;
    return ST_OK;
}

void lex_close(Lexer *lx)
{
    free(lx->path);
    free(lx->src);
    memset(lx, 0, sizeof *lx);
}

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }
static int is_control(unsigned char c) { return c < 0x20 || c == 0x7f; }
static int is_word_byte(unsigned char c)
{
    return !is_control(c) && c != ' ' && c != '{' && c != '}' && c != '[' && c != ']' &&
           c != '"' && c != '#';
}

/* Skips whitespace and comments, counting lines. */
static void skip_blank(Lexer *lx)
{
    while (lx->pos < lx->len) {
        char c = lx->src[lx->pos];
        if (c == '\n') {
            lx->pos++;
            lx->line++;
            lx->line_start = lx->pos;
        } else if (is_space(c)) {
            lx->pos++;
        } else if (c == '#') {
            while (lx->pos < lx->len && lx->src[lx->pos] != '\n') lx->pos++;
        } else {
            break;
        }
    }
}

static void set_token(Lexer *lx, Token *tok, TokenKind kind, size_t start, size_t len)
{
    tok->kind = kind;
    tok->text = lx->src + start;
    tok->len = len;
    tok->line = lx->line;
    tok->col = (uint)(start - lx->line_start + 1);
}

/* Lexes "..." starting at the opening quote; unescapes in place, which only ever
 * shortens the text, so the bytes after the string are untouched. */
static Status lex_string(Lexer *lx, Token *tok, Error *err)
{
    size_t open = lx->pos;
    size_t out = open + 1;
    size_t p = open + 1;
    set_token(lx, tok, TOK_STRING, open, 0);   /* positioned at the opening quote */
    tok->text = lx->src + open + 1;
    for (;;) {
        if (p >= lx->len || lx->src[p] == '\n' || lx->src[p] == '\r') {
            return error_set(err, ST_INPUT,
                             "%s:%u:%u: expected '\"' closing the string that starts here, "
                             "found end of %s", lx->path, tok->line, tok->col,
                             p >= lx->len ? "file" : "line");
        }
        char c = lx->src[p];
        if (c == '"') break;
        if (c == '\\') {
            char e = p + 1 < lx->len ? lx->src[p + 1] : '\0';
            if (e != '"' && e != '\\') {
                uint col = (uint)(p - lx->line_start + 1);
                if (is_control((unsigned char)e) || e == '\0')
                    return error_set(err, ST_INPUT,
                                     "%s:%u:%u: expected '\\\"' or '\\\\' (the only escapes in a "
                                     "string), found '\\' before byte 0x%02x",
                                     lx->path, lx->line, col, (unsigned char)e);
                return error_set(err, ST_INPUT,
                                 "%s:%u:%u: expected '\\\"' or '\\\\' (the only escapes in a "
                                 "string), found '\\%c'", lx->path, lx->line, col, e);
            }
            lx->src[out++] = e;
            p += 2;
            continue;
        }
        if (is_control((unsigned char)c) && c != '\t') {
            uint col = (uint)(p - lx->line_start + 1);
            return error_set(err, ST_INPUT, "%s:%u:%u: unexpected control byte 0x%02x in a string",
                             lx->path, lx->line, col, (unsigned char)c);
        }
        lx->src[out++] = c;
        p++;
    }
    tok->len = out - (open + 1);
    lx->pos = p + 1;
    return ST_OK;
}

Status lex_next(Lexer *lx, Token *tok, Error *err)
{
    if (lx->has_back) {
        *tok = lx->back;
        lx->has_back = 0;
        return ST_OK;
    }
    skip_blank(lx);
    if (lx->pos >= lx->len) {
        set_token(lx, tok, TOK_EOF, lx->len, 0);
        return ST_OK;
    }
    size_t start = lx->pos;
    unsigned char c = (unsigned char)lx->src[start];
    switch (c) {
    case '{': set_token(lx, tok, TOK_LBRACE, start, 1); lx->pos++; return ST_OK;
    case '}': set_token(lx, tok, TOK_RBRACE, start, 1); lx->pos++; return ST_OK;
    case '[': set_token(lx, tok, TOK_LBRACKET, start, 1); lx->pos++; return ST_OK;
    case ']': set_token(lx, tok, TOK_RBRACKET, start, 1); lx->pos++; return ST_OK;
    case '"': return lex_string(lx, tok, err);
    default: break;
    }
    if (is_control(c))
        return error_set(err, ST_INPUT, "%s:%u:%u: unexpected control byte 0x%02x",
                         lx->path, lx->line, (uint)(start - lx->line_start + 1), c);
    size_t p = start;
    while (p < lx->len && is_word_byte((unsigned char)lx->src[p])) p++;
    set_token(lx, tok, TOK_WORD, start, p - start);
    lx->pos = p;
    return ST_OK;
}

void lex_unread(Lexer *lx, const Token *tok)
{
    lx->back = *tok;
    lx->has_back = 1;
}

int tok_is(const Token *tok, const char *word)
{
    size_t n = strlen(word);
    return tok->kind == TOK_WORD && tok->len == n && memcmp(tok->text, word, n) == 0;
}

char *tok_copy(const Token *tok)
{
    char *s = malloc(tok->len + 1);
    if (!s) return NULL;
    memcpy(s, tok->text, tok->len);
    s[tok->len] = '\0';
    return s;
}

/* Length of the UTF-8 sequence starting at s (a byte >= 0x80), or 0 when it is not a
 * valid one: the bytes of a binary file are then shown as \xNN, so that messages stay
 * valid text. */
static size_t utf8_length(const char *s, size_t avail)
{
    const unsigned char *u = (const unsigned char *)s;
    size_t k = u[0] >= 0xf0 && u[0] <= 0xf4 ? 4 : u[0] >= 0xe0 ? 3 : u[0] >= 0xc2 && u[0] <= 0xdf ? 2 : 0;
    if (u[0] > 0xf4 || k == 0 || k > avail) return 0;
    for (size_t j = 1; j < k; j++)
        if ((u[j] & 0xc0) != 0x80) return 0;
    /* overlong or surrogate forms, and code points above U+10FFFF */
    if ((u[0] == 0xe0 && u[1] < 0xa0) || (u[0] == 0xed && u[1] >= 0xa0) ||
        (u[0] == 0xf0 && u[1] < 0x90) || (u[0] == 0xf4 && u[1] >= 0x90))
        return 0;
    return k;
}

void tok_describe(const Token *tok, char *buf, size_t size)
{
    if (size == 0) return;
    if (tok->kind == TOK_EOF) {
        snprintf(buf, size, "end of file");
        return;
    }
    enum { SHOWN = 40 };
    size_t o = 0;
    /* Room for one more byte plus what the longest step writes: "\xNN" or the ending. */
#define ROOM(k) (o + (k) < size)
    int quoted = tok->kind == TOK_STRING;
    if (quoted && ROOM(1)) buf[o++] = '"';
    size_t i;
    for (i = 0; i < tok->len && i < SHOWN;) {
        unsigned char c = (unsigned char)tok->text[i];
        size_t k = c < 0x80 ? 1 : utf8_length(tok->text + i, tok->len - i);
        if (is_control(c) || k == 0) {
            if (!ROOM(4)) break;
            snprintf(buf + o, size - o, "\\x%02x", c);
            o += 4;
            i++;
        } else {
            if (!ROOM(k)) break;
            memcpy(buf + o, tok->text + i, k);
            o += k;
            i += k;
        }
    }
    if (i < tok->len && ROOM(3)) {
        memcpy(buf + o, "...", 3);
        o += 3;
    }
    if (quoted && ROOM(1)) buf[o++] = '"';
#undef ROOM
    buf[o] = '\0';
}

Status tok_expected(const char *path, const Token *tok, const char *what, Error *err)
{
    char found[64];
    tok_describe(tok, found, sizeof found);
    if (tok->kind == TOK_EOF)
        return error_set(err, ST_INPUT, "%s:%u:%u: expected %s, found end of file",
                         path, tok->line, tok->col, what);
    return error_set(err, ST_INPUT, "%s:%u:%u: expected %s, found '%s'", path, tok->line,
                     tok->col, what, found);
}

Status lex_expected(const Lexer *lx, const Token *tok, const char *what, Error *err)
{
    return tok_expected(lx->path, tok, what, err);
}

Status lex_error_at(const Lexer *lx, const Token *tok, Error *err, const char *fmt, ...)
{
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return error_set(err, ST_INPUT, "%s:%u:%u: %s", lx->path, tok->line, tok->col, msg);
}

int tok_float(const Token *tok, float *out)
{
    if (tok->kind != TOK_WORD || tok->len == 0) return -1;
    char local[128];
    char *buf = local;
    if (tok->len >= sizeof local) {
        buf = malloc(tok->len + 1);
        if (!buf) return -1;
    }
    memcpy(buf, tok->text, tok->len);
    buf[tok->len] = '\0';
    char *end;
    float v = strtof(buf, &end);
    /* strtof skips leading whitespace; a word has none, so `end` decides alone */
    int ok = end == buf + tok->len && isfinite(v);
    if (buf != local) free(buf);
    if (!ok) return -1;
    *out = v;
    return 0;
}

int tok_uint(const Token *tok, unsigned long long *out)
{
    if (tok->kind != TOK_WORD) return -1;
    size_t i = 0;
    if (i < tok->len && tok->text[i] == '+') i++;
    if (i == tok->len) return -1;
    unsigned long long v = 0;
    for (; i < tok->len; i++) {
        char c = tok->text[i];
        if (c < '0' || c > '9') return -1;
        unsigned d = (unsigned)(c - '0');
        if (v > (~0ull - d) / 10) return -1;
        v = v * 10 + d;
    }
    *out = v;
    return 0;
}
