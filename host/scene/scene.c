/* scene.c — scene storage: the primitive, material, texture and light arrays, and
 * their lookups. The material constructors are material.c, the light list
 * scene_lights.c, the precision checks scene_precision.c. */
#include "scene/scene.h"

#include "base/array.h"
#include "scene/env_dist.h"

#include "util/kmath.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/instance.h"

void scene_init(Scene *s)
{
    memset(s, 0, sizeof *s);
    s->camera.from = v3(0.0f, 0.0f, 0.0f);
    s->camera.at = v3(0.0f, 0.0f, -1.0f);
    s->camera.up = v3(0.0f, 1.0f, 0.0f);
    s->camera.vfov = 40.0f;
    s->camera.aperture = 0.0f;
    s->camera.focus_dist = 0.0f;
    s->image.width = 512;
    s->image.height = 512;
    s->image.spp = 64;
    s->image.max_depth = 8;
    s->image.split = SCENE_SPLIT_AUTO;
    s->image.seed = 1;
    s->bg_type = BG_CONSTANT;
    s->bg_color = v3(0.0f, 0.0f, 0.0f);
    s->bg_zenith = v3(0.0f, 0.0f, 0.0f);
    s->env_light = NO_INDEX;
    s->camera.type = CAMERA_PERSPECTIVE;
    s->camera.ortho_height = 1.0f;
    s->camera.shutter_open = 0.0f;
    s->camera.shutter_close = 1.0f;
    s->ambient = v3(0.0f, 0.0f, 0.0f);
    s->integrator = INTEGRATOR_PATH;
    s->linear_output = 0;
    s->shadows = 1;
    s->camera_medium = SCENE_MEDIUM_UNSET;
}

void scene_free(Scene *s)
{
    if (s->animation) s->animation->free(s->animation);
    s->animation = NULL;
    for (size_t i = 0; i < s->n_materials; i++) free(s->material_names[i]);
    free(s->material_names);
    for (size_t i = 0; i < s->n_material_textures; i++) free(s->material_textures[i]);
    free(s->material_textures);
    free(s->materials);
    free(s->camera_keys);
    free(s->instance_motion);
    free(s->motion_keys);
    free(s->spheres);
    free(s->sphere_xforms);
    free(s->triangles);
    free(s->shading);
    free(s->tri_extras);
    free(s->tri_extra_of);
    free(s->boxes);
    free(s->planes);
    free(s->revsurfaces);
    free(s->rev_points);
    free(s->lights);
    free(s->delta_lights);
    for (size_t i = 0; i < s->n_textures; i++) {
        free(s->texture_names[i]);
        free(s->texture_sources[i]);
    }
    free(s->texture_names);
    free(s->texture_sources);
    free(s->textures);
    free(s->texels);
    free(s->env_cdf);
    for (size_t i = 0; i < s->n_media; i++) free(s->medium_names[i]);
    free(s->medium_names);
    free(s->media);
    free(s->medium_bindings);
    free(s->grids);
    free(s->grid_data);
    free(s->path);
    free(s->output_hint);
    for (size_t i = 0; i < s->n_warnings; i++) free(s->warnings[i]);
    free(s->warnings);
    strmap_free(&s->material_by_name);
    strmap_free(&s->texture_by_name);
    strmap_free(&s->texture_by_source);
    scene_free_objects(s);
    memset(s, 0, sizeof *s);
}

/* One generic append for every primitive array: the id space is 32-bit (NO_INDEX is
 * reserved), so the total primitive count is capped below 2^32 - 1. */
static Status append(void **arr, size_t *n, size_t *cap, const void *item, size_t elem,
                     const Scene *s, Error *err)
{
    size_t total = s->n_spheres + s->n_triangles + s->n_boxes + s->n_revsurfaces + s->n_planes;
    if (total >= (size_t)NO_INDEX - 1)
        return error_set(err, ST_INPUT, "too many primitives (the limit is %u)", NO_INDEX - 2);
    if (array_reserve(arr, cap, *n + 1, elem))
        return error_set(err, ST_INTERNAL, "out of memory growing the scene");
    memcpy((char *)*arr + *n * elem, item, elem);
    (*n)++;
    return ST_OK;
}

