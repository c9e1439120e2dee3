/* pbrt_parse.c — the pbrt-v4 scene reader (pbrt_parse.h, docs/pbrt.md). */
#include "io/pbrt_parse.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/limit.h"
#include "base/strmap.h"
#include "io/image_write.h"
#include "io/lexer.h"
#include "io/mesh_load.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "kmath.h"
#include "scene/mesh_sink.h"
#include "scene/octa_env.h"
#include "scene/subdiv.h"
#include "scene/transform.h"

/* ------------------------------------------------------------------ parameter lists */

typedef enum {
    PT_FLOAT, PT_INTEGER, PT_BOOL, PT_STRING, PT_TEXTURE, PT_POINT2, PT_VECTOR2, PT_POINT3,
    PT_VECTOR3, PT_NORMAL, PT_RGB, PT_SPECTRUM, PT_BLACKBODY, PT_N
} PType;

/* pbrt-v4's type names, and the older spellings pbrt-v3 files still use */
static const struct { const char *name; PType type; } ptype_names[] = {
    {"float", PT_FLOAT},     {"integer", PT_INTEGER}, {"bool", PT_BOOL},       {"string", PT_STRING},
    {"texture", PT_TEXTURE}, {"point2", PT_POINT2},   {"vector2", PT_VECTOR2}, {"point3", PT_POINT3},
    {"point", PT_POINT3},    {"vector3", PT_VECTOR3}, {"vector", PT_VECTOR3},  {"normal", PT_NORMAL},
    {"normal3", PT_NORMAL},  {"rgb", PT_RGB},         {"color", PT_RGB},       {"spectrum", PT_SPECTRUM},
    {"blackbody", PT_BLACKBODY},
};

typedef struct {
    PType type;
    Token decl;              /* the "type name" string, for positions */
    const char *name;        /* inside decl's text */
    size_t name_len;
    size_t first, n;         /* values: nums[first..] or strs[first..] */
    int strings;             /* the values are strings (string, texture, bool, named spectrum) */
    int used;
} Param;

typedef struct {
    Param *p;     size_t n, cap;
    double *nums; size_t n_nums, cap_nums;
    Token *strs;  size_t n_strs, cap_strs;
} ParamList;

/* ------------------------------------------------------------------ parser state */

typedef struct {
    Transform ctm;
    int reverse;
    uint material;           /* NO_INDEX: pbrt's default (diffuse 0.5), made on first use */
    int area;                /* an AreaLightSource is active */
    vec3 area_L;
    int area_twosided;
    uint area_material;      /* material + emission, made on first use */
    int end_time_only;       /* ActiveTransform EndTime: transforms move the shutter-close pose only */
} GState;

typedef struct {
    const char *name;        /* a constant's value is `color`; else a scene texture */
    int constant;
    vec3 color;
    uint index;
    vec3 mean;               /* the texture's mean colour (a constant's is its colour):
                              * what stands in where only a constant fits */
} PTexture;

/* A material named by NamedMaterial and not yet defined: where it was first used. */
typedef struct {
    uint index;
    int defined;
    char where[160];   /* "path:line:col: material 'name'" for the error at the end */
} PPending;

/* An ObjectBegin/End's shapes, taken out of the scene and copied in at each instance. */
typedef struct {
    Sphere *spheres;      size_t n_spheres;
    SphereXform *sphere_xforms;  size_t n_sphere_xforms;   /* Sphere.xform indexes this */
    Triangle *triangles;  size_t n_triangles;
    TriShading *shading;  size_t n_shading;   /* Triangle.shading indexes this */
} PObject;

typedef struct {
    Scene *s;
    Error *err;
    const char *top_path;    /* includes are found beside the main file, as pbrt does */
    int depth;
    int depth_exceeded;
    int world;               /* after WorldBegin */
    GState g;
    GState *stack;  size_t n_stack, cap_stack;
    StrMap named_material;   /* name -> material index */
    /* NamedMaterial before its MakeNamedMaterial (pbrt-v4 resolves names after the whole
     * file): a diffuse placeholder, replaced in place when the definition comes */
    PPending *pending;  size_t n_pending, cap_pending;
    /* area-light copies of a placeholder (material + emission), patched with it */
    struct { uint area, base; } *area_of_pending;  size_t n_area_pending, cap_area_pending;
    StrMap coordsys;         /* name -> index into coordsys_xf */
    Transform *coordsys_xf;  size_t n_coordsys, cap_coordsys;
    StrMap tex_by_name;      /* name -> index into tex */
    PTexture *tex;  size_t n_tex, cap_tex;
    StrMap warned;           /* warning keys already given */
    StrMap object_by_name;   /* name -> index into objects */
    PObject *objects;  size_t n_objects, cap_objects;
    int in_object;           /* inside ObjectBegin: what it started with */
    size_t obj_spheres, obj_triangles, obj_shading, obj_stack, obj_sphere_xforms;
    /* triangles made so far by tessellating what the file describes in a few numbers
     * (loopsubdiv, emitting ellipsoids): at most CLPT_MAX_TESSELLATED_TRIANGLES */
    size_t tessellated;
    Token obj_name;          /* its name, copied into obj_name_buf */
    char *obj_name_buf;
    ParamList pl;
    /* the camera, finished once the film's size is known */
    int have_camera, cam_ortho;
    Transform cam_from_world;
    double fov, lens_radius, focal_distance, screen_half;
} Parser;

/* Gives a warning once per key ("Shape disk", "diffuse:foo"), at file:line. */
#define warn_once(p, lx, at, key, ...) reader_warn_once((p)->s, &(p)->warned, lx, at, key, (p)->err, __VA_ARGS__)

static int grow(void **ptr, size_t *cap, size_t need, size_t elem)
{
    return array_reserve(ptr, cap, need, elem);
}

/* Parses a word as a double (C syntax, finite); -1 when it is not one. */
static int tok_double(const Token *t, double *out)
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

static int tok_is_bool(const Token *t)
{
    return (t->kind == TOK_WORD || t->kind == TOK_STRING) &&
           ((t->len == 4 && memcmp(t->text, "true", 4) == 0) || (t->len == 5 && memcmp(t->text, "false", 5) == 0));
}

static int tok_eq(const Token *t, const char *s)
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
        if (pa->type == PT_BOOL ? !tok_is_bool(v) : v->kind != TOK_STRING)
            return lex_expected(lx, v, pa->type == PT_BOOL ? "true or false" : "a quoted string", p->err);
        if (grow((void **)&p->pl.strs, &p->pl.cap_strs, p->pl.n_strs + 1, sizeof(Token)))
            return error_set(p->err, ST_INTERNAL, "out of memory");
        p->pl.strs[p->pl.n_strs++] = *v;
    } else {
        double d;
        if (tok_double(v, &d)) return lex_expected(lx, v, "a finite number", p->err);
        if (pa->type == PT_INTEGER && (d != floor(d) || fabs(d) > 2147483647.0))
            return lex_expected(lx, v, "an integer", p->err);
        if (grow((void **)&p->pl.nums, &p->pl.cap_nums, p->pl.n_nums + 1, sizeof(double)))
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
    if (pa->type == PT_RGB || pa->type == PT_BLACKBODY || (pa->type == PT_SPECTRUM && pa->strings))
        ok = pa->n == per;
    if (!ok)
        return lex_error_at(lx, &pa->decl, p->err, "parameter \"%.*s\" needs %s, has %zu value%s",
                            (int)pa->decl.len, pa->decl.text, pa->type == PT_BLACKBODY ? "1 temperature" : what,
                            pa->n, pa->n == 1 ? "" : "s");
    return ST_OK;
}

/* Reads `"type name" value | [ values ]` pairs up to the next directive. */
static Status parse_params(Parser *p, Lexer *lx)
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
        if (grow((void **)&p->pl.p, &p->pl.cap, p->pl.n + 1, sizeof(Param)))
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

static Param *param_find(Parser *p, const char *name)
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

static Status param_type_error(Parser *p, const Lexer *lx, const Param *pa, const char *what)
{
    return lex_error_at(lx, &pa->decl, p->err, "parameter '%.*s' must be %s", (int)pa->name_len, pa->name, what);
}

static Status get_float(Parser *p, const Lexer *lx, const char *name, double *out)
{
    Param *pa = param_find(p, name);
    if (!pa) return ST_OK;
    if (pa->type != PT_FLOAT && pa->type != PT_INTEGER) return param_type_error(p, lx, pa, "a float");
    if (pa->n != 1) return param_type_error(p, lx, pa, "one float");
    *out = p->pl.nums[pa->first];
    return ST_OK;
}

static Status get_int(Parser *p, const Lexer *lx, const char *name, long *out)
{
    Param *pa = param_find(p, name);
    if (!pa) return ST_OK;
    if (pa->type != PT_INTEGER || pa->n != 1) return param_type_error(p, lx, pa, "one integer");
    *out = (long)p->pl.nums[pa->first];
    return ST_OK;
}

static Status get_bool(Parser *p, const Lexer *lx, const char *name, int *out)
{
    Param *pa = param_find(p, name);
    if (!pa) return ST_OK;
    if (pa->type != PT_BOOL || pa->n != 1) return param_type_error(p, lx, pa, "one bool");
    *out = tok_eq(&p->pl.strs[pa->first], "true");
    return ST_OK;
}

/* The string value of a string parameter, or NULL when not given. */
static Status get_string(Parser *p, const Lexer *lx, const char *name, const Token **out)
{
    Param *pa = param_find(p, name);
    if (!pa) return ST_OK;
    if (pa->type != PT_STRING || pa->n != 1) return param_type_error(p, lx, pa, "one string");
    *out = &p->pl.strs[pa->first];
    return ST_OK;
}

static Status get_point(Parser *p, const Lexer *lx, const char *name, vec3 *out)
{
    Param *pa = param_find(p, name);
    if (!pa) return ST_OK;
    if ((pa->type != PT_POINT3 && pa->type != PT_VECTOR3 && pa->type != PT_NORMAL) || pa->n != 3)
        return param_type_error(p, lx, pa, "one point3");
    const double *d = p->pl.nums + pa->first;
    *out = v3((float)d[0], (float)d[1], (float)d[2]);
    return ST_OK;
}

/* ------------------------------------------------------------------ spectra */

/* CIE 1931 colour matching functions, the multi-lobe Gaussian fit of Wyman, Sloan and
 * Shirley (JCGT 2013); enough for a blackbody's colour to a few parts in a thousand. */
