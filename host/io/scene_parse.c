/*
 * scene_parse.c — the scene file reader (the format is docs/scene-format.md).
 *
 * Every statement but `include` is `KEYWORD [NAME] { key value ... }`. One generic
 * routine reads a block against a table of the keys it allows (KeySpec): it rejects
 * unknown and repeated keys and checks each value's type and range where the value is,
 * so errors point at the offending token. The per-statement functions then only check
 * what involves several keys (a camera's up against its view direction, a box's min
 * against its max) and append to the scene.
 */
#include "scene/scene.h"

#include "kmath.h"
#include "scene/camera.h"
#include "io/lexer.h"
#include "base/limit.h"
#include "io/mesh_load.h"
#include "io/obj.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef enum {
    VK_NUMBER,      /* one float within the key's range */
    VK_UINT,        /* one unsigned integer within the key's range */
    VK_VEC3,        /* three floats */
    VK_COLOR,       /* three floats >= 0 */
    VK_DIR,         /* three floats, not all zero */
    VK_WORD,        /* a bare word (checked by the statement) */
    VK_MATERIAL,    /* a material name, or an inline anonymous material block */
    VK_PATH,        /* a string or a word */
    VK_TEXTURE,     /* the name of a texture defined before */
    VK_ROTATE,      /* an axis (three floats, not all zero) and an angle in degrees */
    VK_SCALE,       /* one non-zero float, or three */
    VK_MATRIX       /* sixteen floats, a 4x4 matrix row by row */
} ValueKind;

typedef struct {
    const char *key;
    ValueKind kind;
    int required;
    double lo, hi;          /* VK_NUMBER, VK_UINT: the allowed range */
    int lo_open, hi_open;   /* whether the bound itself is excluded */
    const char *what;       /* VK_NUMBER, VK_UINT, VK_WORD: "a number in (0, 180)" */
} KeySpec;

typedef struct {
    int given;
    Token key;              /* where the key was written */
    Token value;            /* its first value token */
    float f;
    unsigned long long u;
    vec3 v;
    uint material;
    Token word;             /* VK_WORD, VK_PATH */
    float a[16];            /* VK_ROTATE (axis, degrees), VK_SCALE (x y z), VK_MATRIX */
} Value;

typedef struct {
    Scene *s;
    Error *err;
    uint depth;                       /* include nesting: 0 for the top file */
    char *camera_at, *image_at, *background_at;   /* "file:line:col" once given */
    char **material_at;               /* per material index, where it was defined */
    size_t n_material_at, cap_material_at;
    int depth_exceeded;               /* the include limit error is not annotated further */
} Parser;

/* ------------------------------------------------------------------ helpers */

/* The path of `file` as seen from the folder of the file `from` (io/path.h: the file
 * that names it, so an include's names are its own); NULL when out of memory. */
static char *path_beside(const char *from, const char *file, size_t file_len)
{
    char *out;
    path_resolve(from, file, file_len, PATH_BESIDE, &out);
    return out;
}

static const char *kind_what(const KeySpec *k)
{
    switch (k->kind) {
    case VK_VEC3: return "3 numbers";
    case VK_COLOR: return "3 numbers >= 0 (a colour)";
    case VK_DIR: return "a non-zero vector (3 numbers)";
    case VK_MATERIAL: return "a material name or an inline 'material { ... }' block";
    case VK_PATH: return "a file name";
    case VK_TEXTURE: return "a texture name";
    case VK_ROTATE: return "an axis and an angle in degrees (4 numbers, the axis not 0 0 0)";
    case VK_SCALE: return "a non-zero scale factor, or three (x y z)";
    case VK_MATRIX: return "16 numbers (a 4x4 matrix, row by row)";
    case VK_NUMBER:
    case VK_UINT:
    case VK_WORD: return k->what;
    }
    return "a value";
}

static int in_range(const KeySpec *k, double x)
{
    if (x < k->lo || (k->lo_open && x == k->lo)) return 0;
    if (x > k->hi || (k->hi_open && x == k->hi)) return 0;
    return 1;
}

/* "a camera key (from, at, up) or '}'" */
static void list_keys(char *buf, size_t size, const char *block, const KeySpec *keys, size_t n)
{
    size_t o = (size_t)snprintf(buf, size, "a %s key (", block);
    for (size_t i = 0; i < n && o < size; i++)
        o += (size_t)snprintf(buf + o, size - o, "%s%s", i ? ", " : "", keys[i].key);
    if (o < size) snprintf(buf + o, size - o, ") or '}'");
}

static Status parse_material_block(Parser *p, Lexer *lx, const Token *kw, int brace_taken,
                                   const char *name, uint *index);

static Status read_value(Parser *p, Lexer *lx, const KeySpec *k, Value *v)
{
    Error *err = p->err;
    char what[160];
    snprintf(what, sizeof what, "%s for '%s'", kind_what(k), k->key);
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    v->value = t;
    switch (k->kind) {
    case VK_NUMBER:
        if (tok_float(&t, &v->f) || !in_range(k, v->f)) return lex_expected(lx, &t, what, err);
        return ST_OK;
    case VK_UINT:
        if (tok_uint(&t, &v->u) || !in_range(k, (double)v->u)) return lex_expected(lx, &t, what, err);
        return ST_OK;
    case VK_VEC3:
    case VK_COLOR:
    case VK_DIR: {
        float c[3];
        for (int i = 0; i < 3; i++) {
            if (i > 0 && (st = lex_next(lx, &t, p->err))) return st;
            if (tok_float(&t, &c[i]) || (k->kind == VK_COLOR && c[i] < 0.0f))
                return lex_expected(lx, &t, what, err);
        }
        v->v = v3(c[0], c[1], c[2]);
        if (k->kind == VK_DIR && v3_is_zero(v->v))
            return lex_error_at(lx, &v->value, err, "expected %s, found 0 0 0", what);
        return ST_OK;
    }
    case VK_ROTATE:
    case VK_MATRIX: {
        int n = k->kind == VK_ROTATE ? 4 : 16;
        for (int i = 0; i < n; i++) {
            if (i > 0 && (st = lex_next(lx, &t, p->err))) return st;
            if (tok_float(&t, &v->a[i])) return lex_expected(lx, &t, what, err);
        }
        if (k->kind == VK_ROTATE && v->a[0] == 0.0f && v->a[1] == 0.0f && v->a[2] == 0.0f)
            return lex_error_at(lx, &v->value, err, "expected %s, found the axis 0 0 0", what);
        return ST_OK;
    }
    case VK_SCALE:
        /* one factor, or three: the token after the first tells which */
        if (tok_float(&t, &v->a[0]) || v->a[0] == 0.0f) return lex_expected(lx, &t, what, err);
        if ((st = lex_next(lx, &t, p->err))) return st;
        if (tok_float(&t, &v->a[1])) {
            lex_unread(lx, &t);
            v->a[1] = v->a[2] = v->a[0];
            return ST_OK;
        }
        if (v->a[1] == 0.0f) return lex_expected(lx, &t, what, err);
        if ((st = lex_next(lx, &t, p->err))) return st;
        if (tok_float(&t, &v->a[2]) || v->a[2] == 0.0f) return lex_expected(lx, &t, what, err);
        return ST_OK;
    case VK_WORD:
        if (t.kind != TOK_WORD) return lex_expected(lx, &t, what, err);
        v->word = t;
        return ST_OK;
    case VK_PATH:
        if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0)
            return lex_expected(lx, &t, what, err);
        v->word = t;
        return ST_OK;
    case VK_TEXTURE: {
        if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0) return lex_expected(lx, &t, what, err);
        char *name = tok_copy(&t);
        if (!name) return error_set(err, ST_INTERNAL, "out of memory");
        v->u = scene_find_texture(p->s, name);
        free(name);
        if (v->u == NO_INDEX) {
            char shown[64];
            tok_describe(&t, shown, sizeof shown);
            return lex_error_at(lx, &t, err, "texture '%s' is not defined (textures must be defined "
                                "before they are used)", shown);
        }
        return ST_OK;
    }
    case VK_MATERIAL:
        if (t.kind == TOK_LBRACE) return parse_material_block(p, lx, &v->key, 1, NULL, &v->material);
        if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0)
            return lex_expected(lx, &t, what, err);
        {
            char *name = tok_copy(&t);
            if (!name) return error_set(err, ST_INTERNAL, "out of memory");
            v->material = scene_find_material(p->s, name);
            if (v->material == NO_INDEX) {
                char shown[64];
                tok_describe(&t, shown, sizeof shown);
                free(name);
                return lex_error_at(lx, &t, err,
                                    "material '%s' is not defined (materials must be defined "
                                    "before they are used)", shown);
            }
            free(name);
        }
        return ST_OK;
    }
    return error_set(err, ST_INTERNAL, "unhandled value kind");
}

