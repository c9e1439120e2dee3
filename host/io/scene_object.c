/*
 * scene_object.c — the scene reader's objects and instances (docs/instancing.md);
 * part of the reader of scene_parse.c (scene_reader.h).
 *
 *   object NAME { shapes... instances... }     the shapes once, in the object's space
 *   instance NAME { translate ... material M }  the object placed in the world, or,
 *                                               inside an object, in the object's space
 *   instance_key { time T translate ... }      a later pose of the world instance
 *                                               before it (docs/motion.md)
 *
 * Instances nest: an object may hold instances of objects defined before it, up to
 * SCENE_MAX_NESTING deep; each world instance is resolved into one instance per object
 * with shapes on its way down (scene_place_object), so the devices see one level.
 * Object definitions themselves do not nest.
 */
#include "io/scene_reader.h"

#include "base/limit.h"
#include "io/lexer.h"
#include "scene/instance.h"
#include "scene/motion.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The statements an object's block may hold: the shapes with a place in an object's
 * space (an infinite plane has no bounds to instance, lights belong to the world). */
static const struct {
    const char *keyword;
    Status (*parse)(Parser *p, Lexer *lx, const Token *kw);
} object_statements[] = {
    {"sphere", scene_parse_shape}, {"triangle", scene_parse_shape}, {"quad", scene_parse_shape},
    {"box", scene_parse_shape},    {"mesh", scene_parse_mesh},
};
#define N_OBJECT_STATEMENTS (sizeof object_statements / sizeof object_statements[0])

/* An object's name: a word or a string, not empty. */
static Status object_name(Parser *p, Lexer *lx, const char *after, Token *name)
{
    Status st = lex_next(lx, name, p->err);
    if (st) return st;
    if ((name->kind != TOK_WORD && name->kind != TOK_STRING) || name->len == 0) {
        char what[64];
        snprintf(what, sizeof what, "an object name after '%s'", after);
        return lex_expected(lx, name, what, p->err);
    }
    return ST_OK;
}

/* The statements of an object's block, up to its closing brace. */
static Status object_body(Parser *p, Lexer *lx, const Token *name)
{
    for (;;) {
        Token t;
        Status st = lex_next(lx, &t, p->err);
        if (st) return st;
        if (t.kind == TOK_RBRACE) return ST_OK;
        if (t.kind == TOK_EOF)
            return lex_error_at(lx, name, p->err, "object '%.*s' is not closed with '}'", (int)name->len, name->text);
        if (t.kind == TOK_WORD && tok_is(&t, "object"))
            return lex_error_at(lx, &t, p->err, "'object' inside object '%.*s': objects are defined at the top level "
                                "(an object may hold instances of objects defined before it)", (int)name->len,
                                name->text);
        if (t.kind == TOK_WORD && tok_is(&t, "instance")) {
            if ((st = scene_parse_instance(p, lx, &t))) return st;
            continue;
        }
        size_t i = N_OBJECT_STATEMENTS;
        if (t.kind == TOK_WORD)
            for (i = 0; i < N_OBJECT_STATEMENTS; i++)
                if (tok_is(&t, object_statements[i].keyword)) break;
        if (i == N_OBJECT_STATEMENTS)
            return lex_expected(lx, &t, "a shape of the object (sphere, triangle, quad, box, mesh), an instance or '}'",
                                p->err);
        if ((st = object_statements[i].parse(p, lx, &t))) return st;
    }
}

Status scene_parse_object(Parser *p, Lexer *lx, const Token *kw)
{
    Token name, brace;
    Status st = object_name(p, lx, "object", &name);
    if (st) return st;
    if (scene_find_object(p->s, name.text, name.len) != NO_INDEX)
        return lex_error_at(lx, &name, p->err, "object '%.*s' is defined twice", (int)name.len, name.text);
    if ((st = lex_next(lx, &brace, p->err))) return st;
    if (brace.kind != TOK_LBRACE) return lex_expected(lx, &brace, "'{' after the object's name", p->err);
    uint index;
    if ((st = scene_object_begin(p->s, name.text, name.len, &index, p->err)))
        return st == ST_INPUT ? lex_error_at(lx, kw, p->err, "%s", p->err->msg) : st;
    p->object = index;
    p->object_name = name;
    st = object_body(p, lx, &name);
    p->object = NO_INDEX;
    scene_object_end(p->s, index);
    if (st) return st;
    if (scene_object_prims(p->s, index) == 0 && p->s->objects[index].leaves == 0)
        return lex_error_at(lx, &name, p->err, "object '%.*s' holds no shapes or instances", (int)name.len, name.text);
    (void)kw;
    return ST_OK;
}

enum { INST_MATERIAL, TRANSFORM_KEY_IDS(INST), INST_TIME, INST_N };
static const KeySpec instance_keys[INST_N] = {
    [INST_MATERIAL] = {"material", VK_MATERIAL, 0, 0, 0, 0, 0, NULL},
    [INST_TIME] = {"time", VK_NUMBER, 0, -INFINITY, INFINITY, 0, 0, "a time (a number)"},
    TRANSFORM_KEYS(INST),
};

