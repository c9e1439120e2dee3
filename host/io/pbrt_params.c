/* pbrt_params.c — pbrt-v4 parameter lists, spectra and positional arguments (pbrt_reader.h). */
#include "io/pbrt_reader.h"

#include "scene/blackbody.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/limit.h"
#include "base/strmap.h"
#include "io/image_write.h"
#include "io/lexer.h"
#include "io/mesh_load.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "util/kmath.h"
#include "scene/mesh_sink.h"
#include "scene/octa_env.h"
#include "scene/subdiv.h"
#include "scene/transform.h"


/* ------------------------------------------------------------------ parameter lists */

/* pbrt-v4's type names, and the older spellings pbrt-v3 files still use */
static const struct { const char *name; PType type; } ptype_names[] = {
    {"float", PT_FLOAT},     {"integer", PT_INTEGER}, {"bool", PT_BOOL},       {"string", PT_STRING},
    {"texture", PT_TEXTURE}, {"point2", PT_POINT2},   {"vector2", PT_VECTOR2}, {"point3", PT_POINT3},
    {"point", PT_POINT3},    {"vector3", PT_VECTOR3}, {"vector", PT_VECTOR3},  {"normal", PT_NORMAL},
    {"normal3", PT_NORMAL},  {"rgb", PT_RGB},         {"color", PT_RGB},       {"spectrum", PT_SPECTRUM},
    {"blackbody", PT_BLACKBODY},
};


int pbrt_grow(void **ptr, size_t *cap, size_t need, size_t elem)
{
    return array_reserve(ptr, cap, need, elem);
}

/* Parses a word as a double (C syntax, finite); -1 when it is not one. */
int pbrt_tok_double(const Token *t, double *out)
{
    if (t->kind != TOK_WORD || t->len == 0 || t->len >= 64) return -1;
    char buf[64];
    memcpy(buf, t->text, t->len);
    buf[t->len] = '\0';
    char *end;
    double d = strtod(buf, &end);
    if (*end != '\0' || !isfinite(d) || fabs(d) > 3.4e38) return -1;
    *out = d;
    return 0;
}

int pbrt_tok_is_bool(const Token *t)
{
    return (t->kind == TOK_WORD || t->kind == TOK_STRING) &&
           ((t->len == 4 && memcmp(t->text, "true", 4) == 0) || (t->len == 5 && memcmp(t->text, "false", 5) == 0));
}

int pbrt_tok_eq(const Token *t, const char *s)
{
    size_t n = strlen(s);
    return t->len == n && memcmp(t->text, s, n) == 0;
}

/* Reads one value token into the list; `what` names the parameter for messages. */
static Status param_value(Parser *p, Lexer *lx, Param *pa, const Token *v)
{
    int want_string = pa->type == PT_STRING || pa->type == PT_TEXTURE || pa->type == PT_BOOL;
    if (pa->n == 0) pa->strings = want_string || (pa->type == PT_SPECTRUM && v->kind == TOK_STRING);
    if (pa->strings) {
        if (pa->type == PT_BOOL ? !pbrt_tok_is_bool(v) : v->kind != TOK_STRING)
            return lex_expected(lx, v, pa->type == PT_BOOL ? "true or false" : "a quoted string", p->err);
        if (pbrt_grow((void **)&p->pl.strs, &p->pl.cap_strs, p->pl.n_strs + 1, sizeof(Token)))
            return error_set(p->err, ST_INTERNAL, "out of memory");
        p->pl.strs[p->pl.n_strs++] = *v;
    } else {
        double d;
        if (pbrt_tok_double(v, &d)) return lex_expected(lx, v, "a finite number", p->err);
        if (pa->type == PT_INTEGER && (d != floor(d) || fabs(d) > 2147483647.0))
            return lex_expected(lx, v, "an integer", p->err);
        if (pbrt_grow((void **)&p->pl.nums, &p->pl.cap_nums, p->pl.n_nums + 1, sizeof(double)))
            return error_set(p->err, ST_INTERNAL, "out of memory");
        p->pl.nums[p->pl.n_nums++] = d;
    }
    pa->n++;
    return ST_OK;
}

