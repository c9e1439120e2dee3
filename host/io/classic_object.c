/*
 * classic_object.c — the classic reader's objects: Group and Transform blocks, spheres,
 * planes, triangles, OBJ meshes, curves and surfaces of revolution, with their
 * transforms applied while reading (meshes under a Transform as instances, squashed
 * spheres as ellipsoids); part of the reader of classic_parse.c (classic_reader.h).
 */
#include "io/classic_reader.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/kmath.h"
#include "base/limit.h"
#include "io/lexer.h"
#include "io/reader.h"
#include "io/obj.h"
#include "scene/curve.h"
#include "scene/instance.h"
#include "scene/transform.h"

/* The mesh of a surface of revolution that a transform tilts off the vertical: rows per
 * profile segment x columns around the axis. */
#define REV_MESH_STEPS 16
#define REV_MESH_AROUND 96

/* ------------------------------------------------------------------ transforms */

/* n carried by transform_normal_matrix's matrix and made unit length (0 0 0 if it vanishes). */
static vec3 normal_apply(double n[3][3], vec3 v)
{
    double x = n[0][0] * v.x + n[0][1] * v.y + n[0][2] * v.z;
    double y = n[1][0] * v.x + n[1][1] * v.y + n[1][2] * v.z;
    double z = n[2][0] * v.x + n[2][1] * v.y + n[2][2] * v.z;
    double len = sqrt(x * x + y * y + z * z);
    if (!(len > 0.0) || !isfinite(len)) return v3(0.0f, 0.0f, 0.0f);
    return v3((float)(x / len), (float)(y / len), (float)(z / len));
}

/* Whether the linear part is s times an orthogonal matrix (a sphere stays a sphere of
 * radius s*r); *rotates tells whether that orthogonal matrix is not the identity. */
static int similarity(const Transform *m, double *s, int *rotates)
{
    const double (*a)[4] = m->m;
    double g[3][3], trace = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            g[i][j] = a[0][i] * a[0][j] + a[1][i] * a[1][j] + a[2][i] * a[2][j];
            if (i == j) trace += g[i][j];
        }
    double s2 = trace / 3.0;
    if (!(s2 > 0.0) || !isfinite(s2)) return 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (fabs(g[i][j] - (i == j ? s2 : 0.0)) > 1e-6 * s2) return 0;
    *s = sqrt(s2);
    *rotates = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (fabs(a[i][j] / *s - (i == j ? 1.0 : 0.0)) > 1e-6) *rotates = 1;
    return 1;
}

/* ------------------------------------------------------------------ objects */


/* The material of the next object: the last MaterialIndex, else material 0, else
 * (no materials at all) a white diffuse one made on first use. */
static Status object_material(Classic *c, uint *out)
{
    if (c->current != NO_INDEX) *out = c->current;
    else if (c->n_materials > 0) *out = c->first_material;
    else {
        if (c->fallback == NO_INDEX) {
            Status st = scene_add_material(c->s, "", material_phong(v3s(1.0f), v3s(0.0f), 0.0f), &c->fallback, c->err);
            if (st) return st;
        }
        *out = c->fallback;
    }
    return ST_OK;
}

static Status add_tri(Classic *c, vec3 a, vec3 b, vec3 d, uint material, uint shading)
{
    Triangle t;
    memset(&t, 0, sizeof t);
    t.p0 = a;
    t.p1 = b;
    t.p2 = d;
    t.material = material;
    t.shading = shading;
    return scene_add_triangle(c->s, t, c->err);
}

/* An object's block read into v, and the material it gets (object_material). */
static Status read_object(Classic *c, const Token *kw, const char *name, const ClassicKey *keys, size_t n,
                          ClassicValue *v, uint *material)
{
    Status st = classic_read_block(c, kw, name, keys, n, v);
    return st ? st : object_material(c, material);
}

/* Each object below is its keys (an enum and a ClassicKey table) and a builder of its
 * geometry from the values read and its material (keyed_objects, which
 * classic_parse_object reads the block by). */
enum { SPH_CENTER, SPH_RADIUS, SPH_N };
static const ClassicKey sphere_keys[SPH_N] = {
    [SPH_CENTER] = {"center", CK_VEC3, 0}, [SPH_RADIUS] = {"radius", CK_POSITIVE, 1},
};