/* A world instance of an object that nests others may place a great many records from
 * one line: the scene's instances may then reach CLPT_MAX_NESTED_INSTANCES and
 * CLPT_NESTED_INSTANCES_PER_INPUT_BYTE for each byte the load has read (base/limit.h),
 * checked before anything is placed. Counts of 2^62 and more are scene_place_object's
 * to name. */
static Status check_nested_budget(Parser *p, Lexer *lx, const Token *kw, uint object)
{
    const SceneObject *o = &p->s->objects[object];
    if (o->first_nested == o->end_nested || o->leaves >= ((uint64_t)1 << 62)) return ST_OK;
    uint64_t bytes = lex_load_bytes();
    uint64_t budget = CLPT_MAX_NESTED_INSTANCES + CLPT_NESTED_INSTANCES_PER_INPUT_BYTE * bytes;
    uint64_t total = (uint64_t)p->s->n_instances + o->leaves;
    if (total <= budget || total <= 1) return ST_OK;
    return lex_error_at(lx, kw, p->err,
                        "an instance of '%s' places %llu instances through the objects it nests: with the %zu "
                        "placed before, past the %llu a scene of %llu bytes may place (%u and %u a byte; "
                        "docs/instancing.md)",
                        o->name, (unsigned long long)o->leaves, p->s->n_instances, (unsigned long long)budget,
                        (unsigned long long)bytes, CLPT_MAX_NESTED_INSTANCES, CLPT_NESTED_INSTANCES_PER_INPUT_BYTE);
}

Status scene_parse_instance(Parser *p, Lexer *lx, const Token *kw)
{
    Token name;
    Status st = object_name(p, lx, "instance", &name);
    if (st) return st;
    uint object = scene_find_object(p->s, name.text, name.len);
    if (object != NO_INDEX && object == p->object)
        return lex_error_at(lx, &name, p->err, "object '%.*s' instances itself (an object cannot hold itself)",
                            (int)name.len, name.text);
    if (object == NO_INDEX)
        return lex_error_at(lx, &name, p->err, "no object named '%.*s' (define it with 'object %.*s { ... }' before "
                            "its instances)", (int)name.len, name.text, (int)name.len, name.text);
    Value v[INST_N];
    if ((st = scene_parse_block(p, lx, kw, 0, "instance", instance_keys, INST_N, v))) return st;
    Transform m;
    if ((st = scene_parse_transform(p, lx, kw, v + INST_TRANSLATE, "instance", &m))) return st;
    uint material = v[INST_MATERIAL].given ? v[INST_MATERIAL].material : NO_INDEX;
    if (p->object != NO_INDEX) {
        /* instance_key moves a world instance; one inside an object is not one */
        p->last_instance = NO_INDEX;
        p->last_instance_nests = 1;
        st = scene_object_nest(p->s, p->object, object, &m, material, p->err);
        return st == ST_INPUT ? lex_error_at(lx, kw, p->err, "%s", p->err->msg) : st;
    }
    if ((st = check_nested_budget(p, lx, kw, object))) return st;
    size_t first = p->s->n_instances;
    st = scene_place_object(p->s, object, &m, material, p->err);
    if (st) return st == ST_INPUT ? lex_error_at(lx, kw, p->err, "%s", p->err->msg) : st;
    /* an object that nests others places one instance per leaf: instance_key moves
     * a single record (docs/motion.md) */
    p->last_instance_nests = p->s->n_instances - first != 1;
    p->last_instance = p->last_instance_nests ? NO_INDEX : (uint)first;
    p->last_instance_time = v[INST_TIME].given ? v[INST_TIME].f : 0.0f;
    return ST_OK;
}

/* instance_key { time T  translate ... }: a later pose of the instance before it
 * (docs/motion.md), its transform keys as an instance's, applied alone (the pose is
 * the whole transform then, not a change of the one before). */
enum { IK_TIME, TRANSFORM_KEY_IDS(IK), IK_N };
static const KeySpec instance_key_keys[IK_N] = {
    [IK_TIME] = {"time", VK_NUMBER, 1, -INFINITY, INFINITY, 0, 0, "a time (a number)"},
    TRANSFORM_KEYS(IK),
};

Status scene_parse_instance_key(Parser *p, Lexer *lx, const Token *kw)
{
    if (p->last_instance == NO_INDEX && p->last_instance_nests)
        return lex_error_at(lx, kw, p->err, "instance_key after an instance inside an object or of an object that "
                            "nests instances (only a single world instance moves)");
    if (p->last_instance == NO_INDEX)
        return lex_error_at(lx, kw, p->err, "instance_key before any instance (it moves the instance before it)");
    Value v[IK_N];
    Status st = scene_parse_block(p, lx, kw, 0, "instance_key", instance_key_keys, IK_N, v);
    if (st) return st;
    Transform m;
    if ((st = scene_parse_transform(p, lx, kw, v + IK_TRANSLATE, "instance_key", &m))) return st;
    st = scene_add_instance_key(p->s, p->last_instance_time, v[IK_TIME].f, &m, p->err);
    return st == ST_INPUT ? lex_error_at(lx, strstr(p->err->msg, "is not after") ? &v[IK_TIME].value : kw,
                                         p->err, "%s", p->err->msg)
                          : st;
}