/* Reads `{ key value ... }` after the statement keyword `kw` (from after the brace when
 * the caller has already taken it), filling vals[i] for keys[i]; checks that every
 * required key was given. */
static Status parse_block(Parser *p, Lexer *lx, const Token *kw, int brace_taken,
                          const char *block, const KeySpec *keys, size_t n, Value *vals)
{
    Error *err = p->err;
    memset(vals, 0, n * sizeof *vals);
    Token t;
    Status st = brace_taken ? ST_OK : lex_next(lx, &t, p->err);
    if (st) return st;
    if (!brace_taken && t.kind != TOK_LBRACE) {
        char what[80];
        snprintf(what, sizeof what, "'{' to open the %s block", block);
        return lex_expected(lx, &t, what, err);
    }
    for (;;) {
        if ((st = lex_next(lx, &t, p->err))) return st;
        if (t.kind == TOK_RBRACE) break;
        if (t.kind == TOK_EOF)
            return lex_error_at(lx, &t, err,
                                "expected '}' to close the %s block opened at line %u, "
                                "found end of file", block, kw->line);
        size_t i = n;
        if (t.kind == TOK_WORD)
            for (i = 0; i < n; i++)
                if (tok_is(&t, keys[i].key)) break;
        if (i == n) {
            char what[256];
            list_keys(what, sizeof what, block, keys, n);
            return lex_expected(lx, &t, what, err);
        }
        if (vals[i].given)
            return lex_error_at(lx, &t, err, "key '%s' repeated in the %s block (first given at %u:%u)",
                                keys[i].key, block, vals[i].key.line, vals[i].key.col);
        vals[i].given = 1;
        vals[i].key = t;
        if ((st = read_value(p, lx, &keys[i], &vals[i]))) return st;
    }
    for (size_t i = 0; i < n; i++)
        if (keys[i].required && !vals[i].given)
            return lex_error_at(lx, kw, err, "the %s block needs '%s' (it has no default)",
                                block, keys[i].key);
    return ST_OK;
}

/* Rejects a second camera/image/background block, naming where the first one was. */
static Status once(Parser *p, const Lexer *lx, const Token *kw, char **seen)
{
    if (*seen)
        return lex_error_at(lx, kw, p->err, "a second %.*s block (the first is at %s)",
                            (int)kw->len, kw->text, *seen);
    *seen = reader_where(lx, kw);
    if (!*seen) return error_set(p->err, ST_INTERNAL, "out of memory");
    return ST_OK;
}

static double len_d(vec3 a) { return sqrt((double)a.x * a.x + (double)a.y * a.y + (double)a.z * a.z); }

static vec3 cross_d(vec3 a, vec3 b, double *length)
{
    double x = (double)a.y * b.z - (double)a.z * b.y;
    double y = (double)a.z * b.x - (double)a.x * b.z;
    double z = (double)a.x * b.y - (double)a.y * b.x;
    *length = sqrt(x * x + y * y + z * z);
    return v3((float)x, (float)y, (float)z);
}

/* ------------------------------------------------------------------ statements */

