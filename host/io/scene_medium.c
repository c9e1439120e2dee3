/*
 * scene_medium.c — the scene reader's participating media (docs/media.md): the `medium`
 * statement, and the interior and exterior media of shapes; part of the reader of
 * scene_parse.c (scene_reader.h).
 */
#include "io/scene_reader.h"

#include "util/kmath.h"
#include "io/lexer.h"
#include "scene/media.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { MED_TYPE, MED_SIGMA_A, MED_SIGMA_S, MED_ALBEDO, MED_DENSITY, MED_SCALE, MED_G, MED_N };
static const KeySpec medium_keys[MED_N] = {
    [MED_TYPE] = {"type", VK_WORD, 1, 0, 0, 0, 0, "a medium type (homogeneous)"},
    [MED_SIGMA_A] = {"sigma_a", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MED_SIGMA_S] = {"sigma_s", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MED_ALBEDO] = {"albedo", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MED_DENSITY] = {"density", VK_NUMBER, 0, 0, 1e30, 0, 0, "a number in [0, 1e30]"},
    [MED_SCALE] = {"scale", VK_NUMBER, 0, 0, 1e30, 0, 0, "a number in [0, 1e30]"},
    [MED_G] = {"g", VK_NUMBER, 0, -1, 1, 1, 1, "a number in (-1, 1)"},
};

/* The coefficients of a homogeneous medium: sigma_a and sigma_s, or the scattering
 * albedo and the extinction `density` (sigma_s = albedo density, sigma_a = (1 - albedo)
 * density), times `scale`. */
static Status medium_coefficients(Parser *p, const Lexer *lx, const Token *kw, const Value *v, vec3 *sa, vec3 *ss)
{
    int sigmas = v[MED_SIGMA_A].given || v[MED_SIGMA_S].given;
    int albedo = v[MED_ALBEDO].given || v[MED_DENSITY].given;
    if (sigmas && albedo) {
        const Token *t = v[MED_ALBEDO].given ? &v[MED_ALBEDO].key : &v[MED_DENSITY].key;
        return lex_error_at(lx, t, p->err, "a medium is either 'sigma_a' and 'sigma_s', or 'albedo' and "
                            "'density', not both");
    }
    if (!sigmas && !albedo)
        return lex_error_at(lx, kw, p->err, "the medium block needs 'sigma_a' and 'sigma_s', or 'albedo' and "
                            "'density'");
    if (albedo) {
        if (!v[MED_ALBEDO].given || !v[MED_DENSITY].given)
            return lex_error_at(lx, kw, p->err, "a medium's 'albedo' needs its 'density' (and the other way round)");
        vec3 a = v[MED_ALBEDO].v;
        if (a.x > 1.0f || a.y > 1.0f || a.z > 1.0f)
            return lex_error_at(lx, &v[MED_ALBEDO].value, p->err, "a medium's 'albedo' must be in [0, 1] "
                                "(the share of extinction that scatters)");
        float d = v[MED_DENSITY].f;
        *ss = v3_scale(a, d);
        *sa = v3_scale(v3_sub(v3s(1.0f), a), d);
    } else {
        *sa = v[MED_SIGMA_A].v;   /* a key not given is 0 */
        *ss = v[MED_SIGMA_S].v;
    }
    float scale = v[MED_SCALE].given ? v[MED_SCALE].f : 1.0f;
    *sa = v3_scale(*sa, scale);
    *ss = v3_scale(*ss, scale);
    vec3 t = v3_add(*sa, *ss);
    if (!isfinite(t.x) || !isfinite(t.y) || !isfinite(t.z))
        return lex_error_at(lx, kw, p->err, "the medium's extinction (sigma_a + sigma_s, times scale) is beyond "
                            "the largest float (about 3.4e38)");
    return ST_OK;
}

Status scene_parse_medium(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0 || tok_is(&t, "none"))
        return lex_expected(lx, &t, "a medium name (not 'none', which is vacuum)", p->err);
    if (scene_find_medium(p->s, t.text, t.len) != NO_INDEX) {
        char shown[64];
        tok_describe(&t, shown, sizeof shown);
        return lex_error_at(lx, &t, p->err, "medium '%s' is already defined", shown);
    }
    Value v[MED_N];
    if ((st = scene_parse_block(p, lx, kw, 0, "medium", medium_keys, MED_N, v))) return st;
    if (!tok_is(&v[MED_TYPE].word, "homogeneous"))
        return lex_expected(lx, &v[MED_TYPE].word, medium_keys[MED_TYPE].what, p->err);
    vec3 sa, ss;
    if ((st = medium_coefficients(p, lx, kw, v, &sa, &ss))) return st;
    char *name = tok_copy(&t);
    if (!name) return error_set(p->err, ST_INTERNAL, "out of memory");
    st = scene_add_medium(p->s, name, medium_homogeneous(sa, ss, v[MED_G].given ? v[MED_G].f : 0.0f), NULL, p->err);
    free(name);
    return st;
}

Status scene_read_medium_ref(Parser *p, Lexer *lx, const Token *t, uint *ref)
{
    if ((t->kind != TOK_WORD && t->kind != TOK_STRING) || t->len == 0)
        return lex_expected(lx, t, "a medium name or 'none'", p->err);
    if (tok_is(t, "none")) {
        *ref = 0u;
        return ST_OK;
    }
    uint i = scene_find_medium(p->s, t->text, t->len);
    if (i == NO_INDEX) {
        char shown[64];
        tok_describe(t, shown, sizeof shown);
        return lex_error_at(lx, t, p->err, "medium '%s' is not defined (media must be defined before they are "
                            "used)", shown);
    }
    *ref = i + 1u;
    return ST_OK;
}

/* The medium reference of an optional VK_MEDIUM value: unset when not given. */
static uint media_ref(const Value *v)
{
    return v && v->given ? (uint)v->u : SCENE_MEDIUM_UNSET;
}

Status scene_shape_media(Parser *p, const Value *interior, const Value *exterior, uint material, uint *bound)
{
    return scene_bind_media(p->s, material, media_ref(interior), media_ref(exterior), bound, p->err);
}

Status scene_mesh_media(Parser *p, const Value *interior, const Value *exterior, size_t first)
{
    uint in = media_ref(interior), out = media_ref(exterior);
    if (in == SCENE_MEDIUM_UNSET && out == SCENE_MEDIUM_UNSET) return ST_OK;
    uint from = NO_INDEX, to = NO_INDEX;   /* the last binding, as meshes run long on one material */
    for (size_t i = first; i < p->s->n_triangles; i++) {
        Triangle *t = &p->s->triangles[i];
        if (t->material != from) {
            from = t->material;
            Status st = scene_bind_media(p->s, from, in, out, &to, p->err);
            if (st) return st;
        }
        t->material = to;
    }
    return ST_OK;
}
