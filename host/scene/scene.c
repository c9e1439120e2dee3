/* scene.c — scene storage, material helpers and the light list. */
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
    s->image.split = 1;
    s->image.seed = 1;
    s->bg_type = BG_CONSTANT;
    s->bg_color = v3(0.0f, 0.0f, 0.0f);
    s->bg_zenith = v3(0.0f, 0.0f, 0.0f);
    s->env_light = NO_INDEX;
    s->camera.type = CAMERA_PERSPECTIVE;
    s->camera.ortho_height = 1.0f;
    s->ambient = v3(0.0f, 0.0f, 0.0f);
    s->integrator = INTEGRATOR_PATH;
    s->linear_output = 0;
    s->shadows = 1;
}

void scene_free(Scene *s)
{
    for (size_t i = 0; i < s->n_materials; i++) free(s->material_names[i]);
    free(s->material_names);
    for (size_t i = 0; i < s->n_material_textures; i++) free(s->material_textures[i]);
    free(s->material_textures);
    free(s->materials);
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
    free(s->path);
    free(s->output_hint);
    for (size_t i = 0; i < s->n_warnings; i++) free(s->warnings[i]);
    free(s->warnings);
    strmap_free(&s->material_by_name);
    strmap_free(&s->texture_by_name);
    strmap_free(&s->texture_by_source);
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

static Material material_base(uint type)
{
    Material m;
    memset(&m, 0, sizeof m);
    m.type = type;
    m.texture = NO_INDEX;
    m.texture_rm = NO_INDEX;
    m.texture_normal = NO_INDEX;
    m.normal_scale = 1.0f;
    m.ior = 1.5f;
    m.alpha = 1.0f;
    m.alpha_cutoff = 0.5f;      /* glTF's default alphaCutoff */
    m.texture_emission = NO_INDEX;
    m.mix_a = m.mix_b = m.mix_texture = NO_INDEX;
    m.specular_factor = 1.0f;   /* KHR_materials_specular's defaults: F0 and F90 as they were */
    m.specular_color = v3s(1.0f);
    m.texture_specular = m.texture_specular_color = NO_INDEX;
    m.texture_sheen_color = m.texture_sheen_roughness = NO_INDEX;
    return m;
}

Material material_diffuse(vec3 albedo)
{
    Material m = material_base(MAT_DIFFUSE);
    m.albedo = albedo;
    return m;
}

Material material_metal(vec3 albedo, float fuzz)
{
    Material m = material_base(MAT_METAL);
    m.albedo = albedo;
    m.fuzz = fuzz;
    return m;
}

Material material_dielectric(float ior)
{
    Material m = material_base(MAT_DIELECTRIC);
    m.albedo = v3s(1.0f);
    m.ior = ior;
    return m;
}

Material material_conductor(vec3 eta, vec3 k, float roughness)
{
    Material m = material_base(MAT_CONDUCTOR);
    m.albedo = v3s(1.0f);
    m.eta = eta;
    m.k = k;
    m.roughness = roughness;
    return m;
}

Material material_conductor_f0(vec3 f0, float roughness)
{
    Material m = material_conductor(v3s(1.0f), v3s(0.0f), roughness);
    m.specular = f0;
    m.flags |= MAT_F0;
    return m;
}

static Material material_layered(uint base, float roughness)
{
    Material m = material_base(MAT_LAYERED);
    m.layer_base = base;
    m.roughness = roughness;
    m.layer_thickness = 0.01f;
    m.layer_depth = 10;
    m.layer_samples = 1;
    return m;
}

Material material_coated_diffuse(vec3 diffuse, float roughness)
{
    Material m = material_layered(LAYER_BASE_DIFFUSE, roughness);
    m.albedo = diffuse;
    return m;
}

Material material_coated_conductor(vec3 eta, vec3 k, float base_roughness, float roughness)
{
    Material m = material_layered(LAYER_BASE_CONDUCTOR, roughness);
    m.albedo = v3s(1.0f);
    m.eta = eta;
    m.k = k;
    m.base_roughness = base_roughness;
    return m;
}

Material material_mix(uint a, uint b, float amount, uint amount_tex)
{
    Material m = material_base(MAT_MIX);
    m.mix_a = a;
    m.mix_b = b;
    m.mix_amount = amount;
    m.mix_texture = amount_tex;
    return m;
}

/* The depth of `index`'s mixes, entered `level` mixes deep: a cycle, or a chain deeper
 * than the kernels follow, stops at MIX_MAX_DEPTH + 1 (and so do the calls). */
static uint mix_depth(const Scene *s, uint index, uint level)
{
    if (index >= s->n_materials || level > MIX_MAX_DEPTH) return MIX_MAX_DEPTH + 1;
    const Material *m = &s->materials[index];
    if (m->type != MAT_MIX) return 0;
    uint a = mix_depth(s, m->mix_a, level + 1);
    uint b = a > MIX_MAX_DEPTH ? a : mix_depth(s, m->mix_b, level + 1);
    uint deepest = a > b ? a : b;
    return deepest > MIX_MAX_DEPTH ? deepest : deepest + 1;
}

uint scene_mix_depth(const Scene *s, uint index) { return mix_depth(s, index, 0); }

Material material_principled(vec3 base, float metallic, float roughness)
{
    Material m = material_base(MAT_PRINCIPLED);
    m.albedo = base;
    m.metallic = metallic;
    m.roughness = roughness;
    return m;
}

/* -ln(color) / distance per channel. A channel of 0 (all absorbed) is taken as the
 * smallest normal float, so sigma_a stays finite (exp(-sigma_a 0) must still be 1). */
static float absorption_channel(float color, float distance)
{
    float c = color < FLT_MIN ? FLT_MIN : (color > 1.0f ? 1.0f : color);
    return isinf(distance) ? 0.0f : -logf(c) / distance;
}

vec3 material_absorption(vec3 color, float distance)
{
    return v3(absorption_channel(color.x, distance), absorption_channel(color.y, distance),
              absorption_channel(color.z, distance));
}

/* Measured spectra interpolated at 650, 550 and 450 nm for R, G and B: Ag, Al, Au, Cu
 * from pbrt-v4 (src/pbrt/util/spectrum.cpp, after refractiveindex.info), Cr and Ni from
 * Mitsuba 0.6 (data/ior/Cr.*.spd, Ni_palik.*.spd: the luxpop database, Palik's
 * Handbook of Optical Constants of Solids), Fe and Ti from Johnson & Christy, Phys.
 * Rev. B 9, 5056 (1974), as tabulated by refractiveindex.info (data-nk/main/Fe/Johnson.yml,
 * Ti/Johnson.yml; linear in wavelength between its samples). */
static const struct {
    const char *name;
    float eta[3], k[3];
} metal_presets[] = {
    {"Ag", {0.1394f, 0.1248f, 0.1517f}, {4.1288f, 3.3396f, 2.4704f}},
    {"Al", {1.4748f, 0.9586f, 0.6180f}, {7.7941f, 6.6870f, 5.4694f}},
    {"Au", {0.1678f, 0.3504f, 1.5085f}, {3.1378f, 2.7141f, 1.8788f}},
    {"Cr", {3.6375f, 3.1158f, 1.9277f}, {4.3644f, 4.4228f, 4.1675f}},
    {"Cu", {0.2166f, 0.9582f, 1.1658f}, {3.6377f, 2.5771f, 2.3939f}},
    {"Fe", {2.9114f, 2.9497f, 2.5845f}, {3.0893f, 2.9318f, 2.7670f}},
    {"Ni", {2.0140f, 1.7724f, 1.6288f}, {3.8079f, 3.2526f, 2.6540f}},
    {"Ti", {2.7407f, 2.5418f, 2.2670f}, {3.8143f, 3.4345f, 3.0385f}},
};

int material_metal_preset(const char *name, size_t len, vec3 *eta, vec3 *k)
{
    for (size_t i = 0; i < sizeof metal_presets / sizeof metal_presets[0]; i++) {
        if (strlen(metal_presets[i].name) != len || memcmp(metal_presets[i].name, name, len) != 0) continue;
        *eta = v3(metal_presets[i].eta[0], metal_presets[i].eta[1], metal_presets[i].eta[2]);
        *k = v3(metal_presets[i].k[0], metal_presets[i].k[1], metal_presets[i].k[2]);
        return 1;
    }
    return 0;
}

Material material_emissive(vec3 radiance)
{
    Material m = material_base(MAT_EMISSIVE);
    m.emission = radiance;
    return m;
}

Material material_phong(vec3 diffuse, vec3 specular, float shininess)
{
    Material m = material_base(MAT_PHONG);
    m.albedo = diffuse;
    m.specular = specular;
    m.shininess = shininess;
    m.ior = 1.0f;
    return m;
}

Light light_default(uint type)
{
    Light l;
    memset(&l, 0, sizeof l);
    l.type = type;
    l.prim = NO_INDEX;
    l.atten2 = 1.0f;
    l.direction = v3(0.0f, -1.0f, 0.0f);
    l.cos_outer = (float)cos(M_PI / 6.0);
    l.cos_inner = l.cos_outer;
    return l;
}

static int is_emissive(const Scene *s, uint material)
{
    if (material >= s->n_materials) return 0;
    /* any material may emit (a diffuse emitter is what the furnace test needs). An
     * emission texture or an alpha cut-out makes the emitted radiance vary over the
     * surface in a way light sampling does not know: such surfaces are found by BSDF
     * sampling alone (full weight), like the background, which keeps them unbiased. */
    const Material *m = &s->materials[material];
    if (m->texture_emission != NO_INDEX || (m->flags & (MAT_ALPHA_MASK | MAT_ALPHA_BLEND))) return 0;
    return v3_luminance(m->emission) > 0.0f;
}

static double triangle_area(const Triangle *t)
{
    vec3 c = v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0));
    return 0.5 * sqrt((double)c.x * c.x + (double)c.y * c.y + (double)c.z * c.z);
}