/* A sphere stays a plain one (centre, radius) under a similarity, so that scenes that
 * only move and scale spheres uniformly render as before. Any other transform, or a
 * rotation of a textured sphere (whose texture must turn with it), makes it the unit
 * sphere under m . T(center) . S(radius): an exact ellipsoid (scene_add_ellipsoid, as
 * the pbrt reader's), 128 bytes however it is squashed, whose (u, v) follow the
 * untransformed sphere's longitude and latitude (kernels/material/texture.h). Its
 * normals are M^-T of the sphere's, outward under a mirror too. Classic materials emit
 * no light, which an ellipsoid may not. */
static Status build_sphere(Classic *c, const Token *kw, const Transform *m, const ClassicValue *v, uint material)
{
    vec3 center = v[SPH_CENTER].v;   /* the origin when not given */
    double scale;
    int rotates;
    int textured = c->s->materials[material].texture != NO_INDEX;
    if (!similarity(m, &scale, &rotates) || (rotates && textured)) {
        double r = v[SPH_RADIUS].f;
        Transform place = transform_translate(center.x, center.y, center.z), size = transform_scale(r, r, r);
        place = transform_compose(&place, &size);
        Transform unit_to_world = transform_compose(m, &place);
        Status st = scene_add_ellipsoid(c->s, &unit_to_world, material, c->err);
        if (st == ST_INPUT) reader_annotate(&c->lx, kw, c->err);
        return st;
    }
    Sphere sp;
    memset(&sp, 0, sizeof sp);
    sp.center = transform_point(m, center);
    sp.radius = (float)(scale * v[SPH_RADIUS].f);
    sp.material = material;
    if (!(sp.radius > 0.0f) || !isfinite(sp.radius))
        return lex_error_at(&c->lx, kw, c->err, "the transformed sphere's radius is %g", (double)sp.radius);
    return scene_add_sphere(c->s, sp, c->err);
}

enum { PL_NORMAL, PL_OFFSET, PL_N };
static const ClassicKey plane_keys[PL_N] = {
    [PL_NORMAL] = {"normal", CK_DIR, 1}, [PL_OFFSET] = {"offset", CK_ANY, 0},
};

/* The plane dot(normal, p) = offset (normal of any length). */
static Status build_plane(Classic *c, const Token *kw, const Transform *m, const ClassicValue *v, uint material)
{
    (void)kw;
    vec3 n = v[PL_NORMAL].v;
    double n2 = (double)n.x * n.x + (double)n.y * n.y + (double)n.z * n.z;
    double k = v[PL_OFFSET].f / n2;
    vec3 q = v3((float)(n.x * k), (float)(n.y * k), (float)(n.z * k));   /* a point on it */
    double nm[3][3];
    if (!transform_normal_matrix(m, nm)) return error_set(c->err, ST_INTERNAL, "singular transform");
    vec3 nw = normal_apply(nm, n), qw = transform_point(m, q);
    if (v3_is_zero(nw)) return lex_error_at(&c->lx, &v[PL_NORMAL].key, c->err, "the plane's normal is too long");
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = nw;
    pl.offset = (float)((double)nw.x * qw.x + (double)nw.y * qw.y + (double)nw.z * qw.z);
    pl.material = material;
    return scene_add_plane(c->s, pl, c->err);
}

enum { TRI_V0, TRI_V1, TRI_V2, TRI_N };
static const ClassicKey triangle_keys[TRI_N] = {
    [TRI_V0] = {"vertex0", CK_VEC3, 1}, [TRI_V1] = {"vertex1", CK_VEC3, 1}, [TRI_V2] = {"vertex2", CK_VEC3, 1},
};

static Status build_triangle(Classic *c, const Token *kw, const Transform *m, const ClassicValue *v,
                             uint material)
{
    (void)kw;
    vec3 a = transform_point(m, v[TRI_V0].v), b = transform_point(m, v[TRI_V1].v), d = transform_point(m, v[TRI_V2].v);
    /* a mirroring transform turns the winding around; keep the outward side outward */
    return transform_det(m) < 0.0 ? add_tri(c, a, d, b, material, NO_INDEX) : add_tri(c, a, b, d, material, NO_INDEX);
}

enum { MESH_FILE, MESH_N };
static const ClassicKey mesh_keys[MESH_N] = { [MESH_FILE] = {"obj_file", CK_PATH, 1} };

/* Loads the OBJ at `path` into the scene: under m when `object` is NULL, else once
 * untransformed into a new object named `name` (*object receives it). */
