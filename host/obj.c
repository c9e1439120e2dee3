/*
 * obj.c — the Wavefront OBJ reader (the subset is described in obj.h).
 *
 * Meshes reach millions of vertices, so this reader does not use the general lexer: it
 * walks the text in memory once, line by line, keeps vertex data in growing arrays and
 * a reused buffer for a face's corners, and allocates nothing per token. Numbers with
 * few digits take an exact fast path (see parse_float); the rest go to strtof.
 */
#include "obj.h"

#include "kmath.h"
#include "lexer.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    uint v, t, n;        /* 0-based indices; t and n are NO_INDEX when absent */
} Corner;

typedef struct {
    const char *path;
    const char *p, *end;         /* cursor; *end == '\0' */
    const char *line_start;
    uint line;
    Scene *s;
    uint material;
    Error *err;
    vec3 *pos;     size_t n_pos, cap_pos;
    float *uv;     size_t n_uv, cap_uv;       /* pairs */
    vec3 *nrm;     size_t n_nrm, cap_nrm;     /* unit, or zero when unusable */
    Corner *face;  size_t cap_face;
} ObjReader;

/* ------------------------------------------------------------------ the cursor */

static int at_continuation(const ObjReader *r, const char *q)
{
    return q < r->end && q[0] == '\\' &&
           ((q + 1 < r->end && q[1] == '\n') || (q + 2 < r->end && q[1] == '\r' && q[2] == '\n'));
}

/* Skips spaces, tabs, stray CRs and `\` line continuations. */
static void skip_hspace(ObjReader *r)
{
    for (;;) {
        const char *q = r->p;
        if (q < r->end && (*q == ' ' || *q == '\t' || (*q == '\r' && !(q + 1 < r->end && q[1] == '\n')))) {
            r->p++;
        } else if (at_continuation(r, q)) {
            r->p = q + (q[1] == '\n' ? 2 : 3);
            r->line++;
            r->line_start = r->p;
        } else {
            return;
        }
    }
}

/* End of the statement: end of text, a newline (CRLF included) or a comment. */
static int at_eol(const ObjReader *r)
{
    const char *q = r->p;
    return q >= r->end || *q == '\n' || *q == '#' || (*q == '\r' && q + 1 < r->end && q[1] == '\n');
}

static int is_delim(const ObjReader *r, const char *q)
{
    return q >= r->end || *q == ' ' || *q == '\t' || *q == '\r' || *q == '\n' || *q == '#' ||
           at_continuation(r, q);
}

/* Moves past the rest of the line, continuations included, and the newline. */
static void next_line(ObjReader *r)
{
    while (r->p < r->end && *r->p != '\n') {
        if (at_continuation(r, r->p)) {
            r->p += r->p[1] == '\n' ? 2 : 3;
            r->line++;
            r->line_start = r->p;
        } else {
            r->p++;
        }
    }
    if (r->p < r->end) {
        r->p++;
        r->line++;
        r->line_start = r->p;
    }
}

/* "path:line:col: expected <what>, found '<token at q>'" (or "found end of line"). */
static Status fail_at(ObjReader *r, const char *q, const char *what)
{
    uint col = (uint)(q - r->line_start + 1);
    const char *save = r->p;
    r->p = q;
    int eol = at_eol(r);
    r->p = save;
    if (eol)
        return error_set(r->err, ST_INPUT, "%s:%u:%u: expected %s, found end of line", r->path,
                         r->line, col, what);
    const char *e = q;
    while (!is_delim(r, e)) e++;
    Token t;
    t.kind = TOK_WORD;
    t.text = q;
    t.len = (size_t)(e - q);
    t.line = r->line;
    t.col = col;
    char shown[64];
    tok_describe(&t, shown, sizeof shown);
    return error_set(r->err, ST_INPUT, "%s:%u:%u: expected %s, found '%s'", r->path, r->line, col,
                     what, shown);
}

/* ------------------------------------------------------------------ numbers */

