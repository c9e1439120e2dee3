/* pbrt_object.c — pbrt-v4 object instancing: ObjectBegin/End/Instance, and a Shape under
 * a moving transform made an object of its own, outside any object or inside one (then
 * moving within each instance) (pbrt_reader.h, docs/pbrt.md, docs/instancing.md). */
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

/* The shapes the scene made since it held `first` spheres, sphere transforms, triangles
 * and shading records, saved in o (their indexes into each other made relative). */
static Status shapes_save(Parser *p, const size_t first[4], PObject *o)
{
    const Scene *s = p->s;
    o->n_spheres = s->n_spheres - first[0];
    o->n_sphere_xforms = s->n_sphere_xforms - first[1];
    o->n_triangles = s->n_triangles - first[2];
    o->n_shading = s->n_shading - first[3];
    o->sphere_xforms = malloc(o->n_sphere_xforms * sizeof *o->sphere_xforms + 1);
    o->spheres = malloc(o->n_spheres * sizeof *o->spheres + 1);
    o->triangles = malloc(o->n_triangles * sizeof *o->triangles + 1);
    o->shading = malloc(o->n_shading * sizeof *o->shading + 1);
    if (!o->spheres || !o->triangles || !o->shading || !o->sphere_xforms) {
        free(o->spheres);
        free(o->sphere_xforms);
        free(o->triangles);
        free(o->shading);
        o->spheres = NULL, o->sphere_xforms = NULL, o->triangles = NULL, o->shading = NULL;
        return error_set(p->err, ST_INTERNAL, "out of memory");
    }
    /* an object may hold no spheres (or no triangles), and the scene's array may then
     * still be NULL: C gives no NULL + 0, so the empty copies are skipped */
    if (o->n_sphere_xforms)
        memcpy(o->sphere_xforms, s->sphere_xforms + first[1], o->n_sphere_xforms * sizeof *o->sphere_xforms);
    if (o->n_spheres) memcpy(o->spheres, s->spheres + first[0], o->n_spheres * sizeof *o->spheres);
    if (o->n_triangles) memcpy(o->triangles, s->triangles + first[2], o->n_triangles * sizeof *o->triangles);
    if (o->n_shading) memcpy(o->shading, s->shading + first[3], o->n_shading * sizeof *o->shading);
    for (size_t i = 0; i < o->n_triangles; i++)
        if (o->triangles[i].shading != NO_INDEX) o->triangles[i].shading -= (uint)first[3];
    for (size_t i = 0; i < o->n_spheres; i++)
        if (o->spheres[i].xform) o->spheres[i].xform -= (uint)first[1];
    return ST_OK;
}

/* The shapes since ObjectBegin saved in o, to be copied in at an instance. */
static Status object_save(Parser *p, PObject *o)
{
    const size_t first[4] = { p->obj_spheres, p->obj_sphere_xforms, p->obj_triangles, p->obj_shading };
    return shapes_save(p, first, o);
}

static void shapes_free(PObject *o)
{
    free(o->spheres);
    free(o->sphere_xforms);
    free(o->triangles);
    free(o->shading);
    o->spheres = NULL, o->sphere_xforms = NULL, o->triangles = NULL, o->shading = NULL;
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

/* Moving part `part`'s shapes, saved at its Shape, appended to the scene again as they
 * were (the sphere transforms remade from their matrices) and made an object of their
 * own, unnamed (ObjectInstance cannot name it): its index in part->object. */
static Status part_object(Parser *p, const Lexer *lx, const Token *kw, PMovingPart *part)
{
    char buf[64];
    snprintf(buf, sizeof buf, "moving Shape %u:%u", part->line, part->col);
    Token name = {TOK_STRING, buf, strlen(buf), part->line, part->col};
    Status st = object_open(p, lx, kw, &name);
    if (st) return st;
    Scene *s = p->s;
    const PObject *o = &part->shapes;
    uint first_shading = (uint)s->n_shading, index;
    for (size_t i = 0; i < o->n_shading && !st; i++) st = scene_add_shading(s, o->shading[i], &index, p->err);
    for (size_t i = 0; i < o->n_triangles && !st; i++) {
        Triangle t = o->triangles[i];
        if (t.shading != NO_INDEX) t.shading += first_shading;
        st = scene_add_triangle(s, t, p->err);
    }
    for (size_t i = 0; i < o->n_spheres && !st; i++) {
        const Sphere *sp = &o->spheres[i];
        if (!sp->xform) {
            st = scene_add_sphere(s, *sp, p->err);
            continue;
        }
        const float *m = o->sphere_xforms[sp->xform - 1u].to_world;
        Transform own;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++) own.m[r][c] = m[4 * r + c];
        st = scene_add_ellipsoid(s, &own, sp->material, p->err);
    }
    if (st) return st;
    shapes_free(&part->shapes);
    return object_close(p, lx, kw, 0, &part->object);
}

