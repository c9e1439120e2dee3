/*
 * classic_parse.c — the scene format of MIT 6.837 and the courses derived from it
 * (docs/classic-format.md), read with the tokenizer of our own format (host/io/lexer.c).
 *
 * The course's parsers read fields in a fixed order and assert on anything else; this
 * reader takes a block's fields in any order, gives the format's defaults to the ones
 * left out, and reports every mistake with file:line:column. Transforms are applied
 * while reading: the kernels only know world-space spheres, planes, triangles and
 * surfaces of revolution about vertical axes, so a transformed sphere stays a sphere
 * when the transform keeps it round (and unrotated, if it is textured), a surface of
 * revolution stays one when its axis stays upright, and either becomes a fine triangle
 * mesh otherwise.
 */
#include "io/classic_parse.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kmath.h"
#include "base/limit.h"
#include "io/lexer.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/obj.h"
#include "scene/curve.h"
#include "scene/transform.h"
#include "io/texture.h"

/* The tessellation of a sphere that a transform makes an ellipsoid (or rotates, when
 * it is textured): latitude bands x longitude segments. */
#define SPHERE_BANDS 48
#define SPHERE_SEGMENTS 96

/* The mesh of a surface of revolution that a transform tilts off the vertical: rows per
 * profile segment x columns around the axis. */
#define REV_MESH_STEPS 16
#define REV_MESH_AROUND 96

/* ------------------------------------------------------------------ transforms */

/* n carried by transform_normal_matrix's matrix and made unit length (0 0 0 if it vanishes). */
static vec3 normal_apply(double n[3][3], vec3 v)
{
    double x = n[0][0] * v.x + n[0][1] * v.y + n[0][2] * v.z;
    double y = n[1][0] * v.x + n[1][1] * v.y + n[1][2] * v.z;
    double z = n[2][0] * v.x + n[2][1] * v.y + n[2][2] * v.z;
    double len = sqrt(x * x + y * y + z * z);
    if (!(len > 0.0) || !isfinite(len)) return v3(0.0f, 0.0f, 0.0f);
    return v3((float)(x / len), (float)(y / len), (float)(z / len));
}

/* Whether the linear part is s times an orthogonal matrix (a sphere stays a sphere of
 * radius s*r); *rotates tells whether that orthogonal matrix is not the identity. */
static int similarity(const Transform *m, double *s, int *rotates)
{
    const double (*a)[4] = m->m;
    double g[3][3], trace = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            g[i][j] = a[0][i] * a[0][j] + a[1][i] * a[1][j] + a[2][i] * a[2][j];
            if (i == j) trace += g[i][j];
        }
    double s2 = trace / 3.0;
    if (!(s2 > 0.0) || !isfinite(s2)) return 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (fabs(g[i][j] - (i == j ? s2 : 0.0)) > 1e-6 * s2) return 0;
    *s = sqrt(s2);
    *rotates = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (fabs(a[i][j] / *s - (i == j ? 1.0 : 0.0)) > 1e-6) *rotates = 1;
    return 1;
}

/* ------------------------------------------------------------------ the reader */

typedef struct {
    Scene *s;
    Lexer lx;
    Error *err;
    uint first_material;       /* scene index of the classic material 0 */
    uint n_materials;          /* classic materials defined so far */
    uint current;              /* scene material of new objects (MaterialIndex) */
    uint fallback;             /* white material for objects before any material */
    int seen_camera, seen_lights, seen_background, seen_materials;
    int ambient_given;
    int camera_sized;      /* the camera gave width/height: Tsinghua's dialect */
    int keys_2004;         /* a material gave a key only MIT 2004 has (reflectiveColor,
                            * transparentColor, indexOfRefraction, exponent) */
    size_t tessellated;        /* triangles made from spheres so far */
    uint depth;                /* Group and Transform blocks open around the reader */
} Classic;

static Status next(Classic *c, Token *t) { return lex_next(&c->lx, t, c->err); }
static Status expected(Classic *c, const Token *t, const char *what) { return lex_expected(&c->lx, t, what, c->err); }

static Status expect_brace(Classic *c, TokenKind kind, const char *what)
{
    Token t;
    Status st = next(c, &t);
    if (st) return st;
    if (t.kind != kind) return expected(c, &t, what);
    return ST_OK;
}

static Status read_float(Classic *c, float *out, Token *where, const char *what)
{
    Token t;
    Status st = next(c, &t);
    if (st) return st;
    if (where) *where = t;
    if (tok_float(&t, out)) return expected(c, &t, what);
    return ST_OK;
}

/* Field kinds: what a value must be. */
typedef enum {
    CK_VEC3,        /* three numbers */
    CK_COLOR,       /* three numbers >= 0 */
    CK_DIR,         /* three numbers, not all 0 */
    CK_NUMBER,      /* a number >= 0 */
    CK_ANY,         /* any number */
    CK_POSITIVE,    /* a number > 0 */
    CK_COUNT,       /* a whole number 1..16384 */
    CK_PATH         /* a file name: a word or a string */
} ClassicKind;

typedef struct {
    const char *key;
    ClassicKind kind;
    int required;
} ClassicKey;

typedef struct {
    int given;
    Token key;
    vec3 v;
    float f;
    unsigned long long u;
    Token word;
} ClassicValue;

static Status read_value(Classic *c, const ClassicKey *k, ClassicValue *v)
{
    static const char *const what[] = {
        [CK_VEC3] = "3 numbers", [CK_COLOR] = "3 numbers >= 0 (a colour)",
        [CK_DIR] = "a non-zero vector (3 numbers)", [CK_NUMBER] = "a number >= 0",
        [CK_ANY] = "a number", [CK_POSITIVE] = "a number > 0",
        [CK_COUNT] = "a whole number in 1..16384", [CK_PATH] = "a file name",
    };
    char msg[128];
    snprintf(msg, sizeof msg, "%s for '%s'", what[k->kind], k->key);
    Token t;
    Status st;
    switch (k->kind) {
    case CK_VEC3:
    case CK_COLOR:
    case CK_DIR: {
        float x[3];
        Token first;
        for (int i = 0; i < 3; i++) {
            if ((st = read_float(c, &x[i], &t, msg))) return st;
            if (i == 0) first = t;
            if (k->kind == CK_COLOR && x[i] < 0.0f) return expected(c, &t, msg);
        }
        v->v = v3(x[0], x[1], x[2]);
        if (k->kind == CK_DIR && v3_is_zero(v->v))
            return lex_error_at(&c->lx, &first, c->err, "expected %s, found 0 0 0", msg);
        return ST_OK;
    }
    case CK_NUMBER:
    case CK_ANY:
    case CK_POSITIVE:
        if ((st = read_float(c, &v->f, &t, msg))) return st;
        if ((k->kind == CK_NUMBER && v->f < 0.0f) || (k->kind == CK_POSITIVE && !(v->f > 0.0f)))
            return expected(c, &t, msg);
        return ST_OK;
    case CK_COUNT:
        if ((st = next(c, &t))) return st;
        if (tok_uint(&t, &v->u) || v->u < 1 || v->u > 16384) return expected(c, &t, msg);
        return ST_OK;
    case CK_PATH:
        if ((st = next(c, &t))) return st;
        if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0) return expected(c, &t, msg);
        v->word = t;
        return ST_OK;
    }
    return error_set(c->err, ST_INTERNAL, "unhandled field kind");
}

/* Reads `{ key value ... }` for block `block` (opened by keyword kw) against keys[]:
 * any order, each key at most once, the required ones checked at the end. */
