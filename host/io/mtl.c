/* mtl.c — the MTL reader and the mapping onto clpt materials (mtl.h). */
#include "io/mtl.h"

#include "base/array.h"
#include "util/kmath.h"
#include "io/lexer.h"
#include "io/mesh_text.h"
#include "io/path.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* What one newmtl block said, before it becomes a Material. */
typedef struct {
    vec3 kd, ks, ke;
    float ns, ni, d;
    int illum;
    int has_kd, has_ni, has_d;
    char *texture, *texture_at;
} MtlRaw;

typedef struct {
    const char *path;
    const char *p, *end;        /* cursor within the text */
    const char *line_start, *line_end;   /* the current line, comment excluded */
    uint line;
    Error *err;
    MtlLibrary *lib;
    long cur;                   /* index of the material being defined, -1 before any */
    MtlRaw raw;
} MtlReader;

void mtl_free(MtlLibrary *lib)
{
    for (size_t i = 0; i < lib->n; i++) {
        free(lib->items[i].name);
        free(lib->items[i].texture);
        free(lib->items[i].texture_at);
    }
    free(lib->items);
    strmap_free(&lib->by_name);
    memset(lib, 0, sizeof *lib);
}

const MtlMaterial *mtl_find(const MtlLibrary *lib, const char *name, size_t len)
{
    uint32_t i;
    return strmap_find(&lib->by_name, name, len, &i) ? &lib->items[i] : NULL;
}

/* ------------------------------------------------------------------ tokens */

static int is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

static void skip_blank(MtlReader *r)
{
    while (r->p < r->line_end && is_blank(*r->p)) r->p++;
}

/* The next blank-separated token of the line: [*t, return). */
static const char *next_token(MtlReader *r, const char **t)
{
    skip_blank(r);
    *t = r->p;
    while (r->p < r->line_end && !is_blank(*r->p)) r->p++;
    return r->p;
}

static Status fail_at(MtlReader *r, const char *q, const char *what)
{
    uint col = (uint)(q - r->line_start + 1);
    if (q >= r->line_end)
        return error_set(r->err, ST_INPUT, "%s:%u:%u: expected %s, found end of line", r->path, r->line,
                         col, what);
    const char *e = q;
    while (e < r->line_end && !is_blank(*e)) e++;
    Token t = { .kind = TOK_WORD, .text = q, .len = (size_t)(e - q), .line = r->line, .col = col };
    return tok_expected(r->path, &t, what, r->err);
}

static int token_number(const char *t, const char *e, float *out)
{
    return t < e && mesh_parse_float(t, e, out) == e ? 0 : -1;
}

/* One number >= lo after the keyword. */
static Status read_number(MtlReader *r, const char *kw, float lo, float *out)
{
    const char *t, *e = next_token(r, &t);
    char what[96];
    snprintf(what, sizeof what, "a number >= %g after '%s'", (double)lo, kw);
    if (token_number(t, e, out) || !(*out >= lo)) return fail_at(r, t, what);
    return ST_OK;
}

/* "r g b", or "r" alone for a grey; components >= 0. */
static Status read_color(MtlReader *r, const char *kw, vec3 *out)
{
    float c[3];
    char what[96];
    snprintf(what, sizeof what, "a colour (1 or 3 numbers >= 0) after '%s'", kw);
    int n = 0;
    for (; n < 3; n++) {
        const char *t, *e = next_token(r, &t);
        if (t == e && n == 1) break;
        if (token_number(t, e, &c[n]) || !(c[n] >= 0.0f)) return fail_at(r, t, what);
    }
    if (n == 1) c[1] = c[2] = c[0];
    *out = v3(c[0], c[1], c[2]);
    return ST_OK;
}

static Status expect_end(MtlReader *r)
{
    skip_blank(r);
    if (r->p < r->line_end) return fail_at(r, r->p, "end of line");
    return ST_OK;
}

/* ------------------------------------------------------------------ materials */

static Material raw_to_material(const MtlRaw *raw)
{
    Material m;
    int glass = raw->illum == 4 || raw->illum == 6 || raw->illum == 7 || raw->illum == 9 ||
                (raw->has_d && raw->d < 1.0f);
    int mirror = raw->illum == 3 || raw->illum == 5 || raw->illum == 8;
    vec3 kd = raw->has_kd ? raw->kd : v3s(0.8f);
    if (v3_max_comp(raw->ke) > 0.0f) {
        m = material_emissive(raw->ke);
    } else if (glass) {
        m = material_dielectric(raw->has_ni && raw->ni > 0.0f ? raw->ni : 1.5f);
    } else if (mirror) {
        /* Phong exponent to a roughness-like fuzz: 2/(Ns+2) is the variance of the
         * Blinn-Phong lobe's Beckmann equivalent (Walter et al. 2007) */
        float fuzz = (float)sqrt(2.0 / ((double)raw->ns + 2.0));
        m = material_metal(v3_is_zero(raw->ks) ? kd : raw->ks, fuzz > 1.0f ? 1.0f : fuzz);
    } else {
        m = material_diffuse(kd);
    }
    m.specular = raw->ks;
    m.shininess = raw->ns;
    return m;
}

