/*
 * scene_medium.c — the scene reader's participating media (docs/media.md): the `medium`
 * statement, and the interior and exterior media of shapes; part of the reader of
 * scene_parse.c (scene_reader.h).
 */
#include "io/scene_reader.h"

#include "util/kmath.h"
#include "io/lexer.h"
#include "scene/blackbody.h"
#include "scene/media.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MEDIUM_TYPES "a medium type (homogeneous, grid)"

/* The keys both kinds of medium take: the type, the coefficients and the emission. */
#define MEDIUM_COEFFICIENT_KEYS(prefix)                                                                 \
    [prefix##_TYPE] = {"type", VK_WORD, 0, 0, 0, 0, 0, MEDIUM_TYPES},                                   \
    [prefix##_SIGMA_A] = {"sigma_a", VK_COLOR, 0, 0, 0, 0, 0, NULL},                                    \
    [prefix##_SIGMA_S] = {"sigma_s", VK_COLOR, 0, 0, 0, 0, 0, NULL},                                    \
    [prefix##_ALBEDO] = {"albedo", VK_COLOR, 0, 0, 0, 0, 0, NULL},                                      \
    [prefix##_DENSITY] = {"density", VK_NUMBER, 0, 0, 1e30, 0, 0, "a number in [0, 1e30]"},             \
    [prefix##_G] = {"g", VK_NUMBER, 0, -1, 1, 1, 1, "a number in (-1, 1)"},                             \
    [prefix##_EMISSION] = {"emission", VK_COLOR, 0, 0, 0, 0, 0, NULL},                                  \
    [prefix##_EMISSION_SCALE] = {"emission_scale", VK_NUMBER, 0, 0, 1e30, 0, 0, "a number in [0, 1e30]"}

enum { MED_TYPE, MED_SIGMA_A, MED_SIGMA_S, MED_ALBEDO, MED_DENSITY, MED_SCALE, MED_G, MED_EMISSION,
       MED_EMISSION_SCALE, MED_N };
static const KeySpec medium_keys[MED_N] = {
    MEDIUM_COEFFICIENT_KEYS(MED),
    [MED_SCALE] = {"scale", VK_NUMBER, 0, 0, 1e30, 0, 0, "a number in [0, 1e30]"},
};

/* A grid medium's keys: the coefficients (per unit of the grid's density) in the same
 * places as medium_keys, so medium_coefficients reads both; `scale` is the transform's
 * here, as in every block with a transform (the coefficients take no extra factor). */
enum { GM_TYPE, GM_SIGMA_A, GM_SIGMA_S, GM_ALBEDO, GM_DENSITY, GM_G, GM_SIZE, GM_DATA, GM_FILE, GM_MIN, GM_MAX,
       TRANSFORM_KEY_IDS(GM), GM_EMISSION, GM_EMISSION_SCALE, GM_EMISSION_DATA, GM_EMISSION_FILE,
       GM_TEMPERATURE_DATA, GM_TEMPERATURE_FILE, GM_TEMPERATURE_OFFSET, GM_TEMPERATURE_SCALE, GM_N };
static const KeySpec grid_keys[GM_N] = {
    MEDIUM_COEFFICIENT_KEYS(GM),
    [GM_SIZE] = {"size", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [GM_DATA] = {"data", VK_NUMBER_LIST, 0, 0, 0, 0, 0, NULL},
    [GM_FILE] = {"file", VK_PATH, 0, 0, 0, 0, 0, NULL},
    [GM_MIN] = {"min", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [GM_MAX] = {"max", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    TRANSFORM_KEYS(GM),
    [GM_EMISSION_DATA] = {"emission_data", VK_NUMBER_LIST, 0, 0, 0, 0, 0, NULL},
    [GM_EMISSION_FILE] = {"emission_file", VK_PATH, 0, 0, 0, 0, 0, NULL},
    [GM_TEMPERATURE_DATA] = {"temperature_data", VK_NUMBER_LIST, 0, 0, 0, 0, 0, NULL},
    [GM_TEMPERATURE_FILE] = {"temperature_file", VK_PATH, 0, 0, 0, 0, 0, NULL},
    [GM_TEMPERATURE_OFFSET] = {"temperature_offset", VK_NUMBER, 0, -1e30, 1e30, 0, 0, "a number in [-1e30, 1e30]"},
    [GM_TEMPERATURE_SCALE] = {"temperature_scale", VK_NUMBER, 0, 0, 1e30, 0, 0, "a number in [0, 1e30]"},
};

/* The coefficients of a medium: sigma_a and sigma_s, or the scattering albedo and the
 * extinction `density` (sigma_s = albedo density, sigma_a = (1 - albedo) density),
 * times `scale`. v holds the values at the MED_* places (grid_keys keeps them there). */
static Status medium_coefficients(Parser *p, const Lexer *lx, const Token *kw, const Value *v, float scale,
                                  vec3 *sa, vec3 *ss)
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
    *sa = v3_scale(*sa, scale);
    *ss = v3_scale(*ss, scale);
    vec3 t = v3_add(*sa, *ss);
    if (!isfinite(t.x) || !isfinite(t.y) || !isfinite(t.z))
        return lex_error_at(lx, kw, p->err, "the medium's extinction (sigma_a + sigma_s, times scale) is beyond "
                            "the largest float (about 3.4e38)");
    return ST_OK;
}

/* A medium's emission: `emission` (radiance, pbrt-v4's Le) times `emission_scale`
 * (1 when not given), 0 0 0 when there is none; with `tinted` (a temperature grid
 * gives the colour) `emission` is a tint of 1 1 1 when not given. Each channel times
 * sigma_a must stay a float, since a stretch ds emits sigma_a Le ds. */
static Status medium_emission(Parser *p, const Lexer *lx, const Value *emission, const Value *scale, vec3 sa,
                              int tinted, vec3 *le)
{
    *le = v3s(0.0f);
    if (!emission->given && !tinted) {
        if (scale->given)
            return lex_error_at(lx, &scale->key, p->err, "'emission_scale' needs 'emission' (the radiance it "
                                "scales)");
        return ST_OK;
    }
    *le = v3_scale(emission->given ? emission->v : v3s(1.0f), scale->given ? scale->f : 1.0f);
    vec3 e = v3_scale(v3_mul(*le, sa), tinted ? BLACKBODY_RGB_MAX : 1.0f);
    if (!isfinite(le->x) || !isfinite(le->y) || !isfinite(le->z) || !isfinite(e.x) || !isfinite(e.y) ||
        !isfinite(e.z))
        return lex_error_at(lx, emission->given ? &emission->key : &scale->key, p->err,
                            tinted ? "the medium's emission (times emission_scale, sigma_a and a blackbody's colour, "
                                     "up to 256) is beyond the largest float (about 3.4e38)"
                                   : "the medium's emission (times emission_scale and sigma_a) is beyond the largest "
                                     "float (about 3.4e38)");
    return ST_OK;
}

/* A grid's emission scales (`emission_data` / `emission_file`, given at `key`) times its
 * emission le and sigma_a sa (and a blackbody's colour, up to BLACKBODY_RGB_MAX, when
 * `tinted`), and times its densities, must stay a float, as medium_emission checks for
 * a scale of 1 (grid_emission_fits). */
static Status grid_emission_check(Parser *p, const Lexer *lx, const Token *key, vec3 le, vec3 sa, int tinted,
                                  const float *density, const float *scale, const uint n[3])
{
    size_t top;
    if (grid_emission_fits(density, scale, (size_t)n[0] * n[1] * n[2], v3_max_comp(v3_mul(le, sa)),
                           tinted ? BLACKBODY_RGB_MAX : 1.0, &top))
        return ST_OK;
    return lex_error_at(lx, key, p->err, "the grid's emission scale %g at cell %zu %zu %zu, times emission, "
                        "emission_scale and sigma_a%s or times the largest density, is beyond the largest float "
                        "(about 3.4e38)", (double)scale[top], top % n[0], top / n[0] % n[1], top / n[0] / n[1],
                        tinted ? " (and a blackbody's colour, up to 256)" : "");
}

/* The grid's size: three whole numbers >= 1, at most SCENE_LIST_MAX cells in all. */
static Status grid_size(Parser *p, const Lexer *lx, const Value *v, uint n[3])
{
    float c[3] = { v->v.x, v->v.y, v->v.z };
    double cells = 1.0;
    for (int i = 0; i < 3; i++) {
        if (!(c[i] >= 1.0f) || c[i] != floorf(c[i]) || c[i] > (float)SCENE_LIST_MAX)
            return lex_error_at(lx, &v->value, p->err, "a grid's 'size' is three whole numbers >= 1 (cells along "
                                "x, y, z), found %g %g %g", (double)c[0], (double)c[1], (double)c[2]);
        n[i] = (uint)c[i];
        cells *= c[i];
    }
    if (cells > (double)SCENE_LIST_MAX)
        return lex_error_at(lx, &v->value, p->err, "a grid of %u x %u x %u cells is more than %u", n[0], n[1], n[2],
                            SCENE_LIST_MAX);
    return ST_OK;
}

/* A grid's densities from a raw file: n little-endian 32-bit floats, x fastest. */
static Status grid_file(Parser *p, const Lexer *lx, const Value *v, size_t n, float **out)
{
    char *path = scene_path_beside(lx->path, v->word.text, v->word.len);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    char *data;
    size_t len;
    Status st = lex_read_file(path, &data, &len, p->err);
    if (st) {
        free(path);
        return st;
    }
    if (len != n * sizeof(float)) {
        st = lex_error_at(lx, &v->value, p->err, "'%s' has %zu bytes; the grid's 'size' wants %zu (4-byte "
                          "little-endian floats)", path, len, n * sizeof(float));
        free(data);
        free(path);
        return st;
    }
    free(path);
    float *d = malloc(n * sizeof(float));
    if (!d) {
        free(data);
        return error_set(p->err, ST_INTERNAL, "out of memory");
    }
    memcpy(d, data, n * sizeof(float));   /* the hosts clpt runs on are little-endian */
    free(data);
    *out = d;
    return ST_OK;
}

/* A grid's n[0] n[1] n[2] values from an inline list (`data`) or a raw file (`file`),
 * one of which was given, each finite and >= 0; `what` names one value in messages,
 * `whats` several. */
static Status grid_values(Parser *p, const Lexer *lx, const Value *data, const Value *file, const uint n[3],
                          const char *what, const char *whats, float **out)
{
    size_t cells = (size_t)n[0] * n[1] * n[2];
    float *values = NULL;
    Status st;
    if (data->given) {
        if (data->u != cells)
            return lex_error_at(lx, &data->key, p->err, "the grid's 'size' %u %u %u is %zu cells, but '%.*s' "
                                "has %llu numbers", n[0], n[1], n[2], cells, (int)data->key.len, data->key.text,
                                data->u);
        values = malloc(cells * sizeof(float));
        if (!values) return error_set(p->err, ST_INTERNAL, "out of memory");
        memcpy(values, p->list + data->list_at, cells * sizeof(float));
    } else if ((st = grid_file(p, lx, file, cells, &values))) {
        return st;
    }
    const Token *src = data->given ? &data->key : &file->key;
    for (size_t i = 0; i < cells; i++)
        if (!(values[i] >= 0.0f) || !isfinite(values[i])) {
            st = lex_error_at(lx, src, p->err, "%s %g at cell %zu %zu %zu of the grid: %s are finite numbers >= 0",
                              what, (double)values[i], i % n[0], i / n[0] % n[1], i / n[0] / n[1], whats);
            free(values);
            return st;
        }
    *out = values;
    return ST_OK;
}

/* `medium NAME { type grid ... }` from after `type grid` (typed: where they were). */
static Status parse_grid_medium(Parser *p, Lexer *lx, const Token *kw, const Token *name, const Token *type_key)
{
    Value v[GM_N];
    Status st = scene_parse_block(p, lx, kw, 1, "grid medium", grid_keys, GM_N, v);
    if (st) return st;
    if (v[GM_TYPE].given)
        return lex_error_at(lx, &v[GM_TYPE].key, p->err, "key 'type' repeated in the medium block (first given at "
                            "%u:%u)", type_key->line, type_key->col);
    vec3 sa, ss;
    if ((st = medium_coefficients(p, lx, kw, v, 1.0f, &sa, &ss))) return st;
    uint n[3];
    if ((st = grid_size(p, lx, &v[GM_SIZE], n))) return st;
    if (v[GM_DATA].given == v[GM_FILE].given)
        return lex_error_at(lx, v[GM_DATA].given ? &v[GM_FILE].key : kw, p->err,
                            v[GM_DATA].given ? "a grid medium has 'data' or 'file', not both"
                                             : "a grid medium needs its densities: 'data [ ... ]' or 'file NAME'");
    float *density = NULL;
    if ((st = grid_values(p, lx, &v[GM_DATA], &v[GM_FILE], n, "density", "densities", &density))) return st;
    /* a temperature grid: each cell's blackbody colour, times `emission` (1 1 1 when not
     * given) and the emission scales */
    float *temperature = NULL;
    int tinted = v[GM_TEMPERATURE_DATA].given || v[GM_TEMPERATURE_FILE].given;
    if (tinted) {
        if (v[GM_TEMPERATURE_DATA].given && v[GM_TEMPERATURE_FILE].given)
            st = lex_error_at(lx, &v[GM_TEMPERATURE_FILE].key, p->err, "a grid medium has 'temperature_data' or "
                              "'temperature_file', not both");
        else
            st = grid_values(p, lx, &v[GM_TEMPERATURE_DATA], &v[GM_TEMPERATURE_FILE], n, "temperature",
                             "temperatures", &temperature);
    } else if (v[GM_TEMPERATURE_OFFSET].given || v[GM_TEMPERATURE_SCALE].given) {
        const Value *t = v[GM_TEMPERATURE_OFFSET].given ? &v[GM_TEMPERATURE_OFFSET] : &v[GM_TEMPERATURE_SCALE];
        st = lex_error_at(lx, &t->key, p->err, "'%.*s' needs 'temperature_data' or 'temperature_file'",
                          (int)t->key.len, t->key.text);
    }
    if (st) {
        free(density);
        return st;
    }
    vec3 le;
    if ((st = medium_emission(p, lx, &v[GM_EMISSION], &v[GM_EMISSION_SCALE], sa, tinted, &le))) {
        free(density);
        free(temperature);
        return st;
    }
    float *emission = NULL;
    if (v[GM_EMISSION_DATA].given || v[GM_EMISSION_FILE].given) {
        const Value *e = v[GM_EMISSION_DATA].given ? &v[GM_EMISSION_DATA] : &v[GM_EMISSION_FILE];
        if (v[GM_EMISSION_DATA].given && v[GM_EMISSION_FILE].given)
            st = lex_error_at(lx, &v[GM_EMISSION_FILE].key, p->err, "a grid medium has 'emission_data' or "
                              "'emission_file', not both");
        else if (!v[GM_EMISSION].given && !tinted)
            st = lex_error_at(lx, &e->key, p->err, "'%s' needs 'emission' (the radiance its values scale)",
                              v[GM_EMISSION_DATA].given ? "emission_data" : "emission_file");
        else if (!(st = grid_values(p, lx, &v[GM_EMISSION_DATA], &v[GM_EMISSION_FILE], n, "emission scale",
                                    "emission scales", &emission)))
            st = grid_emission_check(p, lx, &e->key, le, sa, tinted, density, emission, n);
        if (st) {
            free(emission);
            free(density);
            free(temperature);
            return st;
        }
    }
    vec3 lo = v[GM_MIN].given ? v[GM_MIN].v : v3s(0.0f), hi = v[GM_MAX].given ? v[GM_MAX].v : v3s(1.0f);
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) {
        free(density);
        free(emission);
        free(temperature);
        return lex_error_at(lx, v[GM_MAX].given ? &v[GM_MAX].key : &v[GM_MIN].key, p->err,
                            "a grid's 'max' must be greater than its 'min' on every axis, found min %g %g %g, "
                            "max %g %g %g", (double)lo.x, (double)lo.y, (double)lo.z, (double)hi.x, (double)hi.y,
                            (double)hi.z);
    }
    Transform to_world;
    if ((st = scene_parse_transform(p, lx, kw, v + GM_TRANSLATE, "grid medium", &to_world))) {
        free(density);
        free(emission);
        free(temperature);
        return st;
    }
    uint grid;
    st = scene_add_grid(p->s, density, n[0], n[1], n[2], lo, hi, &to_world, &grid, p->err);
    free(density);
    if (!st && emission) st = scene_grid_set_emission(p->s, grid, emission, p->err);
    if (!st && temperature) {
        GridTemperature how = { v[GM_TEMPERATURE_OFFSET].given ? (double)v[GM_TEMPERATURE_OFFSET].f : 0.0,
                                v[GM_TEMPERATURE_SCALE].given ? (double)v[GM_TEMPERATURE_SCALE].f : 1.0 };
        st = scene_grid_set_temperature(p->s, grid, temperature, how, p->err);
    }
    free(emission);
    free(temperature);
    if (st) return st;
    char *copy = tok_copy(name);
    if (!copy) return error_set(p->err, ST_INTERNAL, "out of memory");
    Medium m = medium_with_emission(medium_grid(sa, ss, v[GM_G].given ? v[GM_G].f : 0.0f, grid), le);
    st = scene_add_medium(p->s, copy, m, NULL, p->err);
    free(copy);
    return st;
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
    /* The type picks the block's keys (a grid's `scale` is its transform's): a grid
     * says `type grid` first; a block that does not start with `type` is read as
     * homogeneous, as before grids. */
    Token brace, key, type;
    if ((st = lex_next(lx, &brace, p->err))) return st;
    if (brace.kind != TOK_LBRACE) return lex_expected(lx, &brace, "'{' to open the medium block", p->err);
    if ((st = lex_next(lx, &key, p->err))) return st;
    int typed = tok_is(&key, "type");
    if (typed) {
        if ((st = lex_next(lx, &type, p->err))) return st;
        if (type.kind != TOK_WORD) return lex_expected(lx, &type, MEDIUM_TYPES " for 'type'", p->err);
        if (tok_is(&type, "grid")) return parse_grid_medium(p, lx, kw, &t, &key);
    } else {
        lex_unread(lx, &key);
    }
    Value v[MED_N];
    if ((st = scene_parse_block(p, lx, kw, 1, "medium", medium_keys, MED_N, v))) return st;
    /* `type` is required, but may have been taken before the block's keys */
    if (!typed && !v[MED_TYPE].given)
        return lex_error_at(lx, kw, p->err, "the medium block needs 'type' (it has no default)");
    if (typed) {
        if (v[MED_TYPE].given)
            return lex_error_at(lx, &v[MED_TYPE].key, p->err, "key 'type' repeated in the medium block (first "
                                "given at %u:%u)", key.line, key.col);
        v[MED_TYPE].given = 1;
        v[MED_TYPE].key = key;
        v[MED_TYPE].word = type;
    }
    if (tok_is(&v[MED_TYPE].word, "grid"))
        return lex_error_at(lx, &v[MED_TYPE].key, p->err, "'type grid' must be the first key of its medium block "
                            "(a grid's keys are not a homogeneous medium's)");
    if (!tok_is(&v[MED_TYPE].word, "homogeneous"))
        return lex_expected(lx, &v[MED_TYPE].word, MEDIUM_TYPES, p->err);
    vec3 sa, ss, le;
    float scale = v[MED_SCALE].given ? v[MED_SCALE].f : 1.0f;
    if ((st = medium_coefficients(p, lx, kw, v, scale, &sa, &ss))) return st;
    if ((st = medium_emission(p, lx, &v[MED_EMISSION], &v[MED_EMISSION_SCALE], sa, 0, &le))) return st;
    char *name = tok_copy(&t);
    if (!name) return error_set(p->err, ST_INTERNAL, "out of memory");
    Medium m = medium_with_emission(medium_homogeneous(sa, ss, v[MED_G].given ? v[MED_G].f : 0.0f), le);
    st = scene_add_medium(p->s, name, m, NULL, p->err);
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
