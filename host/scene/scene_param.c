/* scene_param.c — see scene_param.h. One table per kind of object: a parameter is a
 * name, how its value is read, where it goes and its range. */
#include "scene/scene_param.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "base/limit.h"
#include "util/kmath.h"

typedef enum {
    PK_NUMBER,   /* a float in [lo, hi] */
    PK_POINT,    /* three finite floats */
    PK_DIR,      /* three floats, not all 0; stored normalised */
    PK_COLOR,    /* one or three floats >= 0 (one: grey) */
    PK_UINT,     /* an integer in [lo, hi] */
    PK_UINT_AUTO /* the same, or auto (stored as 0) */
} ParamKind;

typedef struct {
    const char *name;
    ParamKind kind;
    size_t offset;               /* in the object (SceneCamera, Material ...) */
    double lo, hi;               /* PK_NUMBER, PK_UINT */
    int open;                    /* PK_NUMBER: lo and hi themselves are refused */
    int normalise;               /* PK_DIR: stored as a unit vector */
} ParamSpec;

#define NUM(n, T, f, l, h, open) { n, PK_NUMBER, offsetof(T, f), l, h, open, 0 }
#define PNT(n, T, f) { n, PK_POINT, offsetof(T, f), 0, 0, 0, 0 }
#define DIR(n, T, f, unit) { n, PK_DIR, offsetof(T, f), 0, 0, 0, unit }
#define COL(n, T, f) { n, PK_COLOR, offsetof(T, f), 0, 0, 0, 0 }
#define INT(n, T, f, l, h) { n, PK_UINT, offsetof(T, f), l, h, 0, 0 }
#define INT_AUTO(n, T, f, l, h) { n, PK_UINT_AUTO, offsetof(T, f), l, h, 0, 0 }

static const ParamSpec camera_params[] = {
    PNT("from", SceneCamera, from), PNT("eye", SceneCamera, from),
    PNT("at", SceneCamera, at), PNT("look_at", SceneCamera, at),
    DIR("up", SceneCamera, up, 0),
    NUM("fov", SceneCamera, vfov, 0, 180, 1),
    NUM("aperture", SceneCamera, aperture, 0, INFINITY, 0),
    NUM("focus", SceneCamera, focus_dist, 0, INFINITY, 1),
    NUM("width", SceneCamera, ortho_width, 0, INFINITY, 1),
};

/* A parameter of one type of camera is refused on the other, not silently ignored:
 * fov, aperture and focus are a perspective camera's, width an orthographic one's. */
static Status camera_param_check(const SceneCamera *c, const char *key, const char *name, Error *err)
{
    int ortho = c->type == CAMERA_ORTHOGRAPHIC;
    if (ortho && (strcmp(name, "fov") == 0 || strcmp(name, "aperture") == 0 || strcmp(name, "focus") == 0))
        return error_set(err, ST_USAGE, "scene parameter '%s': the camera is orthographic, with a view width "
                         "(camera.width) and no lens or field of view", key);
    if (!ortho && strcmp(name, "width") == 0)
        return error_set(err, ST_USAGE, "scene parameter '%s': the camera is perspective; camera.width is an "
                         "orthographic camera's view width", key);
    return ST_OK;
}

static const ParamSpec image_params[] = {
    INT("width", SceneImage, width, 1, CLPT_MAX_IMAGE_SIDE),
    INT("height", SceneImage, height, 1, CLPT_MAX_IMAGE_SIDE),
    INT("spp", SceneImage, spp, 1, CLPT_MAX_SPP),
    INT("depth", SceneImage, max_depth, 0, CLPT_MAX_DEPTH),
    INT("seed", SceneImage, seed, 0, 4294967295.0),
    INT_AUTO("split", SceneImage, split, 1, CLPT_MAX_SPLIT),
};

static const ParamSpec background_params[] = {
    COL("color", Scene, bg_color),
};

static const ParamSpec material_params[] = {
    COL("albedo", Material, albedo), COL("emission", Material, emission),
    COL("radiance", Material, emission),
    COL("specular", Material, specular), COL("reflective", Material, reflective),
    COL("transparent", Material, transparent), COL("eta", Material, eta), COL("k", Material, k),
    COL("specular_color", Material, specular_color), COL("sheen_color", Material, sheen_color),
    NUM("ior", Material, ior, 0, INFINITY, 1), NUM("fuzz", Material, fuzz, 0, 1, 0),
    NUM("shininess", Material, shininess, 0, INFINITY, 0), NUM("roughness", Material, roughness, 0, 1, 0),
    NUM("anisotropy", Material, anisotropy, -1, 1, 0), NUM("metallic", Material, metallic, 0, 1, 0),
    NUM("transmission", Material, transmission, 0, 1, 0), NUM("clearcoat", Material, clearcoat, 0, 1, 0),
    NUM("clearcoat_roughness", Material, clearcoat_roughness, 0, 1, 0),
    NUM("alpha", Material, alpha, 0, 1, 0), NUM("specular_factor", Material, specular_factor, 0, INFINITY, 0),
    NUM("sheen_roughness", Material, sheen_roughness, 0, 1, 0),
};