Status scene_set_path(Scene *s, const char *path, Error *err)
{
    size_t n = strlen(path);
    char *copy = malloc(n + 1);
    if (!copy) return error_set(err, ST_INTERNAL, "out of memory");
    memcpy(copy, path, n + 1);
    free(s->path);
    s->path = copy;
    return ST_OK;
}

Status scene_add_material(Scene *s, const char *name, Material m, uint *index, Error *err)
{
    /* Both arrays share cap_materials. The names grow first, through a copy of it: if
     * the materials then fail to grow, the recorded capacity is still the smaller one
     * (the materials'), so neither array can be overrun by a later call. */
    size_t cap_names = s->cap_materials;
    if (array_reserve((void **)&s->material_names, &cap_names, s->n_materials + 1, sizeof(char *)) ||
        array_reserve((void **)&s->materials, &s->cap_materials, s->n_materials + 1, sizeof m))
        return error_set(err, ST_INTERNAL, "out of memory growing the material list");
    char *copy = malloc(strlen(name) + 1);
    if (!copy) return error_set(err, ST_INTERNAL, "out of memory");
    strcpy(copy, name);
    if (strmap_add(&s->material_by_name, name, strlen(name), (uint32_t)s->n_materials) < 0) {
        free(copy);
        return error_set(err, ST_INTERNAL, "out of memory");
    }
    s->materials[s->n_materials] = m;
    s->material_names[s->n_materials] = copy;
    if (index) *index = (uint)s->n_materials;
    s->n_materials++;
    return ST_OK;
}

Status scene_add_sphere(Scene *s, Sphere sp, Error *err)
{
    sp.light = NO_INDEX;
    return append((void **)&s->spheres, &s->n_spheres, &s->cap_spheres, &sp, sizeof sp, s, err);
}

Status scene_add_ellipsoid(Scene *s, const Transform *m, uint material, Error *err)
{
    Transform inv;
    if (!transform_invert(m, &inv)) return error_set(err, ST_INPUT, "the sphere's transform is singular");
    SphereXform x;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) {
            x.to_world[4 * i + j] = (float)m->m[i][j];
            x.to_object[4 * i + j] = (float)inv.m[i][j];
        }
    /* the Frobenius norm bounds the largest stretch: a bounding sphere about M's origin */
    double r2 = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) r2 += (double)x.to_world[4 * i + j] * x.to_world[4 * i + j];
    Sphere sp;
    memset(&sp, 0, sizeof sp);
    sp.center = v3(x.to_world[3], x.to_world[7], x.to_world[11]);
    sp.radius = nextafterf((float)sqrt(r2), INFINITY);
    sp.material = material;
    for (int i = 0; i < 24; i++)
        if (!isfinite(i < 12 ? x.to_world[i] : x.to_object[i - 12]))
            return error_set(err, ST_INPUT, "the sphere's transform or its inverse does not fit in floats");
    if (!(sp.radius > 0) || !isfinite(sp.radius) || !isfinite(fabsf(sp.center.x) + sp.radius) ||
        !isfinite(fabsf(sp.center.y) + sp.radius) || !isfinite(fabsf(sp.center.z) + sp.radius))
        return error_set(err, ST_INPUT, "the sphere reaches beyond the largest float (about 3.4e38)");
    if (s->n_sphere_xforms >= (size_t)NO_INDEX - 1u)
        return error_set(err, ST_INPUT, "too many transformed spheres");
    sp.xform = (uint)s->n_sphere_xforms + 1u;
    Status st = append((void **)&s->sphere_xforms, &s->n_sphere_xforms, &s->cap_sphere_xforms, &x, sizeof x, s, err);
    if (!st) st = scene_add_sphere(s, sp, err);
    return st;
}

