/*
 * scene_camera_path.c — clpt's `camera_path` statement (docs/scene-format.md,
 * docs/animation.md): keys of the camera at times, kept by the reader and, when the
 * scene is to be animated (Scene.keep_animation: --frames), made the scene's animation
 * (scene/camera_path.h). A plain render ignores the path and looks through the camera
 * block, as it renders a glTF file's nodes where the file places them.
 *
 *     camera_path {
 *         interpolation smooth          linear (default), step or smooth
 *         key 0 { from 0 1 6  at 0 1 0 }
 *         key 2 { from 4 2 4 }          what a key leaves out is the key before's
 *     }
 */
#include "io/scene_reader.h"

#include "base/array.h"
#include "io/reader.h"
#include "util/kmath.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { KEY_FROM, KEY_AT, KEY_UP, KEY_FOV, KEY_N };
static const KeySpec key_keys[KEY_N] = {
    [KEY_FROM] = {"from", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [KEY_AT] = {"at", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [KEY_UP] = {"up", VK_DIR, 0, 0, 0, 0, 0, NULL},
    [KEY_FOV] = {"fov", VK_NUMBER, 0, 0, 180, 1, 1, "a number of degrees in (0, 180)"},
};

static void put3(double *d, vec3 v)
{
    d[0] = v.x;
    d[1] = v.y;
    d[2] = v.z;
}

static vec3 get3(const double *d)
{
    return v3((float)d[0], (float)d[1], (float)d[2]);
}

/* The key's camera as the camera block checks one: an eye apart from the point looked
 * at, an up not along the view. */
static Status key_check(Parser *p, Lexer *lx, const Token *kt, const Value *v, const CameraKey *k)
{
    vec3 from = get3(k->from), at = get3(k->at), up = get3(k->up);
    const Token *view_tok = v[KEY_AT].given ? &v[KEY_AT].key : v[KEY_FROM].given ? &v[KEY_FROM].key : kt;
    vec3 dir = v3_sub(at, from);
    double dist = scene_len_d(dir);
    if (!(dist > 0.0)) return lex_error_at(lx, view_tok, p->err, "camera 'from' and 'at' are the same point");
    if (!isfinite(dist)) return lex_error_at(lx, view_tok, p->err, "camera 'from' and 'at' are too far apart");
    double cl;
    scene_cross_d(dir, up, &cl);
    if (!(cl / (dist * scene_len_d(up)) > 1e-6))
        return lex_error_at(lx, v[KEY_UP].given ? &v[KEY_UP].key : view_tok, p->err,
                            "camera 'up' is parallel to the view direction (from 'from' to 'at')");
    return ST_OK;
}

/* `key T { ... }`: the values given, the rest the key before's (the first key's, the
 * camera block's). */
static Status parse_key(Parser *p, Lexer *lx, const Token *kw)
{
    Token tt;
    Status st = lex_next(lx, &tt, p->err);
    if (st) return st;
    float t;
    if (tok_float(&tt, &t)) return lex_expected(lx, &tt, "the key's time in seconds (a number)", p->err);
    if (p->n_path_keys && !((double)t > p->path_keys[p->n_path_keys - 1].t))
        return lex_error_at(lx, &tt, p->err, "key times must increase: %g is not after the key before's, %g", t,
                            p->path_keys[p->n_path_keys - 1].t);
    if (p->n_path_keys >= CAMERA_PATH_MAX_KEYS)
        return lex_error_at(lx, kw, p->err, "more than %d keys in the camera_path", CAMERA_PATH_MAX_KEYS);
    Value v[KEY_N];
    if ((st = scene_parse_block(p, lx, kw, 0, "key", key_keys, KEY_N, v))) return st;
    if (v[KEY_FOV].given && p->s->camera.type == CAMERA_ORTHOGRAPHIC)
        return lex_error_at(lx, &v[KEY_FOV].key, p->err, "'fov' is for a perspective camera; an orthographic "
                            "camera sees parallel rays across its 'width'");
    CameraKey k;
    if (p->n_path_keys) {
        k = p->path_keys[p->n_path_keys - 1];
    } else {
        const SceneCamera *c = &p->s->camera;
        put3(k.from, c->from);
        put3(k.at, c->at);
        put3(k.up, c->up);
        k.fov = c->vfov;
    }
    k.t = t;
    if (v[KEY_FROM].given) put3(k.from, v[KEY_FROM].v);
    if (v[KEY_AT].given) put3(k.at, v[KEY_AT].v);
    if (v[KEY_UP].given) put3(k.up, v[KEY_UP].v);
    if (v[KEY_FOV].given) k.fov = v[KEY_FOV].f;
    if ((st = key_check(p, lx, kw, v, &k))) return st;
    if (array_reserve((void **)&p->path_keys, &p->cap_path_keys, p->n_path_keys + 1, sizeof k))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    p->path_keys[p->n_path_keys++] = k;
    return ST_OK;
}

Status scene_parse_camera_path(Parser *p, Lexer *lx, const Token *kw)
{
    if (p->camera_path_at)
        return lex_error_at(lx, kw, p->err, "a second camera_path block (the first is at %s)", p->camera_path_at);
    if (p->object != NO_INDEX)
        return lex_error_at(lx, kw, p->err, "a camera_path cannot be part of an object");
    if (!(p->camera_path_at = reader_where(lx, kw))) return error_set(p->err, ST_INTERNAL, "out of memory");
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    if (t.kind != TOK_LBRACE) return lex_expected(lx, &t, "'{' to open the camera_path block", p->err);
    int interp_given = 0;
    for (;;) {
        if ((st = lex_next(lx, &t, p->err))) return st;
        if (t.kind == TOK_RBRACE) break;
        if (t.kind == TOK_EOF)
            return lex_error_at(lx, &t, p->err, "expected '}' to close the camera_path block opened at line %u, "
                                "found end of file", kw->line);
        if (tok_is(&t, "key")) {
            if ((st = parse_key(p, lx, &t))) return st;
        } else if (tok_is(&t, "interpolation") && !interp_given) {
            Token w;
            if ((st = lex_next(lx, &w, p->err))) return st;
            p->path_interp = tok_is(&w, "linear") ? CAMERA_PATH_LINEAR : tok_is(&w, "step") ? CAMERA_PATH_STEP
                           : tok_is(&w, "smooth") ? CAMERA_PATH_SMOOTH : -1;
            if (p->path_interp < 0)
                return lex_expected(lx, &w, "an interpolation (linear, step, smooth) for 'interpolation'", p->err);
            interp_given = 1;
        } else if (tok_is(&t, "interpolation")) {
            return lex_error_at(lx, &t, p->err, "key 'interpolation' repeated in the camera_path block");
        } else {
            return lex_expected(lx, &t, "a camera_path key (interpolation, key) or '}'", p->err);
        }
    }
    if (p->n_path_keys == 0) return lex_error_at(lx, kw, p->err, "the camera_path block needs at least one key");
    return ST_OK;
}

Status scene_camera_path_finish(Parser *p)
{
    if (!p->n_path_keys || !p->s->keep_animation) return ST_OK;
    return camera_path_animation(p->path_keys, p->n_path_keys, p->path_interp, &p->s->animation, p->err);
}
