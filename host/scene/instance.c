/* instance.c — objects and instances in a scene (instance.h). */
#include "scene/instance.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "util/kmath.h"

void scene_object_counts(const Scene *s, size_t n[OBJ_KINDS])
{
    n[OBJ_SPHERES] = s->n_spheres;
    n[OBJ_TRIANGLES] = s->n_triangles;
    n[OBJ_BOXES] = s->n_boxes;
    n[OBJ_REVS] = s->n_revsurfaces;
}

/* The first global id of each kind (scene.h's id space). */
static void kind_firsts(const Scene *s, uint first[OBJ_KINDS])
{
    first[OBJ_SPHERES] = 0u;
    first[OBJ_TRIANGLES] = scene_first_triangle(s);
    first[OBJ_BOXES] = scene_first_box(s);
    first[OBJ_REVS] = scene_first_revsurface(s);
}

Status scene_object_begin(Scene *s, const char *name, size_t len, uint *index, Error *err)
{
    size_t now[OBJ_KINDS];
    scene_object_counts(s, now);
    return scene_object_begin_from(s, name, len, now, index, err);
}

Status scene_object_begin_from(Scene *s, const char *name, size_t len, const size_t first[OBJ_KINDS], uint *index,
                               Error *err)
{
    if (s->n_objects >= SCENE_MAX_OBJECTS)
        return error_set(err, ST_INPUT, "too many objects (the limit is %u)", SCENE_MAX_OBJECTS);
    if (array_reserve((void **)&s->objects, &s->cap_objects, s->n_objects + 1, sizeof *s->objects))
        return error_set(err, ST_INTERNAL, "out of memory for an object");
    SceneObject *o = &s->objects[s->n_objects];
    memset(o, 0, sizeof *o);
    o->name = malloc(len + 1);
    if (!o->name || strmap_add(&s->object_by_name, name, len, (uint32_t)s->n_objects) < 0) {
        free(o->name);
        return error_set(err, ST_INTERNAL, "out of memory for an object");
    }
    memcpy(o->name, name, len);
    o->name[len] = '\0';
    memcpy(o->first, first, sizeof o->first);
    scene_object_counts(s, o->end);
    o->first_nested = o->end_nested = s->n_nested;
    o->depth = 1u;
    o->leaves = 0u;
    *index = (uint)s->n_objects++;
    return ST_OK;
}

/* a + b, held at LEAVES_MAX: nesting multiplies counts (8 levels of a million
 * instances each are 2^160), and past the limit only the message needs the number */
#define LEAVES_MAX ((uint64_t)1 << 62)
static uint64_t leaves_add(uint64_t a, uint64_t b)
{
    uint64_t sum = a + b;
    return sum > LEAVES_MAX ? LEAVES_MAX : sum;
}

void scene_object_end(Scene *s, uint index)
{
    SceneObject *o = &s->objects[index];
    scene_object_counts(s, o->end);
    if (scene_object_prims(s, index)) o->leaves = leaves_add(o->leaves, 1u);
}

Status scene_object_nest(Scene *s, uint holder, uint object, const Transform *m, uint material, Error *err)
{
    SceneObject *h = &s->objects[holder];
    const SceneObject *o = &s->objects[object];
    if (object == holder)
        return error_set(err, ST_INPUT, "object '%s' instances itself (an object cannot hold itself)", h->name);
    /* objects are defined before their instances and not inside each other, so a
     * holder's nested objects are all complete: recursion through others cannot be
     * written, and depth and counts are known here */
    if (o->depth + 1u > SCENE_MAX_NESTING)
        return error_set(err, ST_INPUT, "an instance of '%s' inside object '%s' nests objects %u deep (the limit is %u)",
                         o->name, h->name, o->depth + 1u, SCENE_MAX_NESTING);
    Transform inv;
    if (!transform_invert(m, &inv)) return error_set(err, ST_INPUT, "the instance transform is singular");
    if (h->end_nested != s->n_nested)
        return error_set(err, ST_INTERNAL, "object '%s' is not the one being read", h->name);
    if (array_reserve((void **)&s->nested, &s->cap_nested, s->n_nested + 1, sizeof *s->nested))
        return error_set(err, ST_INTERNAL, "out of memory for an instance");
    s->nested[s->n_nested++] = (SceneNested){ *m, object, material };
    h->end_nested = s->n_nested;
    if (o->depth + 1u > h->depth) h->depth = o->depth + 1u;
    h->leaves = leaves_add(h->leaves, o->leaves);
    return ST_OK;
}

/* scene_place_object's walk: the object's own shapes, then what it nests, depth first
 * in the order of its block; the outermost material given wins. */
