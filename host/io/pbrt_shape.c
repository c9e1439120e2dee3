/* pbrt_shape.c — pbrt-v4 shapes and object instancing (pbrt_reader.h, docs/pbrt.md). */
#include "io/pbrt_reader.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/limit.h"
#include "base/strmap.h"
#include "io/image_write.h"
#include "io/lexer.h"
#include "io/mesh_load.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "util/kmath.h"
#include "scene/mesh_sink.h"
#include "scene/motion.h"
#include "scene/instance.h"
#include "scene/octa_env.h"
#include "scene/subdiv.h"
#include "scene/transform.h"


/* ------------------------------------------------------------------ shapes */

/* Flips triangles [first, end): ReverseOrientation, and meshes whose normals say so */
static void flip_triangle(Scene *s, size_t i)
{
    Triangle *t = &s->triangles[i];
    vec3 q = t->p1;
    t->p1 = t->p2;
    t->p2 = q;
    if (t->shading != NO_INDEX) {
        TriShading *sh = &s->shading[t->shading];
        vec3 n = sh->n1;
        sh->n1 = sh->n2;
        sh->n2 = n;
        float u0 = sh->uv1[0], u1 = sh->uv1[1];
        sh->uv1[0] = sh->uv2[0];
        sh->uv1[1] = sh->uv2[1];
        sh->uv2[0] = u0;
        sh->uv2[1] = u1;
    }
}

/* pbrt's side of a triangle: toward its shading normals when it has them (flipped by
 * ReverseOrientation), else the winding's, flipped by ReverseOrientation. */
static void orient_triangles(Parser *p, size_t first)
{
    Scene *s = p->s;
    for (size_t i = first; i < s->n_triangles; i++) {
        Triangle *t = &s->triangles[i];
        int has_n = t->shading != NO_INDEX && (s->shading[t->shading].flags & TRI_HAS_NORMALS);
        if (has_n && p->g.reverse) {
            TriShading *sh = &s->shading[t->shading];
            sh->n0 = v3_neg(sh->n0);
            sh->n1 = v3_neg(sh->n1);
            sh->n2 = v3_neg(sh->n2);
        }
        if (has_n) {
            TriShading *sh = &s->shading[t->shading];
            vec3 n = v3_add(v3_add(sh->n0, sh->n1), sh->n2);
            vec3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0);
            vec3 w = v3(e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x);
            if (w.x * n.x + w.y * n.y + w.z * n.z < 0) flip_triangle(s, i);
        } else if (p->g.reverse) {
            flip_triangle(s, i);
        }
    }
}

/* Reads an index array against `n_points`. */
static Status get_indices(Parser *p, const Lexer *lx, const char *name, size_t per, size_t n_points, const long **unused,
                          Param **out)
{
    (void)unused;
    Param *pa = pbrt_param_find(p, name);
    *out = pa;
    if (!pa) return ST_OK;
    if (pa->type != PT_INTEGER) return pbrt_param_type_error(p, lx, pa, "integer");
    if (pa->n % per) {
        char what[64];
        snprintf(what, sizeof what, "a multiple of %zu integers", per);
        return pbrt_param_type_error(p, lx, pa, what);
    }
    for (size_t i = 0; i < pa->n; i++) {
        double d = p->pl.nums[pa->first + i];
        if (d < 0 || d >= (double)n_points)
            return lex_error_at(lx, &pa->decl, p->err, "'%.*s' value %zu is %.0f, outside the %zu points of 'P'",
                                (int)pa->name_len, pa->name, i, d, n_points);
    }
    return ST_OK;
}

/* P, N, uv of a mesh, each checked against P's count. */
static Status mesh_arrays(Parser *p, const Lexer *lx, const Token *type, Param **P, Param **N, Param **uv)
{
    *P = pbrt_param_find(p, "P");
    if (!*P) return lex_error_at(lx, type, p->err, "a %.*s needs \"point3 P\"", (int)type->len, type->text);
    if ((*P)->type != PT_POINT3) return pbrt_param_type_error(p, lx, *P, "point3");
    size_t np = (*P)->n / 3;
    *N = pbrt_param_find(p, "N");
    if (*N && ((*N)->type != PT_NORMAL || (*N)->n / 3 != np))
        return pbrt_param_type_error(p, lx, *N, "normal, one per point of 'P'");
    *uv = pbrt_param_find(p, "uv");
    if (!*uv) *uv = pbrt_param_find(p, "st");
    if (*uv && ((*uv)->type != PT_POINT2 && (*uv)->type != PT_FLOAT))
        return pbrt_param_type_error(p, lx, *uv, "point2");
    if (*uv && (*uv)->n / 2 != np) return pbrt_param_type_error(p, lx, *uv, "one (u, v) per point of 'P'");
    return ST_OK;
}

