/* gltf_scene.c — the glTF scene: primitives, nodes, cameras, lights (gltf_reader.h). */
#include "io/gltf_reader.h"

#include "base/bytes.h"
#include "base/limit.h"
#include "base/strmap.h"
#include "io/lexer.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "scene/instance.h"
#include "scene/motion.h"
#include "util/kmath.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cjson/cJSON.h>


/* ------------------------------------------------------------------ primitives */

static Status corner_indices(Gltf *g, const cJSON *prim, const char *jp, size_t n_vertices, uint32_t **idx,
                             size_t *n)
{
    int ai;
    Status st = gltf_get_index(g, prim, "indices", 0, "accessors", jp, &ai);
    if (st) return st;
    *idx = malloc((ai < 0 ? n_vertices : 1) * sizeof **idx);
    if (ai < 0) {
        if (!*idx) return error_set(g->err, ST_INTERNAL, "out of memory");
        for (size_t i = 0; i < n_vertices; i++) (*idx)[i] = (uint32_t)i;
        *n = n_vertices;
        return ST_OK;
    }
    free(*idx);
    *idx = NULL;
    char use[120];
    snprintf(use, sizeof use, "%s.indices", jp);
    double *d;
    if ((st = gltf_acc_read(g, ai, 1, use, &d, n))) return st;
    *idx = malloc(*n * sizeof **idx);
    if (!*idx) {
        free(d);
        return error_set(g->err, ST_INTERNAL, "out of memory");
    }
    for (size_t i = 0; i < *n; i++) {
        if (!(d[i] >= 0 && d[i] < (double)n_vertices)) {
            st = error_set(g->err, ST_INPUT, "%s: %s: index %zu is %.0f, past the %zu vertices", g->path, use, i, d[i],
                           n_vertices);
            break;
        }
        (*idx)[i] = (uint32_t)d[i];
    }
    free(d);
    if (st) {
        free(*idx);
        *idx = NULL;
    }
    return st;
}

/* attributes.name as `width`-wide elements (or `width2`-wide, 0: only width; *got says
 * which), as many as POSITION's n_vertices; *out NULL when the primitive lacks it. */
static Status attr_read(Gltf *g, const cJSON *attrs, const char *name, int width, int width2, const char *jp,
                        size_t n_vertices, double **out, int *got)
{
    *out = NULL;
    char use[140];
    snprintf(use, sizeof use, "%s.attributes.%s", jp, name);
    int ai;
    Status st = gltf_get_index(g, attrs, name, 0, "accessors", use, &ai);
    if (st || ai < 0) return st;
    if (strcmp(name, "COLOR_0") == 0) {
        /* glTF 2.0, 3.7.2.1: float, or normalized unsigned byte or short */
        const cJSON *acc = gltf_item_at(g, "accessors", ai);
        const cJSON *ct = cJSON_GetObjectItemCaseSensitive(acc, "componentType");
        double c = cJSON_IsNumber(ct) ? ct->valuedouble : 0;
        int norm = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(acc, "normalized"));
        if (!(c == 5126 || ((c == 5121 || c == 5123) && norm)))
            return error_set(g->err, ST_INPUT, "%s: %s: accessor %d: componentType must be 5126 (float), or 5121 "
                             "or 5123 (unsigned byte or short) with normalized true", g->path, use, ai);
    }
    size_t n;
    if ((st = gltf_acc_read_either(g, ai, width, width2, use, out, &n, got))) return st;
    if (n_vertices && n != n_vertices) {
        free(*out);
        *out = NULL;
        return error_set(g->err, ST_INPUT, "%s: %s: accessor %d has %zu elements, POSITION has %zu", g->path, use, ai,
                         n, n_vertices);
    }
    return ST_OK;
}

/* A primitive's vertex attributes, as doubles per vertex (NULL when absent). */
typedef struct {
    double *pos, *nrm, *uv;
    double *tan, *uv1, *col;    /* TANGENT (4 wide), TEXCOORD_1, COLOR_0 (col_width wide) */
    int col_width;
} Attrs;

static void attrs_free(Attrs *a)
{
    free(a->pos);
    free(a->nrm);
    free(a->uv);
    free(a->tan);
    free(a->uv1);
    free(a->col);
}