static const ParamSpec light_params[] = {
    COL("intensity", Light, intensity),
    PNT("position", Light, position),
    DIR("direction", Light, direction, 1),
};

#define COUNT(a) (sizeof (a) / sizeof (a)[0])

/* ---------------------------------------------------------------- did you mean */

/* Edit distance of two short names, a swap of neighbours counting one edit ("fvo" is
 * one from "fov"); longer names count as far apart. */
static size_t edit_distance(const char *a, size_t na, const char *b)
{
    enum { MAX = 32 };
    size_t nb = strlen(b);
    if (na >= MAX || nb >= MAX) return MAX;
    size_t d[MAX + 1][MAX + 1];
    for (size_t i = 0; i <= na; i++) d[i][0] = i;
    for (size_t j = 0; j <= nb; j++) d[0][j] = j;
    for (size_t i = 1; i <= na; i++)
        for (size_t j = 1; j <= nb; j++) {
            size_t best = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
            if (d[i - 1][j] + 1 < best) best = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < best) best = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && d[i - 2][j - 2] + 1 < best)
                best = d[i - 2][j - 2] + 1;
            d[i][j] = best;
        }
    return d[na][nb];
}

/* Appends " (did you mean 'XREST'?)" to err when one of the n names X (stride bytes
 * apart, starting at first) is within two edits of the `len` bytes at typed. */
static void suggest(Error *err, const char *typed, size_t len, const char *const *first, size_t n, size_t stride,
                    const char *rest)
{
    const char *best = NULL;
    size_t best_d = 3;
    for (size_t i = 0; i < n; i++) {
        const char *name = *(const char *const *)(const void *)((const char *)first + i * stride);
        if (!name) continue;
        size_t d = edit_distance(typed, len, name);
        if (d < best_d) {
            best_d = d;
            best = name;
        }
    }
    if (best) error_append(err, " (did you mean '%s%s'?)", best, rest);
}

/* ---------------------------------------------------------------- values */

/* Up to `max` numbers separated by commas or blanks; returns how many, -1 when the text
 * is not that. A number must be a finite float too: the scene stores floats, and 1e39
 * would become +inf there. */
static int read_numbers(const char *v, double *out, int max)
{
    int n = 0;
    const char *p = v;
    for (;;) {
        while (isspace((unsigned char)*p)) p++;
        if (!*p) break;
        if (n == max) return -1;
        char *end;
        errno = 0;
        double x = strtod(p, &end);
        if (end == p || errno || !isfinite(x) || fabs(x) > FLT_MAX) return -1;
        out[n++] = x;
        p = end;
        while (isspace((unsigned char)*p)) p++;
        if (*p == ',') {
            p++;
            while (isspace((unsigned char)*p)) p++;
            if (!*p) return -1;   /* a trailing comma */
        }
    }
    return n;
}

static Status bad_value(Error *err, const char *key, const char *expected, const char *v)
{
    return error_set(err, ST_USAGE, "scene parameter '%s' expects %s, got '%s'", key, expected, v);
}

/* Reads `v` as p says into the object at obj. */
static Status param_write(const ParamSpec *p, void *obj, const char *key, const char *v, Error *err)
{
    double x[3];
    int n = read_numbers(v, x, 3);
    void *dst = (char *)obj + p->offset;
    switch (p->kind) {
    case PK_NUMBER:
        if (n != 1 || x[0] < p->lo || x[0] > p->hi || (p->open && (x[0] == p->lo || x[0] == p->hi))) {
            char what[96];
            snprintf(what, sizeof what, "a number in %s%g, %g%s", p->open ? "(" : "[", p->lo, p->hi,
                     p->open ? ")" : "]");
            return bad_value(err, key, what, v);
        }
        *(float *)dst = (float)x[0];
        return ST_OK;
    case PK_UINT:
    case PK_UINT_AUTO:
        if (p->kind == PK_UINT_AUTO && strcmp(v, "auto") == 0) {
            *(uint *)dst = 0u;
            return ST_OK;
        }
        if (n != 1 || x[0] != floor(x[0]) || x[0] < p->lo || x[0] > p->hi) {
            char what[96];
            snprintf(what, sizeof what, "%san integer in [%.0f, %.0f]", p->kind == PK_UINT_AUTO ? "auto or " : "",
                     p->lo, p->hi);
            return bad_value(err, key, what, v);
        }
        *(uint *)dst = (uint)x[0];
        return ST_OK;
    case PK_COLOR:
        if (n == 1) x[1] = x[2] = x[0];
        if ((n != 1 && n != 3) || x[0] < 0 || x[1] < 0 || x[2] < 0)
            return bad_value(err, key, "a colour: one number >= 0 or three (\"0.8,0.2,0.2\")", v);
        break;
    case PK_POINT:
        if (n != 3) return bad_value(err, key, "three numbers (\"0,1,5\")", v);
        break;
    case PK_DIR:
        if (n != 3 || (x[0] == 0 && x[1] == 0 && x[2] == 0))
            return bad_value(err, key, "a direction, three numbers not all 0 (\"0,1,0\")", v);
        if (p->normalise) {
            double len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            for (int i = 0; i < 3; i++) x[i] /= len;
        }
        break;
    }
    *(vec3 *)dst = v3((float)x[0], (float)x[1], (float)x[2]);
    return ST_OK;
}