static void raw_reset(MtlRaw *raw)
{
    free(raw->texture);
    free(raw->texture_at);
    memset(raw, 0, sizeof *raw);
    raw->d = 1.0f;
    raw->illum = -1;
}

/* Turns the block being read into the library entry it was opened for. */
static void finish_material(MtlReader *r)
{
    if (r->cur < 0) return;
    MtlMaterial *item = &r->lib->items[r->cur];
    item->m = raw_to_material(&r->raw);
    free(item->texture);
    free(item->texture_at);
    item->texture = r->raw.texture;
    item->texture_at = r->raw.texture_at;
    r->raw.texture = NULL;
    r->raw.texture_at = NULL;
    raw_reset(&r->raw);
    r->cur = -1;
}

static Status read_newmtl(MtlReader *r)
{
    finish_material(r);
    skip_blank(r);
    const char *name = r->p, *e = r->line_end;
    while (e > name && is_blank(e[-1])) e--;
    if (e == name) return fail_at(r, name, "a material name after 'newmtl'");
    size_t len = (size_t)(e - name);
    /* A NUL would end the name for every C string function that later reads it (and for
     * an OBJ's usemtl), while the name map keys the whole bytes: refuse it. */
    const char *nul = memchr(name, '\0', len);
    if (nul)
        return error_set(r->err, ST_INPUT, "%s:%u:%u: a NUL byte in the material name", r->path, r->line,
                         (uint)(nul - r->line_start + 1));
    MtlLibrary *lib = r->lib;
    uint32_t idx;
    if (!strmap_find(&lib->by_name, name, len, &idx)) {
        if (lib->n >= UINT32_MAX ||
            array_reserve((void **)&lib->items, &lib->cap, lib->n + 1, sizeof *lib->items))
            return error_set(r->err, ST_INTERNAL, "out of memory reading '%s'", r->path);
        MtlMaterial *m = &lib->items[lib->n];
        memset(m, 0, sizeof *m);
        m->name = malloc(len + 1);
        if (!m->name || strmap_add(&lib->by_name, name, len, (uint32_t)lib->n) < 0) {
            free(m->name);
            return error_set(r->err, ST_INTERNAL, "out of memory reading '%s'", r->path);
        }
        memcpy(m->name, name, len);
        m->name[len] = '\0';
        idx = (uint32_t)lib->n++;
    }
    r->cur = (long)idx;
    r->p = r->line_end;
    return ST_OK;
}

/* Texture options and how many values each takes (-o, -s, -t: 1 to 3 numbers). */
static int option_args(const char *t, size_t len, int *variable)
{
    static const struct { const char *name; int args, variable; } opts[] = {
        { "-blendu", 1, 0 }, { "-blendv", 1, 0 }, { "-boost", 1, 0 }, { "-mm", 2, 0 },
        { "-o", 3, 1 }, { "-s", 3, 1 }, { "-t", 3, 1 }, { "-texres", 1, 0 }, { "-clamp", 1, 0 },
        { "-bm", 1, 0 }, { "-imfchan", 1, 0 }, { "-type", 1, 0 }, { "-cc", 1, 0 },
    };
    for (size_t i = 0; i < sizeof opts / sizeof opts[0]; i++)
        if (strlen(opts[i].name) == len && strncasecmp(opts[i].name, t, len) == 0) {
            *variable = opts[i].variable;
            return opts[i].args;
        }
    return -1;
}

static Status read_map_kd(MtlReader *r)
{
    for (;;) {
        skip_blank(r);
        if (r->p >= r->line_end || *r->p != '-') break;
        const char *t, *e = next_token(r, &t);
        int variable = 0, n = option_args(t, (size_t)(e - t), &variable);
        if (n < 0) return fail_at(r, t, "a texture option (-blendu, -blendv, -boost, -mm, -o, -s, -t, "
                                        "-texres, -clamp, -bm, -imfchan, -type, -cc) or a file name");
        for (int i = 0; i < n; i++) {
            const char *save = r->p;
            const char *a, *ae = next_token(r, &a);
            float f;
            if (variable && i > 0 && token_number(a, ae, &f)) {
                r->p = save;
                break;
            }
            if (a == ae) return fail_at(r, a, "a value for the texture option");
        }
    }
    skip_blank(r);
    const char *name = r->p, *e = r->line_end;
    while (e > name && is_blank(e[-1])) e--;
    if (e == name) return fail_at(r, name, "a texture file name after 'map_Kd'");
    char *path;
    path_resolve(r->path, name, (size_t)(e - name), PATH_ANY_CASE, &path);
    char at[64];
    snprintf(at, sizeof at, ":%u:%u", r->line, (uint)(name - r->line_start + 1));
    char *where = malloc(strlen(r->path) + strlen(at) + 1);
    if (!path || !where) {
        free(path);
        free(where);
        return error_set(r->err, ST_INTERNAL, "out of memory reading '%s'", r->path);
    }
    strcpy(where, r->path);
    strcat(where, at);
    free(r->raw.texture);
    free(r->raw.texture_at);
    r->raw.texture = path;
    r->raw.texture_at = where;
    r->p = r->line_end;
    return ST_OK;
}

