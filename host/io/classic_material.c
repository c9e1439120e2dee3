/*
 * classic_material.c — the classic reader's Materials block: Phong materials (the
 * course's keys and MIT 2004's) and checkerboards; part of the reader of classic_parse.c
 * (classic_reader.h).
 */
#include "io/classic_reader.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/kmath.h"
#include "io/lexer.h"
#include "io/reader.h"
#include "scene/transform.h"
#include "io/texture.h"

/* ------------------------------------------------------------------ materials */

enum { M_DIFFUSE, M_SPECULAR, M_SHININESS, M_EXPONENT, M_REFLECTIVE, M_TRANSPARENT, M_IOR, M_TEXTURE, M_N };
static const ClassicKey material_keys[M_N] = {
    [M_DIFFUSE] = {"diffuseColor", CK_COLOR, 0},     [M_SPECULAR] = {"specularColor", CK_COLOR, 0},
    [M_SHININESS] = {"shininess", CK_NUMBER, 0},     [M_EXPONENT] = {"exponent", CK_NUMBER, 0},
    [M_REFLECTIVE] = {"reflectiveColor", CK_COLOR, 0}, [M_TRANSPARENT] = {"transparentColor", CK_COLOR, 0},
    [M_IOR] = {"indexOfRefraction", CK_POSITIVE, 0}, [M_TEXTURE] = {"texture", CK_PATH, 0},
};

static Status add_material(Classic *c, Material m)
{
    uint index;
    Status st = scene_add_material(c->s, "", m, &index, c->err);
    if (st) return st;
    if (c->n_materials == 0) c->first_material = index;
    c->n_materials++;
    return ST_OK;
}

static Status parse_phong(Classic *c, const Token *kw)
{
    ClassicValue v[M_N];
    char block[32];
    snprintf(block, sizeof block, "%.*s", (int)kw->len, kw->text);
    Status st = classic_read_block(c, kw, block, material_keys, M_N, v);
    if (st) return st;
    if ((st = classic_only_one(c, &v[M_SHININESS], &v[M_EXPONENT], block))) return st;
    /* the format's defaults: diffuse 1 1 1, specular 0, shininess 0 */
    Material m = material_phong(v[M_DIFFUSE].given ? v[M_DIFFUSE].v : v3s(1.0f),
                                v[M_SPECULAR].given ? v[M_SPECULAR].v : v3s(0.0f),
                                v[M_SHININESS].given ? v[M_SHININESS].f : (v[M_EXPONENT].given ? v[M_EXPONENT].f : 0.0f));
    if (v[M_REFLECTIVE].given) m.reflective = v[M_REFLECTIVE].v;
    c->keys_2004 |= v[M_REFLECTIVE].given || v[M_TRANSPARENT].given || v[M_IOR].given || v[M_EXPONENT].given;
    if (v[M_TRANSPARENT].given) m.transparent = v[M_TRANSPARENT].v;
    if (v[M_IOR].given) m.ior = v[M_IOR].f;
    if (v[M_TEXTURE].given) {
        char *path;
        if ((st = classic_resolve_path(c, &v[M_TEXTURE].word, &path))) return st;
        /* linear texels, as the course's code reads them (its output has no sRGB curve
         * either, so a texture shows its file's bytes) */
        st = texture_load_image(c->s, NULL, path, 1, 0, &m.texture, c->err);
        free(path);
        if (st) {
            if (st == ST_IO || st == ST_INPUT)
                reader_annotate(&c->lx, &v[M_TEXTURE].word, c->err);
            return st;
        }
    }
    return add_material(c, m);
}


/* The classic solid checkerboard: the first material with its diffuse colour
 * alternating with the second's on the unit cells of the (transformed) point. */
