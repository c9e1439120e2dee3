/* mesh_sink.c — mesh options, the triangle sink, bounds, the procedural sphere (mesh_sink.h). */
#include "scene/mesh_sink.h"

#include "base/array.h"
#include "util/kmath.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

MeshOptions mesh_options(uint material)
{
    MeshOptions o;
    o.material = material;
    o.default_material = NO_INDEX;
    o.xf = transform_identity();
    o.smooth_by_index = 0;
    o.no_instances = 0;
    return o;
}

Status mesh_default_material(Scene *s, uint *material, Error *err)
{
    if (*material != NO_INDEX) return ST_OK;
    return scene_add_material(s, "", material_diffuse(v3s(MESH_DEFAULT_ALBEDO)), material, err);
}

/* ------------------------------------------------------------------ the sink */

Status mesh_sink_open(MeshSink *k, Scene *s, const Transform *xf, const char *path, Error *err)
{
    memset(k, 0, sizeof *k);
    k->s = s;
    k->err = err;
    k->path = path;
    k->xf = xf ? *xf : transform_identity();
    k->first_triangle = s->n_triangles;
    k->transformed = !transform_is_identity(&k->xf);
    if (!k->transformed) return ST_OK;
    double det = transform_det(&k->xf);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            if (!isfinite(k->xf.m[i][j]))
                return error_set(err, ST_INPUT, "%s: the mesh transform is not finite", path);
    if (!(fabs(det) > 0.0) || !isfinite(det))
        return error_set(err, ST_INPUT, "%s: the mesh transform is singular (determinant %g)", path, det);
    transform_normal_matrix(&k->xf, k->nxf);
    k->mirrored = det < 0.0;
    return ST_OK;
}

Status mesh_sink_reserve(MeshSink *k, size_t triangles, size_t shading)
{
    Scene *s = k->s;
    if (array_reserve((void **)&s->triangles, &s->cap_triangles, s->n_triangles + triangles,
                      sizeof *s->triangles) ||
        array_reserve((void **)&s->shading, &s->cap_shading, s->n_shading + shading, sizeof *s->shading))
        return error_set(k->err, ST_INTERNAL, "out of memory for the %zu triangles of '%s'", triangles,
                         k->path);
    return ST_OK;
}

/* Unit normal of n under the transform (the sink's inverse transpose); 0 if unusable. */
static int transform_normal(const MeshSink *k, vec3 n, vec3 *out)
{
    double r[3];
    if (k->transformed) {
        for (int i = 0; i < 3; i++) r[i] = k->nxf[i][0] * n.x + k->nxf[i][1] * n.y + k->nxf[i][2] * n.z;
    } else {
        r[0] = n.x;
        r[1] = n.y;
        r[2] = n.z;
    }
    double len = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (!(len > 0.0) || !isfinite(len)) return 0;
    *out = v3((float)(r[0] / len), (float)(r[1] / len), (float)(r[2] / len));
    return !v3_is_zero(*out);
}

/* extra's attributes in the order o of the sink's corners, tangents transformed; its
 * flags cleared of what is unusable. */
static TriExtra extra_transform(const MeshSink *k, const TriExtra *in, const int *o)
{
    TriExtra e;
    memset(&e, 0, sizeof e);
    e.flags = in->flags;
    for (int i = 0; i < 3; i++) {
        const float *t = in->tangent[o[i]];
        double r[3] = { t[0], t[1], t[2] };
        if (k->transformed)
            for (int a = 0; a < 3; a++) r[a] = k->xf.m[a][0] * t[0] + k->xf.m[a][1] * t[1] + k->xf.m[a][2] * t[2];
        double len = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        if (!(len > 0.0) || !isfinite(len)) e.flags &= ~EXTRA_TANGENT;
        for (int a = 0; a < 3; a++) e.tangent[i][a] = len > 0.0 ? (float)(r[a] / len) : 0.0f;
        e.tangent[i][3] = (t[3] < 0.0f) != (k->mirrored != 0) ? -1.0f : 1.0f;
        for (int a = 0; a < 4; a++) {
            e.color[i][a] = in->color[o[i]][a];
            if (!isfinite(e.color[i][a])) e.flags &= ~EXTRA_COLOR;
        }
        for (int a = 0; a < 2; a++) {
            e.uv[i][a] = in->uv[o[i]][a];
            if (!isfinite(e.uv[i][a])) e.flags &= ~EXTRA_UV1;
        }
    }
    if (!(e.flags & EXTRA_TANGENT)) memset(e.tangent, 0, sizeof e.tangent);
    return e;
}

Status mesh_sink_triangle(MeshSink *k, const vec3 p[3], const vec3 *n, const float *uv, uint material)
{
    return mesh_sink_triangle_extra(k, p, n, uv, NULL, material);
}