static vec3 nth3(const Parser *p, const Param *pa, size_t i)
{
    const double *d = p->pl.nums + pa->first + 3 * i;
    return v3((float)d[0], (float)d[1], (float)d[2]);
}

static Status emit_triangle(Parser *p, MeshSink *k, const Param *P, const Param *N, const Param *uv, const size_t idx[3],
                            uint material)
{
    vec3 pt[3], n[3];
    float t[6];
    for (int c = 0; c < 3; c++) {
        pt[c] = nth3(p, P, idx[c]);
        if (N) {
            n[c] = nth3(p, N, idx[c]);
            float l = sqrtf(v3_dot(n[c], n[c]));
            if (!(l > 0)) N = NULL;
            else n[c] = v3_scale(n[c], 1.0f / l);
        }
        if (uv) {
            t[2 * c] = (float)p->pl.nums[uv->first + 2 * idx[c]];
            t[2 * c + 1] = (float)p->pl.nums[uv->first + 2 * idx[c] + 1];
        }
    }
    return mesh_sink_triangle(k, pt, N ? n : NULL, uv ? t : NULL, material);
}

static Status shape_trianglemesh(Parser *p, const Lexer *lx, const Token *type, MeshSink *k, uint material, int bilinear)
{
    Param *P = NULL, *N = NULL, *uv = NULL, *ix = NULL;
    Status st = mesh_arrays(p, lx, type, &P, &N, &uv);
    if (st) return st;
    size_t np = P->n / 3, per = bilinear ? 4 : 3;
    if ((st = get_indices(p, lx, "indices", per, np, NULL, &ix))) return st;
    if (!ix && np != per)
        return lex_error_at(lx, type, p->err, "a %.*s without \"integer indices\" must have exactly %zu points",
                            (int)type->len, type->text, per);
    size_t n = ix ? ix->n / per : 1;
    if ((st = mesh_sink_reserve(k, n * (bilinear ? 2 : 1), (N || uv) ? n * (bilinear ? 2 : 1) : 0))) return st;
    for (size_t f = 0; f < n; f++) {
        size_t v[4];
        for (size_t c = 0; c < per; c++) v[c] = ix ? (size_t)p->pl.nums[ix->first + f * per + c] : c;
        if (!bilinear) {
            if ((st = emit_triangle(p, k, P, N, uv, v, material))) return st;
            continue;
        }
        /* a bilinear patch p00 p10 p01 p11 as two triangles, wound like pbrt's normal */
        size_t a[3] = {v[0], v[1], v[3]}, b[3] = {v[0], v[3], v[2]};
        if ((st = emit_triangle(p, k, P, N, uv, a, material)) || (st = emit_triangle(p, k, P, N, uv, b, material)))
            return st;
    }
    return ST_OK;
}

static int is_similarity(const Transform *t, double *scale)
{
    double c[3][3], l[3];
    for (int j = 0; j < 3; j++) {
        for (int i = 0; i < 3; i++) c[j][i] = t->m[i][j];
        l[j] = sqrt(c[j][0] * c[j][0] + c[j][1] * c[j][1] + c[j][2] * c[j][2]);
    }
    if (!(l[0] > 0) || fabs(l[1] - l[0]) > 1e-6 * l[0] || fabs(l[2] - l[0]) > 1e-6 * l[0]) return 0;
    for (int a = 0; a < 3; a++) {
        int b = (a + 1) % 3;
        if (fabs(c[a][0] * c[b][0] + c[a][1] * c[b][1] + c[a][2] * c[b][2]) > 1e-6 * l[0] * l[0]) return 0;
    }
    *scale = l[0];
    return 1;
}