static Status parse_checkerboard(Classic *c, const Token *kw)
{
    Status st = classic_expect_brace(c, TOK_LBRACE, "'{' to open the Checkerboard block");
    if (st) return st;
    Transform m = transform_identity();
    Token t;
    if ((st = classic_next(c, &t))) return st;
    if (tok_is(&t, "Transform")) {
        if ((st = classic_expect_brace(c, TOK_LBRACE, "'{' to open the Transform block"))) return st;
        if ((st = classic_parse_transform_ops(c, &m, &t))) return st;
        if (t.kind != TOK_RBRACE)
            return classic_expected(c, &t, "a transformation (Translate, Scale, UniformScale, XRotate, YRotate, "
                            "ZRotate, Rotate, Matrix4f, Matrix) or '}'");
        if ((st = classic_next(c, &t))) return st;
    }
    uint idx[2];
    for (int i = 0; i < 2; i++) {
        if (i > 0 && (st = classic_next(c, &t))) return st;
        if (!tok_is(&t, "materialIndex")) return classic_expected(c, &t, "'materialIndex'");
        Token nt;
        unsigned long long u;
        if ((st = classic_next(c, &nt))) return st;
        if (tok_uint(&nt, &u) || u >= c->n_materials) {
            char what[96];
            snprintf(what, sizeof what, "the index of a material defined before it (0..%d)", (int)c->n_materials - 1);
            return classic_expected(c, &nt, what);
        }
        idx[i] = c->first_material + (uint)u;
    }
    if ((st = classic_expect_brace(c, TOK_RBRACE, "'}' closing the Checkerboard block"))) return st;
    Material a = c->s->materials[idx[0]], b = c->s->materials[idx[1]];
    if (a.texture != NO_INDEX || b.texture != NO_INDEX)
        return lex_error_at(&c->lx, kw, c->err, "a Checkerboard of textured materials is not supported");
    Texture tx = texture_make_checker(a.albedo, b.albedo, 1.0f, 1);
    float mm[12];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) mm[4 * i + j] = (float)m.m[i][j];
    texture_set_matrix(&tx, mm);
    if ((st = texture_check_map(&tx, c->err))) {
        error_prefix(c->err, "%s:%u:%u: the Checkerboard's transform", c->lx.path, kw->line, kw->col);
        return st;
    }
    if ((st = scene_add_texture(c->s, NULL, NULL, tx, &a.texture, c->err))) return st;
    return add_material(c, a);
}

/* MIT 6.837 Fall 2019's ray tracer adds k_specular x the mirror ray's light when
 * bounces > 0, for its `Material` and `PhongMaterial` blocks alike (scene07_arch's
 * floor is a PhongMaterial of specularColor 0.4). MIT 2004's PhongMaterial mirrors only
 * with reflectiveColor, and Tsinghua's PA1 (a sized camera) is a ray caster that
 * reflects nothing. So once the Materials block is read, a scene in neither dialect
 * gets its specular colours as mirrors. */
static void mirror_specular_colours(Classic *c)
{
    if (c->camera_sized || c->keys_2004) return;
    for (uint i = c->first_material; i < c->first_material + c->n_materials; i++) {
        Material *m = &c->s->materials[i];
        if (m->type == MAT_PHONG) m->reflective = m->specular;
    }
}

Status classic_parse_materials(Classic *c, const Token *kw)
{
    if (c->seen_materials) return lex_error_at(&c->lx, kw, c->err, "a second Materials block");
    c->seen_materials = 1;
    Status st = classic_expect_brace(c, TOK_LBRACE, "'{' to open the Materials block");
    unsigned long long n;
    if (st || (st = classic_read_count(c, "numMaterials", &n))) return st;
    for (unsigned long long i = 0;; i++) {
        Token t;
        if ((st = classic_next(c, &t))) return st;
        if (t.kind == TOK_RBRACE && i == n) {
            mirror_specular_colours(c);
            return ST_OK;
        }
        if (t.kind == TOK_EOF)
            return lex_error_at(&c->lx, &t, c->err, "expected '}' to close the Materials block opened at line %u, "
                                "found end of file", kw->line);
        if (t.kind == TOK_RBRACE)
            return lex_error_at(&c->lx, &t, c->err, "the Materials block at line %u declares numMaterials %llu "
                                "but has %llu", kw->line, n, i);
        if (i == n) {
            char what[96];
            snprintf(what, sizeof what, "'}' closing the Materials block (numMaterials %llu)", n);
            return classic_expected(c, &t, what);
        }
        if (tok_is(&t, "PhongMaterial") || tok_is(&t, "Material")) st = parse_phong(c, &t);
        else if (tok_is(&t, "Checkerboard")) st = parse_checkerboard(c, &t);
        else return classic_expected(c, &t, "a material (PhongMaterial, Material, Checkerboard)");
        if (st) return st;
    }
}