/* A glTF uv as clpt's: glTF's v runs down the image, clpt's (as OBJ's) up. */
static void uv_flip(const double *uv, float *out)
{
    out[0] = (float)uv[0];
    out[1] = (float)(1.0 - uv[1]);
}

/* One triangle of vertices a, b, c. */
static Status emit(MeshSink *k, const Attrs *at, uint32_t a, uint32_t b, uint32_t c, uint mat)
{
    const uint32_t v[3] = { a, b, c };
    vec3 p[3], n[3];
    float t[6];
    TriExtra e;
    memset(&e, 0, sizeof e);
    e.flags = (at->tan ? EXTRA_TANGENT : 0u) | (at->uv1 ? EXTRA_UV1 : 0u) | (at->col ? EXTRA_COLOR : 0u);
    int normals_ok = at->nrm != NULL, uv_ok = at->uv != NULL;
    for (int i = 0; i < 3; i++) {
        size_t vi = v[i];
        const double *q = at->pos + 3 * vi;
        p[i] = v3((float)q[0], (float)q[1], (float)q[2]);
        if (at->nrm) {
            const double *m = at->nrm + 3 * vi;
            double l = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
            if (!(l > 0) || !isfinite(l)) normals_ok = 0;
            else n[i] = v3((float)(m[0] / l), (float)(m[1] / l), (float)(m[2] / l));
        }
        if (at->uv) {
            uv_flip(at->uv + 2 * vi, t + 2 * i);
            if (!isfinite(t[2 * i]) || !isfinite(t[2 * i + 1])) uv_ok = 0;
        }
        /* the sink checks these for finiteness and transforms the tangents */
        for (int j = 0; at->tan && j < 4; j++) e.tangent[i][j] = (float)at->tan[4 * vi + (size_t)j];
        if (at->uv1) uv_flip(at->uv1 + 2 * vi, e.uv[i]);
        for (int j = 0; at->col && j < 4; j++)
            e.color[i][j] = j < at->col_width ? (float)at->col[(size_t)at->col_width * vi + (size_t)j] : 1.0f;
    }
    return mesh_sink_triangle_extra(k, p, normals_ok ? n : NULL, uv_ok ? t : NULL, e.flags ? &e : NULL, mat);
}

/* Counts the `n` triangles a primitive is about to make (reached through node `node`)
 * against the file's bound, before any is made. */
static Status triangles_count(Gltf *g, size_t n, const char *node, const char *jp)
{
    if (n <= g->max_triangles - g->triangles) {
        g->triangles += n;
        return ST_OK;
    }
    return error_set(g->err, ST_INPUT, "%s: %s (in %s): its %zu triangles bring the file's to %llu, more than the %zu "
                     "a file of its size may make (2^20 and one per byte of the file and its buffers, at most 2^26; "
                     "every node's copy counts)", g->path, jp, node, n,
                     (unsigned long long)g->triangles + n, g->max_triangles);
}