/* Checks a parameter's value count against its type. */
static Status param_check(Parser *p, Lexer *lx, const Param *pa)
{
    size_t per = 1;
    const char *what = "value";
    if (pa->type == PT_POINT2 || pa->type == PT_VECTOR2) {
        per = 2;
        what = "pairs of numbers";
    } else if (pa->type == PT_POINT3 || pa->type == PT_VECTOR3 || pa->type == PT_NORMAL) {
        per = 3;
        what = "triples of numbers";
    } else if (pa->type == PT_RGB) {
        per = 3;
        what = "3 numbers";
    } else if (pa->type == PT_SPECTRUM) {
        per = pa->strings ? 1 : 2;
        what = pa->strings ? "one name" : "(wavelength, value) pairs";
    }
    int ok = pa->n > 0 && pa->n % per == 0;
    /* an "rgb" may hold several colours (pbrt-v4's rgbgrid); pbrt_get_spectrum checks
     * that a single colour is one */
    if (pa->type == PT_BLACKBODY || (pa->type == PT_SPECTRUM && pa->strings)) ok = pa->n == per;
    if (!ok)
        return lex_error_at(lx, &pa->decl, p->err, "parameter \"%.*s\" needs %s, has %zu value%s",
                            (int)pa->decl.len, pa->decl.text, pa->type == PT_BLACKBODY ? "1 temperature" : what,
                            pa->n, pa->n == 1 ? "" : "s");
    return ST_OK;
}

/* Reads `"type name" value | [ values ]` pairs up to the next directive. */
Status pbrt_parse_params(Parser *p, Lexer *lx)
{
    p->pl.n = p->pl.n_nums = p->pl.n_strs = 0;
    for (;;) {
        Token t;
        Status st = lex_next(lx, &t, p->err);
        if (st) return st;
        if (t.kind != TOK_STRING) {
            lex_unread(lx, &t);
            return ST_OK;
        }
        /* "type name": two words separated by blanks */
        size_t i = 0;
        while (i < t.len && (t.text[i] == ' ' || t.text[i] == '\t')) i++;
        size_t ts = i;
        while (i < t.len && t.text[i] != ' ' && t.text[i] != '\t') i++;
        size_t te = i;
        while (i < t.len && (t.text[i] == ' ' || t.text[i] == '\t')) i++;
        size_t ns = i;
        while (i < t.len && t.text[i] != ' ' && t.text[i] != '\t') i++;
        size_t ne = i;
        while (i < t.len && (t.text[i] == ' ' || t.text[i] == '\t')) i++;
        if (te == ts || ne == ns || i != t.len)
            return lex_expected(lx, &t, "a parameter declaration \"type name\"", p->err);
        size_t k, nt = sizeof ptype_names / sizeof ptype_names[0];
        for (k = 0; k < nt; k++)
            if (strlen(ptype_names[k].name) == te - ts && memcmp(ptype_names[k].name, t.text + ts, te - ts) == 0) break;
        if (k == nt)
            return lex_error_at(lx, &t, p->err, "unknown parameter type '%.*s' (float, integer, bool, string, "
                                "texture, point2, vector2, point3, vector3, normal, rgb, spectrum, blackbody)",
                                (int)(te - ts > 40 ? 40 : te - ts), t.text + ts);
        if (pbrt_grow((void **)&p->pl.p, &p->pl.cap, p->pl.n + 1, sizeof(Param)))
            return error_set(p->err, ST_INTERNAL, "out of memory");
        Param *pa = &p->pl.p[p->pl.n];
        memset(pa, 0, sizeof *pa);
        pa->type = ptype_names[k].type;
        pa->decl = t;
        pa->name = t.text + ns;
        pa->name_len = ne - ns;
        Token v;
        if ((st = lex_next(lx, &v, p->err))) return st;
        int string_vals = pa->type == PT_STRING || pa->type == PT_TEXTURE || pa->type == PT_BOOL ||
                          (pa->type == PT_SPECTRUM && v.kind == TOK_STRING);
        pa->first = string_vals ? p->pl.n_strs : p->pl.n_nums;
        if (pa->type == PT_SPECTRUM && v.kind == TOK_LBRACKET) {
            Token w;
            if ((st = lex_next(lx, &w, p->err))) return st;
            string_vals = w.kind == TOK_STRING;
            pa->first = string_vals ? p->pl.n_strs : p->pl.n_nums;
            lex_unread(lx, &w);
        }
        if (v.kind == TOK_LBRACKET) {
            for (;;) {
                if ((st = lex_next(lx, &v, p->err))) return st;
                if (v.kind == TOK_RBRACKET) break;
                if (v.kind == TOK_EOF)
                    return lex_error_at(lx, &v, p->err, "expected ']' to close the values of \"%.*s\" "
                                        "opened at line %u, found end of file",
                                        (int)(t.len > 40 ? 40 : t.len), t.text, t.line);
                if ((st = param_value(p, lx, pa, &v))) return st;
            }
        } else if ((st = param_value(p, lx, pa, &v))) {
            return st;
        }
        if ((st = param_check(p, lx, pa))) return st;
        p->pl.n++;
    }
}