static double g_lobe(double x, double mu, double s1, double s2)
{
    double t = (x - mu) / (x < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

static void cie_xyz(double nm, double *x, double *y, double *z)
{
    *x = 1.056 * g_lobe(nm, 599.8, 37.9, 31.0) + 0.362 * g_lobe(nm, 442.0, 16.0, 26.7) -
         0.065 * g_lobe(nm, 501.1, 20.4, 26.2);
    *y = 0.821 * g_lobe(nm, 568.8, 46.9, 40.5) + 0.286 * g_lobe(nm, 530.9, 16.3, 31.1);
    *z = 1.217 * g_lobe(nm, 437.0, 11.8, 36.0) + 0.681 * g_lobe(nm, 459.0, 26.0, 13.8);
}

/* Linear sRGB of a blackbody at `kelvin`, scaled to luminance 1: pbrt-v4 divides a
 * light's spectrum by its luminance (SpectrumToPhotometric), so only the colour counts. */
static vec3 blackbody_rgb(double kelvin)
{
    const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
    double X = 0, Y = 0, Z = 0;
    for (double nm = 360.0; nm <= 830.0; nm += 1.0) {
        double l = nm * 1e-9;
        double le = (2 * h * c * c) / (pow(l, 5) * (exp((h * c) / (l * kb * kelvin)) - 1));
        double x, y, z;
        cie_xyz(nm, &x, &y, &z);
        X += le * x;
        Y += le * y;
        Z += le * z;
    }
    if (!(Y > 0) || !isfinite(Y)) return v3(1, 1, 1);
    X /= Y;
    Z /= Y;
    Y = 1;
    double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
    double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
    double b = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
    return v3((float)fmax(r, 0), (float)fmax(g, 0), (float)fmax(b, 0));
}

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
        if (tok_eq(t, glasses[i].name)) {
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
static Status get_spectrum(Parser *p, const Lexer *lx, const char *name, vec3 *out, const PTexture **tex, int *given)
{
    Param *pa = param_find(p, name);
    if (tex) *tex = NULL;
    if (!pa) return ST_OK;
    if (given) *given = 1;
    const double *d = pa->strings ? NULL : p->pl.nums + pa->first;   /* no numbers: no array yet */
    switch (pa->type) {
    case PT_RGB:
        if (d[0] < 0 || d[1] < 0 || d[2] < 0) return param_type_error(p, lx, pa, "an rgb colour >= 0");
        *out = v3((float)d[0], (float)d[1], (float)d[2]);
        return ST_OK;
    case PT_FLOAT:
        if (pa->n != 1) return param_type_error(p, lx, pa, "one value");
        *out = v3((float)d[0], (float)d[0], (float)d[0]);
        return ST_OK;
    case PT_BLACKBODY:
        if (!(d[0] > 0)) return param_type_error(p, lx, pa, "a blackbody temperature > 0 (kelvin)");
        *out = blackbody_rgb(d[0]);
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
                return param_type_error(p, lx, pa, "(wavelength, value) pairs with increasing wavelengths");
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
    return param_type_error(p, lx, pa, "rgb, spectrum, blackbody or a texture");
}

/* A float-valued parameter that may be a constant float texture. */
static Status get_float_tex(Parser *p, const Lexer *lx, const char *name, double *out)
{
    Param *pa = param_find(p, name);
    if (!pa) return ST_OK;
    if (pa->type == PT_TEXTURE) {
        vec3 c = v3(0, 0, 0);
        pa->used = 0;
        Status st = get_spectrum(p, lx, name, &c, NULL, NULL);
        *out = c.x;
        return st;
    }
    if (pa->type == PT_SPECTRUM || pa->type == PT_RGB) {
        /* pbrt-v4 takes a dielectric's eta as a spectrum too: clpt takes its green */
        vec3 c = v3((float)*out, (float)*out, (float)*out);
        Status st = get_spectrum(p, lx, name, &c, NULL, NULL);
        *out = c.y;
        return st;
    }
    return get_float(p, lx, name, out);
}

/* Warns once about every parameter the directive did not read. */
static Status warn_unused(Parser *p, const Lexer *lx, const char *what)
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

static Status expect_string(Parser *p, Lexer *lx, const char *what, Token *t)
{
    Status st = lex_next(lx, t, p->err);
    if (st) return st;
    if (t->kind != TOK_STRING) return lex_expected(lx, t, what, p->err);
    return ST_OK;
}

/* A quoted name that `map` must hold (a named material, an object): its token and index,
 * or an error at the name saying which directive defines such names. */
static Status expect_defined(Parser *p, Lexer *lx, const StrMap *map, const char *what, const char *definer,
                             Token *name, uint32_t *index)
{
    char expected[48];
    snprintf(expected, sizeof expected, "a quoted %s name", what);
    Status st = expect_string(p, lx, expected, name);
    if (st) return st;
    if (!strmap_find(map, name->text, name->len, index))
        return lex_error_at(lx, name, p->err, "%s '%.*s' is not defined (%s defines it)", what,
                            (int)(name->len > 40 ? 40 : name->len), name->text, definer);
    return ST_OK;
}

static Status expect_numbers(Parser *p, Lexer *lx, double *out, int n, const char *what)
{
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    /* pbrt accepts Transform [ ... ] with or without brackets */
    int bracket = t.kind == TOK_LBRACKET;
    if (bracket && (st = lex_next(lx, &t, p->err))) return st;
    for (int i = 0; i < n; i++) {
        if (i > 0 && (st = lex_next(lx, &t, p->err))) return st;
        if (tok_double(&t, &out[i])) return lex_expected(lx, &t, what, p->err);
    }
    if (bracket) {
        if ((st = lex_next(lx, &t, p->err))) return st;
        if (t.kind != TOK_RBRACKET) return lex_expected(lx, &t, "']'", p->err);
    }
    return ST_OK;
}

/* ------------------------------------------------------------------ transforms */

/* The transform directives that take numbers: how many, what they are (for messages),
 * and the transform they make of them. Transform replaces the CTM; the others are
 * applied to it (CTM = CTM * t), as pbrt does. */
typedef Status (*XformBuild)(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t);

static Status build_translate(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    (void)p; (void)lx; (void)kw;
    *t = transform_translate(v[0], v[1], v[2]);
    return ST_OK;
}

static Status build_scale(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    (void)p; (void)lx; (void)kw;
    *t = transform_scale(v[0], v[1], v[2]);
    return ST_OK;
}

static Status build_rotate(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    if (v[1] == 0 && v[2] == 0 && v[3] == 0) return lex_error_at(lx, kw, p->err, "Rotate about a zero axis");
    *t = transform_rotate(v[1], v[2], v[3], v[0]);
    return ST_OK;
}

/* pbrt's 16 numbers are the matrix column by column; the last row must be 0 0 0 1 */
static Status build_matrix(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    if (v[3] != 0 || v[7] != 0 || v[11] != 0 || v[15] != 1)
        return lex_error_at(lx, kw, p->err, "a projective transform (its last row is not 0 0 0 1) is not supported");
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) t->m[r][c] = v[c * 4 + r];
    return ST_OK;
}

static Status build_lookat(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    double dir[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]};
    double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    double ul = sqrt(v[6] * v[6] + v[7] * v[7] + v[8] * v[8]);
    if (!(dl > 0) || !(ul > 0)) return lex_error_at(lx, kw, p->err, "LookAt: the eye and the point looked at are the same, or up is zero");
    for (int i = 0; i < 3; i++) dir[i] /= dl;
    double up[3] = {v[6] / ul, v[7] / ul, v[8] / ul};
    /* right = up x dir, as pbrt: its camera space is left-handed */
    double r[3] = {up[1] * dir[2] - up[2] * dir[1], up[2] * dir[0] - up[0] * dir[2], up[0] * dir[1] - up[1] * dir[0]};
    double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (!(rl > 1e-9)) return lex_error_at(lx, kw, p->err, "LookAt: up is parallel to the view direction");
    for (int i = 0; i < 3; i++) r[i] /= rl;
    double nu[3] = {dir[1] * r[2] - dir[2] * r[1], dir[2] * r[0] - dir[0] * r[2], dir[0] * r[1] - dir[1] * r[0]};
    Transform w;
    for (int i = 0; i < 3; i++) {
        w.m[i][0] = r[i];
        w.m[i][1] = nu[i];
        w.m[i][2] = dir[i];
        w.m[i][3] = v[i];
    }
    int ok;
    *t = transform_inverse(&w, &ok);
    return ST_OK;
}

static const struct {
    const char *name;
    int numbers;
    const char *what;         /* for "expected <what>" */
    XformBuild build;
    int replace;              /* the CTM becomes the transform */
} xform_directives[] = {
    {"Translate", 3, "a number (Translate x y z)", build_translate, 0},
    {"Scale", 3, "a number (Scale x y z)", build_scale, 0},
    {"Rotate", 4, "a number (Rotate degrees x y z)", build_rotate, 0},
    {"LookAt", 9, "a number (LookAt eye, look, up)", build_lookat, 0},
    {"Transform", 16, "a number (16 matrix entries)", build_matrix, 1},
    {"ConcatTransform", 16, "a number (16 matrix entries)", build_matrix, 0},
};

/* Translate, Scale, Rotate, LookAt, Transform, ConcatTransform: by the table above. */
static Status d_xform(Parser *p, Lexer *lx, const Token *kw)
{
    size_t i = 0, n = sizeof xform_directives / sizeof xform_directives[0];
    while (i < n && !tok_eq(kw, xform_directives[i].name)) i++;
    if (i == n) return error_set(p->err, ST_INTERNAL, "no transform directive '%.*s'", (int)kw->len, kw->text);
    double v[16];
    Transform t;
    Status st = expect_numbers(p, lx, v, xform_directives[i].numbers, xform_directives[i].what);
    if (!st) st = xform_directives[i].build(p, lx, kw, v, &t);
    if (st) return st;
    if (xform_directives[i].replace)
        p->g.ctm = t;
    else
        p->g.ctm = transform_compose(&p->g.ctm, &t);
    return ST_OK;
}

static Status d_coordsys(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token t;
    Status st = expect_string(p, lx, "a quoted coordinate system name", &t);
    if (st) return st;
    uint32_t i;
    if (strmap_find(&p->coordsys, t.text, t.len, &i)) {
        p->coordsys_xf[i] = p->g.ctm;
        return ST_OK;
    }
    if (grow((void **)&p->coordsys_xf, &p->cap_coordsys, p->n_coordsys + 1, sizeof(Transform)) ||
        strmap_add(&p->coordsys, t.text, t.len, (uint32_t)p->n_coordsys))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    p->coordsys_xf[p->n_coordsys++] = p->g.ctm;
    return ST_OK;
}

static Status d_coordsys_transform(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token t;
    Status st = expect_string(p, lx, "a quoted coordinate system name", &t);
    if (st) return st;
    uint32_t i;
    if (!strmap_find(&p->coordsys, t.text, t.len, &i))
        return lex_error_at(lx, &t, p->err, "coordinate system '%.*s' is not defined", (int)(t.len > 40 ? 40 : t.len),
                            t.text);
    p->g.ctm = p->coordsys_xf[i];
    return ST_OK;
}

static Status d_identity(Parser *p, Lexer *lx, const Token *kw)
{
    (void)lx; (void)kw;
    p->g.ctm = transform_identity();
    return ST_OK;
}

static Status d_reverse(Parser *p, Lexer *lx, const Token *kw)
{
    (void)lx; (void)kw;
    p->g.reverse = !p->g.reverse;
    return ST_OK;
}

/* ------------------------------------------------------------------ attributes */

static Status push_state(Parser *p)
{
    if (grow((void **)&p->stack, &p->cap_stack, p->n_stack + 1, sizeof(GState)))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    p->stack[p->n_stack++] = p->g;
    return ST_OK;
}

static Status d_attr_begin(Parser *p, Lexer *lx, const Token *kw)
{
    (void)lx; (void)kw;
    return push_state(p);
}

static Status d_attr_end(Parser *p, Lexer *lx, const Token *kw)
{
    if (p->n_stack == 0) return lex_error_at(lx, kw, p->err, "%.*s without a matching begin", (int)kw->len, kw->text);
    p->g = p->stack[--p->n_stack];
    return ST_OK;
}

/* TransformBegin/End (pbrt-v3, deprecated in v4) keep only the transform */
static Status d_transform_end(Parser *p, Lexer *lx, const Token *kw)
{
    if (p->n_stack == 0) return lex_error_at(lx, kw, p->err, "TransformEnd without a matching TransformBegin");
    p->g.ctm = p->stack[--p->n_stack].ctm;
    return ST_OK;
}

static Status d_world_begin(Parser *p, Lexer *lx, const Token *kw)
{
    if (p->world) return lex_error_at(lx, kw, p->err, "WorldBegin given twice");
    p->world = 1;
    p->g.ctm = transform_identity();
    p->g.end_time_only = 0; /* pbrt-v4's WorldBegin makes all transforms active again */
    Token t = {TOK_STRING, "world", 5, kw->line, kw->col};
    uint32_t i;
    if (!strmap_find(&p->coordsys, t.text, t.len, &i)) {
        if (grow((void **)&p->coordsys_xf, &p->cap_coordsys, p->n_coordsys + 1, sizeof(Transform)) ||
            strmap_add(&p->coordsys, t.text, t.len, (uint32_t)p->n_coordsys))
            return error_set(p->err, ST_INTERNAL, "out of memory");
        p->coordsys_xf[p->n_coordsys++] = p->g.ctm;
    }
    return ST_OK;
}

/* ------------------------------------------------------------------ options */

static Status d_camera(Parser *p, Lexer *lx, const Token *kw)
{
    Token type;
    Status st = expect_string(p, lx, "a quoted camera type", &type);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    if (p->world) return lex_error_at(lx, kw, p->err, "Camera must come before WorldBegin");
    if (!tok_eq(&type, "perspective") && !tok_eq(&type, "orthographic")) {
        st = warn_once(p, lx, &type, "Camera", "Camera \"%.*s\" is not supported; a perspective camera is used",
                       (int)(type.len > 40 ? 40 : type.len), type.text);
        if (st) return st;
    }
    p->have_camera = 1;
    p->cam_ortho = tok_eq(&type, "orthographic");
    p->cam_from_world = p->g.ctm;
    p->fov = 90;
    p->lens_radius = 0;
    p->focal_distance = 1e6;
    if ((st = get_float(p, lx, "fov", &p->fov)) || (st = get_float(p, lx, "lensradius", &p->lens_radius)) ||
        (st = get_float(p, lx, "focaldistance", &p->focal_distance)))
        return st;
    if (!(p->fov > 0 && p->fov < 180)) return param_type_error(p, lx, param_find(p, "fov"), "in (0, 180) degrees");
    if (!(p->lens_radius >= 0)) return param_type_error(p, lx, param_find(p, "lensradius"), ">= 0");
    if (!(p->focal_distance > 0)) return param_type_error(p, lx, param_find(p, "focaldistance"), "> 0");
    /* the camera's coordinate system, as pbrt names it */
    Token cn = {TOK_STRING, "camera", 6, kw->line, kw->col};
    int ok;
    Transform wfc = transform_inverse(&p->g.ctm, &ok);
    if (!ok) return lex_error_at(lx, kw, p->err, "the camera transform is singular");
    uint32_t i;
    if (!strmap_find(&p->coordsys, cn.text, cn.len, &i)) {
        if (grow((void **)&p->coordsys_xf, &p->cap_coordsys, p->n_coordsys + 1, sizeof(Transform)) ||
            strmap_add(&p->coordsys, cn.text, cn.len, (uint32_t)p->n_coordsys))
            return error_set(p->err, ST_INTERNAL, "out of memory");
        i = (uint32_t)p->n_coordsys++;
    }
    p->coordsys_xf[i] = wfc;
    return warn_unused(p, lx, "Camera");
}

static Status d_film(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token type;
    Status st = expect_string(p, lx, "a quoted film type", &type);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    long w = 1280, h = 720;   /* pbrt-v4's defaults */
    if ((st = get_int(p, lx, "xresolution", &w)) || (st = get_int(p, lx, "yresolution", &h))) return st;
    if (w < 1 || w > CLPT_MAX_IMAGE_SIDE) return param_type_error(p, lx, param_find(p, "xresolution"), "in 1..16384");
    if (h < 1 || h > CLPT_MAX_IMAGE_SIDE) return param_type_error(p, lx, param_find(p, "yresolution"), "in 1..16384");
    p->s->image.width = (uint)w;
    p->s->image.height = (uint)h;
    /* the image pbrt would write: clpt's output when -o does not name one (main.c) */
    const Token *f = NULL;
    if ((st = get_string(p, lx, "filename", &f))) return st;
    if (f) {
        char *name = tok_copy(f);
        if (!name) return error_set(p->err, ST_INTERNAL, "out of memory");
        ImageFormat format;
        if (!name[0] || image_format_from_path(name, &format, p->err)) {
            free(name);
            return lex_error_at(lx, f, p->err, "Film \"filename\" '%.*s' is not an image clpt writes (.png, .ppm, "
                                ".bmp, .pfm, .exr, .hdr)", (int)(f->len > 60 ? 60 : f->len), f->text);
        }
        free(p->s->output_hint);
        p->s->output_hint = name;
    }
    return warn_unused(p, lx, "Film");
}

static Status d_sampler(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token type;
    Status st = expect_string(p, lx, "a quoted sampler type", &type);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    long n = 16;
    if ((st = get_int(p, lx, "pixelsamples", &n))) return st;
    if (n < 1 || n > CLPT_MAX_SPP) return param_type_error(p, lx, param_find(p, "pixelsamples"), "in 1..1000000");
    p->s->image.spp = (uint)n;
    param_find(p, "seed");   /* clpt's seed is its own; pbrt's only picks other noise */
    return warn_unused(p, lx, "Sampler");
}

static Status d_integrator(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token type;
    Status st = expect_string(p, lx, "a quoted integrator type", &type);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    if (!tok_eq(&type, "path") && !tok_eq(&type, "volpath")) {
        st = warn_once(p, lx, &type, "Integrator", "Integrator \"%.*s\" is not supported; clpt's path tracer is used",
                       (int)(type.len > 40 ? 40 : type.len), type.text);
        if (st) return st;
    }
    long d = 5;
    if ((st = get_int(p, lx, "maxdepth", &d))) return st;
    if (d < 0 || d > CLPT_MAX_DEPTH) return param_type_error(p, lx, param_find(p, "maxdepth"), "in 0..1024");
    p->s->image.max_depth = (uint)d;
    param_find(p, "regularize");
    return warn_unused(p, lx, "Integrator");
}

/* ------------------------------------------------------------------ materials */

/* pbrt's roughness to clpt's perceptual roughness (GGX alpha = roughness^2); pbrt
 * remaps its roughness to alpha = sqrt(r) unless remaproughness is false. */
static float clpt_roughness(double r, int remap)
{
    double alpha = remap ? sqrt(fmax(r, 0)) : fmax(r, 0);
    return (float)fmin(sqrt(alpha), 1.0);
}

/* prefix + roughness, or + uroughness/vroughness, as clpt's roughness and anisotropy */
static Status get_roughness_named(Parser *p, const Lexer *lx, const char *prefix, double dflt, float *rough,
                                  float *aniso)
{
    double r = dflt, u = -1, v = -1;
    int remap = 1;
    char nr[48], nu[48], nv[48];
    snprintf(nr, sizeof nr, "%sroughness", prefix);
    snprintf(nu, sizeof nu, "%suroughness", prefix);
    snprintf(nv, sizeof nv, "%svroughness", prefix);
    Status st;
    if ((st = get_float_tex(p, lx, nr, &r)) || (st = get_float_tex(p, lx, nu, &u)) ||
        (st = get_float_tex(p, lx, nv, &v)) || (st = get_bool(p, lx, "remaproughness", &remap)))
        return st;
    if (u < 0) u = r;
    if (v < 0) v = r;
    double au = pow(clpt_roughness(u, remap), 2), av = pow(clpt_roughness(v, remap), 2);
    double hi = fmax(au, av), lo = fmin(au, av);
    *rough = (float)sqrt(sqrt(au * av));
    /* alpha_x / alpha_y = 1 / (1 - 0.9 A) (docs/scene-format.md); the direction of the
     * stretch is clpt's, not the file's */
    *aniso = hi > 0 ? (float)fmin((1 - lo / hi) / 0.9, 1.0) : 0.0f;
    return ST_OK;
}

static Status get_roughness(Parser *p, const Lexer *lx, Material *m, double dflt)
{
    return get_roughness_named(p, lx, "", dflt, &m->roughness, &m->anisotropy);
}

static Status conductor_params(Parser *p, const Lexer *lx, const char *eta_name, const char *k_name,
                               const char *refl_name, Material *m)
{
    vec3 eta, k, refl = v3(0, 0, 0);
    material_metal_preset("Cu", 2, &eta, &k);   /* pbrt's default conductor is copper */
    int has_refl = 0;
    Status st;
    if ((st = get_spectrum(p, lx, eta_name, &eta, NULL, NULL)) || (st = get_spectrum(p, lx, k_name, &k, NULL, NULL)) ||
        (st = get_spectrum(p, lx, refl_name, &refl, NULL, &has_refl)))
        return st;
    float rough = m->roughness, aniso = m->anisotropy;
    *m = has_refl ? material_conductor_f0(refl, rough) : material_conductor(eta, k, rough);
    m->roughness = rough;
    m->anisotropy = aniso;
    return ST_OK;
}

static Status texture_of(Parser *p, const Lexer *lx, const char *name, vec3 *albedo, uint *texture)
{
    const PTexture *tex;
    Status st = get_spectrum(p, lx, name, albedo, &tex, NULL);
    if (st) return st;
    if (tex) *texture = tex->index;
    return ST_OK;
}

static PPending *pending_of(Parser *p, uint index)
{
    for (size_t i = 0; i < p->n_pending; i++)
        if (p->pending[i].index == index && !p->pending[i].defined) return &p->pending[i];
    return NULL;
}

/* pbrt's mix: its two named materials (defined before it, so a mix never contains
 * itself) and `amount`, a float or a float texture (an image's red channel), chosen per
 * hit by the kernels (kernels/mix.h). */
static Status make_mix(Parser *p, const Lexer *lx, const Token *type, Material *m)
{
    Param *pa = param_find(p, "materials");
    if (!pa || pa->type != PT_STRING || pa->n != 2)
        return lex_error_at(lx, type, p->err, "a mix material needs \"string materials\" with two names");
    uint32_t parts[2];
    for (int i = 0; i < 2; i++) {
        const Token *named = &p->pl.strs[pa->first + i];
        if (!strmap_find(&p->named_material, named->text, named->len, &parts[i]) || pending_of(p, parts[i]))
            return lex_error_at(lx, named, p->err, "material '%.*s' is not defined (MakeNamedMaterial defines it)",
                                (int)(named->len > 40 ? 40 : named->len), named->text);
    }
    double amount = 0.5;
    uint amount_tex = NO_INDEX;
    Param *am = param_find(p, "amount");
    Status st;
    if (am && am->type == PT_TEXTURE) {
        const PTexture *tex;
        vec3 c = v3(0.5f, 0.5f, 0.5f);
        if ((st = get_spectrum(p, lx, "amount", &c, &tex, NULL))) return st;
        amount = tex ? 1.0 : c.x;
        if (tex) amount_tex = tex->index;
    } else if ((st = get_float(p, lx, "amount", &amount))) {
        return st;
    }
    /* the kernels follow MIX_MAX_DEPTH mixes from a hit's material */
    uint da = scene_mix_depth(p->s, parts[0]), db = scene_mix_depth(p->s, parts[1]);
    if ((da > db ? da : db) >= MIX_MAX_DEPTH)
        return lex_error_at(lx, type, p->err, "mix materials nest more than %u deep", MIX_MAX_DEPTH);
    *m = material_mix(parts[0], parts[1], (float)amount, amount_tex);
    return ST_OK;
}

/* The medium between a coat and its base: thickness, albedo, g, maxdepth, nsamples
 * (pbrt-v4's defaults are material_coated_*'s). */
static Status coated_medium(Parser *p, const Lexer *lx, Material *m)
{
    double thickness = m->layer_thickness, g = m->layer_g;
    long depth = (long)m->layer_depth, samples = (long)m->layer_samples;
    Status st;
    if ((st = get_float_tex(p, lx, "thickness", &thickness)) || (st = get_float_tex(p, lx, "g", &g)) ||
        (st = get_spectrum(p, lx, "albedo", &m->layer_albedo, NULL, NULL)) ||
        (st = get_int(p, lx, "maxdepth", &depth)) || (st = get_int(p, lx, "nsamples", &samples)))
        return st;
    if (!(thickness >= 0)) return param_type_error(p, lx, param_find(p, "thickness"), ">= 0");
    if (!(g > -1 && g < 1)) return param_type_error(p, lx, param_find(p, "g"), "between -1 and 1");
    if (depth < 0 || depth > 256) return param_type_error(p, lx, param_find(p, "maxdepth"), "0 to 256");
    if (samples < 1 || samples > 64) return param_type_error(p, lx, param_find(p, "nsamples"), "1 to 64");
    m->layer_thickness = (float)thickness;
    m->layer_g = (float)g;
    m->layer_depth = (uint)depth;
    m->layer_samples = (uint)samples;
    return ST_OK;
}

/* pbrt-v4's coateddiffuse and coatedconductor: MAT_LAYERED (kernels/layered.h). A
 * conductor's `reflectance` becomes pbrt's index for it, eta 1 and k = 2 sqrt(r) /
 * sqrt(1 - r), as CoatedConductorMaterial does. */
static Status make_coated(Parser *p, const Lexer *lx, int conductor, Material *m)
{
    Status st;
    double eta = 1.5;
    if (conductor) {
        Material base = material_conductor(v3(1, 1, 1), v3(0, 0, 0), 0);
        if ((st = conductor_params(p, lx, "conductor.eta", "conductor.k", "reflectance", &base))) return st;
        vec3 e = base.eta, k = base.k;
        if (base.flags & MAT_F0) {
            float r[3] = {base.specular.x, base.specular.y, base.specular.z}, kk[3];
            for (int i = 0; i < 3; i++) {
                float c = r[i] < 0.9999f ? r[i] : 0.9999f;
                kk[i] = 2.0f * sqrtf(c) / sqrtf(1.0f - c);
            }
            e = v3(1, 1, 1);
            k = v3(kk[0], kk[1], kk[2]);
        }
        *m = material_coated_conductor(e, k, 0, 0);
        if ((st = get_roughness_named(p, lx, "conductor.", 0, &m->base_roughness, &m->base_anisotropy)) ||
            (st = get_roughness_named(p, lx, "interface.", 0, &m->roughness, &m->anisotropy)) ||
            (st = get_float_tex(p, lx, "interface.eta", &eta)))
            return st;
    } else {
        *m = material_coated_diffuse(v3(0.5f, 0.5f, 0.5f), 0);
        if ((st = texture_of(p, lx, "reflectance", &m->albedo, &m->texture)) || (st = get_roughness(p, lx, m, 0)) ||
            (st = get_float_tex(p, lx, "eta", &eta)))
            return st;
    }
    /* pbrt-v4 takes an index of 0 as 1 (no interface) */
    if (eta < 0) return param_type_error(p, lx, param_find(p, conductor ? "interface.eta" : "eta"), ">= 0");
    m->ior = eta == 0 ? 1.0f : (float)eta;
    return coated_medium(p, lx, m);
}

/* Builds the material of type `type` from the current parameter list. */
static Status make_material(Parser *p, const Lexer *lx, const Token *type, Material *m, const char *what)
{
    Status st;
    if (tok_eq(type, "diffuse")) {
        *m = material_diffuse(v3(0.5f, 0.5f, 0.5f));
        st = texture_of(p, lx, "reflectance", &m->albedo, &m->texture);
    } else if (tok_eq(type, "conductor")) {
        *m = material_conductor(v3(1, 1, 1), v3(0, 0, 0), 0);
        if ((st = get_roughness(p, lx, m, 0))) return st;
        st = conductor_params(p, lx, "eta", "k", "reflectance", m);
    } else if (tok_eq(type, "dielectric") || tok_eq(type, "thindielectric")) {
        double eta = 1.5;
        if ((st = get_float_tex(p, lx, "eta", &eta))) return st;
        if (!(eta > 0)) return param_type_error(p, lx, param_find(p, "eta"), "> 0");
        *m = material_dielectric((float)eta);
        if ((st = get_roughness(p, lx, m, 0))) return st;
        if (tok_eq(type, "thindielectric")) m->flags |= MAT_THIN;
    } else if (tok_eq(type, "coateddiffuse") || tok_eq(type, "coatedconductor")) {
        st = make_coated(p, lx, tok_eq(type, "coatedconductor"), m);
    } else if (tok_eq(type, "interface") || tok_eq(type, "") || tok_eq(type, "none")) {
        /* an invisible boundary (a medium's edge): glass of index 1 passes light unbent.
         * pbrt-v4 makes no material for "" and "none" either (MaterialHandle::Create),
         * as pbrt-v4-scenes' clouds.pbrt uses: Material "" on its medium's sphere. */
        *m = material_dielectric(1.0f);
        st = ST_OK;
    } else if (tok_eq(type, "mix")) {
        st = make_mix(p, lx, type, m);
    } else {
        *m = material_diffuse(v3(0.5f, 0.5f, 0.5f));
        char key[96];
        snprintf(key, sizeof key, "Material %.*s", (int)(type->len > 40 ? 40 : type->len), type->text);
        st = warn_once(p, lx, type, key, "material \"%.*s\" is not supported; diffuse 0.5 is used",
                       (int)(type->len > 40 ? 40 : type->len), type->text);
        for (size_t i = 0; i < p->pl.n; i++) p->pl.p[i].used = 1;
    }
    if (st) return st;
    param_find(p, "type");
    return warn_unused(p, lx, what);
}

static Status set_material(Parser *p, uint index)
{
    p->g.material = index;
    p->g.area_material = NO_INDEX;
    return ST_OK;
}

static Status d_material(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token type;
    Status st = expect_string(p, lx, "a quoted material type", &type);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    Material m;
    if ((st = make_material(p, lx, &type, &m, "Material"))) return st;
    uint index;
    if ((st = scene_add_material(p->s, "", m, &index, p->err))) return st;
    return set_material(p, index);
}

static Status d_make_named_material(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token name;
    Status st = expect_string(p, lx, "a quoted material name", &name);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    const Token *type = NULL;
    if ((st = get_string(p, lx, "type", &type))) return st;
    if (!type) return lex_error_at(lx, &name, p->err, "MakeNamedMaterial needs \"string type\"");
    Material m;
    if ((st = make_material(p, lx, type, &m, "MakeNamedMaterial"))) return st;
    uint index;
    PPending *pd;
    if (strmap_find(&p->named_material, name.text, name.len, &index) && (pd = pending_of(p, index))) {
        /* used before: the placeholder and its area-light copies become this material */
        pd->defined = 1;
        for (size_t i = 0; i < p->n_area_pending; i++) {
            if (p->area_of_pending[i].base != index) continue;
            Material *a = &p->s->materials[p->area_of_pending[i].area];
            Material e = m;
            e.emission = a->emission;
            e.flags |= a->flags & MAT_TWO_SIDED;
            *a = e;
        }
        p->s->materials[index] = m;
        return ST_OK;
    }
    char *n = tok_copy(&name);
    if (!n) return error_set(p->err, ST_INTERNAL, "out of memory");
    st = scene_add_material(p->s, n, m, &index, p->err);
    free(n);
    if (st) return st;
    if (strmap_set(&p->named_material, name.text, name.len, index))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    return ST_OK;
}

static Status d_named_material(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token name;
    Status st = expect_string(p, lx, "a quoted material name", &name);
    if (st) return st;
    uint32_t i;
    if (strmap_find(&p->named_material, name.text, name.len, &i)) return set_material(p, i);
    /* not defined yet: pbrt-v4 looks names up once the whole scene is read, so a
     * later MakeNamedMaterial (pbrt-v4-scenes' contemporary-bathroom.pbrt includes its
     * materials.pbrt at the end) defines it; a placeholder until then */
    char *n = tok_copy(&name);
    if (!n) return error_set(p->err, ST_INTERNAL, "out of memory");
    st = scene_add_material(p->s, n, material_diffuse(v3(0.5f, 0.5f, 0.5f)), &i, p->err);
    free(n);
    if (st) return st;
    if (strmap_set(&p->named_material, name.text, name.len, i) ||
        grow((void **)&p->pending, &p->cap_pending, p->n_pending + 1, sizeof(PPending)))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    PPending *pd = &p->pending[p->n_pending++];
    pd->index = i;
    pd->defined = 0;
    snprintf(pd->where, sizeof pd->where, "%s:%u:%u: material '%.*s'", lx->path, name.line, name.col,
             (int)(name.len > 40 ? 40 : name.len), name.text);
    return set_material(p, i);
}

/* A file the scene names, found as pbrt finds it: a relative path from the main
 * file's folder, includes or not (io/path.h). NULL when out of memory. */
static char *beside_main(const Parser *p, const Token *f)
{
    char *path;
    path_resolve(p->top_path, f->text, f->len, PATH_BESIDE, &path);
    return path;
}

/* pbrt-v4's (u, v) mapping of 2D textures: (uscale u + udelta, vscale v + vdelta) of
 * clpt's surface coordinates; another `mapping` (spherical, cylindrical, planar) is a
 * warning and uv. */
static Status tex_uv_mapping(Parser *p, const Lexer *lx, Texture *t)
{
    double su = 1, sv = 1, du = 0, dv = 0;
    const Token *mapping = NULL;
    Status st;
    if ((st = get_float(p, lx, "uscale", &su)) || (st = get_float(p, lx, "vscale", &sv)) ||
        (st = get_float(p, lx, "udelta", &du)) || (st = get_float(p, lx, "vdelta", &dv)) ||
        (st = get_string(p, lx, "mapping", &mapping)))
        return st;
    if (mapping && !tok_eq(mapping, "uv") &&
        (st = warn_once(p, lx, mapping, "texture-mapping", "texture mapping \"%.*s\" is not supported; uv is used",
                        (int)(mapping->len > 40 ? 40 : mapping->len), mapping->text)))
        return st;
    const char *names[4] = { "uscale", "vscale", "udelta", "vdelta" };
    const double vals[4] = { su, sv, du, dv };
    for (int i = 0; i < 4; i++)
        if (!(fabs(vals[i]) <= TEXTURE_MAX_MAP_ENTRY))
            return lex_error_at(lx, &param_find(p, names[i])->decl, p->err, "\"%s\" is %g; clpt takes texture "
                                "scales and offsets of at most %.0f in size", names[i], vals[i],
                                (double)TEXTURE_MAX_MAP_ENTRY);
    texture_set_scale_offset(t, (float)su, (float)sv, (float)du, (float)dv);
    return ST_OK;
}

/* Texel i of scene texture t as linear RGB. */
static vec3 texel_rgb(const Scene *s, const Texture *t, size_t i)
{
    if (t->flags & TEX_FLOAT) {
        float f[3];
        memcpy(f, s->texels + t->offset + 3 * i, sizeof f);
        return v3(f[0], f[1], f[2]);
    }
    uint c = s->texels[t->offset + i];
    float rgb[3];
    for (int k = 0; k < 3; k++) {
        rgb[k] = (float)((c >> (8 * k)) & 255u) / 255.0f;
        if (t->flags & TEX_SRGB) rgb[k] = k_srgb_to_linear(rgb[k]);
    }
    return v3(rgb[0], rgb[1], rgb[2]);
}

/* The mean colour of an image texture's texels. */
static vec3 image_mean(const Scene *s, const Texture *t)
{
    size_t n = (size_t)t->width * t->height;
    double sum[3] = { 0, 0, 0 };
    for (size_t i = 0; i < n; i++) {
        vec3 c = texel_rgb(s, t, i);
        sum[0] += c.x;
        sum[1] += c.y;
        sum[2] += c.z;
    }
    return n ? v3((float)(sum[0] / n), (float)(sum[1] / n), (float)(sum[2] / n)) : v3(0, 0, 0);
}

static Status tex_imagemap(Parser *p, const Lexer *lx, const Token *cls, PTexture *t)
{
    const Token *f = NULL, *enc = NULL;
    Status st;
    if ((st = get_string(p, lx, "filename", &f))) return st;
    if (!f) return lex_error_at(lx, cls, p->err, "an imagemap texture needs \"string filename\"");
    if ((st = get_string(p, lx, "encoding", &enc))) return st;
    int linear = enc && tok_eq(enc, "linear");
    /* pbrt-v4's wrap: "repeat" (its default, and clpt's), "clamp" (clpt's clamp to the
     * edge); "black" and "octahedralsphere" a warning and repeat */
    const Token *wrap = NULL;
    if ((st = get_string(p, lx, "wrap", &wrap))) return st;
    int clamp = wrap && tok_eq(wrap, "clamp");
    if (wrap && !clamp && !tok_eq(wrap, "repeat") &&
        (st = warn_once(p, lx, wrap, "texture-wrap", "texture wrap \"%.*s\" is not supported; repeat is used",
                        (int)(wrap->len > 40 ? 40 : wrap->len), wrap->text)))
        return st;
    char *path = beside_main(p, f);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    st = texture_load_image(p->s, NULL, path, linear, clamp, &t->index, p->err);
    free(path);
    if (st) {
        reader_annotate(lx, f, p->err);
        return st;
    }
    t->constant = 0;
    Texture *tx = &p->s->textures[t->index];
    t->mean = image_mean(p->s, tx);
    return tex_uv_mapping(p, lx, tx);
}

/* A colour parameter that may name another texture (checkerboard's tex1 and tex2,
 * scale's tex and scale): a constant's value; a varying texture in *tex when `tex` is
 * not NULL, else its mean colour with a warning. */
static Status tex_operand(Parser *p, const Lexer *lx, const char *name, vec3 *out, const PTexture **tex)
{
    Param *pa = param_find(p, name);
    if (tex) *tex = NULL;
    if (!pa) return ST_OK;
    if (pa->type != PT_TEXTURE) {
        pa->used = 0;
        return get_spectrum(p, lx, name, out, NULL, NULL);
    }
    const Token *n = &p->pl.strs[pa->first];
    uint32_t i;
    if (!strmap_find(&p->tex_by_name, n->text, n->len, &i))
        return lex_error_at(lx, n, p->err, "texture '%.*s' is not defined", (int)(n->len > 40 ? 40 : n->len), n->text);
    const PTexture *src = &p->tex[i];
    if (src->constant) {
        *out = src->color;
    } else if (tex) {
        *tex = src;
    } else {
        *out = src->mean;
        return warn_once(p, lx, &pa->decl, "checker-texture", "a checkerboard's \"%.*s\" is a texture: its mean "
                         "colour is used", (int)pa->name_len, pa->name);
    }
    return ST_OK;
}

/* pbrt-v4's checkerboard: tex1 on the cells whose integer coordinates sum to an even
 * number (pbrt's weight 0.5 - bf(s) bf(t) / 2 is 0 there), tex2 on the others: clpt's
 * TEX_CHECKER colour0 and colour1. 2D on the surface's (u, v) mapped as tex_uv_mapping,
 * or 3D (dimension 3) at the point in the texture's space: the CTM at Texture maps
 * texture space to the world, as pbrt's PointTransformMapping. */
static Status tex_checkerboard(Parser *p, const Lexer *lx, PTexture *t)
{
    vec3 c1 = v3(1, 1, 1), c2 = v3(0, 0, 0);   /* pbrt's defaults */
    long dim = 2;
    Status st;
    if ((st = tex_operand(p, lx, "tex1", &c1, NULL)) || (st = tex_operand(p, lx, "tex2", &c2, NULL)) ||
        (st = get_int(p, lx, "dimension", &dim)))
        return st;
    if (dim != 2 && dim != 3) return param_type_error(p, lx, param_find(p, "dimension"), "2 or 3");
    Texture tx = texture_make_checker(c1, c2, 1.0f, dim == 3);
    if (dim == 3) {
        int ok;
        Transform inv = transform_inverse(&p->g.ctm, &ok);
        if (!ok) return lex_error_at(lx, &param_find(p, "dimension")->decl, p->err,
                                     "the checkerboard's transform cannot be inverted");
        float m[12];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) m[4 * i + j] = (float)inv.m[i][j];
        texture_set_matrix(&tx, m);
        if ((st = texture_check_map(&tx, p->err))) {
            const Token *d = &param_find(p, "dimension")->decl;
            error_prefix(p->err, "%s:%u:%u: the 3D checkerboard's transform", lx->path, d->line, d->col);
            return st;
        }
    } else if ((st = tex_uv_mapping(p, lx, &tx))) {
        return st;
    }
    t->constant = 0;
    t->mean = v3_scale(v3_add(c1, c2), 0.5f);
    return scene_add_texture(p->s, NULL, NULL, tx, &t->index, p->err);
}

/* A copy of varying texture src with every colour times k: a checkerboard with its two
 * colours scaled, an image as float texels scaled (the original stays for its other
 * users). */
static Status tex_scaled_copy(Parser *p, const PTexture *src, vec3 k, PTexture *out)
{
    Scene *s = p->s;
    Texture tx = s->textures[src->index];
    out->constant = 0;
    out->mean = v3_mul(src->mean, k);
    if (tx.type == TEX_CHECKER) {
        tx.color0 = v3_mul(tx.color0, k);
        tx.color1 = v3_mul(tx.color1, k);
        return scene_add_texture(s, NULL, NULL, tx, &out->index, p->err);
    }
    size_t n = (size_t)tx.width * tx.height;
    uint *texels = malloc(n * 3 * sizeof *texels);
    if (!texels) return error_set(p->err, ST_INTERNAL, "out of memory");
    for (size_t i = 0; i < n; i++) {
        vec3 c = v3_mul(texel_rgb(s, &tx, i), k);
        float f[3] = { c.x, c.y, c.z };
        memcpy(texels + 3 * i, f, sizeof f);
    }
    Status st = scene_add_texels(s, texels, n * 3, &tx.offset, p->err);
    free(texels);
    if (st) return st;
    tx.flags = (tx.flags & ~TEX_SRGB) | TEX_FLOAT;
    return scene_add_texture(s, NULL, NULL, tx, &out->index, p->err);
}

/* pbrt-v4's scale: tex x scale. Two constants multiply; a varying texture times a
 * constant is a scaled copy of it; two varying ones, a warning: the first times the
 * second's mean colour. */
static Status tex_scale(Parser *p, const Lexer *lx, PTexture *t)
{
    vec3 a = v3(1, 1, 1), b = v3(1, 1, 1);
    const PTexture *ta, *tb;
    Status st;
    if ((st = tex_operand(p, lx, "tex", &a, &ta)) || (st = tex_operand(p, lx, "scale", &b, &tb))) return st;
    if (ta && tb) {
        if ((st = warn_once(p, lx, &param_find(p, "scale")->decl, "scale-two", "a scale texture of two textures: "
                            "the second's mean colour scales the first")))
            return st;
        b = tb->mean;
        tb = NULL;
    }
    if (!ta && !tb) {
        t->color = v3_mul(a, b);
        return ST_OK;
    }
    return ta ? tex_scaled_copy(p, ta, b, t) : tex_scaled_copy(p, tb, a, t);
}

static Status d_texture(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token name, vtype, cls;
    Status st = expect_string(p, lx, "a quoted texture name", &name);
    if (!st) st = expect_string(p, lx, "a quoted texture type (spectrum or float)", &vtype);
    if (!st) st = expect_string(p, lx, "a quoted texture class", &cls);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    PTexture t = {0};
    t.constant = 1;
    t.color = v3(1, 1, 1);
    t.index = NO_INDEX;
    if (tok_eq(&cls, "constant")) {
        if ((st = get_spectrum(p, lx, "value", &t.color, NULL, NULL))) return st;
    } else if (tok_eq(&cls, "imagemap")) {
        st = tex_imagemap(p, lx, &cls, &t);
    } else if (tok_eq(&cls, "checkerboard")) {
        st = tex_checkerboard(p, lx, &t);
    } else if (tok_eq(&cls, "scale")) {
        st = tex_scale(p, lx, &t);
    } else {
        char key[96];
        snprintf(key, sizeof key, "Texture %.*s", (int)(cls.len > 40 ? 40 : cls.len), cls.text);
        st = warn_once(p, lx, &cls, key, "texture \"%.*s\" is not supported; it is a constant 1",
                       (int)(cls.len > 40 ? 40 : cls.len), cls.text);
        for (size_t i = 0; i < p->pl.n; i++) p->pl.p[i].used = 1;
    }
    if (st) return st;
    if (t.constant) t.mean = t.color;
    if (grow((void **)&p->tex, &p->cap_tex, p->n_tex + 1, sizeof(PTexture)) ||
        strmap_set(&p->tex_by_name, name.text, name.len, (uint32_t)p->n_tex))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    p->tex[p->n_tex++] = t;
    return warn_unused(p, lx, "Texture");
}

/* The material of the next shape: the current one, with the area light's emission. */
static Status shape_material(Parser *p, uint *out)
{
    Status st;
    *out = NO_INDEX;
    if (p->g.material == NO_INDEX) {
        uint i;
        if ((st = scene_add_material(p->s, "", material_diffuse(v3(0.5f, 0.5f, 0.5f)), &i, p->err))) return st;
        p->g.material = i;
    }
    if (!p->g.area) {
        *out = p->g.material;
        return ST_OK;
    }
    if (p->g.area_material == NO_INDEX) {
        Material m = p->s->materials[p->g.material];
        m.emission = p->g.area_L;
        if (p->g.area_twosided) m.flags |= MAT_TWO_SIDED;
        uint i;
        if ((st = scene_add_material(p->s, "", m, &i, p->err))) return st;
        p->g.area_material = i;
        if (pending_of(p, p->g.material)) {
            if (grow((void **)&p->area_of_pending, &p->cap_area_pending, p->n_area_pending + 1,
                     sizeof *p->area_of_pending))
                return error_set(p->err, ST_INTERNAL, "out of memory");
            p->area_of_pending[p->n_area_pending].area = i;
            p->area_of_pending[p->n_area_pending++].base = p->g.material;
        }
    }
    *out = p->g.area_material;
    return ST_OK;
}

/* ------------------------------------------------------------------ lights */

static Status d_area_light(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token type;
    Status st = expect_string(p, lx, "a quoted area light type", &type);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    if (!tok_eq(&type, "diffuse"))
        return lex_error_at(lx, &type, p->err, "area light \"%.*s\" is not supported (diffuse is)",
                            (int)(type.len > 40 ? 40 : type.len), type.text);
    vec3 L = v3(1, 1, 1);
    double scale = 1;
    int two = 0;
    if ((st = get_spectrum(p, lx, "L", &L, NULL, NULL)) || (st = get_float(p, lx, "scale", &scale)) ||
        (st = get_bool(p, lx, "twosided", &two)))
        return st;
    if (!(scale >= 0)) return param_type_error(p, lx, param_find(p, "scale"), ">= 0");
    p->g.area = 1;
    p->g.area_L = v3_scale(L, (float)scale);
    p->g.area_twosided = two;
    p->g.area_material = NO_INDEX;
    return warn_unused(p, lx, "AreaLightSource");
}

static vec3 xf_dir(const Transform *t, vec3 d)
{
    vec3 o = transform_point(t, v3(0, 0, 0)), e = transform_point(t, d);
    return v3_sub(e, o);
}

static Status light_dir(Parser *p, const Lexer *lx, const Token *at, vec3 d, vec3 *out)
{
    double l = sqrt((double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z);
    if (!(l > 0) || !isfinite(l)) return lex_error_at(lx, at, p->err, "the light's 'from' and 'to' are the same point");
    *out = v3((float)(d.x / l), (float)(d.y / l), (float)(d.z / l));
    return ST_OK;
}

/* pbrt-v4's ImageInfiniteLight: the square map at `f` (beside the main file), in the
 * light's frame (the CTM), scaled by `scale` (octa_env.h). */
static Status infinite_map(Parser *p, const Lexer *lx, const Token *f, double scale, double illuminance)
{
    char *path = beside_main(p, f);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    float *rgb = NULL;
    int w = 0, h = 0;
    Status st = texture_read_rgb(path, 0, &rgb, &w, &h, p->err);
    free(path);
    if (st) {
        reader_annotate(lx, f, p->err);
        return st;
    }
    int finite = 1, invertible;
    size_t n = (size_t)w * (size_t)h * 3u;
    for (size_t i = 0; i < n && finite; i++) finite = isfinite(rgb[i]);
    Transform inv = transform_inverse(&p->g.ctm, &invertible);
    if (w != h) {
        st = lex_error_at(lx, f, p->err, "the infinite light's map is %dx%d; pbrt-v4's maps are square (equal-area "
                          "octahedral)", w, h);
    } else if (!finite) {
        st = lex_error_at(lx, f, p->err, "the infinite light's map has infinite or NaN pixels");
    } else if (!invertible) {
        st = lex_error_at(lx, f, p->err, "the infinite light's transform cannot be inverted");
    } else {
        if (illuminance > 0) {
            /* pbrt-v4's normalisation: the map's illuminance on an upward (+z) surface,
             * a sum over the upper hemisphere's texels of luminance x cos(theta) times
             * 2 pi / texels (its code's factor; each texel spans 4 pi / texels) */
            double k_e = 0;
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++) {
                    double d[3];
                    octa_square_to_sphere((x + 0.5) / w, (y + 0.5) / h, d);
                    if (d[2] <= 0) continue;
                    const float *t = rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
                    k_e += (0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2]) * d[2];
                }
            k_e *= 2 * M_PI / ((double)w * h);
            if (k_e > 0) scale *= illuminance / k_e;
        }
        double m[9];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) m[3 * i + j] = inv.m[i][j];
        st = octa_env_set(p->s, rgb, (uint)w, m, (float)scale, p->err);
    }
    free(rgb);
    return st;
}