/* The parameter `name` of the table, or an error naming what there is. */
static Status param_find(const ParamSpec *t, size_t n, const char *name, const char *key, const char *what,
                         const ParamSpec **out, Error *err)
{
    for (size_t i = 0; i < n; i++)
        if (strcmp(t[i].name, name) == 0) {
            *out = &t[i];
            return ST_OK;
        }
    error_set(err, ST_USAGE, "unknown scene parameter '%s': %s has", key, what);
    for (size_t i = 0; i < n; i++) error_append(err, "%s %s", i ? "," : "", t[i].name);
    suggest(err, name, strlen(name), &t[0].name, n, sizeof t[0], "");
    return ST_USAGE;
}

/* ---------------------------------------------------------------- objects */

/* material.NAME.PARAM: every material of that name (a name may be used by several, as
 * an OBJ's MTL and a glTF's meshes do). */
static Status set_material(Scene *s, const char *key, const char *rest, const char *v, Error *err)
{
    const char *dot = strrchr(rest, '.');
    if (!dot || dot == rest)
        return error_set(err, ST_USAGE, "scene parameter '%s' must be material.NAME.PARAM", key);
    size_t len = (size_t)(dot - rest);
    const ParamSpec *p;
    Status st = param_find(material_params, COUNT(material_params), dot + 1, key, "a material", &p, err);
    if (st) return st;
    size_t found = 0;
    for (size_t i = 0; i < s->n_materials; i++) {
        const char *name = s->material_names[i];
        if (!name || strlen(name) != len || strncmp(name, rest, len) != 0) continue;
        if ((st = param_write(p, &s->materials[i], key, v, err))) return st;
        found++;
    }
    if (found) return ST_OK;
    error_set(err, ST_USAGE, "scene parameter '%s': the scene has no material named '%.*s'", key, (int)len, rest);
    suggest(err, rest, len, (const char *const *)s->material_names, s->n_materials, sizeof *s->material_names, "");
    return ST_USAGE;
}

/* light.N.PARAM: the N-th point, spot or directional light. */
static Status set_light(Scene *s, const char *key, const char *rest, const char *v, Error *err)
{
    char *end;
    errno = 0;
    unsigned long n = strtoul(rest, &end, 10);
    if (end == rest || *end != '.' || !isdigit((unsigned char)rest[0]) || errno)
        return error_set(err, ST_USAGE, "scene parameter '%s' must be light.N.PARAM, N from 0", key);
    if (n >= s->n_delta_lights)
        return error_set(err, ST_USAGE, "scene parameter '%s': the scene has %zu point, spot or directional "
                         "light%s (emitting surfaces are set as material.NAME.emission)", key, s->n_delta_lights,
                         s->n_delta_lights == 1 ? "" : "s");
    const ParamSpec *p;
    Status st = param_find(light_params, COUNT(light_params), end + 1, key, "a light", &p, err);
    return st ? st : param_write(p, &s->delta_lights[n], key, v, err);
}

/* camera.P, image.P, background.P */
static Status set_simple(const ParamSpec *t, size_t n, void *obj, const char *what, const char *key,
                         const char *rest, const char *v, Error *err)
{
    const ParamSpec *p;
    Status st = param_find(t, n, rest, key, what, &p, err);
    return st ? st : param_write(p, obj, key, v, err);
}

Status scene_param_set(Scene *s, const char *key, const char *value, Error *err)
{
    static const char *const kinds[] = { "camera", "image", "background", "material", "light" };
    const char *dot = strchr(key, '.');
    size_t len = dot ? (size_t)(dot - key) : strlen(key);
    const char *rest = dot ? dot + 1 : "";
    if (len == 6 && strncmp(key, "camera", 6) == 0) {
        Status st = camera_param_check(&s->camera, key, rest, err);
        return st ? st : set_simple(camera_params, COUNT(camera_params), &s->camera, "the camera", key, rest, value,
                                    err);
    }
    if (len == 5 && strncmp(key, "image", 5) == 0)
        return set_simple(image_params, COUNT(image_params), &s->image, "the image", key, rest, value, err);
    if (len == 10 && strncmp(key, "background", 10) == 0)
        return set_simple(background_params, COUNT(background_params), s, "the background", key, rest, value, err);
    if (len == 8 && strncmp(key, "material", 8) == 0) return set_material(s, key, rest, value, err);
    if (len == 5 && strncmp(key, "light", 5) == 0) return set_light(s, key, rest, value, err);
    error_set(err, ST_USAGE, "unknown scene parameter '%s': a path starts with camera., image., background., "
              "material.NAME. or light.N.", key);
    suggest(err, key, len, kinds, COUNT(kinds), sizeof kinds[0], key + len);
    return ST_USAGE;
}