static Status primitive_load(Gltf *g, MeshSink *k, const cJSON *prim, const char *jp, const char *node)
{
    long long mode;
    Status st = gltf_get_int(g, prim, "mode", 4, 0, 6, jp, &mode);
    if (st) return st;
    if (mode < 4)
        return scene_warn(g->s, g->err, "%s: %s: mode %lld (points or lines) is not drawn", g->path, jp, mode);
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    if (!cJSON_IsObject(attrs)) return gltf_bad(g, jp, "attributes: expected an object");
    if (!cJSON_GetObjectItemCaseSensitive(attrs, "POSITION")) return gltf_bad(g, jp, "attributes.POSITION: missing");
    Attrs at;
    memset(&at, 0, sizeof at);
    uint32_t *idx = NULL;
    size_t nv = 0, ni = 0;
    char use[140];
    snprintf(use, sizeof use, "%s.attributes.POSITION", jp);
    int pa, w;
    if ((st = gltf_get_index(g, attrs, "POSITION", 1, "accessors", use, &pa))) return st;
    if ((st = gltf_acc_read(g, pa, 3, use, &at.pos, &nv))) return st;
    uint mat;
    int mi;
    if (!(st = attr_read(g, attrs, "NORMAL", 3, 0, jp, nv, &at.nrm, &w)) &&
        !(st = attr_read(g, attrs, "TEXCOORD_0", 2, 0, jp, nv, &at.uv, &w)) &&
        !(st = attr_read(g, attrs, "TANGENT", 4, 0, jp, nv, &at.tan, &w)) &&
        !(st = attr_read(g, attrs, "TEXCOORD_1", 2, 0, jp, nv, &at.uv1, &w)) &&
        !(st = attr_read(g, attrs, "COLOR_0", 3, 4, jp, nv, &at.col, &at.col_width)) &&
        !(st = corner_indices(g, prim, jp, nv, &idx, &ni)) &&
        !(st = gltf_get_index(g, prim, "material", 0, "materials", jp, &mi)))
        st = gltf_material_get(g, mi, &mat);
    if (!st && ni >= 3) st = triangles_count(g, mode == 4 ? ni / 3 : ni - 2, node, jp);
    if (!st && mode == 4) {
        for (size_t i = 0; i + 2 < ni && !st; i += 3) st = emit(k, &at, idx[i], idx[i + 1], idx[i + 2], mat);
    } else if (!st && mode == 5) {
        /* every other triangle of a strip swaps its first two corners to keep the winding */
        for (size_t i = 0; i + 2 < ni && !st; i++)
            st = i % 2 ? emit(k, &at, idx[i + 1], idx[i], idx[i + 2], mat)
                       : emit(k, &at, idx[i], idx[i + 1], idx[i + 2], mat);
    } else if (!st) {
        for (size_t i = 0; i + 2 < ni && !st; i++) st = emit(k, &at, idx[i + 1], idx[i + 2], idx[0], mat);
    }
    attrs_free(&at);
    free(idx);
    return st;
}

static Status mesh_instance(Gltf *g, int mesh, const Transform *xf, const char *node)
{
    char jp[64];
    snprintf(jp, sizeof jp, "meshes[%d]", mesh);
    const cJSON *prims = cJSON_GetObjectItemCaseSensitive(gltf_item_at(g, "meshes", mesh), "primitives");
    if (!cJSON_IsArray(prims)) return gltf_bad(g, jp, "primitives: expected an array");
    MeshSink k;
    Status st = mesh_sink_open(&k, g->s, xf, g->path, g->err);
    int i = 0;
    for (const cJSON *p = gltf_first_of(prims); !st && p; p = p->next, i++) {
        char jpp[96];
        snprintf(jpp, sizeof jpp, "%s.primitives[%d]", jp, i);
        st = primitive_load(g, &k, p, jpp, node);
    }
    return st;
}

/* ------------------------------------------------------------------ nodes */

/* T . R . S (glTF 2.0, 3.5.3): translation t, unit-normalised quaternion q (x, y, z, w),
 * scale s; NULL t or s: none. q must not be zero. */
static void trs_matrix(const double *t, const double *q, const double *s, Transform *out)
{
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    double x = q[0] / l, y = q[1] / l, z = q[2] / l, w = q[3] / l;
    const double r[3][3] = {
        { 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w) },
        { 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w) },
        { 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y) },
    };
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) out->m[i][j] = r[i][j] * (s ? s[j] : 1.0);
        out->m[i][3] = t ? t[i] : 0.0;
    }
}

Status gltf_node_local(Gltf *g, int n, Transform *out)
{
    char jp[64];
    snprintf(jp, sizeof jp, "nodes[%d]", n);
    const cJSON *node = gltf_item_at(g, "nodes", n);
    double m[16];
    static const double ident[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
    static const double t0[3] = { 0, 0, 0 }, r0[4] = { 0, 0, 0, 1 }, s0[3] = { 1, 1, 1 };
    Status st;
    /* an animated node has no matrix (gltf_anim.c refuses one) */
    if (cJSON_GetObjectItemCaseSensitive(node, "matrix")) {
        if ((st = gltf_get_nums(g, node, "matrix", 16, ident, jp, m))) return st;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++) out->m[r][c] = m[4 * c + r];   /* column-major */
        return ST_OK;
    }
    double t[3], q[4], sc[3];
    if ((st = gltf_get_nums(g, node, "translation", 3, t0, jp, t)) || (st = gltf_get_nums(g, node, "rotation", 4, r0, jp, q)) ||
        (st = gltf_get_nums(g, node, "scale", 3, s0, jp, sc)))
        return st;
    const GltfNodePose *p = g->pose ? &g->pose[n] : NULL;
    if (p && (p->animated & GLTF_ANIM_T)) memcpy(t, p->t, sizeof t);
    if (p && (p->animated & GLTF_ANIM_R)) memcpy(q, p->r, sizeof q);
    if (p && (p->animated & GLTF_ANIM_S)) memcpy(sc, p->s, sizeof sc);
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(l > 0)) return gltf_bad(g, jp, p && (p->animated & GLTF_ANIM_R) ? "rotation: the animation makes a zero "
                                  "quaternion" : "rotation: a zero quaternion");
    trs_matrix(t, q, sc, out);
    return ST_OK;
}