/* LightSource "infinite": a constant L, or an image (never both, as in pbrt); clpt has
 * one background, so a second light with a map is ignored with a warning, and a map
 * replaces the constants before it. */
static Status infinite_light(Parser *p, const Lexer *lx, const Token *type, double scale)
{
    vec3 c = v3(1, 1, 1);
    int has_L = 0;
    const Token *f = NULL;
    double illuminance = -1;
    Status st;
    if ((st = get_spectrum(p, lx, "L", &c, NULL, &has_L)) || (st = get_string(p, lx, "filename", &f)) ||
        (st = get_float(p, lx, "illuminance", &illuminance)))
        return st;
    param_find(p, "portal");   /* a sampling aid only */
    if (f && has_L)
        return lex_error_at(lx, type, p->err, "an infinite light takes \"L\" or \"filename\", not both");
    if (p->s->bg_type == BG_MAP)
        return warn_once(p, lx, type, "infinite-second", "clpt has one environment map: this infinite light is "
                         "ignored");
    if (f) {
        if (p->s->bg_type == BG_CONSTANT && !v3_is_zero(p->s->bg_color) &&
            (st = warn_once(p, lx, type, "infinite-replace", "clpt has one background: the infinite light's map "
                            "replaces the constant ones before it")))
            return st;
        return infinite_map(p, lx, f, scale, illuminance);
    }
    /* pbrt-v4: a uniform hemisphere of radiance L gives illuminance pi L */
    if (illuminance > 0) scale *= illuminance / M_PI;
    p->s->bg_type = BG_CONSTANT;
    p->s->bg_color = v3_add(p->s->bg_color, v3_scale(c, (float)scale));
    return ST_OK;
}

