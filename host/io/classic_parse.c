/*
 * classic_parse.c — the scene format of MIT 6.837 and the courses derived from it
 * (docs/classic-format.md), read with the tokenizer of our own format (host/io/lexer.c):
 * tokens and field blocks, camera, lights, background, the entry points; materials and
 * objects are in classic_material.c and classic_object.c (classic_reader.h).
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
#include "io/classic_reader.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/kmath.h"
#include "io/lexer.h"
#include "io/path.h"
#include "io/reader.h"
#include "scene/transform.h"
#include "io/texture.h"

/* ------------------------------------------------------------------ the reader */

Status classic_next(Classic *c, Token *t) { return lex_next(&c->lx, t, c->err); }
Status classic_expected(Classic *c, const Token *t, const char *what) { return lex_expected(&c->lx, t, what, c->err); }

Status classic_expect_brace(Classic *c, TokenKind kind, const char *what)
{
    Token t;
    Status st = classic_next(c, &t);
    if (st) return st;
    if (t.kind != kind) return classic_expected(c, &t, what);
    return ST_OK;
}

Status classic_read_float(Classic *c, float *out, Token *where, const char *what)
{
    Token t;
    Status st = classic_next(c, &t);
    if (st) return st;
    if (where) *where = t;
    if (tok_float(&t, out)) return classic_expected(c, &t, what);
    return ST_OK;
}


Status classic_read_value(Classic *c, const ClassicKey *k, ClassicValue *v)
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
            if ((st = classic_read_float(c, &x[i], &t, msg))) return st;
            if (i == 0) first = t;
            if (k->kind == CK_COLOR && x[i] < 0.0f) return classic_expected(c, &t, msg);
        }
        v->v = v3(x[0], x[1], x[2]);
        if (k->kind == CK_DIR && v3_is_zero(v->v))
            return lex_error_at(&c->lx, &first, c->err, "expected %s, found 0 0 0", msg);
        return ST_OK;
    }
    case CK_NUMBER:
    case CK_ANY:
    case CK_POSITIVE:
        if ((st = classic_read_float(c, &v->f, &t, msg))) return st;
        if ((k->kind == CK_NUMBER && v->f < 0.0f) || (k->kind == CK_POSITIVE && !(v->f > 0.0f)))
            return classic_expected(c, &t, msg);
        return ST_OK;
    case CK_COUNT:
        if ((st = classic_next(c, &t))) return st;
        if (tok_uint(&t, &v->u) || v->u < 1 || v->u > 16384) return classic_expected(c, &t, msg);
        return ST_OK;
    case CK_PATH:
        if ((st = classic_next(c, &t))) return st;
        if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0) return classic_expected(c, &t, msg);
        v->word = t;
        return ST_OK;
    }
    return error_set(c->err, ST_INTERNAL, "unhandled field kind");
}

/* Reads `{ key value ... }` for block `block` (opened by keyword kw) against keys[]:
 * any order, each key at most once, the required ones checked at the end. */
Status classic_read_block(Classic *c, const Token *kw, const char *block, const ClassicKey *keys, size_t n,
                          ClassicValue *vals)
{
    memset(vals, 0, n * sizeof *vals);
    char what[300];
    Status st = ST_OK;
    snprintf(what, sizeof what, "'{' to open the %s block", block);
    if ((st = classic_expect_brace(c, TOK_LBRACE, what))) return st;
    for (;;) {
        Token t;
        if ((st = classic_next(c, &t))) return st;
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
            return classic_expected(c, &t, what);
        }
        if (vals[i].given)
            return lex_error_at(&c->lx, &t, c->err, "'%s' repeated in the %s block (first given at %u:%u)",
                                keys[i].key, block, vals[i].key.line, vals[i].key.col);
        vals[i].given = 1;
        vals[i].key = t;
        if ((st = classic_read_value(c, &keys[i], &vals[i]))) return st;
    }
    for (size_t i = 0; i < n; i++)
        if (keys[i].required && !vals[i].given)
            return lex_error_at(&c->lx, kw, c->err, "the %s block needs '%s'", block, keys[i].key);
    return ST_OK;
}