/* Counts `tris` more tessellated triangles against the scene's budget, before anything
 * is made: a few numbers in a file (a loopsubdiv's levels, thousands of emitting
 * ellipsoids) must not become gigabytes, while a large subdivided model, whose file is
 * large too, must still load. The budget is CLPT_MAX_TESSELLATED_TRIANGLES and
 * CLPT_TESSELLATED_PER_INPUT_BYTE for each byte the load has read so far. `what` names
 * the shape in the message. */
static Status tessellation_budget(Parser *p, const Lexer *lx, const Token *at, size_t tris, const char *what)
{
    uint64_t budget = CLPT_MAX_TESSELLATED_TRIANGLES + CLPT_TESSELLATED_PER_INPUT_BYTE * lex_load_bytes();
    if (tris > budget - p->tessellated)
        return lex_error_at(lx, at, p->err, "%s makes %zu triangles; with the %zu tessellated before it that is "
                            "past the %llu a scene of %llu bytes may make (%u and %u per byte of its files)", what,
                            tris, p->tessellated, (unsigned long long)budget, (unsigned long long)lex_load_bytes(),
                            CLPT_MAX_TESSELLATED_TRIANGLES, CLPT_TESSELLATED_PER_INPUT_BYTE);
    p->tessellated += tris;
    return ST_OK;
}

/* sphere_tessellate's triangles: 64 x 32 quads less one triangle of each at the poles */
enum { SPHERE_MESH_NU = 64, SPHERE_MESH_NV = 32,
       SPHERE_MESH_TRIANGLES = 2 * SPHERE_MESH_NU * SPHERE_MESH_NV - 2 * SPHERE_MESH_NU };

/* An emitting sphere under a transform that is not a similarity (an ellipsoid), or one
 * turned inside out: a UV sphere of 64 x 32 quads through the mesh sink. */
static Status sphere_tessellate(Parser *p, MeshSink *k, double r, uint material)
{
    enum { NU = SPHERE_MESH_NU, NV = SPHERE_MESH_NV };
    Status st = mesh_sink_reserve(k, 2 * NU * NV, 2 * NU * NV);
    for (int j = 0; j < NV && !st; j++)
        for (int i = 0; i < NU && !st; i++) {
            vec3 q[4], n[4];
            float uv[8];
            for (int c = 0; c < 4; c++) {
                int ii = i + (c == 1 || c == 2), jj = j + (c >= 2);
                double phi = 2 * M_PI * ii / NU, th = M_PI * jj / NV;
                n[c] = v3((float)(sin(th) * cos(phi)), (float)(sin(th) * sin(phi)), (float)cos(th));
                q[c] = v3_scale(n[c], (float)r);
                uv[2 * c] = (float)ii / NU;
                uv[2 * c + 1] = (float)jj / NV;
            }
            /* corners 0 1 2 3 go around the quad; outward winding is 0 2 1, 0 3 2 */
            vec3 a[3] = {q[0], q[2], q[1]}, an[3] = {n[0], n[2], n[1]};
            vec3 b[3] = {q[0], q[3], q[2]}, bn[3] = {n[0], n[3], n[2]};
            float auv[6] = {uv[0], uv[1], uv[4], uv[5], uv[2], uv[3]};
            float buv[6] = {uv[0], uv[1], uv[6], uv[7], uv[4], uv[5]};
            if (j > 0) st = mesh_sink_triangle(k, a, an, auv, material);
            if (!st && j < NV - 1) st = mesh_sink_triangle(k, b, bn, buv, material);
        }
    (void)p;
    return st;
}

