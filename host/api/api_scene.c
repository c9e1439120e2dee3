/* api_scene.c — scenes: where they come from and the edits made to them, read again
 * for each render (api.h says why). */
#include "api/api.h"

#include <stdlib.h>
#include <string.h>

#include "options.h"
#include "scene/scene_param.h"
#include "scene_options.h"

void clpt_scene_free(clpt_scene *sc)
{
    if (!sc) return;
    for (size_t i = 0; i < sc->n_sets; i++) {
        free(sc->keys[i]);
        free(sc->values[i]);
    }
    free(sc->keys);
    free(sc->values);
    free(sc->name);
    free(sc->text);
    free(sc);
}

Status api_scene_read(const clpt_scene *sc, const Options *o, Scene *out, Error *err)
{
    SceneKind kind = SCENE_KIND_CLPT;
    Status st = scene_options_before_load(o, out, err);
    if (st) return st;
    st = sc->text ? scene_load_bytes(sc->name, sc->text, sc->len, (SceneFormat)o->format, out, &kind, err)
                  : scene_load_file(sc->name, (SceneFormat)o->format, out, &kind, err);
    for (size_t i = 0; i < sc->n_sets && st == ST_OK; i++) st = scene_param_set(out, sc->keys[i], sc->values[i], err);
    return st ? st : scene_options_apply(o, out, kind == SCENE_KIND_MESH, err);
}

/* Reads the new scene once, so that a bad file fails at the load, with its warnings
 * said there (and not again at each render). */
static clpt_status scene_check(clpt_scene *sc, clpt_scene **out)
{
    clpt_context *ctx = sc->ctx;
    Options o;
    Scene s;
    scene_init(&s);
    Status st = api_render_options(sc, NULL, &o, &ctx->err);
    if (st == ST_OK) st = api_scene_read(sc, &o, &s, &ctx->err);
    if (st == ST_OK)
        for (size_t i = 0; i < s.n_warnings; i++) api_warn(ctx, s.warnings[i]);
    scene_free(&s);
    if (st != ST_OK) {
        clpt_scene_free(sc);
        return (clpt_status)st;
    }
    *out = sc;
    return CLPT_OK;
}

static clpt_scene *scene_new(clpt_context *ctx, const char *name)
{
    clpt_scene *sc = calloc(1, sizeof *sc);
    if (!sc) return NULL;
    sc->ctx = ctx;
    if (!(sc->name = strdup(name))) {
        free(sc);
        return NULL;
    }
    return sc;
}

clpt_status clpt_scene_load(clpt_context *ctx, const char *path, clpt_scene **out)
{
    if (!ctx || !out) return CLPT_ERROR_USAGE;
    *out = NULL;
    error_clear(&ctx->err);
    if (!path || !path[0]) return api_fail(ctx, ST_USAGE, "clpt_scene_load needs a file name");
    clpt_scene *sc = scene_new(ctx, path);
    if (!sc) return api_fail(ctx, ST_INTERNAL, "out of memory");
    return scene_check(sc, out);
}

clpt_status clpt_scene_load_string(clpt_context *ctx, const char *text, size_t len, const char *name,
                                   clpt_scene **out)
{
    if (!ctx || !out) return CLPT_ERROR_USAGE;
    *out = NULL;
    error_clear(&ctx->err);
    if (!text) return api_fail(ctx, ST_USAGE, "clpt_scene_load_string needs the scene's text");
    clpt_scene *sc = scene_new(ctx, name && name[0] ? name : "scene");
    if (!sc || !(sc->text = malloc(len + 1))) {
        clpt_scene_free(sc);
        return api_fail(ctx, ST_INTERNAL, "out of memory");
    }
    memcpy(sc->text, text, len);
    sc->text[len] = '\0';   /* the readers need the end marked */
    sc->len = len;
    return scene_check(sc, out);
}

/* Adds key=value to the scene's edits (copied). */
static Status scene_add_set(clpt_scene *sc, const char *key, const char *value, Error *err)
{
    char **keys = realloc(sc->keys, (sc->n_sets + 1) * sizeof *keys);
    if (keys) sc->keys = keys;
    char **values = realloc(sc->values, (sc->n_sets + 1) * sizeof *values);
    if (values) sc->values = values;
    char *k = strdup(key), *v = strdup(value);
    if (!keys || !values || !k || !v) {
        free(k);
        free(v);
        return error_set(err, ST_INTERNAL, "out of memory");
    }
    sc->keys[sc->n_sets] = k;
    sc->values[sc->n_sets++] = v;
    return ST_OK;
}

clpt_status clpt_scene_set(clpt_scene *sc, const char *key, const char *value)
{
    if (!sc) return CLPT_ERROR_USAGE;
    clpt_context *ctx = sc->ctx;
    error_clear(&ctx->err);
    if (!key || !value) return api_fail(ctx, ST_USAGE, "clpt_scene_set needs a key and a value");
    Status st = scene_add_set(sc, key, value, &ctx->err);
    if (st) return (clpt_status)st;
    /* checked on the scene as read: the material's name, the light's index */
    Options o;
    Scene s;
    scene_init(&s);
    st = api_render_options(sc, NULL, &o, &ctx->err);
    if (st == ST_OK) st = api_scene_read(sc, &o, &s, &ctx->err);
    scene_free(&s);
    if (st != ST_OK) {
        /* a refused edit is not kept */
        sc->n_sets--;
        free(sc->keys[sc->n_sets]);
        free(sc->values[sc->n_sets]);
    }
    return (clpt_status)st;
}