Param *pbrt_param_find(Parser *p, const char *name)
{
    size_t n = strlen(name);
    Param *found = NULL;
    for (size_t i = 0; i < p->pl.n; i++) {
        Param *pa = &p->pl.p[i];
        if (pa->name_len == n && memcmp(pa->name, name, n) == 0) {
            pa->used = 1;
            found = pa;   /* the last one given wins, as in pbrt */
        }
    }
    return found;
}

Status pbrt_param_type_error(Parser *p, const Lexer *lx, const Param *pa, const char *what)
{
    return lex_error_at(lx, &pa->decl, p->err, "parameter '%.*s' must be %s", (int)pa->name_len, pa->name, what);
}

Status pbrt_get_float(Parser *p, const Lexer *lx, const char *name, double *out)
{
    Param *pa = pbrt_param_find(p, name);
    if (!pa) return ST_OK;
    if (pa->type != PT_FLOAT && pa->type != PT_INTEGER) return pbrt_param_type_error(p, lx, pa, "a float");
    if (pa->n != 1) return pbrt_param_type_error(p, lx, pa, "one float");
    *out = p->pl.nums[pa->first];
    return ST_OK;
}

/* The parameter `name` into *out when given (else NULL), checked to hold `n` values of
 * one of `types` (bits 1 << PT_x); `what` names them in the error. */
static Status param_of(Parser *p, const Lexer *lx, const char *name, unsigned types, size_t n, const char *what,
                       const Param **out)
{
    const Param *pa = *out = pbrt_param_find(p, name);
    if (pa && (!(types & (1u << pa->type)) || pa->n != n)) return pbrt_param_type_error(p, lx, pa, what);
    return ST_OK;
}

Status pbrt_get_int(Parser *p, const Lexer *lx, const char *name, long *out)
{
    const Param *pa;
    Status st = param_of(p, lx, name, 1u << PT_INTEGER, 1, "one integer", &pa);
    if (st == ST_OK && pa) *out = (long)p->pl.nums[pa->first];
    return st;
}

/* pbrt_get_int of a value that must lie in lo..hi: an error at the parameter where the
 * scene gives one outside (the default, *out on entry, is taken to lie inside). */
Status pbrt_get_int_in(Parser *p, const Lexer *lx, const char *name, long lo, long hi, long *out)
{
    Status st = pbrt_get_int(p, lx, name, out);
    if (st || (*out >= lo && *out <= hi)) return st;
    char range[48];
    snprintf(range, sizeof range, "in %ld..%ld", lo, hi);
    return pbrt_param_type_error(p, lx, pbrt_param_find(p, name), range);
}