Status mesh_sink_triangle_extra(MeshSink *k, const vec3 p[3], const vec3 *n, const float *uv,
                                const TriExtra *extra, uint material)
{
    /* a mirroring transform turns the winding normal inside out: swap corners 1 and 2 */
    static const int order[2][3] = { { 0, 1, 2 }, { 0, 2, 1 } };
    const int *o = order[k->mirrored];
    vec3 q[3];
    for (int i = 0; i < 3; i++) q[i] = k->transformed ? transform_point(&k->xf, p[o[i]]) : p[o[i]];
    /* a binary file's NaN, or a double (or a transformed point) beyond the float range */
    for (int i = 0; i < 3; i++)
        if (!isfinite(q[i].x) || !isfinite(q[i].y) || !isfinite(q[i].z))
            return error_set(k->err, ST_INPUT,
                             "%s: a corner of triangle %zu is not a finite single-precision point%s",
                             k->path, k->s->n_triangles - k->first_triangle + 1,
                             k->transformed ? " after the mesh transform" : "");
    /* the kernels compute edges in float: corners 6e38 apart give infinite edges */
    for (int i = 0; i < 3; i++) {
        vec3 e = v3_sub(q[(i + 1) % 3], q[i]);
        if (!isfinite(e.x) || !isfinite(e.y) || !isfinite(e.z))
            return error_set(k->err, ST_INPUT,
                             "%s: the corners of triangle %zu are too far apart (their differences "
                             "overflow single precision)%s", k->path, k->s->n_triangles - k->first_triangle + 1,
                             k->transformed ? " after the mesh transform" : "");
    }
    Triangle t;
    memset(&t, 0, sizeof t);
    t.p0 = q[0];
    t.p1 = q[1];
    t.p2 = q[2];
    t.material = material;
    t.shading = NO_INDEX;
    TriShading sh;
    memset(&sh, 0, sizeof sh);
    if (n) {
        vec3 *dst[3] = { &sh.n0, &sh.n1, &sh.n2 };
        int ok = 1;
        for (int i = 0; i < 3 && ok; i++) ok = transform_normal(k, n[o[i]], dst[i]);
        if (ok) sh.flags |= TRI_HAS_NORMALS;
    }
    if (uv) {
        float *dst[3] = { sh.uv0, sh.uv1, sh.uv2 };
        for (int i = 0; i < 3; i++) {
            dst[i][0] = uv[2 * o[i]];
            dst[i][1] = uv[2 * o[i] + 1];
        }
        sh.flags |= TRI_HAS_UV;
    }
    TriExtra e;
    memset(&e, 0, sizeof e);
    if (extra) e = extra_transform(k, extra, o);
    if (sh.flags || e.flags) {
        Status st = scene_add_shading(k->s, sh, &t.shading, k->err);
        if (!st && e.flags) st = scene_add_tri_extra(k->s, t.shading, e, k->err);
        if (st) return st;
    }
    return scene_add_triangle(k->s, t, k->err);
}

void mesh_bounds(const Scene *s, size_t first, size_t n, vec3 *lo, vec3 *hi)
{
    float l[3] = { INFINITY, INFINITY, INFINITY }, h[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t i = first; i < first + n && i < s->n_triangles; i++) {
        const vec3 *p[3] = { &s->triangles[i].p0, &s->triangles[i].p1, &s->triangles[i].p2 };
        for (int j = 0; j < 3; j++) {
            const float c[3] = { p[j]->x, p[j]->y, p[j]->z };
            for (int a = 0; a < 3; a++) {
                if (c[a] < l[a]) l[a] = c[a];
                if (c[a] > h[a]) h[a] = c[a];
            }
        }
    }
    *lo = v3(l[0], l[1], l[2]);
    *hi = v3(h[0], h[1], h[2]);
}

/* ------------------------------------------------------------------ smooth normals */

/* A triangle's unit winding normal in double, or 0 0 0 when it has no area. */
static void face_normal(const Triangle *t, double n[3])
{
    double a[3] = { (double)t->p1.x - t->p0.x, (double)t->p1.y - t->p0.y, (double)t->p1.z - t->p0.z };
    double b[3] = { (double)t->p2.x - t->p0.x, (double)t->p2.y - t->p0.y, (double)t->p2.z - t->p0.z };
    n[0] = a[1] * b[2] - a[2] * b[1];
    n[1] = a[2] * b[0] - a[0] * b[2];
    n[2] = a[0] * b[1] - a[1] * b[0];
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int i = 0; i < 3; i++) n[i] = len > 0.0 && isfinite(len) ? n[i] / len : 0.0;
}

