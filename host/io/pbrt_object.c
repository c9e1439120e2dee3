/* pbrt_object.c — pbrt-v4 object instancing: ObjectBegin/End/Instance, and a Shape under
 * a moving transform made an object of its own (pbrt_reader.h, docs/pbrt.md,
 * docs/instancing.md). */
#include "io/pbrt_reader.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/strmap.h"
#include "io/lexer.h"
#include "io/reader.h"
#include "util/kmath.h"
#include "scene/instance.h"
#include "scene/mesh_sink.h"
#include "scene/motion.h"
#include "scene/transform.h"

/* pbrt-v4's objects are clpt's (docs/instancing.md): the shapes between ObjectBegin and
 * ObjectEnd stay once in the scene, in the space their own CTM gives them, and each
 * ObjectInstance places them under the CTM of that moment (pbrt-v4's render-from-
 * instance is the CTM at ObjectInstance times world-from-render: the object's shapes
 * are not moved back by the CTM at ObjectBegin). An object with no shapes is copied in
 * at each instance instead (nothing to place). Emitting triangles are lights under
 * every instance (LIGHT_INSTANCED), but an emitting sphere only under a similarity: an
 * instance that squashes it makes an ellipsoid, which light sampling has no density
 * for. So an object holding an emitting sphere keeps its shapes for copies too, and
 * each ObjectInstance decides by its CTM: a similarity places an instance, any other
 * copies the shapes, the emitting sphere as a mesh light (instance_ellipsoid). */
#define PBRT_MAX_FLAT_TRIANGLES ((size_t)1 << 26)

/* Starts object `name` (ObjectBegin's work after its name is read). */
static Status object_open(Parser *p, const Lexer *lx, const Token *kw, const Token *name_tok)
{
    Token name = *name_tok;
    Status st;
    if (p->in_object)
        return lex_error_at(lx, kw, p->err, "ObjectBegin \"%.*s\" inside ObjectBegin \"%s\" (objects do not nest)",
                            (int)(name.len > 60 ? 60 : name.len), name.text, p->obj_name_buf);
    if ((st = pbrt_push_state(p))) return st;
    p->in_object = 1;
    p->obj_stack = p->n_stack;
    p->obj_spheres = p->s->n_spheres;
    p->obj_sphere_xforms = p->s->n_sphere_xforms;
    p->obj_triangles = p->s->n_triangles;
    p->obj_shading = p->s->n_shading;
    scene_object_counts(p->s, p->obj_first);
    snprintf(p->obj_where, sizeof p->obj_where, "%s:%u:%u", lx->path, kw->line, kw->col);
    free(p->obj_name_buf);
    p->obj_name_buf = tok_copy(&name);
    if (!p->obj_name_buf) return error_set(p->err, ST_INTERNAL, "out of memory");
    p->obj_name = name;
    p->obj_name.text = p->obj_name_buf;
    return ST_OK;
}

Status pbrt_object_begin(Parser *p, Lexer *lx, const Token *kw)
{
    Token name;
    Status st = pbrt_expect_string(p, lx, "a quoted object name", &name);
    if (st) return st;
    return object_open(p, lx, kw, &name);
}

/* Whether a sphere made since ObjectBegin emits light (an AreaLightSource's); an
 * emitting sphere under a CTM that is no similarity is already a mesh (shape_sphere). */
static int object_sphere_emits(const Parser *p)
{
    const Scene *s = p->s;
    for (size_t i = p->obj_spheres; i < s->n_spheres; i++)
        if (!v3_is_zero(s->materials[s->spheres[i].material].emission)) return 1;
    return 0;
}

/* The shapes since ObjectBegin as a scene object. pbrt lets a name be defined again
 * (the later object serves the instances after it); the scene's names are unique, so
 * a later one is told apart by its index. */
static Status object_keep(Parser *p, PObject *o)
{
    char name[96];
    const char *text = p->obj_name.text;
    size_t len = p->obj_name.len;
    if (scene_find_object(p->s, text, len) != NO_INDEX) {
        snprintf(name, sizeof name, "%.*s#%zu", (int)(len > 60 ? 60 : len), text, p->s->n_objects);
        text = name;
        len = strlen(name);
    }
    Status st = scene_object_begin_from(p->s, text, len, p->obj_first, &o->object, p->err);
    if (st) return st;
    scene_object_end(p->s, o->object);
    return ST_OK;
}