Status pbrt_get_bool(Parser *p, const Lexer *lx, const char *name, int *out)
{
    const Param *pa;
    Status st = param_of(p, lx, name, 1u << PT_BOOL, 1, "one bool", &pa);
    if (st == ST_OK && pa) *out = pbrt_tok_eq(&p->pl.strs[pa->first], "true");
    return st;
}

/* The string value of a string parameter, or NULL when not given. */
Status pbrt_get_string(Parser *p, const Lexer *lx, const char *name, const Token **out)
{
    const Param *pa;
    Status st = param_of(p, lx, name, 1u << PT_STRING, 1, "one string", &pa);
    if (st == ST_OK && pa) *out = &p->pl.strs[pa->first];
    return st;
}

Status pbrt_get_point(Parser *p, const Lexer *lx, const char *name, vec3 *out)
{
    const Param *pa;
    Status st = param_of(p, lx, name, (1u << PT_POINT3) | (1u << PT_VECTOR3) | (1u << PT_NORMAL), 3, "one point3",
                         &pa);
    if (st != ST_OK || !pa) return st;
    const double *d = p->pl.nums + pa->first;
    *out = v3((float)d[0], (float)d[1], (float)d[2]);
    return ST_OK;
}

/* ------------------------------------------------------------------ spectra */

/* pbrt-v4's named glasses, their index at 550 nm */
static const struct { const char *name; float ior; } glasses[] = {
    {"glass-BK7", 1.5185f},  {"glass-BAF10", 1.6700f}, {"glass-FK51A", 1.4866f}, {"glass-LASF9", 1.8503f},
    {"glass-F5", 1.6053f},   {"glass-F10", 1.6275f},   {"glass-F11", 1.6237f},   {"glass-SF5", 1.6727f},
    {"glass-SF10", 1.7283f}, {"glass-SF11", 1.7847f},
};

/* A named spectrum as RGB: "metal-XX-eta" / "metal-XX-k" through clpt's metal presets,
 * the glasses as their index; 0 when clpt does not know the name. */
static int named_spectrum(const Token *t, vec3 *out)
{
    if (t->len > 6 && memcmp(t->text, "metal-", 6) == 0) {
        const char *m = t->text + 6;
        size_t ml = t->len - 6;
        int is_k = ml > 2 && memcmp(m + ml - 2, "-k", 2) == 0;
        int is_eta = ml > 4 && memcmp(m + ml - 4, "-eta", 4) == 0;
        if (!is_k && !is_eta) return 0;
        vec3 eta, k;
        if (!material_metal_preset(m, ml - (is_k ? 2 : 4), &eta, &k)) return 0;
        *out = is_k ? k : eta;
        return 1;
    }
    for (size_t i = 0; i < sizeof glasses / sizeof glasses[0]; i++)
        if (pbrt_tok_eq(t, glasses[i].name)) {
            *out = v3(glasses[i].ior, glasses[i].ior, glasses[i].ior);
            return 1;
        }
    return 0;
}

/* A sampled spectrum (wavelength, value pairs, sorted) at `nm`, linearly interpolated. */
static double spectrum_at(const double *d, size_t pairs, double nm)
{
    if (nm <= d[0]) return d[1];
    for (size_t i = 1; i < pairs; i++)
        if (nm <= d[2 * i]) {
            double l0 = d[2 * i - 2], l1 = d[2 * i];
            double t = l1 > l0 ? (nm - l0) / (l1 - l0) : 1.0;
            return d[2 * i - 1] * (1 - t) + d[2 * i + 1] * t;
        }
    return d[2 * pairs - 1];
}