static Status read_block(Classic *c, const Token *kw, const char *block, const ClassicKey *keys, size_t n,
                         ClassicValue *vals)
{
    memset(vals, 0, n * sizeof *vals);
    char what[300];
    Status st = ST_OK;
    snprintf(what, sizeof what, "'{' to open the %s block", block);
    if ((st = expect_brace(c, TOK_LBRACE, what))) return st;
    for (;;) {
        Token t;
        if ((st = next(c, &t))) return st;
        if (t.kind == TOK_RBRACE) break;
        size_t i = n;
        if (t.kind == TOK_WORD)
            for (i = 0; i < n; i++)
                if (tok_is(&t, keys[i].key)) break;
        if (i == n) {
            size_t o = (size_t)snprintf(what, sizeof what, "a %s field (", block);
            for (size_t j = 0; j < n && o < sizeof what; j++)
                o += (size_t)snprintf(what + o, sizeof what - o, "%s%s", j ? ", " : "", keys[j].key);
            if (o < sizeof what) snprintf(what + o, sizeof what - o, ") or '}'");
            if (t.kind == TOK_EOF)
                return lex_error_at(&c->lx, &t, c->err, "expected '}' to close the %s block opened at line %u, "
                                    "found end of file", block, kw->line);
            return expected(c, &t, what);
        }
        if (vals[i].given)
            return lex_error_at(&c->lx, &t, c->err, "'%s' repeated in the %s block (first given at %u:%u)",
                                keys[i].key, block, vals[i].key.line, vals[i].key.col);
        vals[i].given = 1;
        vals[i].key = t;
        if ((st = read_value(c, &keys[i], &vals[i]))) return st;
    }
    for (size_t i = 0; i < n; i++)
        if (keys[i].required && !vals[i].given)
            return lex_error_at(&c->lx, kw, c->err, "the %s block needs '%s'", block, keys[i].key);
    return ST_OK;
}

/* Two alternative spellings of one field (shininess/exponent, falloff/attenuation). */
static Status only_one(Classic *c, const ClassicValue *a, const ClassicValue *b, const char *block)
{
    if (!a->given || !b->given) return ST_OK;
    const ClassicValue *later = a->key.line > b->key.line ||
                                (a->key.line == b->key.line && a->key.col > b->key.col) ? a : b;
    const ClassicValue *first = later == a ? b : a;
    return lex_error_at(&c->lx, &later->key, c->err, "a %s block takes '%.*s' or '%.*s', not both", block,
                        (int)first->key.len, first->key.text, (int)later->key.len, later->key.text);
}

/* `KEY N` with N a whole number (numLights, numMaterials, numObjects). */
static Status read_count(Classic *c, const char *key, unsigned long long *n)
{
    Token t;
    Status st = next(c, &t);
    if (st) return st;
    char what[64];
    snprintf(what, sizeof what, "'%s'", key);
    if (!tok_is(&t, key)) return expected(c, &t, what);
    if ((st = next(c, &t))) return st;
    snprintf(what, sizeof what, "a whole number for '%s'", key);
    if (tok_uint(&t, n) || *n > 100000000ull) return expected(c, &t, what);
    return ST_OK;
}

/* A file named in the scene: beside the scene file, else from the current folder
 * (course scenes are written to be run from the course's code folder; io/path.h). */
static Status resolve_path(Classic *c, const Token *t, char **out)
{
    int r = path_resolve(c->lx.path, t->text, t->len, PATH_BESIDE_OR_CWD, out);
    if (r == PATH_OK) return ST_OK;
    if (r == PATH_NO_MEMORY) return error_set(c->err, ST_INTERNAL, "out of memory");
    char *beside = *out;
    *out = NULL;
    Status st = error_set(c->err, ST_IO, "%s:%u:%u: cannot open '%.*s': neither '%s' (beside the scene) nor "
                          "'%.*s' (from the current folder) exists", c->lx.path, t->line, t->col, (int)t->len,
                          t->text, beside, (int)t->len, t->text);
    free(beside);
    return st;
}

/* ------------------------------------------------------------------ camera, lights */

enum { CAM_CENTER, CAM_DIRECTION, CAM_LOOKAT, CAM_UP, CAM_ANGLE, CAM_SIZE, CAM_WIDTH, CAM_HEIGHT, CAM_N };
static const ClassicKey camera_keys[CAM_N] = {
    [CAM_CENTER] = {"center", CK_VEC3, 1},     [CAM_DIRECTION] = {"direction", CK_DIR, 0},
    [CAM_LOOKAT] = {"lookat", CK_VEC3, 0},     [CAM_UP] = {"up", CK_DIR, 1},
    [CAM_ANGLE] = {"angle", CK_POSITIVE, 0},   [CAM_SIZE] = {"size", CK_POSITIVE, 0},
    [CAM_WIDTH] = {"width", CK_COUNT, 0},      [CAM_HEIGHT] = {"height", CK_COUNT, 0},
};

static Status parse_camera(Classic *c, const Token *kw, int ortho)
{
    if (c->seen_camera) return lex_error_at(&c->lx, kw, c->err, "a second camera (a scene has one)");
    c->seen_camera = 1;
    ClassicValue v[CAM_N];
    const char *block = ortho ? "OrthographicCamera" : "PerspectiveCamera";
    Status st = read_block(c, kw, block, camera_keys, CAM_N, v);
    if (st) return st;
    int bad = ortho ? CAM_ANGLE : CAM_SIZE, need = ortho ? CAM_SIZE : CAM_ANGLE;
    if (v[bad].given)
        return lex_error_at(&c->lx, &v[bad].key, c->err, "'%s' belongs to the %s; a %s has '%s'",
                            camera_keys[bad].key, ortho ? "PerspectiveCamera" : "OrthographicCamera", block,
                            camera_keys[need].key);
    if (!v[need].given) return lex_error_at(&c->lx, kw, c->err, "the %s block needs '%s'", block, camera_keys[need].key);
    if ((st = only_one(c, &v[CAM_DIRECTION], &v[CAM_LOOKAT], block))) return st;
    if (!v[CAM_DIRECTION].given && !v[CAM_LOOKAT].given)
        return lex_error_at(&c->lx, kw, c->err, "the %s block needs 'direction' (or 'lookat')", block);
    if (!ortho && !(v[CAM_ANGLE].f < 180.0f))
        return lex_error_at(&c->lx, &v[CAM_ANGLE].key, c->err, "'angle' is the field of view in degrees, "
                            "in (0, 180); found %g", (double)v[CAM_ANGLE].f);
    SceneCamera *cam = &c->s->camera;
    cam->from = v[CAM_CENTER].v;
    vec3 dir = v[CAM_DIRECTION].given ? v[CAM_DIRECTION].v : v3_sub(v[CAM_LOOKAT].v, cam->from);
    const Token *dir_key = v[CAM_DIRECTION].given ? &v[CAM_DIRECTION].key : &v[CAM_LOOKAT].key;
    double dl = sqrt((double)dir.x * dir.x + (double)dir.y * dir.y + (double)dir.z * dir.z);
    if (!(dl > 0.0) || !isfinite(dl))
        return lex_error_at(&c->lx, dir_key, c->err, "the view direction is zero or not finite");
    cam->at = v3_add(cam->from, v3((float)(dir.x / dl), (float)(dir.y / dl), (float)(dir.z / dl)));
    cam->up = v[CAM_UP].v;
    vec3 cr = v3_cross(v3_sub(cam->at, cam->from), cam->up);
    double crl = sqrt((double)cr.x * cr.x + (double)cr.y * cr.y + (double)cr.z * cr.z);
    double ul = sqrt((double)cam->up.x * cam->up.x + (double)cam->up.y * cam->up.y + (double)cam->up.z * cam->up.z);
    if (!(crl > 1e-6 * ul))
        return lex_error_at(&c->lx, &v[CAM_UP].key, c->err, "'up' is parallel to the view direction");
    cam->type = ortho ? CAMERA_ORTHOGRAPHIC : CAMERA_PERSPECTIVE;
    if (ortho) cam->ortho_height = v[CAM_SIZE].f;
    else cam->vfov = v[CAM_ANGLE].f;
    /* a camera with width/height is Tsinghua's, which re-orthogonalises `up` as MIT's
     * 2004 edition did; without them it is MIT Fall 2019's, which spans the image with
     * `up` as given (docs/classic-format.md, "Conventions") */
    c->camera_sized = v[CAM_WIDTH].given || v[CAM_HEIGHT].given;
    cam->course_basis = !ortho && !c->camera_sized;
    cam->aperture = 0.0f;
    if (v[CAM_WIDTH].given) c->s->image.width = (uint)v[CAM_WIDTH].u;
    if (v[CAM_HEIGHT].given) c->s->image.height = (uint)v[CAM_HEIGHT].u;
    return ST_OK;
}