static Status load_mesh(Classic *c, const Token *kw, const ClassicValue *v, const char *path, const Transform *m,
                        uint material, const char *name, uint *object)
{
    Status st = ST_OK;
    if (object && (st = scene_object_begin(c->s, name, strlen(name), object, c->err)) == ST_INPUT)
        reader_annotate(&c->lx, kw, c->err);    /* past SCENE_MAX_OBJECTS */
    if (st) return st;
    /* the sink applies the transform as it does to a mesh of our format */
    MeshOptions o = mesh_options(material);
    if (!object) o.xf = *m;
    /* MIT Fall 2019's loader smooths a mesh's normals over shared vertex indices;
     * Tsinghua's (a sized camera) keeps one normal per face (docs/classic-format.md,
     * "Conventions") */
    o.smooth_by_index = !c->camera_sized;
    st = obj_load_with(path, c->s, &o, c->err);
    if (object) scene_object_end(c->s, *object);
    if (st == ST_IO) {
        reader_annotate(&c->lx, &v[MESH_FILE].word, c->err);
        return st;
    }
    if (st) {
        size_t len = strlen(c->err->msg);
        snprintf(c->err->msg + len, sizeof c->err->msg - len, " (in the TriangleMesh of %s:%u:%u)", c->lx.path,
                 kw->line, kw->col);
    }
    return st;
}

/* A mesh outside any Transform is read into the world as it always was. Under a
 * Transform it becomes an instance (docs/instancing.md) of one object per mesh file,
 * material and normal convention, read the first time that mesh is met: the same OBJ
 * under N transforms is stored once and placed N times. The object's name is that key,
 * so the scene's own table of objects finds it again. An instance's normals go by
 * M^-T, which keeps a mirrored mesh's outward side outward as the sink's swapped
 * corners did. */
static Status build_mesh(Classic *c, const Token *kw, const Transform *m, const ClassicValue *v, uint material)
{
    char *path;
    Status st = classic_resolve_path(c, &v[MESH_FILE].word, &path);
    if (st) return st;
    if (transform_is_identity(m)) {
        st = load_mesh(c, kw, v, path, m, material, NULL, NULL);
        free(path);
        return st;
    }
    size_t cap = strlen(path) + 64;
    char *name = malloc(cap);
    if (!name) {
        free(path);
        return error_set(c->err, ST_INTERNAL, "out of memory");
    }
    snprintf(name, cap, "TriangleMesh %s, material %u%s", path, material, c->camera_sized ? "" : ", smoothed");
    uint object = scene_find_object(c->s, name, strlen(name));
    if (object == NO_INDEX) st = load_mesh(c, kw, v, path, m, material, name, &object);
    free(name);
    free(path);
    if (st || !scene_object_prims(c->s, object)) return st;
    if ((st = scene_add_instance(c->s, object, m, NO_INDEX, c->err)) == ST_INPUT) reader_annotate(&c->lx, kw, c->err);
    return st;
}

Status classic_finish_instances(Classic *c)
{
    Scene *s = c->s;
    if (s->n_objects == 0) return ST_OK;
    /* an object placed twice is what instancing is for; when none is, the copies are
     * what the reader made before (the same corners, within rounding), and the scene
     * keeps the one-level tree and the lean kernels */
    uint8_t *placed = calloc(s->n_objects, 1);
    if (!placed) return error_set(c->err, ST_INTERNAL, "out of memory");
    int shared = 0;
    for (size_t i = 0; i < s->n_instances && !shared; i++) shared = placed[s->instance_objects[i]]++ > 0;
    free(placed);
    if (shared) return ST_OK;
    return scene_flatten_instances(s, c->err);    /* objects hold triangles alone: no refusal */
}

/* A profile curve: `{ controls [ x y z ] [ x y z ] ... }` as the Tsinghua PA2/PA3
 * starter code reads it (docs/classic-format.md, "Curves"), the keyword in kw. The
 * points go to *pts (x y z triples, malloc'd; the caller frees it) and their '[' tokens
 * to *at when not NULL (malloc'd too), for messages about one point. */