static int v3_same(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* Whether triangles a and b (lights of one material, unit normals na and nb) are the two
 * halves of one parallelogram: they share two corners (the diagonal, bit for bit), b's
 * third corner is the reflection of a's across the diagonal's middle (to 1e-5 of the
 * diagonal), their areas agree to 1e-5 and their winding normals point the same way.
 * Then *corner is a's corner off the diagonal and *e1, *e2 the edges from it, so the
 * parallelogram is corner + s e1 + t e2 over [0,1)^2. */
static int triangles_form_quad(const Triangle *a, const Triangle *b, vec3 na, vec3 nb, vec3 *corner, vec3 *e1,
                               vec3 *e2)
{
    const vec3 pa[3] = { a->p0, a->p1, a->p2 }, pb[3] = { b->p0, b->p1, b->p2 };
    for (int i = 0; i < 3; i++) {
        vec3 d0 = pa[(i + 1) % 3], d1 = pa[(i + 2) % 3];
        int j0 = -1, j1 = -1;
        for (int j = 0; j < 3; j++) {
            if (v3_same(pb[j], d0)) j0 = j;
            else if (v3_same(pb[j], d1)) j1 = j;
        }
        if (j0 < 0 || j1 < 0) continue;
        vec3 far = v3_sub(v3_add(d0, d1), pa[i]), off = v3_sub(pb[3 - j0 - j1], far), diag = v3_sub(d1, d0);
        double off2 = (double)v3_dot(off, off), diag2 = (double)v3_dot(diag, diag);
        double area_a = triangle_area(a), area_b = triangle_area(b);
        if (!(off2 <= 1e-10 * diag2) || !(fabs(area_a - area_b) <= 1e-5 * area_a) || !(area_a > 0.0) ||
            !(v3_dot(na, nb) > 0.0f))
            return 0;
        *corner = pa[i];
        *e1 = v3_sub(d0, pa[i]);
        *e2 = v3_sub(d1, pa[i]);
        return 1;
    }
    return 0;
}

/* Marks consecutive triangle lights [first, end), their normals set, that are the halves
 * of a parallelogram (types.h, LIGHT_QUAD_*) and gives each pair equal power, hence equal
 * choice probabilities, so that the pair's first light-sample coordinate can run across
 * both. */
static void pair_quad_lights(const Scene *s, Light *lights, double *power, size_t first, size_t end)
{
    uint first_tri = scene_first_triangle(s);
    for (size_t k = first; k + 1 < end; k++) {
        const Triangle *a = &s->triangles[lights[k].prim - first_tri];
        const Triangle *b = &s->triangles[lights[k + 1].prim - first_tri];
        vec3 corner, e1, e2;
        if (a->material != b->material ||
            !triangles_form_quad(a, b, lights[k].normal, lights[k + 1].normal, &corner, &e1, &e2))
            continue;
        double mean = 0.5 * (power[k] + power[k + 1]);
        for (size_t h = k; h <= k + 1; h++) {
            lights[h].quad = h == k ? LIGHT_QUAD_FIRST : LIGHT_QUAD_SECOND;
            lights[h].position = corner;
            lights[h].direction = e1;
            lights[h].intensity = e2;
            power[h] = mean;
        }
        k++;
    }
}

static double box_area(const Box *b)
{
    double dx = (double)b->hi.x - b->lo.x, dy = (double)b->hi.y - b->lo.y, dz = (double)b->hi.z - b->lo.z;
    return 2.0 * (dx * dy + dy * dz + dz * dx);
}

/* Radius of the bounding sphere of the finite primitives (1 when there are none): the
 * size of the region a point or directional light shines on, for its power estimate. */
static double scene_radius(const Scene *s)
{
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
#define GROW(p, r)                                                                        \
    do {                                                                                  \
        double c_[3] = { (p).x, (p).y, (p).z };                                           \
        for (int a_ = 0; a_ < 3; a_++) {                                                  \
            if (c_[a_] - (r) < lo[a_]) lo[a_] = c_[a_] - (r);                             \
            if (c_[a_] + (r) > hi[a_]) hi[a_] = c_[a_] + (r);                             \
        }                                                                                 \
    } while (0)
    for (size_t i = 0; i < s->n_spheres; i++) GROW(s->spheres[i].center, (double)s->spheres[i].radius);
    for (size_t i = 0; i < s->n_triangles; i++) {
        GROW(s->triangles[i].p0, 0.0);
        GROW(s->triangles[i].p1, 0.0);
        GROW(s->triangles[i].p2, 0.0);
    }
    for (size_t i = 0; i < s->n_boxes; i++) {
        GROW(s->boxes[i].lo, 0.0);
        GROW(s->boxes[i].hi, 0.0);
    }
#undef GROW
    if (!(hi[0] >= lo[0])) return 1.0;
    double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    double r = 0.5 * sqrt(dx * dx + dy * dy + dz * dz);
    return r > 0.0 && isfinite(r) ? r : 1.0;
}

/* Estimated power of a delta light over a scene of radius r (see scene.h). */
static double delta_light_power(const Light *l, double r)
{
    double lum = v3_luminance(l->intensity);
    if (light_has(l->type, LT_INFINITE)) return M_PI * r * r * lum;
    double atten = (double)l->atten0 + (double)l->atten1 * r + (double)l->atten2 * r * r;
    double solid_angle = 4.0 * M_PI;
    if (light_has(l->type, LT_CONE))
        solid_angle = 2.0 * M_PI * (1.0 - 0.5 * ((double)l->cos_inner + (double)l->cos_outer));
    return atten > 0.0 ? solid_angle * r * r * lum / atten : 0.0;
}

Status scene_set_envmap_texels(Scene *s, const uint *texels, uint width, uint height, float intensity, Error *err)
{
    uint offset, index;
    Status st = scene_add_texels(s, texels, 3u * (size_t)width * height, &offset, err);
    if (st) return st;
    Texture t;
    memset(&t, 0, sizeof t);
    t.type = TEX_IMAGE;
    t.flags = TEX_FLOAT;
    t.offset = offset;
    t.width = width;
    t.height = height;
    if ((st = scene_add_texture(s, NULL, NULL, t, &index, err))) return st;
    return scene_set_envmap(s, index, intensity, 0.0f, err);
}

Status scene_set_envmap(Scene *s, uint texture, float intensity, float rotate, Error *err)
{
    const Texture *t = &s->textures[texture];
    if (!(t->flags & TEX_FLOAT))
        return error_set(err, ST_INPUT, "'%s': an environment map must be a high-dynamic-range image (.hdr or "
                         ".exr)", s->texture_sources[texture] ? s->texture_sources[texture] : "");
    /* the guide tables (kernels/light/envmap.h) hold pixel indices as exact floats */
    if (t->width > (1u << 24) || t->height > (1u << 24))
        return error_set(err, ST_INPUT, "'%s': an environment map is at most 16777216 pixels wide and high, not %ux%u",
                         s->texture_sources[texture] ? s->texture_sources[texture] : "", t->width, t->height);
    float *cdf;
    size_t n;
    double mean;
    Status st = env_dist_build(s->texels + t->offset, t->width, t->height, &cdf, &n, &mean, err);
    if (st) return st;
    free(s->env_cdf);
    s->env_cdf = cdf;
    s->n_env_cdf = n;
    s->env_mean = mean * (double)intensity;
    if (!(intensity > 0.0f)) {
        /* a black map is no light */
        free(s->env_cdf);
        s->env_cdf = NULL;
        s->n_env_cdf = 0;
    }
    s->bg_type = BG_MAP;
    s->bg_cubemap = texture;
    s->bg_color = v3s(intensity);
    s->bg_zenith = v3s(intensity);
    s->bg_rotate = rotate;
    return ST_OK;
}

Status scene_prepare_lights(Scene *s, Error *err)
{
    free(s->lights);
    s->lights = NULL;
    s->n_lights = 0;
    s->env_light = NO_INDEX;
    int env = s->bg_type == BG_MAP && s->n_env_cdf > 0;
    size_t n = (size_t)env;
    for (size_t i = 0; i < s->n_spheres; i++) {
        /* the kernels sample sphere lights by the cone a sphere subtends: an ellipsoid
         * has none (the pbrt reader makes emitting ones meshes) */
        if (s->spheres[i].xform && is_emissive(s, s->spheres[i].material))
            return error_set(err, ST_INPUT, "sphere %zu is an ellipsoid that emits light, which clpt cannot "
                             "sample; make it a mesh", i);
        n += (size_t)is_emissive(s, s->spheres[i].material);
    }
    for (size_t i = 0; i < s->n_triangles; i++) n += (size_t)is_emissive(s, s->triangles[i].material);
    for (size_t i = 0; i < s->n_boxes; i++) n += (size_t)is_emissive(s, s->boxes[i].material);
    n += s->n_delta_lights;
    if (n == 0) return ST_OK;
    if (n >= (size_t)NO_INDEX) return error_set(err, ST_INPUT, "too many emissive primitives");
    Light *lights = calloc(n, sizeof *lights);
    double *power = calloc(n, sizeof *power);
    if (!lights || !power) {
        free(lights);
        free(power);
        return error_set(err, ST_INTERNAL, "out of memory building the light list");
    }
    size_t k = 0;
    double total = 0.0;
#define ADD_LIGHT(arr, count, first, area_expr)                                          \
    for (size_t i = 0; i < (count); i++) {                                                \
        if (!is_emissive(s, arr[i].material)) continue;                                   \
        double area = (area_expr);                                                        \
        lights[k].type = LIGHT_AREA;                                                      \
        lights[k].prim = (uint)((first) + i);                                             \
        lights[k].area = (float)area;                                                     \
        power[k] = M_PI * area * v3_luminance(s->materials[arr[i].material].emission);   \
        total += power[k];                                                                \
        arr[i].light = (uint)k;                                                           \
        k++;                                                                              \
    }
    ADD_LIGHT(s->spheres, s->n_spheres, 0, 4.0 * M_PI * (double)s->spheres[i].radius * s->spheres[i].radius)
    size_t first_tri_light = k;
    uint first_tri = scene_first_triangle(s);
    ADD_LIGHT(s->triangles, s->n_triangles, first_tri, triangle_area(&s->triangles[i]))
    for (size_t j = first_tri_light; j < k; j++) {
        /* the normal surface_at computes for the triangle: the same float operations */
        const Triangle *t = &s->triangles[lights[j].prim - first_tri];
        lights[j].normal = v3_norm(v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0)));
    }
    pair_quad_lights(s, lights, power, first_tri_light, k);
    ADD_LIGHT(s->boxes, s->n_boxes, scene_first_box(s), box_area(&s->boxes[i]))
