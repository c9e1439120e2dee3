/*
 * scene_parse.c — the scene file reader (the format is docs/scene-format.md): blocks,
 * camera, image, background, includes, the statement loop (scene_reader.h has the parts).
 *
 * Every statement but `include` is `KEYWORD [NAME] { key value ... }`. One generic
 * routine reads a block against a table of the keys it allows (KeySpec): it rejects
 * unknown and repeated keys and checks each value's type and range where the value is,
 * so errors point at the offending token. The per-statement functions then only check
 * what involves several keys (a camera's up against its view direction, a box's min
 * against its max) and append to the scene.
 */
#include "io/scene_reader.h"

#include "util/kmath.h"
#include "base/array.h"
#include "scene/camera.h"
#include "io/lexer.h"
#include "base/limit.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "scene/media.h"
#include "scene/motion.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ helpers */

/* The path of `file` as seen from the folder of the file `from` (io/path.h: the file
 * that names it, so an include's names are its own); NULL when out of memory. */
char *scene_path_beside(const char *from, const char *file, size_t file_len)
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
    case VK_MEDIUM: return "a medium name or 'none'";
    case VK_NUMBER_LIST: return "'[' and numbers, then ']'";
    case VK_PAIR: return k->what;
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
    case VK_PAIR:
    case VK_ROTATE:
    case VK_MATRIX: {
        int n = k->kind == VK_PAIR ? 2 : k->kind == VK_ROTATE ? 4 : 16;
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
    case VK_NUMBER_LIST: {
        if (t.kind != TOK_LBRACKET) return lex_expected(lx, &t, what, err);
        v->list_at = p->n_list;
        v->u = 0;
        for (;;) {
            if ((st = lex_next(lx, &t, p->err))) return st;
            if (t.kind == TOK_RBRACKET) return ST_OK;
            float x;
            if (tok_float(&t, &x)) return lex_expected(lx, &t, "a number or ']'", err);
            if (v->u >= SCENE_LIST_MAX)
                return lex_error_at(lx, &v->value, err, "more than %u numbers in the list of '%s'",
                                    SCENE_LIST_MAX, k->key);
            if (array_reserve((void **)&p->list, &p->cap_list, p->n_list + 1, sizeof *p->list))
                return error_set(err, ST_INTERNAL, "out of memory");
            p->list[p->n_list++] = x;
            v->u++;
        }
    }
    case VK_MEDIUM: {
        uint ref;
        if ((st = scene_read_medium_ref(p, lx, &t, &ref))) return st;
        v->u = ref;
        return ST_OK;
    }
    case VK_MATERIAL:
        if (t.kind == TOK_LBRACE) return scene_parse_material_block(p, lx, &v->key, 1, NULL, &v->material);
        if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0)
            return lex_expected(lx, &t, what, err);
        {
            char *name = tok_copy(&t);
            if (!name) return error_set(err, ST_INTERNAL, "out of memory");
            v->material = scene_find_material(p->s, name);
            /* `none`, unless a material has that name: a boundary between media and
             * no surface (docs/media.md) */
            if (v->material == NO_INDEX && strcmp(name, "none") == 0) {
                free(name);
                return scene_interface_material(p->s, &v->material, err);
            }
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
Status scene_parse_block(Parser *p, Lexer *lx, const Token *kw, int brace_taken,
                         const char *block, const KeySpec *keys, size_t n, Value *vals)
{
    Error *err = p->err;
    memset(vals, 0, n * sizeof *vals);
    p->n_list = 0;
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

/* A block that stands at most once in a scene (camera, image, background): its keys
 * into vals, as scene_parse_block; a second one is an error naming where the first was
 * (*seen, set here). */
static Status parse_once_block(Parser *p, Lexer *lx, const Token *kw, char **seen, const char *block,
                               const KeySpec *keys, size_t n, Value *vals)
{
    if (*seen)
        return lex_error_at(lx, kw, p->err, "a second %.*s block (the first is at %s)",
                            (int)kw->len, kw->text, *seen);
    *seen = reader_where(lx, kw);
    if (!*seen) return error_set(p->err, ST_INTERNAL, "out of memory");
    return scene_parse_block(p, lx, kw, 0, block, keys, n, vals);
}

double scene_len_d(vec3 a) { return sqrt((double)a.x * a.x + (double)a.y * a.y + (double)a.z * a.z); }

vec3 scene_cross_d(vec3 a, vec3 b, double *length)
{
    double x = (double)a.y * b.z - (double)a.z * b.y;
    double y = (double)a.z * b.x - (double)a.x * b.z;
    double z = (double)a.x * b.y - (double)a.y * b.x;
    *length = sqrt(x * x + y * y + z * z);
    return v3((float)x, (float)y, (float)z);
}

/* ------------------------------------------------------------------ statements */

enum { CAM_TYPE, CAM_FROM, CAM_AT, CAM_UP, CAM_FOV, CAM_APERTURE, CAM_FOCUS, CAM_WIDTH, CAM_MEDIUM, CAM_SHUTTER,
       CAM_TIME, CAM_N };
static const KeySpec camera_keys[CAM_N] = {
    [CAM_TYPE] = {"type", VK_WORD, 0, 0, 0, 0, 0, "a camera type (perspective, orthographic)"},
    [CAM_FROM] = {"from", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [CAM_AT] = {"at", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [CAM_UP] = {"up", VK_DIR, 0, 0, 0, 0, 0, NULL},
    [CAM_FOV] = {"fov", VK_NUMBER, 0, 0, 180, 1, 1, "a number of degrees in (0, 180)"},
    [CAM_APERTURE] = {"aperture", VK_NUMBER, 0, 0, INFINITY, 0, 1, "a number >= 0"},
    [CAM_FOCUS] = {"focus", VK_NUMBER, 0, 0, INFINITY, 1, 1, "a distance > 0"},
    [CAM_WIDTH] = {"width", VK_NUMBER, 0, 0, INFINITY, 1, 1, "a width > 0 (scene units)"},
    [CAM_MEDIUM] = {"medium", VK_MEDIUM, 0, 0, 0, 0, 0, NULL},
    [CAM_SHUTTER] = {"shutter", VK_PAIR, 0, 0, 0, 0, 0, "two times, the shutter's opening and closing"},
    [CAM_TIME] = {"time", VK_NUMBER, 0, -INFINITY, INFINITY, 0, 0, "a time (a number)"},
};

/* The camera's type, and the keys that belong to the other type refused (a perspective
 * camera's fov, aperture and focus mean nothing to parallel rays; an orthographic view
 * needs its width, which a perspective camera has no use for). */
static Status camera_type(Parser *p, Lexer *lx, const Token *kw, const Value *v, SceneCamera *c)
{
    int ortho = v[CAM_TYPE].given && tok_is(&v[CAM_TYPE].word, "orthographic");
    if (v[CAM_TYPE].given && !ortho && !tok_is(&v[CAM_TYPE].word, "perspective"))
        return lex_expected(lx, &v[CAM_TYPE].word, "a camera type (perspective, orthographic) for 'type'", p->err);
    if (!ortho && v[CAM_WIDTH].given)
        return lex_error_at(lx, &v[CAM_WIDTH].key, p->err,
                            "'width' is the view's width of an orthographic camera (type orthographic)");
    static const int perspective_only[] = { CAM_FOV, CAM_APERTURE, CAM_FOCUS };
    for (size_t i = 0; ortho && i < 3; i++)
        if (v[perspective_only[i]].given)
            return lex_error_at(lx, &v[perspective_only[i]].key, p->err, "'%s' is for a perspective camera; "
                                "an orthographic camera sees parallel rays across its 'width'",
                                camera_keys[perspective_only[i]].key);
    if (ortho && !v[CAM_WIDTH].given)
        return lex_error_at(lx, kw, p->err, "an orthographic camera needs 'width', its view's width in scene units");
    c->type = ortho ? CAMERA_ORTHOGRAPHIC : CAMERA_PERSPECTIVE;
    c->ortho_width = ortho ? v[CAM_WIDTH].f : 0.0f;
    return ST_OK;
}

static Status check_view(Parser *p, Lexer *lx, const Token *kw, const SceneCamera *c, const Value *vfrom,
                         const Value *vat, const Value *vup, const Value *vfocus);

static Status parse_camera(Parser *p, Lexer *lx, const Token *kw)
{
    /* a path's first key starts from the camera block's values */
    if (p->camera_path_at)
        return lex_error_at(lx, kw, p->err, "the camera block must come before the camera_path (at %s), whose "
                            "keys start from its values", p->camera_path_at);
    Value v[CAM_N];
    Status st = parse_once_block(p, lx, kw, &p->camera_at, "camera", camera_keys, CAM_N, v);
    if (st) return st;
    SceneCamera *c = &p->s->camera;
    if ((st = camera_type(p, lx, kw, v, c))) return st;
    if (v[CAM_FROM].given) c->from = v[CAM_FROM].v;
    if (v[CAM_AT].given) c->at = v[CAM_AT].v;
    if (v[CAM_UP].given) c->up = v[CAM_UP].v;
    if (v[CAM_FOV].given) c->vfov = v[CAM_FOV].f;
    if (v[CAM_APERTURE].given) c->aperture = v[CAM_APERTURE].f;
    if (v[CAM_FOCUS].given) c->focus_dist = v[CAM_FOCUS].f;
    if (v[CAM_MEDIUM].given) p->s->camera_medium = (uint)v[CAM_MEDIUM].u;
    if (v[CAM_SHUTTER].given) {
        if (!(v[CAM_SHUTTER].a[1] >= v[CAM_SHUTTER].a[0]))
            return lex_error_at(lx, &v[CAM_SHUTTER].value, p->err, "the shutter closes (%g) before it opens (%g)",
                                (double)v[CAM_SHUTTER].a[1], (double)v[CAM_SHUTTER].a[0]);
        c->shutter_open = v[CAM_SHUTTER].a[0];
        c->shutter_close = v[CAM_SHUTTER].a[1];
    }
    /* the pose's time: 0 unless given (as an instance's) */
    c->time = v[CAM_TIME].given ? v[CAM_TIME].f : 0.0f;
    return check_view(p, lx, kw, c, &v[CAM_FROM], &v[CAM_AT], &v[CAM_UP], v[CAM_FOCUS].given ? &v[CAM_FOCUS] : NULL);
}

/* A camera's pose (c->from, at, up, from the keys vfrom, vat, vup where given) checked
 * as a whole: blames the key that made it invalid, or the block kw if the defaults
 * did. vfocus: the focus key, when given. */
static Status check_view(Parser *p, Lexer *lx, const Token *kw, const SceneCamera *c, const Value *vfrom,
                         const Value *vat, const Value *vup, const Value *vfocus)
{
    const Token *view_tok = vat->given ? &vat->key : vfrom->given ? &vfrom->key : kw;
    vec3 dir = v3_sub(c->at, c->from);
    double dist = scene_len_d(dir);
    if (!(dist > 0.0))
        return lex_error_at(lx, view_tok, p->err, "camera 'from' and 'at' are the same point");
    if (!isfinite(dist))
        return lex_error_at(lx, view_tok, p->err, "camera 'from' and 'at' are too far apart");
    double cl;
    scene_cross_d(dir, c->up, &cl);
    /* sine of the angle between up and the view direction */
    if (!(cl / (dist * scene_len_d(c->up)) > 1e-6))
        return lex_error_at(lx, vup->given ? &vup->key : view_tok, p->err,
                            "camera 'up' is parallel to the view direction (from 'from' to 'at')");
    double focus = camera_focus(c);
    if (c->type == CAMERA_PERSPECTIVE && focus < camera_min_focus(c->from))
        return lex_error_at(lx, vfocus ? &vfocus->key : view_tok, p->err,
                            "the camera's focus distance (%s) %g is too short for single precision "
                            "with a lens at 'from' %g %g %g: at least %g",
                            vfocus ? "'focus'" : "from 'from' to 'at'", focus,
                            (double)c->from.x, (double)c->from.y, (double)c->from.z,
                            camera_min_focus(c->from));
    return ST_OK;
}

/* camera_key { time T from ... at ... up ... }: a later pose of the camera (docs/motion.md),
 * after the camera block and the keys before it in time; what it leaves out is the
 * pose before it's. */
enum { CK_TIME, CK_FROM, CK_AT, CK_UP, CK_N };
static const KeySpec camera_key_keys[CK_N] = {
    [CK_TIME] = {"time", VK_NUMBER, 1, -INFINITY, INFINITY, 0, 0, "a time (a number)"},
    [CK_FROM] = {"from", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [CK_AT] = {"at", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [CK_UP] = {"up", VK_DIR, 0, 0, 0, 0, 0, NULL},
};

static Status parse_camera_key(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[CK_N];
    Scene *s = p->s;
    if (!p->camera_at)
        return lex_error_at(lx, kw, p->err, "camera_key before the camera block (a moving camera's keys follow it)");
    if (s->n_camera_keys + 1 >= MOTION_MAX_KEYS)
        return lex_error_at(lx, kw, p->err, "more than %u poses of the camera", MOTION_MAX_KEYS);
    Status st = scene_parse_block(p, lx, kw, 0, "camera_key", camera_key_keys, CK_N, v);
    if (st) return st;
    SceneCamera pose = s->camera;
    float before = s->camera.time;
    if (s->n_camera_keys) {
        const SceneCameraKey *last = &s->camera_keys[s->n_camera_keys - 1];
        pose.from = last->from;
        pose.at = last->at;
        pose.up = last->up;
        before = last->time;
    }
    if (!(v[CK_TIME].f > before))
        return lex_error_at(lx, &v[CK_TIME].value, p->err,
                            "camera_key time %g is not after the camera's pose before it (time %g): poses are given "
                            "in increasing time", (double)v[CK_TIME].f, (double)before);
    if (v[CK_FROM].given) pose.from = v[CK_FROM].v;
    if (v[CK_AT].given) pose.at = v[CK_AT].v;
    if (v[CK_UP].given) pose.up = v[CK_UP].v;
    if ((st = check_view(p, lx, kw, &pose, &v[CK_FROM], &v[CK_AT], &v[CK_UP], NULL))) return st;
    if (s->n_camera_keys == s->cap_camera_keys) {
        size_t cap = s->cap_camera_keys ? 2 * s->cap_camera_keys : 4;
        SceneCameraKey *grown = realloc(s->camera_keys, cap * sizeof *grown);
        if (!grown) return error_set(p->err, ST_INTERNAL, "out of memory");
        s->camera_keys = grown;
        s->cap_camera_keys = cap;
    }
    SceneCameraKey *k = &s->camera_keys[s->n_camera_keys++];
    k->time = v[CK_TIME].f;
    k->from = pose.from;
    k->at = pose.at;
    k->up = pose.up;
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
    [IMG_SPLIT] = {"split", VK_WORD, 0, 1, CLPT_MAX_SPLIT, 0, 0, "auto or an integer in 1.." CLPT_STR(CLPT_MAX_SPLIT)},
};

static Status parse_image(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[IMG_N];
    Status st = parse_once_block(p, lx, kw, &p->image_at, "image", image_keys, IMG_N, v);
    if (st) return st;
    SceneImage *im = &p->s->image;
    if (v[IMG_WIDTH].given) im->width = (uint)v[IMG_WIDTH].u;
    if (v[IMG_HEIGHT].given) im->height = (uint)v[IMG_HEIGHT].u;
    if (v[IMG_SPP].given) im->spp = (uint)v[IMG_SPP].u;
    if (v[IMG_DEPTH].given) im->max_depth = (uint)v[IMG_DEPTH].u;
    if (v[IMG_SEED].given) im->seed = (uint)v[IMG_SEED].u;
    if (v[IMG_SPLIT].given) {
        /* auto (SCENE_SPLIT_AUTO: the render's pilot chooses) or a count */
        const Token *w = &v[IMG_SPLIT].word;
        unsigned long long n = 0;
        if (!tok_is(w, "auto") && (tok_uint(w, &n) || !in_range(&image_keys[IMG_SPLIT], (double)n)))
            return lex_expected(lx, w, "auto or an integer in 1.." CLPT_STR(CLPT_MAX_SPLIT) " for 'split'", p->err);
        im->split = tok_is(w, "auto") ? SCENE_SPLIT_AUTO : (uint)n;
    }
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

enum { BG_COLOR, BG_HORIZON, BG_ZENITH, BG_AMBIENT, BG_CUBE, BG_MAP_KEY, BG_INTENSITY, BG_ROTATE, BG_MEDIUM,
       BG_N };
static const KeySpec background_keys[BG_N] = {
    [BG_COLOR] = {"color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [BG_HORIZON] = {"horizon", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [BG_ZENITH] = {"zenith", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [BG_AMBIENT] = {"ambient", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [BG_CUBE] = {"cubemap", VK_PATH, 0, 0, 0, 0, 0, NULL},
    [BG_MAP_KEY] = {"map", VK_PATH, 0, 0, 0, 0, 0, NULL},
    [BG_INTENSITY] = {"intensity", VK_NUMBER, 0, 0, 1e30, 0, 0, "a number in [0, 1e30]"},
    [BG_ROTATE] = {"rotate", VK_NUMBER, 0, -1e6, 1e6, 0, 0, "a number of degrees in [-1e6, 1e6]"},
    [BG_MEDIUM] = {"medium", VK_MEDIUM, 0, 0, 0, 0, 0, NULL},
};

/* `map "FILE"`: an equirectangular environment map (kernels/light/envmap.h), the file found
 * beside the scene file, a high-dynamic-range image (.hdr, .exr). */
static Status parse_background_map(Parser *p, Lexer *lx, const Value *v)
{
    const Token *f = &v[BG_MAP_KEY].word;
    char *path = scene_path_beside(lx->path, f->text, f->len);
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
    char *path = scene_path_beside(lx->path, f->text, f->len);
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
    Status st = parse_once_block(p, lx, kw, &p->background_at, "background", background_keys, BG_N, v);
    if (st) return st;
    Scene *s = p->s;
    if (v[BG_AMBIENT].given) s->ambient = v[BG_AMBIENT].v;   /* the whitted integrator's */
    /* the medium everywhere no boundary says otherwise (docs/media.md); alone, it keeps
     * the black background */
    if (v[BG_MEDIUM].given) s->world_medium = (uint)v[BG_MEDIUM].u;
    int bg_keys = 0;
    for (int i = 0; i < BG_N; i++) bg_keys += i != BG_MEDIUM && i != BG_AMBIENT && v[i].given;
    if (v[BG_MEDIUM].given && bg_keys == 0) return ST_OK;
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
    char *path = scene_path_beside(lx->path, t.text, t.len);
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
    {"camera", parse_camera},                 {"camera_key", parse_camera_key},
    {"image", parse_image},
    {"background", parse_background},         {"material", scene_parse_material},
    {"sphere", scene_parse_shape},            {"plane", scene_parse_shape},
    {"triangle", scene_parse_shape},          {"quad", scene_parse_shape},
    {"box", scene_parse_shape},               {"mesh", scene_parse_mesh},
    {"include", parse_include},               {"light", scene_parse_light},
    {"texture", scene_parse_texture},         {"medium", scene_parse_medium},
    {"object", scene_parse_object},           {"instance", scene_parse_instance},
    {"camera_path", scene_parse_camera_path},
    {"instance_key", scene_parse_instance_key},
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
                              "plane, triangle, quad, box, mesh, light, texture, medium, include, object, "
                              "instance, camera_path, camera_key, instance_key)", p->err);
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
    Status path_st = scene_set_path(s, path, err);
    if (path_st) return path_st;
    Parser p = { .s = s, .err = err, .object = NO_INDEX, .last_instance = NO_INDEX };
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
    if (!st) st = scene_camera_path_finish(&p);
    free(p.camera_path_at);
    free(p.path_keys);
    free(p.camera_at);
    free(p.image_at);
    free(p.background_at);
    for (size_t i = 0; i < p.n_material_at; i++) free(p.material_at[i]);
    free(p.material_at);
    free(p.list);
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