Status pbrt_object_end(Parser *p, Lexer *lx, const Token *kw)
{
    if (!p->in_object) return lex_error_at(lx, kw, p->err, "ObjectEnd without ObjectBegin");
    uint32_t index;
    PMovingPart *parts = p->obj_moving;
    size_t n = p->n_obj_moving;
    Status st = object_close(p, lx, kw, 1, &index);
    if (st) return st;
    /* the object's entry owns its parts from here (pbrt_objects_free) */
    p->obj_moving = NULL;
    p->n_obj_moving = p->cap_obj_moving = 0;
    p->objects[index].moving = parts;
    p->objects[index].n_moving = n;
    for (size_t j = 0; j < n && !st; j++) st = part_object(p, lx, kw, &parts[j]);
    return st;
}

/* A Shape inside ObjectBegin/End under a moving transform. pbrt-v4 moves it within its
 * object: its BasicSceneBuilder::Shape keeps a shape under an animated CTM as an
 * animated shape of the instance definition, and BasicScene::CreateAggregate makes it an
 * AnimatedPrimitive inside the instance's BVH (src/pbrt/scene.cpp), so each instance
 * places it at (the instance's transform) x (the shape's CTM at the path's time). clpt
 * moves instances only and flattens nesting, so the shape is made in its own space
 * (both transforms the identity), taken out of the object's shapes, and at ObjectEnd
 * made an object of its own (part_object) that each ObjectInstance places as a moving
 * instance (part_place). */
Status pbrt_object_shape_moving(Parser *p, Lexer *lx, const Token *type)
{
    int tl = (int)(type->len > 40 ? 40 : type->len);
    if (!(p->time_end > p->time_start))
        return lex_error_at(lx, type, p->err, "Shape \"%.*s\" moves (ActiveTransform) but TransformTimes gives its start "
                            "and end the same time %g", tl, type->text, p->time_start);
    MotionKey key;
    if (motion_key_make(&p->g.ctm, (float)p->time_start, &key, p->err) ||
        motion_key_make(&p->g.ctm_end, (float)p->time_end, &key, p->err))
        return lex_error_at(lx, type, p->err, "Shape \"%.*s\" in object \"%s\" moves under a singular transform (at "
                            "its start or end time)", tl, type->text, p->obj_name_buf);
    if (pbrt_grow((void **)&p->obj_moving, &p->cap_obj_moving, p->n_obj_moving + 1, sizeof(PMovingPart)))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    PMovingPart part;
    memset(&part, 0, sizeof part);
    part.start = p->g.ctm;
    part.end = p->g.ctm_end;
    part.line = type->line;
    part.col = type->col;
    Scene *s = p->s;
    const size_t first[4] = { s->n_spheres, s->n_sphere_xforms, s->n_triangles, s->n_shading };
    p->g.ctm = p->g.ctm_end = transform_identity();
    Status st = pbrt_shape_make(p, lx, type);
    p->g.ctm = part.start;
    p->g.ctm_end = part.end;
    if (st) return st;
    if (s->n_spheres == first[0] && s->n_triangles == first[2]) return ST_OK;   /* nothing made */
    if ((st = shapes_save(p, first, &part.shapes))) return st;
    s->n_spheres = first[0];
    s->n_sphere_xforms = first[1];
    s->n_triangles = first[2];
    s->n_shading = first[3];
    p->obj_moving[p->n_obj_moving++] = part;
    return ST_OK;
}

