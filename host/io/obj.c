/*
 * obj.c — the Wavefront OBJ reader (the subset is described in obj.h).
 *
 * Meshes reach millions of vertices, so this reader does not use the general lexer: it
 * walks the text in memory once, line by line, keeps vertex data in growing arrays and
 * a reused buffer for a face's corners, and allocates nothing per token. Numbers with
 * few digits take an exact fast path (see parse_float); the rest go to strtof.
 */
#include "io/obj.h"
#include "base/array.h"
#include "io/texture.h"

#include "util/kmath.h"
#include "io/lexer.h"
#include "io/mesh_load.h"
#include "io/mesh_text.h"
#include "io/path.h"
#include "io/mtl.h"

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
    const MeshOptions *opt;
    MeshSink sink;
    uint material;               /* of the faces being read; NO_INDEX: the default */
    uint default_material;       /* the default, once needed */
    MtlLibrary lib;              /* the mtllib files read so far */
    StrMap mtl_read;             /* their paths, each read once however often named */
    uint *lib_index;             /* per library entry: its scene material, or NO_INDEX */
    size_t n_lib_index, cap_lib_index;
    Error *err;
    vec3 *pos;     size_t n_pos, cap_pos;
    float *uv;     size_t n_uv, cap_uv;       /* pairs */
    vec3 *nrm;     size_t n_nrm, cap_nrm;     /* unit, or zero when unusable */
    Corner *face;  size_t cap_face;
    uint *keys;    size_t n_keys, cap_keys;   /* smooth_by_index: the triangles' corners'
                                               * vertex indices, in the scene's order */
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
    Token t = { .kind = TOK_WORD, .text = q, .len = (size_t)(e - q), .line = r->line, .col = col };
    return tok_expected(r->path, &t, what, r->err);
}

/* ------------------------------------------------------------------ numbers */

