/*
 * ply.c — the PLY reader (the subset is described in ply.h).
 *
 * The header is read line by line into a list of elements and their properties, each
 * property tagged with the role it plays (a coordinate, a normal, a texture coordinate,
 * the face's index list, or nothing). Before anything else is allocated, the counts are
 * checked against the bytes that follow the header: every binary record needs at least
 * the sizes of its scalars and list counts, every ascii value at least two bytes. The
 * data is then read record by record in one pass over the file in memory; ascii numbers
 * take the exact fast path of mesh_parse_float, so the 34 MB ascii dragon reads in a
 * few tenths of a second. Faces are kept as vertex-index triples and turned into scene
 * triangles at the end, which lets the face element come before the vertex element.
 */
#include "io/ply.h"

#include "base/array.h"
#include "base/strmap.h"

#include "util/kmath.h"
#include "io/lexer.h"
#include "io/mesh_load.h"
#include "io/mesh_text.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef enum { T_INT8, T_UINT8, T_INT16, T_UINT16, T_INT32, T_UINT32, T_FLOAT32, T_FLOAT64, T_N } PlyType;

static const struct {
    const char *name, *alias;
    int size, is_float;
    double lo, hi;
} types[T_N] = {
    { "char", "int8", 1, 0, -128.0, 127.0 },
    { "uchar", "uint8", 1, 0, 0.0, 255.0 },
    { "short", "int16", 2, 0, -32768.0, 32767.0 },
    { "ushort", "uint16", 2, 0, 0.0, 65535.0 },
    { "int", "int32", 4, 0, -2147483648.0, 2147483647.0 },
    { "uint", "uint32", 4, 0, 0.0, 4294967295.0 },
    { "float", "float32", 4, 1, 0.0, 0.0 },
    { "double", "float64", 8, 1, 0.0, 0.0 },
};

enum { R_NONE, R_X, R_Y, R_Z, R_NX, R_NY, R_NZ, R_U, R_V, R_INDICES, R_N };
enum { EL_OTHER, EL_VERTEX, EL_FACE };
enum { F_ASCII, F_LITTLE, F_BIG };

/* Vertex property names and their roles; the first property with a role takes it. */
static const struct { const char *name; int role; } vertex_roles[] = {
    { "x", R_X }, { "y", R_Y }, { "z", R_Z }, { "nx", R_NX }, { "ny", R_NY }, { "nz", R_NZ },
    { "u", R_U }, { "v", R_V }, { "s", R_U }, { "t", R_V }, { "texture_u", R_U },
    { "texture_v", R_V }, { "texture_s", R_U }, { "texture_t", R_V },
};

typedef struct {
    const char *name;  size_t name_len;
    int is_list;
    PlyType count_type, type;
    int role;
    uint line;                    /* of its header line */
} PlyProp;

typedef struct {
    const char *name;  size_t name_len;
    uint64_t count;
    uint line;                    /* of its header line */
    const char *line_at;          /* the start of that line */
    PlyProp *props;  size_t n_props, cap_props;
    unsigned roles_taken;         /* bit R_*: a property has that role */
    StrMap prop_names;            /* property name -> its index: a name may come once */
    int kind;
} PlyElement;

typedef struct {
    const char *path;
    const char *data, *end;       /* the whole file; *end == '\0' */
    const char *p;                /* cursor */
    const char *line_start;       /* ascii: start of the cursor's line */
    uint line;
    int format;
    int swap;                     /* binary data of the other byte order than this host's */
    Error *err;
    PlyElement *el;  size_t n_el, cap_el;
    int seen_kind[3];             /* EL_VERTEX, EL_FACE: that element was declared */
    /* what the current record is, for messages */
    const PlyElement *cur_el;
    uint64_t cur_rec;
    const PlyProp *cur_prop;
    /* the mesh */
    float *pos, *nrm, *uv;        /* 3, 3 and 2 per vertex */
    size_t n_vert;
    int vertices_read, has_nrm, has_uv;
    uint *tri;  size_t n_tri, cap_tri;      /* vertex indices, 3 per triangle */
    uint *poly; size_t cap_poly;            /* one face's corners */
} PlyReader;

