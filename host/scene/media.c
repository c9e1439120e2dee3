/* media.c — participating media in the host's scene (see media.h). */
#include "scene/media.h"

#include "base/array.h"
#include "scene/blackbody.h"

#include "util/kmath.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

Medium medium_homogeneous(vec3 sigma_a, vec3 sigma_s, float g)
{
    Medium m;
    memset(&m, 0, sizeof m);
    m.type = MEDIUM_HOMOGENEOUS;
    /* hg_sample_mu divides by g: nearly isotropic media are taken as isotropic */
    m.g = fabsf(g) < 1e-3f ? 0.0f : g;
    m.sigma_a = sigma_a;
    m.sigma_s = sigma_s;
    return m;
}

Medium medium_grid(vec3 sigma_a, vec3 sigma_s, float g, uint grid)
{
    Medium m = medium_homogeneous(sigma_a, sigma_s, g);
    m.type = MEDIUM_GRID;
    m.grid = grid;
    return m;
}

Medium medium_with_emission(Medium m, vec3 le)
{
    m.emission = le;
    m.flags = v3_is_zero(le) ? (m.flags & ~MEDIUM_EMISSIVE) : (m.flags | MEDIUM_EMISSIVE);
    return m;
}

Status scene_grid_set_emission(Scene *s, uint grid, const float *scale, Error *err)
{
    GridMedium *g = &s->grids[grid];
    size_t n = (size_t)g->nx * g->ny * g->nz, at = s->n_grid_data;
    if (at + n > 0xffffffffu) return error_set(err, ST_INPUT, "the density grids hold more than 2^32 values together");
    if (array_reserve((void **)&s->grid_data, &s->cap_grid_data, at + n, sizeof(float)))
        return error_set(err, ST_INTERNAL, "out of memory for an emission grid");
    memcpy(s->grid_data + at, scale, n * sizeof(float));
    g->emission_at = (uint)at;   /* > 0: the grid's densities come first */
    s->n_grid_data = at + n;
    return ST_OK;
}

int grid_emission_fits(const float *density, const float *scale, size_t n, double sa_le, double factor,
                       size_t *top)
{
    double dens = 0.0;
    *top = 0;
    for (size_t i = 0; i < n; i++) {
        dens = density[i] > dens ? density[i] : dens;
        *top = scale[i] > scale[*top] ? i : *top;
    }
    double s = n ? scale[*top] : 0.0;
    return dens * s <= (double)FLT_MAX && sa_le * s * factor <= (double)FLT_MAX;
}

Status scene_grid_set_temperature(Scene *s, uint grid, const float *temperature, GridTemperature how, Error *err)
{
    GridMedium *g = &s->grids[grid];
    size_t n = (size_t)g->nx * g->ny * g->nz, at = s->n_grid_data;
    size_t total = n + 1 + 3 * (size_t)GRID_BLACKBODY_STEPS;
    if (at + total > 0xffffffffu) return error_set(err, ST_INPUT, "the density grids hold more than 2^32 values together");
    BlackbodyTable *table = malloc(sizeof *table);
    if (!table || array_reserve((void **)&s->grid_data, &s->cap_grid_data, at + total, sizeof(float))) {
        free(table);
        return error_set(err, ST_INTERNAL, "out of memory for a temperature grid");
    }
    float *kelvin = s->grid_data + at, *head = kelvin + n, *rgb = head + 1;
    float hottest = 0.0f;
    for (size_t i = 0; i < n; i++) {
        double k = ((double)temperature[i] - how.offset) * how.scale;
        kelvin[i] = (float)(k > GRID_TEMPERATURE_MAX ? GRID_TEMPERATURE_MAX : k);
        hottest = kelvin[i] > hottest ? kelvin[i] : hottest;
    }
    /* a grid that nowhere passes the cutoff still gets a table (of black, but for its
     * top step): the kernels' lookup stays in it */
    if (hottest < 2.0f * GRID_TEMPERATURE_CUTOFF) hottest = 2.0f * GRID_TEMPERATURE_CUTOFF;
    blackbody_table_init(table);
    head[0] = (float)(GRID_BLACKBODY_STEPS - 1u) / hottest;
    for (uint k = 0; k < GRID_BLACKBODY_STEPS; k++) {
        double t = (double)hottest * k / (GRID_BLACKBODY_STEPS - 1u);
        vec3 c = blackbody_rgb_peak_normalised(table, t);
        rgb[3 * k + 0] = c.x;
        rgb[3 * k + 1] = c.y;
        rgb[3 * k + 2] = c.z;
    }
    free(table);
    g->temperature_at = (uint)at;   /* > 0: the grid's densities come first */
    s->n_grid_data = at + total;
    return ST_OK;
}

