/*
 * scene_shape.c — the scene reader's shapes (sphere, plane, triangle, quad, box), meshes
 * and lights; part of the reader of scene_parse.c (scene_reader.h).
 */
#include "io/scene_reader.h"

#include "util/kmath.h"
#include "io/lexer.h"
#include "io/mesh_load.h"
#include "io/reader.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The material a shape gets from its surface keys (v[prefix##_MATERIAL] onwards),
 * bound to its interior and exterior media. Each shape below is a key table and a
 * builder of its geometry from the values read, which binds its surface here;
 * surface_shapes pairs them and scene_parse_shape reads the block. */
static Status shape_surface(Parser *p, const Value *surface, uint *material)
{
    return scene_shape_media(p, &surface[1], &surface[2], surface[0].material, material);
}

enum { SPH_CENTER, SPH_RADIUS, SURFACE_KEY_IDS(SPH), SPH_N };
static const KeySpec sphere_keys[SPH_N] = {
    [SPH_CENTER] = {"center", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [SPH_RADIUS] = {"radius", VK_NUMBER, 1, 0, INFINITY, 1, 1, "a radius > 0"},
    SURFACE_KEYS(SPH),
};

static Status build_sphere(Parser *p, const Lexer *lx, const Token *kw, const Value *v)
{
    (void)kw;
    Status st;
    vec3 c = v[SPH_CENTER].v;
    float r = v[SPH_RADIUS].f;
    /* a bounding box that overflows would leave the sphere out of the kd-tree */
    if (!isfinite(fabsf(c.x) + r) || !isfinite(fabsf(c.y) + r) || !isfinite(fabsf(c.z) + r))
        return lex_error_at(lx, &v[SPH_RADIUS].key, p->err,
                            "the sphere reaches beyond the largest float (about 3.4e38)");
    Sphere sp;
    memset(&sp, 0, sizeof sp);
    sp.center = c;
    sp.radius = r;
    if ((st = shape_surface(p, &v[SPH_MATERIAL], &sp.material))) return st;
    return scene_add_sphere(p->s, sp, p->err);
}

enum { PL_POINT, PL_NORMAL, SURFACE_KEY_IDS(PL), PL_N };
static const KeySpec plane_keys[PL_N] = {
    [PL_POINT] = {"point", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [PL_NORMAL] = {"normal", VK_DIR, 1, 0, 0, 0, 0, NULL},
    SURFACE_KEYS(PL),
};

static Status build_plane(Parser *p, const Lexer *lx, const Token *kw, const Value *v)
{
    (void)kw;
    Status st;
    vec3 n = v[PL_NORMAL].v, q = v[PL_POINT].v;
    double len = scene_len_d(n);
    if (!isfinite(len))
        return lex_error_at(lx, &v[PL_NORMAL].key, p->err, "plane 'normal' is too long to normalise");
    double nx = n.x / len, ny = n.y / len, nz = n.z / len;
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = v3((float)nx, (float)ny, (float)nz);
    pl.offset = (float)(nx * q.x + ny * q.y + nz * q.z);
    if ((st = shape_surface(p, &v[PL_MATERIAL], &pl.material))) return st;
    return scene_add_plane(p->s, pl, p->err);
}

static Status add_triangle(Parser *p, const Lexer *lx, const Token *kw, vec3 a, vec3 b, vec3 c,
                           uint material, const char *which)
{
    double area2;
    scene_cross_d(v3_sub(b, a), v3_sub(c, a), &area2);
    /* the kernels compute edges in float: corners 6e38 apart give infinite edges */
    if (isnan(area2) || isinf(area2))
        return lex_error_at(lx, kw, p->err, "%.*s: the corners %s are too far apart (their "
                            "differences overflow single precision)", (int)kw->len, kw->text, which);
    if (!(area2 > 0.0))
        return lex_error_at(lx, kw, p->err, "degenerate %.*s: the corners %s lie on one line",
                            (int)kw->len, kw->text, which);
    Triangle t;
    memset(&t, 0, sizeof t);
    t.p0 = a;
    t.p1 = b;
    t.p2 = c;
    t.material = material;
    t.shading = NO_INDEX;
    return scene_add_triangle(p->s, t, p->err);
}

enum { TRI_V0, TRI_V1, TRI_V2, SURFACE_KEY_IDS(TRI), TRI_N };
static const KeySpec triangle_keys[TRI_N] = {
    [TRI_V0] = {"v0", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [TRI_V1] = {"v1", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [TRI_V2] = {"v2", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    SURFACE_KEYS(TRI),
};
enum { QUAD_V0, QUAD_V1, QUAD_V2, QUAD_V3, SURFACE_KEY_IDS(QUAD), QUAD_N };
static const KeySpec quad_keys[QUAD_N] = {
    [QUAD_V0] = {"v0", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [QUAD_V1] = {"v1", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [QUAD_V2] = {"v2", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [QUAD_V3] = {"v3", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    SURFACE_KEYS(QUAD),
};

static Status build_triangle(Parser *p, const Lexer *lx, const Token *kw, const Value *v)
{
    Status st;
    uint m;
    if ((st = shape_surface(p, &v[TRI_MATERIAL], &m))) return st;
    return add_triangle(p, lx, kw, v[TRI_V0].v, v[TRI_V1].v, v[TRI_V2].v, m, "v0 v1 v2");
}

static Status build_quad(Parser *p, const Lexer *lx, const Token *kw, const Value *v)
{
    Status st;
    uint m;
    if ((st = shape_surface(p, &v[QUAD_MATERIAL], &m))) return st;
    st = add_triangle(p, lx, kw, v[QUAD_V0].v, v[QUAD_V1].v, v[QUAD_V2].v, m, "v0 v1 v2");
    if (!st) st = add_triangle(p, lx, kw, v[QUAD_V0].v, v[QUAD_V2].v, v[QUAD_V3].v, m, "v0 v2 v3");
    return st;
}

enum { BOX_MIN, BOX_MAX, SURFACE_KEY_IDS(BOX), BOX_N };
static const KeySpec box_keys[BOX_N] = {
    [BOX_MIN] = {"min", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    [BOX_MAX] = {"max", VK_VEC3, 1, 0, 0, 0, 0, NULL},
    SURFACE_KEYS(BOX),
};

static Status build_box(Parser *p, const Lexer *lx, const Token *kw, const Value *v)
{
    (void)kw;
    Status st;
    vec3 lo = v[BOX_MIN].v, hi = v[BOX_MAX].v;
    static const char axis[3] = {'x', 'y', 'z'};
    for (int i = 0; i < 3; i++)
        if (!(v3_get(lo, i) < v3_get(hi, i)))
            return lex_error_at(lx, &v[BOX_MAX].key, p->err,
                                "box 'max' must be greater than 'min' on every axis, "
                                "but on %c it is %.9g <= %.9g",
                                axis[i], (double)v3_get(hi, i), (double)v3_get(lo, i));
    Box b;
    memset(&b, 0, sizeof b);
    b.lo = lo;
    b.hi = hi;
    if ((st = shape_surface(p, &v[BOX_MATERIAL], &b.material))) return st;
    return scene_add_box(p->s, b, p->err);
}

/* The shapes with a surface: each one's block, read by scene_parse_shape, and its
 * builder. */
typedef Status (*ShapeBuild)(Parser *p, const Lexer *lx, const Token *kw, const Value *v);
static const struct {
    const char *name;
    const KeySpec *keys;
    uint n_keys;
    ShapeBuild build;
} surface_shapes[] = {
    {"sphere", sphere_keys, SPH_N, build_sphere},
    {"plane", plane_keys, PL_N, build_plane},
    {"triangle", triangle_keys, TRI_N, build_triangle},
    {"quad", quad_keys, QUAD_N, build_quad},
    {"box", box_keys, BOX_N, build_box},
};
enum { SHAPE_MAX_KEYS = 7 };
_Static_assert((int)SPH_N <= (int)SHAPE_MAX_KEYS && (int)PL_N <= (int)SHAPE_MAX_KEYS &&
               (int)TRI_N <= (int)SHAPE_MAX_KEYS && (int)QUAD_N <= (int)SHAPE_MAX_KEYS &&
               (int)BOX_N <= (int)SHAPE_MAX_KEYS, "surface_shapes: a block with more keys than SHAPE_MAX_KEYS");

Status scene_parse_shape(Parser *p, Lexer *lx, const Token *kw)
{
    for (size_t i = 0; i < sizeof surface_shapes / sizeof surface_shapes[0]; i++)
        if (tok_is(kw, surface_shapes[i].name)) {
            Value v[SHAPE_MAX_KEYS];
            Status st = scene_parse_block(p, lx, kw, 0, surface_shapes[i].name, surface_shapes[i].keys,
                                          surface_shapes[i].n_keys, v);
            return st ? st : surface_shapes[i].build(p, lx, kw, v);
        }
    return error_set(p->err, ST_INTERNAL, "no shape '%.*s'", (int)kw->len, kw->text);
}

enum { MESH_FILE, MESH_MATERIAL, TRANSFORM_KEY_IDS(MESH), MESH_INTERIOR, MESH_EXTERIOR, MESH_N };
static const KeySpec mesh_keys[MESH_N] = {
    [MESH_FILE] = {"file", VK_PATH, 1, 0, 0, 0, 0, NULL},
    [MESH_MATERIAL] = {"material", VK_MATERIAL, 0, 0, 0, 0, 0, NULL},
    TRANSFORM_KEYS(MESH),
    MEDIUM_KEYS(MESH),
};

/* The transform of a block's translate, rotate, rx, ry, rz, scale and matrix keys
 * (t[0 .. 7), in that order): scale, then rotate, rx, ry, rz, then translate; or a whole
 * affine matrix, which excludes the others. `what` names the block in the message for a
 * singular one ("mesh": "the mesh transform is singular (it flattens the mesh)"). */
Status scene_parse_transform(Parser *p, const Lexer *lx, const Token *kw, const Value *t, const char *what,
                             Transform *out)
{
    enum { T_TRANSLATE, T_ROTATE, T_RX, T_RY, T_RZ, T_SCALE, T_MATRIX };
    Transform m = transform_identity();
    if (t[T_MATRIX].given) {
        for (int i = T_TRANSLATE; i < T_MATRIX; i++)
            if (t[i].given) {
                const Token *later = &t[i].key;
                if (t[T_MATRIX].key.line > later->line ||
                    (t[T_MATRIX].key.line == later->line && t[T_MATRIX].key.col > later->col))
                    later = &t[T_MATRIX].key;
                return lex_error_at(lx, later, p->err,
                                    "'matrix' cannot be combined with translate, rotate, rx, ry, rz or scale "
                                    "(fold them into the matrix)");
            }
        const float *a = t[T_MATRIX].a;
        if (a[12] != 0.0f || a[13] != 0.0f || a[14] != 0.0f || a[15] != 1.0f)
            return lex_error_at(lx, &t[T_MATRIX].key, p->err,
                                "the last row of 'matrix' must be 0 0 0 1 (an affine transform), found "
                                "%g %g %g %g", (double)a[12], (double)a[13], (double)a[14], (double)a[15]);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) m.m[i][j] = a[4 * i + j];
    } else {
        if (t[T_SCALE].given) {
            const float *a = t[T_SCALE].a;
            m = transform_scale(a[0], a[1], a[2]);
        }
        Transform r;
        if (t[T_ROTATE].given) {
            const float *a = t[T_ROTATE].a;
            r = transform_rotate(a[0], a[1], a[2], a[3]);
            m = transform_compose(&r, &m);
        }
        for (int axis = 0; axis < 3; axis++) {
            const Value *rv = &t[T_RX + axis];
            if (!rv->given) continue;
            r = transform_rotate(axis == 0, axis == 1, axis == 2, rv->f);
            m = transform_compose(&r, &m);
        }
        if (t[T_TRANSLATE].given) {
            vec3 d = t[T_TRANSLATE].v;
            r = transform_translate(d.x, d.y, d.z);
            m = transform_compose(&r, &m);
        }
    }
    double det = transform_det(&m);
    if (!(fabs(det) > 1e-300) || !isfinite(det)) {
        const Token *at = t[T_MATRIX].given ? &t[T_MATRIX].key : t[T_SCALE].given ? &t[T_SCALE].key : kw;
        return lex_error_at(lx, at, p->err, "the %s transform is singular (it flattens the %s)", what,
                            strcmp(what, "mesh") == 0 ? "mesh" : "object");
    }
    *out = m;
    return ST_OK;
}

/* A mesh too small for single precision shades black or vanishes (a mesh 1e-30
 * across): refused when most of its triangles' normals underflow (a few slivers in a
 * mesh of normal size are harmless, and only those are lost). */
static Status check_mesh_size(Parser *p, const Lexer *lx, const Token *f, const char *path, size_t first)
{
    size_t tiny, with_area;
    vec3 lo, hi;
    scene_count_tiny_triangles(p->s, first, p->s->n_triangles, &tiny, &with_area, &lo, &hi);
    if (tiny == 0 || tiny * 2 < with_area) return ST_OK;
    return lex_error_at(lx, f, p->err, "the mesh '%s' is too small for single precision: %zu of its %zu "
                        "triangles have normals that underflow (it spans %g x %g x %g after its transform); "
                        "scale it up", path, tiny, with_area, (double)(hi.x - lo.x), (double)(hi.y - lo.y),
                        (double)(hi.z - lo.z));
}

Status scene_parse_mesh(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[MESH_N];
    Status st = scene_parse_block(p, lx, kw, 0, "mesh", mesh_keys, MESH_N, v);
    if (st) return st;
    const Token *f = &v[MESH_FILE].word;
    MeshOptions o = mesh_options(v[MESH_MATERIAL].given ? v[MESH_MATERIAL].material : NO_INDEX);
    if ((st = scene_parse_transform(p, lx, kw, v + MESH_TRANSLATE, "mesh", &o.xf))) return st;
    o.no_instances = p->object != NO_INDEX;
    char *path = scene_path_beside(lx->path, f->text, f->len);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    if (mesh_kind(path) == MESH_NONE) {
        free(path);
        return lex_expected(lx, f, "a mesh file name ending in .obj, .ply, .obj.gz, .ply.gz, .gltf or .glb", p->err);
    }
    size_t first = p->s->n_triangles;
    st = mesh_load(path, p->s, &o, p->err);
    if (st) reader_note_nested(lx, f, kw, "in the mesh of", st, p->err);
    else st = check_mesh_size(p, lx, f, path, first);
    if (!st) st = scene_mesh_media(p, &v[MESH_INTERIOR], &v[MESH_EXTERIOR], first);
    free(path);
    return st;
}

/* ------------------------------------------------------------------ lights, textures */

enum { LK_TYPE, LK_POSITION, LK_DIRECTION, LK_INTENSITY, LK_ATTEN, LK_ANGLE, LK_INNER, LK_N };
static const KeySpec light_keys[LK_N] = {
    [LK_TYPE] = {"type", VK_WORD, 1, 0, 0, 0, 0, "a light type (point, spot, directional)"},
    [LK_POSITION] = {"position", VK_VEC3, 0, 0, 0, 0, 0, NULL},
    [LK_DIRECTION] = {"direction", VK_DIR, 0, 0, 0, 0, 0, NULL},
    [LK_INTENSITY] = {"intensity", VK_COLOR, 1, 0, 0, 0, 0, NULL},
    [LK_ATTEN] = {"attenuation", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [LK_ANGLE] = {"angle", VK_NUMBER, 0, 0, 180, 1, 1, "a number of degrees in (0, 180)"},
    [LK_INNER] = {"inner", VK_NUMBER, 0, 0, 180, 0, 1, "a number of degrees in [0, 180)"},
};

Status scene_parse_light(Parser *p, Lexer *lx, const Token *kw)
{
    Value v[LK_N];
    Status st = scene_parse_block(p, lx, kw, 0, "light", light_keys, LK_N, v);
    if (st) return st;
    static const struct { const char *name; uint type; unsigned allowed; } types[] = {
        {"point", LIGHT_POINT, 1u << LK_POSITION | 1u << LK_ATTEN},
        {"spot", LIGHT_SPOT, 1u << LK_POSITION | 1u << LK_DIRECTION | 1u << LK_ATTEN | 1u << LK_ANGLE | 1u << LK_INNER},
        {"directional", LIGHT_DIRECTIONAL, 1u << LK_DIRECTION},
    };
    size_t ti;
    for (ti = 0; ti < 3; ti++)
        if (tok_is(&v[LK_TYPE].word, types[ti].name)) break;
    if (ti == 3) return lex_expected(lx, &v[LK_TYPE].word, light_keys[LK_TYPE].what, p->err);
    unsigned allowed = types[ti].allowed | 1u << LK_TYPE | 1u << LK_INTENSITY;
    for (int i = 0; i < LK_N; i++)
        if (v[i].given && !(allowed & (1u << i)))
            return lex_error_at(lx, &v[i].key, p->err, "a %s light has no '%s'", types[ti].name, light_keys[i].key);
    Light l = light_default(types[ti].type);
    l.intensity = v[LK_INTENSITY].v;
    if (v[LK_POSITION].given) l.position = v[LK_POSITION].v;
    if (v[LK_DIRECTION].given) {
        vec3 d = v[LK_DIRECTION].v;
        double len = scene_len_d(d);
        l.direction = v3((float)(d.x / len), (float)(d.y / len), (float)(d.z / len));
    }
    if (v[LK_ATTEN].given) {
        if (v3_is_zero(v[LK_ATTEN].v))
            return lex_error_at(lx, &v[LK_ATTEN].key, p->err, "'attenuation' (constant linear quadratic) must not be all 0");
        l.atten0 = v[LK_ATTEN].v.x;
        l.atten1 = v[LK_ATTEN].v.y;
        l.atten2 = v[LK_ATTEN].v.z;
    }
    float outer = v[LK_ANGLE].given ? v[LK_ANGLE].f : 30.0f, inner = v[LK_INNER].given ? v[LK_INNER].f : outer;
    if (inner > outer) return lex_error_at(lx, &v[LK_INNER].key, p->err, "'inner' must not exceed 'angle'");
    l.cos_outer = (float)cos((double)outer * M_PI / 180.0);
    l.cos_inner = (float)cos((double)inner * M_PI / 180.0);
    return scene_add_light(p->s, l, p->err);
}