static Status shape_sphere(Parser *p, const Lexer *lx, const Token *type, uint material)
{
    double r = 1, scale;
    Status st = pbrt_get_float(p, lx, "radius", &r);
    if (st) return st;
    if (!(r > 0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "radius"), "> 0");
    Param *zmin = pbrt_param_find(p, "zmin"), *zmax = pbrt_param_find(p, "zmax"), *phimax = pbrt_param_find(p, "phimax");
    if (zmin || zmax || phimax) {
        st = warn_once(p, lx, type, "sphere-partial", "partial spheres (zmin, zmax, phimax) are rendered whole");
        if (st) return st;
    }
    int emits = !v3_is_zero(p->s->materials[material].emission);
    int similar = is_similarity(&p->g.ctm, &scale);
    if (!similar && !emits) {
        /* an ellipsoid stays analytic: 32 + 96 bytes however it is squashed */
        Transform m = transform_scale(r, r, r);
        m = transform_compose(&p->g.ctm, &m);
        if ((st = scene_add_ellipsoid(p->s, &m, material, p->err)) == ST_INPUT)
            reader_annotate(lx, type, p->err);
        return st;
    }
    if (similar && !(p->g.reverse && emits)) {
        Sphere sp;
        memset(&sp, 0, sizeof sp);
        sp.center = transform_point(&p->g.ctm, v3(0, 0, 0));
        sp.radius = (float)(r * scale);
        sp.material = material;
        if (!(sp.radius > 0) || !isfinite(sp.radius) || !isfinite(fabsf(sp.center.x) + sp.radius) ||
            !isfinite(fabsf(sp.center.y) + sp.radius) || !isfinite(fabsf(sp.center.z) + sp.radius))
            return lex_error_at(lx, type, p->err, "the sphere reaches beyond the largest float (about 3.4e38)");
        return scene_add_sphere(p->s, sp, p->err);
    }
    /* an emitting ellipsoid, or a sphere that emits inwards: the kernels sample sphere
     * lights by their cone of directions, which neither has, so a mesh */
    if ((st = tessellation_budget(p, lx, type, SPHERE_MESH_TRIANGLES, "an emitting ellipsoid (or inward-emitting "
                                  "sphere) as a mesh")))
        return st;
    MeshSink k;
    size_t first = p->s->n_triangles;
    if ((st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err))) return st;
    if ((st = sphere_tessellate(p, &k, r, material))) return st;
    orient_triangles(p, first);
    return ST_OK;
}

/* pbrt's loopsubdiv: subdivided here to `levels` (default 3), limit positions, smooth
 * normals (scene/subdiv.h). Each level makes four triangles of one, so a 4 KB file asked
 * for 33 million triangles: levels stop at PBRT_MAX_SUBDIV_LEVELS and the triangles
 * count against the scene's tessellation budget (tessellation_budget). pbrt-v4 itself
 * has no bound; its scenes use levels up to about 5. */
#define PBRT_MAX_SUBDIV_LEVELS 10
static Status shape_loopsubdiv(Parser *p, const Lexer *lx, const Token *type, uint material)
{
    Param *P = pbrt_param_find(p, "P"), *ix;
    if (!P) return lex_error_at(lx, type, p->err, "a loopsubdiv needs \"point3 P\"");
    if (P->type != PT_POINT3) return pbrt_param_type_error(p, lx, P, "point3");
    size_t np = P->n / 3;
    long levels = 3;
    Status st = pbrt_get_int(p, lx, "levels", &levels);
    if (st) return st;
    if (levels < 0 || levels > PBRT_MAX_SUBDIV_LEVELS)
        return lex_error_at(lx, type, p->err, "loopsubdiv level %ld is beyond %d (each level makes four "
                            "triangles of one: level %d makes 4^%d = %.0f of each)", levels, PBRT_MAX_SUBDIV_LEVELS,
                            (int)levels, (int)levels, pow(4.0, (double)levels));
    if ((st = get_indices(p, lx, "indices", 3, np, NULL, &ix))) return st;
    if (!ix) return lex_error_at(lx, type, p->err, "a loopsubdiv needs \"integer indices\"");
    size_t nt = ix->n / 3;
    /* nt 4^levels, saturated; counted before anything is allocated */
    size_t made = nt;
    for (long l = 0; l < levels; l++) made = made > SIZE_MAX / 4 ? SIZE_MAX : made * 4;
    char what[96];
    snprintf(what, sizeof what, "loopsubdiv to level %ld of %zu triangles", levels, nt);
    if ((st = tessellation_budget(p, lx, type, made, what))) return st;
    uint32_t *idx = malloc(ix->n * sizeof *idx + 1);
    if (!idx) return error_set(p->err, ST_INTERNAL, "out of memory");
    for (size_t i = 0; i < ix->n; i++) idx[i] = (uint32_t)p->pl.nums[ix->first + i];
    SubdivMesh m;
    st = subdiv_loop(p->pl.nums + P->first, np, idx, nt, (int)levels, CLPT_MAX_TESSELLATED_TRIANGLES, &m, p->err);
    free(idx);
    if (st == ST_INPUT) reader_annotate(lx, type, p->err);
    if (st) return st;
    MeshSink k;
    size_t first = p->s->n_triangles;
    if (!(st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err))) st = mesh_sink_reserve(&k, m.n_tris, m.n_tris);
    for (size_t f = 0; f < m.n_tris && !st; f++) {
        vec3 q[3], n[3];
        int has_n = 1;
        for (int c = 0; c < 3; c++) {
            const double *a = m.p + 3 * m.idx[3 * f + c], *b = m.n + 3 * m.idx[3 * f + c];
            q[c] = v3((float)a[0], (float)a[1], (float)a[2]);
            n[c] = v3((float)b[0], (float)b[1], (float)b[2]);
            has_n &= !v3_is_zero(n[c]);
        }
        st = mesh_sink_triangle(&k, q, has_n ? n : NULL, NULL, material);
    }
    subdiv_free(&m);
    if (!st) orient_triangles(p, first);
    return st;
}