Status scene_add_triangle(Scene *s, Triangle t, Error *err)
{
    t.light = NO_INDEX;
    return append((void **)&s->triangles, &s->n_triangles, &s->cap_triangles, &t, sizeof t, s, err);
}

Status scene_add_shading(Scene *s, TriShading sh, uint *index, Error *err)
{
    if (s->n_shading >= (size_t)NO_INDEX - 1)
        return error_set(err, ST_INPUT, "too many shading records");
    if (array_reserve((void **)&s->shading, &s->cap_shading, s->n_shading + 1, sizeof sh))
        return error_set(err, ST_INTERNAL, "out of memory growing the scene");
    /* once any triangle has extras, every shading record has an entry in tri_extra_of */
    if (s->n_tri_extra_of &&
        array_reserve((void **)&s->tri_extra_of, &s->cap_tri_extra_of, s->n_shading + 1, sizeof *s->tri_extra_of))
        return error_set(err, ST_INTERNAL, "out of memory growing the scene");
    sh.flags &= ~TRI_HAS_EXTRA;
    s->shading[s->n_shading] = sh;
    if (s->n_tri_extra_of) s->tri_extra_of[s->n_tri_extra_of++] = NO_INDEX;
    if (index) *index = (uint)s->n_shading;
    s->n_shading++;
    return ST_OK;
}

Status scene_add_tri_extra(Scene *s, uint shading, TriExtra e, Error *err)
{
    if (shading >= s->n_shading) return error_set(err, ST_INTERNAL, "corner attributes for no shading record");
    if (array_reserve((void **)&s->tri_extra_of, &s->cap_tri_extra_of, s->n_shading, sizeof *s->tri_extra_of) ||
        array_reserve((void **)&s->tri_extras, &s->cap_tri_extras, s->n_tri_extras + 1, sizeof e))
        return error_set(err, ST_INTERNAL, "out of memory growing the scene");
    while (s->n_tri_extra_of < s->n_shading) s->tri_extra_of[s->n_tri_extra_of++] = NO_INDEX;
    s->tri_extras[s->n_tri_extras] = e;
    s->tri_extra_of[shading] = (uint)s->n_tri_extras++;
    s->shading[shading].flags |= TRI_HAS_EXTRA;
    return ST_OK;
}

Status scene_add_box(Scene *s, Box b, Error *err)
{
    b.light = NO_INDEX;
    return append((void **)&s->boxes, &s->n_boxes, &s->cap_boxes, &b, sizeof b, s, err);
}

Status scene_add_plane(Scene *s, Plane p, Error *err)
{
    return append((void **)&s->planes, &s->n_planes, &s->cap_planes, &p, sizeof p, s, err);
}

Status scene_add_revsurface(Scene *s, RevSurface r, const float *xy, Error *err)
{
    size_t n = 2u * ((size_t)r.n_segments * r.degree + 1u);
    if (r.n_segments == 0 || r.degree == 0 || r.degree > REV_MAX_DEGREE || s->n_rev_points / 2u >= NO_INDEX - n)
        return error_set(err, ST_INPUT, "a surface of revolution with %u segments of degree %u", r.n_segments,
                         r.degree);
    float rmax = 0.0f, lo_y = xy[1], hi_y = xy[1];
    for (size_t i = 0; i < n; i += 2) {
        rmax = fmaxf(rmax, fabsf(xy[i]));
        lo_y = fminf(lo_y, xy[i + 1]);
        hi_y = fmaxf(hi_y, xy[i + 1]);
    }
    r.lo = v3(r.axis_x - rmax, lo_y, r.axis_z - rmax);
    r.hi = v3(r.axis_x + rmax, hi_y, r.axis_z + rmax);
    r.first = (uint)(s->n_rev_points / 2u);
    if (array_reserve((void **)&s->rev_points, &s->cap_rev_points, s->n_rev_points + n, sizeof(float)))
        return error_set(err, ST_INTERNAL, "out of memory growing the scene");
    Status st = append((void **)&s->revsurfaces, &s->n_revsurfaces, &s->cap_revsurfaces, &r, sizeof r, s, err);
    if (st) return st;
    memcpy(s->rev_points + s->n_rev_points, xy, n * sizeof(float));
    s->n_rev_points += n;
    return ST_OK;
}