/* A spectrum-valued parameter (rgb, blackbody, spectrum, or a float as a grey) into
 * *out; *tex receives a texture parameter's texture (NULL for none). Unknown named
 * spectra keep *out and give a warning. *given is set when the parameter exists. */
Status pbrt_get_spectrum(Parser *p, const Lexer *lx, const char *name, vec3 *out, const PTexture **tex, int *given)
{
    Param *pa = pbrt_param_find(p, name);
    if (tex) *tex = NULL;
    if (!pa) return ST_OK;
    if (given) *given = 1;
    const double *d = pa->strings ? NULL : p->pl.nums + pa->first;   /* no numbers: no array yet */
    switch (pa->type) {
    case PT_RGB:
        if (pa->n != 3)
            return lex_error_at(lx, &pa->decl, p->err, "parameter \"%.*s\" needs 3 numbers, has %zu values",
                                (int)pa->decl.len, pa->decl.text, pa->n);
        if (d[0] < 0 || d[1] < 0 || d[2] < 0) return pbrt_param_type_error(p, lx, pa, "an rgb colour >= 0");
        *out = v3((float)d[0], (float)d[1], (float)d[2]);
        return ST_OK;
    case PT_FLOAT:
        if (pa->n != 1) return pbrt_param_type_error(p, lx, pa, "one value");
        *out = v3((float)d[0], (float)d[0], (float)d[0]);
        return ST_OK;
    case PT_BLACKBODY:
        if (!(d[0] > 0)) return pbrt_param_type_error(p, lx, pa, "a blackbody temperature > 0 (kelvin)");
        *out = blackbody_rgb_unit_luminance(d[0]);
        return ST_OK;
    case PT_SPECTRUM:
        if (pa->strings) {
            const Token *t = &p->pl.strs[pa->first];
            if (named_spectrum(t, out)) return ST_OK;
            char key[96];
            snprintf(key, sizeof key, "spectrum %.*s", (int)(t->len > 60 ? 60 : t->len), t->text);
            return warn_once(p, lx, &pa->decl, key, "named spectrum \"%.*s\" is not known to clpt; "
                             "its default is used", (int)(t->len > 60 ? 60 : t->len), t->text);
        }
        for (size_t i = 1; i < pa->n / 2; i++)
            if (!(d[2 * i] > d[2 * i - 2]))
                return pbrt_param_type_error(p, lx, pa, "(wavelength, value) pairs with increasing wavelengths");
        /* the wavelengths clpt's metal presets take for R, G and B */
        *out = v3((float)spectrum_at(d, pa->n / 2, 650), (float)spectrum_at(d, pa->n / 2, 550),
                  (float)spectrum_at(d, pa->n / 2, 450));
        return ST_OK;
    case PT_TEXTURE: {
        const Token *t = &p->pl.strs[pa->first];
        uint32_t i;
        if (!strmap_find(&p->tex_by_name, t->text, t->len, &i))
            return lex_error_at(lx, t, p->err, "texture '%.*s' is not defined", (int)(t->len > 40 ? 40 : t->len),
                                t->text);
        if (p->tex[i].constant) *out = p->tex[i].color;
        else if (tex) *tex = &p->tex[i];
        else return warn_once(p, lx, &pa->decl, "texture-param", "image textures are only used for colours "
                              "(reflectance); '%.*s' takes its default", (int)pa->name_len, pa->name);
        return ST_OK;
    }
    case PT_INTEGER: case PT_BOOL: case PT_STRING: case PT_POINT2: case PT_VECTOR2: case PT_POINT3:
    case PT_VECTOR3: case PT_NORMAL: case PT_N:
        break;
    }
    return pbrt_param_type_error(p, lx, pa, "rgb, spectrum, blackbody or a texture");
}