/* The shapes since ObjectBegin saved in o, to be copied in at an instance. */
static Status object_save(Parser *p, PObject *o)
{
    const Scene *s = p->s;
    o->n_spheres = s->n_spheres - p->obj_spheres;
    o->n_triangles = s->n_triangles - p->obj_triangles;
    o->n_shading = s->n_shading - p->obj_shading;
    o->n_sphere_xforms = s->n_sphere_xforms - p->obj_sphere_xforms;
    o->sphere_xforms = malloc(o->n_sphere_xforms * sizeof *o->sphere_xforms + 1);
    o->spheres = malloc(o->n_spheres * sizeof *o->spheres + 1);
    o->triangles = malloc(o->n_triangles * sizeof *o->triangles + 1);
    o->shading = malloc(o->n_shading * sizeof *o->shading + 1);
    if (!o->spheres || !o->triangles || !o->shading || !o->sphere_xforms) {
        free(o->spheres);
        free(o->sphere_xforms);
        free(o->triangles);
        free(o->shading);
        return error_set(p->err, ST_INTERNAL, "out of memory");
    }
    /* an object may hold no spheres (or no triangles), and the scene's array may then
     * still be NULL: C gives no NULL + 0, so the empty copies are skipped */
    if (o->n_sphere_xforms)
        memcpy(o->sphere_xforms, s->sphere_xforms + p->obj_sphere_xforms, o->n_sphere_xforms * sizeof *o->sphere_xforms);
    if (o->n_spheres) memcpy(o->spheres, s->spheres + p->obj_spheres, o->n_spheres * sizeof *o->spheres);
    if (o->n_triangles) memcpy(o->triangles, s->triangles + p->obj_triangles, o->n_triangles * sizeof *o->triangles);
    if (o->n_shading) memcpy(o->shading, s->shading + p->obj_shading, o->n_shading * sizeof *o->shading);
    for (size_t i = 0; i < o->n_triangles; i++)
        if (o->triangles[i].shading != NO_INDEX) o->triangles[i].shading -= (uint)p->obj_shading;
    for (size_t i = 0; i < o->n_spheres; i++)
        if (o->spheres[i].xform) o->spheres[i].xform -= (uint)p->obj_sphere_xforms;
    return ST_OK;
}

/* The shapes since ObjectBegin taken out of the scene, to be copied in at each instance. */
static Status object_take(Parser *p, PObject *o)
{
    Scene *s = p->s;
    o->object = NO_INDEX;
    Status st = object_save(p, o);
    if (st) return st;
    s->n_sphere_xforms = p->obj_sphere_xforms;
    s->n_spheres = p->obj_spheres;
    s->n_triangles = p->obj_triangles;
    s->n_shading = p->obj_shading;
    return ST_OK;
}

/* Ends the object begun (ObjectEnd's work): its index in p->objects in *index, under
 * its name when `named` (an object made for a moving Shape has none: ObjectInstance
 * cannot name it). */
static Status object_close(Parser *p, const Lexer *lx, const Token *kw, int named, uint32_t *index)
{
    if (p->n_stack != p->obj_stack)
        return lex_error_at(lx, kw, p->err, "ObjectEnd inside an AttributeBegin of its object, or after one "
                            "that closes more than it opened");
    PObject o;
    memset(&o, 0, sizeof o);
    int empty = p->s->n_triangles == p->obj_triangles && p->s->n_spheres == p->obj_spheres;
    o.sphere_emits = !empty && object_sphere_emits(p);
    if (pbrt_grow((void **)&p->objects, &p->cap_objects, p->n_objects + 1, sizeof(PObject)))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    Status st = empty ? object_take(p, &o) : o.sphere_emits ? object_save(p, &o) : ST_OK;
    if (!st && !empty && (st = object_keep(p, &o))) {
        free(o.spheres);
        free(o.sphere_xforms);
        free(o.triangles);
        free(o.shading);
    }
    if (st) return st == ST_INPUT ? lex_error_at(lx, kw, p->err, "%s", p->err->msg) : st;
    /* a name defined again replaces the earlier object, for the instances after it */
    if (named && strmap_set(&p->object_by_name, p->obj_name.text, p->obj_name.len, (uint32_t)p->n_objects)) {
        free(o.spheres);
        free(o.sphere_xforms);
        free(o.triangles);
        free(o.shading);
        return error_set(p->err, ST_INTERNAL, "out of memory");
    }
    *index = (uint32_t)p->n_objects;
    p->objects[p->n_objects++] = o;
    p->in_object = 0;
    p->g = p->stack[--p->n_stack];
    return ST_OK;
}