/* Reads one number at the cursor, exactly as strtof would round it. */
static int parse_float(ObjReader *r, float *out)
{
    const char *e = mesh_parse_float(r->p, r->end, out);
    if (!e || !is_delim(r, e)) return -1;
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

/* The scene material of the faces being read: the override, the current usemtl's, or
 * the default (added on first use when the caller gave none). */
static Status face_material(ObjReader *r, uint *out)
{
    if (r->opt->material != NO_INDEX) {
        *out = r->opt->material;
        return ST_OK;
    }
    if (r->material != NO_INDEX) {
        *out = r->material;
        return ST_OK;
    }
    Status st = mesh_default_material(r->s, &r->default_material, r->err);
    if (st) return st;
    *out = r->default_material;
    return ST_OK;
}

/* The vertex indices of a triangle's corners for mesh_smooth_normals, in the order the
 * sink stores them (corners 1 and 2 swap under a mirroring transform). */
static Status keep_corner_keys(ObjReader *r, const Corner *const k[3])
{
    if (array_reserve((void **)&r->keys, &r->cap_keys, r->n_keys + 3, sizeof *r->keys))
        return error_set(r->err, ST_INTERNAL, "out of memory reading '%s'", r->path);
    int m = r->sink.mirrored != 0;
    r->keys[r->n_keys++] = k[0]->v;
    r->keys[r->n_keys++] = k[m ? 2 : 1]->v;
    r->keys[r->n_keys++] = k[m ? 1 : 2]->v;
    return ST_OK;
}

static Status emit_triangle(ObjReader *r, const Corner *a, const Corner *b, const Corner *c)
{
    const Corner *const k[3] = { a, b, c };
    vec3 p[3], n[3];
    float uv[6];
    int has_n = 1, has_uv = 1;
    for (int i = 0; i < 3; i++) {
        p[i] = r->pos[k[i]->v];
        has_n = has_n && k[i]->n != NO_INDEX && !v3_is_zero(r->nrm[k[i]->n]);
        has_uv = has_uv && k[i]->t != NO_INDEX;
    }
    for (int i = 0; i < 3; i++) {
        if (has_n) n[i] = r->nrm[k[i]->n];
        if (has_uv) memcpy(&uv[2 * i], &r->uv[2 * k[i]->t], 2 * sizeof *uv);
    }
    uint material;
    Status st = face_material(r, &material);
    if (!st && r->opt->smooth_by_index) st = keep_corner_keys(r, k);
    if (st) return st;
    return mesh_sink_triangle(&r->sink, p, has_n ? n : NULL, has_uv ? uv : NULL, material);
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

/* The rest of the statement, blanks trimmed (names may contain spaces). */
static void rest_of_line(ObjReader *r, const char **b, const char **e)
{
    skip_hspace(r);
    *b = r->p;
    while (!at_eol(r)) r->p++;
    const char *q = r->p;
    while (q > *b && (q[-1] == ' ' || q[-1] == '\t' || q[-1] == '\r')) q--;
    *e = q;
}

/* mtllib FILE...: each file is read into the library now (relative to the OBJ). A file
 * that cannot be opened is skipped with a warning, as most OBJ readers do: meshes often
 * travel without their MTL, and their faces then get the default material. */
static Status read_mtllib(ObjReader *r)
{
    if (r->opt->material != NO_INDEX) return ST_OK;   /* overridden: the MTL is not needed */
    for (;;) {
        skip_hspace(r);
        if (at_eol(r)) break;
        const char *name = r->p;
        while (!is_delim(r, r->p)) r->p++;
        char *path;
        path_resolve(r->path, name, (size_t)(r->p - name), PATH_ANY_CASE, &path);
        if (!path) return error_set(r->err, ST_INTERNAL, "out of memory reading '%s'", r->path);
        /* a file named again is not read again: 80,000 'mtllib' lines would otherwise
         * read the library 80,000 times */
        int again = strmap_add(&r->mtl_read, path, strlen(path), 0);
        if (again) {
            free(path);
            if (again < 0) return error_set(r->err, ST_INTERNAL, "out of memory reading '%s'", r->path);
            continue;
        }
        Status st = mtl_load(path, &r->lib, r->err);
        free(path);
        if (st == ST_IO) {
            char msg[sizeof r->err->msg];
            snprintf(msg, sizeof msg, "%s", r->err->msg);
            error_clear(r->err);
            st = scene_warn(r->s, r->err, "%s:%u:%u: %s; the faces that use its materials get the default "
                            "material", r->path, r->line, (uint)(name - r->line_start + 1), msg);
        }
        if (st) return st;
    }
    return ST_OK;
}

/* map_Kd: the diffuse colour of scene material `index` comes from the image (sRGB,
 * repeating). An image that cannot be read is a warning naming the MTL line, not an
 * error, for the same reason as a missing MTL file: models travel without their
 * textures, and the material still renders, with its Kd. A corrupt image is an error. */
static Status add_map_kd(ObjReader *r, const MtlMaterial *m, uint index)
{
    uint tex;
    Error image_err = { 0 };
    Status st = texture_load_image(r->s, NULL, m->texture, 0, 0, &tex, &image_err);
    if (st == ST_IO)
        st = scene_warn(r->s, r->err, "%s: %s; the material is rendered without this map_Kd texture",
                        m->texture_at, image_err.msg);
    else if (st)
        st = error_set(r->err, st, "%s", image_err.msg);
    else if (!(st = scene_set_material_texture(r->s, index, m->texture, r->err)))
        r->s->materials[index].texture = tex;
    error_clear(&image_err);
    return st;
}

/* usemtl NAME: the faces that follow get the library's material NAME, added to the
 * scene the first time it is used. A name no MTL defines gives the default material
 * (McGuire's glossy Cornell boxes use a 'light' their MTL lacks). */
static Status read_usemtl(ObjReader *r)
{
    const char *name, *end;
    rest_of_line(r, &name, &end);
    if (r->opt->material != NO_INDEX) return ST_OK;
    const MtlMaterial *m = mtl_find(&r->lib, name, (size_t)(end - name));
    if (!m) {
        r->material = NO_INDEX;
        return ST_OK;
    }
    size_t i = (size_t)(m - r->lib.items);
    if (array_reserve((void **)&r->lib_index, &r->cap_lib_index, r->lib.n, sizeof *r->lib_index))
        return error_set(r->err, ST_INTERNAL, "out of memory reading '%s'", r->path);
    while (r->n_lib_index < r->lib.n) r->lib_index[r->n_lib_index++] = NO_INDEX;
    if (r->lib_index[i] == NO_INDEX) {
        Status st = scene_add_material(r->s, "", m->m, &r->lib_index[i], r->err);
        if (!st && m->texture) st = add_map_kd(r, m, r->lib_index[i]);
        if (st) return st;
    }
    r->material = r->lib_index[i];
    return ST_OK;
}

/* Statements accepted and skipped: grouping and smoothing, and line and point
 * elements, which have no surface. */
static const char *const ignored[] = {"o", "g", "s", "l", "p"};

static int word_is(const char *q, size_t len, const char *w)
{
    return strlen(w) == len && memcmp(q, w, len) == 0;
}

Status obj_parse_with(const char *path, const char *text, size_t len, Scene *s, const MeshOptions *o,
                      Error *err)
{
    /* the reader's own state (a line cursor for its messages) at the first line; the
     * members not named start at zero */
    ObjReader r = { .path = path, .p = text, .end = text + len, .line_start = text, .line = 1, .s = s, .opt = o,
                    .material = NO_INDEX, .default_material = o->default_material, .err = err };
    size_t first = s->n_triangles;
    Status st = mesh_sink_open(&r.sink, s, &o->xf, path, err);
    while (!st && r.p < r.end) {
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
        } else if (word_is(kw, kl, "usemtl")) {
            st = read_usemtl(&r);
        } else if (word_is(kw, kl, "mtllib")) {
            st = read_mtllib(&r);
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
    if (!st && o->smooth_by_index) st = mesh_smooth_normals(s, first, r.keys, (uint)r.n_pos, err);
    free(r.keys);
    free(r.pos);
    free(r.uv);
    free(r.nrm);
    free(r.face);
    free(r.lib_index);
    mtl_free(&r.lib);
    strmap_free(&r.mtl_read);
    return st;
}

Status obj_parse(const char *path, const char *text, size_t len, Scene *s, uint material, Error *err)
{
    MeshOptions o = mesh_options(material);
    return obj_parse_with(path, text, len, s, &o, err);
}

Status obj_load_with(const char *path, Scene *s, const MeshOptions *o, Error *err)
{
    return mesh_read_with(path, obj_parse_with, s, o, err);
}

Status obj_load(const char *path, Scene *s, uint material, Error *err)
{
    MeshOptions o = mesh_options(material);
    return obj_load_with(path, s, &o, err);
}