/* Two alternative spellings of one field (shininess/exponent, falloff/attenuation). */
Status classic_only_one(Classic *c, const ClassicValue *a, const ClassicValue *b, const char *block)
{
    if (!a->given || !b->given) return ST_OK;
    const ClassicValue *later = a->key.line > b->key.line ||
                                (a->key.line == b->key.line && a->key.col > b->key.col) ? a : b;
    const ClassicValue *first = later == a ? b : a;
    return lex_error_at(&c->lx, &later->key, c->err, "a %s block takes '%.*s' or '%.*s', not both", block,
                        (int)first->key.len, first->key.text, (int)later->key.len, later->key.text);
}

/* `KEY N` with N a whole number (numLights, numMaterials, numObjects). */
Status classic_read_count(Classic *c, const char *key, unsigned long long *n)
{
    Token t;
    Status st = classic_next(c, &t);
    if (st) return st;
    char what[64];
    snprintf(what, sizeof what, "'%s'", key);
    if (!tok_is(&t, key)) return classic_expected(c, &t, what);
    if ((st = classic_next(c, &t))) return st;
    snprintf(what, sizeof what, "a whole number for '%s'", key);
    if (tok_uint(&t, n) || *n > 100000000ull) return classic_expected(c, &t, what);
    return ST_OK;
}

/* A file named in the scene: beside the scene file, else from the current folder
 * (course scenes are written to be run from the course's code folder; io/path.h). */
Status classic_resolve_path(Classic *c, const Token *t, char **out)
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
    Status st = classic_read_block(c, kw, block, camera_keys, CAM_N, v);
    if (st) return st;
    int bad = ortho ? CAM_ANGLE : CAM_SIZE, need = ortho ? CAM_SIZE : CAM_ANGLE;
    if (v[bad].given)
        return lex_error_at(&c->lx, &v[bad].key, c->err, "'%s' belongs to the %s; a %s has '%s'",
                            camera_keys[bad].key, ortho ? "PerspectiveCamera" : "OrthographicCamera", block,
                            camera_keys[need].key);
    if (!v[need].given) return lex_error_at(&c->lx, kw, c->err, "the %s block needs '%s'", block, camera_keys[need].key);
    if ((st = classic_only_one(c, &v[CAM_DIRECTION], &v[CAM_LOOKAT], block))) return st;
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
        return classic_expected(c, kw, "a light (DirectionalLight, PointLight, SpotLight)");
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
    Status st = classic_read_block(c, kw, block, keys, n, got);
    if (st) return st;
    memset(v, 0, sizeof v);
    for (size_t i = 0; i < n; i++) v[idx[i]] = got[i];
    if ((st = classic_only_one(c, &v[L_FALLOFF], &v[L_ATTEN], block))) return st;
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
    Status st = classic_expect_brace(c, TOK_LBRACE, "'{' to open the Lights block");
    unsigned long long n;
    if (st || (st = classic_read_count(c, "numLights", &n))) return st;
    for (unsigned long long i = 0;; i++) {
        Token t;
        if ((st = classic_next(c, &t))) return st;
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
            return classic_expected(c, &t, what);
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
    Status st = classic_resolve_path(c, word, &path);
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
    Status st = classic_read_block(c, kw, "Background", background_keys, BG_N, v);
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
    Status path_st = scene_set_path(s, path, err);
    if (path_st) return path_st;
    Classic c = { .s = s, .err = err, .current = NO_INDEX, .fallback = NO_INDEX };
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
        if ((st = classic_next(&c, &t)) || t.kind == TOK_EOF) break;
        if (tok_is(&t, "PerspectiveCamera")) st = parse_camera(&c, &t, 0);
        else if (tok_is(&t, "OrthographicCamera")) st = parse_camera(&c, &t, 1);
        else if (tok_is(&t, "Lights")) st = parse_lights(&c, &t);
        else if (tok_is(&t, "Background")) st = parse_background(&c, &t);
        else if (tok_is(&t, "Materials")) st = classic_parse_materials(&c, &t);
        else if (tok_is(&t, "Group")) st = classic_parse_object(&c, &t, &identity);
        else
            st = classic_expected(&c, &t, "a scene block (PerspectiveCamera, OrthographicCamera, Lights, Background, "
                          "Materials, Group)");
        if (st) break;
    }
    if (!st) st = classic_finish_instances(&c);
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