static Status d_light(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token type;
    Status st = expect_string(p, lx, "a quoted light type", &type);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    double scale = 1;
    if ((st = get_float(p, lx, "scale", &scale))) return st;
    vec3 from = v3(0, 0, 0), to = v3(0, 0, 1), c = v3(1, 1, 1);
    if ((st = get_point(p, lx, "from", &from)) || (st = get_point(p, lx, "to", &to))) return st;
    if (tok_eq(&type, "point") || tok_eq(&type, "spot")) {
        int spot = tok_eq(&type, "spot");
        if ((st = get_spectrum(p, lx, "I", &c, NULL, NULL))) return st;
        Light l = light_default(spot ? LIGHT_SPOT : LIGHT_POINT);
        l.intensity = v3_scale(c, (float)scale);
        l.position = transform_point(&p->g.ctm, from);
        if (spot) {
            double cone = 30, delta = 5;
            if ((st = get_float(p, lx, "coneangle", &cone)) || (st = get_float(p, lx, "conedelta", &delta))) return st;
            if (!(cone > 0 && cone < 180)) return param_type_error(p, lx, param_find(p, "coneangle"), "in (0, 180)");
            if (!(delta >= 0)) return param_type_error(p, lx, param_find(p, "conedelta"), ">= 0");
            if ((st = light_dir(p, lx, &type, xf_dir(&p->g.ctm, v3_sub(to, from)), &l.direction))) return st;
            l.cos_outer = (float)cos(cone * M_PI / 180);
            l.cos_inner = (float)cos(fmax(cone - delta, 0) * M_PI / 180);
        }
        if ((st = scene_add_light(p->s, l, p->err))) return st;
    } else if (tok_eq(&type, "distant")) {
        if ((st = get_spectrum(p, lx, "L", &c, NULL, NULL))) return st;
        Light l = light_default(LIGHT_DIRECTIONAL);
        l.intensity = v3_scale(c, (float)scale);
        if ((st = light_dir(p, lx, &type, xf_dir(&p->g.ctm, v3_sub(to, from)), &l.direction))) return st;
        if ((st = scene_add_light(p->s, l, p->err))) return st;
    } else if (tok_eq(&type, "infinite")) {
        if ((st = infinite_light(p, lx, &type, scale))) return st;
    } else {
        char key[96];
        snprintf(key, sizeof key, "LightSource %.*s", (int)(type.len > 40 ? 40 : type.len), type.text);
        for (size_t i = 0; i < p->pl.n; i++) p->pl.p[i].used = 1;
        return warn_once(p, lx, &type, key, "LightSource \"%.*s\" is not supported; skipped",
                         (int)(type.len > 40 ? 40 : type.len), type.text);
    }
    return warn_unused(p, lx, "LightSource");
}