static Status place_nested(Scene *s, uint object, const Transform *m, uint material, Error *err)
{
    const SceneObject *o = &s->objects[object];
    Status st = ST_OK;
    if (scene_object_prims(s, object)) st = scene_add_instance(s, object, m, material, err);
    for (size_t k = o->first_nested; !st && k < o->end_nested; k++) {
        const SceneNested *n = &s->nested[k];
        Transform c = transform_compose(m, &n->m);
        st = place_nested(s, n->object, &c, material != NO_INDEX ? material : n->material, err);
    }
    return st;
}

Status scene_place_object(Scene *s, uint object, const Transform *m, uint material, Error *err)
{
    const SceneObject *o = &s->objects[object];
    if (o->first_nested == o->end_nested) return scene_add_instance(s, object, m, material, err);
    /* counted before anything is allocated: a few lines of nesting can ask for more
     * instances than any memory holds */
    if (o->leaves > SCENE_MAX_INSTANCES - s->n_instances) {
        if (o->leaves == LEAVES_MAX)
            return error_set(err, ST_INPUT, "an instance of '%s' places 2^62 or more instances through the objects "
                             "it nests (the limit is %u)", o->name, SCENE_MAX_INSTANCES);
        return error_set(err, ST_INPUT, "an instance of '%s' places %llu instances through the objects it nests, "
                         "%zu more than the limit of %u", o->name, (unsigned long long)o->leaves,
                         (size_t)(s->n_instances + o->leaves - SCENE_MAX_INSTANCES), SCENE_MAX_INSTANCES);
    }
    if (array_reserve((void **)&s->instances, &s->cap_instances, s->n_instances + (size_t)o->leaves,
                      sizeof *s->instances) ||
        array_reserve((void **)&s->instance_objects, &s->cap_instance_objects, s->n_instances + (size_t)o->leaves,
                      sizeof *s->instance_objects))
        return error_set(err, ST_INTERNAL, "out of memory for %llu instances", (unsigned long long)o->leaves);
    return place_nested(s, object, m, material, err);
}

uint scene_find_object(const Scene *s, const char *name, size_t len)
{
    uint32_t v;
    return strmap_find(&s->object_by_name, name, len, &v) ? (uint)v : NO_INDEX;
}

size_t scene_object_prims(const Scene *s, uint index)
{
    size_t n = 0;
    for (int k = 0; k < OBJ_KINDS; k++) n += s->objects[index].end[k] - s->objects[index].first[k];
    return n;
}

Status scene_add_instance(Scene *s, uint object, const Transform *m, uint material, Error *err)
{
    if (s->n_instances >= SCENE_MAX_INSTANCES)
        return error_set(err, ST_INPUT, "too many instances (the limit is %u)", SCENE_MAX_INSTANCES);
    Transform inv;
    if (!transform_invert(m, &inv)) return error_set(err, ST_INPUT, "the instance transform is singular");
    Instance x;
    memset(&x, 0, sizeof x);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) {
            x.to_world[4 * i + j] = (float)m->m[i][j];
            x.to_object[4 * i + j] = (float)inv.m[i][j];
        }
    for (int i = 0; i < 12; i++)
        if (!isfinite(x.to_world[i]) || !isfinite(x.to_object[i]))
            return error_set(err, ST_INPUT, "the instance transform or its inverse does not fit in floats");
    x.root = 0u;
    x.material = material;
    x.flags = (transform_is_identity(m) ? INST_IDENTITY : 0u) | (transform_det(m) < 0.0 ? INST_MIRROR : 0u);
    if (array_reserve((void **)&s->instances, &s->cap_instances, s->n_instances + 1, sizeof x) ||
        array_reserve((void **)&s->instance_objects, &s->cap_instance_objects, s->n_instances + 1, sizeof object))
        return error_set(err, ST_INTERNAL, "out of memory for an instance");
    s->instance_objects[s->n_instances] = object;
    s->instances[s->n_instances++] = x;
    return ST_OK;
}

size_t scene_object_ranges(const Scene *s, uint index, uint lo[OBJ_KINDS], uint hi[OBJ_KINDS])
{
    uint first[OBJ_KINDS];
    kind_firsts(s, first);
    const SceneObject *o = &s->objects[index];
    size_t n = 0;
    for (int k = 0; k < OBJ_KINDS; k++) {
        if (o->end[k] == o->first[k]) continue;
        lo[n] = first[k] + (uint)o->first[k];
        hi[n] = first[k] + (uint)o->end[k];
        n++;
    }
    return n;
}