static const float pow10_exact[11] = {1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f,
                                      1e6f, 1e7f, 1e8f, 1e9f, 1e10f};

/* Reads one number at the cursor, exactly as strtof would round it. The fast path
 * takes plain decimals whose digits form an integer m <= 2^24 with at most 10 of them
 * after the point: m and 10^k (k <= 10, since 5^10 < 2^24) are then exact floats, so
 * the single IEEE division m / 10^k is the correctly rounded value, which is strtof's
 * answer. Everything else (exponents, long mantissas, hex) goes to strtof. */
static int parse_float(ObjReader *r, float *out)
{
    const char *q = r->p;
    /* strtof would skip leading white space (\v, \f) that OBJ does not allow */
    if (q >= r->end || isspace((unsigned char)*q)) return -1;
    int neg = 0;
    if (q < r->end && (*q == '-' || *q == '+')) neg = *q++ == '-';
    uint64_t m = 0;
    int digits = 0, frac = 0, seen_point = 0;
    for (; q < r->end; q++) {
        if (*q >= '0' && *q <= '9') {
            if (digits < 19) m = m * 10 + (uint64_t)(*q - '0');
            digits += m > 0 || *q != '0';   /* leading zeros are free */
            frac += seen_point;
        } else if (*q == '.' && !seen_point) {
            seen_point = 1;
        } else {
            break;
        }
    }
    int has_digit = q > r->p + (neg || *r->p == '+') + seen_point;
    if (has_digit && is_delim(r, q) && digits < 19 && m <= (1u << 24) && frac <= 10) {
        float v = (float)m / pow10_exact[frac];
        *out = neg ? -v : v;
        r->p = q;
        return 0;
    }
    char *e;
    float v = strtof(r->p, &e);
    if (e == r->p || !is_delim(r, e) || !isfinite(v)) return -1;
    *out = v;
    r->p = e;
    return 0;
}

/* Reads `count` numbers; fails with "expected <count> numbers after '<kw>'". */
static Status read_floats(ObjReader *r, float *out, int count, const char *what)
{
    for (int i = 0; i < count; i++) {
        skip_hspace(r);
        if (at_eol(r) || parse_float(r, &out[i])) return fail_at(r, r->p, what);
    }
    return ST_OK;
}

/* Reads up to `max` more numbers, ignoring them but rejecting malformed ones. */
static Status read_optional_floats(ObjReader *r, float *out, int max, int *got, const char *what)
{
    *got = 0;
    for (int i = 0; i < max; i++) {
        skip_hspace(r);
        if (at_eol(r)) break;
        if (parse_float(r, &out[i])) return fail_at(r, r->p, what);
        (*got)++;
    }
    return ST_OK;
}

static Status expect_eol(ObjReader *r)
{
    skip_hspace(r);
    if (!at_eol(r)) return fail_at(r, r->p, "end of line");
    return ST_OK;
}

#define GROW(r, arr, n, cap)                                                              \
    (array_reserve((void **)&(arr), &(cap), (n) + 1, sizeof *(arr))                       \
         ? error_set((r)->err, ST_INTERNAL, "out of memory reading '%s'", (r)->path)       \
         : ST_OK)

/* ------------------------------------------------------------------ statements */

static Status read_v(ObjReader *r)
{
    float c[3], extra[4];
    int n_extra;
    Status st = read_floats(r, c, 3, "3 coordinates after 'v'");
    if (!st) st = read_optional_floats(r, extra, 4, &n_extra, "a number (w or r g b) after 'v x y z'");
    if (!st) st = expect_eol(r);
    if (!st) st = GROW(r, r->pos, r->n_pos, r->cap_pos);
    if (st) return st;
    r->pos[r->n_pos++] = v3(c[0], c[1], c[2]);
    return ST_OK;
}