void pbrt_objects_free(Parser *p)
{
    for (size_t i = 0; i < p->n_objects; i++) {
        for (size_t j = 0; j < p->objects[i].n_moving; j++) shapes_free(&p->objects[i].moving[j].shapes);
        free(p->objects[i].moving);
        shapes_free(&p->objects[i]);
    }
    free(p->objects);
    for (size_t j = 0; j < p->n_obj_moving; j++) shapes_free(&p->obj_moving[j].shapes);
    free(p->obj_moving);
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

/* The keys of one moving part under an instance: exact with two (W C0, W C1) when the
 * instance stands still under a similarity, which commutes with the interpolation
 * (translation and stretch linear, rotation slerp: a fixed rotation and uniform scale on
 * the left carry each through); else the product of the two interpolations sampled at
 * this many times evenly over TransformTimes, interpolated between them. */
#define PBRT_PART_KEYS 17

/* The most poses the moving Shapes in objects may take, all instances together (64
 * bytes each: 64 MiB). A few lines (many moving Shapes in an object, many instances
 * of it) would otherwise ask for gigabytes. */
#define PBRT_MAX_PART_KEYS ((size_t)1 << 20)

/* The transform of two keys k (start, end) at time t, the ends exactly as given. */
static Transform pair_at(const MotionKey k[2], const Transform *start, const Transform *end, int i, int n, float t)
{
    if (i == 0) return *start;
    if (i == n - 1) return *end;
    return motion_transform_at(k, 2, t);
}

/* Moving part `part` (pbrt_object_shape_moving) under the instance's transforms W
 * (ctm, ctm_end): a moving instance of the part's object whose pose at time t is
 * W(t) C(t), C the part's own transforms, each interpolated as pbrt-v4 interpolates an
 * AnimatedTransform (clpt's own instance interpolation for W: docs/pbrt.md#motion). */
static Status part_place(Parser *p, const Lexer *lx, const Token *name, const char *what, const PMovingPart *part)
{
    double scale;
    int w_moves = pbrt_ctm_moves(p);
    int n = !w_moves && pbrt_is_similarity(&p->g.ctm, &scale) ? 2 : PBRT_PART_KEYS;
    if (p->part_keys + (size_t)n > PBRT_MAX_PART_KEYS)
        return lex_error_at(lx, name, p->err, "%s \"%.*s\": the moving Shapes in objects would take more than %zu "
                            "poses (2 per instance under a still similarity, else %d)", what,
                            (int)(name->len > 60 ? 60 : name->len), name->text, PBRT_MAX_PART_KEYS, PBRT_PART_KEYS);
    p->part_keys += (size_t)n;
    MotionKey ck[2], wk[2];
    Status st = motion_key_make(&part->start, (float)p->time_start, &ck[0], p->err);
    if (!st) st = motion_key_make(&part->end, (float)p->time_end, &ck[1], p->err);
    if (!st) st = motion_key_make(&p->g.ctm, (float)p->time_start, &wk[0], p->err);
    if (!st) st = motion_key_make(&p->g.ctm_end, (float)p->time_end, &wk[1], p->err);
    if (st)
        return st == ST_INPUT ? lex_error_at(lx, name, p->err, "%s \"%.*s\" at its end time: %s", what,
                                             (int)(name->len > 60 ? 60 : name->len), name->text, p->err->msg)
                              : st;
    ck[0].count = ck[1].count = wk[0].count = wk[1].count = 2;
    motion_keys_shortest_arcs(ck, 2);
    motion_keys_shortest_arcs(wk, 2);
    uint object = p->objects[part->object].object;
    for (int i = 0; i < n && !st; i++) {
        float t = (float)(p->time_start + (p->time_end - p->time_start) * i / (n - 1));
        Transform c = pair_at(ck, &part->start, &part->end, i, n, t);
        Transform w = w_moves ? pair_at(wk, &p->g.ctm, &p->g.ctm_end, i, n, t) : p->g.ctm;
        Transform m = transform_compose(&w, &c);
        st = i == 0 ? scene_add_instance(p->s, object, &m, NO_INDEX, p->err)
                    : scene_add_instance_key(p->s, (float)p->time_start, t, &m, p->err);
    }
    return st == ST_INPUT ? lex_error_at(lx, name, p->err, "%s \"%.*s\": its moving Shape at %u:%u: %s", what,
                                         (int)(name->len > 60 ? 60 : name->len), name->text, part->line, part->col,
                                         p->err->msg)
                          : st;
}

static Status object_place_still(Parser *p, const Lexer *lx, const Token *name_tok, const char *what, uint32_t i);

/* ObjectInstance of p->objects[i] under the current transforms; `what` and `name` for
 * messages ("ObjectInstance" and its name, or "Shape" and its type): its still shapes
 * (object_place_still), then its moving Shapes, each a moving instance (part_place). */
static Status object_place(Parser *p, const Lexer *lx, const Token *name, const char *what, uint32_t i)
{
    const PObject *o = &p->objects[i];
    int still = o->object != NO_INDEX || o->n_spheres || o->n_triangles;
    Status st = still || !o->n_moving ? object_place_still(p, lx, name, what, i) : ST_OK;
    if (st || !o->n_moving) return st;
    Transform inv;
    if (!transform_invert(&p->g.ctm, &inv))
        return still ? ST_OK    /* skipped with object_place_still's warning */
                     : warn_once(p, lx, name, "instance-singular", "ObjectInstance \"%.*s\" under a singular "
                                 "transform is skipped", (int)(name->len > 60 ? 60 : name->len), name->text);
    for (size_t j = 0; j < o->n_moving && !st; j++) st = part_place(p, lx, name, what, &o->moving[j]);
    return st;
}

/* The still shapes of p->objects[i] under the current transforms: an instance, or
 * copies (above). */
static Status object_place_still(Parser *p, const Lexer *lx, const Token *name_tok, const char *what, uint32_t i)
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