/* The sample indices whose interpolation reaches into majorant cell c of m along an
 * axis of n samples at cell centres (kernels/medium/grid.h: x = q n - 0.5, clamped). */
static void majorant_span(uint c, uint m, uint n, uint *first, uint *last)
{
    double lo = (double)c / m * n - 0.5, hi = (double)(c + 1u) / m * n - 0.5;
    double f = floor(lo), l = ceil(hi);
    *first = f < 0.0 ? 0u : (uint)f;
    *last = l > (double)(n - 1u) ? n - 1u : (uint)l;
    if (*first > n - 1u) *first = n - 1u;
}

Status scene_add_grid(Scene *s, const float *density, uint nx, uint ny, uint nz, vec3 lo, vec3 hi,
                      const Transform *to_world, uint *grid, Error *err)
{
    GridMedium g;
    memset(&g, 0, sizeof g);
    g.nx = nx;
    g.ny = ny;
    g.nz = nz;
    g.mx = nx < GRID_MAJORANT_RES ? nx : GRID_MAJORANT_RES;
    g.my = ny < GRID_MAJORANT_RES ? ny : GRID_MAJORANT_RES;
    g.mz = nz < GRID_MAJORANT_RES ? nz : GRID_MAJORANT_RES;
    /* the densities, then the majorant cells, then the minorant cells */
    size_t n_density = (size_t)nx * ny * nz, n_major = (size_t)g.mx * g.my * g.mz;
    size_t at = s->n_grid_data, n_all = n_density + 2 * n_major;
    if (at + n_all > 0xffffffffu)
        return error_set(err, ST_INPUT, "the density grids hold more than 2^32 values together");
    if (array_reserve((void **)&s->grid_data, &s->cap_grid_data, at + n_all, sizeof(float)) ||
        array_reserve((void **)&s->grids, &s->cap_grids, s->n_grids + 1, sizeof g))
        return error_set(err, ST_INTERNAL, "out of memory for a density grid");
    g.density_at = (uint)at;
    g.majorant_at = (uint)(at + n_density);
    g.minorant_at = (uint)(at + n_density + n_major);
    float *d = s->grid_data + at, *maj = s->grid_data + g.majorant_at, *mnr = s->grid_data + g.minorant_at;
    memcpy(d, density, n_density * sizeof(float));
    float top = 0.0f;
    for (size_t i = 0; i < n_density; i++) top = d[i] > top ? d[i] : top;
    g.max_density = top;
    /* each majorant cell: the largest sample the trilinear lookup blends anywhere in it,
     * and the smallest (the lookup is a convex blend of those samples, so it lies
     * between the two everywhere in the cell: the minorant is residual ratio tracking's
     * control, kernels/medium/grid.h) */
    for (uint cz = 0; cz < g.mz; cz++)
        for (uint cy = 0; cy < g.my; cy++)
            for (uint cx = 0; cx < g.mx; cx++) {
                uint x0, x1, y0, y1, z0, z1;
                majorant_span(cx, g.mx, nx, &x0, &x1);
                majorant_span(cy, g.my, ny, &y0, &y1);
                majorant_span(cz, g.mz, nz, &z0, &z1);
                float m = 0.0f, least = d[((size_t)z0 * ny + y0) * nx + x0];
                for (uint z = z0; z <= z1; z++)
                    for (uint y = y0; y <= y1; y++)
                        for (uint x = x0; x <= x1; x++) {
                            float v = d[((size_t)z * ny + y) * nx + x];
                            m = v > m ? v : m;
                            least = v < least ? v : least;
                        }
                maj[((size_t)cz * g.my + cy) * g.mx + cx] = m;
                mnr[((size_t)cz * g.my + cy) * g.mx + cx] = least;
            }
    /* world -> medium space -> the box's unit cube */
    int ok;
    Transform inv = transform_inverse(to_world, &ok);
    if (!ok) return error_set(err, ST_INPUT, "the grid medium's transform is singular");
    Transform unit = transform_scale(1.0 / ((double)hi.x - lo.x), 1.0 / ((double)hi.y - lo.y),
                                     1.0 / ((double)hi.z - lo.z));
    Transform shift = transform_translate(-(double)lo.x, -(double)lo.y, -(double)lo.z);
    Transform box = transform_compose(&unit, &shift);
    Transform to_grid = transform_compose(&box, &inv);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) g.to_grid[4 * i + j] = (float)to_grid.m[i][j];
    s->n_grid_data = at + n_all;
    s->grids[s->n_grids] = g;
    *grid = (uint)s->n_grids++;
    return ST_OK;
}