static Status read_vt(ObjReader *r)
{
    float c[3] = {0.0f, 0.0f, 0.0f};
    int n_more;
    Status st = read_floats(r, c, 1, "a texture coordinate after 'vt'");
    if (!st) st = read_optional_floats(r, c + 1, 2, &n_more, "a number (v or w) after 'vt u'");
    if (!st) st = expect_eol(r);
    if (!st) st = array_reserve((void **)&r->uv, &r->cap_uv, 2 * r->n_uv + 2, sizeof *r->uv)
                      ? error_set(r->err, ST_INTERNAL, "out of memory reading '%s'", r->path)
                      : ST_OK;
    if (st) return st;
    r->uv[2 * r->n_uv] = c[0];
    r->uv[2 * r->n_uv + 1] = c[1];
    r->n_uv++;
    return ST_OK;
}

static Status read_vn(ObjReader *r)
{
    float c[3];
    Status st = read_floats(r, c, 3, "3 coordinates after 'vn'");
    if (!st) st = expect_eol(r);
    if (!st) st = GROW(r, r->nrm, r->n_nrm, r->cap_nrm);
    if (st) return st;
    double len = sqrt((double)c[0] * c[0] + (double)c[1] * c[1] + (double)c[2] * c[2]);
    /* a zero normal cannot be made unit; triangles using it are shaded flat */
    vec3 n = v3(0.0f, 0.0f, 0.0f);
    if (len > 0.0 && isfinite(len)) n = v3((float)(c[0] / len), (float)(c[1] / len), (float)(c[2] / len));
    r->nrm[r->n_nrm++] = n;
    return ST_OK;
}

/* Reads one 1-based or negative index at the cursor and makes it 0-based against
 * `count` items defined so far. */
static Status read_index(ObjReader *r, const char *tok, size_t count, const char *kind, uint *out)
{
    const char *q = r->p;
    int neg = 0;
    if (q < r->end && *q == '-') {
        neg = 1;
        q++;
    }
    uint64_t v = 0;
    const char *digits = q;
    while (q < r->end && *q >= '0' && *q <= '9') {
        if (v <= UINT32_MAX) v = v * 10 + (uint64_t)(*q - '0');
        q++;
    }
    char what[128];
    if (q == digits) {
        snprintf(what, sizeof what, "a %s index", kind);
        return fail_at(r, tok, what);
    }
    r->p = q;
    if (v == 0 || v > count) {
        if (count == 0)
            snprintf(what, sizeof what, "a %s index (none is defined before this line)", kind);
        else
            snprintf(what, sizeof what, "a %s index in 1..%zu or -%zu..-1", kind, count, count);
        return fail_at(r, tok, what);
    }
    *out = neg ? (uint)(count - v) : (uint)(v - 1);
    return ST_OK;
}

static Status emit_triangle(ObjReader *r, const Corner *a, const Corner *b, const Corner *c)
{
    Triangle t;
    memset(&t, 0, sizeof t);
    t.p0 = r->pos[a->v];
    t.p1 = r->pos[b->v];
    t.p2 = r->pos[c->v];
    t.material = r->material;
    t.shading = NO_INDEX;
    uint flags = 0;
    if (a->n != NO_INDEX && b->n != NO_INDEX && c->n != NO_INDEX &&
        !v3_is_zero(r->nrm[a->n]) && !v3_is_zero(r->nrm[b->n]) && !v3_is_zero(r->nrm[c->n]))
        flags |= TRI_HAS_NORMALS;
    if (a->t != NO_INDEX && b->t != NO_INDEX && c->t != NO_INDEX) flags |= TRI_HAS_UV;
    if (flags) {
        TriShading sh;
        memset(&sh, 0, sizeof sh);
        sh.flags = flags;
        if (flags & TRI_HAS_NORMALS) {
            sh.n0 = r->nrm[a->n];
            sh.n1 = r->nrm[b->n];
            sh.n2 = r->nrm[c->n];
        }
        if (flags & TRI_HAS_UV) {
            memcpy(sh.uv0, &r->uv[2 * a->t], sizeof sh.uv0);
            memcpy(sh.uv1, &r->uv[2 * b->t], sizeof sh.uv1);
            memcpy(sh.uv2, &r->uv[2 * c->t], sizeof sh.uv2);
        }
        Status st = scene_add_shading(r->s, sh, &t.shading, r->err);
        if (st) return st;
    }
    return scene_add_triangle(r->s, t, r->err);
}