/* A float-valued parameter that may be a constant float texture. */
Status pbrt_get_float_tex(Parser *p, const Lexer *lx, const char *name, double *out)
{
    Param *pa = pbrt_param_find(p, name);
    if (!pa) return ST_OK;
    if (pa->type == PT_TEXTURE) {
        vec3 c = v3(0, 0, 0);
        pa->used = 0;
        Status st = pbrt_get_spectrum(p, lx, name, &c, NULL, NULL);
        *out = c.x;
        return st;
    }
    if (pa->type == PT_SPECTRUM || pa->type == PT_RGB) {
        /* pbrt-v4 takes a dielectric's eta as a spectrum too: clpt takes its green */
        vec3 c = v3((float)*out, (float)*out, (float)*out);
        Status st = pbrt_get_spectrum(p, lx, name, &c, NULL, NULL);
        *out = c.y;
        return st;
    }
    return pbrt_get_float(p, lx, name, out);
}

/* Warns once about every parameter the directive did not read. */
Status pbrt_warn_unused(Parser *p, const Lexer *lx, const char *what)
{
    for (size_t i = 0; i < p->pl.n; i++) {
        Param *pa = &p->pl.p[i];
        if (pa->used) continue;
        char key[160];
        snprintf(key, sizeof key, "%s:%.*s", what, (int)(pa->name_len > 60 ? 60 : pa->name_len), pa->name);
        Status st = warn_once(p, lx, &pa->decl, key, "%s: parameter \"%.*s\" is not supported; ignored", what,
                              (int)(pa->decl.len > 60 ? 60 : pa->decl.len), pa->decl.text);
        if (st) return st;
    }
    return ST_OK;
}

/* ------------------------------------------------------------------ positional args */

Status pbrt_expect_string(Parser *p, Lexer *lx, const char *what, Token *t)
{
    Status st = lex_next(lx, t, p->err);
    if (st) return st;
    if (t->kind != TOK_STRING) return lex_expected(lx, t, what, p->err);
    return ST_OK;
}

/* The head of most directives: one quoted string (a type or a name), then the parameter
 * list, read into p->pl. */
Status pbrt_expect_head(Parser *p, Lexer *lx, const char *what, Token *t)
{
    Status st = pbrt_expect_string(p, lx, what, t);
    return st ? st : pbrt_parse_params(p, lx);
}

/* A quoted name that `map` must hold (a named material, an object): its token and index,
 * or an error at the name saying which directive defines such names. */
Status pbrt_expect_defined(Parser *p, Lexer *lx, const StrMap *map, const char *what, const char *definer,
                           Token *name, uint32_t *index)
{
    char expected[48];
    snprintf(expected, sizeof expected, "a quoted %s name", what);
    Status st = pbrt_expect_string(p, lx, expected, name);
    if (st) return st;
    if (!strmap_find(map, name->text, name->len, index))
        return lex_error_at(lx, name, p->err, "%s '%.*s' is not defined (%s defines it)", what,
                            (int)(name->len > 40 ? 40 : name->len), name->text, definer);
    return ST_OK;
}

Status pbrt_expect_numbers(Parser *p, Lexer *lx, double *out, int n, const char *what)
{
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    /* pbrt accepts Transform [ ... ] with or without brackets */
    int bracket = t.kind == TOK_LBRACKET;
    if (bracket && (st = lex_next(lx, &t, p->err))) return st;
    for (int i = 0; i < n; i++) {
        if (i > 0 && (st = lex_next(lx, &t, p->err))) return st;
        if (pbrt_tok_double(&t, &out[i])) return lex_expected(lx, &t, what, p->err);
    }
    if (bracket) {
        if ((st = lex_next(lx, &t, p->err))) return st;
        if (t.kind != TOK_RBRACKET) return lex_expected(lx, &t, "']'", p->err);
    }
    return ST_OK;
}


/* A file the scene names, found as pbrt finds it: a relative path from the main
 * file's folder, includes or not (io/path.h). NULL when out of memory. */
char *pbrt_beside_main(const Parser *p, const Token *f)
{
    char *path;
    path_resolve(p->top_path, f->text, f->len, PATH_BESIDE, &path);
    return path;
}