/* A classic light of colour col shines kd * col * cos on a diffuse surface; the
 * kernels' lights are radiometric (kd / pi x intensity x cos), so intensity = pi col. */
static vec3 classic_intensity(vec3 col) { return v3_scale(col, (float)M_PI); }

enum { L_POSITION, L_DIRECTION, L_COLOR, L_FALLOFF, L_ATTEN, L_ANGLE, L_INNER, L_N };
static const ClassicKey light_keys[L_N] = {
    [L_POSITION] = {"position", CK_VEC3, 0}, [L_DIRECTION] = {"direction", CK_DIR, 0},
    [L_COLOR] = {"color", CK_COLOR, 1},      [L_FALLOFF] = {"falloff", CK_NUMBER, 0},
    [L_ATTEN] = {"attenuation", CK_COLOR, 0}, [L_ANGLE] = {"angle", CK_POSITIVE, 0},
    [L_INNER] = {"innerAngle", CK_NUMBER, 0},
};

static Status parse_light(Classic *c, const Token *kw)
{
    uint type;
    unsigned allowed, required;
    const char *block;
    if (tok_is(kw, "DirectionalLight")) {
        type = LIGHT_DIRECTIONAL;
        block = "DirectionalLight";
        allowed = 1u << L_DIRECTION | 1u << L_COLOR;
        required = 1u << L_DIRECTION;
    } else if (tok_is(kw, "PointLight")) {
        type = LIGHT_POINT;
        block = "PointLight";
        allowed = 1u << L_POSITION | 1u << L_COLOR | 1u << L_FALLOFF | 1u << L_ATTEN;
        required = 1u << L_POSITION;
    } else if (tok_is(kw, "SpotLight")) {
        type = LIGHT_SPOT;
        block = "SpotLight";
        allowed = 1u << L_POSITION | 1u << L_DIRECTION | 1u << L_COLOR | 1u << L_FALLOFF | 1u << L_ATTEN |
                  1u << L_ANGLE | 1u << L_INNER;
        required = 1u << L_POSITION | 1u << L_DIRECTION | 1u << L_ANGLE;
    } else {
        return expected(c, kw, "a light (DirectionalLight, PointLight, SpotLight)");
    }
    ClassicKey keys[L_N];
    ClassicValue v[L_N];
    size_t idx[L_N], n = 0;
    for (size_t i = 0; i < L_N; i++)
        if (allowed & (1u << i)) {
            keys[n] = light_keys[i];
            keys[n].required = (required & (1u << i)) != 0 || i == L_COLOR;
            idx[n++] = i;
        }
    ClassicValue got[L_N];
    Status st = read_block(c, kw, block, keys, n, got);
    if (st) return st;
    memset(v, 0, sizeof v);
    for (size_t i = 0; i < n; i++) v[idx[i]] = got[i];
    if ((st = only_one(c, &v[L_FALLOFF], &v[L_ATTEN], block))) return st;
    Light l = light_default(type);
    l.intensity = classic_intensity(v[L_COLOR].v);
    /* no falloff unless asked: the course's point lights shine equally at any distance */
    l.atten0 = 1.0f;
    l.atten1 = 0.0f;
    l.atten2 = 0.0f;
    /* `falloff F` is MIT 6.837 Fall 2019's keyword, whose PointLight shines
     * color / (F d^2) (its starter code's Light.cpp); F = 0 would divide by zero there,
     * so it means no falloff here (docs/classic-format.md, "Conventions") */
    if (v[L_FALLOFF].given && v[L_FALLOFF].f > 0.0f) {
        l.atten0 = 0.0f;
        l.atten2 = v[L_FALLOFF].f;
    }
    if (v[L_ATTEN].given) {
        l.atten0 = v[L_ATTEN].v.x;
        l.atten1 = v[L_ATTEN].v.y;
        l.atten2 = v[L_ATTEN].v.z;
        if (v3_is_zero(v[L_ATTEN].v))
            return lex_error_at(&c->lx, &v[L_ATTEN].key, c->err,
                                "'attenuation' is constant linear quadratic, not all 0");
    }
    if (v[L_POSITION].given) l.position = v[L_POSITION].v;
    if (v[L_DIRECTION].given) l.direction = v3_norm(v[L_DIRECTION].v);
    if (type == LIGHT_SPOT) {
        float outer = v[L_ANGLE].f, inner = v[L_INNER].given ? v[L_INNER].f : outer;
        if (!(outer < 180.0f))
            return lex_error_at(&c->lx, &v[L_ANGLE].key, c->err, "'angle' (the cone's half-angle, degrees) "
                                "must be below 180");
        if (inner > outer)
            return lex_error_at(&c->lx, &v[L_INNER].key, c->err, "'innerAngle' must not exceed 'angle'");
        l.cos_outer = (float)cos((double)outer * M_PI / 180.0);
        l.cos_inner = (float)cos((double)inner * M_PI / 180.0);
    }
    return scene_add_light(c->s, l, c->err);
}

static Status parse_lights(Classic *c, const Token *kw)
{
    if (c->seen_lights) return lex_error_at(&c->lx, kw, c->err, "a second Lights block");
    c->seen_lights = 1;
    Status st = expect_brace(c, TOK_LBRACE, "'{' to open the Lights block");
    unsigned long long n;
    if (st || (st = read_count(c, "numLights", &n))) return st;
    for (unsigned long long i = 0;; i++) {
        Token t;
        if ((st = next(c, &t))) return st;
        if (t.kind == TOK_RBRACE && i == n) return ST_OK;
        if (t.kind == TOK_EOF)
            return lex_error_at(&c->lx, &t, c->err, "expected '}' to close the Lights block opened at line %u, "
                                "found end of file", kw->line);
        if (t.kind == TOK_RBRACE)
            return lex_error_at(&c->lx, &t, c->err, "the Lights block at line %u declares numLights %llu "
                                "but has %llu", kw->line, n, i);
        if (i == n) {
            char what[96];
            snprintf(what, sizeof what, "'}' closing the Lights block (numLights %llu)", n);
            return expected(c, &t, what);
        }
        if ((st = parse_light(c, &t))) return st;
    }
}

enum { BG_COLOR, BG_AMBIENT, BG_CUBE, BG_N };
static const ClassicKey background_keys[BG_N] = {
    [BG_COLOR] = {"color", CK_COLOR, 0}, [BG_AMBIENT] = {"ambientLight", CK_COLOR, 0},
    [BG_CUBE] = {"cubeMap", CK_PATH, 0},
};

/* `cubeMap DIR`: escaping rays see the six images of DIR (the course's getBackgroundColor
 * returns the cube map's texel when there is one, whatever the colour says). */
static Status parse_cubemap(Classic *c, const Token *word)
{
    char *path;
    Status st = resolve_path(c, word, &path);
    if (st) return st;
    uint first;
    st = texture_load_cubemap(c->s, path, &first, c->err);
    free(path);
    if (st) {
        if (st == ST_IO || st == ST_INPUT) reader_annotate(&c->lx, word, c->err);
        return st;
    }
    c->s->bg_type = BG_CUBEMAP;
    c->s->bg_cubemap = first;
    return ST_OK;
}