static Status read_f(ObjReader *r, const char *kw)
{
    /* where `f` is, for the vertex count error (a continuation may move line_start) */
    uint kw_line = r->line, kw_col = (uint)(kw - r->line_start + 1);
    size_t n = 0;
    Status st;
    for (;;) {
        skip_hspace(r);
        if (at_eol(r)) break;
        const char *tok = r->p;
        Corner c = {0, NO_INDEX, NO_INDEX};
        if ((st = read_index(r, tok, r->n_pos, "vertex", &c.v))) return st;
        if (r->p < r->end && *r->p == '/') {
            r->p++;
            if (r->p < r->end && *r->p != '/') {
                if ((st = read_index(r, tok, r->n_uv, "texture coordinate", &c.t))) return st;
            }
            if (r->p < r->end && *r->p == '/') {
                r->p++;
                if ((st = read_index(r, tok, r->n_nrm, "normal", &c.n))) return st;
            }
        }
        if (!is_delim(r, r->p)) return fail_at(r, tok, "a face vertex (v, v/vt, v//vn or v/vt/vn)");
        if ((st = GROW(r, r->face, n, r->cap_face))) return st;
        r->face[n++] = c;
    }
    if (n < 3) {
        char found[48];
        snprintf(found, sizeof found, "%zu", n);
        return error_set(r->err, ST_INPUT,
                         "%s:%u:%u: expected at least 3 vertices in a face, found %s", r->path,
                         kw_line, kw_col, found);
    }
    for (size_t k = 1; k + 1 < n; k++)
        if ((st = emit_triangle(r, &r->face[0], &r->face[k], &r->face[k + 1]))) return st;
    return ST_OK;
}

/* Statements accepted and skipped: grouping, smoothing and materials (MTL support
 * comes with the meshes work), and line and point elements, which have no surface. */
static const char *const ignored[] = {"o", "g", "s", "usemtl", "mtllib", "l", "p"};

static int word_is(const char *q, size_t len, const char *w)
{
    return strlen(w) == len && memcmp(q, w, len) == 0;
}

Status obj_parse(const char *path, const char *text, size_t len, Scene *s, uint material,
                 Error *err)
{
    ObjReader r;
    memset(&r, 0, sizeof r);
    r.path = path;
    r.p = text;
    r.end = text + len;
    r.line_start = text;
    r.line = 1;
    r.s = s;
    r.material = material;
    r.err = err;
    Status st = ST_OK;
    while (r.p < r.end) {
        skip_hspace(&r);
        if (at_eol(&r)) {
            next_line(&r);
            continue;
        }
        const char *kw = r.p;
        while (!is_delim(&r, r.p)) r.p++;
        size_t kl = (size_t)(r.p - kw);
        if (word_is(kw, kl, "v")) {
            st = read_v(&r);
        } else if (word_is(kw, kl, "f")) {
            st = read_f(&r, kw);
        } else if (word_is(kw, kl, "vt")) {
            st = read_vt(&r);
        } else if (word_is(kw, kl, "vn")) {
            st = read_vn(&r);
        } else {
            size_t i, n = sizeof ignored / sizeof ignored[0];
            for (i = 0; i < n; i++)
                if (word_is(kw, kl, ignored[i])) break;
            if (i == n)
                st = fail_at(&r, kw, "an OBJ statement (v, vt, vn, f, o, g, s, usemtl, mtllib, l, p)");
        }
        if (st) break;
        next_line(&r);
    }
    free(r.pos);
    free(r.uv);
    free(r.nrm);
    free(r.face);
    return st;
}

Status obj_load(const char *path, Scene *s, uint material, Error *err)
{
    char *text;
    size_t len;
    Status st = lex_read_file(path, &text, &len, err);
    if (st) return st;
    st = obj_parse(path, text, len, s, material, err);
    free(text);
    return st;
}