enum { CAM_FROM, CAM_AT, CAM_UP, CAM_FOV, CAM_APERTURE, CAM_FOCUS, CAM_N };
static const KeySpec camera_keys[CAM_N] = {
    [CAM_FROM] = {"from", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [CAM_AT] = {"at", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [CAM_UP] = {"up", VK_DIR, 0, 0, 0, 0, 0, NULL},
    [CAM_FOV] = {"fov", VK_NUMBER, 0, 0, 180, 1, 1, "a number of degrees in (0, 180)"},
    [CAM_APERTURE] = {"aperture", VK_NUMBER, 0, 0, INFINITY, 0, 1, "a number >= 0"},
    [CAM_FOCUS] = {"focus", VK_NUMBER, 0, 0, INFINITY, 1, 1, "a distance > 0"},
};

static Status parse_camera(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[CAM_N];
    Status st = once(p, lx, kw, &p->camera_at);
    if (!st) st = parse_block(p, lx, kw, 0, "camera", camera_keys, CAM_N, v);
    if (st) return st;
    SceneCamera *c = &p->s->camera;
    if (v[CAM_FROM].given) c->from = v[CAM_FROM].v;
    if (v[CAM_AT].given) c->at = v[CAM_AT].v;
    if (v[CAM_UP].given) c->up = v[CAM_UP].v;
    if (v[CAM_FOV].given) c->vfov = v[CAM_FOV].f;
    if (v[CAM_APERTURE].given) c->aperture = v[CAM_APERTURE].f;
    if (v[CAM_FOCUS].given) c->focus_dist = v[CAM_FOCUS].f;
    /* blame the key that made the camera invalid, or the block if the defaults did */
    const Token *view_tok = v[CAM_AT].given ? &v[CAM_AT].key : v[CAM_FROM].given ? &v[CAM_FROM].key : kw;
    vec3 dir = v3_sub(c->at, c->from);
    double dist = len_d(dir);
    if (!(dist > 0.0))
        return lex_error_at(lx, view_tok, p->err, "camera 'from' and 'at' are the same point");
    if (!isfinite(dist))
        return lex_error_at(lx, view_tok, p->err, "camera 'from' and 'at' are too far apart");
    double cl;
    cross_d(dir, c->up, &cl);
    /* sine of the angle between up and the view direction */
    if (!(cl / (dist * len_d(c->up)) > 1e-6))
        return lex_error_at(lx, v[CAM_UP].given ? &v[CAM_UP].key : view_tok, p->err,
                            "camera 'up' is parallel to the view direction (from 'from' to 'at')");
    double focus = camera_focus(c);
    if (focus < camera_min_focus(c->from))
        return lex_error_at(lx, v[CAM_FOCUS].given ? &v[CAM_FOCUS].key : view_tok, p->err,
                            "the camera's focus distance (%s) %g is too short for single precision "
                            "with a lens at 'from' %g %g %g: at least %g",
                            v[CAM_FOCUS].given ? "'focus'" : "from 'from' to 'at'", focus,
                            (double)c->from.x, (double)c->from.y, (double)c->from.z,
                            camera_min_focus(c->from));
    return ST_OK;
}

enum { IMG_WIDTH, IMG_HEIGHT, IMG_SPP, IMG_DEPTH, IMG_SEED, IMG_SHADOWS, IMG_SAMPLER, IMG_SPLIT, IMG_N };
static const KeySpec image_keys[IMG_N] = {
    [IMG_WIDTH] = {"width", VK_UINT, 0, 1, CLPT_MAX_SCENE_IMAGE_SIDE, 0, 0,
                   "an integer in 1.." CLPT_STR(CLPT_MAX_SCENE_IMAGE_SIDE)},
    [IMG_HEIGHT] = {"height", VK_UINT, 0, 1, CLPT_MAX_SCENE_IMAGE_SIDE, 0, 0,
                    "an integer in 1.." CLPT_STR(CLPT_MAX_SCENE_IMAGE_SIDE)},
    [IMG_SPP] = {"spp", VK_UINT, 0, 1, CLPT_MAX_SPP, 0, 0, "an integer in 1.." CLPT_STR(CLPT_MAX_SPP)},
    [IMG_DEPTH] = {"depth", VK_UINT, 0, 0, CLPT_MAX_DEPTH, 0, 0, "an integer in 0.." CLPT_STR(CLPT_MAX_DEPTH)},
    [IMG_SEED] = {"seed", VK_UINT, 0, 0, 4294967295.0, 0, 0, "an integer in 0..4294967295"},
    [IMG_SHADOWS] = {"shadows", VK_WORD, 0, 0, 0, 0, 0, "on or off"},
    [IMG_SAMPLER] = {"sampler", VK_WORD, 0, 0, 0, 0, 0, "sobol or independent"},
    [IMG_SPLIT] = {"split", VK_UINT, 0, 1, CLPT_MAX_SPLIT, 0, 0, "an integer in 1.." CLPT_STR(CLPT_MAX_SPLIT)},
};

static Status parse_image(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[IMG_N];
    Status st = once(p, lx, kw, &p->image_at);
    if (!st) st = parse_block(p, lx, kw, 0, "image", image_keys, IMG_N, v);
    if (st) return st;
    SceneImage *im = &p->s->image;
    if (v[IMG_WIDTH].given) im->width = (uint)v[IMG_WIDTH].u;
    if (v[IMG_HEIGHT].given) im->height = (uint)v[IMG_HEIGHT].u;
    if (v[IMG_SPP].given) im->spp = (uint)v[IMG_SPP].u;
    if (v[IMG_DEPTH].given) im->max_depth = (uint)v[IMG_DEPTH].u;
    if (v[IMG_SEED].given) im->seed = (uint)v[IMG_SEED].u;
    if (v[IMG_SPLIT].given) im->split = (uint)v[IMG_SPLIT].u;
    if (v[IMG_SHADOWS].given) {
        const Token *w = &v[IMG_SHADOWS].word;
        if (!tok_is(w, "on") && !tok_is(w, "off")) return lex_expected(lx, w, image_keys[IMG_SHADOWS].what, p->err);
        p->s->shadows = tok_is(w, "on");
    }
    if (v[IMG_SAMPLER].given) {
        const Token *w = &v[IMG_SAMPLER].word;
        if (!tok_is(w, "sobol") && !tok_is(w, "independent"))
            return lex_expected(lx, w, image_keys[IMG_SAMPLER].what, p->err);
        im->sampler = tok_is(w, "sobol") ? SAMPLER_SOBOL : SAMPLER_INDEPENDENT;
    }
    /* a size the command line replaces is checked after it (host/main.c): --width 64
     * --height 64 renders a scene whose own image is too large */
    if (!p->s->size_overridden && limit_pixels(im->width, im->height, ST_INPUT, "", NULL) != ST_OK) {
        const Token *t = v[IMG_HEIGHT].given ? &v[IMG_HEIGHT].key : &v[IMG_WIDTH].key;
        return lex_error_at(lx, t, p->err,
                            "an image of %ux%u pixels is larger than clpt renders (at most %u pixels, as in "
                            "16384x8192, and %d on each side); --width and --height render it smaller",
                            im->width, im->height, CLPT_MAX_PIXELS, CLPT_MAX_IMAGE_SIDE);
    }
    return ST_OK;
}

enum { BG_COLOR, BG_HORIZON, BG_ZENITH, BG_AMBIENT, BG_CUBE, BG_MAP_KEY, BG_INTENSITY, BG_ROTATE, BG_N };
static const KeySpec background_keys[BG_N] = {
    [BG_COLOR] = {"color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [BG_HORIZON] = {"horizon", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [BG_ZENITH] = {"zenith", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [BG_AMBIENT] = {"ambient", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [BG_CUBE] = {"cubemap", VK_PATH, 0, 0, 0, 0, 0, NULL},
    [BG_MAP_KEY] = {"map", VK_PATH, 0, 0, 0, 0, 0, NULL},
    [BG_INTENSITY] = {"intensity", VK_NUMBER, 0, 0, 1e30, 0, 0, "a number in [0, 1e30]"},
    [BG_ROTATE] = {"rotate", VK_NUMBER, 0, -1e6, 1e6, 0, 0, "a number of degrees in [-1e6, 1e6]"},
};

/* `map "FILE"`: an equirectangular environment map (kernels/envmap.h), the file found
 * beside the scene file, a high-dynamic-range image (.hdr, .exr). */
static Status parse_background_map(Parser *p, Lexer *lx, const Value *v)
{
    const Token *f = &v[BG_MAP_KEY].word;
    char *path = path_beside(lx->path, f->text, f->len);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    uint tex;
    Status st = texture_load_image(p->s, NULL, path, 1, 0, &tex, p->err);
    free(path);
    if (!st) st = scene_set_envmap(p->s, tex, v[BG_INTENSITY].given ? v[BG_INTENSITY].f : 1.0f,
                                   v[BG_ROTATE].given ? v[BG_ROTATE].f : 0.0f, p->err);
    if (st == ST_IO || st == ST_INPUT) reader_annotate(lx, f, p->err);
    return st;
}

/* `cubemap "DIR"`: the classic format's cube map (six images, the MIT 6.837 course's
 * names and orientation; host/io/texture.c), the folder found beside the scene file. */
static Status parse_background_cubemap(Parser *p, Lexer *lx, const Value *v)
{
    const Token *f = &v->word;
    char *path = path_beside(lx->path, f->text, f->len);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    uint first;
    Status st = texture_load_cubemap(p->s, path, &first, p->err);
    free(path);
    if (st == ST_IO || st == ST_INPUT) reader_annotate(lx, f, p->err);
    if (st) return st;
    p->s->bg_type = BG_CUBEMAP;
    p->s->bg_cubemap = first;
    return ST_OK;
}

static Status parse_background(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[BG_N];
    Status st = once(p, lx, kw, &p->background_at);
    if (!st) st = parse_block(p, lx, kw, 0, "background", background_keys, BG_N, v);
    if (st) return st;
    Scene *s = p->s;
    if (v[BG_AMBIENT].given) s->ambient = v[BG_AMBIENT].v;   /* the whitted integrator's */
    int sky = v[BG_HORIZON].given || v[BG_ZENITH].given;
    if (!v[BG_MAP_KEY].given && (v[BG_INTENSITY].given || v[BG_ROTATE].given)) {
        const Token *t = v[BG_INTENSITY].given ? &v[BG_INTENSITY].key : &v[BG_ROTATE].key;
        return lex_error_at(lx, t, p->err, "'%s' belongs to an environment map: the background block needs 'map'",
                            v[BG_INTENSITY].given ? "intensity" : "rotate");
    }
    if (v[BG_MAP_KEY].given && (v[BG_COLOR].given || sky || v[BG_CUBE].given))
        return lex_error_at(lx, &v[BG_MAP_KEY].key, p->err,
                            "a background is either 'map', 'cubemap' or a colour ('color', or 'horizon' and "
                            "'zenith'), not several");
    if (v[BG_MAP_KEY].given) return parse_background_map(p, lx, v);
    if (v[BG_CUBE].given && (v[BG_COLOR].given || sky))
        return lex_error_at(lx, &v[BG_CUBE].key, p->err,
                            "a background is either 'cubemap' or a colour ('color', or 'horizon' and "
                            "'zenith'), not both");
    if (v[BG_CUBE].given) return parse_background_cubemap(p, lx, &v[BG_CUBE]);
    if (v[BG_COLOR].given && sky) {
        const Token *t = v[BG_HORIZON].given ? &v[BG_HORIZON].key : &v[BG_ZENITH].key;
        if (t->line < v[BG_COLOR].key.line ||
            (t->line == v[BG_COLOR].key.line && t->col < v[BG_COLOR].key.col))
            t = &v[BG_COLOR].key;
        return lex_error_at(lx, t, p->err,
                            "a background is either 'color' (constant) or 'horizon' and "
                            "'zenith' (sky), not both");
    }
    if (!v[BG_COLOR].given && !sky)
        return lex_error_at(lx, kw, p->err,
                            "the background block needs 'color', or 'horizon' and 'zenith', "
                            "or 'cubemap', or 'map'");
    if (sky && !(v[BG_HORIZON].given && v[BG_ZENITH].given))
        return lex_error_at(lx, kw, p->err, "a sky background needs both 'horizon' and 'zenith'");
    if (sky) {
        s->bg_type = BG_SKY;
        s->bg_color = v[BG_HORIZON].v;
        s->bg_zenith = v[BG_ZENITH].v;
    } else {
        s->bg_type = BG_CONSTANT;
        s->bg_color = v[BG_COLOR].v;
        s->bg_zenith = v[BG_COLOR].v;
    }
    return ST_OK;
}

enum { MAT_KEY_TYPE, MAT_KEY_ALBEDO, MAT_KEY_FUZZ, MAT_KEY_IOR, MAT_KEY_RADIANCE, MAT_KEY_EMISSION, MAT_KEY_SIDES,
       MAT_KEY_SPECULAR, MAT_KEY_SHININESS, MAT_KEY_REFLECTIVE, MAT_KEY_TRANSPARENT, MAT_KEY_TEXTURE,
       MAT_KEY_ROUGHNESS, MAT_KEY_ANISOTROPY, MAT_KEY_ETA, MAT_KEY_K, MAT_KEY_METAL, MAT_KEY_THIN,
       MAT_KEY_METALLIC, MAT_KEY_TRANSMISSION, MAT_KEY_CLEARCOAT, MAT_KEY_CLEARCOAT_ROUGHNESS, MAT_KEY_STRENGTH,
       MAT_KEY_METALLIC_ROUGHNESS, MAT_KEY_NORMAL_MAP, MAT_KEY_NORMAL_SCALE, MAT_KEY_ALPHA, MAT_KEY_ALPHA_MODE,
       MAT_KEY_ALPHA_CUTOFF, MAT_KEY_EMISSION_TEXTURE, MAT_KEY_ATTENUATION_COLOR, MAT_KEY_ATTENUATION_DISTANCE,
       MAT_KEY_SPECULAR_FACTOR, MAT_KEY_SPECULAR_COLOR, MAT_KEY_SHEEN_COLOR, MAT_KEY_SHEEN_ROUGHNESS, MAT_KEY_N };
static const KeySpec material_keys[MAT_KEY_N] = {
    [MAT_KEY_TYPE] = {"type", VK_WORD, 1, 0, 0, 0, 0,
                      "a material type (diffuse, metal, conductor, dielectric, principled, emissive, phong)"},
    [MAT_KEY_ALBEDO] = {"albedo", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_FUZZ] = {"fuzz", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_IOR] = {"ior", VK_NUMBER, 0, 0, INFINITY, 1, 1, "a number > 0"},
    [MAT_KEY_RADIANCE] = {"radiance", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_EMISSION] = {"emission", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SIDES] = {"sides", VK_UINT, 0, 1, 2, 0, 0, "1 or 2 (the sides that emit)"},
    [MAT_KEY_SPECULAR] = {"specular", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SHININESS] = {"shininess", VK_NUMBER, 0, 0, 1e6, 0, 0, "a number in [0, 1e6]"},
    [MAT_KEY_REFLECTIVE] = {"reflective", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_TRANSPARENT] = {"transparent", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_TEXTURE] = {"texture", VK_TEXTURE, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_ROUGHNESS] = {"roughness", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_ANISOTROPY] = {"anisotropy", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_ETA] = {"eta", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_K] = {"k", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_METAL] = {"metal", VK_WORD, 0, 0, 0, 0, 0, "a metal (Ag, Al, Au, Cr, Cu, Fe, Ni, Ti)"},
    [MAT_KEY_THIN] = {"thin", VK_WORD, 0, 0, 0, 0, 0, "on or off"},
    [MAT_KEY_METALLIC] = {"metallic", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_TRANSMISSION] = {"transmission", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_CLEARCOAT] = {"clearcoat", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_CLEARCOAT_ROUGHNESS] = {"clearcoat_roughness", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_STRENGTH] = {"strength", VK_NUMBER, 0, 0, 1e6, 0, 0, "a number in [0, 1e6]"},
    [MAT_KEY_METALLIC_ROUGHNESS] = {"metallic_roughness", VK_TEXTURE, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_NORMAL_MAP] = {"normal_map", VK_TEXTURE, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_NORMAL_SCALE] = {"normal_scale", VK_NUMBER, 0, 0, 100, 0, 0, "a number in [0, 100]"},
    [MAT_KEY_ALPHA] = {"alpha", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_ALPHA_MODE] = {"alpha_mode", VK_WORD, 0, 0, 0, 0, 0, "opaque, mask or blend"},
    [MAT_KEY_ALPHA_CUTOFF] = {"alpha_cutoff", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_EMISSION_TEXTURE] = {"emission_texture", VK_TEXTURE, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_ATTENUATION_COLOR] = {"attenuation_color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_ATTENUATION_DISTANCE] = {"attenuation_distance", VK_NUMBER, 0, 0, INFINITY, 1, 0,
                                      "a number > 0"},
    [MAT_KEY_SPECULAR_FACTOR] = {"specular_factor", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_SPECULAR_COLOR] = {"specular_color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SHEEN_COLOR] = {"sheen_color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SHEEN_ROUGHNESS] = {"sheen_roughness", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
};

/* Which keys each material type takes (bit i = material_keys[i]), and which it needs. */
static const struct {
    const char *name;
    uint type;
    unsigned long long allowed, required;   /* MAT_KEY_N > 32 */
} material_types[] = {
    {"diffuse", MAT_DIFFUSE,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_EMISSION | 1ull << MAT_KEY_SIDES | 1ull << MAT_KEY_TEXTURE,
     1ull << MAT_KEY_ALBEDO},
    {"metal", MAT_METAL,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_FUZZ | 1ull << MAT_KEY_EMISSION | 1ull << MAT_KEY_SIDES |
     1ull << MAT_KEY_TEXTURE,
     1ull << MAT_KEY_ALBEDO},
    {"conductor", MAT_CONDUCTOR,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_TEXTURE | 1ull << MAT_KEY_ETA | 1ull << MAT_KEY_K | 1ull << MAT_KEY_METAL |
     1ull << MAT_KEY_SPECULAR | 1ull << MAT_KEY_ROUGHNESS | 1ull << MAT_KEY_ANISOTROPY | 1ull << MAT_KEY_EMISSION |
     1ull << MAT_KEY_SIDES,
     0},
    {"dielectric", MAT_DIELECTRIC,
     1ull << MAT_KEY_IOR | 1ull << MAT_KEY_ROUGHNESS | 1ull << MAT_KEY_ANISOTROPY | 1ull << MAT_KEY_THIN |
     1ull << MAT_KEY_EMISSION | 1ull << MAT_KEY_SIDES, 0},
    {"principled", MAT_PRINCIPLED,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_TEXTURE | 1ull << MAT_KEY_METALLIC | 1ull << MAT_KEY_ROUGHNESS |
     1ull << MAT_KEY_ANISOTROPY | 1ull << MAT_KEY_TRANSMISSION | 1ull << MAT_KEY_IOR | 1ull << MAT_KEY_THIN |
     1ull << MAT_KEY_CLEARCOAT | 1ull << MAT_KEY_CLEARCOAT_ROUGHNESS | 1ull << MAT_KEY_EMISSION | 1ull << MAT_KEY_STRENGTH |
     1ull << MAT_KEY_METALLIC_ROUGHNESS | 1ull << MAT_KEY_NORMAL_MAP | 1ull << MAT_KEY_NORMAL_SCALE | 1ull << MAT_KEY_SIDES |
     1ull << MAT_KEY_ALPHA | 1ull << MAT_KEY_ALPHA_MODE | 1ull << MAT_KEY_ALPHA_CUTOFF | 1ull << MAT_KEY_EMISSION_TEXTURE |
     1ull << MAT_KEY_ATTENUATION_COLOR | 1ull << MAT_KEY_ATTENUATION_DISTANCE | 1ull << MAT_KEY_SPECULAR_FACTOR |
     1ull << MAT_KEY_SPECULAR_COLOR | 1ull << MAT_KEY_SHEEN_COLOR | 1ull << MAT_KEY_SHEEN_ROUGHNESS,
     0},
    {"emissive", MAT_EMISSIVE, 1ull << MAT_KEY_RADIANCE | 1ull << MAT_KEY_SIDES, 1ull << MAT_KEY_RADIANCE},
    {"phong", MAT_PHONG,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_SPECULAR | 1ull << MAT_KEY_SHININESS | 1ull << MAT_KEY_REFLECTIVE |
     1ull << MAT_KEY_TRANSPARENT | 1ull << MAT_KEY_IOR | 1ull << MAT_KEY_TEXTURE | 1ull << MAT_KEY_EMISSION |
     1ull << MAT_KEY_SIDES,
     1ull << MAT_KEY_ALBEDO},
};
#define N_MATERIAL_TYPES (sizeof material_types / sizeof material_types[0])

/* A conductor's Fresnel term: exactly one of a preset (`metal`), a complex index (`eta`
 * with `k`) or an artist's reflectance at normal incidence (`specular`). */
static Status parse_conductor(Parser *p, Lexer *lx, const Token *kw, const Value *v, Material *m)
{
    int n = v[MAT_KEY_METAL].given + (v[MAT_KEY_ETA].given || v[MAT_KEY_K].given) + v[MAT_KEY_SPECULAR].given;
    if (n != 1)
        return lex_error_at(lx, kw, p->err,
                            "a conductor needs exactly one of 'metal', 'eta' and 'k', or 'specular'");
    if (v[MAT_KEY_ETA].given != v[MAT_KEY_K].given)
        return lex_error_at(lx, v[MAT_KEY_ETA].given ? &v[MAT_KEY_ETA].key : &v[MAT_KEY_K].key, p->err,
                            "a conductor's 'eta' needs its 'k' (the complex index eta + i k)");
    if (v[MAT_KEY_SPECULAR].given) {
        *m = material_conductor_f0(v[MAT_KEY_SPECULAR].v, 0.0f);
    } else if (v[MAT_KEY_METAL].given) {
        const Token *w = &v[MAT_KEY_METAL].word;
        vec3 eta, k;
        if (!material_metal_preset(w->text, w->len, &eta, &k))
            return lex_expected(lx, w, material_keys[MAT_KEY_METAL].what, p->err);
        *m = material_conductor(eta, k, 0.0f);
    } else {
        *m = material_conductor(v[MAT_KEY_ETA].v, v[MAT_KEY_K].v, 0.0f);
    }
    if (v[MAT_KEY_ALBEDO].given) m->albedo = v[MAT_KEY_ALBEDO].v;
    return ST_OK;
}

/* glTF's alpha: `alpha` (baseColorFactor's A, times the base-colour texture's alpha),
 * `alpha_mode` opaque (default; alpha ignored), mask (cut out below `alpha_cutoff`,
 * default 0.5) or blend (stochastic opacity). A cutoff means nothing outside mask, so it
 * is refused there rather than silently ignored. */
static Status parse_alpha(Parser *p, Lexer *lx, const Value *v, Material *m)
{
    if (v[MAT_KEY_ALPHA].given) m->alpha = v[MAT_KEY_ALPHA].f;
    uint mode = 0u;
    if (v[MAT_KEY_ALPHA_MODE].given) {
        const Token *w = &v[MAT_KEY_ALPHA_MODE].word;
        if (tok_is(w, "mask")) mode = MAT_ALPHA_MASK;
        else if (tok_is(w, "blend")) mode = MAT_ALPHA_BLEND;
        else if (!tok_is(w, "opaque")) return lex_expected(lx, w, material_keys[MAT_KEY_ALPHA_MODE].what, p->err);
    }
    if (v[MAT_KEY_ALPHA_CUTOFF].given && mode != MAT_ALPHA_MASK)
        return lex_error_at(lx, &v[MAT_KEY_ALPHA_CUTOFF].key, p->err,
                            "'alpha_cutoff' needs 'alpha_mode mask'");
    if (v[MAT_KEY_ALPHA_CUTOFF].given) m->alpha_cutoff = v[MAT_KEY_ALPHA_CUTOFF].f;
    m->flags |= mode;
    return ST_OK;
}

/* The principled keys of the glTF extensions: KHR_materials_volume's attenuation (read
 * in a solid, `thin off`), KHR_materials_specular's factor and colour, and
 * KHR_materials_sheen's colour and roughness. */
static void parse_principled_layers(const Value *v, Material *m)
{
    vec3 color = v[MAT_KEY_ATTENUATION_COLOR].given ? v[MAT_KEY_ATTENUATION_COLOR].v : v3s(1.0f);
    float distance = v[MAT_KEY_ATTENUATION_DISTANCE].given ? v[MAT_KEY_ATTENUATION_DISTANCE].f : INFINITY;
    m->absorption = material_absorption(color, distance);
    if (v[MAT_KEY_SPECULAR_FACTOR].given) m->specular_factor = v[MAT_KEY_SPECULAR_FACTOR].f;
    if (v[MAT_KEY_SPECULAR_COLOR].given) m->specular_color = v[MAT_KEY_SPECULAR_COLOR].v;
    if (v[MAT_KEY_SHEEN_COLOR].given) m->sheen_color = v[MAT_KEY_SHEEN_COLOR].v;
    if (v[MAT_KEY_SHEEN_ROUGHNESS].given) m->sheen_roughness = v[MAT_KEY_SHEEN_ROUGHNESS].f;
}

/* Reads a material's `{ ... }`; a NULL name makes an anonymous (inline) material. */
static Status parse_material_block(Parser *p, Lexer *lx, const Token *kw, int brace_taken,
                                   const char *name, uint *index)
{
    Value v[MAT_KEY_N];
    Status st = parse_block(p, lx, kw, brace_taken, "material", material_keys, MAT_KEY_N, v);
    if (st) return st;
    size_t ti;
    for (ti = 0; ti < N_MATERIAL_TYPES; ti++)
        if (tok_is(&v[MAT_KEY_TYPE].word, material_types[ti].name)) break;
    if (ti == N_MATERIAL_TYPES)
        return lex_expected(lx, &v[MAT_KEY_TYPE].word, material_keys[MAT_KEY_TYPE].what, p->err);
    unsigned long long allowed = material_types[ti].allowed | 1ull << MAT_KEY_TYPE;
    for (int i = 0; i < MAT_KEY_N; i++) {
        if (!v[i].given || (allowed & (1ull << i))) continue;
        char what[512];
        size_t o = (size_t)snprintf(what, sizeof what, "a %s material key (type",
                                    material_types[ti].name);
        for (int j = 1; j < MAT_KEY_N; j++)
            if (allowed & (1ull << j))
                o += (size_t)snprintf(what + o, sizeof what - o, ", %s", material_keys[j].key);
        snprintf(what + o, sizeof what - o, ") or '}'");
        return lex_expected(lx, &v[i].key, what, p->err);
    }
    for (int i = 0; i < MAT_KEY_N; i++)
        if ((material_types[ti].required & (1ull << i)) && !v[i].given)
            return lex_error_at(lx, kw, p->err, "a material of type %s needs '%s'",
                                material_types[ti].name, material_keys[i].key);
    Material m;
    switch (material_types[ti].type) {
    case MAT_CONDUCTOR:
        if ((st = parse_conductor(p, lx, kw, v, &m))) return st;
        break;
    case MAT_METAL:
        m = material_metal(v[MAT_KEY_ALBEDO].v, v[MAT_KEY_FUZZ].given ? v[MAT_KEY_FUZZ].f : 0.0f);
        break;
    case MAT_DIELECTRIC:
        m = material_dielectric(v[MAT_KEY_IOR].given ? v[MAT_KEY_IOR].f : 1.5f);
        break;
    case MAT_PRINCIPLED:
        m = material_principled(v[MAT_KEY_ALBEDO].given ? v[MAT_KEY_ALBEDO].v : v3s(1.0f),
                                v[MAT_KEY_METALLIC].given ? v[MAT_KEY_METALLIC].f : 1.0f,
                                v[MAT_KEY_ROUGHNESS].given ? v[MAT_KEY_ROUGHNESS].f : 1.0f);
        if (v[MAT_KEY_TRANSMISSION].given) m.transmission = v[MAT_KEY_TRANSMISSION].f;
        if (v[MAT_KEY_IOR].given) m.ior = v[MAT_KEY_IOR].f;
        if (v[MAT_KEY_CLEARCOAT].given) m.clearcoat = v[MAT_KEY_CLEARCOAT].f;
        if (v[MAT_KEY_CLEARCOAT_ROUGHNESS].given) m.clearcoat_roughness = v[MAT_KEY_CLEARCOAT_ROUGHNESS].f;
        if (v[MAT_KEY_METALLIC_ROUGHNESS].given) m.texture_rm = (uint)v[MAT_KEY_METALLIC_ROUGHNESS].u;
        if (v[MAT_KEY_NORMAL_MAP].given) m.texture_normal = (uint)v[MAT_KEY_NORMAL_MAP].u;
        if (v[MAT_KEY_NORMAL_SCALE].given) m.normal_scale = v[MAT_KEY_NORMAL_SCALE].f;
        if (v[MAT_KEY_EMISSION_TEXTURE].given) m.texture_emission = (uint)v[MAT_KEY_EMISSION_TEXTURE].u;
        if ((st = parse_alpha(p, lx, v, &m))) return st;
        parse_principled_layers(v, &m);
        break;
    case MAT_EMISSIVE:
        m = material_emissive(v[MAT_KEY_RADIANCE].v);
        break;
    case MAT_PHONG:
        m = material_phong(v[MAT_KEY_ALBEDO].v, v[MAT_KEY_SPECULAR].given ? v[MAT_KEY_SPECULAR].v : v3s(0.0f),
                           v[MAT_KEY_SHININESS].given ? v[MAT_KEY_SHININESS].f : 0.0f);
        if (v[MAT_KEY_REFLECTIVE].given) m.reflective = v[MAT_KEY_REFLECTIVE].v;
        if (v[MAT_KEY_TRANSPARENT].given) m.transparent = v[MAT_KEY_TRANSPARENT].v;
        m.ior = v[MAT_KEY_IOR].given ? v[MAT_KEY_IOR].f : 1.5f;
        break;
    default:
        m = material_diffuse(v[MAT_KEY_ALBEDO].v);
        break;
    }
    if (v[MAT_KEY_THIN].given) {
        const Token *w = &v[MAT_KEY_THIN].word;
        if (!tok_is(w, "on") && !tok_is(w, "off"))
            return lex_expected(lx, w, material_keys[MAT_KEY_THIN].what, p->err);
        if (tok_is(w, "on")) m.flags |= MAT_THIN;
    }
    /* a surface that both reflects and glows (the furnace test's sphere); glTF's
     * emissive factor times KHR_materials_emissive_strength */
    if (v[MAT_KEY_EMISSION].given) m.emission = v[MAT_KEY_EMISSION].v;
    if (v[MAT_KEY_STRENGTH].given) m.emission = v3_scale(m.emission, v[MAT_KEY_STRENGTH].f);
    if (v[MAT_KEY_SIDES].given && v[MAT_KEY_SIDES].u == 2) m.flags |= MAT_TWO_SIDED;
    if (v[MAT_KEY_TEXTURE].given) m.texture = (uint)v[MAT_KEY_TEXTURE].u;
    if (v[MAT_KEY_ROUGHNESS].given) m.roughness = v[MAT_KEY_ROUGHNESS].f;
    if (v[MAT_KEY_ANISOTROPY].given) m.anisotropy = v[MAT_KEY_ANISOTROPY].f;
    /* inline materials get the empty name, which no named material can have, so a
     * lookup never finds them */
    if ((st = scene_add_material(p->s, name ? name : "", m, index, p->err))) return st;
    if (array_reserve((void **)&p->material_at, &p->cap_material_at, p->s->n_materials,
                      sizeof(char *)))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    while (p->n_material_at < p->s->n_materials) p->material_at[p->n_material_at++] = NULL;
    /* only for messages: a failed copy just loses the "defined at" part */
    if (name) p->material_at[*index] = reader_where(lx, kw);
    return ST_OK;
}

static Status parse_material(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0)
        return lex_expected(lx, &t, "a material name", p->err);
    char *name = tok_copy(&t);
    if (!name) return error_set(p->err, ST_INTERNAL, "out of memory");
    uint prev = scene_find_material(p->s, name);
    if (prev != NO_INDEX) {
        char shown[64];
        tok_describe(&t, shown, sizeof shown);
        const char *where = prev < p->n_material_at ? p->material_at[prev] : NULL;
        st = lex_error_at(lx, &t, p->err, "material '%s' is already defined%s%s%s", shown,
                          where ? " (at " : "", where ? where : "", where ? ")" : "");
        free(name);
        return st;
    }
    uint index;
    st = parse_material_block(p, lx, kw, 0, name, &index);
    free(name);
    return st;
}

enum { SPH_CENTER, SPH_RADIUS, SPH_MATERIAL, SPH_N };
static const KeySpec sphere_keys[SPH_N] = {
    [SPH_CENTER] = {"center", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [SPH_RADIUS] = {"radius", VK_NUMBER, 1, 0, INFINITY, 1, 1, "a radius > 0"},
    [SPH_MATERIAL] = {"material", VK_MATERIAL, 1, 0, 0, 0, 0, NULL},
};

static Status parse_sphere(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[SPH_N];
    Status st = parse_block(p, lx, kw, 0, "sphere", sphere_keys, SPH_N, v);
    if (st) return st;
    vec3 c = v[SPH_CENTER].v;
    float r = v[SPH_RADIUS].f;
    /* a bounding box that overflows would leave the sphere out of the kd-tree */
    if (!isfinite(fabsf(c.x) + r) || !isfinite(fabsf(c.y) + r) || !isfinite(fabsf(c.z) + r))
        return lex_error_at(lx, &v[SPH_RADIUS].key, p->err,
                            "the sphere reaches beyond the largest float (about 3.4e38)");
    Sphere sp;
    memset(&sp, 0, sizeof sp);
    sp.center = c;
    sp.radius = r;
    sp.material = v[SPH_MATERIAL].material;
    return scene_add_sphere(p->s, sp, p->err);
}

enum { PL_POINT, PL_NORMAL, PL_MATERIAL, PL_N };
static const KeySpec plane_keys[PL_N] = {
    [PL_POINT] = {"point", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [PL_NORMAL] = {"normal", VK_DIR, 1, 0, 0, 0, 0, NULL},
    [PL_MATERIAL] = {"material", VK_MATERIAL, 1, 0, 0, 0, 0, NULL},
};

static Status parse_plane(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[PL_N];
    Status st = parse_block(p, lx, kw, 0, "plane", plane_keys, PL_N, v);
    if (st) return st;
    vec3 n = v[PL_NORMAL].v, q = v[PL_POINT].v;
    double len = len_d(n);
    if (!isfinite(len))
        return lex_error_at(lx, &v[PL_NORMAL].key, p->err, "plane 'normal' is too long to normalise");
    double nx = n.x / len, ny = n.y / len, nz = n.z / len;
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = v3((float)nx, (float)ny, (float)nz);
    pl.offset = (float)(nx * q.x + ny * q.y + nz * q.z);
    pl.material = v[PL_MATERIAL].material;
    return scene_add_plane(p->s, pl, p->err);
}

static Status add_triangle(Parser *p, const Lexer *lx, const Token *kw, vec3 a, vec3 b, vec3 c,
                           uint material, const char *which)
{
    double area2;
    cross_d(v3_sub(b, a), v3_sub(c, a), &area2);
    /* the kernels compute edges in float: corners 6e38 apart give infinite edges */
    if (isnan(area2) || isinf(area2))
        return lex_error_at(lx, kw, p->err, "%.*s: the corners %s are too far apart (their "
                            "differences overflow single precision)", (int)kw->len, kw->text, which);
    if (!(area2 > 0.0))
        return lex_error_at(lx, kw, p->err, "degenerate %.*s: the corners %s lie on one line",
                            (int)kw->len, kw->text, which);
    Triangle t;
    memset(&t, 0, sizeof t);
    t.p0 = a;
    t.p1 = b;
    t.p2 = c;
    t.material = material;
    t.shading = NO_INDEX;
    return scene_add_triangle(p->s, t, p->err);
}

enum { TRI_V0, TRI_V1, TRI_V2, TRI_V3, TRI_MATERIAL, TRI_N };
static const KeySpec triangle_keys[TRI_N - 1] = {
    {"v0", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    {"v1", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    {"v2", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    {"material", VK_MATERIAL, 1, 0, 0, 0, 0, NULL},
};
static const KeySpec quad_keys[TRI_N] = {
    [TRI_V0] = {"v0", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [TRI_V1] = {"v1", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [TRI_V2] = {"v2", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [TRI_V3] = {"v3", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [TRI_MATERIAL] = {"material", VK_MATERIAL, 1, 0, 0, 0, 0, NULL},
};

static Status parse_triangle(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[TRI_N - 1];
    Status st = parse_block(p, lx, kw, 0, "triangle", triangle_keys, TRI_N - 1, v);
    if (st) return st;
    return add_triangle(p, lx, kw, v[0].v, v[1].v, v[2].v, v[3].material, "v0 v1 v2");
}

static Status parse_quad(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[TRI_N];
    Status st = parse_block(p, lx, kw, 0, "quad", quad_keys, TRI_N, v);
    if (st) return st;
    uint m = v[TRI_MATERIAL].material;
    st = add_triangle(p, lx, kw, v[TRI_V0].v, v[TRI_V1].v, v[TRI_V2].v, m, "v0 v1 v2");
    if (!st) st = add_triangle(p, lx, kw, v[TRI_V0].v, v[TRI_V2].v, v[TRI_V3].v, m, "v0 v2 v3");
    return st;
}

enum { BOX_MIN, BOX_MAX, BOX_MATERIAL, BOX_N };
static const KeySpec box_keys[BOX_N] = {
    [BOX_MIN] = {"min", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [BOX_MAX] = {"max", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [BOX_MATERIAL] = {"material", VK_MATERIAL, 1, 0, 0, 0, 0, NULL},
};

static Status parse_box(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[BOX_N];
    Status st = parse_block(p, lx, kw, 0, "box", box_keys, BOX_N, v);
    if (st) return st;
    vec3 lo = v[BOX_MIN].v, hi = v[BOX_MAX].v;
    static const char axis[3] = {'x', 'y', 'z'};
    for (int i = 0; i < 3; i++)
        if (!(v3_get(lo, i) < v3_get(hi, i)))
            return lex_error_at(lx, &v[BOX_MAX].key, p->err,
                                "box 'max' must be greater than 'min' on every axis, "
                                "but on %c it is %.9g <= %.9g",
                                axis[i], (double)v3_get(hi, i), (double)v3_get(lo, i));
    Box b;
    memset(&b, 0, sizeof b);
    b.lo = lo;
    b.hi = hi;
    b.material = v[BOX_MATERIAL].material;
    return scene_add_box(p->s, b, p->err);
}

enum { MESH_FILE, MESH_MATERIAL, MESH_TRANSLATE, MESH_ROTATE, MESH_RX, MESH_RY, MESH_RZ, MESH_SCALE,
       MESH_MATRIX, MESH_N };
static const KeySpec mesh_keys[MESH_N] = {
    [MESH_FILE] = {"file", VK_PATH, 1, 0, 0, 0, 0, NULL},
    [MESH_MATERIAL] = {"material", VK_MATERIAL, 0, 0, 0, 0, 0, NULL},
    [MESH_TRANSLATE] = {"translate", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [MESH_ROTATE] = {"rotate", VK_ROTATE, 0, 0, 0, 0, 0, NULL},
    [MESH_RX] = {"rx", VK_NUMBER, 0, -INFINITY, INFINITY, 0, 0, "an angle in degrees"},
    [MESH_RY] = {"ry", VK_NUMBER, 0, -INFINITY, INFINITY, 0, 0, "an angle in degrees"},
    [MESH_RZ] = {"rz", VK_NUMBER, 0, -INFINITY, INFINITY, 0, 0, "an angle in degrees"},
    [MESH_SCALE] = {"scale", VK_SCALE, 0, 0, 0, 0, 0, NULL},
    [MESH_MATRIX] = {"matrix", VK_MATRIX, 0, 0, 0, 0, 0, NULL},
};

/* The instance transform of a mesh block: scale, then rotate, rx, ry, rz, then
 * translate; or a whole affine matrix, which excludes the others. */
static Status mesh_transform(Parser *p, const Lexer *lx, const Token *kw, const Value *v, Transform *out)
{
    Transform t = transform_identity();
    if (v[MESH_MATRIX].given) {
        for (int i = MESH_TRANSLATE; i < MESH_MATRIX; i++)
            if (v[i].given) {
                const Token *later = &v[i].key;
                if (v[MESH_MATRIX].key.line > later->line ||
                    (v[MESH_MATRIX].key.line == later->line && v[MESH_MATRIX].key.col > later->col))
                    later = &v[MESH_MATRIX].key;
                return lex_error_at(lx, later, p->err,
                                    "'matrix' cannot be combined with translate, rotate, rx, ry, rz or scale "
                                    "(fold them into the matrix)");
            }
        const float *a = v[MESH_MATRIX].a;
        if (a[12] != 0.0f || a[13] != 0.0f || a[14] != 0.0f || a[15] != 1.0f)
            return lex_error_at(lx, &v[MESH_MATRIX].key, p->err,
                                "the last row of 'matrix' must be 0 0 0 1 (an affine transform), found "
                                "%g %g %g %g", (double)a[12], (double)a[13], (double)a[14], (double)a[15]);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) t.m[i][j] = a[4 * i + j];
    } else {
        if (v[MESH_SCALE].given) {
            const float *a = v[MESH_SCALE].a;
            t = transform_scale(a[0], a[1], a[2]);
        }
        Transform r;
        if (v[MESH_ROTATE].given) {
            const float *a = v[MESH_ROTATE].a;
            r = transform_rotate(a[0], a[1], a[2], a[3]);
            t = transform_compose(&r, &t);
        }
        for (int axis = 0; axis < 3; axis++) {
            const Value *rv = &v[MESH_RX + axis];
            if (!rv->given) continue;
            r = transform_rotate(axis == 0, axis == 1, axis == 2, rv->f);
            t = transform_compose(&r, &t);
        }
        if (v[MESH_TRANSLATE].given) {
            vec3 d = v[MESH_TRANSLATE].v;
            r = transform_translate(d.x, d.y, d.z);
            t = transform_compose(&r, &t);
        }
    }
    double det = transform_det(&t);
    if (!(fabs(det) > 1e-300) || !isfinite(det)) {
        const Token *at = v[MESH_MATRIX].given ? &v[MESH_MATRIX].key : v[MESH_SCALE].given ? &v[MESH_SCALE].key : kw;
        return lex_error_at(lx, at, p->err, "the mesh transform is singular (it flattens the mesh)");
    }
    *out = t;
    return ST_OK;
}

/* A mesh too small for single precision shades black or vanishes (a mesh 1e-30
 * across): refused when most of its triangles' normals underflow (a few slivers in a
 * mesh of normal size are harmless, and only those are lost). */
static Status check_mesh_size(Parser *p, const Lexer *lx, const Token *f, const char *path, size_t first)
{
    size_t tiny, with_area;
    vec3 lo, hi;
    scene_count_tiny_triangles(p->s, first, p->s->n_triangles, &tiny, &with_area, &lo, &hi);
    if (tiny == 0 || tiny * 2 < with_area) return ST_OK;
    return lex_error_at(lx, f, p->err, "the mesh '%s' is too small for single precision: %zu of its %zu "
                        "triangles have normals that underflow (it spans %g x %g x %g after its transform); "
                        "scale it up", path, tiny, with_area, (double)(hi.x - lo.x), (double)(hi.y - lo.y),
                        (double)(hi.z - lo.z));
}

static Status parse_mesh(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[MESH_N];
    Status st = parse_block(p, lx, kw, 0, "mesh", mesh_keys, MESH_N, v);
    if (st) return st;
    const Token *f = &v[MESH_FILE].word;
    MeshOptions o = mesh_options(v[MESH_MATERIAL].given ? v[MESH_MATERIAL].material : NO_INDEX);
    if ((st = mesh_transform(p, lx, kw, v, &o.xf))) return st;
    char *path = path_beside(lx->path, f->text, f->len);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    if (mesh_kind(path) == MESH_NONE) {
        free(path);
        return lex_expected(lx, f, "a mesh file name ending in .obj, .ply, .obj.gz, .ply.gz, .gltf or .glb", p->err);
    }
    size_t first = p->s->n_triangles;
    st = mesh_load(path, p->s, &o, p->err);
    if (st) reader_note_nested(lx, f, kw, "in the mesh of", st, p->err);
    else st = check_mesh_size(p, lx, f, path, first);
    free(path);
    return st;
}

/* ------------------------------------------------------------------ lights, textures */

enum { LT_TYPE, LT_POSITION, LT_DIRECTION, LT_INTENSITY, LT_ATTEN, LT_ANGLE, LT_INNER, LT_N };
static const KeySpec light_keys[LT_N] = {
    [LT_TYPE] = {"type", VK_WORD, 1, 0, 0, 0, 0, "a light type (point, spot, directional)"},
    [LT_POSITION] = {"position", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [LT_DIRECTION] = {"direction", VK_DIR, 0, 0, 0, 0, 0, NULL},
    [LT_INTENSITY] = {"intensity", VK_COLOR, 1, 0, 0, 0, 0, NULL},
    [LT_ATTEN] = {"attenuation", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [LT_ANGLE] = {"angle", VK_NUMBER, 0, 0, 180, 1, 1, "a number of degrees in (0, 180)"},
    [LT_INNER] = {"inner", VK_NUMBER, 0, 0, 180, 0, 1, "a number of degrees in [0, 180)"},
};

static Status parse_light(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[LT_N];
    Status st = parse_block(p, lx, kw, 0, "light", light_keys, LT_N, v);
    if (st) return st;
    static const struct { const char *name; uint type; unsigned allowed; } types[] = {
        {"point", LIGHT_POINT, 1u << LT_POSITION | 1u << LT_ATTEN},
        {"spot", LIGHT_SPOT, 1u << LT_POSITION | 1u << LT_DIRECTION | 1u << LT_ATTEN | 1u << LT_ANGLE | 1u << LT_INNER},
        {"directional", LIGHT_DIRECTIONAL, 1u << LT_DIRECTION},
    };
    size_t ti;
    for (ti = 0; ti < 3; ti++)
        if (tok_is(&v[LT_TYPE].word, types[ti].name)) break;
    if (ti == 3) return lex_expected(lx, &v[LT_TYPE].word, light_keys[LT_TYPE].what, p->err);
    unsigned allowed = types[ti].allowed | 1u << LT_TYPE | 1u << LT_INTENSITY;
    for (int i = 0; i < LT_N; i++)
        if (v[i].given && !(allowed & (1u << i)))
            return lex_error_at(lx, &v[i].key, p->err, "a %s light has no '%s'", types[ti].name, light_keys[i].key);
    Light l = light_default(types[ti].type);
    l.intensity = v[LT_INTENSITY].v;
    if (v[LT_POSITION].given) l.position = v[LT_POSITION].v;
    if (v[LT_DIRECTION].given) {
        vec3 d = v[LT_DIRECTION].v;
        double len = len_d(d);
        l.direction = v3((float)(d.x / len), (float)(d.y / len), (float)(d.z / len));
    }
    if (v[LT_ATTEN].given) {
        if (v3_is_zero(v[LT_ATTEN].v))
            return lex_error_at(lx, &v[LT_ATTEN].key, p->err, "'attenuation' (constant linear quadratic) must not be all 0");
        l.atten0 = v[LT_ATTEN].v.x;
        l.atten1 = v[LT_ATTEN].v.y;
        l.atten2 = v[LT_ATTEN].v.z;
    }
    float outer = v[LT_ANGLE].given ? v[LT_ANGLE].f : 30.0f, inner = v[LT_INNER].given ? v[LT_INNER].f : outer;
    if (inner > outer) return lex_error_at(lx, &v[LT_INNER].key, p->err, "'inner' must not exceed 'angle'");
    l.cos_outer = (float)cos((double)outer * M_PI / 180.0);
    l.cos_inner = (float)cos((double)inner * M_PI / 180.0);
    return scene_add_light(p->s, l, p->err);
}

enum { TX_TYPE, TX_FILE, TX_ENCODING, TX_WRAP, TX_COLOR0, TX_COLOR1, TX_SPACE, TX_SCALE, TX_N };
static const KeySpec texture_keys[TX_N] = {
    [TX_TYPE] = {"type", VK_WORD, 1, 0, 0, 0, 0, "a texture type (image, checker)"},
    [TX_FILE] = {"file", VK_PATH, 0, 0, 0, 0, 0, NULL},
    [TX_ENCODING] = {"encoding", VK_WORD, 0, 0, 0, 0, 0, "srgb or linear"},
    [TX_WRAP] = {"wrap", VK_WORD, 0, 0, 0, 0, 0, "repeat or clamp"},
    [TX_COLOR0] = {"color0", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [TX_COLOR1] = {"color1", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [TX_SPACE] = {"space", VK_WORD, 0, 0, 0, 0, 0, "uv or solid"},
    /* TEXTURE_MAX_MAP_ENTRY: a larger scale leaves no fraction to pick a texel by */
    [TX_SCALE] = {"scale", VK_NUMBER, 0, 0, TEXTURE_MAX_MAP_ENTRY, 1, 0, "a number in (0, 16777216]"},
};

static Status parse_texture(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0)
        return lex_expected(lx, &t, "a texture name", p->err);
    char *name = tok_copy(&t);
    if (!name) return error_set(p->err, ST_INTERNAL, "out of memory");
    if (scene_find_texture(p->s, name) != NO_INDEX) {
        char shown[64];
        tok_describe(&t, shown, sizeof shown);
        free(name);
        return lex_error_at(lx, &t, p->err, "texture '%s' is already defined", shown);
    }
    Value v[TX_N];
    if ((st = parse_block(p, lx, kw, 0, "texture", texture_keys, TX_N, v))) {
        free(name);
        return st;
    }
    int image = tok_is(&v[TX_TYPE].word, "image");
    unsigned allowed = 1u << TX_TYPE | 1u << TX_SCALE;
    if (image) allowed |= 1u << TX_FILE | 1u << TX_ENCODING | 1u << TX_WRAP;
    else if (tok_is(&v[TX_TYPE].word, "checker")) allowed |= 1u << TX_COLOR0 | 1u << TX_COLOR1 | 1u << TX_SPACE;
    else st = lex_expected(lx, &v[TX_TYPE].word, texture_keys[TX_TYPE].what, p->err);
    for (int i = 0; !st && i < TX_N; i++)
        if (v[i].given && !(allowed & (1u << i)))
            st = lex_error_at(lx, &v[i].key, p->err, "an %s texture has no '%s'", image ? "image" : "checker",
                              texture_keys[i].key);
    struct { int index; const char *a, *b; } words[] = {
        {TX_ENCODING, "srgb", "linear"}, {TX_WRAP, "repeat", "clamp"}, {TX_SPACE, "uv", "solid"} };
    int second[TX_N] = {0};
    for (size_t i = 0; !st && i < sizeof words / sizeof words[0]; i++) {
        const Value *w = &v[words[i].index];
        if (!w->given) continue;
        if (tok_is(&w->word, words[i].b)) second[words[i].index] = 1;
        else if (!tok_is(&w->word, words[i].a))
            st = lex_expected(lx, &w->word, texture_keys[words[i].index].what, p->err);
    }
    if (!st && image && !v[TX_FILE].given)
        st = lex_error_at(lx, kw, p->err, "an image texture needs 'file'");
    float scale = v[TX_SCALE].given ? v[TX_SCALE].f : 1.0f;
    if (!st && image) {
        const Token *f = &v[TX_FILE].word;
        char *path = path_beside(lx->path, f->text, f->len);
        if (!path) st = error_set(p->err, ST_INTERNAL, "out of memory");
        uint index;
        if (!st) st = texture_load_image(p->s, name, path, second[TX_ENCODING], second[TX_WRAP], &index, p->err);
        free(path);
        if (st == ST_IO || st == ST_INPUT) reader_annotate(lx, f, p->err);
        if (!st) texture_set_scale_offset(&p->s->textures[index], scale, scale, 0.0f, 0.0f);
    } else if (!st) {
        Texture tx = texture_make_checker(v[TX_COLOR0].given ? v[TX_COLOR0].v : v3s(0.8f),
                                     v[TX_COLOR1].given ? v[TX_COLOR1].v : v3s(0.2f), scale, second[TX_SPACE]);
        st = scene_add_texture(p->s, name, NULL, tx, NULL, p->err);
    }
    free(name);
    return st;
}

static Status parse_file(Parser *p, const char *path);

static Status parse_include(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0)
        return lex_expected(lx, &t, "a file name after 'include'", p->err);
    if (p->depth + 1 >= CLPT_MAX_INCLUDE_DEPTH) {
        p->depth_exceeded = 1;
        return lex_error_at(lx, kw, p->err,
                            "includes nested more than %d deep (does a file include itself?)",
                            CLPT_MAX_INCLUDE_DEPTH);
    }
    char *path = path_beside(lx->path, t.text, t.len);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    p->depth++;
    st = parse_file(p, path);
    p->depth--;
    free(path);
    if (st != ST_IO && p->depth_exceeded) return st;
    return reader_note_nested(lx, &t, kw, "included from", st, p->err);
}

static const struct {
    const char *keyword;
    Status (*parse)(Parser *p, Lexer *lx, const Token *kw);
} statements[] = {
    {"camera", parse_camera},   {"image", parse_image},       {"background", parse_background},
    {"material", parse_material}, {"sphere", parse_sphere},   {"plane", parse_plane},
    {"triangle", parse_triangle}, {"quad", parse_quad},       {"box", parse_box},
    {"mesh", parse_mesh},       {"include", parse_include},   {"light", parse_light},
    {"texture", parse_texture},
};
#define N_STATEMENTS (sizeof statements / sizeof statements[0])

static Status parse_statements(Parser *p, Lexer *lx)
{
    Status st;
    for (;;) {
        Token t;
        if ((st = lex_next(lx, &t, p->err)) || t.kind == TOK_EOF) break;
        size_t i = N_STATEMENTS;
        if (t.kind == TOK_WORD)
            for (i = 0; i < N_STATEMENTS; i++)
                if (tok_is(&t, statements[i].keyword)) break;
        if (i == N_STATEMENTS) {
            st = lex_expected(lx, &t,
                              "a statement (camera, image, background, material, sphere, "
                              "plane, triangle, quad, box, mesh, light, texture, include)", p->err);
            break;
        }
        if ((st = statements[i].parse(p, lx, &t))) break;
    }
    return st;
}

static Status parse_file(Parser *p, const char *path)
{
    Lexer lx;
    Status st = lex_open_file(&lx, path, p->err);
    if (st) return st;
    st = parse_statements(p, &lx);
    lex_close(&lx);
    return st;
}

/* scene_load and scene_load_text: `text` NULL reads the file `path`. */
static Status load(const char *path, const char *text, size_t len, Scene *s, Error *err)
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
    Status st;
    if (text) {
        Lexer lx;
        st = lex_open_text(&lx, path, text, len, err);
        if (!st) st = parse_statements(&p, &lx);
        lex_close(&lx);
    } else {
        st = parse_file(&p, path);
    }
    if (!st) st = scene_check_precision(s, err);
    free(p.camera_at);
    free(p.image_at);
    free(p.background_at);
    for (size_t i = 0; i < p.n_material_at; i++) free(p.material_at[i]);
    free(p.material_at);
    return st;
}

Status scene_load(const char *path, Scene *s, Error *err)
{
    return load(path, NULL, 0, s, err);
}

Status scene_load_text(const char *path, const char *text, size_t len, Scene *s, Error *err)
{
    return load(path, text, len, s, err);
}