static Status parse_curve(Classic *c, const Token *kw, CurveKind kind, float **pts, Token **at, size_t *n)
{
    const char *name = kind == CURVE_BEZIER ? "BezierCurve" : "BsplineCurve";
    char what[160];
    *pts = NULL;
    if (at) *at = NULL;
    *n = 0;
    snprintf(what, sizeof what, "'{' to open the %s block", name);
    Status st = classic_expect_brace(c, TOK_LBRACE, what);
    Token t;
    if (st || (st = classic_next(c, &t))) return st;
    if (!tok_is(&t, "controls")) return classic_expected(c, &t, "'controls' (the curve's control points follow it)");
    size_t cap = 0;
    for (;;) {
        if ((st = classic_next(c, &t))) return st;
        if (t.kind == TOK_RBRACE) break;
        if (t.kind != TOK_LBRACKET) {
            if (t.kind == TOK_EOF)
                return lex_error_at(&c->lx, &t, c->err, "expected '}' to close the %s block opened at line %u, "
                                    "found end of file", name, kw->line);
            snprintf(what, sizeof what, "'[' starting a control point, or '}' closing the %s", name);
            return classic_expected(c, &t, what);
        }
        if (*n == CURVE_MAX_POINTS)
            return lex_error_at(&c->lx, &t, c->err, "the %s has more than %u control points", name,
                                CURVE_MAX_POINTS);
        if (*n == cap) {
            cap = cap ? 2 * cap : 16;
            float *grown = realloc(*pts, cap * 3 * sizeof **pts);
            Token *grown_at = at ? realloc(*at, cap * sizeof **at) : NULL;
            if (grown) *pts = grown;
            if (grown_at) *at = grown_at;
            if (!grown || (at && !grown_at)) return error_set(c->err, ST_INTERNAL, "out of memory");
        }
        if (at) (*at)[*n] = t;
        for (int k = 0; k < 3; k++)
            if ((st = classic_read_float(c, &(*pts)[3 * *n + k], NULL, "3 numbers (x y z) for the control point")))
                return st;
        if ((st = classic_expect_brace(c, TOK_RBRACKET, "']' closing the control point"))) return st;
        (*n)++;
    }
    if (*n < CURVE_MIN_POINTS)
        return lex_error_at(&c->lx, kw, c->err, "the %s has %zu control points; it needs at least %u", name, *n,
                            CURVE_MIN_POINTS);
    if (kind == CURVE_BEZIER && *n > CURVE_MAX_BEZIER_POINTS)
        return lex_error_at(&c->lx, kw, c->err, "the BezierCurve has %zu control points; at most %u are supported "
                            "(degree %u; a BsplineCurve takes any number)", *n, CURVE_MAX_BEZIER_POINTS,
                            REV_MAX_DEGREE);
    return ST_OK;
}

/* A curve on its own: read and checked, then dropped, as the course draws only surfaces. */
static Status parse_lone_curve(Classic *c, const Token *kw)
{
    float *pts;
    size_t n;
    Status st = parse_curve(c, kw, tok_is(kw, "BezierCurve") ? CURVE_BEZIER : CURVE_BSPLINE, &pts, NULL, &n);
    free(pts);
    return st;
}

/* Whether m keeps the y axis vertical and upward with a uniform scale (any turn about
 * y, or mirror through a vertical plane, maps a surface of revolution to itself): then
 * the surface stays one, with its profile scaled by *scale and its axis moved. */
static int keeps_axis(const Transform *m, double *scale)
{
    int rotates;
    if (!similarity(m, scale, &rotates)) return 0;
    const double (*a)[4] = m->m;
    return fabs(a[0][1]) <= 1e-6 * *scale && fabs(a[2][1]) <= 1e-6 * *scale && a[1][1] > 0.0;
}

/* The Bezier segments of the profile (x y pairs), its points in the xy plane checked. */
static Status revsurface_profile(Classic *c, CurveKind kind, const float *pts, const Token *at, size_t n,
                                 float **xy, unsigned *n_segments, unsigned *degree)
{
    float *flat = malloc(2 * n * sizeof *flat);
    *xy = malloc(6 * n * sizeof **xy);    /* a B-spline makes 3n - 8 pairs */
    if (!flat || !*xy) {
        free(flat);
        return error_set(c->err, ST_INTERNAL, "out of memory");
    }
    for (size_t i = 0; i < n; i++) {
        if (pts[3 * i + 2] != 0.0f) {
            free(flat);
            return lex_error_at(&c->lx, &at[i], c->err, "a RevSurface's profile lies in the xy plane, but this "
                                "control point has z = %g", (double)pts[3 * i + 2]);
        }
        flat[2 * i] = pts[3 * i];
        flat[2 * i + 1] = pts[3 * i + 1];
    }
    curve_to_segments(kind, flat, n, *xy, n_segments, degree);
    free(flat);
    return ST_OK;
}

