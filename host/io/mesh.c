/* mesh.c — transforms, the triangle sink, loading by extension, numbers, paths (mesh.h). */
#include "io/mesh.h"

#include "kmath.h"
#include "io/obj.h"
#include "io/ply.h"

#include <ctype.h>
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

/* ------------------------------------------------------------------ transforms */

Transform transform_identity(void)
{
    Transform t;
    memset(&t, 0, sizeof t);
    t.m[0][0] = t.m[1][1] = t.m[2][2] = 1.0;
    return t;
}

int transform_is_identity(const Transform *t)
{
    Transform id = transform_identity();
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            if (t->m[i][j] != id.m[i][j]) return 0;
    return 1;
}

Transform transform_compose(const Transform *a, const Transform *b)
{
    Transform r;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 4; j++) {
            double v = j == 3 ? a->m[i][3] : 0.0;
            for (int k = 0; k < 3; k++) v += a->m[i][k] * b->m[k][j];
            r.m[i][j] = v;
        }
    }
    return r;
}

Transform transform_translate(double x, double y, double z)
{
    Transform t = transform_identity();
    t.m[0][3] = x;
    t.m[1][3] = y;
    t.m[2][3] = z;
    return t;
}

Transform transform_scale(double x, double y, double z)
{
    Transform t = transform_identity();
    t.m[0][0] = x;
    t.m[1][1] = y;
    t.m[2][2] = z;
    return t;
}

/* sin and cos of an angle in degrees, exact at multiples of 90 (so that `ry 90` maps
 * axes onto axes without 6e-17 residue). */
static void sincos_degrees(double deg, double *s, double *c)
{
    double q = deg / 90.0;
    if (q == floor(q) && fabs(q) < 1e15) {
        long k = (long)fmod(q, 4.0);
        if (k < 0) k += 4;
        static const double sv[4] = { 0.0, 1.0, 0.0, -1.0 }, cv[4] = { 1.0, 0.0, -1.0, 0.0 };
        *s = sv[k];
        *c = cv[k];
        return;
    }
    double r = deg * (M_PI / 180.0);
    *s = sin(r);
    *c = cos(r);
}

Transform transform_rotate(double x, double y, double z, double degrees)
{
    Transform t = transform_identity();
    double len = sqrt(x * x + y * y + z * z);
    if (!(len > 0.0) || !isfinite(len)) return t;
    x /= len;
    y /= len;
    z /= len;
    double s, c;
    sincos_degrees(degrees, &s, &c);
    double d = 1.0 - c;
    /* Rodrigues' formula */
    t.m[0][0] = c + x * x * d;      t.m[0][1] = x * y * d - z * s;  t.m[0][2] = x * z * d + y * s;
    t.m[1][0] = y * x * d + z * s;  t.m[1][1] = c + y * y * d;      t.m[1][2] = y * z * d - x * s;
    t.m[2][0] = z * x * d - y * s;  t.m[2][1] = z * y * d + x * s;  t.m[2][2] = c + z * z * d;
    return t;
}

double transform_det(const Transform *t)
{
#define M(i, j) t->m[i][j]
    return M(0, 0) * (M(1, 1) * M(2, 2) - M(1, 2) * M(2, 1)) -
           M(0, 1) * (M(1, 0) * M(2, 2) - M(1, 2) * M(2, 0)) +
           M(0, 2) * (M(1, 0) * M(2, 1) - M(1, 1) * M(2, 0));
#undef M
}

vec3 transform_point(const Transform *t, vec3 p)
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = t->m[i][0] * p.x + t->m[i][1] * p.y + t->m[i][2] * p.z + t->m[i][3];
    return v3((float)r[0], (float)r[1], (float)r[2]);
}