/* ------------------------------------------------------------------ shapes */

/* Flips triangles [first, end): ReverseOrientation, and meshes whose normals say so */
static void flip_triangle(Scene *s, size_t i)
{
    Triangle *t = &s->triangles[i];
    vec3 q = t->p1;
    t->p1 = t->p2;
    t->p2 = q;
    if (t->shading != NO_INDEX) {
        TriShading *sh = &s->shading[t->shading];
        vec3 n = sh->n1;
        sh->n1 = sh->n2;
        sh->n2 = n;
        float u0 = sh->uv1[0], u1 = sh->uv1[1];
        sh->uv1[0] = sh->uv2[0];
        sh->uv1[1] = sh->uv2[1];
        sh->uv2[0] = u0;
        sh->uv2[1] = u1;
    }
}

/* pbrt's side of a triangle: toward its shading normals when it has them (flipped by
 * ReverseOrientation), else the winding's, flipped by ReverseOrientation. */
static void orient_triangles(Parser *p, size_t first)
{
    Scene *s = p->s;
    for (size_t i = first; i < s->n_triangles; i++) {
        Triangle *t = &s->triangles[i];
        int has_n = t->shading != NO_INDEX && (s->shading[t->shading].flags & TRI_HAS_NORMALS);
        if (has_n && p->g.reverse) {
            TriShading *sh = &s->shading[t->shading];
            sh->n0 = v3_neg(sh->n0);
            sh->n1 = v3_neg(sh->n1);
            sh->n2 = v3_neg(sh->n2);
        }
        if (has_n) {
            TriShading *sh = &s->shading[t->shading];
            vec3 n = v3_add(v3_add(sh->n0, sh->n1), sh->n2);
            vec3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0);
            vec3 w = v3(e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x);
            if (w.x * n.x + w.y * n.y + w.z * n.z < 0) flip_triangle(s, i);
        } else if (p->g.reverse) {
            flip_triangle(s, i);
        }
    }
}

/* Reads an index array against `n_points`. */
static Status get_indices(Parser *p, const Lexer *lx, const char *name, size_t per, size_t n_points, const long **unused,
                          Param **out)
{
    (void)unused;
    Param *pa = param_find(p, name);
    *out = pa;
    if (!pa) return ST_OK;
    if (pa->type != PT_INTEGER) return param_type_error(p, lx, pa, "integer");
    if (pa->n % per) {
        char what[64];
        snprintf(what, sizeof what, "a multiple of %zu integers", per);
        return param_type_error(p, lx, pa, what);
    }
    for (size_t i = 0; i < pa->n; i++) {
        double d = p->pl.nums[pa->first + i];
        if (d < 0 || d >= (double)n_points)
            return lex_error_at(lx, &pa->decl, p->err, "'%.*s' value %zu is %.0f, outside the %zu points of 'P'",
                                (int)pa->name_len, pa->name, i, d, n_points);
    }
    return ST_OK;
}

/* P, N, uv of a mesh, each checked against P's count. */
static Status mesh_arrays(Parser *p, const Lexer *lx, const Token *type, Param **P, Param **N, Param **uv)
{
    *P = param_find(p, "P");
    if (!*P) return lex_error_at(lx, type, p->err, "a %.*s needs \"point3 P\"", (int)type->len, type->text);
    if ((*P)->type != PT_POINT3) return param_type_error(p, lx, *P, "point3");
    size_t np = (*P)->n / 3;
    *N = param_find(p, "N");
    if (*N && ((*N)->type != PT_NORMAL || (*N)->n / 3 != np))
        return param_type_error(p, lx, *N, "normal, one per point of 'P'");
    *uv = param_find(p, "uv");
    if (!*uv) *uv = param_find(p, "st");
    if (*uv && ((*uv)->type != PT_POINT2 && (*uv)->type != PT_FLOAT))
        return param_type_error(p, lx, *uv, "point2");
    if (*uv && (*uv)->n / 2 != np) return param_type_error(p, lx, *uv, "one (u, v) per point of 'P'");
    return ST_OK;
}