static Status parse_background(Classic *c, const Token *kw)
{
    if (c->seen_background) return lex_error_at(&c->lx, kw, c->err, "a second Background block");
    c->seen_background = 1;
    ClassicValue v[BG_N];
    Status st = read_block(c, kw, "Background", background_keys, BG_N, v);
    if (st) return st;
    if (v[BG_COLOR].given) {
        c->s->bg_type = BG_CONSTANT;
        c->s->bg_color = c->s->bg_zenith = v[BG_COLOR].v;
    }
    if (v[BG_AMBIENT].given) {
        c->s->ambient = v[BG_AMBIENT].v;
        c->ambient_given = 1;
    }
    if (v[BG_CUBE].given) return parse_cubemap(c, &v[BG_CUBE].word);
    return ST_OK;
}

/* ------------------------------------------------------------------ materials */

enum { M_DIFFUSE, M_SPECULAR, M_SHININESS, M_EXPONENT, M_REFLECTIVE, M_TRANSPARENT, M_IOR, M_TEXTURE, M_N };
static const ClassicKey material_keys[M_N] = {
    [M_DIFFUSE] = {"diffuseColor", CK_COLOR, 0},     [M_SPECULAR] = {"specularColor", CK_COLOR, 0},
    [M_SHININESS] = {"shininess", CK_NUMBER, 0},     [M_EXPONENT] = {"exponent", CK_NUMBER, 0},
    [M_REFLECTIVE] = {"reflectiveColor", CK_COLOR, 0}, [M_TRANSPARENT] = {"transparentColor", CK_COLOR, 0},
    [M_IOR] = {"indexOfRefraction", CK_POSITIVE, 0}, [M_TEXTURE] = {"texture", CK_PATH, 0},
};

static Status add_material(Classic *c, Material m)
{
    uint index;
    Status st = scene_add_material(c->s, "", m, &index, c->err);
    if (st) return st;
    if (c->n_materials == 0) c->first_material = index;
    c->n_materials++;
    return ST_OK;
}

static Status parse_phong(Classic *c, const Token *kw)
{
    ClassicValue v[M_N];
    char block[32];
    snprintf(block, sizeof block, "%.*s", (int)kw->len, kw->text);
    Status st = read_block(c, kw, block, material_keys, M_N, v);
    if (st) return st;
    if ((st = only_one(c, &v[M_SHININESS], &v[M_EXPONENT], block))) return st;
    /* the format's defaults: diffuse 1 1 1, specular 0, shininess 0 */
    Material m = material_phong(v[M_DIFFUSE].given ? v[M_DIFFUSE].v : v3s(1.0f),
                                v[M_SPECULAR].given ? v[M_SPECULAR].v : v3s(0.0f),
                                v[M_SHININESS].given ? v[M_SHININESS].f : (v[M_EXPONENT].given ? v[M_EXPONENT].f : 0.0f));
    if (v[M_REFLECTIVE].given) m.reflective = v[M_REFLECTIVE].v;
    c->keys_2004 |= v[M_REFLECTIVE].given || v[M_TRANSPARENT].given || v[M_IOR].given || v[M_EXPONENT].given;
    if (v[M_TRANSPARENT].given) m.transparent = v[M_TRANSPARENT].v;
    if (v[M_IOR].given) m.ior = v[M_IOR].f;
    if (v[M_TEXTURE].given) {
        char *path;
        if ((st = resolve_path(c, &v[M_TEXTURE].word, &path))) return st;
        /* linear texels, as the course's code reads them (its output has no sRGB curve
         * either, so a texture shows its file's bytes) */
        st = texture_load_image(c->s, NULL, path, 1, 0, &m.texture, c->err);
        free(path);
        if (st) {
            if (st == ST_IO || st == ST_INPUT)
                reader_annotate(&c->lx, &v[M_TEXTURE].word, c->err);
            return st;
        }
    }
    return add_material(c, m);
}

static Status parse_transform_ops(Classic *c, Transform *m, Token *stop);

/* The classic solid checkerboard: the first material with its diffuse colour
 * alternating with the second's on the unit cells of the (transformed) point. */
static Status parse_checkerboard(Classic *c, const Token *kw)
{
    Status st = expect_brace(c, TOK_LBRACE, "'{' to open the Checkerboard block");
    if (st) return st;
    Transform m = transform_identity();
    Token t;
    if ((st = next(c, &t))) return st;
    if (tok_is(&t, "Transform")) {
        if ((st = expect_brace(c, TOK_LBRACE, "'{' to open the Transform block"))) return st;
        if ((st = parse_transform_ops(c, &m, &t))) return st;
        if (t.kind != TOK_RBRACE)
            return expected(c, &t, "a transformation (Translate, Scale, UniformScale, XRotate, YRotate, "
                            "ZRotate, Rotate, Matrix4f, Matrix) or '}'");
        if ((st = next(c, &t))) return st;
    }
    uint idx[2];
    for (int i = 0; i < 2; i++) {
        if (i > 0 && (st = next(c, &t))) return st;
        if (!tok_is(&t, "materialIndex")) return expected(c, &t, "'materialIndex'");
        Token nt;
        unsigned long long u;
        if ((st = next(c, &nt))) return st;
        if (tok_uint(&nt, &u) || u >= c->n_materials) {
            char what[96];
            snprintf(what, sizeof what, "the index of a material defined before it (0..%d)", (int)c->n_materials - 1);
            return expected(c, &nt, what);
        }
        idx[i] = c->first_material + (uint)u;
    }
    if ((st = expect_brace(c, TOK_RBRACE, "'}' closing the Checkerboard block"))) return st;
    Material a = c->s->materials[idx[0]], b = c->s->materials[idx[1]];
    if (a.texture != NO_INDEX || b.texture != NO_INDEX)
        return lex_error_at(&c->lx, kw, c->err, "a Checkerboard of textured materials is not supported");
    Texture tx = texture_make_checker(a.albedo, b.albedo, 1.0f, 1);
    float mm[12];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) mm[4 * i + j] = (float)m.m[i][j];
    texture_set_matrix(&tx, mm);
    if ((st = texture_check_map(&tx, c->err))) {
        error_prefix(c->err, "%s:%u:%u: the Checkerboard's transform", c->lx.path, kw->line, kw->col);
        return st;
    }
    if ((st = scene_add_texture(c->s, NULL, NULL, tx, &a.texture, c->err))) return st;
    return add_material(c, a);
}

/* MIT 6.837 Fall 2019's ray tracer adds k_specular x the mirror ray's light when
 * bounces > 0, for its `Material` and `PhongMaterial` blocks alike (scene07_arch's
 * floor is a PhongMaterial of specularColor 0.4). MIT 2004's PhongMaterial mirrors only
 * with reflectiveColor, and Tsinghua's PA1 (a sized camera) is a ray caster that
 * reflects nothing. So once the Materials block is read, a scene in neither dialect
 * gets its specular colours as mirrors. */
static void mirror_specular_colours(Classic *c)
{
    if (c->camera_sized || c->keys_2004) return;
    for (uint i = c->first_material; i < c->first_material + c->n_materials; i++) {
        Material *m = &c->s->materials[i];
        if (m->type == MAT_PHONG) m->reflective = m->specular;
    }
}