#undef ADD_LIGHT
    double radius = s->n_delta_lights || env ? scene_radius(s) : 1.0;
    for (size_t i = 0; i < s->n_delta_lights; i++, k++) {
        lights[k] = s->delta_lights[i];
        lights[k].prim = NO_INDEX;
        power[k] = delta_light_power(&s->delta_lights[i], radius);
        if (!(power[k] >= 0.0) || !isfinite(power[k])) power[k] = 0.0;
        total += power[k];
    }
    if (env) {
        lights[k].type = LIGHT_ENV;
        lights[k].prim = NO_INDEX;
        power[k] = M_PI * s->env_mean * 4.0 * M_PI * radius * radius;
        if (!(power[k] >= 0.0) || !isfinite(power[k])) power[k] = 0.0;
        total += power[k];
        s->env_light = (uint)k++;
    }
    /* Degenerate or black lights get zero power; if all are, choose uniformly so the
     * distribution stays valid. */
    double acc = 0.0;
    for (size_t i = 0; i < n; i++) {
        double p = total > 0.0 ? power[i] / total : 1.0 / (double)n;
        acc += p;
        lights[i].pick_pdf = (float)p;
        lights[i].cdf = (float)acc;
    }
    lights[n - 1].cdf = 1.0f;  /* exact top so a uniform sample in [0,1) always lands */
    free(power);
    s->lights = lights;
    s->n_lights = n;
    return ST_OK;
}