static vec3 nth3(const Parser *p, const Param *pa, size_t i)
{
    const double *d = p->pl.nums + pa->first + 3 * i;
    return v3((float)d[0], (float)d[1], (float)d[2]);
}

static Status emit_triangle(Parser *p, MeshSink *k, const Param *P, const Param *N, const Param *uv, const size_t idx[3],
                            uint material)
{
    vec3 pt[3], n[3];
    float t[6];
    for (int c = 0; c < 3; c++) {
        pt[c] = nth3(p, P, idx[c]);
        if (N) {
            n[c] = nth3(p, N, idx[c]);
            float l = sqrtf(v3_dot(n[c], n[c]));
            if (!(l > 0)) N = NULL;
            else n[c] = v3_scale(n[c], 1.0f / l);
        }
        if (uv) {
            t[2 * c] = (float)p->pl.nums[uv->first + 2 * idx[c]];
            t[2 * c + 1] = (float)p->pl.nums[uv->first + 2 * idx[c] + 1];
        }
    }
    return mesh_sink_triangle(k, pt, N ? n : NULL, uv ? t : NULL, material);
}

static Status shape_trianglemesh(Parser *p, const Lexer *lx, const Token *type, MeshSink *k, uint material, int bilinear)
{
    Param *P = NULL, *N = NULL, *uv = NULL, *ix = NULL;
    Status st = mesh_arrays(p, lx, type, &P, &N, &uv);
    if (st) return st;
    size_t np = P->n / 3, per = bilinear ? 4 : 3;
    if ((st = get_indices(p, lx, "indices", per, np, NULL, &ix))) return st;
    if (!ix && np != per)
        return lex_error_at(lx, type, p->err, "a %.*s without \"integer indices\" must have exactly %zu points",
                            (int)type->len, type->text, per);
    size_t n = ix ? ix->n / per : 1;
    if ((st = mesh_sink_reserve(k, n * (bilinear ? 2 : 1), (N || uv) ? n * (bilinear ? 2 : 1) : 0))) return st;
    for (size_t f = 0; f < n; f++) {
        size_t v[4];
        for (size_t c = 0; c < per; c++) v[c] = ix ? (size_t)p->pl.nums[ix->first + f * per + c] : c;
        if (!bilinear) {
            if ((st = emit_triangle(p, k, P, N, uv, v, material))) return st;
            continue;
        }
        /* a bilinear patch p00 p10 p01 p11 as two triangles, wound like pbrt's normal */
        size_t a[3] = {v[0], v[1], v[3]}, b[3] = {v[0], v[3], v[2]};
        if ((st = emit_triangle(p, k, P, N, uv, a, material)) || (st = emit_triangle(p, k, P, N, uv, b, material)))
            return st;
    }
    return ST_OK;
}

static int is_similarity(const Transform *t, double *scale)
{
    double c[3][3], l[3];
    for (int j = 0; j < 3; j++) {
        for (int i = 0; i < 3; i++) c[j][i] = t->m[i][j];
        l[j] = sqrt(c[j][0] * c[j][0] + c[j][1] * c[j][1] + c[j][2] * c[j][2]);
    }
    if (!(l[0] > 0) || fabs(l[1] - l[0]) > 1e-6 * l[0] || fabs(l[2] - l[0]) > 1e-6 * l[0]) return 0;
    for (int a = 0; a < 3; a++) {
        int b = (a + 1) % 3;
        if (fabs(c[a][0] * c[b][0] + c[a][1] * c[b][1] + c[a][2] * c[b][2]) > 1e-6 * l[0] * l[0]) return 0;
    }
    *scale = l[0];
    return 1;
}

/* Counts `tris` more tessellated triangles against the scene's budget, before anything
 * is made: a few numbers in a file (a loopsubdiv's levels, thousands of emitting
 * ellipsoids) must not become gigabytes, while a large subdivided model, whose file is
 * large too, must still load. The budget is CLPT_MAX_TESSELLATED_TRIANGLES and
 * CLPT_TESSELLATED_PER_INPUT_BYTE for each byte the load has read so far. `what` names
 * the shape in the message. */
static Status tessellation_budget(Parser *p, const Lexer *lx, const Token *at, size_t tris, const char *what)
{
    uint64_t budget = CLPT_MAX_TESSELLATED_TRIANGLES + CLPT_TESSELLATED_PER_INPUT_BYTE * lex_load_bytes();
    if (tris > budget - p->tessellated)
        return lex_error_at(lx, at, p->err, "%s makes %zu triangles; with the %zu tessellated before it that is "
                            "past the %llu a scene of %llu bytes may make (%u and %u per byte of its files)", what,
                            tris, p->tessellated, (unsigned long long)budget, (unsigned long long)lex_load_bytes(),
                            CLPT_MAX_TESSELLATED_TRIANGLES, CLPT_TESSELLATED_PER_INPUT_BYTE);
    p->tessellated += tris;
    return ST_OK;
}

/* sphere_tessellate's triangles: 64 x 32 quads less one triangle of each at the poles */
enum { SPHERE_MESH_NU = 64, SPHERE_MESH_NV = 32,
       SPHERE_MESH_TRIANGLES = 2 * SPHERE_MESH_NU * SPHERE_MESH_NV - 2 * SPHERE_MESH_NU };

/* An emitting sphere under a transform that is not a similarity (an ellipsoid), or one
 * turned inside out: a UV sphere of 64 x 32 quads through the mesh sink. */
static Status sphere_tessellate(Parser *p, MeshSink *k, double r, uint material)
{
    enum { NU = SPHERE_MESH_NU, NV = SPHERE_MESH_NV };
    Status st = mesh_sink_reserve(k, 2 * NU * NV, 2 * NU * NV);
    for (int j = 0; j < NV && !st; j++)
        for (int i = 0; i < NU && !st; i++) {
            vec3 q[4], n[4];
            float uv[8];
            for (int c = 0; c < 4; c++) {
                int ii = i + (c == 1 || c == 2), jj = j + (c >= 2);
                double phi = 2 * M_PI * ii / NU, th = M_PI * jj / NV;
                n[c] = v3((float)(sin(th) * cos(phi)), (float)(sin(th) * sin(phi)), (float)cos(th));
                q[c] = v3_scale(n[c], (float)r);
                uv[2 * c] = (float)ii / NU;
                uv[2 * c + 1] = (float)jj / NV;
            }
            /* corners 0 1 2 3 go around the quad; outward winding is 0 2 1, 0 3 2 */
            vec3 a[3] = {q[0], q[2], q[1]}, an[3] = {n[0], n[2], n[1]};
            vec3 b[3] = {q[0], q[3], q[2]}, bn[3] = {n[0], n[3], n[2]};
            float auv[6] = {uv[0], uv[1], uv[4], uv[5], uv[2], uv[3]};
            float buv[6] = {uv[0], uv[1], uv[6], uv[7], uv[4], uv[5]};
            if (j > 0) st = mesh_sink_triangle(k, a, an, auv, material);
            if (!st && j < NV - 1) st = mesh_sink_triangle(k, b, bn, buv, material);
        }
    (void)p;
    return st;
}

static Status shape_sphere(Parser *p, const Lexer *lx, const Token *type, uint material)
{
    double r = 1, scale;
    Status st = get_float(p, lx, "radius", &r);
    if (st) return st;
    if (!(r > 0)) return param_type_error(p, lx, param_find(p, "radius"), "> 0");
    Param *zmin = param_find(p, "zmin"), *zmax = param_find(p, "zmax"), *phimax = param_find(p, "phimax");
    if (zmin || zmax || phimax) {
        st = warn_once(p, lx, type, "sphere-partial", "partial spheres (zmin, zmax, phimax) are rendered whole");
        if (st) return st;
    }
    int emits = !v3_is_zero(p->s->materials[material].emission);
    int similar = is_similarity(&p->g.ctm, &scale);
    if (!similar && !emits) {
        /* an ellipsoid stays analytic: 32 + 96 bytes however it is squashed */
        Transform m = transform_scale(r, r, r);
        m = transform_compose(&p->g.ctm, &m);
        if ((st = scene_add_ellipsoid(p->s, &m, material, p->err)) == ST_INPUT)
            reader_annotate(lx, type, p->err);
        return st;
    }
    if (similar && !(p->g.reverse && emits)) {
        Sphere sp;
        memset(&sp, 0, sizeof sp);
        sp.center = transform_point(&p->g.ctm, v3(0, 0, 0));
        sp.radius = (float)(r * scale);
        sp.material = material;
        if (!(sp.radius > 0) || !isfinite(sp.radius) || !isfinite(fabsf(sp.center.x) + sp.radius) ||
            !isfinite(fabsf(sp.center.y) + sp.radius) || !isfinite(fabsf(sp.center.z) + sp.radius))
            return lex_error_at(lx, type, p->err, "the sphere reaches beyond the largest float (about 3.4e38)");
        return scene_add_sphere(p->s, sp, p->err);
    }
    /* an emitting ellipsoid, or a sphere that emits inwards: the kernels sample sphere
     * lights by their cone of directions, which neither has, so a mesh */
    if ((st = tessellation_budget(p, lx, type, SPHERE_MESH_TRIANGLES, "an emitting ellipsoid (or inward-emitting "
                                  "sphere) as a mesh")))
        return st;
    MeshSink k;
    size_t first = p->s->n_triangles;
    if ((st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err))) return st;
    if ((st = sphere_tessellate(p, &k, r, material))) return st;
    orient_triangles(p, first);
    return ST_OK;
}

/* pbrt's loopsubdiv: subdivided here to `levels` (default 3), limit positions, smooth
 * normals (scene/subdiv.h). Each level makes four triangles of one, so a 4 KB file asked
 * for 33 million triangles: levels stop at PBRT_MAX_SUBDIV_LEVELS and the triangles
 * count against the scene's tessellation budget (tessellation_budget). pbrt-v4 itself
 * has no bound; its scenes use levels up to about 5. */
#define PBRT_MAX_SUBDIV_LEVELS 10
static Status shape_loopsubdiv(Parser *p, const Lexer *lx, const Token *type, uint material)
{
    Param *P = param_find(p, "P"), *ix;
    if (!P) return lex_error_at(lx, type, p->err, "a loopsubdiv needs \"point3 P\"");
    if (P->type != PT_POINT3) return param_type_error(p, lx, P, "point3");
    size_t np = P->n / 3;
    long levels = 3;
    Status st = get_int(p, lx, "levels", &levels);
    if (st) return st;
    if (levels < 0 || levels > PBRT_MAX_SUBDIV_LEVELS)
        return lex_error_at(lx, type, p->err, "loopsubdiv level %ld is beyond %d (each level makes four "
                            "triangles of one: level %d makes 4^%d = %.0f of each)", levels, PBRT_MAX_SUBDIV_LEVELS,
                            (int)levels, (int)levels, pow(4.0, (double)levels));
    if ((st = get_indices(p, lx, "indices", 3, np, NULL, &ix))) return st;
    if (!ix) return lex_error_at(lx, type, p->err, "a loopsubdiv needs \"integer indices\"");
    size_t nt = ix->n / 3;
    /* nt 4^levels, saturated; counted before anything is allocated */
    size_t made = nt;
    for (long l = 0; l < levels; l++) made = made > SIZE_MAX / 4 ? SIZE_MAX : made * 4;
    char what[96];
    snprintf(what, sizeof what, "loopsubdiv to level %ld of %zu triangles", levels, nt);
    if ((st = tessellation_budget(p, lx, type, made, what))) return st;
    uint32_t *idx = malloc(ix->n * sizeof *idx + 1);
    if (!idx) return error_set(p->err, ST_INTERNAL, "out of memory");
    for (size_t i = 0; i < ix->n; i++) idx[i] = (uint32_t)p->pl.nums[ix->first + i];
    SubdivMesh m;
    st = subdiv_loop(p->pl.nums + P->first, np, idx, nt, (int)levels, CLPT_MAX_TESSELLATED_TRIANGLES, &m, p->err);
    free(idx);
    if (st == ST_INPUT) reader_annotate(lx, type, p->err);
    if (st) return st;
    MeshSink k;
    size_t first = p->s->n_triangles;
    if (!(st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err))) st = mesh_sink_reserve(&k, m.n_tris, m.n_tris);
    for (size_t f = 0; f < m.n_tris && !st; f++) {
        vec3 q[3], n[3];
        int has_n = 1;
        for (int c = 0; c < 3; c++) {
            const double *a = m.p + 3 * m.idx[3 * f + c], *b = m.n + 3 * m.idx[3 * f + c];
            q[c] = v3((float)a[0], (float)a[1], (float)a[2]);
            n[c] = v3((float)b[0], (float)b[1], (float)b[2]);
            has_n &= !v3_is_zero(n[c]);
        }
        st = mesh_sink_triangle(&k, q, has_n ? n : NULL, NULL, material);
    }
    subdiv_free(&m);
    if (!st) orient_triangles(p, first);
    return st;
}

/* pbrt's disk (height, radius, innerradius, phimax) and cylinder (radius, zmin, zmax,
 * phimax) as meshes: the kernels have neither primitive. A disk is flat, so one ring of
 * segments is exact but for the rim; a cylinder's side is ruled, so one band of quads.
 * The rim is a polygon of 64 segments per full turn (a 64-gon holds 99.8% of the
 * circle's area). The analytic normals (+z for a disk, outward for a cylinder) are the
 * shading normals, so orient_triangles puts each triangle on pbrt's side, and (u, v)
 * are pbrt's: u = phi / phimax, v from the outer rim in (disk) or from zmin up
 * (cylinder). Real scenes use disks as area lights (pbrt-v4-scenes' killeroos). */