/* Adds the surface: exact (kernels/geom/revsurface.h) when m keeps the axis vertical, else
 * as a mesh through m. */
static Status add_revsurface(Classic *c, const Token *kw, float *xy, unsigned n_segments, unsigned degree,
                             const Transform *m, uint material)
{
    double scale;
    if (keeps_axis(m, &scale)) {
        size_t np = (size_t)n_segments * degree + 1;
        for (size_t i = 0; i < np; i++) {
            xy[2 * i] = (float)(scale * xy[2 * i]);
            xy[2 * i + 1] = (float)(scale * xy[2 * i + 1] + m->m[1][3]);
        }
        RevSurface r;
        memset(&r, 0, sizeof r);
        r.material = material;
        r.axis_x = (float)m->m[0][3];
        r.axis_z = (float)m->m[2][3];
        r.n_segments = n_segments;
        r.degree = degree;
        return scene_add_revsurface(c->s, r, xy, c->err);
    }
    size_t tris = 2u * REV_MESH_STEPS * REV_MESH_AROUND * (size_t)n_segments;
    if (tris > CLPT_MAX_TESSELLATED_TRIANGLES - c->tessellated)
        return lex_error_at(&c->lx, kw, c->err, "its transform tilts this RevSurface's axis, which makes it a mesh "
                            "of %zu triangles, and the scene's meshes made from tilted surfaces would then hold "
                            "more than %u (CLPT_MAX_TESSELLATED_TRIANGLES)", tris,
                            CLPT_MAX_TESSELLATED_TRIANGLES);
    c->tessellated += tris;
    return curve_mesh_revsurface(c->s, xy, n_segments, degree, m, material, REV_MESH_STEPS, REV_MESH_AROUND,
                                 c->err);
}

/* RevSurface { profile BezierCurve { ... } } (or a BsplineCurve): the profile revolved
 * about the y axis. */
static Status parse_revsurface(Classic *c, const Token *kw, const Transform *m)
{
    Status st = classic_expect_brace(c, TOK_LBRACE, "'{' to open the RevSurface block");
    Token t, curve;
    if (st || (st = classic_next(c, &t))) return st;
    if (t.kind == TOK_RBRACE)
        return lex_error_at(&c->lx, kw, c->err, "the RevSurface block needs 'profile' (a BezierCurve or "
                            "BsplineCurve block)");
    if (!tok_is(&t, "profile")) return classic_expected(c, &t, "'profile' (a BezierCurve or BsplineCurve block follows)");
    if ((st = classic_next(c, &curve))) return st;
    if (!tok_is(&curve, "BezierCurve") && !tok_is(&curve, "BsplineCurve"))
        return classic_expected(c, &curve, "a BezierCurve or BsplineCurve block for the profile");
    CurveKind kind = tok_is(&curve, "BezierCurve") ? CURVE_BEZIER : CURVE_BSPLINE;
    float *pts, *xy = NULL;
    Token *at;
    size_t n;
    unsigned n_segments = 0, degree = 0;
    uint material;
    st = parse_curve(c, &curve, kind, &pts, &at, &n);
    if (!st) st = classic_expect_brace(c, TOK_RBRACE, "'}' closing the RevSurface (it holds one profile)");
    if (!st) st = revsurface_profile(c, kind, pts, at, n, &xy, &n_segments, &degree);
    if (!st) st = object_material(c, &material);
    if (!st) st = add_revsurface(c, kw, xy, n_segments, degree, m, material);
    free(pts);
    free(at);
    free(xy);
    return st;
}

/* Reads transformations into *m (each applied on the right: the first one listed is
 * the last applied to the object, as in the course's parser) up to the first token that
 * is not one, returned in *stop. Matrix4f and Matrix multiply on the left, as there. */