static vec3 xf_dir(const Transform *t, double x, double y, double z)
{
    double v[3];
    for (int i = 0; i < 3; i++) v[i] = t->m[i][0] * x + t->m[i][1] * y + t->m[i][2] * z;
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(l > 0)) l = 1;
    return v3((float)(v[0] / l), (float)(v[1] / l), (float)(v[2] / l));
}

static int camera_wanted(const Gltf *g, int cam, const cJSON *node)
{
    const char *want = g->view->camera;
    if (!want) return !g->view->has_camera;
    char *end;
    long v = strtol(want, &end, 10);
    if (*want && !*end) return v == cam;
    const cJSON *cn = cJSON_GetObjectItemCaseSensitive(gltf_item_at(g, "cameras", cam), "name");
    const cJSON *nn = cJSON_GetObjectItemCaseSensitive(node, "name");
    return (cJSON_IsString(cn) && strcmp(cn->valuestring, want) == 0) ||
           (cJSON_IsString(nn) && strcmp(nn->valuestring, want) == 0);
}

void gltf_camera_frame(const Transform *xf, vec3 *from, vec3 *at, vec3 *up)
{
    *from = transform_point(xf, v3(0.0f, 0.0f, 0.0f));
    vec3 fwd = xf_dir(xf, 0, 0, -1);
    *at = v3(from->x + fwd.x, from->y + fwd.y, from->z + fwd.z);
    *up = xf_dir(xf, 0, 1, 0);
}

Status gltf_camera_set(Gltf *g, int cam, const Transform *xf)
{
    char jp[64];
    snprintf(jp, sizeof jp, "cameras[%d]", cam);
    const cJSON *c = gltf_item_at(g, "cameras", cam);
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(c, "type");
    SceneCamera *sc = &g->s->camera;
    int ortho = cJSON_IsString(type) && strcmp(type->valuestring, "orthographic") == 0;
    double aspect = 0, v;
    Status st;
    if (ortho) {
        const cJSON *o = cJSON_GetObjectItemCaseSensitive(c, "orthographic");
        if ((st = gltf_get_num(g, o, "ymag", 1.0, 1e-30, 1e30, jp, &v))) return st;
        sc->type = CAMERA_ORTHOGRAPHIC;
        sc->ortho_height = (float)(2.0 * v);
        double xmag;
        if ((st = gltf_get_num(g, o, "xmag", 0.0, 0.0, 1e30, jp, &xmag))) return st;
        aspect = xmag > 0 ? xmag / v : 0;
    } else {
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(c, "perspective");
        if (!cJSON_IsObject(p)) return gltf_bad(g, jp, "perspective: expected an object");
        if ((st = gltf_get_num(g, p, "yfov", -1.0, 1e-6, 3.14, jp, &v))) return st;
        if (v < 0) return gltf_bad(g, jp, "perspective.yfov: missing (required)");
        if ((st = gltf_get_num(g, p, "aspectRatio", 0.0, 1e-3, 1e3, jp, &aspect))) return st;
        sc->type = CAMERA_PERSPECTIVE;
        sc->vfov = (float)(v * 180.0 / M_PI);
    }
    gltf_camera_frame(xf, &sc->from, &sc->at, &sc->up);
    sc->aperture = 0.0f;
    sc->focus_dist = 0.0f;
    if (!isfinite(sc->from.x) || !isfinite(sc->from.y) || !isfinite(sc->from.z) || !isfinite(sc->at.x) ||
        !isfinite(sc->at.y) || !isfinite(sc->at.z))
        return gltf_bad(g, jp, "its node puts the camera beyond the float range");
    if (aspect > 0) {
        double h = floor(g->s->image.width / aspect + 0.5);
        g->s->image.height = (uint)fmax(1.0, fmin(h, (double)CLPT_MAX_IMAGE_SIDE));
    }
    g->view->has_camera = 1;
    return ST_OK;
}