static int flat(const Scene *s, const Triangle *t)
{
    return t->shading == NO_INDEX || !(s->shading[t->shading].flags & TRI_HAS_NORMALS);
}

/* The normalised sum n as a float unit vector; 0 when it cancels out. */
static int summed_normal(const double *n, vec3 *out)
{
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 1e-9)) return 0;
    *out = v3((float)(n[0] / len), (float)(n[1] / len), (float)(n[2] / len));
    return !v3_is_zero(*out);
}

static Status give_normals(Scene *s, Triangle *tr, const vec3 nn[3], Error *err)
{
    if (tr->shading == NO_INDEX) {
        TriShading sh;
        memset(&sh, 0, sizeof sh);
        Status st = scene_add_shading(s, sh, &tr->shading, err);
        if (st) return st;
    }
    TriShading *sh = &s->shading[tr->shading];
    sh->n0 = nn[0];
    sh->n1 = nn[1];
    sh->n2 = nn[2];
    sh->flags |= TRI_HAS_NORMALS;
    return ST_OK;
}

Status mesh_smooth_normals(Scene *s, size_t first, const uint *keys, uint n_keys, Error *err)
{
    double *sum = calloc((size_t)n_keys * 3 + 3, sizeof *sum);
    if (!sum) return error_set(err, ST_INTERNAL, "out of memory for the normals of %u vertices", n_keys);
    for (size_t i = first; i < s->n_triangles; i++) {
        const Triangle *tr = &s->triangles[i];
        if (!flat(s, tr)) continue;
        double fn[3];
        face_normal(tr, fn);
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) sum[3 * (size_t)keys[3 * (i - first) + j] + k] += fn[k];
    }
    Status st = ST_OK;
    for (size_t i = first; i < s->n_triangles && !st; i++) {
        Triangle *tr = &s->triangles[i];
        if (!flat(s, tr)) continue;
        vec3 nn[3];
        int ok = 1;
        for (int j = 0; j < 3 && ok; j++) ok = summed_normal(&sum[3 * (size_t)keys[3 * (i - first) + j]], &nn[j]);
        if (ok) st = give_normals(s, tr, nn, err);
    }
    free(sum);
    return st;
}

/* ------------------------------------------------------------------ procedural */

Status mesh_make_sphere(Scene *s, size_t min_triangles, uint material, Error *err)
{
    /* rows j = 1 .. nv-1 of nu vertices between the poles: 2 * nu * (nv - 1) triangles */
    size_t nv = 2;
    while (4 * nv * (nv - 1) < min_triangles) nv++;
    size_t nu = 2 * nv, n_vert = nu * (nv - 1) + 2;
    vec3 *v = malloc(n_vert * sizeof *v);
    if (!v) return error_set(err, ST_INTERNAL, "out of memory for a sphere of %zu triangles", min_triangles);
    v[0] = v3(0.0f, 1.0f, 0.0f);
    v[n_vert - 1] = v3(0.0f, -1.0f, 0.0f);
    for (size_t j = 1; j < nv; j++)
        for (size_t i = 0; i < nu; i++) {
            double theta = M_PI * (double)j / (double)nv, phi = 2.0 * M_PI * (double)i / (double)nu;
            double r = 1.0 + 0.06 * sin(7.0 * theta) * cos(5.0 * phi) + 0.02 * sin(23.0 * phi);
            v[1 + (j - 1) * nu + i] = v3((float)(r * sin(theta) * cos(phi)), (float)(r * cos(theta)),
                                         (float)(-r * sin(theta) * sin(phi)));
        }
    MeshSink k;
    Status st = mesh_sink_open(&k, s, NULL, "sphere", err);
    if (!st) st = mesh_sink_reserve(&k, 2 * nu * (nv - 1), 0);
#define RING(j, i) v[1 + ((j) - 1) * nu + (i) % nu]
    for (size_t i = 0; i < nu && !st; i++) {
        vec3 top[3] = { v[0], RING(1, i), RING(1, i + 1) };
        vec3 bottom[3] = { v[n_vert - 1], RING(nv - 1, i + 1), RING(nv - 1, i) };
        st = mesh_sink_triangle(&k, top, NULL, NULL, material);
        if (!st) st = mesh_sink_triangle(&k, bottom, NULL, NULL, material);
        for (size_t j = 1; j + 1 < nv && !st; j++) {
            vec3 a[3] = { RING(j, i), RING(j + 1, i), RING(j + 1, i + 1) };
            vec3 b[3] = { RING(j, i), RING(j + 1, i + 1), RING(j, i + 1) };
            st = mesh_sink_triangle(&k, a, NULL, NULL, material);
            if (!st) st = mesh_sink_triangle(&k, b, NULL, NULL, material);
        }
    }
#undef RING
    free(v);
    return st;
}