Status pbrt_object_end(Parser *p, Lexer *lx, const Token *kw)
{
    if (!p->in_object) return lex_error_at(lx, kw, p->err, "ObjectEnd without ObjectBegin");
    uint32_t index;
    return object_close(p, lx, kw, 1, &index);
}

/* An object's sphere sp under the instance's transform when either makes it an
 * ellipsoid: the unit sphere under ctm . (sp's own transform). An emitting one is a
 * mesh, as shape_sphere makes an emitting ellipsoid (sphere lights are sampled by their
 * cone, which an ellipsoid has not); the object's sphere faced outwards (a reversed one
 * was a mesh already), so its copy does too, whatever the instance's orientation. */
static Status instance_ellipsoid(Parser *p, const Lexer *lx, const Token *name, const PObject *o, const Sphere *sp)
{
    Transform own;
    if (sp->xform) {
        const float *m = o->sphere_xforms[sp->xform - 1u].to_world;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) own.m[i][j] = m[4 * i + j];
    } else {
        Transform t = transform_translate(sp->center.x, sp->center.y, sp->center.z),
                  sc = transform_scale(sp->radius, sp->radius, sp->radius);
        own = transform_compose(&t, &sc);
    }
    Transform m = transform_compose(&p->g.ctm, &own);
    if (!v3_is_zero(p->s->materials[sp->material].emission)) {
        return pbrt_sphere_mesh(p, lx, name, "an emitting sphere copied under a transform that is no similarity, "
                                "as a mesh,", &m, 1.0, sp->material, 0);
    }
    Status st = scene_add_ellipsoid(p->s, &m, sp->material, p->err);
    if (st == ST_INPUT) error_prefix(p->err, "%s:%u:%u: the instanced sphere", lx->path, name->line, name->col);
    return st;
}

/* An instance of a scene object: the CTM is its transform. A singular one (a Scale 0,
 * say) places nothing that can be seen: skipped with a warning. Under a moving CTM
 * (ActiveTransform) the instance moves: its own pose at the start time, a key at the
 * end time (docs/motion.md), as pbrt-v4 animates an instance. */
static Status instance_place(Parser *p, const Lexer *lx, const Token *name, const char *what, uint object)
{
    Transform inv;
    if (!transform_invert(&p->g.ctm, &inv))
        return warn_once(p, lx, name, "instance-singular", "ObjectInstance \"%.*s\" under a singular transform is "
                         "skipped", (int)(name->len > 60 ? 60 : name->len), name->text);
    Status st = scene_add_instance(p->s, object, &p->g.ctm, NO_INDEX, p->err);
    if (!st && pbrt_ctm_moves(p)) {
        if (!(p->time_end > p->time_start))
            return lex_error_at(lx, name, p->err, "%s \"%.*s\" moves (ActiveTransform) but TransformTimes gives its "
                                "start and end the same time %g", what, (int)(name->len > 60 ? 60 : name->len),
                                name->text, p->time_start);
        st = scene_add_instance_key(p->s, (float)p->time_start, (float)p->time_end, &p->g.ctm_end, p->err);
        if (st == ST_INPUT)
            return lex_error_at(lx, name, p->err, "%s \"%.*s\" at its end time: %s", what,
                                (int)(name->len > 60 ? 60 : name->len), name->text, p->err->msg);
    }
    return st == ST_INPUT ? lex_error_at(lx, name, p->err, "%s", p->err->msg) : st;
}

/* ObjectInstance of p->objects[i] under the current transforms; `what` and `name` for
 * messages ("ObjectInstance" and its name, or "Shape" and its type). */