static Status light_add(Gltf *g, int li, const Transform *xf, const char *jp)
{
    const cJSON *l = gltf_item_at(g, "lights", li);
    if (li < 0 || !l) return gltf_bad(g, jp, "KHR_lights_punctual.light names no light of the file's extensions");
    char jl[80];
    snprintf(jl, sizeof jl, "extensions.KHR_lights_punctual.lights[%d]", li);
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(l, "type");
    const char *t = cJSON_IsString(type) ? type->valuestring : "";
    static const double white[3] = { 1, 1, 1 };
    double color[3], intensity;
    Status st = gltf_get_nums(g, l, "color", 3, white, jl, color);
    if (!st) st = gltf_get_num(g, l, "intensity", 1.0, 0.0, 1e30, jl, &intensity);
    if (st) return st;
    uint lt = strcmp(t, "point") == 0 ? LIGHT_POINT : strcmp(t, "spot") == 0 ? LIGHT_SPOT
            : strcmp(t, "directional") == 0 ? LIGHT_DIRECTIONAL : NO_INDEX;
    if (lt == NO_INDEX) return gltf_bad(g, jl, "type: expected point, spot or directional");
    Light L = light_default(lt);
    Transform w = transform_compose(&g->o->xf, xf);
    L.position = transform_point(&w, v3(0.0f, 0.0f, 0.0f));
    L.direction = xf_dir(&w, 0, 0, -1);
    if (!isfinite(L.position.x) || !isfinite(L.position.y) || !isfinite(L.position.z))
        return gltf_bad(g, jp, "its transform puts the light beyond the float range");
    double k = intensity / LUMENS_PER_WATT;
    L.intensity = v3((float)(color[0] * k), (float)(color[1] * k), (float)(color[2] * k));
    if (lt == LIGHT_SPOT) {
        const cJSON *sp = cJSON_GetObjectItemCaseSensitive(l, "spot");
        double inner, outer;
        if ((st = gltf_get_num(g, sp, "innerConeAngle", 0.0, 0.0, M_PI / 2, jl, &inner)) ||
            (st = gltf_get_num(g, sp, "outerConeAngle", M_PI / 4, 0.0, M_PI / 2, jl, &outer)))
            return st;
        L.cos_outer = (float)cos(outer);
        L.cos_inner = (float)cos(fmin(inner, outer));
        L.spot_falloff = SPOT_GLTF;
    }
    g->has_lights = 1;
    return scene_add_light(g->s, L, g->err);
}

/* ------------------------------------------------------------------ instances */

static int placed_grow(Gltf *g)
{
    if (g->n_placed < g->cap_placed) return 0;
    size_t cap = g->cap_placed ? 2 * g->cap_placed : 16;
    GltfPlacement *p = realloc(g->placed, cap * sizeof *p);
    if (!p) return -1;
    g->placed = p;
    g->cap_placed = cap;
    return 0;
}

/* What a mesh used more than once became: not yet seen, or a scene object; MESH_COPIES
 * asks place() and gpu_instances() for copies (a mesh placed once). */
#define MESH_UNSEEN NO_INDEX
#define MESH_COPIES (NO_INDEX - 1u)

/* Mesh `mesh` made once as a scene object in its own space (*out); an object of no
 * triangles is made and never placed. A mesh that emits is an object too: glTF's
 * emitters are triangles, which are lights under every instance (LIGHT_INSTANCED,
 * docs/instancing.md), so no transform needs a copy. */
static Status mesh_object(Gltf *g, int mesh, const char *node, uint *out)
{
    char jp[64], name[600];
    snprintf(jp, sizeof jp, "meshes[%d]", mesh);
    snprintf(name, sizeof name, "%.500s:%s", g->path, jp);
    Status st = scene_object_begin(g->s, name, strlen(name), out, g->err);
    if (st) return st;
    const Transform id = transform_identity();
    st = mesh_instance(g, mesh, &id, node);
    scene_object_end(g->s, *out);
    return st;
}