/* pbrt's disk (height, radius, innerradius, phimax) and cylinder (radius, zmin, zmax,
 * phimax) as meshes: the kernels have neither primitive. A disk is flat, so one ring of
 * segments is exact but for the rim; a cylinder's side is ruled, so one band of quads.
 * The rim is a polygon of 64 segments per full turn (a 64-gon holds 99.8% of the
 * circle's area). The analytic normals (+z for a disk, outward for a cylinder) are the
 * shading normals, so orient_triangles puts each triangle on pbrt's side, and (u, v)
 * are pbrt's: u = phi / phimax, v from the outer rim in (disk) or from zmin up
 * (cylinder). Real scenes use disks as area lights (pbrt-v4-scenes' killeroos). */
static Status shape_disk_cylinder(Parser *p, const Lexer *lx, const Token *type, uint material, int cylinder)
{
    double radius = 1, inner = 0, height = 0, zmin = -1, zmax = 1, phimax = 360;
    Status st;
    if ((st = pbrt_get_float(p, lx, "radius", &radius)) || (st = pbrt_get_float(p, lx, "phimax", &phimax))) return st;
    if (cylinder ? (st = pbrt_get_float(p, lx, "zmin", &zmin)) || (st = pbrt_get_float(p, lx, "zmax", &zmax))
                 : (st = pbrt_get_float(p, lx, "height", &height)) || (st = pbrt_get_float(p, lx, "innerradius", &inner)))
        return st;
    if (!(radius > 0) || !isfinite(radius)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "radius"), "> 0 and finite");
    if (!(phimax > 0 && phimax <= 360)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "phimax"), "in (0, 360]");
    if (!cylinder && !(inner >= 0 && inner < radius))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "innerradius"), "in [0, radius)");
    if (!isfinite(height) || !isfinite(zmin) || !isfinite(zmax))
        return lex_error_at(lx, type, p->err, "the %.*s's height or z range is not finite", (int)type->len, type->text);
    if (cylinder && zmin > zmax) {   /* pbrt takes them in either order */
        double t = zmin;
        zmin = zmax;
        zmax = t;
    }
    if (cylinder && !(zmax > zmin))
        return lex_error_at(lx, type, p->err, "the cylinder's zmin and zmax are equal: it has no side");
    int nseg = (int)ceil(64.0 * phimax / 360.0);
    if (nseg < 4) nseg = 4;
    double turn = phimax * M_PI / 180.0;
    MeshSink k;
    size_t first = p->s->n_triangles;
    if ((st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err)) ||
        (st = mesh_sink_reserve(&k, 2 * (size_t)nseg, 2 * (size_t)nseg)))
        return st;
    for (int i = 0; i < nseg && !st; i++) {
        double f0 = (double)i / nseg, f1 = (double)(i + 1) / nseg;
        float c0 = (float)cos(f0 * turn), s0 = (float)sin(f0 * turn), c1 = (float)cos(f1 * turn),
              s1 = (float)sin(f1 * turn);
        vec3 q[4], n[4];
        float uv[8];
        if (cylinder) {   /* corners: (phi0, zmin) (phi1, zmin) (phi0, zmax) (phi1, zmax) */
            float r = (float)radius;
            q[0] = v3(r * c0, r * s0, (float)zmin);
            q[1] = v3(r * c1, r * s1, (float)zmin);
            q[2] = v3(r * c0, r * s0, (float)zmax);
            q[3] = v3(r * c1, r * s1, (float)zmax);
            n[0] = n[2] = v3(c0, s0, 0.0f);
            n[1] = n[3] = v3(c1, s1, 0.0f);
        } else {          /* corners: outer phi0, outer phi1, inner phi0, inner phi1 */
            float ro = (float)radius, ri = (float)inner, z = (float)height;
            q[0] = v3(ro * c0, ro * s0, z);
            q[1] = v3(ro * c1, ro * s1, z);
            q[2] = v3(ri * c0, ri * s0, z);
            q[3] = v3(ri * c1, ri * s1, z);
            n[0] = n[1] = n[2] = n[3] = v3(0.0f, 0.0f, 1.0f);
        }
        const float v_lo = 0.0f, v_hi = 1.0f;   /* disk: outer rim v 0, inner 1; cylinder: zmin 0, zmax 1 */
        const float u[4] = { (float)f0, (float)f1, (float)f0, (float)f1 }, v[4] = { v_lo, v_lo, v_hi, v_hi };
        for (int c = 0; c < 4; c++) {
            uv[2 * c] = u[c];
            uv[2 * c + 1] = v[c];
        }
        vec3 a[3] = { q[0], q[1], q[3] }, an[3] = { n[0], n[1], n[3] };
        vec3 b[3] = { q[0], q[3], q[2] }, bn[3] = { n[0], n[3], n[2] };
        float auv[6] = { uv[0], uv[1], uv[2], uv[3], uv[6], uv[7] };
        float buv[6] = { uv[0], uv[1], uv[6], uv[7], uv[4], uv[5] };
        int disk_centre = !cylinder && inner == 0;   /* the inner corners meet: one triangle */
        if (disk_centre) {
            vec3 t[3] = { q[0], q[1], q[2] }, tn[3] = { n[0], n[1], n[2] };
            float tuv[6] = { uv[0], uv[1], uv[2], uv[3], uv[4], uv[5] };
            st = mesh_sink_triangle(&k, t, tn, tuv, material);
        } else {
            st = mesh_sink_triangle(&k, a, an, auv, material);
            if (!st) st = mesh_sink_triangle(&k, b, bn, buv, material);
        }
    }
    if (!st) orient_triangles(p, first);
    double reach = st ? 0.0 : scene_triangles_reach(p->s, first, p->s->n_triangles);
    if (reach > SCENE_MAX_COORDINATE)
        return lex_error_at(lx, type, p->err, "the %.*s reaches %g from the origin (radius %g, after the transform), "
                            "beyond the 2^62 (%g) single precision can intersect: scale the scene down",
                            (int)type->len, type->text, reach, radius, SCENE_MAX_COORDINATE);
    return st;
}

