/* pbrt_shape.c — pbrt-v4 shapes: each type's reader and the Shape dispatch (pbrt_reader.h,
 * docs/pbrt.md); ObjectBegin/End/Instance and moving shapes are pbrt_object.c's. */
#include "io/pbrt_reader.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/limit.h"
#include "io/image_write.h"
#include "io/lexer.h"
#include "io/mesh_load.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "util/kmath.h"
#include "scene/mesh_sink.h"
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
 * ReverseOrientation, `reverse`), else the winding's, flipped by ReverseOrientation. */
static void orient_triangles(Scene *s, size_t first, int reverse)
{
    for (size_t i = first; i < s->n_triangles; i++) {
        Triangle *t = &s->triangles[i];
        int has_n = t->shading != NO_INDEX && (s->shading[t->shading].flags & TRI_HAS_NORMALS);
        if (has_n && reverse) {
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
        } else if (reverse) {
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

int pbrt_is_similarity(const Transform *t, double *scale)
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
static Status sphere_tessellate(MeshSink *k, double r, uint material)
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
    return st;
}

Status pbrt_sphere_mesh(Parser *p, const Lexer *lx, const Token *at, const char *what, const Transform *xf, double r,
                        uint material, int reverse)
{
    Status st = tessellation_budget(p, lx, at, SPHERE_MESH_TRIANGLES, what);
    MeshSink k;
    size_t first = p->s->n_triangles;
    if (!st) st = mesh_sink_open(&k, p->s, xf, lx->path, p->err);
    if (!st) st = sphere_tessellate(&k, r, material);
    if (st) return st;
    orient_triangles(p->s, first, reverse);
    return ST_OK;
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
    int similar = pbrt_is_similarity(&p->g.ctm, &scale);
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
    return pbrt_sphere_mesh(p, lx, type, "an emitting ellipsoid (or inward-emitting sphere) as a mesh", &p->g.ctm, r,
                            material, p->g.reverse);
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
    if (!st) orient_triangles(p->s, first, p->g.reverse);
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
    if (!st) orient_triangles(p->s, first, p->g.reverse);
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
    orient_triangles(p->s, first, p->g.reverse);
    pbrt_param_find(p, "displacement.edgelength");
    return ST_OK;
}

Status pbrt_shape_make(Parser *p, Lexer *lx, const Token *type_tok)
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
        if (!st) orient_triangles(p->s, first, p->g.reverse);
    }
    if (st) return st;
    pbrt_param_find(p, "alpha");
    if (pbrt_param_find(p, "alpha") && (st = warn_once(p, lx, &type, "alpha", "shape alpha (cut-outs) is not supported; ignored")))
        return st;
    return pbrt_warn_unused(p, lx, "Shape");
}

Status pbrt_shape(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    if (pbrt_ctm_moves(p))
        return p->in_object ? pbrt_object_shape_moving(p, lx, type) : pbrt_shape_moving(p, lx, kw, type);
    return pbrt_shape_make(p, lx, type);
}