/* The error of a scene call (no location) put under the JSON path jp. */
static Status scene_error_at(Gltf *g, Status st, const char *jp)
{
    if (st != ST_INPUT) return st;
    char msg[sizeof g->err->msg];
    snprintf(msg, sizeof msg, "%s", g->err->msg);
    return gltf_bad(g, jp, msg);
}

/* The keys of the instance just placed for node pl->node, which moves over the
 * shutter: its world transform at each time after the open, times `local` (an
 * EXT_mesh_gpu_instancing entry's; NULL: none), as the walk composed w. */
static Status place_keys(Gltf *g, const GltfPlacement *pl, const Transform *local, const char *jp)
{
    const GltfBlur *b = g->blur;
    Status st = ST_OK;
    for (size_t k = 1; k < b->n_times && !st; k++) {
        Transform w;
        if ((st = b->world_at(b->ctx, pl->node, b->times[k], &w, g->err))) return st;
        if (local) w = transform_compose(&w, local);
        st = scene_add_instance_key(g->s, (float)b->times[0], (float)b->times[k], &w, g->err);
        if (st == ST_INPUT) {
            char at[200];
            snprintf(at, sizeof at, "%s (at %g s of the shutter)", jp, b->times[k]);
            return scene_error_at(g, st, at);
        }
    }
    return st;
}

/* One instance of `object` (or a copy of mesh `mesh`) under w; a singular w (a scale
 * of 0 that hides a node) places nothing and is counted for one warning. A node that
 * moves over the shutter (pl given, g->blur) gets its keys. */
static Status place(Gltf *g, int mesh, uint object, const Transform *w, const GltfPlacement *pl,
                    const Transform *local, const char *jp)
{
    if (object == MESH_COPIES) return mesh_instance(g, mesh, w, jp);
    if (scene_object_prims(g->s, object) == 0) return ST_OK;
    Transform inv;
    if (!transform_invert(w, &inv)) {
        g->singular++;
        return ST_OK;
    }
    Status st = scene_error_at(g, scene_add_instance(g->s, object, w, NO_INDEX, g->err), jp);
    if (!st && pl && g->blur && g->blur->moves[pl->node]) st = place_keys(g, pl, local, jp);
    return st;
}

/* One EXT_mesh_gpu_instancing attribute: `width` floats per instance (ROTATION also
 * normalized bytes or shorts), as many as the others (*count, 0 until one is read). */
static Status gpu_attribute(Gltf *g, const cJSON *attrs, const char *name, int width, const char *jp, double **out,
                            size_t *count)
{
    *out = NULL;
    char use[200], at[180];
    snprintf(at, sizeof at, "%s.attributes", jp);
    snprintf(use, sizeof use, "%s.%s", at, name);
    int ai;
    Status st = gltf_get_index(g, attrs, name, 0, "accessors", at, &ai);
    if (st || ai < 0) return st;
    const cJSON *acc = gltf_item_at(g, "accessors", ai);
    const cJSON *ct = cJSON_GetObjectItemCaseSensitive(acc, "componentType");
    double c = cJSON_IsNumber(ct) ? ct->valuedouble : 0;
    int norm = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(acc, "normalized"));
    int rotation = width == 4;
    if (!(c == 5126 || (rotation && (c == 5120 || c == 5122) && norm)))
        return error_set(g->err, ST_INPUT, "%s: %s: accessor %d: componentType must be 5126 (float)%s", g->path, use,
                         ai, rotation ? ", or 5120 or 5122 (byte or short) with normalized true" : "");
    size_t n;
    if ((st = gltf_acc_read(g, ai, width, use, out, &n))) return st;
    if (*count && n != *count) {
        free(*out);
        *out = NULL;
        return error_set(g->err, ST_INPUT, "%s: %s: accessor %d has %zu elements, another attribute has %zu (all "
                         "must have the same count)", g->path, use, ai, n, *count);
    }
    *count = n;
    return ST_OK;
}

/* The instances of a node with EXT_mesh_gpu_instancing: node world . T . R . S of each
 * entry (the extension's "Transformation Order"; a rotation's quaternion normalised, as
 * a node's is). */