Status scene_object_mask(const Scene *s, uint8_t **mask, Error *err)
{
    *mask = NULL;
    if (s->n_objects == 0) return ST_OK;
    size_t total = scene_first_plane(s);
    uint8_t *m = calloc(total + 1, 1);
    if (!m) return error_set(err, ST_INTERNAL, "out of memory listing the objects' primitives");
    for (uint i = 0; i < (uint)s->n_objects; i++) {
        uint lo[OBJ_KINDS], hi[OBJ_KINDS];
        size_t n = scene_object_ranges(s, i, lo, hi);
        for (size_t r = 0; r < n; r++) memset(m + lo[r], 1, hi[r] - lo[r]);
    }
    *mask = m;
    return ST_OK;
}

/* ------------------------------------------------------------------ flattening */

static Transform instance_transform(const Instance *x)
{
    Transform t;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) t.m[i][j] = (double)x->to_world[4 * i + j];
    return t;
}

/* Whether M's linear part is diagonal: a box stays a box (mirrored or not). */
static int keeps_boxes(const Transform *t)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (i != j && t->m[i][j] != 0.0) return 0;
    return 1;
}

/* What flattening cannot copy, checked before anything changes. */
static Status flatten_check(const Scene *s, Error *err)
{
    for (size_t i = 0; i < s->n_instances; i++) {
        const Instance *x = &s->instances[i];
        const SceneObject *o = &s->objects[s->instance_objects[i]];
        if (x->flags & INST_IDENTITY) continue;
        Transform t = instance_transform(x);
        if (o->end[OBJ_BOXES] > o->first[OBJ_BOXES] && !keeps_boxes(&t))
            return error_set(err, ST_INPUT, "object '%s' holds a box that instance %zu rotates: flattening has no "
                             "world copy for a rotated box", o->name, i);
        if (o->end[OBJ_REVS] > o->first[OBJ_REVS])
            return error_set(err, ST_INPUT, "object '%s' holds a surface of revolution that instance %zu "
                             "transforms: flattening has no world copy for it", o->name, i);
    }
    return ST_OK;
}

static vec3 point_d(const Transform *t, vec3 p)
{
    return transform_point(t, p);
}

/* A unit normal carried by the normal matrix nm, in double. */
static vec3 normal_d(double (*nm)[3], vec3 n)
{
    double v[3];
    for (int i = 0; i < 3; i++) v[i] = nm[i][0] * n.x + nm[i][1] * n.y + nm[i][2] * n.z;
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(len > 0.0)) return n;
    return v3((float)(v[0] / len), (float)(v[1] / len), (float)(v[2] / len));
}

static Status copy_triangle(Scene *s, size_t i, const Instance *x, const Transform *t, double (*nm)[3],
                            Error *err)
{
    Triangle tr = s->triangles[i];
    if (x->material != NO_INDEX) tr.material = x->material;
    if (x->flags & INST_IDENTITY) return scene_add_triangle(s, tr, err);
    /* a mirror keeps the outward side by swapping two corners, as a mesh block does */
    int swap = (x->flags & INST_MIRROR) != 0;
    vec3 p1 = point_d(t, tr.p1), p2 = point_d(t, tr.p2);
    tr.p0 = point_d(t, tr.p0);
    tr.p1 = swap ? p2 : p1;
    tr.p2 = swap ? p1 : p2;
    if (tr.shading != NO_INDEX) {
        TriShading sh = s->shading[tr.shading];
        uint extra = s->n_tri_extra_of ? s->tri_extra_of[tr.shading] : NO_INDEX;
        if (sh.flags & TRI_HAS_NORMALS) {
            vec3 n1 = normal_d(nm, sh.n1), n2 = normal_d(nm, sh.n2);
            sh.n0 = normal_d(nm, sh.n0);
            sh.n1 = swap ? n2 : n1;
            sh.n2 = swap ? n1 : n2;
        }
        if (swap) {
            float uv[2] = { sh.uv1[0], sh.uv1[1] };
            memcpy(sh.uv1, sh.uv2, sizeof uv);
            memcpy(sh.uv2, uv, sizeof uv);
        }
        uint idx;
        Status st = scene_add_shading(s, sh, &idx, err);
        if (st) return st;
        if (extra != NO_INDEX) s->tri_extra_of[idx] = extra;
        tr.shading = idx;
    }
    return scene_add_triangle(s, tr, err);
}

static Status copy_sphere(Scene *s, size_t i, const Instance *x, const Transform *t, Error *err)
{
    Sphere sp = s->spheres[i];
    uint material = x->material != NO_INDEX ? x->material : sp.material;
    if (x->flags & INST_IDENTITY) {
        sp.material = material;
        return scene_add_sphere(s, sp, err);
    }
    /* the unit sphere's map into the object, then the instance's */
    Transform inner;
    if (sp.xform) {
        const SphereXform *sx = &s->sphere_xforms[sp.xform - 1u];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++) inner.m[r][c] = (double)sx->to_world[4 * r + c];
    } else {
        Transform sc = transform_scale(sp.radius, sp.radius, sp.radius);
        Transform tr = transform_translate(sp.center.x, sp.center.y, sp.center.z);
        inner = transform_compose(&tr, &sc);
    }
    Transform m = transform_compose(t, &inner);
    return scene_add_ellipsoid(s, &m, material, err);
}