static Status shape_disk_cylinder(Parser *p, const Lexer *lx, const Token *type, uint material, int cylinder)
{
    double radius = 1, inner = 0, height = 0, zmin = -1, zmax = 1, phimax = 360;
    Status st;
    if ((st = get_float(p, lx, "radius", &radius)) || (st = get_float(p, lx, "phimax", &phimax))) return st;
    if (cylinder ? (st = get_float(p, lx, "zmin", &zmin)) || (st = get_float(p, lx, "zmax", &zmax))
                 : (st = get_float(p, lx, "height", &height)) || (st = get_float(p, lx, "innerradius", &inner)))
        return st;
    if (!(radius > 0) || !isfinite(radius)) return param_type_error(p, lx, param_find(p, "radius"), "> 0 and finite");
    if (!(phimax > 0 && phimax <= 360)) return param_type_error(p, lx, param_find(p, "phimax"), "in (0, 360]");
    if (!cylinder && !(inner >= 0 && inner < radius))
        return param_type_error(p, lx, param_find(p, "innerradius"), "in [0, radius)");
    if (!isfinite(height) || !isfinite(zmin) || !isfinite(zmax))
        return lex_error_at(lx, type, p->err, "the %.*s's height or z range is not finite", (int)type->len, type->text);
    if (cylinder && zmin > zmax) {   /* pbrt takes them in either order */
        double t = zmin;
        zmin = zmax;
        zmax = t;
    }
    if (cylinder && !(zmax > zmin))
        return lex_error_at(lx, type, p->err, "the cylinder's zmin and zmax are equal: it has no side");
    int nseg = (int)ceil(64.0 * phimax / 360.0);
    if (nseg < 4) nseg = 4;
    double turn = phimax * M_PI / 180.0;
    MeshSink k;
    size_t first = p->s->n_triangles;
    if ((st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err)) ||
        (st = mesh_sink_reserve(&k, 2 * (size_t)nseg, 2 * (size_t)nseg)))
        return st;
    for (int i = 0; i < nseg && !st; i++) {
        double f0 = (double)i / nseg, f1 = (double)(i + 1) / nseg;
        float c0 = (float)cos(f0 * turn), s0 = (float)sin(f0 * turn), c1 = (float)cos(f1 * turn),
              s1 = (float)sin(f1 * turn);
        vec3 q[4], n[4];
        float uv[8];
        if (cylinder) {   /* corners: (phi0, zmin) (phi1, zmin) (phi0, zmax) (phi1, zmax) */
            float r = (float)radius;
            q[0] = v3(r * c0, r * s0, (float)zmin);
            q[1] = v3(r * c1, r * s1, (float)zmin);
            q[2] = v3(r * c0, r * s0, (float)zmax);
            q[3] = v3(r * c1, r * s1, (float)zmax);
            n[0] = n[2] = v3(c0, s0, 0.0f);
            n[1] = n[3] = v3(c1, s1, 0.0f);
        } else {          /* corners: outer phi0, outer phi1, inner phi0, inner phi1 */
            float ro = (float)radius, ri = (float)inner, z = (float)height;
            q[0] = v3(ro * c0, ro * s0, z);
            q[1] = v3(ro * c1, ro * s1, z);
            q[2] = v3(ri * c0, ri * s0, z);
            q[3] = v3(ri * c1, ri * s1, z);
            n[0] = n[1] = n[2] = n[3] = v3(0.0f, 0.0f, 1.0f);
        }
        const float v_lo = 0.0f, v_hi = 1.0f;   /* disk: outer rim v 0, inner 1; cylinder: zmin 0, zmax 1 */
        const float u[4] = { (float)f0, (float)f1, (float)f0, (float)f1 }, v[4] = { v_lo, v_lo, v_hi, v_hi };
        for (int c = 0; c < 4; c++) {
            uv[2 * c] = u[c];
            uv[2 * c + 1] = v[c];
        }
        vec3 a[3] = { q[0], q[1], q[3] }, an[3] = { n[0], n[1], n[3] };
        vec3 b[3] = { q[0], q[3], q[2] }, bn[3] = { n[0], n[3], n[2] };
        float auv[6] = { uv[0], uv[1], uv[2], uv[3], uv[6], uv[7] };
        float buv[6] = { uv[0], uv[1], uv[6], uv[7], uv[4], uv[5] };
        int disk_centre = !cylinder && inner == 0;   /* the inner corners meet: one triangle */
        if (disk_centre) {
            vec3 t[3] = { q[0], q[1], q[2] }, tn[3] = { n[0], n[1], n[2] };
            float tuv[6] = { uv[0], uv[1], uv[2], uv[3], uv[4], uv[5] };
            st = mesh_sink_triangle(&k, t, tn, tuv, material);
        } else {
            st = mesh_sink_triangle(&k, a, an, auv, material);
            if (!st) st = mesh_sink_triangle(&k, b, bn, buv, material);
        }
    }
    if (!st) orient_triangles(p, first);
    double reach = st ? 0.0 : scene_triangles_reach(p->s, first, p->s->n_triangles);
    if (reach > SCENE_MAX_COORDINATE)
        return lex_error_at(lx, type, p->err, "the %.*s reaches %g from the origin (radius %g, after the transform), "
                            "beyond the 2^62 (%g) single precision can intersect: scale the scene down",
                            (int)type->len, type->text, reach, radius, SCENE_MAX_COORDINATE);
    return st;
}

static Status shape_plymesh(Parser *p, const Lexer *lx, const Token *type, uint material)
{
    const Token *f = NULL;
    Status st = get_string(p, lx, "filename", &f);
    if (st) return st;
    if (!f) return lex_error_at(lx, type, p->err, "a plymesh needs \"string filename\"");
    char *path = beside_main(p, f);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    if (mesh_kind(path) != MESH_PLY) {
        free(path);
        return lex_expected(lx, f, "a PLY file name ending in .ply or .ply.gz", p->err);
    }
    MeshOptions o = mesh_options(material);
    o.xf = p->g.ctm;
    size_t first = p->s->n_triangles;
    st = mesh_load(path, p->s, &o, p->err);
    free(path);
    if (st == ST_IO) reader_annotate(lx, f, p->err);
    if (st) return st;
    orient_triangles(p, first);
    param_find(p, "displacement.edgelength");
    return ST_OK;
}

static Status d_shape(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token type;
    Status st = expect_string(p, lx, "a quoted shape type", &type);
    if (!st) st = parse_params(p, lx);
    if (st) return st;
    int known = tok_eq(&type, "sphere") || tok_eq(&type, "trianglemesh") || tok_eq(&type, "plymesh") ||
                tok_eq(&type, "bilinearmesh") || tok_eq(&type, "loopsubdiv") || tok_eq(&type, "disk") ||
                tok_eq(&type, "cylinder");
    if (!known) {
        char key[96];
        snprintf(key, sizeof key, "Shape %.*s", (int)(type.len > 40 ? 40 : type.len), type.text);
        return warn_once(p, lx, &type, key, "Shape \"%.*s\" is not supported; skipped",
                         (int)(type.len > 40 ? 40 : type.len), type.text);
    }
    uint material;
    if ((st = shape_material(p, &material))) return st;
    if (tok_eq(&type, "sphere")) {
        st = shape_sphere(p, lx, &type, material);
    } else if (tok_eq(&type, "plymesh")) {
        st = shape_plymesh(p, lx, &type, material);
    } else if (tok_eq(&type, "loopsubdiv")) {
        st = shape_loopsubdiv(p, lx, &type, material);
    } else if (tok_eq(&type, "disk") || tok_eq(&type, "cylinder")) {
        st = shape_disk_cylinder(p, lx, &type, material, tok_eq(&type, "cylinder"));
    } else {
        MeshSink k;
        size_t first = p->s->n_triangles;
        if ((st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err))) return st;
        st = shape_trianglemesh(p, lx, &type, &k, material, tok_eq(&type, "bilinearmesh"));
        if (!st) orient_triangles(p, first);
    }
    if (st) return st;
    param_find(p, "alpha");
    if (param_find(p, "alpha") && (st = warn_once(p, lx, &type, "alpha", "shape alpha (cut-outs) is not supported; ignored")))
        return st;
    return warn_unused(p, lx, "Shape");
}

/* ------------------------------------------------------------------ instancing */

/* Instances are flattened: ObjectEnd takes the object's shapes out of the scene and
 * each ObjectInstance appends them again, moved by the instance's transform. */
#define PBRT_MAX_FLAT_TRIANGLES ((size_t)1 << 26)

static Status d_object_begin(Parser *p, Lexer *lx, const Token *kw)
{
    Token name;
    Status st = expect_string(p, lx, "a quoted object name", &name);
    if (st) return st;
    if (p->in_object) return lex_error_at(lx, kw, p->err, "ObjectBegin inside another ObjectBegin");
    if ((st = push_state(p))) return st;
    p->in_object = 1;
    p->obj_stack = p->n_stack;
    p->obj_spheres = p->s->n_spheres;
    p->obj_sphere_xforms = p->s->n_sphere_xforms;
    p->obj_triangles = p->s->n_triangles;
    p->obj_shading = p->s->n_shading;
    free(p->obj_name_buf);
    p->obj_name_buf = tok_copy(&name);
    if (!p->obj_name_buf) return error_set(p->err, ST_INTERNAL, "out of memory");
    p->obj_name = name;
    p->obj_name.text = p->obj_name_buf;
    return ST_OK;
}

static Status d_object_end(Parser *p, Lexer *lx, const Token *kw)
{
    if (!p->in_object) return lex_error_at(lx, kw, p->err, "ObjectEnd without ObjectBegin");
    if (p->n_stack != p->obj_stack)
        return lex_error_at(lx, kw, p->err, "ObjectEnd inside an AttributeBegin of its object, or after one "
                            "that closes more than it opened");
    Scene *s = p->s;
    PObject o;
    memset(&o, 0, sizeof o);
    o.n_spheres = s->n_spheres - p->obj_spheres;
    o.n_triangles = s->n_triangles - p->obj_triangles;
    o.n_shading = s->n_shading - p->obj_shading;
    o.n_sphere_xforms = s->n_sphere_xforms - p->obj_sphere_xforms;
    o.sphere_xforms = malloc(o.n_sphere_xforms * sizeof *o.sphere_xforms + 1);
    if (!o.sphere_xforms) return error_set(p->err, ST_INTERNAL, "out of memory");
    if (o.n_sphere_xforms)
        memcpy(o.sphere_xforms, s->sphere_xforms + p->obj_sphere_xforms, o.n_sphere_xforms * sizeof *o.sphere_xforms);
    s->n_sphere_xforms = p->obj_sphere_xforms;
    o.spheres = malloc(o.n_spheres * sizeof *o.spheres + 1);
    o.triangles = malloc(o.n_triangles * sizeof *o.triangles + 1);
    o.shading = malloc(o.n_shading * sizeof *o.shading + 1);
    if (!o.spheres || !o.triangles || !o.shading ||
        grow((void **)&p->objects, &p->cap_objects, p->n_objects + 1, sizeof(PObject))) {
        free(o.spheres);
        free(o.sphere_xforms);
        free(o.triangles);
        free(o.shading);
        return error_set(p->err, ST_INTERNAL, "out of memory");
    }
    /* an object may hold no spheres (or no triangles), and the scene's array may then
     * still be NULL: C gives no NULL + 0, so the empty copies are skipped */
    if (o.n_spheres) memcpy(o.spheres, s->spheres + p->obj_spheres, o.n_spheres * sizeof *o.spheres);
    if (o.n_triangles) memcpy(o.triangles, s->triangles + p->obj_triangles, o.n_triangles * sizeof *o.triangles);
    if (o.n_shading) memcpy(o.shading, s->shading + p->obj_shading, o.n_shading * sizeof *o.shading);
    for (size_t i = 0; i < o.n_triangles; i++)
        if (o.triangles[i].shading != NO_INDEX) o.triangles[i].shading -= (uint)p->obj_shading;
    for (size_t i = 0; i < o.n_spheres; i++)
        if (o.spheres[i].xform) o.spheres[i].xform -= (uint)p->obj_sphere_xforms;
    s->n_spheres = p->obj_spheres;
    s->n_triangles = p->obj_triangles;
    s->n_shading = p->obj_shading;
    /* a name defined again replaces the earlier object, for the instances after it */
    if (strmap_set(&p->object_by_name, p->obj_name.text, p->obj_name.len, (uint32_t)p->n_objects)) {
        free(o.spheres);
        free(o.sphere_xforms);
        free(o.triangles);
        free(o.shading);
        return error_set(p->err, ST_INTERNAL, "out of memory");
    }
    p->objects[p->n_objects++] = o;
    p->in_object = 0;
    p->g = p->stack[--p->n_stack];
    return ST_OK;
}

/* An object's sphere sp under the instance's transform when either makes it an
 * ellipsoid: the unit sphere under ctm . (sp's own transform). Emitting ones are
 * skipped with a warning (their lights would need a mesh, made per instance). */
static Status instance_ellipsoid(Parser *p, const Lexer *lx, const Token *name, const PObject *o, const Sphere *sp)
{
    if (!v3_is_zero(p->s->materials[sp->material].emission))
        return warn_once(p, lx, name, "instance-sphere", "an emitting sphere in an instance whose transform is not a "
                         "similarity (an ellipsoid) is skipped");
    Transform own;
    if (sp->xform) {
        const float *m = o->sphere_xforms[sp->xform - 1u].to_world;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) own.m[i][j] = m[4 * i + j];
    } else {
        Transform t = transform_translate(sp->center.x, sp->center.y, sp->center.z),
                  sc = transform_scale(sp->radius, sp->radius, sp->radius);
        own = transform_compose(&t, &sc);
    }
    Transform m = transform_compose(&p->g.ctm, &own);
    Status st = scene_add_ellipsoid(p->s, &m, sp->material, p->err);
    if (st == ST_INPUT) error_prefix(p->err, "%s:%u:%u: the instanced sphere", lx->path, name->line, name->col);
    return st;
}