static Status gpu_instances(Gltf *g, const GltfPlacement *pl, uint object, const char *node)
{
    char jp[120];
    snprintf(jp, sizeof jp, "%s.extensions.EXT_mesh_gpu_instancing", node);
    const cJSON *ext = gltf_ext_of(gltf_item_at(g, "nodes", pl->node), "EXT_mesh_gpu_instancing");
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(ext, "attributes");
    if (!cJSON_IsObject(attrs)) return gltf_bad(g, jp, "attributes: expected an object");
    double *tr = NULL, *rot = NULL, *sc = NULL;
    size_t n = 0;
    Status st = gpu_attribute(g, attrs, "TRANSLATION", 3, jp, &tr, &n);
    if (!st) st = gpu_attribute(g, attrs, "ROTATION", 4, jp, &rot, &n);
    if (!st) st = gpu_attribute(g, attrs, "SCALE", 3, jp, &sc, &n);
    if (!st && n == 0) st = gltf_bad(g, jp, "attributes: none of TRANSLATION, ROTATION, SCALE");
    for (size_t i = 0; i < n && !st; i++) {
        char ji[160];
        snprintf(ji, sizeof ji, "%s (instance %zu)", jp, i);
        double q[4] = { 0, 0, 0, 1 };
        if (rot) memcpy(q, rot + 4 * i, sizeof q);
        double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (!(l > 0)) {
            st = gltf_bad(g, ji, "ROTATION: a zero quaternion");
            break;
        }
        Transform local;
        trs_matrix(tr ? tr + 3 * i : NULL, q, sc ? sc + 3 * i : NULL, &local);
        Transform w = transform_compose(&pl->w, &local);
        st = place(g, pl->mesh, object, &w, pl, &local, ji);
    }
    free(tr);
    free(rot);
    free(sc);
    return st;
}

/* The meshes the node walk placed, in its order. */
static Status meshes_place(Gltf *g)
{
    int n_meshes = g->t[T_MESHES].n;
    unsigned *uses = calloc((size_t)n_meshes + 1, sizeof *uses);
    uint *made = malloc(((size_t)n_meshes + 1) * sizeof *made);
    if (!uses || !made) {
        free(uses);
        free(made);
        return error_set(g->err, ST_INTERNAL, "out of memory");
    }
    for (int m = 0; m < n_meshes; m++) made[m] = MESH_UNSEEN;
    /* a node with EXT_mesh_gpu_instancing places its mesh many times */
    for (size_t i = 0; i < g->n_placed; i++) uses[g->placed[i].mesh] += g->placed[i].gpu_instanced ? 2u : 1u;
    Status st = ST_OK;
    for (size_t i = 0; i < g->n_placed && !st; i++) {
        const GltfPlacement *pl = &g->placed[i];
        char jp[64];
        snprintf(jp, sizeof jp, "nodes[%d]", pl->node);
        /* a mesh that moves over the shutter is an instance even when used once:
         * copies cannot move */
        int moves = g->blur && g->blur->moves[pl->node];
        if ((uses[pl->mesh] < 2 && !moves) || g->o->no_instances) {
            if (pl->gpu_instanced) st = gpu_instances(g, pl, MESH_COPIES, jp);
            else st = mesh_instance(g, pl->mesh, &pl->w, jp);
            continue;
        }
        if (made[pl->mesh] == MESH_UNSEEN && (st = mesh_object(g, pl->mesh, jp, &made[pl->mesh]))) break;
        st = pl->gpu_instanced ? gpu_instances(g, pl, made[pl->mesh], jp)
                               : place(g, pl->mesh, made[pl->mesh], &pl->w, pl, NULL, jp);
    }
    free(uses);
    free(made);
    if (!st && g->singular)
        st = scene_warn(g->s, g->err, "%s: mesh instances under a singular transform (a scale of 0) are skipped: %zu",
                        g->path, g->singular);
    return st;
}