Status scene_add_medium(Scene *s, const char *name, Medium m, uint *index, Error *err)
{
    size_t cap_names = s->cap_media;
    if (array_reserve((void **)&s->medium_names, &cap_names, s->n_media + 1, sizeof(char *)) ||
        array_reserve((void **)&s->media, &s->cap_media, s->n_media + 1, sizeof m))
        return error_set(err, ST_INTERNAL, "out of memory growing the media list");
    size_t len = strlen(name);
    char *copy = malloc(len + 1);
    if (!copy) return error_set(err, ST_INTERNAL, "out of memory");
    memcpy(copy, name, len + 1);
    s->media[s->n_media] = m;
    s->medium_names[s->n_media] = copy;
    if (index) *index = (uint)s->n_media;
    s->n_media++;
    return ST_OK;
}

uint scene_find_medium(const Scene *s, const char *name, size_t len)
{
    for (size_t i = 0; i < s->n_media; i++)
        if (strlen(s->medium_names[i]) == len && memcmp(s->medium_names[i], name, len) == 0) return (uint)i;
    return NO_INDEX;
}

Status scene_interface_material(Scene *s, uint *index, Error *err)
{
    for (size_t i = 0; i < s->n_materials; i++)
        if ((s->materials[i].flags & MAT_INTERFACE) && s->materials[i].medium_in == s->materials[i].medium_out) {
            *index = (uint)i;
            return ST_OK;
        }
    return scene_add_material(s, "none", material_interface(), index, err);
}

Material material_interface(void)
{
    /* an emitter of no light: a type that scatters nothing and compiles little, which
     * the integrator never asks about (it passes the boundary first) */
    Material m = material_emissive(v3s(0.0f));
    m.flags = MAT_INTERFACE;
    return m;
}

Status scene_bind_media(Scene *s, uint material, uint in, uint out, uint *bound, Error *err)
{
    if (in == SCENE_MEDIUM_UNSET && out == SCENE_MEDIUM_UNSET) {
        *bound = material;
        return ST_OK;
    }
    for (size_t i = 0; i < s->n_medium_bindings; i++) {
        const SceneMediumBinding *b = &s->medium_bindings[i];
        if (b->origin == material && b->in == in && b->out == out) {
            *bound = b->material;
            return ST_OK;
        }
    }
    if (array_reserve((void **)&s->medium_bindings, &s->cap_medium_bindings, s->n_medium_bindings + 1,
                      sizeof *s->medium_bindings))
        return error_set(err, ST_INTERNAL, "out of memory");
    /* the name of the original, which scene_add_material may move: copied first */
    const char *name = s->material_names[material];
    size_t len = strlen(name);
    char *copy = malloc(len + 1);
    if (!copy) return error_set(err, ST_INTERNAL, "out of memory");
    memcpy(copy, name, len + 1);
    Status st = scene_add_material(s, copy, s->materials[material], bound, err);
    free(copy);
    if (st) return st;
    SceneMediumBinding b = { *bound, material, in, out };
    s->medium_bindings[s->n_medium_bindings++] = b;
    scene_prepare_media(s);
    return ST_OK;
}

uint scene_medium_resolve(const Scene *s, uint ref)
{
    return ref == SCENE_MEDIUM_UNSET ? s->world_medium : ref;
}

int scene_has_media(const Scene *s)
{
    if (s->n_media > 0) return 1;
    for (size_t i = 0; i < s->n_materials; i++)
        if (s->materials[i].flags & MAT_INTERFACE) return 1;
    return 0;
}

void scene_prepare_media(Scene *s)
{
    /* a subsurface material's interior is its walk's medium (scene/subsurface.h), and
     * its exterior the background's unless a shape says otherwise */
    for (size_t i = 0; i < s->n_materials; i++)
        if (s->materials[i].subsurface > 0.0f) s->materials[i].medium_out = s->world_medium;
    for (size_t i = 0; i < s->n_medium_bindings; i++) {
        const SceneMediumBinding *b = &s->medium_bindings[i];
        Material m = s->materials[b->origin];
        if (!(m.subsurface > 0.0f)) m.medium_in = scene_medium_resolve(s, b->in);
        m.medium_out = scene_medium_resolve(s, b->out);
        s->materials[b->material] = m;
    }
}