static Status d_object_instance(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token name;
    uint32_t i;
    Status st = expect_defined(p, lx, &p->object_by_name, "object", "ObjectBegin", &name, &i);
    if (st) return st;
    const PObject *o = &p->objects[i];
    if (p->s->n_triangles + o->n_triangles > PBRT_MAX_FLAT_TRIANGLES)
        return lex_error_at(lx, &name, p->err, "the flattened instances would hold more than %zu triangles",
                            PBRT_MAX_FLAT_TRIANGLES);
    MeshSink k;
    if ((st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err)) ||
        (st = mesh_sink_reserve(&k, o->n_triangles, o->n_shading)))
        return st;
    for (size_t t = 0; t < o->n_triangles && !st; t++) {
        const Triangle *tr = &o->triangles[t];
        const TriShading *sh = tr->shading != NO_INDEX ? &o->shading[tr->shading] : NULL;
        vec3 q[3] = { tr->p0, tr->p1, tr->p2 };
        vec3 n[3];
        float uv[6];
        int has_n = sh && (sh->flags & TRI_HAS_NORMALS), has_uv = sh && (sh->flags & TRI_HAS_UV);
        if (has_n) {
            n[0] = sh->n0;
            n[1] = sh->n1;
            n[2] = sh->n2;
        }
        if (has_uv) {
            const float u[6] = { sh->uv0[0], sh->uv0[1], sh->uv1[0], sh->uv1[1], sh->uv2[0], sh->uv2[1] };
            memcpy(uv, u, sizeof uv);
        }
        st = mesh_sink_triangle(&k, q, has_n ? n : NULL, has_uv ? uv : NULL, tr->material);
    }
    double scale;
    int similar = is_similarity(&p->g.ctm, &scale);
    for (size_t j = 0; j < o->n_spheres && !st; j++) {
        if (!similar || o->spheres[j].xform) {
            st = instance_ellipsoid(p, lx, &name, o, &o->spheres[j]);
            continue;
        }
        Sphere sp = o->spheres[j];
        sp.center = transform_point(&p->g.ctm, sp.center);
        sp.radius = (float)(sp.radius * scale);
        if (!(sp.radius > 0) || !isfinite(sp.radius) || !isfinite(fabsf(sp.center.x) + sp.radius) ||
            !isfinite(fabsf(sp.center.y) + sp.radius) || !isfinite(fabsf(sp.center.z) + sp.radius))
            return lex_error_at(lx, &name, p->err, "the instanced sphere reaches beyond the largest float");
        st = scene_add_sphere(p->s, sp, p->err);
    }
    return st;
}

/* ------------------------------------------------------------------ files */

static Status parse_file(Parser *p, const char *path, const char *text, size_t len);

static Status d_include(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st = expect_string(p, lx, "a quoted file name", &t);
    if (st) return st;
    if (p->depth + 1 >= CLPT_MAX_INCLUDE_DEPTH) {
        p->depth_exceeded = 1;
        return lex_error_at(lx, kw, p->err, "includes nested more than %d deep (does a file include itself?)",
                            CLPT_MAX_INCLUDE_DEPTH);
    }
    char *path = beside_main(p, &t);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    /* the included file has a lexer of its own: nothing is pushed back across files */
    p->depth++;
    st = parse_file(p, path, NULL, 0);
    p->depth--;
    free(path);
    if (st != ST_IO && p->depth_exceeded) return st;
    return reader_note_nested(lx, &t, kw, "included from", st, p->err);
}

/* A directive clpt does not support: its arguments and parameters are skipped. */
static Status d_unsupported(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st;
    for (;;) {
        if ((st = lex_next(lx, &t, p->err))) return st;
        double d;
        int arg = t.kind == TOK_STRING || t.kind == TOK_LBRACKET || t.kind == TOK_RBRACKET ||
                  (t.kind == TOK_WORD && (tok_double(&t, &d) == 0 || tok_is_bool(&t)));
        if (!arg) break;
    }
    lex_unread(lx, &t);
    char key[64];
    snprintf(key, sizeof key, "%.*s", (int)(kw->len > 40 ? 40 : kw->len), kw->text);
    return warn_once(p, lx, kw, key, "%s is not supported; ignored", key);
}

/* ActiveTransform StartTime | EndTime | All (a bare word, not a string). clpt has no
 * motion blur: it renders the shutter-open pose, so a transform directive given while
 * only EndTime is active leaves the transform as it is. AttributeBegin/End keep the
 * setting with the rest of the graphics state, as pbrt-v4's does. */
static Status d_active_transform(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    if (t.kind == TOK_WORD && tok_eq(&t, "StartTime"))
        p->g.end_time_only = 0;
    else if (t.kind == TOK_WORD && tok_eq(&t, "All"))
        p->g.end_time_only = 0;
    else if (t.kind == TOK_WORD && tok_eq(&t, "EndTime"))
        p->g.end_time_only = 1;
    else
        return lex_expected(lx, &t, "StartTime, EndTime or All (ActiveTransform)", p->err);
    return warn_once(p, lx, kw, "ActiveTransform",
                     "ActiveTransform: motion blur is not supported; the StartTime (shutter-open) transform is used");
}

static int is_transform_directive(Status (*fn)(Parser *, Lexer *, const Token *));

static Status d_ignored(Parser *p, Lexer *lx, const Token *kw)
{
    (void)p; (void)lx; (void)kw;
    return ST_OK;
}

static const struct {
    const char *name;
    Status (*fn)(Parser *p, Lexer *lx, const Token *kw);
} directives[] = {
    {"Translate", d_xform},
    {"Scale", d_xform},
    {"Rotate", d_xform},
    {"LookAt", d_xform},
    {"Transform", d_xform},
    {"ConcatTransform", d_xform},
    {"CoordinateSystem", d_coordsys},
    {"CoordSysTransform", d_coordsys_transform},
    {"Identity", d_identity},
    {"ReverseOrientation", d_reverse},
    {"AttributeBegin", d_attr_begin},
    {"AttributeEnd", d_attr_end},
    {"TransformBegin", d_attr_begin},
    {"TransformEnd", d_transform_end},
    {"WorldBegin", d_world_begin},
    {"WorldEnd", d_ignored},        /* pbrt-v3's end of file */
    {"Camera", d_camera},
    {"Film", d_film},
    {"Sampler", d_sampler},
    {"Integrator", d_integrator},
    {"Material", d_material},
    {"MakeNamedMaterial", d_make_named_material},
    {"NamedMaterial", d_named_material},
    {"Texture", d_texture},
    {"AreaLightSource", d_area_light},
    {"LightSource", d_light},
    {"Shape", d_shape},
    {"Include", d_include},
    {"Import", d_include},
    {"PixelFilter", d_unsupported},
    {"ColorSpace", d_unsupported},
    {"Option", d_unsupported},
    {"Accelerator", d_unsupported},
    {"TransformTimes", d_unsupported},
    {"ActiveTransform", d_active_transform},
    {"MakeNamedMedium", d_unsupported},
    {"MediumInterface", d_unsupported},
    {"Attribute", d_unsupported},
    {"ObjectBegin", d_object_begin},
    {"ObjectEnd", d_object_end},
    {"ObjectInstance", d_object_instance},
};
#define N_DIRECTIVES (sizeof directives / sizeof directives[0])

static size_t directive_index(const Token *t)
{
    if (t->kind != TOK_WORD) return N_DIRECTIVES;
    for (size_t i = 0; i < N_DIRECTIVES; i++)
        if (tok_eq(t, directives[i].name)) return i;
    return N_DIRECTIVES;
}

static Status parse_statements(Parser *p, Lexer *lx)
{
    Status st;
    for (;;) {
        Token t;
        if ((st = lex_next(lx, &t, p->err)) || t.kind == TOK_EOF) break;
        size_t i = directive_index(&t);
        if (i == N_DIRECTIVES) {
            st = lex_expected(lx, &t, "a pbrt directive (Shape, Material, LightSource, AttributeBegin, ...)", p->err);
            break;
        }
        if (p->world && (directives[i].fn == d_camera || directives[i].fn == d_film ||
                         directives[i].fn == d_sampler || directives[i].fn == d_integrator)) {
            st = lex_error_at(lx, &t, p->err, "%s must come before WorldBegin", directives[i].name);
            break;
        }
        Transform before = p->g.ctm;
        if ((st = directives[i].fn(p, lx, &t))) break;
        if (p->g.end_time_only && is_transform_directive(directives[i].fn)) p->g.ctm = before;
    }
    return st;
}

/* the directives that change the current transform (ActiveTransform EndTime skips them) */
static int is_transform_directive(Status (*fn)(Parser *, Lexer *, const Token *))
{
    return fn == d_xform || fn == d_coordsys_transform || fn == d_identity;
}

static Status parse_file(Parser *p, const char *path, const char *text, size_t len)
{
    Lexer lx;
    Status st = text ? lex_open_text(&lx, path, text, len, p->err) : lex_open_file(&lx, path, p->err);
    if (st) return st;
    st = parse_statements(p, &lx);
    lex_close(&lx);
    return st;
}

/* ------------------------------------------------------------------ the camera */

/* pbrt's camera at cam_from_world looks down its +z with +y up and +x to the image's
 * right; its field of view spans the shorter image side. */
static Status finish_camera(Parser *p)
{
    SceneCamera *c = &p->s->camera;
    if (!p->have_camera) {
        /* pbrt's default: at the origin looking down +z, fov 90 */
        p->cam_from_world = transform_identity();
        p->fov = 90;
        p->lens_radius = 0;
        p->focal_distance = 1e6;
    }
    int ok;
    Transform w = transform_inverse(&p->cam_from_world, &ok);
    if (!ok) return error_set(p->err, ST_INPUT, "%s: the camera transform is singular", p->top_path);
    vec3 o = transform_point(&w, v3(0, 0, 0));
    vec3 f = xf_dir(&w, v3(0, 0, 1)), u = xf_dir(&w, v3(0, 1, 0)), r = xf_dir(&w, v3(1, 0, 0));
    float fl = sqrtf(v3_dot(f, f));
    c->from = o;
    c->at = v3_add(o, v3_scale(f, 1.0f / fl));
    c->up = u;
    /* clpt's image right is forward x up; pbrt's is the camera's +x */
    vec3 fu = v3(f.y * u.z - f.z * u.y, f.z * u.x - f.x * u.z, f.x * u.y - f.y * u.x);
    c->mirror_x = v3_dot(fu, r) < 0;
    double w_px = p->s->image.width, h_px = p->s->image.height;
    double aspect = w_px / h_px;
    if (p->cam_ortho) {
        c->type = CAMERA_ORTHOGRAPHIC;
        /* the screen window is [-1, 1] on the shorter side */
        c->ortho_height = (float)(aspect >= 1 ? 2.0 : 2.0 / aspect);
        return ST_OK;
    }
    c->type = CAMERA_PERSPECTIVE;
    double half = tan(p->fov * M_PI / 360.0);
    c->vfov = (float)(aspect >= 1 ? p->fov : 360.0 / M_PI * atan(half / aspect));
    c->aperture = (float)(2 * p->lens_radius);
    c->focus_dist = p->lens_radius > 0 ? (float)p->focal_distance : 0.0f;
    return ST_OK;
}

/* ------------------------------------------------------------------ entry points */

int pbrt_detect(const char *text, size_t len)
{
    size_t i = 0;
    for (;;) {
        while (i < len && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r' || text[i] == '\n')) i++;
        if (i < len && text[i] == '#') {
            while (i < len && text[i] != '\n') i++;
            continue;
        }
        break;
    }
    size_t s = i;
    while (i < len && ((text[i] >= 'A' && text[i] <= 'Z') || (text[i] >= 'a' && text[i] <= 'z'))) i++;
    Token t = {TOK_WORD, text + s, i - s, 1, 1};
    return i > s && directive_index(&t) < N_DIRECTIVES;
}

Status pbrt_load_text(const char *path, const char *text, size_t len, Scene *s, Error *err)
{
    free(s->path);
    size_t n = strlen(path);
    s->path = malloc(n + 1);
    if (!s->path) return error_set(err, ST_INTERNAL, "out of memory");
    memcpy(s->path, path, n + 1);
    Parser p;
    memset(&p, 0, sizeof p);
    p.s = s;
    p.err = err;
    p.top_path = path;
    p.g.ctm = transform_identity();
    p.g.material = NO_INDEX;
    p.g.area_material = NO_INDEX;
    /* pbrt-v4's defaults where clpt's differ */
    s->image.width = 1280;
    s->image.height = 720;
    s->image.spp = 16;
    s->image.max_depth = 5;
    Status st = parse_file(&p, path, text, len);
    if (!st && p.in_object) st = error_set(err, ST_INPUT, "%s: ObjectBegin \"%s\" has no ObjectEnd", path, p.obj_name_buf);
    for (size_t i = 0; !st && i < p.n_pending; i++)
        if (!p.pending[i].defined)
            st = error_set(err, ST_INPUT, "%s is used by NamedMaterial and never defined (MakeNamedMaterial defines it)",
                           p.pending[i].where);
    if (!st) st = finish_camera(&p);
    if (!st) st = scene_check_precision(s, err);
    free(p.stack);
    free(p.pending);
    free(p.area_of_pending);
    free(p.coordsys_xf);
    free(p.tex);
    free(p.pl.p);
    free(p.pl.nums);
    free(p.pl.strs);
    strmap_free(&p.named_material);
    strmap_free(&p.coordsys);
    strmap_free(&p.tex_by_name);
    strmap_free(&p.warned);
    strmap_free(&p.object_by_name);
    for (size_t i = 0; i < p.n_objects; i++) {
        free(p.objects[i].spheres);
        free(p.objects[i].sphere_xforms);
        free(p.objects[i].triangles);
        free(p.objects[i].shading);
    }
    free(p.objects);
    free(p.obj_name_buf);
    return st;
}