static Status parse_materials(Classic *c, const Token *kw)
{
    if (c->seen_materials) return lex_error_at(&c->lx, kw, c->err, "a second Materials block");
    c->seen_materials = 1;
    Status st = expect_brace(c, TOK_LBRACE, "'{' to open the Materials block");
    unsigned long long n;
    if (st || (st = read_count(c, "numMaterials", &n))) return st;
    for (unsigned long long i = 0;; i++) {
        Token t;
        if ((st = next(c, &t))) return st;
        if (t.kind == TOK_RBRACE && i == n) {
            mirror_specular_colours(c);
            return ST_OK;
        }
        if (t.kind == TOK_EOF)
            return lex_error_at(&c->lx, &t, c->err, "expected '}' to close the Materials block opened at line %u, "
                                "found end of file", kw->line);
        if (t.kind == TOK_RBRACE)
            return lex_error_at(&c->lx, &t, c->err, "the Materials block at line %u declares numMaterials %llu "
                                "but has %llu", kw->line, n, i);
        if (i == n) {
            char what[96];
            snprintf(what, sizeof what, "'}' closing the Materials block (numMaterials %llu)", n);
            return expected(c, &t, what);
        }
        if (tok_is(&t, "PhongMaterial") || tok_is(&t, "Material")) st = parse_phong(c, &t);
        else if (tok_is(&t, "Checkerboard")) st = parse_checkerboard(c, &t);
        else return expected(c, &t, "a material (PhongMaterial, Material, Checkerboard)");
        if (st) return st;
    }
}

/* ------------------------------------------------------------------ objects */

static Status parse_object(Classic *c, const Token *kw, const Transform *m);

/* The material of the next object: the last MaterialIndex, else material 0, else
 * (no materials at all) a white diffuse one made on first use. */
static Status object_material(Classic *c, uint *out)
{
    if (c->current != NO_INDEX) *out = c->current;
    else if (c->n_materials > 0) *out = c->first_material;
    else {
        if (c->fallback == NO_INDEX) {
            Status st = scene_add_material(c->s, "", material_phong(v3s(1.0f), v3s(0.0f), 0.0f), &c->fallback, c->err);
            if (st) return st;
        }
        *out = c->fallback;
    }
    return ST_OK;
}

static Status add_tri(Classic *c, vec3 a, vec3 b, vec3 d, uint material, uint shading)
{
    Triangle t;
    memset(&t, 0, sizeof t);
    t.p0 = a;
    t.p1 = b;
    t.p2 = d;
    t.material = material;
    t.shading = shading;
    return scene_add_triangle(c->s, t, c->err);
}

/* A sphere under a transform that does not keep it a (plain) sphere: a latitude-
 * longitude mesh with the sphere's normals and (u, v) (kernels/texture.h) carried over.
 * The kernels have no ellipsoids, so the mesh costs 9,024 triangles a sphere; their
 * total is capped (CLPT_MAX_TESSELLATED_TRIANGLES) before they are made. */
static Status tessellate_sphere(Classic *c, const Token *kw, vec3 center, float radius, const Transform *m,
                                uint material)
{
    enum { PER_SPHERE = 2 * SPHERE_SEGMENTS * (SPHERE_BANDS - 1) };
    if (PER_SPHERE > CLPT_MAX_TESSELLATED_TRIANGLES - c->tessellated)
        return lex_error_at(&c->lx, kw, c->err, "its transform makes this sphere a mesh of %d triangles, and the "
                            "meshes of the scene's spheres would then hold more than %u "
                            "(CLPT_MAX_TESSELLATED_TRIANGLES, %u such spheres): scale spheres uniformly, or "
                            "use fewer", PER_SPHERE, CLPT_MAX_TESSELLATED_TRIANGLES,
                            CLPT_MAX_TESSELLATED_TRIANGLES / PER_SPHERE);
    c->tessellated += PER_SPHERE;
    double nm[3][3];
    if (!transform_normal_matrix(m, nm)) return error_set(c->err, ST_INTERNAL, "singular transform");
    int flip = transform_det(m) < 0.0;
    enum { NB = SPHERE_BANDS, NS = SPHERE_SEGMENTS };
    for (int i = 0; i < NB; i++)
        for (int j = 0; j < NS; j++) {
            vec3 p[4], n[4];
            float uv[4][2];
            for (int k = 0; k < 4; k++) {
                int bi = i + (k >= 2), sj = j + (k == 1 || k == 2);
                double theta = M_PI * bi / NB, phi = 2.0 * M_PI * sj / NS;
                /* u = 0.5 + atan2(x, z) / 2pi: phi measured from -z through +x */
                vec3 dir = v3((float)(-sin(theta) * sin(phi)), (float)cos(theta), (float)(-sin(theta) * cos(phi)));
                p[k] = transform_point(m, v3_madd(center, dir, radius));
                n[k] = normal_apply(nm, dir);
                uv[k][0] = (float)sj / NS;
                uv[k][1] = 1.0f - (float)bi / NB;
            }
            /* quad 0 1 2 3 (0 top-left, going around); the poles give one triangle */
            int tris[2][3] = { { 0, 3, 2 }, { 0, 2, 1 } };
            for (int t = 0; t < 2; t++) {
                if ((t == 0 && i == NB - 1) || (t == 1 && i == 0)) continue;
                int a = tris[t][0], b = tris[t][flip ? 2 : 1], d = tris[t][flip ? 1 : 2];
                TriShading sh;
                memset(&sh, 0, sizeof sh);
                sh.n0 = n[a]; sh.n1 = n[b]; sh.n2 = n[d];
                memcpy(sh.uv0, uv[a], sizeof sh.uv0);
                memcpy(sh.uv1, uv[b], sizeof sh.uv1);
                memcpy(sh.uv2, uv[d], sizeof sh.uv2);
                sh.flags = TRI_HAS_NORMALS | TRI_HAS_UV;
                uint si;
                Status st = scene_add_shading(c->s, sh, &si, c->err);
                if (!st) st = add_tri(c, p[a], p[b], p[d], material, si);
                if (st) return st;
            }
        }
    return ST_OK;
}

enum { SPH_CENTER, SPH_RADIUS, SPH_N };
static const ClassicKey sphere_keys[SPH_N] = {
    [SPH_CENTER] = {"center", CK_VEC3, 0}, [SPH_RADIUS] = {"radius", CK_POSITIVE, 1},
};

static Status parse_sphere(Classic *c, const Token *kw, const Transform *m)
{
    ClassicValue v[SPH_N];
    Status st = read_block(c, kw, "Sphere", sphere_keys, SPH_N, v);
    uint material;
    if (st || (st = object_material(c, &material))) return st;
    vec3 center = v[SPH_CENTER].v;   /* the origin when not given */
    double scale;
    int rotates;
    int textured = c->s->materials[material].texture != NO_INDEX;
    if (!similarity(m, &scale, &rotates) || (rotates && textured))
        return tessellate_sphere(c, kw, center, v[SPH_RADIUS].f, m, material);
    Sphere sp;
    memset(&sp, 0, sizeof sp);
    sp.center = transform_point(m, center);
    sp.radius = (float)(scale * v[SPH_RADIUS].f);
    sp.material = material;
    if (!(sp.radius > 0.0f) || !isfinite(sp.radius))
        return lex_error_at(&c->lx, kw, c->err, "the transformed sphere's radius is %g", (double)sp.radius);
    return scene_add_sphere(c->s, sp, c->err);
}

enum { PL_NORMAL, PL_OFFSET, PL_N };
static const ClassicKey plane_keys[PL_N] = {
    [PL_NORMAL] = {"normal", CK_DIR, 1}, [PL_OFFSET] = {"offset", CK_ANY, 0},
};