Status scene_add_light(Scene *s, Light l, Error *err)
{
    if (s->n_delta_lights >= (size_t)NO_INDEX / 2)
        return error_set(err, ST_INPUT, "too many lights");
    if (array_reserve((void **)&s->delta_lights, &s->cap_delta_lights, s->n_delta_lights + 1, sizeof l))
        return error_set(err, ST_INTERNAL, "out of memory growing the light list");
    l.prim = NO_INDEX;
    s->delta_lights[s->n_delta_lights++] = l;
    return ST_OK;
}

static char *dup_or_null(const char *text, int *failed)
{
    if (!text) return NULL;
    char *copy = malloc(strlen(text) + 1);
    if (!copy) *failed = 1;
    else strcpy(copy, text);
    return copy;
}

/* The texture_by_source key: the encoding's letter, then the path. */
static char *source_key(const char *path, int linear, size_t *len)
{
    size_t n = strlen(path);
    char *key = malloc(n + 2);
    if (!key) return NULL;
    key[0] = linear ? 'L' : 'S';
    memcpy(key + 1, path, n + 1);
    *len = n + 1;
    return key;
}

/* Records the texture about to be added as read from `source`, for the encodings its
 * texels serve (both for float texels), unless an earlier one does so already. 0, or
 * -1 when out of memory. */
static int texture_source_add(Scene *s, const char *source, uint flags)
{
    for (int linear = 0; linear < 2; linear++) {
        if (!(flags & TEX_FLOAT) && (linear ? (flags & TEX_SRGB) != 0 : (flags & TEX_SRGB) == 0)) continue;
        size_t len;
        char *key = source_key(source, linear, &len);
        int r = key ? strmap_add(&s->texture_by_source, key, len, (uint32_t)s->n_textures) : -1;
        free(key);
        if (r < 0) return -1;
    }
    return 0;
}

uint scene_find_texture_source(const Scene *s, const char *path, int linear)
{
    size_t len;
    char *key = source_key(path, linear, &len);
    uint32_t index = NO_INDEX;
    if (key && !strmap_find(&s->texture_by_source, key, len, &index)) index = NO_INDEX;
    free(key);
    return index;
}

Status scene_add_texture(Scene *s, const char *name, const char *source, Texture t, uint *index,
                         Error *err)
{
    if (s->n_textures >= (size_t)NO_INDEX - 1) return error_set(err, ST_INPUT, "too many textures");
    /* the three arrays share cap_textures: grow the two side arrays through copies of
     * it, so that a failure leaves the recorded capacity the smallest of the three */
    size_t cap_a = s->cap_textures, cap_b = s->cap_textures;
    if (array_reserve((void **)&s->texture_names, &cap_a, s->n_textures + 1, sizeof(char *)) ||
        array_reserve((void **)&s->texture_sources, &cap_b, s->n_textures + 1, sizeof(char *)) ||
        array_reserve((void **)&s->textures, &s->cap_textures, s->n_textures + 1, sizeof t))
        return error_set(err, ST_INTERNAL, "out of memory growing the texture list");
    int failed = 0;
    char *n = dup_or_null(name, &failed), *src = dup_or_null(source, &failed);
    if (!failed && name && strmap_add(&s->texture_by_name, name, strlen(name), (uint32_t)s->n_textures) < 0)
        failed = 1;
    if (!failed && source && texture_source_add(s, source, t.flags) < 0) failed = 1;
    if (failed) {
        free(n);
        free(src);
        return error_set(err, ST_INTERNAL, "out of memory");
    }
    s->textures[s->n_textures] = t;
    s->texture_names[s->n_textures] = n;
    s->texture_sources[s->n_textures] = src;
    if (index) *index = (uint)s->n_textures;
    s->n_textures++;
    return ST_OK;
}

