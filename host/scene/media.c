/* media.c — participating media in the host's scene (see media.h). */
#include "scene/media.h"

#include "base/array.h"

#include "util/kmath.h"

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
    for (size_t i = 0; i < s->n_medium_bindings; i++) {
        const SceneMediumBinding *b = &s->medium_bindings[i];
        Material m = s->materials[b->origin];
        m.medium_in = scene_medium_resolve(s, b->in);
        m.medium_out = scene_medium_resolve(s, b->out);
        s->materials[b->material] = m;
    }
}