/* The plane dot(normal, p) = offset (normal of any length). */
static Status parse_plane(Classic *c, const Token *kw, const Transform *m)
{
    ClassicValue v[PL_N];
    Status st = read_block(c, kw, "Plane", plane_keys, PL_N, v);
    uint material;
    if (st || (st = object_material(c, &material))) return st;
    vec3 n = v[PL_NORMAL].v;
    double n2 = (double)n.x * n.x + (double)n.y * n.y + (double)n.z * n.z;
    double k = v[PL_OFFSET].f / n2;
    vec3 q = v3((float)(n.x * k), (float)(n.y * k), (float)(n.z * k));   /* a point on it */
    double nm[3][3];
    if (!transform_normal_matrix(m, nm)) return error_set(c->err, ST_INTERNAL, "singular transform");
    vec3 nw = normal_apply(nm, n), qw = transform_point(m, q);
    if (v3_is_zero(nw)) return lex_error_at(&c->lx, &v[PL_NORMAL].key, c->err, "the plane's normal is too long");
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = nw;
    pl.offset = (float)((double)nw.x * qw.x + (double)nw.y * qw.y + (double)nw.z * qw.z);
    pl.material = material;
    return scene_add_plane(c->s, pl, c->err);
}

enum { TRI_V0, TRI_V1, TRI_V2, TRI_N };
static const ClassicKey triangle_keys[TRI_N] = {
    [TRI_V0] = {"vertex0", CK_VEC3, 1}, [TRI_V1] = {"vertex1", CK_VEC3, 1}, [TRI_V2] = {"vertex2", CK_VEC3, 1},
};

static Status parse_triangle(Classic *c, const Token *kw, const Transform *m)
{
    ClassicValue v[TRI_N];
    Status st = read_block(c, kw, "Triangle", triangle_keys, TRI_N, v);
    uint material;
    if (st || (st = object_material(c, &material))) return st;
    vec3 a = transform_point(m, v[TRI_V0].v), b = transform_point(m, v[TRI_V1].v), d = transform_point(m, v[TRI_V2].v);
    /* a mirroring transform turns the winding around; keep the outward side outward */
    return transform_det(m) < 0.0 ? add_tri(c, a, d, b, material, NO_INDEX) : add_tri(c, a, b, d, material, NO_INDEX);
}

enum { MESH_FILE, MESH_N };
static const ClassicKey mesh_keys[MESH_N] = { [MESH_FILE] = {"obj_file", CK_PATH, 1} };

static Status parse_mesh(Classic *c, const Token *kw, const Transform *m)
{
    ClassicValue v[MESH_N];
    Status st = read_block(c, kw, "TriangleMesh", mesh_keys, MESH_N, v);
    uint material;
    if (st || (st = object_material(c, &material))) return st;
    char *path;
    if ((st = resolve_path(c, &v[MESH_FILE].word, &path))) return st;
    /* the sink applies the transform as it does to a mesh of our format */
    MeshOptions o = mesh_options(material);
    o.xf = *m;
    /* MIT Fall 2019's loader smooths a mesh's normals over shared vertex indices;
     * Tsinghua's (a sized camera) keeps one normal per face (docs/classic-format.md,
     * "Conventions") */
    o.smooth_by_index = !c->camera_sized;
    st = obj_load_with(path, c->s, &o, c->err);
    free(path);
    if (st == ST_IO) {
        reader_annotate(&c->lx, &v[MESH_FILE].word, c->err);
        return st;
    }
    if (st) {
        size_t len = strlen(c->err->msg);
        snprintf(c->err->msg + len, sizeof c->err->msg - len, " (in the TriangleMesh of %s:%u:%u)", c->lx.path,
                 kw->line, kw->col);
    }
    return st;
}

/* A profile curve: `{ controls [ x y z ] [ x y z ] ... }` as the Tsinghua PA2/PA3
 * starter code reads it (docs/classic-format.md, "Curves"), the keyword in kw. The
 * points go to *pts (x y z triples, malloc'd; the caller frees it) and their '[' tokens
 * to *at when not NULL (malloc'd too), for messages about one point. */
static Status parse_curve(Classic *c, const Token *kw, CurveKind kind, float **pts, Token **at, size_t *n)
{
    const char *name = kind == CURVE_BEZIER ? "BezierCurve" : "BsplineCurve";
    char what[160];
    *pts = NULL;
    if (at) *at = NULL;
    *n = 0;
    snprintf(what, sizeof what, "'{' to open the %s block", name);
    Status st = expect_brace(c, TOK_LBRACE, what);
    Token t;
    if (st || (st = next(c, &t))) return st;
    if (!tok_is(&t, "controls")) return expected(c, &t, "'controls' (the curve's control points follow it)");
    size_t cap = 0;
    for (;;) {
        if ((st = next(c, &t))) return st;
        if (t.kind == TOK_RBRACE) break;
        if (t.kind != TOK_LBRACKET) {
            if (t.kind == TOK_EOF)
                return lex_error_at(&c->lx, &t, c->err, "expected '}' to close the %s block opened at line %u, "
                                    "found end of file", name, kw->line);
            snprintf(what, sizeof what, "'[' starting a control point, or '}' closing the %s", name);
            return expected(c, &t, what);
        }
        if (*n == CURVE_MAX_POINTS)
            return lex_error_at(&c->lx, &t, c->err, "the %s has more than %u control points", name,
                                CURVE_MAX_POINTS);
        if (*n == cap) {
            cap = cap ? 2 * cap : 16;
            float *grown = realloc(*pts, cap * 3 * sizeof **pts);
            Token *grown_at = at ? realloc(*at, cap * sizeof **at) : NULL;
            if (grown) *pts = grown;
            if (grown_at) *at = grown_at;
            if (!grown || (at && !grown_at)) return error_set(c->err, ST_INTERNAL, "out of memory");
        }
        if (at) (*at)[*n] = t;
        for (int k = 0; k < 3; k++)
            if ((st = read_float(c, &(*pts)[3 * *n + k], NULL, "3 numbers (x y z) for the control point")))
                return st;
        if ((st = expect_brace(c, TOK_RBRACKET, "']' closing the control point"))) return st;
        (*n)++;
    }
    if (*n < CURVE_MIN_POINTS)
        return lex_error_at(&c->lx, kw, c->err, "the %s has %zu control points; it needs at least %u", name, *n,
                            CURVE_MIN_POINTS);
    if (kind == CURVE_BEZIER && *n > CURVE_MAX_BEZIER_POINTS)
        return lex_error_at(&c->lx, kw, c->err, "the BezierCurve has %zu control points; at most %u are supported "
                            "(degree %u; a BsplineCurve takes any number)", *n, CURVE_MAX_BEZIER_POINTS,
                            REV_MAX_DEGREE);
    return ST_OK;
}

/* A curve on its own: read and checked, then dropped, as the course draws only surfaces. */
static Status parse_lone_curve(Classic *c, const Token *kw)
{
    float *pts;
    size_t n;
    Status st = parse_curve(c, kw, tok_is(kw, "BezierCurve") ? CURVE_BEZIER : CURVE_BSPLINE, &pts, NULL, &n);
    free(pts);
    return st;
}

/* Whether m keeps the y axis vertical and upward with a uniform scale (any turn about
 * y, or mirror through a vertical plane, maps a surface of revolution to itself): then
 * the surface stays one, with its profile scaled by *scale and its axis moved. */
static int keeps_axis(const Transform *m, double *scale)
{
    int rotates;
    if (!similarity(m, scale, &rotates)) return 0;
    const double (*a)[4] = m->m;
    return fabs(a[0][1]) <= 1e-6 * *scale && fabs(a[2][1]) <= 1e-6 * *scale && a[1][1] > 0.0;
}