/* ------------------------------------------------------------------ precision */

/* Radii and distances the kernels square: 2^62 squared is 2^124, far enough below
 * FLT_MAX (2^128) for sums of three squares. */
#define PRECISION_MAX_SQUARED_DISTANCE 0x1p62
/* A sphere's radius over the camera's distance from its surface: at 2^24 the camera
 * ray's hit computes |o - c|^2 - r^2 with no digit left; 2^22 leaves a margin. */
#define PRECISION_MAX_SPHERE_RATIO 0x1p22

static vec3 vmin(vec3 a, vec3 b) { return v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)); }
static vec3 vmax(vec3 a, vec3 b) { return v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)); }

void scene_count_tiny_triangles(const Scene *s, size_t first, size_t end, size_t *tiny, size_t *with_area,
                                vec3 *lo, vec3 *hi)
{
    *tiny = *with_area = 0;
    vec3 l = v3s(INFINITY), h = v3s(-INFINITY);
    for (size_t i = first; i < end && i < s->n_triangles; i++) {
        const Triangle *t = &s->triangles[i];
        l = vmin(l, vmin(t->p0, vmin(t->p1, t->p2)));
        h = vmax(h, vmax(t->p0, vmax(t->p1, t->p2)));
        /* the kernels' geometric normal (surface.h): float edges, cross, length */
        vec3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0);
        double x = (double)e1.y * e2.z - (double)e1.z * e2.y, y = (double)e1.z * e2.x - (double)e1.x * e2.z,
               z = (double)e1.x * e2.y - (double)e1.y * e2.x;
        if (!(x * x + y * y + z * z > 0.0)) continue;
        (*with_area)++;
        /* a subnormal squared length still normalises (measured: the bunny 1.5e-9
         * across renders right, 1.5e-11 black); below 2^-140 it keeps too few bits */
        vec3 n = v3_cross(e1, e2);
        if (!(v3_dot(n, n) >= 0x1p-140f)) (*tiny)++;
    }
    if (lo) *lo = l;
    if (hi) *hi = h;
}