static Status object_place(Parser *p, const Lexer *lx, const Token *name_tok, const char *what, uint32_t i)
{
    Token name = *name_tok;
    Status st;
    const PObject *o = &p->objects[i];
    double scale;
    int similar = pbrt_is_similarity(&p->g.ctm, &scale);
    Transform inv;
    if (o->object != NO_INDEX && (similar || !o->sphere_emits || !transform_invert(&p->g.ctm, &inv)))
        return instance_place(p, lx, &name, what, o->object);
    if (pbrt_ctm_moves(p) && (st = pbrt_warn_still(p, lx, &name, "an ObjectInstance copied into the scene")))
        return st;
    if (o->object != NO_INDEX &&
        (st = warn_once(p, lx, &name, "instance-emits", "ObjectInstance \"%.*s\" holds an emitting sphere under a "
                        "transform that is no similarity: its shapes are copied (an instanced ellipsoid is no light)",
                        (int)(name.len > 60 ? 60 : name.len), name.text)))
        return st;
    if (p->s->n_triangles + o->n_triangles > PBRT_MAX_FLAT_TRIANGLES)
        return lex_error_at(lx, &name, p->err, "the flattened instances would hold more than %zu triangles",
                            PBRT_MAX_FLAT_TRIANGLES);
    MeshSink k;
    if ((st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err)) ||
        (st = mesh_sink_reserve(&k, o->n_triangles, o->n_shading)))
        return st;
    for (size_t t = 0; t < o->n_triangles && !st; t++) {
        const Triangle *tr = &o->triangles[t];
        const TriShading *sh = tr->shading != NO_INDEX ? &o->shading[tr->shading] : NULL;
        vec3 q[3] = { tr->p0, tr->p1, tr->p2 };
        vec3 n[3];
        float uv[6];
        int has_n = sh && (sh->flags & TRI_HAS_NORMALS), has_uv = sh && (sh->flags & TRI_HAS_UV);
        if (has_n) {
            n[0] = sh->n0;
            n[1] = sh->n1;
            n[2] = sh->n2;
        }
        if (has_uv) {
            const float u[6] = { sh->uv0[0], sh->uv0[1], sh->uv1[0], sh->uv1[1], sh->uv2[0], sh->uv2[1] };
            memcpy(uv, u, sizeof uv);
        }
        st = mesh_sink_triangle(&k, q, has_n ? n : NULL, has_uv ? uv : NULL, tr->material);
    }
    for (size_t j = 0; j < o->n_spheres && !st; j++) {
        if (!similar || o->spheres[j].xform) {
            st = instance_ellipsoid(p, lx, &name, o, &o->spheres[j]);
            continue;
        }
        Sphere sp = o->spheres[j];
        sp.center = transform_point(&p->g.ctm, sp.center);
        sp.radius = (float)(sp.radius * scale);
        if (!(sp.radius > 0) || !isfinite(sp.radius) || !isfinite(fabsf(sp.center.x) + sp.radius) ||
            !isfinite(fabsf(sp.center.y) + sp.radius) || !isfinite(fabsf(sp.center.z) + sp.radius))
            return lex_error_at(lx, &name, p->err, "the instanced sphere reaches beyond the largest float");
        st = scene_add_sphere(p->s, sp, p->err);
    }
    return st;
}

Status pbrt_object_instance(Parser *p, Lexer *lx, const Token *kw)
{
    Token name;
    uint32_t i;
    Status st = pbrt_expect_defined(p, lx, &p->object_by_name, "object", "ObjectBegin", &name, &i);
    if (st) return st;
    if (p->in_object)
        return lex_error_at(lx, kw, p->err, "ObjectInstance inside ObjectBegin \"%s\" (objects hold shapes, not "
                            "instances)", p->obj_name_buf);
    return object_place(p, lx, &name, "ObjectInstance", i);
}

/* A Shape outside any object under a moving transform: pbrt-v4 moves it (an animated
 * primitive); clpt moves instances only (docs/motion.md), so the shape becomes an
 * object of its own, made in its object space (both transforms the identity), and one
 * instance of it under the two transforms, interpolated as pbrt-v4 interpolates the
 * shape's (docs/pbrt.md#motion). */
Status pbrt_shape_moving(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    char buf[64];
    snprintf(buf, sizeof buf, "moving Shape %u:%u", type->line, type->col);
    Token name = {TOK_STRING, buf, strlen(buf), type->line, type->col};
    Status st = object_open(p, lx, kw, &name);
    if (st) return st;
    p->g.ctm = p->g.ctm_end = transform_identity();
    if ((st = pbrt_shape_make(p, lx, type))) return st;
    uint32_t index;
    if ((st = object_close(p, lx, kw, 0, &index))) return st;
    return object_place(p, lx, type, "Shape", index);
}