static int kw_is(const char *t, const char *e, const char *w)
{
    size_t n = (size_t)(e - t);
    return strlen(w) == n && strncasecmp(t, w, n) == 0;
}

/* One statement, the keyword [kw, kw_end) already taken. */
static Status read_statement(MtlReader *r, const char *kw, const char *kw_end)
{
    if (kw_is(kw, kw_end, "newmtl")) return read_newmtl(r);
    static const char *const used[] = { "Kd", "Ks", "Ke", "Ns", "Ni", "d", "Tr", "illum", "map_Kd" };
    size_t i, n = sizeof used / sizeof used[0];
    for (i = 0; i < n; i++)
        if (kw_is(kw, kw_end, used[i])) break;
    if (i == n) {
        r->p = r->line_end;     /* an extension or a statement clpt has no use for */
        return ST_OK;
    }
    if (r->cur < 0) return fail_at(r, kw, "'newmtl' before the first material statement");
    MtlRaw *raw = &r->raw;
    Status st;
    float f;
    switch (i) {
    case 0: st = read_color(r, used[i], &raw->kd); raw->has_kd = 1; break;
    case 1: st = read_color(r, used[i], &raw->ks); break;
    case 2: st = read_color(r, used[i], &raw->ke); break;
    case 3: st = read_number(r, used[i], 0.0f, &raw->ns); break;
    case 4: st = read_number(r, used[i], 0.0f, &raw->ni); raw->has_ni = 1; break;
    case 5:
    case 6: {
        /* "d -halo 0.5": the halo variant is read as a plain dissolve */
        skip_blank(r);
        if (i == 5 && r->line_end - r->p >= 5 && strncmp(r->p, "-halo", 5) == 0) r->p += 5;
        st = read_number(r, used[i], 0.0f, &f);
        if (!st && f > 1.0f) st = fail_at(r, kw, "a value in [0, 1]");
        /* d is the opacity, Tr its complement; d wins when both are given */
        if (!st && (i == 5 || !raw->has_d)) {
            raw->d = i == 5 ? f : 1.0f - f;
            raw->has_d = 1;
        }
        break;
    }
    case 7: {
        st = read_number(r, used[i], 0.0f, &f);
        if (!st && (f != floorf(f) || f > 10.0f))
            st = error_set(r->err, ST_INPUT, "%s:%u:%u: expected an illumination model 0..10 after 'illum'",
                           r->path, r->line, (uint)(kw - r->line_start + 1));
        if (!st) raw->illum = (int)f;   /* converting an out-of-range float is undefined */
        break;
    }
    default: return read_map_kd(r);
    }
    if (st) return st;
    return expect_end(r);
}

Status mtl_parse(const char *path, const char *text, size_t len, MtlLibrary *lib, Error *err)
{
    MtlReader r;
    memset(&r, 0, sizeof r);
    r.path = path;
    r.p = text;
    r.end = text + len;
    r.line = 1;
    r.err = err;
    r.lib = lib;
    r.cur = -1;
    raw_reset(&r.raw);
    Status st = ST_OK;
    while (r.p < r.end && !st) {
        r.line_start = r.p;
        const char *nl = memchr(r.p, '\n', (size_t)(r.end - r.p));
        const char *eol = nl ? nl : r.end;
        const char *hash = memchr(r.p, '#', (size_t)(eol - r.p));
        r.line_end = hash ? hash : eol;
        const char *kw, *kw_end = next_token(&r, &kw);
        if (kw != kw_end) st = read_statement(&r, kw, kw_end);
        r.p = nl ? nl + 1 : r.end;
        r.line++;
    }
    if (!st) finish_material(&r);
    raw_reset(&r.raw);
    return st;
}

Status mtl_load(const char *path, MtlLibrary *lib, Error *err)
{
    char *text;
    size_t len;
    Status st = lex_read_file(path, &text, &len, err);
    if (st) return st;
    st = mtl_parse(path, text, len, lib, err);
    free(text);
    return st;
}