Status classic_parse_transform_ops(Classic *c, Transform *m, Token *stop)
{
    Status st;
    for (;;) {
        Token t;
        if ((st = classic_next(c, &t))) return st;
        Transform x;
        float f;
        if (tok_is(&t, "Translate") || tok_is(&t, "Scale")) {
            ClassicKey k = { tok_is(&t, "Translate") ? "Translate" : "Scale", CK_VEC3, 0 };
            ClassicValue v;
            if ((st = classic_read_value(c, &k, &v))) return st;
            x = tok_is(&t, "Translate") ? transform_translate(v.v.x, v.v.y, v.v.z)
                                         : transform_scale(v.v.x, v.v.y, v.v.z);
            *m = transform_compose(m, &x);
        } else if (tok_is(&t, "UniformScale")) {
            if ((st = classic_read_float(c, &f, NULL, "a number for 'UniformScale'"))) return st;
            x = transform_scale(f, f, f);
            *m = transform_compose(m, &x);
        } else if (tok_is(&t, "XRotate") || tok_is(&t, "YRotate") || tok_is(&t, "ZRotate")) {
            char what[64];
            snprintf(what, sizeof what, "a number of degrees for '%.*s'", (int)t.len, t.text);
            if ((st = classic_read_float(c, &f, NULL, what))) return st;
            x = transform_rotate(t.text[0] == 'X', t.text[0] == 'Y', t.text[0] == 'Z', f);
            *m = transform_compose(m, &x);
        } else if (tok_is(&t, "Rotate")) {
            float a[4];
            Token at;
            if ((st = classic_expect_brace(c, TOK_LBRACE, "'{' before Rotate's axis and degrees"))) return st;
            for (int i = 0; i < 4; i++)
                if ((st = classic_read_float(c, &a[i], &at, i < 3 ? "3 numbers (the axis) for 'Rotate'"
                                                          : "a number of degrees for 'Rotate'")))
                    return st;
            if ((st = classic_expect_brace(c, TOK_RBRACE, "'}' after Rotate's axis and degrees"))) return st;
            double len = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
            if (!(len > 0.0) || !isfinite(len))
                return lex_error_at(&c->lx, &t, c->err, "Rotate's axis must be a non-zero vector");
            x = transform_rotate(a[0], a[1], a[2], a[3]);
            *m = transform_compose(m, &x);
        } else if (tok_is(&t, "Matrix4f") || tok_is(&t, "Matrix")) {
            /* Matrix4f (2012): the numbers column by column; Matrix (2004): row by row */
            int by_column = tok_is(&t, "Matrix4f");
            if ((st = classic_expect_brace(c, TOK_LBRACE, "'{' before the matrix's 16 numbers"))) return st;
            double r[4][4];
            Token first = t;
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 4; i++) {
                    if ((st = classic_read_float(c, &f, i + j == 0 ? &first : NULL, "16 numbers for the matrix"))) return st;
                    if (by_column) r[i][j] = f;
                    else r[j][i] = f;
                }
            if ((st = classic_expect_brace(c, TOK_RBRACE, "'}' after the matrix's 16 numbers"))) return st;
            /* the kernels take spheres, planes and triangles through affine maps only */
            if (r[3][0] != 0.0 || r[3][1] != 0.0 || r[3][2] != 0.0 || r[3][3] != 1.0)
                return lex_error_at(&c->lx, &first, c->err, "the matrix's last row is %g %g %g %g; it must be "
                                    "0 0 0 1 (an affine transform)", r[3][0], r[3][1], r[3][2], r[3][3]);
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 4; j++) x.m[i][j] = r[i][j];
            *m = transform_compose(&x, m);
        } else {
            *stop = t;
            return ST_OK;
        }
    }
}

static Status parse_transform(Classic *c, const Token *kw, const Transform *parent)
{
    Status st = classic_expect_brace(c, TOK_LBRACE, "'{' to open the Transform block");
    if (st) return st;
    Transform m = transform_identity();
    Token t;
    if ((st = classic_parse_transform_ops(c, &m, &t))) return st;
    if (t.kind != TOK_WORD)
        return classic_expected(c, &t, "a transformation (Translate, Scale, UniformScale, XRotate, YRotate, ZRotate, "
                        "Rotate, Matrix4f, Matrix) or the object it applies to");
    Transform world = transform_compose(parent, &m);
    double d = transform_det(&world);
    if (!(fabs(d) > 1e-30) || !isfinite(d))
        return lex_error_at(&c->lx, kw, c->err, "the Transform is singular (it flattens its object)");
    if ((st = classic_parse_object(c, &t, &world))) return st;
    return classic_expect_brace(c, TOK_RBRACE, "'}' closing the Transform (it holds one object)");
}