static Status node_visit(Gltf *g, int n, const Transform *parent, int depth)
{
    char jp[64];
    snprintf(jp, sizeof jp, "nodes[%d]", n);
    if (g->visited[n]) return gltf_bad(g, jp, "reached twice in the node tree (a node has one parent, no cycles)");
    if (depth > CLPT_MAX_NESTING) return gltf_bad(g, jp, "the node tree is nested too deep");
    g->visited[n] = 1;
    const cJSON *node = gltf_item_at(g, "nodes", n);
    Transform local, xf;
    Status st = gltf_node_local(g, n, &local);
    if (st) return st;
    xf = transform_compose(parent, &local);
    int mesh, cam;
    if ((st = gltf_get_index(g, node, "mesh", 0, "meshes", jp, &mesh))) return st;
    if ((st = gltf_get_index(g, node, "camera", 0, "cameras", jp, &cam))) return st;
    const cJSON *gpu = gltf_ext_of(node, "EXT_mesh_gpu_instancing");
    if (mesh >= 0) {
        if (placed_grow(g)) return error_set(g->err, ST_INTERNAL, "out of memory");
        GltfPlacement *pl = &g->placed[g->n_placed++];
        pl->mesh = mesh;
        pl->node = n;
        pl->gpu_instanced = gpu != NULL;
        pl->w = transform_compose(&g->o->xf, &xf);
    } else if (gpu && (st = scene_warn(g->s, g->err, "%s: %s.extensions.EXT_mesh_gpu_instancing: the node has no "
                                       "mesh; ignored", g->path, jp))) {
        return st;
    }
    if (cam >= 0 && g->view && camera_wanted(g, cam, node)) {
        Transform w = transform_compose(&g->o->xf, &xf);
        if ((st = gltf_camera_set(g, cam, &w))) return st;
        g->camera_node = n;
        g->camera_index = cam;
    }
    const cJSON *lp = gltf_ext_of(node, "KHR_lights_punctual");
    if (lp) {
        long long li;
        if ((st = gltf_get_int(g, lp, "light", -1, 0, INT32_MAX, jp, &li)) || (st = light_add(g, (int)li, &xf, jp)))
            return st;
    }
    const cJSON *kids = cJSON_GetObjectItemCaseSensitive(node, "children");
    int i = 0;
    for (const cJSON *c = gltf_first_of(kids); c; c = c->next, i++) {
        if (!cJSON_IsNumber(c) || c->valuedouble < 0 || c->valuedouble >= g->n_nodes ||
            c->valuedouble != floor(c->valuedouble)) {
            char jc[96];
            snprintf(jc, sizeof jc, "%s.children[%d]", jp, i);
            return gltf_bad(g, jc, "not the index of a node");
        }
        if ((st = node_visit(g, (int)c->valuedouble, &xf, depth + 1))) return st;
    }
    return ST_OK;
}

Status gltf_scene_walk(Gltf *g)
{
    const Transform id = transform_identity();
    /* a walk of an animation's frame starts as the first did */
    memset(g->visited, 0, (size_t)g->n_nodes + 1);
    g->n_placed = 0;
    g->triangles = 0;
    g->singular = 0;
    if (g->view) g->view->has_camera = 0;
    int n_scenes = g->t[T_SCENES].n;
    long long sc;
    Status st = gltf_get_int(g, g->root, "scene", 0, 0, n_scenes > 0 ? n_scenes - 1 : 0, "(top level)", &sc);
    if (st) return st;
    if (n_scenes > 0) {
        char jp[64];
        snprintf(jp, sizeof jp, "scenes[%lld].nodes", sc);
        const cJSON *roots = cJSON_GetObjectItemCaseSensitive(g->t[T_SCENES].item[sc], "nodes");
        for (const cJSON *r = gltf_first_of(roots); r; r = r->next) {
            if (!cJSON_IsNumber(r) || r->valuedouble < 0 || r->valuedouble >= g->n_nodes ||
                r->valuedouble != floor(r->valuedouble))
                return gltf_bad(g, jp, "an entry is not the index of a node");
            if ((st = node_visit(g, (int)r->valuedouble, &id, 0))) return st;
        }
        return meshes_place(g);
    }
    /* no scenes: every node that is no other node's child is a root */
    unsigned char *child = calloc((size_t)g->n_nodes + 1, 1);
    if (!child) return error_set(g->err, ST_INTERNAL, "out of memory");
    for (int n = 0; n < g->n_nodes; n++) {
        const cJSON *kids = cJSON_GetObjectItemCaseSensitive(gltf_item_at(g, "nodes", n), "children");
        for (const cJSON *c = gltf_first_of(kids); c; c = c->next) {
            if (cJSON_IsNumber(c) && c->valuedouble >= 0 && c->valuedouble < g->n_nodes) child[(int)c->valuedouble] = 1;
        }
    }
    for (int n = 0; n < g->n_nodes && !st; n++)
        if (!child[n]) st = node_visit(g, n, &id, 0);
    free(child);
    return st ? st : meshes_place(g);
}