double scene_triangles_reach(const Scene *s, size_t first, size_t end)
{
    double reach = 0.0;
    for (size_t i = first; i < end && i < s->n_triangles; i++) {
        const Triangle *t = &s->triangles[i];
        const vec3 c[3] = { t->p0, t->p1, t->p2 };
        for (int k = 0; k < 3; k++)
            reach = fmax(reach, fmax(fabs((double)c[k].x), fmax(fabs((double)c[k].y), fabs((double)c[k].z))));
    }
    return reach;
}

static Status check_sphere(const Scene *s, size_t i, Error *err)
{
    const Sphere *sp = &s->spheres[i];
    double fx = (double)s->camera.from.x - sp->center.x, fy = (double)s->camera.from.y - sp->center.y,
           fz = (double)s->camera.from.z - sp->center.z;
    double r = sp->radius, dist = sqrt(fx * fx + fy * fy + fz * fz);
    double gap = fabs(dist - r);
    const char *path = s->path ? s->path : "scene";
    if (r > PRECISION_MAX_SQUARED_DISTANCE || dist > PRECISION_MAX_SQUARED_DISTANCE)
        return error_set(err, ST_INPUT, "%s: sphere %zu (centre %g %g %g, radius %g) is too large or too far "
                         "from the camera for single precision: its radius and its distance from the camera "
                         "(%g) must be at most 2^62 (%g)", path, i + 1, (double)sp->center.x,
                         (double)sp->center.y, (double)sp->center.z, r, dist, PRECISION_MAX_SQUARED_DISTANCE);
    if (r > PRECISION_MAX_SPHERE_RATIO * gap)
        return error_set(err, ST_INPUT, "%s: sphere %zu (centre %g %g %g, radius %g) is %g from the camera, "
                         "more than 2^22 times closer than its radius: single precision cannot find where "
                         "the camera's rays meet it (use a plane for a ground this large, or move the camera "
                         "at least %g from it)", path, i + 1, (double)sp->center.x, (double)sp->center.y,
                         (double)sp->center.z, r, gap, r / PRECISION_MAX_SPHERE_RATIO);
    return ST_OK;
}

Status scene_check_precision(const Scene *s, Error *err)
{
    for (size_t i = 0; i < s->n_spheres; i++) {
        Status st = check_sphere(s, i, err);
        if (st) return st;
    }
    double reach = scene_triangles_reach(s, 0, s->n_triangles);
    if (reach > SCENE_MAX_COORDINATE)
        return error_set(err, ST_INPUT, "%s: a triangle has a corner %g from the origin, beyond the 2^62 (%g) "
                         "single precision can intersect: scale the scene down", s->path ? s->path : "scene",
                         reach, SCENE_MAX_COORDINATE);
    size_t tiny, with_area;
    vec3 lo, hi;
    scene_count_tiny_triangles(s, 0, s->n_triangles, &tiny, &with_area, &lo, &hi);
    if (tiny > 0 && tiny * 2 >= with_area)
        return error_set(err, ST_INPUT, "%s: %zu of the scene's %zu triangles are too small for single "
                         "precision (their normals underflow; the triangles span %g x %g x %g): scale them up",
                         s->path ? s->path : "scene", tiny, with_area, (double)(hi.x - lo.x),
                         (double)(hi.y - lo.y), (double)(hi.z - lo.z));
    return ST_OK;
}