/* The Bezier segments of the profile (x y pairs), its points in the xy plane checked. */
static Status revsurface_profile(Classic *c, CurveKind kind, const float *pts, const Token *at, size_t n,
                                 float **xy, unsigned *n_segments, unsigned *degree)
{
    float *flat = malloc(2 * n * sizeof *flat);
    *xy = malloc(6 * n * sizeof **xy);    /* a B-spline makes 3n - 8 pairs */
    if (!flat || !*xy) {
        free(flat);
        return error_set(c->err, ST_INTERNAL, "out of memory");
    }
    for (size_t i = 0; i < n; i++) {
        if (pts[3 * i + 2] != 0.0f) {
            free(flat);
            return lex_error_at(&c->lx, &at[i], c->err, "a RevSurface's profile lies in the xy plane, but this "
                                "control point has z = %g", (double)pts[3 * i + 2]);
        }
        flat[2 * i] = pts[3 * i];
        flat[2 * i + 1] = pts[3 * i + 1];
    }
    curve_to_segments(kind, flat, n, *xy, n_segments, degree);
    free(flat);
    return ST_OK;
}

/* Adds the surface: exact (kernels/revsurface.h) when m keeps the axis vertical, else
 * as a mesh through m. */
static Status add_revsurface(Classic *c, const Token *kw, float *xy, unsigned n_segments, unsigned degree,
                             const Transform *m, uint material)
{
    double scale;
    if (keeps_axis(m, &scale)) {
        size_t np = (size_t)n_segments * degree + 1;
        for (size_t i = 0; i < np; i++) {
            xy[2 * i] = (float)(scale * xy[2 * i]);
            xy[2 * i + 1] = (float)(scale * xy[2 * i + 1] + m->m[1][3]);
        }
        RevSurface r;
        memset(&r, 0, sizeof r);
        r.material = material;
        r.axis_x = (float)m->m[0][3];
        r.axis_z = (float)m->m[2][3];
        r.n_segments = n_segments;
        r.degree = degree;
        return scene_add_revsurface(c->s, r, xy, c->err);
    }
    size_t tris = 2u * REV_MESH_STEPS * REV_MESH_AROUND * (size_t)n_segments;
    if (tris > CLPT_MAX_TESSELLATED_TRIANGLES - c->tessellated)
        return lex_error_at(&c->lx, kw, c->err, "its transform tilts this RevSurface's axis, which makes it a mesh "
                            "of %zu triangles, and the scene's meshes made from spheres and surfaces would then "
                            "hold more than %u (CLPT_MAX_TESSELLATED_TRIANGLES)", tris,
                            CLPT_MAX_TESSELLATED_TRIANGLES);
    c->tessellated += tris;
    return curve_mesh_revsurface(c->s, xy, n_segments, degree, m, material, REV_MESH_STEPS, REV_MESH_AROUND,
                                 c->err);
}

/* RevSurface { profile BezierCurve { ... } } (or a BsplineCurve): the profile revolved
 * about the y axis. */
static Status parse_revsurface(Classic *c, const Token *kw, const Transform *m)
{
    Status st = expect_brace(c, TOK_LBRACE, "'{' to open the RevSurface block");
    Token t, curve;
    if (st || (st = next(c, &t))) return st;
    if (t.kind == TOK_RBRACE)
        return lex_error_at(&c->lx, kw, c->err, "the RevSurface block needs 'profile' (a BezierCurve or "
                            "BsplineCurve block)");
    if (!tok_is(&t, "profile")) return expected(c, &t, "'profile' (a BezierCurve or BsplineCurve block follows)");
    if ((st = next(c, &curve))) return st;
    if (!tok_is(&curve, "BezierCurve") && !tok_is(&curve, "BsplineCurve"))
        return expected(c, &curve, "a BezierCurve or BsplineCurve block for the profile");
    CurveKind kind = tok_is(&curve, "BezierCurve") ? CURVE_BEZIER : CURVE_BSPLINE;
    float *pts, *xy = NULL;
    Token *at;
    size_t n;
    unsigned n_segments = 0, degree = 0;
    uint material;
    st = parse_curve(c, &curve, kind, &pts, &at, &n);
    if (!st) st = expect_brace(c, TOK_RBRACE, "'}' closing the RevSurface (it holds one profile)");
    if (!st) st = revsurface_profile(c, kind, pts, at, n, &xy, &n_segments, &degree);
    if (!st) st = object_material(c, &material);
    if (!st) st = add_revsurface(c, kw, xy, n_segments, degree, m, material);
    free(pts);
    free(at);
    free(xy);
    return st;
}

/* Reads transformations into *m (each applied on the right: the first one listed is
 * the last applied to the object, as in the course's parser) up to the first token that
 * is not one, returned in *stop. Matrix4f and Matrix multiply on the left, as there. */
static Status parse_transform_ops(Classic *c, Transform *m, Token *stop)
{
    Status st;
    for (;;) {
        Token t;
        if ((st = next(c, &t))) return st;
        Transform x;
        float f;
        if (tok_is(&t, "Translate") || tok_is(&t, "Scale")) {
            ClassicKey k = { tok_is(&t, "Translate") ? "Translate" : "Scale", CK_VEC3, 0 };
            ClassicValue v;
            if ((st = read_value(c, &k, &v))) return st;
            x = tok_is(&t, "Translate") ? transform_translate(v.v.x, v.v.y, v.v.z)
                                         : transform_scale(v.v.x, v.v.y, v.v.z);
            *m = transform_compose(m, &x);
        } else if (tok_is(&t, "UniformScale")) {
            if ((st = read_float(c, &f, NULL, "a number for 'UniformScale'"))) return st;
            x = transform_scale(f, f, f);
            *m = transform_compose(m, &x);
        } else if (tok_is(&t, "XRotate") || tok_is(&t, "YRotate") || tok_is(&t, "ZRotate")) {
            char what[64];
            snprintf(what, sizeof what, "a number of degrees for '%.*s'", (int)t.len, t.text);
            if ((st = read_float(c, &f, NULL, what))) return st;
            x = transform_rotate(t.text[0] == 'X', t.text[0] == 'Y', t.text[0] == 'Z', f);
            *m = transform_compose(m, &x);
        } else if (tok_is(&t, "Rotate")) {
            float a[4];
            Token at;
            if ((st = expect_brace(c, TOK_LBRACE, "'{' before Rotate's axis and degrees"))) return st;
            for (int i = 0; i < 4; i++)
                if ((st = read_float(c, &a[i], &at, i < 3 ? "3 numbers (the axis) for 'Rotate'"
                                                          : "a number of degrees for 'Rotate'")))
                    return st;
            if ((st = expect_brace(c, TOK_RBRACE, "'}' after Rotate's axis and degrees"))) return st;
            double len = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
            if (!(len > 0.0) || !isfinite(len))
                return lex_error_at(&c->lx, &t, c->err, "Rotate's axis must be a non-zero vector");
            x = transform_rotate(a[0], a[1], a[2], a[3]);
            *m = transform_compose(m, &x);
        } else if (tok_is(&t, "Matrix4f") || tok_is(&t, "Matrix")) {
            /* Matrix4f (2012): the numbers column by column; Matrix (2004): row by row */
            int by_column = tok_is(&t, "Matrix4f");
            if ((st = expect_brace(c, TOK_LBRACE, "'{' before the matrix's 16 numbers"))) return st;
            double r[4][4];
            Token first = t;
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 4; i++) {
                    if ((st = read_float(c, &f, i + j == 0 ? &first : NULL, "16 numbers for the matrix"))) return st;
                    if (by_column) r[i][j] = f;
                    else r[j][i] = f;
                }
            if ((st = expect_brace(c, TOK_RBRACE, "'}' after the matrix's 16 numbers"))) return st;
            /* the kernels take spheres, planes and triangles through affine maps only */
            if (r[3][0] != 0.0 || r[3][1] != 0.0 || r[3][2] != 0.0 || r[3][3] != 1.0)
                return lex_error_at(&c->lx, &first, c->err, "the matrix's last row is %g %g %g %g; it must be "
                                    "0 0 0 1 (an affine transform)", r[3][0], r[3][1], r[3][2], r[3][3]);
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 4; j++) x.m[i][j] = r[i][j];
            *m = transform_compose(&x, m);
        } else {
            *stop = t;
            return ST_OK;
        }
    }
}