static Status parse_group(Classic *c, const Token *kw, const Transform *m)
{
    Status st = classic_expect_brace(c, TOK_LBRACE, "'{' to open the Group block");
    unsigned long long n;
    if (st || (st = classic_read_count(c, "numObjects", &n))) return st;
    for (unsigned long long count = 0;;) {
        Token t;
        if ((st = classic_next(c, &t))) return st;
        if (t.kind == TOK_RBRACE && count == n) return ST_OK;
        if (t.kind == TOK_EOF)
            return lex_error_at(&c->lx, &t, c->err, "expected '}' to close the Group block opened at line %u, "
                                "found end of file", kw->line);
        if (t.kind == TOK_RBRACE)
            return lex_error_at(&c->lx, &t, c->err, "the Group at line %u declares numObjects %llu but has %llu",
                                kw->line, n, count);
        if (tok_is(&t, "MaterialIndex")) {
            Token nt;
            unsigned long long u;
            if ((st = classic_next(c, &nt))) return st;
            if (tok_uint(&nt, &u) || u >= c->n_materials) {
                char what[128];
                if (c->n_materials == 0)
                    snprintf(what, sizeof what, "a material index, but no materials are defined before it");
                else
                    snprintf(what, sizeof what, "a material index in 0..%u", c->n_materials - 1);
                return classic_expected(c, &nt, what);
            }
            c->current = c->first_material + (uint)u;
            continue;
        }
        if (count == n) {
            char what[96];
            snprintf(what, sizeof what, "'}' closing the Group (numObjects %llu)", n);
            return classic_expected(c, &t, what);
        }
        if ((st = classic_parse_object(c, &t, m))) return st;
        count++;
    }
}

/* Group and Transform recurse: a limit on their nesting keeps the stack bounded. */
static Status enter_block(Classic *c, const Token *kw)
{
    if (c->depth >= CLPT_MAX_NESTING)
        return lex_error_at(&c->lx, kw, c->err, "Group and Transform blocks nested more than %d deep",
                            CLPT_MAX_NESTING);
    c->depth++;
    return ST_OK;
}

/* The objects that are one block of keys: read by read_object, then built. */
typedef Status (*ObjectBuild)(Classic *c, const Token *kw, const Transform *m, const ClassicValue *v, uint material);
static const struct {
    const char *name;
    const ClassicKey *keys;
    size_t n_keys;
    ObjectBuild build;
} keyed_objects[] = {
    {"Sphere", sphere_keys, SPH_N, build_sphere},
    {"Plane", plane_keys, PL_N, build_plane},
    {"Triangle", triangle_keys, TRI_N, build_triangle},
    {"TriangleMesh", mesh_keys, MESH_N, build_mesh},
};
enum { OBJECT_MAX_KEYS = 3 };
_Static_assert((int)SPH_N <= (int)OBJECT_MAX_KEYS && (int)PL_N <= (int)OBJECT_MAX_KEYS &&
               (int)TRI_N <= (int)OBJECT_MAX_KEYS && (int)MESH_N <= (int)OBJECT_MAX_KEYS,
               "keyed_objects: a block with more keys than OBJECT_MAX_KEYS");

Status classic_parse_object(Classic *c, const Token *kw, const Transform *m)
{
    if (tok_is(kw, "Group") || tok_is(kw, "Transform")) {
        Status st = enter_block(c, kw);
        if (st) return st;
        st = tok_is(kw, "Group") ? parse_group(c, kw, m) : parse_transform(c, kw, m);
        c->depth--;
        return st;
    }
    for (size_t i = 0; i < sizeof keyed_objects / sizeof keyed_objects[0]; i++)
        if (tok_is(kw, keyed_objects[i].name)) {
            ClassicValue v[OBJECT_MAX_KEYS];
            uint material;
            Status st = read_object(c, kw, keyed_objects[i].name, keyed_objects[i].keys, keyed_objects[i].n_keys, v,
                                    &material);
            return st ? st : keyed_objects[i].build(c, kw, m, v, material);
        }
    if (tok_is(kw, "RevSurface")) return parse_revsurface(c, kw, m);
    if (tok_is(kw, "BezierCurve") || tok_is(kw, "BsplineCurve")) return parse_lone_curve(c, kw);
    return classic_expected(c, kw, "an object (Group, Sphere, Plane, Triangle, TriangleMesh, Transform, RevSurface, "
                    "BezierCurve, BsplineCurve) or MaterialIndex");
}