MeshOptions mesh_options(uint material)
{
    MeshOptions o;
    o.material = material;
    o.default_material = NO_INDEX;
    o.xf = transform_identity();
    return o;
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
    /* inverse transpose = cofactor matrix / det */
    double (*m)[4] = k->xf.m;
    for (int i = 0; i < 3; i++) {
        int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (int j = 0; j < 3; j++) {
            int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            k->nxf[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / det;
        }
    }
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

Status mesh_sink_triangle(MeshSink *k, const vec3 p[3], const vec3 *n, const float *uv, uint material)
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
    if (sh.flags) {
        Status st = scene_add_shading(k->s, sh, &t.shading, k->err);
        if (st) return st;
    }
    return scene_add_triangle(k->s, t, k->err);
}

/* ------------------------------------------------------------------ files */

MeshKind mesh_kind(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    if (!dot) return MESH_NONE;
    if (strcasecmp(dot, ".obj") == 0) return MESH_OBJ;
    if (strcasecmp(dot, ".ply") == 0) return MESH_PLY;
    return MESH_NONE;
}

Status mesh_load(const char *path, Scene *s, const MeshOptions *o, Error *err)
{
    switch (mesh_kind(path)) {
    case MESH_OBJ: return obj_load_with(path, s, o, err);
    case MESH_PLY: return ply_load(path, s, o, err);
    case MESH_NONE: break;
    }
    return error_set(err, ST_INPUT, "'%s': not a mesh file (expected a name ending in .obj or .ply)", path);
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

/* ------------------------------------------------------------------ numbers */

static const float pow10_exact[11] = { 1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f,
                                       1e6f, 1e7f, 1e8f, 1e9f, 1e10f };

/* The fast path takes plain decimals whose digits form an integer m <= 2^24 with at most
 * 10 of them after the point: m and 10^k (k <= 10, since 5^10 < 2^24) are then exact
 * floats, so the single IEEE division m / 10^k is the correctly rounded value, which is
 * strtof's answer. Everything else (exponents, long mantissas, hex) goes to strtof. */
const char *mesh_parse_float(const char *p, const char *end, float *out)
{
    const char *q = p;
    if (q >= end || isspace((unsigned char)*q)) return NULL;
    int neg = 0;
    if (*q == '-' || *q == '+') neg = *q++ == '-';
    uint64_t m = 0;
    int digits = 0, frac = 0, seen_point = 0, any = 0;
    for (; q < end; q++) {
        char c = *q;
        if (c >= '0' && c <= '9') {
            if (digits < 19) m = m * 10 + (uint64_t)(c - '0');
            digits += m > 0;            /* leading zeros are free */
            frac += seen_point;
            any = 1;
        } else if (c == '.' && !seen_point) {
            seen_point = 1;
        } else {
            break;
        }
    }
    /* anything that could continue a number (an exponent, hex, inf, nan) is strtof's */
    int more = q < end && (isalnum((unsigned char)*q) || *q == '.' || *q == '_');
    if (any && !more && digits < 19 && m <= (1u << 24) && frac <= 10) {
        float v = (float)m / pow10_exact[frac];
        *out = neg ? -v : v;
        return q;
    }
    char *e;
    float v = strtof(p, &e);
    if (e == p || !isfinite(v)) return NULL;
    *out = v;
    return e;
}

/* ------------------------------------------------------------------ paths */

static int path_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Replaces the component path[start, end) by a directory entry of the folder path[0,
 * start) that equals it without regard to case; 0 when there is none. Entries have the
 * same length as the component when they match, so the path is rewritten in place. */
static int match_component(char *path, size_t start, size_t end)
{
    char saved = path[start];
    size_t len = end - start;
    char name[256];
    if (len >= sizeof name) return 0;
    memcpy(name, path + start, len);
    name[len] = '\0';
    path[start] = '\0';
    DIR *d = opendir(start == 0 ? "." : path);
    path[start] = saved;
    if (!d) return 0;
    int found = 0;
    struct dirent *e;
    while (!found && (e = readdir(d)) != NULL) {
        if (strlen(e->d_name) == len && strcasecmp(e->d_name, name) == 0) {
            memcpy(path + start, e->d_name, len);
            found = 1;
        }
    }
    closedir(d);
    return found;
}

char *mesh_resolve_path(const char *beside, const char *name, size_t len)
{
    const char *slash = strrchr(beside, '/');
    size_t dir = (len > 0 && (name[0] == '/' || name[0] == '\\')) || !slash ? 0 : (size_t)(slash - beside) + 1;
    char *out = malloc(dir + len + 1);
    if (!out) return NULL;
    memcpy(out, beside, dir);
    for (size_t i = 0; i < len; i++) out[dir + i] = name[i] == '\\' ? '/' : name[i];
    out[dir + len] = '\0';
    if (path_exists(out)) return out;
    char *fixed = malloc(dir + len + 1);
    if (!fixed) return out;
    memcpy(fixed, out, dir + len + 1);
    size_t n = dir + len, start = 0;
    while (start < n) {
        while (start < n && fixed[start] == '/') start++;
        size_t end = start;
        while (end < n && fixed[end] != '/') end++;
        if (end == start) break;
        char saved = fixed[end];
        fixed[end] = '\0';
        int exists = path_exists(fixed);
        fixed[end] = saved;
        if (!exists && !match_component(fixed, start, end)) {
            free(fixed);
            return out;
        }
        start = end;
    }
    free(out);
    return fixed;
}
