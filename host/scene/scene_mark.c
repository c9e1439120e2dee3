/* scene_mark.c — the scene taken back to a mark, for a reader that places again
 * (scene_mark.h). */
#include "scene/scene_mark.h"

#include <stdlib.h>
#include <string.h>

void scene_mark(const Scene *s, SceneMark *m)
{
    m->triangles = s->n_triangles;
    m->shading = s->n_shading;
    m->tri_extras = s->n_tri_extras;
    m->tri_extra_of = s->n_tri_extra_of;
    m->objects = s->n_objects;
    m->instances = s->n_instances;
    m->delta_lights = s->n_delta_lights;
}

/* Never grows a count: a kind the scene holds fewer of than at the mark (the kd-tree's
 * flattening dropped them) stays as it is. */
static size_t back_to(size_t now, size_t mark)
{
    return now < mark ? now : mark;
}

Status scene_rewind(Scene *s, const SceneMark *m, Error *err)
{
    s->n_triangles = back_to(s->n_triangles, m->triangles);
    s->n_shading = back_to(s->n_shading, m->shading);
    s->n_tri_extras = back_to(s->n_tri_extras, m->tri_extras);
    s->n_tri_extra_of = back_to(s->n_tri_extra_of, m->tri_extra_of);
    s->n_delta_lights = back_to(s->n_delta_lights, m->delta_lights);
    s->n_instances = back_to(s->n_instances, m->instances);
    /* the per-instance light table is scene_prepare_lights', made again with the lights */
    free(s->instance_lights);
    s->instance_lights = NULL;
    if (s->n_objects <= m->objects) return ST_OK;
    for (size_t i = m->objects; i < s->n_objects; i++) free(s->objects[i].name);
    s->n_objects = m->objects;
    /* the map has no removal: made again from the objects left */
    strmap_free(&s->object_by_name);
    memset(&s->object_by_name, 0, sizeof s->object_by_name);
    for (size_t i = 0; i < s->n_objects; i++) {
        const char *name = s->objects[i].name;
        if (strmap_add(&s->object_by_name, name, strlen(name), (uint32_t)i) < 0)
            return error_set(err, ST_INTERNAL, "out of memory for the objects' names");
    }
    return ST_OK;
}