static Status shape_plymesh(Parser *p, const Lexer *lx, const Token *type, uint material)
{
    const Token *f = NULL;
    Status st = pbrt_get_string(p, lx, "filename", &f);
    if (st) return st;
    if (!f) return lex_error_at(lx, type, p->err, "a plymesh needs \"string filename\"");
    char *path = pbrt_beside_main(p, f);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    if (mesh_kind(path) != MESH_PLY) {
        free(path);
        return lex_expected(lx, f, "a PLY file name ending in .ply or .ply.gz", p->err);
    }
    MeshOptions o = mesh_options(material);
    o.xf = p->g.ctm;
    size_t first = p->s->n_triangles;
    st = mesh_load(path, p->s, &o, p->err);
    free(path);
    if (st == ST_IO) reader_annotate(lx, f, p->err);
    if (st) return st;
    orient_triangles(p, first);
    pbrt_param_find(p, "displacement.edgelength");
    return ST_OK;
}

static Status shape_moving(Parser *p, Lexer *lx, const Token *kw, const Token *type);
static Status object_place(Parser *p, const Lexer *lx, const Token *name, const char *what, uint32_t i);

/* A Shape of `type`, its parameters read, under the current transform's start pose. */
static Status shape_make(Parser *p, Lexer *lx, const Token *type_tok)
{
    Token type = *type_tok;
    Status st;
    int known = pbrt_tok_eq(&type, "sphere") || pbrt_tok_eq(&type, "trianglemesh") || pbrt_tok_eq(&type, "plymesh") ||
                pbrt_tok_eq(&type, "bilinearmesh") || pbrt_tok_eq(&type, "loopsubdiv") || pbrt_tok_eq(&type, "disk") ||
                pbrt_tok_eq(&type, "cylinder");
    if (!known) {
        char key[96];
        snprintf(key, sizeof key, "Shape %.*s", (int)(type.len > 40 ? 40 : type.len), type.text);
        return warn_once(p, lx, &type, key, "Shape \"%.*s\" is not supported; skipped",
                         (int)(type.len > 40 ? 40 : type.len), type.text);
    }
    /* an object's shapes are placed by its instances, which move: not the shapes */
    if (pbrt_ctm_moves(p) && (st = pbrt_warn_still(p, lx, &type, "a Shape in an object"))) return st;
    uint material;
    if ((st = pbrt_shape_material(p, &material))) return st;
    if (pbrt_tok_eq(&type, "sphere")) {
        st = shape_sphere(p, lx, &type, material);
    } else if (pbrt_tok_eq(&type, "plymesh")) {
        st = shape_plymesh(p, lx, &type, material);
    } else if (pbrt_tok_eq(&type, "loopsubdiv")) {
        st = shape_loopsubdiv(p, lx, &type, material);
    } else if (pbrt_tok_eq(&type, "disk") || pbrt_tok_eq(&type, "cylinder")) {
        st = shape_disk_cylinder(p, lx, &type, material, pbrt_tok_eq(&type, "cylinder"));
    } else {
        MeshSink k;
        size_t first = p->s->n_triangles;
        if ((st = mesh_sink_open(&k, p->s, &p->g.ctm, lx->path, p->err))) return st;
        st = shape_trianglemesh(p, lx, &type, &k, material, pbrt_tok_eq(&type, "bilinearmesh"));
        if (!st) orient_triangles(p, first);
    }
    if (st) return st;
    pbrt_param_find(p, "alpha");
    if (pbrt_param_find(p, "alpha") && (st = warn_once(p, lx, &type, "alpha", "shape alpha (cut-outs) is not supported; ignored")))
        return st;
    return pbrt_warn_unused(p, lx, "Shape");
}