/* ------------------------------------------------------------------ messages */

/* "path:line:col: " for a position in the header or ascii data, "path: byte offset N: "
 * in binary data. */
static void where(const PlyReader *r, const char *at, int in_header, char *buf, size_t size)
{
    if (in_header || r->format == F_ASCII) {
        /* the column counts from the start of at's line */
        const char *ls = at;
        while (ls > r->data && ls[-1] != '\n') ls--;
        uint line = r->line;
        if (at < r->line_start) {
            /* an earlier line (a header line passed in explicitly): count */
            line = 1;
            for (const char *q = r->data; q < ls; q++) line += *q == '\n';
        }
        snprintf(buf, size, "%s:%u:%u", r->path, line, (uint)(at - ls + 1));
    } else {
        snprintf(buf, size, "%s: byte offset %zu", r->path, (size_t)(at - r->data));
    }
}

/* " (element 'face', record 12, property 'vertex_indices')" */
static void record_context(const PlyReader *r, char *buf, size_t size)
{
    buf[0] = '\0';
    if (!r->cur_el) return;
    int n = snprintf(buf, size, " (element '%.*s', record %llu", (int)r->cur_el->name_len, r->cur_el->name,
                     (unsigned long long)r->cur_rec);
    if (n < 0 || (size_t)n >= size) return;
    if (r->cur_prop)
        snprintf(buf + n, size - (size_t)n, ", property '%.*s')", (int)r->cur_prop->name_len, r->cur_prop->name);
    else
        snprintf(buf + n, size - (size_t)n, ")");
}