Status scene_add_texels(Scene *s, const uint *texels, size_t n, uint *offset, Error *err)
{
    if (n > (size_t)NO_INDEX - 1 - s->n_texels)
        return error_set(err, ST_INPUT, "the textures are too large together (more than 2^32 texels)");
    if (array_reserve((void **)&s->texels, &s->cap_texels, s->n_texels + n, sizeof *texels))
        return error_set(err, ST_INTERNAL, "out of memory for the texture images");
    memcpy(s->texels + s->n_texels, texels, n * sizeof *texels);
    *offset = (uint)s->n_texels;
    s->n_texels += n;
    return ST_OK;
}

uint scene_find_texture(const Scene *s, const char *name)
{
    uint32_t index;
    return strmap_find(&s->texture_by_name, name, strlen(name), &index) ? index : NO_INDEX;
}

Status scene_set_material_texture(Scene *s, uint index, const char *path, Error *err)
{
    if (index >= s->n_materials)
        return error_set(err, ST_INTERNAL, "texture for material %u of %zu", index, s->n_materials);
    if (index >= s->n_material_textures) {
        char **grown = realloc(s->material_textures, (index + 1) * sizeof *grown);
        if (!grown) return error_set(err, ST_INTERNAL, "out of memory");
        for (size_t i = s->n_material_textures; i <= index; i++) grown[i] = NULL;
        s->material_textures = grown;
        s->n_material_textures = (size_t)index + 1;
    }
    char *copy = malloc(strlen(path) + 1);
    if (!copy) return error_set(err, ST_INTERNAL, "out of memory");
    strcpy(copy, path);
    free(s->material_textures[index]);
    s->material_textures[index] = copy;
    return ST_OK;
}

const char *scene_material_texture(const Scene *s, uint index)
{
    return index < s->n_material_textures ? s->material_textures[index] : NULL;
}

Status scene_warn(Scene *s, Error *err, const char *fmt, ...)
{
    /* a file with thousands of the same problem would bury the render's output */
    enum { MAX_WARNINGS = 20 };
    if (s->n_warnings > MAX_WARNINGS) return ST_OK;
    char msg[1024];
    if (s->n_warnings == MAX_WARNINGS) {
        snprintf(msg, sizeof msg, "more warnings follow; only the first %d are shown", MAX_WARNINGS);
    } else {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, sizeof msg, fmt, ap);
        va_end(ap);
    }
    char **grown = realloc(s->warnings, (s->n_warnings + 1) * sizeof *grown);
    if (!grown) return error_set(err, ST_INTERNAL, "out of memory");
    s->warnings = grown;
    grown[s->n_warnings] = malloc(strlen(msg) + 1);
    if (!grown[s->n_warnings]) return error_set(err, ST_INTERNAL, "out of memory");
    strcpy(grown[s->n_warnings++], msg);
    return ST_OK;
}

uint scene_find_material(const Scene *s, const char *name)
{
    uint32_t index;
    return strmap_find(&s->material_by_name, name, strlen(name), &index) ? index : NO_INDEX;
}

uint scene_first_triangle(const Scene *s) { return (uint)s->n_spheres; }
uint scene_first_box(const Scene *s) { return (uint)(s->n_spheres + s->n_triangles); }
uint scene_first_revsurface(const Scene *s) { return (uint)(s->n_spheres + s->n_triangles + s->n_boxes); }
uint scene_first_plane(const Scene *s) { return scene_first_revsurface(s) + (uint)s->n_revsurfaces; }