static Status copy_box(Scene *s, size_t i, const Instance *x, const Transform *t, Error *err)
{
    Box b = s->boxes[i];
    if (x->material != NO_INDEX) b.material = x->material;
    if (!(x->flags & INST_IDENTITY)) {
        vec3 a = point_d(t, b.lo), c = point_d(t, b.hi);
        b.lo = v3(fminf(a.x, c.x), fminf(a.y, c.y), fminf(a.z, c.z));
        b.hi = v3(fmaxf(a.x, c.x), fmaxf(a.y, c.y), fmaxf(a.z, c.z));
    }
    return scene_add_box(s, b, err);
}

/* The copies of instance x's object. */
static Status copy_instance(Scene *s, const Instance *x, uint object, Error *err)
{
    const SceneObject o = s->objects[object];
    Transform t = instance_transform(x);
    double nm[3][3];
    if (!transform_normal_matrix(&t, nm)) return error_set(err, ST_INPUT, "the instance transform is singular");
    Status st = ST_OK;
    for (size_t i = o.first[OBJ_TRIANGLES]; !st && i < o.end[OBJ_TRIANGLES]; i++)
        st = copy_triangle(s, i, x, &t, nm, err);
    for (size_t i = o.first[OBJ_SPHERES]; !st && i < o.end[OBJ_SPHERES]; i++) st = copy_sphere(s, i, x, &t, err);
    for (size_t i = o.first[OBJ_BOXES]; !st && i < o.end[OBJ_BOXES]; i++) st = copy_box(s, i, x, &t, err);
    for (size_t i = o.first[OBJ_REVS]; !st && i < o.end[OBJ_REVS]; i++) {
        RevSurface r = s->revsurfaces[i];
        if (x->material != NO_INDEX) r.material = x->material;
        if (array_reserve((void **)&s->revsurfaces, &s->cap_revsurfaces, s->n_revsurfaces + 1, sizeof r))
            st = error_set(err, ST_INTERNAL, "out of memory growing the scene");
        else s->revsurfaces[s->n_revsurfaces++] = r;   /* the identity (flatten_check) */
    }
    return st;
}

/* Drops elements [first, end) of each object from an array of n elements (the
 * objects' ranges increase), keeping the others in order; returns the new count. */
static size_t drop_objects(const Scene *s, int kind, void *arr, size_t n, size_t elem)
{
    size_t out = 0, at = 0;
    char *a = arr;
    for (size_t i = 0; i <= s->n_objects; i++) {
        size_t stop = i < s->n_objects ? s->objects[i].first[kind] : n;
        if (stop > at) {
            memmove(a + out * elem, a + at * elem, (stop - at) * elem);
            out += stop - at;
        }
        if (i < s->n_objects) at = s->objects[i].end[kind];
    }
    return out;
}

Status scene_flatten_instances(Scene *s, Error *err)
{
    if (s->n_objects == 0) return ST_OK;
    Status st = flatten_check(s, err);
    for (size_t i = 0; !st && i < s->n_instances; i++) {
        Instance x = s->instances[i];
        st = copy_instance(s, &x, s->instance_objects[i], err);
    }
    if (st) return st;
    s->n_spheres = drop_objects(s, OBJ_SPHERES, s->spheres, s->n_spheres, sizeof *s->spheres);
    s->n_triangles = drop_objects(s, OBJ_TRIANGLES, s->triangles, s->n_triangles, sizeof *s->triangles);
    s->n_boxes = drop_objects(s, OBJ_BOXES, s->boxes, s->n_boxes, sizeof *s->boxes);
    s->n_revsurfaces = drop_objects(s, OBJ_REVS, s->revsurfaces, s->n_revsurfaces, sizeof *s->revsurfaces);
    scene_free_objects(s);
    return ST_OK;
}

void scene_free_objects(Scene *s)
{
    for (size_t i = 0; i < s->n_objects; i++) free(s->objects[i].name);
    free(s->objects);
    free(s->instances);
    free(s->instance_objects);
    free(s->instance_lights);
    free(s->nested);
    strmap_free(&s->object_by_name);
    s->objects = NULL;
    s->instances = NULL;
    s->instance_objects = NULL;
    s->instance_lights = NULL;
    s->nested = NULL;
    s->n_objects = s->cap_objects = s->n_instances = s->cap_instances = s->cap_instance_objects = 0;
    s->n_nested = s->cap_nested = 0;
}