static Status fail(PlyReader *r, const char *at, int in_header, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static Status fail(PlyReader *r, const char *at, int in_header, const char *fmt, ...)
{
    char pos[600], msg[512], ctx[256];
    where(r, at, in_header, pos, sizeof pos);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (in_header) ctx[0] = '\0';
    else record_context(r, ctx, sizeof ctx);
    return error_set(r->err, ST_INPUT, "%s: %s%s", pos, msg, ctx);
}

static int is_ws(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

/* "expected <what>, found '<token at q>'" (or "found end of file"). */
static Status fail_expected(PlyReader *r, const char *q, int in_header, const char *what)
{
    if (q >= r->end) return fail(r, q, in_header, "expected %s, found end of file", what);
    const char *e = q;
    while (e < r->end && !is_ws(*e)) e++;
    Token t;
    t.kind = TOK_WORD;
    t.text = q;
    t.len = (size_t)(e - q);
    t.line = 0;
    t.col = 0;
    char shown[64];
    tok_describe(&t, shown, sizeof shown);
    return fail(r, q, in_header, "expected %s, found '%s'", what, shown);
}

static Status out_of_memory(PlyReader *r)
{
    return error_set(r->err, ST_INTERNAL, "out of memory reading '%s'", r->path);
}

/* ------------------------------------------------------------------ header */

typedef struct { const char *t[8]; size_t len[8]; int n; } Words;

/* Splits [b, e) into blank-separated words (at most 8; more counts as 8 + 1). */
static void split_words(const char *b, const char *e, Words *w)
{
    w->n = 0;
    while (b < e) {
        while (b < e && (*b == ' ' || *b == '\t' || *b == '\r')) b++;
        if (b >= e) break;
        const char *s = b;
        while (b < e && *b != ' ' && *b != '\t' && *b != '\r') b++;
        if (w->n == 8) {
            w->n = 9;
            return;
        }
        w->t[w->n] = s;
        w->len[w->n] = (size_t)(b - s);
        w->n++;
    }
}

static int word_eq(const Words *w, int i, const char *s)
{
    return i < w->n && w->len[i] == strlen(s) && memcmp(w->t[i], s, w->len[i]) == 0;
}

static int parse_type(const Words *w, int i, PlyType *out)
{
    for (int k = 0; k < T_N; k++)
        if (word_eq(w, i, types[k].name) || word_eq(w, i, types[k].alias)) {
            *out = (PlyType)k;
            return 0;
        }
    return -1;
}

#define TYPE_LIST "a type (char, uchar, short, ushort, int, uint, float, double, or int8 ... float64)"

static Status add_property(PlyReader *r, const Words *w, const char *line)
{
    if (r->n_el == 0) return fail(r, line, 1, "a property before the first element");
    PlyElement *e = &r->el[r->n_el - 1];
    PlyProp p;
    memset(&p, 0, sizeof p);
    int at = 1;
    if (word_eq(w, 1, "list")) {
        p.is_list = 1;
        if (parse_type(w, 2, &p.count_type) || types[p.count_type].is_float)
            return fail_expected(r, w->n > 2 ? w->t[2] : line + strlen("property list "), 1,
                                 "an integer type for the list count (char, uchar, short, ushort, int, uint)");
        at = 3;
    }
    if (parse_type(w, at, &p.type))
        return fail_expected(r, w->n > at ? w->t[at] : line, 1, TYPE_LIST);
    if (w->n != at + 2)
        return fail_expected(r, w->n > at + 2 ? w->t[at + 2] : line, 1,
                             w->n > at + 2 ? "end of line after the property name" : "a property name");
    p.name = w->t[at + 1];
    p.name_len = w->len[at + 1];
    p.line = r->line;
    /* a second 'x' would be read into the first one's place, or ignored, silently:
     * which of the two the file meant is unknowable */
    int seen = strmap_add(&e->prop_names, p.name, p.name_len, (uint32_t)e->n_props);
    if (seen < 0) return out_of_memory(r);
    if (seen > 0) {
        uint32_t first = 0;
        strmap_find(&e->prop_names, p.name, p.name_len, &first);
        return fail(r, p.name, 1, "a second property '%.*s' in element '%.*s' (the first is on line %u); a name "
                    "may come once in an element", (int)p.name_len, p.name, (int)e->name_len, e->name,
                    e->props[first].line);
    }
    Words name = { { p.name }, { p.name_len }, 1 };
    if (e->kind == EL_VERTEX && !p.is_list) {
        for (size_t k = 0; k < sizeof vertex_roles / sizeof vertex_roles[0]; k++)
            if (word_eq(&name, 0, vertex_roles[k].name)) p.role = vertex_roles[k].role;
    }
    if (e->kind == EL_FACE && (word_eq(&name, 0, "vertex_indices") || word_eq(&name, 0, "vertex_index"))) {
        if (!p.is_list || types[p.type].is_float)
            return fail(r, p.name, 1, "'%.*s' must be a list of integers (property list uchar int %.*s)",
                        (int)p.name_len, p.name, (int)p.name_len, p.name);
        p.role = R_INDICES;
    }
    /* a role already taken by an earlier property stays with it (a bit set rather
     * than a scan of the earlier properties, which was quadratic in their number) */
    if (e->roles_taken & (1u << p.role)) p.role = R_NONE;
    if (p.role != R_NONE) e->roles_taken |= 1u << p.role;
    if (array_reserve((void **)&e->props, &e->cap_props, e->n_props + 1, sizeof *e->props)) return out_of_memory(r);
    e->props[e->n_props++] = p;
    return ST_OK;
}

static Status add_element(PlyReader *r, const Words *w, const char *line, uint line_no)
{
    if (w->n != 3) return fail_expected(r, w->n > 3 ? w->t[3] : line, 1, "'element NAME COUNT'");
    uint64_t count = 0;
    for (size_t i = 0; i < w->len[2]; i++) {
        char c = w->t[2][i];
        if (c < '0' || c > '9' || count > (UINT64_C(1) << 40))
            return fail_expected(r, w->t[2], 1, "a record count (a whole number below 2^40)");
        count = count * 10 + (uint64_t)(c - '0');
    }
    if (array_reserve((void **)&r->el, &r->cap_el, r->n_el + 1, sizeof *r->el)) return out_of_memory(r);
    PlyElement *e = &r->el[r->n_el];
    memset(e, 0, sizeof *e);
    e->name = w->t[1];
    e->name_len = w->len[1];
    e->count = count;
    e->line = line_no;
    e->line_at = line;
    e->kind = word_eq(w, 1, "vertex") ? EL_VERTEX : word_eq(w, 1, "face") ? EL_FACE : EL_OTHER;
    if (e->kind != EL_OTHER && r->seen_kind[e->kind])
        return fail(r, line, 1, "a second '%.*s' element", (int)e->name_len, e->name);
    r->seen_kind[e->kind] = 1;
    r->n_el++;
    return ST_OK;
}

/* Reads the header up to and including the end_header line; r->p is then the data. */
static Status parse_header(PlyReader *r)
{
    const char *p = r->data;
    int have_format = 0;
    for (uint line_no = 1;; line_no++) {
        r->line = line_no;
        r->line_start = p;
        if (p >= r->end)
            return fail(r, p, 1, "the header ends without 'end_header'");
        const char *nl = memchr(p, '\n', (size_t)(r->end - p));
        const char *le = nl ? nl : r->end;
        Words w;
        split_words(p, le, &w);
        if (line_no == 1) {
            if (!word_eq(&w, 0, "ply") || w.n != 1)
                return fail_expected(r, p, 1, "'ply' on the first line (is this a PLY file?)");
        } else if (w.n == 0) {
            return fail(r, p, 1, "an empty header line");
        } else if (word_eq(&w, 0, "comment") || word_eq(&w, 0, "obj_info")) {
            /* nothing */
        } else if (word_eq(&w, 0, "format")) {
            if (have_format) return fail(r, p, 1, "a second 'format' line");
            if (word_eq(&w, 1, "ascii")) r->format = F_ASCII;
            else if (word_eq(&w, 1, "binary_little_endian")) r->format = F_LITTLE;
            else if (word_eq(&w, 1, "binary_big_endian")) r->format = F_BIG;
            else return fail_expected(r, w.n > 1 ? w.t[1] : le, 1,
                                      "a PLY format (ascii, binary_little_endian, binary_big_endian)");
            if (!word_eq(&w, 2, "1.0") || w.n != 3)
                return fail_expected(r, w.n > 2 ? w.t[2] : le, 1, "version 1.0 after the format");
            have_format = 1;
        } else if (word_eq(&w, 0, "element")) {
            Status st = add_element(r, &w, p, line_no);
            if (st) return st;
        } else if (word_eq(&w, 0, "property")) {
            Status st = add_property(r, &w, p);
            if (st) return st;
        } else if (word_eq(&w, 0, "end_header") && w.n == 1) {
            if (!have_format) return fail(r, p, 1, "'end_header' before any 'format' line");
            r->p = nl ? nl + 1 : r->end;
            r->line = line_no + 1;
            r->line_start = r->p;
            return ST_OK;
        } else {
            return fail_expected(r, w.t[0], 1,
                                 "a header line (format, element, property, comment, obj_info, end_header)");
        }
        p = nl ? nl + 1 : r->end;
    }
}

/* Checks the vertex and face elements, then what the header promises against the bytes
 * that follow it, before anything is allocated from the counts. */
static Status check_header(PlyReader *r)
{
    for (size_t i = 0; i < r->n_el; i++) {
        const PlyElement *e = &r->el[i];
        const char *line = e->line_at;
        if (e->n_props == 0 && e->count > 0)
            return fail(r, line, 1, "element '%.*s' has %llu records but no properties", (int)e->name_len,
                        e->name, (unsigned long long)e->count);
        if (e->kind == EL_VERTEX) {
            int have[R_N] = { 0 };
            for (size_t k = 0; k < e->n_props; k++) have[e->props[k].role] = 1;
            static const char axis[3] = { 'x', 'y', 'z' };
            for (int a = 0; a < 3; a++)
                if (!have[R_X + a])
                    return fail(r, line, 1, "the vertex element has no '%c' property", axis[a]);
            if (e->count >= (uint64_t)UINT32_MAX)
                return fail(r, line, 1, "%llu vertices, more than the %u supported",
                            (unsigned long long)e->count, UINT32_MAX - 1);
            r->has_nrm = have[R_NX] && have[R_NY] && have[R_NZ];
            r->has_uv = have[R_U] && have[R_V];
        }
        if (e->kind == EL_FACE) {
            int have = 0;
            for (size_t k = 0; k < e->n_props; k++) have |= e->props[k].role == R_INDICES;
            if (!have) return fail(r, line, 1, "the face element has no 'vertex_indices' list");
        }
    }
    double avail = (double)(r->end - r->p), need = 0.0;
    for (size_t i = 0; i < r->n_el; i++) {
        const PlyElement *e = &r->el[i];
        double min = 0.0;
        for (size_t k = 0; k < e->n_props; k++) {
            const PlyProp *p = &e->props[k];
            if (r->format == F_ASCII) min += 2.0;
            else min += types[p->is_list ? p->count_type : p->type].size;
        }
        need += (double)e->count * min;
        /* the last ascii value needs no separator after it */
        if (need > avail + (r->format == F_ASCII ? 1.0 : 0.0))
            return fail(r, e->line_at, 1,
                        "element '%.*s' declares %llu records of at least %.0f bytes each, more than "
                        "the %.0f bytes after the header can hold (a truncated file or a wrong count)",
                        (int)e->name_len, e->name, (unsigned long long)e->count, min, avail);
    }
    return ST_OK;
}

/* ------------------------------------------------------------------ values */

/* Skips ascii white space, counting lines. */
static void skip_ws(PlyReader *r)
{
    const char *p = r->p;
    while (p < r->end && is_ws(*p)) {
        if (*p == '\n') {
            r->line++;
            r->line_start = p + 1;
        }
        p++;
    }
    r->p = p;
}

static Status bad_value(PlyReader *r, const char *at, PlyType t)
{
    char what[160];
    if (types[t].is_float)
        snprintf(what, sizeof what, "a finite number (%s)", types[t].name);
    else
        snprintf(what, sizeof what, "a whole number in %.0f..%.0f (%s)", types[t].lo, types[t].hi, types[t].name);
    return fail_expected(r, at, 0, what);
}

static Status ascii_value(PlyReader *r, PlyType t, double *out)
{
    skip_ws(r);
    const char *p = r->p;
    if (p >= r->end) return bad_value(r, p, t);
    if (types[t].is_float) {
        float f;
        const char *e = mesh_parse_float(p, r->end, &f);
        if (e && (e >= r->end || is_ws(*e))) {
            *out = f;
            r->p = e;
            return ST_OK;
        }
        if (t == T_FLOAT64) {
            /* a double beyond the float range is still a valid value */
            char *de;
            double d = strtod(p, &de);
            if (de != p && isfinite(d) && (de >= r->end || is_ws(*de))) {
                *out = d;
                r->p = de;
                return ST_OK;
            }
        }
        return bad_value(r, p, t);
    }
    const char *q = p;
    int neg = 0;
    if (*q == '-' || *q == '+') neg = *q++ == '-';
    double v = 0.0;
    const char *digits = q;
    while (q < r->end && *q >= '0' && *q <= '9' && v < 1e12) v = v * 10.0 + (*q++ - '0');
    if (q == digits || (q < r->end && !is_ws(*q))) return bad_value(r, p, t);
    v = neg ? -v : v;
    if (v < types[t].lo || v > types[t].hi) return bad_value(r, p, t);
    *out = v;
    r->p = q;
    return ST_OK;
}

static Status truncated(PlyReader *r)
{
    return fail(r, r->end, 0, "the file ends inside a record; the header declares %llu records of element '%.*s'",
                (unsigned long long)r->cur_el->count, (int)r->cur_el->name_len, r->cur_el->name);
}

static Status binary_value(PlyReader *r, PlyType t, double *out)
{
    int size = types[t].size;
    if (r->end - r->p < size) return truncated(r);
    unsigned char b[8];
    memcpy(b, r->p, (size_t)size);
    if (r->swap)
        for (int i = 0; i < size / 2; i++) {
            unsigned char x = b[i];
            b[i] = b[size - 1 - i];
            b[size - 1 - i] = x;
        }
    switch (t) {
    case T_INT8: { int8_t v; memcpy(&v, b, 1); *out = v; break; }
    case T_UINT8: *out = b[0]; break;
    case T_INT16: { int16_t v; memcpy(&v, b, 2); *out = v; break; }
    case T_UINT16: { uint16_t v; memcpy(&v, b, 2); *out = v; break; }
    case T_INT32: { int32_t v; memcpy(&v, b, 4); *out = v; break; }
    case T_UINT32: { uint32_t v; memcpy(&v, b, 4); *out = v; break; }
    case T_FLOAT32: { float v; memcpy(&v, b, 4); *out = v; break; }
    case T_FLOAT64: { double v; memcpy(&v, b, 8); *out = v; break; }
    case T_N: break;
    }
    r->p += size;
    return ST_OK;
}

static Status read_value(PlyReader *r, PlyType t, double *out)
{
    return r->format == F_ASCII ? ascii_value(r, t, out) : binary_value(r, t, out);
}

/* Where the next value starts, for messages about it. */
static const char *value_start(PlyReader *r)
{
    if (r->format == F_ASCII) skip_ws(r);
    return r->p;
}

/* ------------------------------------------------------------------ records */

static Status add_face(PlyReader *r, size_t n, const char *at)
{
    if (n < 3) return fail(r, at, 0, "a face needs at least 3 vertices, found %zu", n);
    size_t tris = n - 2;
    if (array_reserve((void **)&r->tri, &r->cap_tri, 3 * (r->n_tri + tris), sizeof *r->tri)) return out_of_memory(r);
    uint *t = r->tri + 3 * r->n_tri;
    for (size_t k = 1; k + 1 < n; k++) {
        *t++ = r->poly[0];
        *t++ = r->poly[k];
        *t++ = r->poly[k + 1];
    }
    r->n_tri += tris;
    return ST_OK;
}

/* A list: its count, then the values; the face's vertex indices are kept. */
static Status read_list(PlyReader *r, const PlyProp *p, int indices)
{
    const char *at = value_start(r);
    double c;
    Status st = read_value(r, p->count_type, &c);
    if (st) return st;
    if (c < 0.0) return fail(r, at, 0, "a negative list count, %.0f", c);
    /* The count is checked against the bytes left before anything is reserved from it:
     * a list is at least one byte per binary value or two per ascii value (a digit and a
     * separator, none after the last), so a lying count fails here instead of asking for
     * gigabytes. */
    double left = (double)(r->end - r->p);
    double least = r->format == F_ASCII ? 2.0 * c - 1.0 : c * (double)types[p->type].size;
    if (least > left) return truncated(r);
    size_t n = (size_t)c;
    if (!indices && r->format != F_ASCII) {
        r->p += n * (size_t)types[p->type].size;
        return ST_OK;
    }
    if (indices && array_reserve((void **)&r->poly, &r->cap_poly, n, sizeof *r->poly)) return out_of_memory(r);
    for (size_t i = 0; i < n; i++) {
        double v;
        const char *vat = value_start(r);
        if ((st = read_value(r, p->type, &v))) return st;
        if (!indices) continue;
        if (v < 0.0 || (r->vertices_read && v >= (double)r->n_vert))
            return fail(r, vat, 0, "vertex index %.0f is out of range (the file has %zu vertices)", v, r->n_vert);
        r->poly[i] = (uint)v;
    }
    return indices ? add_face(r, n, at) : ST_OK;
}

static Status read_element(PlyReader *r, PlyElement *e)
{
    r->cur_el = e;
    if (e->kind == EL_VERTEX) {
        size_t n = (size_t)e->count;
        r->n_vert = n;
        r->pos = malloc(3 * n * sizeof *r->pos + 1);
        r->nrm = r->has_nrm ? malloc(3 * n * sizeof *r->nrm + 1) : NULL;
        r->uv = r->has_uv ? malloc(2 * n * sizeof *r->uv + 1) : NULL;
        if (!r->pos || (r->has_nrm && !r->nrm) || (r->has_uv && !r->uv)) return out_of_memory(r);
    }
    if (e->kind == EL_FACE && e->count > 0 &&
        array_reserve((void **)&r->tri, &r->cap_tri, 3 * (size_t)e->count, sizeof *r->tri))
        return out_of_memory(r);
    for (uint64_t rec = 0; rec < e->count; rec++) {
        r->cur_rec = rec;
        float val[R_N] = { 0 };
        for (size_t k = 0; k < e->n_props; k++) {
            const PlyProp *p = &e->props[k];
            r->cur_prop = p;
            Status st;
            if (p->is_list) {
                st = read_list(r, p, p->role == R_INDICES);
            } else {
                double v;
                st = read_value(r, p->type, &v);
                val[p->role] = (float)v;
            }
            if (st) return st;
        }
        r->cur_prop = NULL;
        if (e->kind == EL_VERTEX) {
            memcpy(&r->pos[3 * rec], &val[R_X], 3 * sizeof *val);
            if (r->has_nrm) memcpy(&r->nrm[3 * rec], &val[R_NX], 3 * sizeof *val);
            if (r->has_uv) memcpy(&r->uv[2 * rec], &val[R_U], 2 * sizeof *val);
        }
    }
    if (e->kind == EL_VERTEX) r->vertices_read = 1;
    r->cur_el = NULL;
    return ST_OK;
}

/* ------------------------------------------------------------------ the mesh */

static Status emit_triangles(PlyReader *r, Scene *s, const MeshOptions *o)
{
    /* faces read before the vertices could not be checked then */
    for (size_t i = 0; i < 3 * r->n_tri; i++)
        if (r->tri[i] >= r->n_vert)
            return error_set(r->err, ST_INPUT, "%s: vertex index %u of triangle %zu is out of range (the file has %zu vertices)",
                             r->path, r->tri[i], i / 3, r->n_vert);
    MeshSink k;
    Status st = mesh_sink_open(&k, s, &o->xf, r->path, r->err);
    if (!st) st = mesh_sink_reserve(&k, r->n_tri, r->has_nrm || r->has_uv ? r->n_tri : 0);
    if (st) return st;
    uint material = o->material != NO_INDEX ? o->material : o->default_material;
    if (r->n_tri > 0 && (st = mesh_default_material(s, &material, r->err))) return st;
    for (size_t i = 0; i < r->n_tri && !st; i++) {
        const uint *t = &r->tri[3 * i];
        vec3 p[3], n[3];
        float uv[6];
        for (int c = 0; c < 3; c++) {
            const float *q = &r->pos[3 * (size_t)t[c]];
            p[c] = v3(q[0], q[1], q[2]);
            if (r->has_nrm) {
                q = &r->nrm[3 * (size_t)t[c]];
                n[c] = v3(q[0], q[1], q[2]);
            }
            if (r->has_uv) memcpy(&uv[2 * c], &r->uv[2 * (size_t)t[c]], 2 * sizeof *uv);
        }
        st = mesh_sink_triangle(&k, p, r->has_nrm ? n : NULL, r->has_uv ? uv : NULL, material);
    }
    return st;
}

Status ply_parse(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o, Error *err)
{
    PlyReader r = { .path = path, .data = data, .end = data + len, .err = err };
    uint16_t one = 1;
    unsigned char first;
    memcpy(&first, &one, 1);
    Status st = parse_header(&r);
    r.swap = r.format != F_ASCII && (r.format == F_LITTLE) != (first == 1);
    if (!st) st = check_header(&r);
    for (size_t i = 0; i < r.n_el && !st; i++) st = read_element(&r, &r.el[i]);
    if (!st && r.format == F_ASCII) {
        skip_ws(&r);
        if (r.p < r.end) st = fail_expected(&r, r.p, 0, "the end of the file after the last element");
    }
    if (!st) st = emit_triangles(&r, s, o);
    for (size_t i = 0; i < r.n_el; i++) {
        free(r.el[i].props);
        strmap_free(&r.el[i].prop_names);
    }
    free(r.el);
    free(r.pos);
    free(r.nrm);
    free(r.uv);
    free(r.tri);
    free(r.poly);
    return st;
}

Status ply_load(const char *path, Scene *s, const MeshOptions *o, Error *err)
{
    return mesh_read_with(path, ply_parse, s, o, err);
}