static Status parse_transform(Classic *c, const Token *kw, const Transform *parent)
{
    Status st = expect_brace(c, TOK_LBRACE, "'{' to open the Transform block");
    if (st) return st;
    Transform m = transform_identity();
    Token t;
    if ((st = parse_transform_ops(c, &m, &t))) return st;
    if (t.kind != TOK_WORD)
        return expected(c, &t, "a transformation (Translate, Scale, UniformScale, XRotate, YRotate, ZRotate, "
                        "Rotate, Matrix4f, Matrix) or the object it applies to");
    Transform world = transform_compose(parent, &m);
    double d = transform_det(&world);
    if (!(fabs(d) > 1e-30) || !isfinite(d))
        return lex_error_at(&c->lx, kw, c->err, "the Transform is singular (it flattens its object)");
    if ((st = parse_object(c, &t, &world))) return st;
    return expect_brace(c, TOK_RBRACE, "'}' closing the Transform (it holds one object)");
}

static Status parse_group(Classic *c, const Token *kw, const Transform *m)
{
    Status st = expect_brace(c, TOK_LBRACE, "'{' to open the Group block");
    unsigned long long n;
    if (st || (st = read_count(c, "numObjects", &n))) return st;
    for (unsigned long long count = 0;;) {
        Token t;
        if ((st = next(c, &t))) return st;
        if (t.kind == TOK_RBRACE && count == n) return ST_OK;
        if (t.kind == TOK_EOF)
            return lex_error_at(&c->lx, &t, c->err, "expected '}' to close the Group block opened at line %u, "
                                "found end of file", kw->line);
        if (t.kind == TOK_RBRACE)
            return lex_error_at(&c->lx, &t, c->err, "the Group at line %u declares numObjects %llu but has %llu",
                                kw->line, n, count);
        if (tok_is(&t, "MaterialIndex")) {
            Token nt;
            unsigned long long u;
            if ((st = next(c, &nt))) return st;
            if (tok_uint(&nt, &u) || u >= c->n_materials) {
                char what[128];
                if (c->n_materials == 0)
                    snprintf(what, sizeof what, "a material index, but no materials are defined before it");
                else
                    snprintf(what, sizeof what, "a material index in 0..%u", c->n_materials - 1);
                return expected(c, &nt, what);
            }
            c->current = c->first_material + (uint)u;
            continue;
        }
        if (count == n) {
            char what[96];
            snprintf(what, sizeof what, "'}' closing the Group (numObjects %llu)", n);
            return expected(c, &t, what);
        }
        if ((st = parse_object(c, &t, m))) return st;
        count++;
    }
}

/* Group and Transform recurse: a limit on their nesting keeps the stack bounded. */
static Status enter_block(Classic *c, const Token *kw)
{
    if (c->depth >= CLPT_MAX_NESTING)
        return lex_error_at(&c->lx, kw, c->err, "Group and Transform blocks nested more than %d deep",
                            CLPT_MAX_NESTING);
    c->depth++;
    return ST_OK;
}

static Status parse_object(Classic *c, const Token *kw, const Transform *m)
{
    if (tok_is(kw, "Group") || tok_is(kw, "Transform")) {
        Status st = enter_block(c, kw);
        if (st) return st;
        st = tok_is(kw, "Group") ? parse_group(c, kw, m) : parse_transform(c, kw, m);
        c->depth--;
        return st;
    }
    if (tok_is(kw, "Sphere")) return parse_sphere(c, kw, m);
    if (tok_is(kw, "Plane")) return parse_plane(c, kw, m);
    if (tok_is(kw, "Triangle")) return parse_triangle(c, kw, m);
    if (tok_is(kw, "TriangleMesh")) return parse_mesh(c, kw, m);
    if (tok_is(kw, "RevSurface")) return parse_revsurface(c, kw, m);
    if (tok_is(kw, "BezierCurve") || tok_is(kw, "BsplineCurve")) return parse_lone_curve(c, kw);
    return expected(c, kw, "an object (Group, Sphere, Plane, Triangle, TriangleMesh, Transform, RevSurface, "
                    "BezierCurve, BsplineCurve) or MaterialIndex");
}

/* ------------------------------------------------------------------ files */

int classic_detect(const char *text, size_t len)
{
    static const char *const words[] = { "PerspectiveCamera", "OrthographicCamera", "Lights", "Background",
                                         "Materials", "Group" };
    size_t i = 0;
    for (;;) {
        while (i < len && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r' || text[i] == '\n' ||
                           text[i] == '\f' || text[i] == '\v'))
            i++;
        if (i < len && text[i] == '#') {
            while (i < len && text[i] != '\n') i++;
            continue;
        }
        break;
    }
    size_t start = i;
    while (i < len && ((text[i] >= 'a' && text[i] <= 'z') || (text[i] >= 'A' && text[i] <= 'Z'))) i++;
    for (size_t w = 0; w < sizeof words / sizeof words[0]; w++)
        if (strlen(words[w]) == i - start && memcmp(words[w], text + start, i - start) == 0) return 1;
    return 0;
}

/* classic_load and classic_load_text: `text` NULL reads the file `path`. */
static Status load(const char *path, const char *text, size_t len, Scene *s, Error *err)
{
    free(s->path);
    s->path = malloc(strlen(path) + 1);
    if (!s->path) return error_set(err, ST_INTERNAL, "out of memory");
    strcpy(s->path, path);
    Classic c;
    memset(&c, 0, sizeof c);
    c.s = s;
    c.err = err;
    c.current = NO_INDEX;
    c.fallback = NO_INDEX;
    Status st = text ? lex_open_text(&c.lx, path, text, len, err) : lex_open_file(&c.lx, path, err);
    if (st) return st;
    /* how the course's reference ray tracer draws a scene (docs/classic-format.md) */
    s->integrator = INTEGRATOR_WHITTED;
    s->linear_output = 1;
    s->normal_miss_grey = 1;
    s->shadows = 0;       /* the course ray casters cast none */
    s->image.spp = 1;
    s->bg_type = BG_CONSTANT;
    s->bg_color = s->bg_zenith = v3s(0.5f);
    Transform identity = transform_identity();
    Token t;
    for (;;) {
        if ((st = next(&c, &t)) || t.kind == TOK_EOF) break;
        if (tok_is(&t, "PerspectiveCamera")) st = parse_camera(&c, &t, 0);
        else if (tok_is(&t, "OrthographicCamera")) st = parse_camera(&c, &t, 1);
        else if (tok_is(&t, "Lights")) st = parse_lights(&c, &t);
        else if (tok_is(&t, "Background")) st = parse_background(&c, &t);
        else if (tok_is(&t, "Materials")) st = parse_materials(&c, &t);
        else if (tok_is(&t, "Group")) st = parse_object(&c, &t, &identity);
        else
            st = expected(&c, &t, "a scene block (PerspectiveCamera, OrthographicCamera, Lights, Background, "
                          "Materials, Group)");
        if (st) break;
    }
    if (!st && !c.seen_camera)
        st = lex_error_at(&c.lx, &t, err, "the scene has no camera (a PerspectiveCamera or OrthographicCamera block)");
    /* as in the course's parser: a scene without lights is drawn in flat colours */
    if (!st && s->n_delta_lights == 0 && !c.ambient_given) s->ambient = v3s(1.0f);
    lex_close(&c.lx);
    return st;
}

Status classic_load(const char *path, Scene *s, Error *err)
{
    return load(path, NULL, 0, s, err);
}

Status classic_load_text(const char *path, const char *text, size_t len, Scene *s, Error *err)
{
    return load(path, text, len, s, err);
}