Status pbrt_shape(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    if (!p->in_object && pbrt_ctm_moves(p)) return shape_moving(p, lx, kw, type);
    return shape_make(p, lx, type);
}

/* ------------------------------------------------------------------ instancing */

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
        Status st = tessellation_budget(p, lx, name, SPHERE_MESH_TRIANGLES, "an emitting sphere copied under a "
                                        "transform that is no similarity, as a mesh,");
        MeshSink k;
        size_t first = p->s->n_triangles;
        if (!st) st = mesh_sink_open(&k, p->s, &m, lx->path, p->err);
        if (!st) st = sphere_tessellate(p, &k, 1.0, sp->material);
        if (st) return st;
        int reverse = p->g.reverse;
        p->g.reverse = 0;
        orient_triangles(p, first);
        p->g.reverse = reverse;
        return ST_OK;
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
static Status shape_moving(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    char buf[64];
    snprintf(buf, sizeof buf, "moving Shape %u:%u", type->line, type->col);
    Token name = {TOK_STRING, buf, strlen(buf), type->line, type->col};
    Status st = object_open(p, lx, kw, &name);
    if (st) return st;
    p->g.ctm = p->g.ctm_end = transform_identity();
    if ((st = shape_make(p, lx, type))) return st;
    uint32_t index;
    if ((st = object_close(p, lx, kw, 0, &index))) return st;
    return object_place(p, lx, type, "Shape", index);
}

/* ObjectInstance of p->objects[i] under the current transforms; `what` and `name` for
 * messages ("ObjectInstance" and its name, or "Shape" and its type). */
static Status object_place(Parser *p, const Lexer *lx, const Token *name_tok, const char *what, uint32_t i)
{
    Token name = *name_tok;
    Status st;
    const PObject *o = &p->objects[i];
    double scale;
    int similar = is_similarity(&p->g.ctm, &scale);
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
