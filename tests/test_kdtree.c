/*
 * test_kdtree.c -- the two trees: the kd-tree build (host/accel/kdtree.c) and the 8-wide
 * BVH build (host/accel/bvh.c, bvh_collapse.c), the primitive intersections
 * (kernels/geom/intersect.h) and both walks (kernels/accel/traverse.h and traverse_bvh.h,
 * compiled here as C).
 *
 * Each tree's structure is checked directly (nesting, which primitives each leaf must
 * hold, the statistics), and the walks against brute force: every primitive tested
 * with the same intersection functions, on random scenes and random rays.
 */
#include <stdint.h>
#include <stdlib.h>

#include "harness.h"
#include "accel/bvh.h"
#include "accel/kdtree.h"
#include "io/mesh_load.h"
#include "scene/transform.h"
#include "geom/surface.h"
#include "accel/traverse.h"

/* ------------------------------------------------------------------ helpers */

static uint64_t rng = 1;
static void rng_seed(uint64_t s) { rng = s * 0x9e3779b97f4a7c15ull + 1; }
static float frand(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (float)(rng >> 40) / 16777216.0f;
}
static float frange(float a, float b) { return a + (b - a) * frand(); }
static vec3 vrand(float a, float b) { return v3(frange(a, b), frange(a, b), frange(a, b)); }

typedef struct {
    Sphere sph[512];     uint ns;
    SphereXform xf[512]; uint nxf;   /* the ellipsoids' transforms (Sphere.xform) */
    Triangle tri[4096];  uint nt;
    Box box[256];        uint nb;
    Plane pln[4];        uint np;
    KdTree tree;
    RenderParams params;
    SceneView view;             /* the kd-tree */
    Bvh bvh;
    RenderParams wide_params;
    SceneView wide_view;        /* the BVH */
} TestScene;

static TestScene scene;   /* large: static rather than on the stack */

static void scene_clear(void)
{
    kd_free(&scene.tree);
    bvh_free(&scene.bvh);
    scene.ns = scene.nt = scene.nb = scene.np = scene.nxf = 0;
}

static void add_sphere(vec3 c, float r)
{
    Sphere s = { c, r, 0, NO_INDEX, 0, 0 };
    scene.sph[scene.ns++] = s;
}
/* The unit sphere under translate(c) . rotate(angle about axis) . scale(a): a Sphere
 * with a SphereXform, its bounding sphere as scene_add_ellipsoid makes it. */
static void add_ellipsoid(vec3 c, vec3 a, vec3 axis, float angle)
{
    Transform t = transform_translate(c.x, c.y, c.z), r = transform_rotate(axis.x, axis.y, axis.z, angle),
              sc = transform_scale(a.x, a.y, a.z), inv;
    Transform m = transform_compose(&r, &sc);
    m = transform_compose(&t, &m);
    transform_invert(&m, &inv);
    SphereXform *x = &scene.xf[scene.nxf++];
    for (int i = 0; i < 12; i++) {
        x->to_world[i] = (float)m.m[i / 4][i % 4];
        x->to_object[i] = (float)inv.m[i / 4][i % 4];
    }
    Sphere s = { c, a.x + a.y + a.z, 0, NO_INDEX, scene.nxf, 0 };
    scene.sph[scene.ns++] = s;
}
static void add_triangle(vec3 a, vec3 b, vec3 c)
{
    Triangle t = { a, 0, b, NO_INDEX, c, NO_INDEX };
    scene.tri[scene.nt++] = t;
}
static void add_box(vec3 lo, vec3 hi)
{
    Box b = { lo, 0, hi, NO_INDEX };
    scene.box[scene.nb++] = b;
}
static void add_plane(vec3 n, float offset)
{
    Plane p = { n, offset, 0, 0, 0, 0 };
    scene.pln[scene.np++] = p;
}

/* Builds both trees and a SceneView of each for the kernel functions. */
static Status scene_build(int threads)
{
    KdInput in = { scene.sph, scene.ns, scene.tri, scene.nt, scene.box, scene.nb, NULL, 0, scene.xf, scene.nxf, NULL, 0 };
    Error err = { 0 };
    kd_free(&scene.tree);
    bvh_free(&scene.bvh);
    Status st = kd_build(&in, threads, &scene.tree, &err);
    if (st == ST_OK) st = bvh_build(&in, threads, &scene.bvh, &err);
    if (st != ST_OK) {
        fprintf(stderr, "  tree build: %s\n", err.msg);
        return st;
    }
    memset(&scene.params, 0, sizeof scene.params);
    scene.params.n_spheres = scene.ns;
    scene.params.n_triangles = scene.nt;
    scene.params.n_boxes = scene.nb;
    scene.params.n_planes = scene.np;
    scene.params.n_nodes = scene.tree.n_nodes;
    scene.params.n_leaf_prims = scene.tree.n_leaf_prims;
    scene.params.bounds_lo = scene.tree.lo;
    scene.params.bounds_hi = scene.tree.hi;
    /* named fields: the buffers this test does not use stay NULL whatever the list holds */
    SceneView v = { .params = &scene.params, .nodes = scene.tree.nodes, .leaf_prims = scene.tree.leaf_prims,
                    .spheres = scene.sph, .triangles = scene.tri, .boxes = scene.box, .planes = scene.pln,
                    .sphere_xforms = scene.xf };
    scene.view = v;
    scene.wide_params = scene.params;
    scene.wide_params.n_nodes = scene.wide_params.n_leaf_prims = 0;
    scene.wide_params.n_bvh_nodes = scene.bvh.n_nodes;
    SceneView w = { .params = &scene.wide_params, .bvh = scene.bvh.nodes, .bvh_leaves = scene.bvh.leaf_prims,
                    .spheres = scene.sph, .triangles = scene.tri, .boxes = scene.box, .planes = scene.pln,
                    .sphere_xforms = scene.xf };
    scene.wide_view = w;
    return ST_OK;
}

/* The tree the walk tests use: the kd-tree, or the BVH while walk_bvh is set. */
static int walk_bvh;
static const SceneView *walk_view(void) { return walk_bvh ? &scene.wide_view : &scene.view; }

/* Every primitive tested; primitives the builder leaves out (bounds not finite) are
 * left out here too. */
static int prim_finite(uint id)
{
    if (id < scene.ns) {
        const Sphere *s = &scene.sph[id];
        return isfinite(s->center.x) && isfinite(s->center.y) && isfinite(s->center.z) &&
               isfinite(s->radius);
    }
    id -= scene.ns;
    if (id < scene.nt) {
        const Triangle *t = &scene.tri[id];
        const float *f = &t->p0.x;
        return isfinite(f[0]) && isfinite(f[1]) && isfinite(f[2]) && isfinite(t->p1.x) &&
               isfinite(t->p1.y) && isfinite(t->p1.z) && isfinite(t->p2.x) &&
               isfinite(t->p2.y) && isfinite(t->p2.z);
    }
    id -= scene.nt;
    const Box *b = &scene.box[id];
    return isfinite(b->lo.x) && isfinite(b->lo.y) && isfinite(b->lo.z) && isfinite(b->hi.x) &&
           isfinite(b->hi.y) && isfinite(b->hi.z);
}

static Hit brute_closest(Ray ray)
{
    RayPre rp;
    ray_prepare(ray, &rp);
    Hit best = { ray.tmax, NO_INDEX, 0.0f, 0.0f, NO_INDEX, 0u, 0u, 0u };
    uint n = scene.ns + scene.nt + scene.nb;
    for (uint id = 0; id < n + scene.np; id++) {
        Ray r = ray;
        r.tmax = best.t;
        Hit h;
        int hit;
        if (id >= n) hit = plane_intersect(scene.pln[id - n], r, &h);
        else if (!prim_finite(id)) continue;
        else hit = trace_prim(&scene.view, id, &rp, r, &h);
        if (hit) {
            h.prim = id;
            best = h;
        }
    }
    return best;
}

static Ray make_ray(vec3 o, vec3 d, float tmin, float tmax)
{
    Ray r = { o, tmin, d, tmax };
    return r;
}

/* Compares the walk's answers with brute force for one ray; returns 1 if they agree:
 * the same primitive with the same t, u and v (the same function computed both; of
 * primitives at the same t, the lowest id: leaf_test's tie rule, which brute force
 * follows by testing in id order), and any-hit true exactly when there is a closest
 * hit. */
static int ray_agrees(Ray ray, int verbose)
{
    Hit a = trace_closest(walk_view(), ray), b = brute_closest(ray);
    int any = trace_any(walk_view(), ray);
    int ok;
    if (a.prim == NO_INDEX || b.prim == NO_INDEX) ok = a.prim == b.prim;
    else ok = a.prim == b.prim && a.t == b.t && a.u == b.u && a.v == b.v;
    ok = ok && any == (b.prim != NO_INDEX);
    if (!ok && verbose)
        fprintf(stderr, "  ray o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g) tmin %g tmax %g: %s %u t=%.9g, "
                "brute %u t=%.9g, any %d\n", ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z,
                ray.tmin, ray.tmax, walk_bvh ? "BVH" : "kd", a.prim, a.t, b.prim, b.t, any);
    return ok;
}

/* A random ray of one of several kinds: from outside or inside the scene's box, with
 * zero direction components, with a short tmax or a positive tmin. */
static Ray random_ray(float lo, float hi)
{
    float mid = 0.5f * (lo + hi), span = hi - lo;
    int kind = (int)(frand() * 6.0f);
    vec3 o = vrand(lo, hi), d = vrand(-1.0f, 1.0f);
    float tmin = 0.0f, tmax = K_INF;
    switch (kind) {
    case 0:   /* from far outside towards a point inside */
        o = v3_add(v3s(mid), v3_scale(v3_norm(vrand(-1.0f, 1.0f)), span * 1.5f));
        d = v3_sub(vrand(lo, hi), o);
        break;
    case 1:   /* one or two components exactly zero */
        d.x = frand() < 0.5f ? 0.0f : d.x;
        d.y = frand() < 0.5f ? 0.0f : d.y;
        if (d.x != 0.0f && d.y != 0.0f) d.z = 0.0f;
        if (v3_is_zero(d)) d.z = -1.0f;
        break;
    case 2:   /* short segment (shadow-ray like) */
        tmax = frange(0.0f, 1.0f);
        break;
    case 3:   /* starting a little way along */
        tmin = frange(0.0f, 0.5f);
        d = v3_scale(d, frange(0.1f, 10.0f));
        break;
    default:
        break;
    }
    return make_ray(o, d, tmin, tmax);
}

static void random_triangle(float lo, float hi, float size)
{
    vec3 c = vrand(lo, hi);
    add_triangle(v3_add(c, vrand(-size, size)), v3_add(c, vrand(-size, size)), v3_add(c, vrand(-size, size)));
}

/* Spheres, triangles of mixed sizes, boxes, axis-aligned flat triangles on integer
 * planes (so they lie exactly on candidate split planes), planes. */
static void random_scene(uint64_t seed, uint ns, uint nt, uint nb, uint np)
{
    scene_clear();
    rng_seed(seed);
    for (uint i = 0; i < ns; i++) add_sphere(vrand(-4.0f, 4.0f), frange(0.05f, 0.8f));
    for (uint i = 0; i < nt; i++) {
        uint kind = i % 4;
        if (kind == 0) random_triangle(-4.0f, 4.0f, 2.0f);
        else if (kind == 1) random_triangle(-4.0f, 4.0f, 0.3f);
        else if (kind == 2) {
            /* axis-aligned, in the plane axis = integer */
            int axis = (int)(frand() * 3.0f) % 3;
            float at = (float)((int)frange(-4.0f, 5.0f));
            vec3 p[3];
            for (int j = 0; j < 3; j++) {
                p[j] = vrand(-4.0f, 4.0f);
                if (axis == 0) p[j].x = at;
                else if (axis == 1) p[j].y = at;
                else p[j].z = at;
            }
            add_triangle(p[0], p[1], p[2]);
        } else random_triangle(-4.0f, 4.0f, 1.0f);
    }
    for (uint i = 0; i < nb; i++) {
        vec3 lo = vrand(-4.0f, 4.0f), hi = v3_add(lo, vrand(0.0f, 1.5f));
        if (i % 5 == 0) hi.y = lo.y;    /* flat */
        add_box(lo, hi);
    }
    if (np > 0) add_plane(v3(0.0f, 1.0f, 0.0f), -5.0f);
    if (np > 1) add_plane(v3_norm(v3(1.0f, 0.5f, 0.2f)), 6.0f);
}

/* ------------------------------------------------------------------ intersection */

static void test_sphere(void)
{
    Sphere s = { v3(0.0f, 0.0f, -5.0f), 1.0f, 0, NO_INDEX, 0, 0 };
    Hit h;
    CHECK(sphere_intersect(s, make_ray(v3s(0.0f), v3(0.0f, 0.0f, -1.0f), 0.0f, K_INF), &h));
    CHECK_NEAR(h.t, 4.0f, 1e-6);
    /* unnormalised direction: t scales inversely */
    CHECK(sphere_intersect(s, make_ray(v3s(0.0f), v3(0.0f, 0.0f, -2.0f), 0.0f, K_INF), &h));
    CHECK_NEAR(h.t, 2.0f, 1e-6);
    /* from inside: the far root */
    CHECK(sphere_intersect(s, make_ray(v3(0.0f, 0.0f, -5.0f), v3(1.0f, 0.0f, 0.0f), 0.0f, K_INF), &h));
    CHECK_NEAR(h.t, 1.0f, 1e-6);
    /* strict interval: tmax at the near root excludes it */
    CHECK(!sphere_intersect(s, make_ray(v3s(0.0f), v3(0.0f, 0.0f, -1.0f), 0.0f, 4.0f), &h));
    /* tmin past the near root gives the far one */
    CHECK(sphere_intersect(s, make_ray(v3s(0.0f), v3(0.0f, 0.0f, -1.0f), 4.5f, K_INF), &h));
    CHECK_NEAR(h.t, 6.0f, 1e-6);
    CHECK(!sphere_intersect(s, make_ray(v3s(0.0f), v3(0.0f, 1.0f, 0.0f), 0.0f, K_INF), &h));
    CHECK(!sphere_intersect(s, make_ray(v3s(0.0f), v3s(0.0f), 0.0f, K_INF), &h));
    /* a small sphere far away keeps its precision (the naive discriminant loses it) */
    Sphere far = { v3(0.0f, 0.0f, -10000.0f), 0.01f, 0, NO_INDEX, 0, 0 };
    CHECK(sphere_intersect(far, make_ray(v3s(0.0f), v3(0.0f, 0.0f, -1.0f), 0.0f, K_INF), &h));
    CHECK_NEAR(h.t, 9999.99f, 1e-3);
    CHECK(sphere_intersect(far, make_ray(v3s(0.0f), v3(0.0f, 0.0000009f, -1.0f), 0.0f, K_INF), &h));
}

static void test_triangle(void)
{
    Triangle t = { v3(0.0f, 0.0f, -2.0f), 0, v3(2.0f, 0.0f, -2.0f), NO_INDEX, v3(0.0f, 2.0f, -2.0f), NO_INDEX };
    rng_seed(7);
    for (int i = 0; i < 1000; i++) {
        vec3 o = vrand(-3.0f, 3.0f), target = v3(frange(0.0f, 2.0f), frange(0.0f, 2.0f), -2.0f);
        Ray r = make_ray(o, v3_scale(v3_sub(target, o), frange(0.5f, 3.0f)), 0.0f, K_INF);
        RayPre rp;
        ray_prepare(r, &rp);
        Hit h;
        int inside = target.x + target.y < 2.0f;
        int hit = triangle_intersect(&rp, &t, r, &h);
        if (fabsf(target.x + target.y - 2.0f) > 1e-4f && o.z != -2.0f) CHECK_EQ_INT(hit, inside);
        if (hit) {
            /* p = (1-u-v) p0 + u p1 + v p2 is the point o + t d */
            vec3 p = v3_madd(r.o, r.d, h.t);
            vec3 q = v3_add(v3_add(v3_scale(t.p0, 1.0f - h.u - h.v), v3_scale(t.p1, h.u)), v3_scale(t.p2, h.v));
            CHECK(v3_len(v3_sub(p, q)) < 1e-4f);
        }
    }
    /* both faces */
    Hit h;
    Ray down = make_ray(v3(0.5f, 0.5f, 0.0f), v3(0.0f, 0.0f, -1.0f), 0.0f, K_INF);
    Ray up = make_ray(v3(0.5f, 0.5f, -4.0f), v3(0.0f, 0.0f, 1.0f), 0.0f, K_INF);
    RayPre rpd, rpu;
    ray_prepare(down, &rpd);
    ray_prepare(up, &rpu);
    CHECK(triangle_intersect(&rpd, &t, down, &h));
    CHECK_NEAR(h.t, 2.0f, 1e-6);
    CHECK_NEAR(h.u, 0.25f, 1e-6);
    CHECK_NEAR(h.v, 0.25f, 1e-6);
    CHECK(triangle_intersect(&rpu, &t, up, &h));
    CHECK_NEAR(h.t, 2.0f, 1e-6);
    /* degenerate (zero area) and parallel: misses, no NaN trouble */
    Triangle flat = { v3(0.0f, 0.0f, -2.0f), 0, v3(1.0f, 1.0f, -2.0f), NO_INDEX, v3(2.0f, 2.0f, -2.0f), NO_INDEX };
    CHECK(!triangle_intersect(&rpd, &flat, down, &h));
    Ray side = make_ray(v3(-1.0f, 0.5f, -2.0f), v3(1.0f, 0.0f, 0.0f), 0.0f, K_INF);
    RayPre rps;
    ray_prepare(side, &rps);
    CHECK(!triangle_intersect(&rps, &t, side, &h));
    Ray nan_ray = make_ray(v3(NAN, 0.0f, 0.0f), v3(0.0f, 0.0f, -1.0f), 0.0f, K_INF);
    RayPre rpn;
    ray_prepare(nan_ray, &rpn);
    CHECK(!triangle_intersect(&rpn, &t, nan_ray, &h));
}

/* Rays through the shared edges and vertices of a mesh never slip through. */
static void test_watertight(void)
{
    /* A 6x6 grid of quads on a tilted plane, each split into two triangles. */
    enum { G = 6 };
    vec3 v[G + 1][G + 1];
    for (int i = 0; i <= G; i++)
        for (int j = 0; j <= G; j++) {
            float x = (float)i * 0.7f, y = (float)j * 0.45f;
            v[i][j] = v3(x, y, 0.3f * x - 0.17f * y + 1.0f);
        }
    Triangle tris[2 * G * G];
    int n = 0;
    for (int i = 0; i < G; i++)
        for (int j = 0; j < G; j++) {
            Triangle a = { v[i][j], 0, v[i + 1][j], NO_INDEX, v[i + 1][j + 1], NO_INDEX };
            Triangle b = { v[i][j], 0, v[i + 1][j + 1], NO_INDEX, v[i][j + 1], NO_INDEX };
            tris[n++] = a;
            tris[n++] = b;
        }
    rng_seed(11);
    int misses = 0, rays = 0;
    for (int k = 0; k < 20000; k++) {
        /* aim at an interior vertex, or at a point of an interior edge */
        int i = 1 + (int)(frand() * (G - 1)), j = 1 + (int)(frand() * (G - 1));
        vec3 target = v[i][j];
        int which = k % 4;
        float s = frand();
        if (which == 1) target = v3_add(v[i][j], v3_scale(v3_sub(v[i + 1][j], v[i][j]), s));
        if (which == 2) target = v3_add(v[i][j], v3_scale(v3_sub(v[i][j + 1], v[i][j]), s));
        if (which == 3) target = v3_add(v[i][j], v3_scale(v3_sub(v[i + 1][j + 1], v[i][j]), s));
        vec3 o = v3_add(target, v3_scale(vrand(-1.0f, 1.0f), 5.0f));
        if (k % 7 == 0) o = v3(target.x, target.y, 10.0f);   /* d has two zero components */
        Ray r = make_ray(o, v3_sub(target, o), 0.0f, K_INF);
        RayPre rp;
        ray_prepare(r, &rp);
        int hit = 0;
        Hit h;
        for (int t = 0; t < n; t++) hit |= triangle_intersect(&rp, &tris[t], r, &h);
        misses += !hit;
        rays++;
    }
    CHECK_EQ_INT(misses, 0);
    fprintf(stderr, "  watertight: %d rays through edges and vertices, %d misses\n", rays, misses);
}

/* The leaf group test (8 triangles at once) gives every lane bit for bit what the
 * one-triangle test gives, and reports the nearest lane, the first of equals. The groups
 * mix ordinary triangles, triangles sharing edges (rays through the edges give exact
 * zeros, re-evaluated exactly), repeats (as the unused lanes of a group hold) and
 * degenerate ones. */
static void test_group_intersect(void)
{
    rng_seed(12);
    int checked = 0, hits = 0, bad = 0;
    for (int k = 0; k < 3000; k++) {
        Triangle tri[KD_GROUP];
        vec3 a = vrand(-2.0f, 2.0f), b = vrand(-2.0f, 2.0f), c = vrand(-2.0f, 2.0f);
        for (uint l = 0; l < KD_GROUP; l++) {
            vec3 p0 = vrand(-2.0f, 2.0f), p1 = vrand(-2.0f, 2.0f), p2 = vrand(-2.0f, 2.0f);
            if (l == 1) { p0 = a; p1 = b; p2 = c; }                  /* a fan around edge a-b */
            if (l == 2) { p0 = b; p1 = a; p2 = vrand(-2.0f, 2.0f); }
            if (l == 3) { p0 = a; p1 = a; p2 = c; }                  /* degenerate */
            if (l == 7 && k % 2) { p0 = tri[6].p0; p1 = tri[6].p1; p2 = tri[6].p2; }   /* a repeat */
            Triangle t = { p0, 0, p1, NO_INDEX, p2, NO_INDEX };
            tri[l] = t;
        }
        float rows[9 * KD_GROUP];
        for (uint l = 0; l < KD_GROUP; l++) {
            const float f[9] = { tri[l].p0.x, tri[l].p0.y, tri[l].p0.z, tri[l].p1.x, tri[l].p1.y,
                                 tri[l].p1.z, tri[l].p2.x, tri[l].p2.y, tri[l].p2.z };
            for (uint r = 0; r < 9; r++) rows[r * KD_GROUP + l] = f[r];
        }
        if (k % 4 == 3) {
            /* small integer corners and rays along an axis through integer points: edge
             * functions exactly 0, which the exact re-evaluation decides */
            for (uint l = 0; l < KD_GROUP; l++) {
                vec3 *p[3] = { &tri[l].p0, &tri[l].p1, &tri[l].p2 };
                for (int q = 0; q < 3; q++)
                    *p[q] = v3(floorf(frange(0.0f, 3.0f)), floorf(frange(0.0f, 3.0f)), floorf(frange(0.0f, 3.0f)));
            }
            for (uint l = 0; l < KD_GROUP; l++) {
                const float f[9] = { tri[l].p0.x, tri[l].p0.y, tri[l].p0.z, tri[l].p1.x, tri[l].p1.y,
                                     tri[l].p1.z, tri[l].p2.x, tri[l].p2.y, tri[l].p2.z };
                for (uint r = 0; r < 9; r++) rows[r * KD_GROUP + l] = f[r];
            }
            a = v3(floorf(frange(0.0f, 3.0f)), floorf(frange(0.0f, 3.0f)), -1.0f);
        }
        /* aim at the shared edge, a vertex or anywhere */
        float s = frand();
        vec3 target = k % 3 == 0 ? v3_add(a, v3_scale(v3_sub(b, a), s)) : k % 3 == 1 ? a : vrand(-2.0f, 2.0f);
        vec3 o = v3_add(target, v3_scale(vrand(-1.0f, 1.0f), 4.0f));
        if (k % 4 == 3) {
            target = v3(a.x, a.y, 5.0f);
            o = a;
        }
        float tmax = k % 5 == 0 ? frange(0.2f, 1.2f) : K_INF;
        Ray r = make_ray(o, v3_sub(target, o), k % 7 == 0 ? 0.5f : 0.0f, tmax);
        RayPre rp;
        ray_prepare(r, &rp);
        Hit g;
        uint mask = triangle_intersect_group(&rp, rows, r.tmin, r.tmax, &g);
        Hit best = { r.tmax, NO_INDEX, 0.0f, 0.0f, NO_INDEX, 0u, 0u, 0u };
        for (uint l = 0; l < KD_GROUP; l++) {
            Hit h;
            int one = triangle_intersect(&rp, &tri[l], r, &h);
            bad += one != (int)((mask >> l) & 1u);
            if (one && h.t < best.t) {
                best = h;
                best.prim = l;
            }
            checked++;
        }
        if (best.prim != NO_INDEX) {
            hits++;
            bad += mask == 0 || g.prim != best.prim || memcmp(&g.t, &best.t, sizeof g.t) != 0 ||
                   memcmp(&g.u, &best.u, sizeof g.u) != 0 || memcmp(&g.v, &best.v, sizeof g.v) != 0;
        }
    }
    CHECK_EQ_INT(bad, 0);
    fprintf(stderr, "  %d lanes, %d groups hit, %d differ from the one-triangle test\n", checked, hits, bad);
}

static void test_box(void)
{
    Box b = { v3(-1.0f, -1.0f, -1.0f), 0, v3(1.0f, 1.0f, 1.0f), NO_INDEX };
    Ray r = make_ray(v3s(0.0f), v3s(0.0f), 0.0f, K_INF);
    Hit h;
    /* from outside along each axis: the entry face; from inside: the exit face */
    for (int axis = 0; axis < 3; axis++)
        for (int sgn = 0; sgn < 2; sgn++) {
            float dir = sgn ? -1.0f : 1.0f;
            vec3 d = v3(axis == 0 ? dir : 0.0f, axis == 1 ? dir : 0.0f, axis == 2 ? dir : 0.0f);
            r = make_ray(v3_scale(d, -3.0f), v3_scale(d, 2.0f), 0.0f, K_INF);
            RayPre rp;
            ray_prepare(r, &rp);
            CHECK(box_intersect(&rp, b, r, &h));
            CHECK_NEAR(h.t, 1.0f, 1e-6);
            CHECK_EQ_INT((int)h.u, 2 * axis + sgn);           /* entering +x hits the -x face */
            r = make_ray(v3(0.1f, 0.2f, 0.3f), d, 0.0f, K_INF);
            ray_prepare(r, &rp);
            CHECK(box_intersect(&rp, b, r, &h));
            CHECK_EQ_INT((int)h.u, 2 * axis + (1 - sgn));     /* leaving +x through +x */
        }
    /* oblique, hits the +y face first */
    r = make_ray(v3(0.0f, 5.0f, 0.0f), v3(0.1f, -1.0f, 0.05f), 0.0f, K_INF);
    RayPre rp;
    ray_prepare(r, &rp);
    CHECK(box_intersect(&rp, b, r, &h));
    CHECK_EQ_INT((int)h.u, 3);
    CHECK_NEAR(h.t, 4.0f, 1e-6);
    /* miss, parallel outside, a flat box hit on its face */
    r = make_ray(v3(0.0f, 5.0f, 0.0f), v3(1.0f, 0.0f, 0.0f), 0.0f, K_INF);
    ray_prepare(r, &rp);
    CHECK(!box_intersect(&rp, b, r, &h));
    Box flat = { v3(-1.0f, 0.0f, -1.0f), 0, v3(1.0f, 0.0f, 1.0f), NO_INDEX };
    r = make_ray(v3(0.2f, 3.0f, 0.1f), v3(0.0f, -1.0f, 0.0f), 0.0f, K_INF);
    ray_prepare(r, &rp);
    CHECK(box_intersect(&rp, flat, r, &h));
    CHECK_NEAR(h.t, 3.0f, 1e-6);
    CHECK_EQ_INT((int)h.u, 3);
}

static void test_plane(void)
{
    Plane p = { v3(0.0f, 1.0f, 0.0f), 2.0f, 0, 0, 0, 0 };
    Hit h;
    CHECK(plane_intersect(p, make_ray(v3s(0.0f), v3(0.0f, 1.0f, 0.0f), 0.0f, K_INF), &h));
    CHECK_NEAR(h.t, 2.0f, 1e-6);
    CHECK(plane_intersect(p, make_ray(v3(0.0f, 5.0f, 0.0f), v3(0.3f, -0.5f, 0.0f), 0.0f, K_INF), &h));
    CHECK_NEAR(h.t, 6.0f, 1e-6);
    CHECK(!plane_intersect(p, make_ray(v3s(0.0f), v3(1.0f, 0.0f, 0.0f), 0.0f, K_INF), &h));
    CHECK(!plane_intersect(p, make_ray(v3s(0.0f), v3(0.0f, -1.0f, 0.0f), 0.0f, K_INF), &h));
}

/* ------------------------------------------------------------------ tree structure */

/* Separating-axis test of a triangle against a box given by centre and half extents
 * (Akenine-Moller), in double: a check independent of the builder's clipping. */
static int axis_separates(double v[3][3], const double h[3], const double a[3])
{
    double p0 = v[0][0] * a[0] + v[0][1] * a[1] + v[0][2] * a[2];
    double p1 = v[1][0] * a[0] + v[1][1] * a[1] + v[1][2] * a[2];
    double p2 = v[2][0] * a[0] + v[2][1] * a[1] + v[2][2] * a[2];
    double r = h[0] * fabs(a[0]) + h[1] * fabs(a[1]) + h[2] * fabs(a[2]);
    double mn = fmin(p0, fmin(p1, p2)), mx = fmax(p0, fmax(p1, p2));
    return mn > r || mx < -r;
}

static int triangle_overlaps_box(const Triangle *t, const double lo[3], const double hi[3])
{
    double c[3], h[3], v[3][3];
    const vec3 *p[3] = { &t->p0, &t->p1, &t->p2 };
    for (int k = 0; k < 3; k++) {
        c[k] = 0.5 * (lo[k] + hi[k]);
        h[k] = 0.5 * (hi[k] - lo[k]);
    }
    for (int i = 0; i < 3; i++) {
        v[i][0] = p[i]->x - c[0];
        v[i][1] = p[i]->y - c[1];
        v[i][2] = p[i]->z - c[2];
    }
    double e[3][3];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) e[i][k] = v[(i + 1) % 3][k] - v[i][k];
    for (int k = 0; k < 3; k++) {
        double a[3] = { k == 0, k == 1, k == 2 };
        if (axis_separates(v, h, a)) return 0;
    }
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            double u[3] = { k == 0, k == 1, k == 2 };
            double a[3] = { e[i][1] * u[2] - e[i][2] * u[1], e[i][2] * u[0] - e[i][0] * u[2],
                            e[i][0] * u[1] - e[i][1] * u[0] };
            if (axis_separates(v, h, a)) return 0;
        }
    double n[3] = { e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                    e[0][0] * e[1][1] - e[0][1] * e[1][0] };
    return !axis_separates(v, h, n);
}

static int bounds_overlap_box(const double plo[3], const double phi[3], const double lo[3], const double hi[3])
{
    for (int k = 0; k < 3; k++)
        if (plo[k] > hi[k] || phi[k] < lo[k]) return 0;
    return 1;
}

/* Must primitive `id` be in a leaf with box lo..hi? Yes if its geometry (a sphere's
 * or box's bounding box, a triangle itself) meets the box shrunk by eps: touching the
 * boundary, or lying in it (a flat primitive on a split plane), asks for nothing. */
static int must_contain(uint id, const double lo_in[3], const double hi_in[3], double eps)
{
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = lo_in[k] + eps;
        hi[k] = hi_in[k] - eps;
        if (lo[k] > hi[k]) return 0;
    }
    if (id < scene.ns) {
        const Sphere *s = &scene.sph[id];
        double r = fabs(s->radius), c[3] = { s->center.x, s->center.y, s->center.z };
        double plo[3] = { c[0] - r, c[1] - r, c[2] - r }, phi[3] = { c[0] + r, c[1] + r, c[2] + r };
        return bounds_overlap_box(plo, phi, lo, hi);
    }
    if (id < scene.ns + scene.nt) return triangle_overlaps_box(&scene.tri[id - scene.ns], lo, hi);
    const Box *b = &scene.box[id - scene.ns - scene.nt];
    double plo[3] = { b->lo.x, b->lo.y, b->lo.z }, phi[3] = { b->hi.x, b->hi.y, b->hi.z };
    return bounds_overlap_box(plo, phi, lo, hi);
}

typedef struct { double lo[3], hi[3]; } DBox;

static double half_area(const DBox *b)
{
    double dx = b->hi[0] - b->lo[0], dy = b->hi[1] - b->lo[1], dz = b->hi[2] - b->lo[2];
    return dx * dy + dy * dz + dz * dx;
}

/* Walks the flattened tree checking nesting, leaf contents and the statistics. */
static void check_tree(void)
{
    const KdTree *t = &scene.tree;
    uint n_prims = scene.ns + scene.nt + scene.nb;
    DBox root = { { t->lo.x, t->lo.y, t->lo.z }, { t->hi.x, t->hi.y, t->hi.z } };
    double diag = sqrt(k_sqr((float)(root.hi[0] - root.lo[0])) + k_sqr((float)(root.hi[1] - root.lo[1])) +
                       k_sqr((float)(root.hi[2] - root.lo[2])));
    double eps = 1e-5 * diag, root_area = half_area(&root);
    /* the root box holds every primitive's bounds */
    for (uint id = 0; id < n_prims; id++) {
        DBox huge = { { -1e30, -1e30, -1e30 }, { 1e30, 1e30, 1e30 } };
        if (!prim_finite(id)) continue;
        CHECK(must_contain(id, huge.lo, huge.hi, 0.0));
    }
    uint stack_node[KD_MAX_DEPTH + 1];
    DBox stack_box[KD_MAX_DEPTH + 1];
    int stack_depth[KD_MAX_DEPTH + 1], sp = 0;
    stack_node[sp] = 0;
    stack_box[sp] = root;
    stack_depth[sp++] = 0;
    unsigned char *seen = calloc(n_prims + 1, 1);
    uint leaves = 0, empty = 0, max_depth = 0, visited = 0, missing = 0, bad_nesting = 0;
    double sah = 0.0;
    while (sp > 0) {
        sp--;
        uint ni = stack_node[sp];
        DBox box = stack_box[sp];
        int depth = stack_depth[sp];
        visited++;
        if ((uint)depth > max_depth) max_depth = (uint)depth;
        CHECK(ni < t->n_nodes);
        if (ni >= t->n_nodes) break;
        KdNode n = t->nodes[ni];
        uint axis = n.bits & 3u;
        if (axis != KD_LEAF) {
            float split = k_as_float(n.data);
            uint above = n.bits >> 4;
            /* the empty-child marks say exactly which children are empty leaves */
            CHECK_EQ_INT((n.bits & KD_EMPTY_BELOW) != 0, t->nodes[ni + 1].bits == KD_LEAF);
            if (above < t->n_nodes) CHECK_EQ_INT((n.bits & KD_EMPTY_ABOVE) != 0, t->nodes[above].bits == KD_LEAF);
            /* children nest: the split is strictly inside the parent's extent */
            if (!(split > box.lo[axis] && split < box.hi[axis])) bad_nesting++;
            CHECK(above > ni + 1 && above < t->n_nodes);
            sah += KD_COST_TRAVERSAL * half_area(&box) / root_area;
            DBox below = box, up = box;
            below.hi[axis] = split;
            up.lo[axis] = split;
            CHECK(sp + 2 <= KD_MAX_DEPTH);
            if (sp + 2 > KD_MAX_DEPTH) break;
            stack_node[sp] = above; stack_box[sp] = up; stack_depth[sp++] = depth + 1;
            stack_node[sp] = ni + 1; stack_box[sp] = below; stack_depth[sp++] = depth + 1;
            continue;
        }
        uint *ids = malloc((n_prims + 1) * sizeof *ids);
        uint count = kd_leaf_ids(t, ni, ids, n_prims + 1);
        CHECK(count <= n_prims);
        leaves++;
        empty += count == 0;
        sah += kd_leaf_cost(count) * half_area(&box) / root_area;
        unsigned char *in_leaf = calloc(n_prims + 1, 1);
        for (uint i = 0; i < count; i++) {
            uint id = ids[i];
            CHECK(id < n_prims);
            if (id >= n_prims) continue;
            CHECK(!in_leaf[id]);   /* unique */
            in_leaf[id] = 1;
            seen[id] = 1;
        }
        free(ids);
        /* the leaf record: its groups hold the triangles' corners, in increasing id
         * order, the last one repeated in the unused lanes; then the others' count */
        const uint *g = t->leaf_prims + n.data;
        uint prev = 0, groups = n.bits >> 3;
        for (uint gi = 0; gi < groups; gi++, g += KD_GROUP_WORDS)
            for (uint l = 0; l < KD_GROUP; l++) {
                uint id = g[l];
                CHECK(id >= scene.ns && id < scene.ns + scene.nt);
                if (id < scene.ns || id >= scene.ns + scene.nt) continue;
                CHECK(gi + l == 0 || id >= prev);
                prev = id;
                const Triangle *tr = &scene.tri[id - scene.ns];
                const float want[9] = { tr->p0.x, tr->p0.y, tr->p0.z, tr->p1.x, tr->p1.y, tr->p1.z,
                                        tr->p2.x, tr->p2.y, tr->p2.z };
                for (uint r = 0; r < 9; r++) {
                    float got;
                    memcpy(&got, &g[KD_GROUP + r * KD_GROUP + l], sizeof got);
                    CHECK(memcmp(&got, &want[r], sizeof got) == 0);
                }
            }
        if (n.bits & KD_LEAF_OTHERS) CHECK(g[0] >= 1 && g[0] <= count);
        for (uint id = 0; id < n_prims; id++)
            if (!in_leaf[id] && prim_finite(id) && must_contain(id, box.lo, box.hi, eps)) missing++;
        free(in_leaf);
    }
    CHECK_EQ_INT(bad_nesting, 0);
    CHECK_EQ_INT(missing, 0);
    CHECK_EQ_INT(visited, t->n_nodes);
    for (uint id = 0; id < n_prims; id++)
        if (prim_finite(id)) CHECK(seen[id]);
    free(seen);
    const KdStats *st = &t->stats;
    CHECK_EQ_INT(st->n_nodes, t->n_nodes);
    CHECK_EQ_INT(st->n_leaves, leaves);
    CHECK_EQ_INT(st->n_empty_leaves, empty);
    CHECK_EQ_INT(st->max_depth, max_depth);
    CHECK(st->max_depth <= KD_MAX_DEPTH - 1);
    CHECK_EQ_INT(st->bytes, (size_t)t->n_nodes * sizeof(KdNode) + (size_t)t->n_leaf_prims * sizeof(uint));
    CHECK_NEAR(st->sah_cost, sah, 1e-6 * sah);
    /* The build minimises the SAH with the empty-space bonus (cuts off empty space even
     * where the plain SAH says it does not pay): by that measure the tree is never worse
     * than a single leaf. */
    CHECK(st->sah_cost_bonus <= st->leaf_sah_cost);
    CHECK(st->sah_cost_bonus <= st->sah_cost);
    CHECK_NEAR(st->leaf_sah_cost, kd_leaf_cost(st->n_prims), 1e-9);
}

static void test_structure(void)
{
    const uint64_t seeds[] = { 1, 2, 3, 4 };
    for (int i = 0; i < 4; i++) {
        random_scene(seeds[i], 30, 160, 20, 0);
        CHECK(scene_build(0) == ST_OK);
        check_tree();
        CHECK_EQ_INT(scene.tree.stats.n_prims, 210);
    }
    /* only tiny triangles: leaves hold them without copies all over */
    scene_clear();
    rng_seed(9);
    for (int i = 0; i < 2000; i++) random_triangle(0.0f, 10.0f, 0.02f);
    CHECK(scene_build(1) == ST_OK);
    check_tree();
    const KdStats *st = &scene.tree.stats;
    CHECK(st->mean_prims_per_leaf * (st->n_leaves - st->n_empty_leaves) < 1.5 * 2000);
    CHECK(st->sah_cost < 0.15 * st->leaf_sah_cost);   /* 0.12 with the default constants */
    fprintf(stderr, "  2000 tiny triangles: SAH cost %.1f (one leaf: %.1f), %.2f refs per triangle\n", st->sah_cost,
            st->leaf_sah_cost, st->mean_prims_per_leaf * (st->n_leaves - st->n_empty_leaves) / 2000.0);
}

/* Walks the BVH checking that every child box holds what is below it (the primitives'
 * bounds, the grandchildren's boxes), that every primitive with finite bounds is in
 * exactly one leaf, the leaf records (the kd-tree's layout, written by the same code,
 * so their corner copies are checked there), unused lanes, and the statistics. */
static void check_bvh(void)
{
    const Bvh *t = &scene.bvh;
    uint n_prims = scene.ns + scene.nt + scene.nb;
    unsigned char *seen = calloc(n_prims + 1, 1);
    uint *ids = malloc((n_prims + 1) * sizeof *ids);
    uint stack[512], depth_of[512], sp = 0, visited = 0, leaves = 0, max_depth = 0, bad_box = 0, dup = 0;
    stack[sp] = 0;
    depth_of[sp++] = 1;
    while (sp > 0) {
        sp--;
        uint ni = stack[sp], depth = depth_of[sp];
        CHECK(ni < t->n_nodes);
        if (ni >= t->n_nodes) break;
        visited++;
        if (depth > max_depth) max_depth = depth;
        const BvhNode *n = &t->nodes[ni];
        int unused_seen = 0;
        for (uint l = 0; l < BVH_WIDTH; l++) {
            DBox box = { { n->box[0][l], n->box[2][l], n->box[4][l] }, { n->box[1][l], n->box[3][l], n->box[5][l] } };
            if (n->kind[l] == BVH_CHILD_NONE) {
                /* an empty box no ray enters; used lanes come first */
                CHECK(n->box[0][l] == INFINITY && n->box[1][l] == -INFINITY);
                unused_seen = 1;
                continue;
            }
            CHECK(!unused_seen);
            if (n->kind[l] == BVH_CHILD_NODE) {
                CHECK(n->ref[l] > ni && n->ref[l] < t->n_nodes);   /* parents first */
                if (n->ref[l] >= t->n_nodes) continue;
                const BvhNode *c = &t->nodes[n->ref[l]];
                for (uint m = 0; m < BVH_WIDTH; m++) {
                    if (c->kind[m] == BVH_CHILD_NONE) continue;
                    for (int k = 0; k < 3; k++)
                        bad_box += !(c->box[2 * k][m] >= box.lo[k] && c->box[2 * k + 1][m] <= box.hi[k]);
                }
                CHECK(sp < 512);
                if (sp >= 512) break;
                stack[sp] = n->ref[l];
                depth_of[sp++] = depth + 1;
                continue;
            }
            /* a leaf: its record's ids, each inside the lane's box */
            CHECK_EQ_INT(n->kind[l] & 3u, KD_LEAF);
            leaves++;
            const uint *g = t->leaf_prims + n->ref[l];
            uint count = 0, groups = n->kind[l] >> 3;
            for (uint gi = 0; gi < groups; gi++, g += KD_GROUP_WORDS)
                for (uint k = 0; k < KD_GROUP; k++)
                    if (count == 0 || g[k] != ids[count - 1]) ids[count++] = g[k];
            if (n->kind[l] & KD_LEAF_OTHERS)
                for (uint k = 1; k <= g[0]; k++) ids[count++] = g[k];
            CHECK(count >= 1);
            for (uint i = 0; i < count; i++) {
                uint id = ids[i];
                CHECK(id < n_prims);
                if (id >= n_prims) continue;
                dup += seen[id];
                seen[id] = 1;
                CHECK(must_contain(id, box.lo, box.hi, 0.0));
            }
        }
    }
    CHECK_EQ_INT(bad_box, 0);
    CHECK_EQ_INT(dup, 0);
    CHECK_EQ_INT(visited, t->n_nodes);
    uint finite = 0;
    for (uint id = 0; id < n_prims; id++) {
        finite += prim_finite(id);
        CHECK_EQ_INT(seen[id], prim_finite(id));
    }
    CHECK_EQ_INT(t->stats.n_nodes, t->n_nodes);
    CHECK_EQ_INT(t->stats.n_leaves, leaves);
    CHECK_EQ_INT(t->stats.max_depth, max_depth);
    CHECK_EQ_INT(t->stats.n_skipped, n_prims - finite);
    CHECK(t->stats.max_stack <= BVH_STACK);
    free(seen);
    free(ids);
}

static void test_bvh_structure(void)
{
    const uint64_t seeds[] = { 1, 2, 3, 4 };
    for (int i = 0; i < 4; i++) {
        random_scene(seeds[i], 30, 160, 20, 0);
        CHECK(scene_build(0) == ST_OK);
        check_bvh();
    }
    /* 2000 tiny triangles: wide nodes, leaves of a few groups at most */
    scene_clear();
    rng_seed(9);
    for (int i = 0; i < 2000; i++) random_triangle(0.0f, 10.0f, 0.02f);
    CHECK(scene_build(1) == ST_OK);
    check_bvh();
    const BvhStats *st = &scene.bvh.stats;
    CHECK(st->n_leaves >= 2000 / 32 && st->mean_prims_per_leaf <= 32.0);
    CHECK(st->n_nodes < st->n_leaves);   /* nodes hold several children each */
    fprintf(stderr, "  2000 tiny triangles: %u nodes, %u leaves (%.1f triangles each), depth %u, SAH cost %.2f\n",
            st->n_nodes, st->n_leaves, st->mean_prims_per_leaf, st->max_depth, st->sah_cost);
}

/* Inputs that defeat the binned SAH: a thousand copies of one triangle (one centre:
 * no split, one leaf of many groups) and triangles at exponentially growing distances
 * (nearly all centres in the first bin at every level: a deep chain, cut at the depth
 * limit, whose wide nodes turn binary before the walk's stack could fill). The walk
 * still agrees with brute force. */
static void test_bvh_degenerate(void)
{
    scene_clear();
    for (int i = 0; i < 1000; i++) add_triangle(v3(0.0f, 0.0f, 1.0f), v3(1.0f, 0.0f, 1.0f), v3(0.0f, 1.0f, 1.0f));
    add_triangle(v3(-1.0f, -1.0f, 3.0f), v3(2.0f, -1.0f, 3.0f), v3(-1.0f, 2.0f, 3.0f));
    CHECK(scene_build(0) == ST_OK);
    check_bvh();
    walk_bvh = 1;
    Ray r = make_ray(v3(0.2f, 0.2f, 0.0f), v3(0.0f, 0.0f, 1.0f), 0.0f, K_INF);
    Hit h = trace_closest(walk_view(), r);
    CHECK(h.prim < 1000u && h.t == 1.0f);
    CHECK(ray_agrees(r, 1));
    scene_clear();
    float x = 1.0f;
    for (int i = 0; i < 3000; i++, x *= 1.02f)
        add_triangle(v3(x, 0.0f, 0.0f), v3(x, 1.0f, 0.0f), v3(x, 0.0f, 1.0f));
    CHECK(scene_build(0) == ST_OK);
    check_bvh();
    /* deep enough that nodes near the bottom had to turn binary (past BVH_STACK - 40 - 7
     * entries, bvh_collapse.c), and still within the walk's stack */
    CHECK(scene.bvh.stats.max_stack > BVH_STACK - 40 - 7 && scene.bvh.stats.max_stack <= BVH_STACK);
    rng_seed(23);
    int bad = 0;
    for (int i = 0; i < 5000; i++) {
        vec3 o = v3(frange(-10.0f, x), frange(-0.5f, 1.5f), frange(-0.5f, 1.5f));
        Ray ray = make_ray(o, vrand(-1.0f, 1.0f), 0.0f, K_INF);
        if (i % 2) ray.d = v3(frand() < 0.5f ? 1.0f : -1.0f, 0.0f, 0.0f);   /* along the chain */
        bad += !ray_agrees(ray, bad < 3);
    }
    CHECK_EQ_INT(bad, 0);
    fprintf(stderr, "  a chain of 3000 triangles: binary depth %u, %u wide levels, stack %u, %d of 5000 rays disagree\n",
            scene.bvh.stats.max_binary_depth, scene.bvh.stats.max_depth, scene.bvh.stats.max_stack, bad);
    walk_bvh = 0;
}

/* ------------------------------------------------------------------ traversal */

static void test_against_brute_force_once(void)
{
    struct { uint64_t seed; uint ns, nt, nb, np; int rays; } cases[] = {
        { 21, 40, 200, 25, 2, 30000 },
        { 22, 0, 400, 0, 0, 30000 },
        { 23, 120, 0, 60, 1, 20000 },
        { 24, 10, 300, 10, 2, 30000 },
    };
    int total = 0, bad = 0;
    for (int c = 0; c < 4; c++) {
        random_scene(cases[c].seed, cases[c].ns, cases[c].nt, cases[c].nb, cases[c].np);
        CHECK(scene_build(0) == ST_OK);
        int hits = 0;
        for (int i = 0; i < cases[c].rays; i++) {
            Ray r = random_ray(-5.0f, 5.0f);
            bad += !ray_agrees(r, bad < 5);
            hits += trace_any(walk_view(), r);
            total++;
        }
        CHECK(hits > cases[c].rays / 10);    /* the scenes are not trivially missed */
    }
    CHECK_EQ_INT(bad, 0);
    fprintf(stderr, "  %s: %d random rays, %d disagree with brute force\n", walk_bvh ? "BVH" : "kd-tree", total, bad);
}

/* The kd-tree, then the BVH. */
static void test_against_brute_force(void)
{
    for (walk_bvh = 0; walk_bvh < 2; walk_bvh++) test_against_brute_force_once();
    walk_bvh = 0;
}

/* Ellipsoids (spheres under a transform) among spheres and triangles: their boxes
 * (the transform's rows, kdtree.c) hold them, so both trees find what brute force does,
 * and a ray through the rim of each box's extent finds the ellipsoid there. */
static void test_ellipsoids(void)
{
    float lo[3], hi[3];
    /* scale (2, 1, 0.5) turned 90 degrees about z: x reaches 1, y 2, z 0.5 */
    scene_clear();
    add_ellipsoid(v3(1.0f, 2.0f, 3.0f), v3(2.0f, 1.0f, 0.5f), v3(0.0f, 0.0f, 1.0f), 90.0f);
    KdInput in = { scene.sph, scene.ns, NULL, 0, NULL, 0, NULL, 0, scene.xf, scene.nxf, NULL, 0 };
    CHECK(kd_prim_box(&in, 0, lo, hi));
    CHECK_NEAR(lo[0], 0.0, 1e-5);
    CHECK_NEAR(hi[1], 4.0, 1e-5);
    CHECK_NEAR(hi[2], 3.5, 1e-5);
    CHECK(hi[1] >= 4.0f && lo[2] <= 2.5f);
    for (walk_bvh = 0; walk_bvh < 2; walk_bvh++) {
        random_scene(25, 30, 200, 0, 0);
        rng_seed(99);
        for (int i = 0; i < 80; i++)
            add_ellipsoid(vrand(-4.0f, 4.0f), vrand(0.05f, 1.2f), vrand(-1.0f, 1.0f), frange(0.0f, 180.0f));
        CHECK(scene_build(0) == ST_OK);
        int bad = 0, hits = 0;
        for (int i = 0; i < 30000; i++) {
            Ray r = random_ray(-5.0f, 5.0f);
            bad += !ray_agrees(r, bad < 5);
            Hit h = trace_closest(walk_view(), r);
            hits += h.prim != NO_INDEX && h.prim < scene.ns && scene.sph[h.prim].xform != 0u;
        }
        fprintf(stderr, "  %s: 30000 rays among 80 ellipsoids, %d hit one, %d disagree with brute force\n",
                walk_bvh ? "BVH" : "kd-tree", hits, bad);
        CHECK_EQ_INT(bad, 0);
        CHECK(hits > 1000);
    }
    walk_bvh = 0;
}

/* Two rays walked in turns (trace_closest2, trace_any2) give each ray bit for bit what
 * it gets alone, on every kind of scene and ray (planes, spheres, boxes, NaN, zero
 * components). */
static void test_pairs(void)
{
    struct { uint64_t seed; uint ns, nt, nb, np; } cases[] = {
        { 81, 40, 200, 25, 2 }, { 82, 0, 400, 0, 0 }, { 83, 120, 0, 60, 1 },
    };
    int differ = 0, total = 0;
    for (int c = 0; c < 3; c++) {
        random_scene(cases[c].seed, cases[c].ns, cases[c].nt, cases[c].nb, cases[c].np);
        CHECK(scene_build(0) == ST_OK);
        for (int i = 0; i < 10000; i++) {
            Ray a = random_ray(-5.0f, 5.0f), b = random_ray(-5.0f, 5.0f);
            if (i % 97 == 0) a.o.x = NAN;
            Hit ha, hb, sa = trace_closest(&scene.view, a), sb = trace_closest(&scene.view, b);
            trace_closest2(&scene.view, a, b, &ha, &hb);
            int oa, ob;
            trace_any2(&scene.view, a, b, &oa, &ob);
            differ += memcmp(&ha, &sa, sizeof ha) != 0 || memcmp(&hb, &sb, sizeof hb) != 0;
            differ += oa != trace_any(&scene.view, a) || ob != trace_any(&scene.view, b);
            total++;
        }
    }
    CHECK_EQ_INT(differ, 0);
    fprintf(stderr, "  %d pairs of rays, %d differ from the rays traced alone\n", total, differ);
}

/* ------------------------------------------------------------------ real meshes */

typedef struct {
    Scene scene;
    KdTree tree;
    RenderParams params;
    SceneView view;
    Bvh bvh;
    RenderParams wide_params;
    SceneView wide_view;
} MeshScene;

/* Loads a mesh file (or "sphere:N", the closed procedural sphere) and builds its tree. */
static int mesh_scene_open(MeshScene *m, const char *what)
{
    memset(m, 0, sizeof *m);
    scene_init(&m->scene);
    Error err = { 0 };
    Status st;
    if (strncmp(what, "sphere:", 7) == 0) {
        st = mesh_make_sphere(&m->scene, (size_t)atol(what + 7), 0, &err);
    } else {
        MeshOptions o = mesh_options(0);
        st = mesh_load(what, &m->scene, &o, &err);
    }
    KdInput in = { NULL, 0, m->scene.triangles, m->scene.n_triangles, NULL, 0, NULL, 0, NULL, 0, NULL, 0 };
    if (st == ST_OK) st = kd_build(&in, 0, &m->tree, &err);
    if (st == ST_OK) st = bvh_build(&in, 0, &m->bvh, &err);
    if (st != ST_OK) {
        fprintf(stderr, "  %s: %s\n", what, err.msg);
        return -1;
    }
    m->params.n_triangles = (uint)m->scene.n_triangles;
    m->params.n_nodes = m->tree.n_nodes;
    m->params.n_leaf_prims = m->tree.n_leaf_prims;
    m->params.bounds_lo = m->tree.lo;
    m->params.bounds_hi = m->tree.hi;
    m->view = (SceneView){ .params = &m->params, .nodes = m->tree.nodes, .leaf_prims = m->tree.leaf_prims,
                           .triangles = m->scene.triangles };
    m->wide_params = m->params;
    m->wide_params.n_nodes = m->wide_params.n_leaf_prims = 0;
    m->wide_params.n_bvh_nodes = m->bvh.n_nodes;
    m->wide_view = (SceneView){ .params = &m->wide_params, .bvh = m->bvh.nodes, .bvh_leaves = m->bvh.leaf_prims,
                                .triangles = m->scene.triangles };
    return 0;
}

static void mesh_scene_close(MeshScene *m)
{
    kd_free(&m->tree);
    bvh_free(&m->bvh);
    scene_free(&m->scene);
}

static vec3 triangle_point(const Triangle *t, float u, float v)
{
    if (u + v > 1.0f) {
        u = 1.0f - u;
        v = 1.0f - v;
    }
    return v3_add(v3_add(v3_scale(t->p0, 1.0f - u - v), v3_scale(t->p1, u)), v3_scale(t->p2, v));
}

/* The mesh file's triangles as the test scene (which holds at most 4096). */
static void mesh_into_scene(const char *path)
{
    MeshScene m;
    scene_clear();
    int bad = mesh_scene_open(&m, path);
    CHECK(!bad && m.scene.n_triangles <= sizeof scene.tri / sizeof scene.tri[0]);
    for (size_t i = 0; !bad && i < m.scene.n_triangles && scene.nt < sizeof scene.tri / sizeof scene.tri[0]; i++)
        scene.tri[scene.nt++] = m.scene.triangles[i];
    mesh_scene_close(&m);
}

/* Eight rays walked as a packet (trace_packet through the kd-tree, trace_packet_wide
 * through the BVH) give each ray bit for bit what it gets alone: coherent packets (one
 * origin, directions within a small cone, as a camera's neighbouring pixels; or
 * neighbouring origins toward one point, as shadow rays), some with a NaN ray, a ray
 * that misses the scene or a tmax that ends inside it, and incoherent packets of random
 * rays (mixed signs: walked one by one); and packets aimed at the corners and edges of
 * a mesh's triangles, where several triangles are hit at one t, whose hits must also be
 * brute force's (the tie rule; for the kd-tree, the cell after a leaf that starts at
 * the closest hit is visited, lane by lane). */
static void packets_check(int wide)
{
    struct { uint64_t seed; uint ns, nt, nb, np; } cases[] = {
        { 91, 40, 200, 25, 2 }, { 92, 0, 400, 0, 0 }, { 93, 120, 0, 60, 1 }, { 94, 0, 4000, 0, 0 },
    };
    int differ = 0, total = 0, packed = 0, brute_bad = 0;
    for (int c = 0; c < 5; c++) {
        int mesh = c == 4;          /* the random scenes, then a mesh */
        if (mesh) mesh_into_scene("tests/data/models/bun_zipper_res4.ply");
        else random_scene(cases[c].seed, cases[c].ns, cases[c].nt, cases[c].nb, cases[c].np);
        CHECK(scene_build(0) == ST_OK);
        vec3 mid = v3_scale(v3_add(scene.tree.lo, scene.tree.hi), 0.5f);
        float radius = v3_len(v3_sub(scene.tree.hi, scene.tree.lo));
        walk_bvh = wide;
        for (int i = 0; i < 3000; i++) {
            Ray r[TRACE_PACKET];
            int kind = mesh ? 3 : i % 3;
            vec3 o = vrand(-8.0f, 8.0f), target = vrand(-4.0f, 4.0f);
            vec3 d = v3_norm(v3_sub(target, o));
            const Triangle *t = mesh ? &scene.tri[(uint)(frand() * (float)scene.nt) % scene.nt] : NULL;
            if (mesh) o = v3_add(mid, v3_scale(v3_norm(vrand(-1.0f, 1.0f)), radius));
            for (int l = 0; l < TRACE_PACKET; l++) {
                if (kind == 3) {          /* a camera at a mesh triangle's corners and edges */
                    const vec3 *corner[3] = { &t->p0, &t->p1, &t->p2 };
                    vec3 p = *corner[l % 3];
                    if (l >= 3) p = v3_scale(v3_add(p, *corner[(l + 1) % 3]), 0.5f);
                    if (l >= 6) p = triangle_point(t, frand(), l == 6 ? 0.0f : frand());
                    r[l] = make_ray(o, v3_sub(p, o), 0.0f, K_INF);
                } else if (kind == 0) {   /* a camera: one origin, a cone of 0.05 radians */
                    r[l] = make_ray(o, v3_norm(v3_add(d, vrand(-0.05f, 0.05f))), 0.0f, K_INF);
                } else if (kind == 1) {   /* shadow rays toward one point */
                    vec3 p = v3_add(o, vrand(-0.3f, 0.3f));
                    r[l] = make_ray(p, v3_sub(target, p), 0.0f, 0.9999f);
                } else {
                    r[l] = random_ray(-5.0f, 5.0f);
                }
            }
            if (i % 11 == 0) r[i % TRACE_PACKET].o.y = NAN;
            if (i % 13 == 0) r[(i + 3) % TRACE_PACKET].tmax = 2.0f;
            if (i % 17 == 0) r[(i + 5) % TRACE_PACKET].d = v3_neg(r[(i + 5) % TRACE_PACKET].d);
            uint neg = 0, mixed = 0;
            for (int l = 0; l < TRACE_PACKET; l++) {
                RayPre p;
                ray_prepare(r[l], &p);
                if (l == 0) neg = p.neg;
                mixed |= p.neg ^ neg;
            }
            packed += !mixed;
            for (int any = 0; any < 2; any++) {
                Hit h[TRACE_PACKET];
                const SceneView *v = wide ? &scene.wide_view : &scene.view;
                if (wide) trace_packet_wide(v, r, any, h);
                else trace_packet(v, r, any, h);
                for (int l = 0; l < TRACE_PACKET; l++) {
                    if (any) {
                        differ += (h[l].prim != NO_INDEX) != trace_any(v, r[l]);
                    } else {
                        Hit ref = trace_closest(v, r[l]);
                        differ += memcmp(&h[l], &ref, sizeof ref) != 0;
                        if (mesh) brute_bad += !ray_agrees(r[l], brute_bad < 3);
                    }
                    total++;
                }
            }
        }
    }
    walk_bvh = 0;
    CHECK_EQ_INT(differ, 0);
    CHECK_EQ_INT(brute_bad, 0);
    CHECK(packed > 5 * 3000 / 2);    /* most packets took the packet walk */
    fprintf(stderr, "  %s: %d rays in packets of %d (%d packets walked together), %d differ from the rays traced "
            "alone; at a mesh's corners and edges %d disagree with brute force\n", wide ? "BVH" : "kd-tree",
            total, TRACE_PACKET, packed, differ, brute_bad);
}

static void test_packets(void) { packets_check(0); }
static void test_packets_wide(void) { packets_check(1); }

static void test_empty_scene(void)
{
    scene_clear();
    CHECK(scene_build(0) == ST_OK);
    /* the BVH: a root without children */
    CHECK_EQ_INT(scene.bvh.n_nodes, 1);
    for (uint l = 0; l < BVH_WIDTH; l++) CHECK_EQ_INT(scene.bvh.nodes[0].kind[l], BVH_CHILD_NONE);
    Ray down = make_ray(v3s(0.0f), v3(0.0f, 0.0f, 1.0f), 0.0f, K_INF);
    CHECK_EQ_INT(trace_closest(&scene.wide_view, down).prim, NO_INDEX);
    CHECK(!trace_any(&scene.wide_view, down));
    CHECK_EQ_INT(scene.tree.n_nodes, 1);
    CHECK_EQ_INT(scene.tree.nodes[0].bits, KD_LEAF);
    CHECK_EQ_INT(scene.tree.stats.n_leaves, 1);
    CHECK_EQ_INT(scene.tree.stats.n_empty_leaves, 1);
    Ray r = make_ray(v3s(0.0f), v3(0.0f, 0.0f, 1.0f), 0.0f, K_INF);
    CHECK_EQ_INT(trace_closest(&scene.view, r).prim, NO_INDEX);
    CHECK(!trace_any(&scene.view, r));
    /* planes alone (not in the tree) */
    add_plane(v3(0.0f, 0.0f, 1.0f), 3.0f);
    CHECK(scene_build(2) == ST_OK);
    Hit h = trace_closest(&scene.view, r);
    CHECK_EQ_INT(h.prim, 0);
    CHECK_NEAR(h.t, 3.0f, 1e-6);
    CHECK(trace_any(&scene.view, r));
    r.tmax = 2.0f;
    CHECK(!trace_any(&scene.view, r));
    scene_clear();
}

/* Broken input must not break the build: primitives with NaN or inf are left out,
 * zero-area triangles stay in (and are never hit). */
static void test_bad_primitives_once(void)
{
    random_scene(31, 10, 100, 10, 0);
    add_triangle(v3(NAN, 0.0f, 0.0f), v3(1.0f, 0.0f, 0.0f), v3(0.0f, 1.0f, 0.0f));
    add_triangle(v3(0.0f, 0.0f, 0.0f), v3(INFINITY, 0.0f, 0.0f), v3(0.0f, 1.0f, 0.0f));
    add_triangle(v3(1.0f, 1.0f, 1.0f), v3(1.0f, 1.0f, 1.0f), v3(1.0f, 1.0f, 1.0f));   /* a point */
    add_triangle(v3(0.0f, 0.0f, 0.0f), v3(1.0f, 1.0f, 1.0f), v3(2.0f, 2.0f, 2.0f));   /* a line */
    add_sphere(v3(0.0f, NAN, 0.0f), 1.0f);
    add_box(v3(0.0f, 0.0f, 0.0f), v3(1.0f, -INFINITY, 1.0f));
    CHECK(scene_build(0) == ST_OK);
    CHECK_EQ_INT(scene.tree.stats.n_skipped, 4);
    CHECK_EQ_INT(scene.tree.stats.n_prims, 10 + 100 + 10 + 2);
    CHECK(isfinite(scene.tree.lo.x) && isfinite(scene.tree.hi.y));
    check_tree();
    CHECK_EQ_INT(scene.bvh.stats.n_skipped, 4);
    int bad = 0;
    for (int i = 0; i < 5000; i++) bad += !ray_agrees(random_ray(-5.0f, 5.0f), bad < 3);
    CHECK_EQ_INT(bad, 0);
}

/* The kd-tree, then the BVH (which leaves out what the kd-tree does). */
static void test_bad_primitives(void)
{
    for (walk_bvh = 0; walk_bvh < 2; walk_bvh++) test_bad_primitives_once();
    walk_bvh = 0;
}

/* Axis-aligned flat triangles exactly on the planes the builder splits at, and rays
 * along the axes (two zero direction components), starting inside and outside. */
static void test_flat_on_split_planes_once(void)
{
    scene_clear();
    /* A stack of unit squares at z = 0..7 and a wall of them at x = 0..7, with
     * vertices on integer coordinates. */
    for (int i = 0; i < 8; i++)
        for (int a = 0; a < 4; a++)
            for (int b = 0; b < 4; b++) {
                float z = (float)i, x0 = (float)a, y0 = (float)b;
                add_triangle(v3(x0, y0, z), v3(x0 + 1.0f, y0, z), v3(x0 + 1.0f, y0 + 1.0f, z));
                add_triangle(v3(x0, y0, z), v3(x0 + 1.0f, y0 + 1.0f, z), v3(x0, y0 + 1.0f, z));
                add_triangle(v3(z, x0 + 4.0f, y0), v3(z, x0 + 5.0f, y0), v3(z, x0 + 5.0f, y0 + 1.0f));
            }
    CHECK(scene_build(0) == ST_OK);
    CHECK(scene.tree.stats.n_nodes > 1);
    check_tree();
    rng_seed(41);
    int bad = 0, hits = 0, n = 0;
    for (int i = 0; i < 20000; i++) {
        vec3 o = vrand(-1.0f, 9.0f);
        vec3 d;
        int kind = i % 4;
        if (kind == 0) d = v3(0.0f, 0.0f, frand() < 0.5f ? -1.0f : 1.0f);        /* along z */
        else if (kind == 1) d = v3(frand() < 0.5f ? -1.0f : 1.0f, 0.0f, 0.0f);   /* along x */
        else if (kind == 2) {                                                     /* integer origin */
            o = v3((float)(int)frange(-1.0f, 9.0f), (float)(int)frange(-1.0f, 9.0f), (float)(int)frange(-1.0f, 9.0f));
            d = vrand(-1.0f, 1.0f);
        } else d = vrand(-1.0f, 1.0f);
        Ray r = make_ray(o, d, 0.0f, K_INF);
        bad += !ray_agrees(r, bad < 5);
        hits += trace_closest(walk_view(), r).prim != NO_INDEX;
        n++;
    }
    CHECK_EQ_INT(bad, 0);
    CHECK(hits > n / 8);
    fprintf(stderr, "  %d rays, %d hits, %d disagree with brute force\n", n, hits, bad);
    /* rays lying in the planes of the squares (candidate split planes), parallel to
     * them: they graze the squares (no hit) and meet the wall at x = 0 */
    for (int z = 0; z < 8; z++) {
        Ray in_plane = make_ray(v3(-1.0f, 5.5f, (float)z), v3(1.0f, 0.0f, 0.0f), 0.0f, K_INF);
        Hit h = trace_closest(walk_view(), in_plane);
        CHECK(ray_agrees(in_plane, 1));
        if (z < 4) CHECK(h.prim != NO_INDEX && h.t == 1.0f);
    }
}

/* The kd-tree, then the BVH (whose boxes have these squares on their faces). */
static void test_flat_on_split_planes(void)
{
    for (walk_bvh = 0; walk_bvh < 2; walk_bvh++) test_flat_on_split_planes_once();
    walk_bvh = 0;
}

/* The node array does not depend on the number of threads. */
static void test_deterministic(void)
{
    scene_clear();
    rng_seed(51);
    for (int i = 0; i < 4000; i++) random_triangle(-10.0f, 10.0f, 0.4f);
    for (int i = 0; i < 200; i++) add_sphere(vrand(-10.0f, 10.0f), frange(0.05f, 0.3f));
    CHECK(scene_build(1) == ST_OK);
    KdTree one = scene.tree;
    memset(&scene.tree, 0, sizeof scene.tree);
    const int threads[] = { 2, 3, 0 };
    for (int i = 0; i < 3; i++) {
        CHECK(scene_build(threads[i]) == ST_OK);
        CHECK_EQ_INT(scene.tree.n_nodes, one.n_nodes);
        CHECK_EQ_INT(scene.tree.n_leaf_prims, one.n_leaf_prims);
        if (scene.tree.n_nodes == one.n_nodes)
            CHECK(!memcmp(scene.tree.nodes, one.nodes, one.n_nodes * sizeof *one.nodes));
        if (scene.tree.n_leaf_prims == one.n_leaf_prims)
            CHECK(!memcmp(scene.tree.leaf_prims, one.leaf_prims, one.n_leaf_prims * sizeof(uint)));
        kd_free(&scene.tree);
    }
    kd_free(&one);
}

typedef struct { const void *p; size_t n; } HashPart;

static uint64_t fnv_parts(const HashPart *part, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < part[i].n; j++) {
            h ^= ((const unsigned char *)part[i].p)[j];
            h *= 0x100000001b3ull;
        }
    return h;
}

/* FNV-1a over a flat tree (counts, nodes, leaf data, root box): what the kernels read.
 * Both trees (KdTree, Bvh) have these fields. */
#define TREE_HASH(t)                                                                     \
    fnv_parts((const HashPart[]){ { &(t)->n_nodes, sizeof (t)->n_nodes },                \
                                  { &(t)->n_leaf_prims, sizeof (t)->n_leaf_prims },      \
                                  { (t)->nodes, (t)->n_nodes * sizeof *(t)->nodes },     \
                                  { (t)->leaf_prims, (t)->n_leaf_prims * sizeof(uint) }, \
                                  { &(t)->lo, sizeof (t)->lo },                          \
                                  { &(t)->hi, sizeof (t)->hi } },                        \
              6)

/* A closed bumpy sphere of 12 n^2 triangles: each face of a cube in an n x n grid,
 * pushed onto the sphere. Only + - * / and sqrtf (exact in IEEE arithmetic), so the
 * mesh, unlike mesh_make_sphere's (libm's sin and cos), is the same on every machine. */
static Triangle *cube_sphere(uint n, size_t *count)
{
    Triangle *t = malloc((size_t)12 * n * n * sizeof *t);
    if (!t) return NULL;
    size_t m = 0;
    for (int face = 0; face < 6; face++) {
        int k = face >> 1;
        float s = face & 1 ? 1.0f : -1.0f;
        for (uint i = 0; i < n; i++)
            for (uint j = 0; j < n; j++) {
                vec3 p[4];
                for (int c = 0; c < 4; c++) {
                    float u = -1.0f + 2.0f * (float)(i + (uint)(c & 1)) / (float)n;
                    float v = -1.0f + 2.0f * (float)(j + (uint)(c >> 1)) / (float)n;
                    float q[3];
                    q[k] = s;
                    q[(k + 1) % 3] = s * u;
                    q[(k + 2) % 3] = v;
                    float bump = 1.0f + 0.05f * u * v * (1.0f - u * u);
                    float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                    p[c] = v3_scale(v3(q[0], q[1], q[2]), bump / len);
                }
                t[m++] = (Triangle){ p[0], 0, p[1], NO_INDEX, p[3], NO_INDEX };
                t[m++] = (Triangle){ p[0], 0, p[3], NO_INDEX, p[2], NO_INDEX };
            }
    }
    *count = m;
    return t;
}

/* The BVH is the same whatever the number of threads (from 32768 primitives, subtrees
 * below the top are built by the threads: the cube sphere has 76800 triangles). */
static void test_bvh_deterministic(void)
{
    size_t nt = 0;
    Triangle *tri = cube_sphere(80, &nt);
    CHECK(tri != NULL);
    if (!tri) return;
    KdInput in = { NULL, 0, tri, nt, NULL, 0, NULL, 0, NULL, 0, NULL, 0 };
    Bvh one;
    Error err = { 0 };
    CHECK(bvh_build(&in, 1, &one, &err) == ST_OK);
    const int threads[] = { 2, 3, 0 };
    for (int i = 0; i < 3; i++) {
        Bvh t;
        if (bvh_build(&in, threads[i], &t, &err) != ST_OK) {
            CHECK_MSG(0, "%s", err.msg);
            continue;
        }
        CHECK_EQ_INT(t.n_nodes, one.n_nodes);
        CHECK_EQ_INT(t.n_leaf_prims, one.n_leaf_prims);
        if (t.n_nodes == one.n_nodes) CHECK(!memcmp(t.nodes, one.nodes, one.n_nodes * sizeof *one.nodes));
        if (t.n_leaf_prims == one.n_leaf_prims)
            CHECK(!memcmp(t.leaf_prims, one.leaf_prims, one.n_leaf_prims * sizeof(uint)));
        bvh_free(&t);
    }
    fprintf(stderr, "  %zu triangles: %u nodes, %u leaves, the same with 1, 2, 3 and all threads\n", nt, one.n_nodes,
            one.stats.n_leaves);
    bvh_free(&one);
    free(tri);
}

/* Spheres, triangles of three sizes (a quarter of them flat in z on integer planes, so
 * they lie on candidate split planes) and boxes (a fifth flat in y), each number drawn
 * in a statement of its own: random_scene's draws are function arguments, whose order
 * of evaluation C leaves open (gcc and clang differ), so its scene depends on the
 * compiler. */
static void mixed_scene(void)
{
    scene_clear();
    rng_seed(81);
    float r[9];
    for (uint i = 0; i < 4000; i++) {
        for (int j = 0; j < 9; j++) r[j] = frange(-4.0f, 4.0f);
        vec3 a = v3(r[0], r[1], r[2]);
        if (i < 400) {
            add_sphere(a, 0.05f + 0.1f * fabsf(r[3]));
        } else if (i < 600) {
            vec3 hi = v3_add(a, v3(0.4f * fabsf(r[3]), i % 5 ? 0.4f * fabsf(r[4]) : 0.0f, 0.4f * fabsf(r[5])));
            add_box(a, hi);
        } else {
            float size = i % 3 == 0 ? 0.5f : i % 3 == 1 ? 0.1f : 0.03f;
            vec3 b = v3_add(a, v3(size * r[3], size * r[4], size * r[5]));
            vec3 c = v3_add(a, v3(size * r[6], size * r[7], size * r[8]));
            if (i % 4 == 0) a.z = b.z = c.z = (float)(int)r[2];
            add_triangle(a, b, c);
        }
    }
}

/* The trees (kd-tree and BVH) of two fixed inputs, pinned by hash: a change to a build
 * that changes any node or leaf word (a refactoring should not) shows here. Both inputs are made without
 * libm and without draws in function arguments, so they are the same bits with any C
 * compiler. When a change to the SAH or the layout is meant, check the trees (make
 * bench, docs/kdtree.md) and pin the new hashes. */
static void test_pinned_trees(void)
{
    size_t nt = 0;
    Triangle *tri = cube_sphere(40, &nt);
    CHECK(tri != NULL);
    if (!tri) return;
    KdInput in = { NULL, 0, tri, nt, NULL, 0, NULL, 0, NULL, 0, NULL, 0 };
    const int threads[] = { 1, 3, 0 };
    for (int i = 0; i < 3; i++) {
        KdTree t;
        Error err = { 0 };
        if (kd_build(&in, threads[i], &t, &err) != ST_OK) {
            CHECK_MSG(0, "%s", err.msg);
            continue;
        }
        CHECK(t.n_nodes > 1000);
        CHECK_MSG(TREE_HASH(&t) == 0x8f9182d907c91c8bull, "cube sphere, %d threads: %016llx", threads[i],
                  (unsigned long long)TREE_HASH(&t));
        kd_free(&t);
        Bvh b;
        if (bvh_build(&in, threads[i], &b, &err) != ST_OK) {
            CHECK_MSG(0, "%s", err.msg);
            continue;
        }
        CHECK_MSG(TREE_HASH(&b) == 0x7d48e72b7457c2eaull, "cube sphere BVH, %d threads: %016llx", threads[i],
                  (unsigned long long)TREE_HASH(&b));
        bvh_free(&b);
    }
    free(tri);

    mixed_scene();
    for (int i = 0; i < 3; i++) {
        if (scene_build(threads[i]) != ST_OK) {
            CHECK(!"mixed scene builds");
            continue;
        }
        CHECK(scene.tree.n_nodes > 100);
        CHECK_MSG(TREE_HASH(&scene.tree) == 0x9958cac2f43dba5eull, "mixed scene, %d threads: %016llx", threads[i],
                  (unsigned long long)TREE_HASH(&scene.tree));
        CHECK_MSG(TREE_HASH(&scene.bvh) == 0x62e589a58d787c2dull, "mixed scene BVH, %d threads: %016llx", threads[i],
                  (unsigned long long)TREE_HASH(&scene.bvh));
    }
}

/* From 65536 primitives the boxes are gathered on several threads, and from 2048
 * non-empty leaves the leaf records are written on several; the root's axes run side
 * by side with more than one thread. The tree stays the same bits, with primitives
 * left out (a NaN and an infinite corner) in either thread's range. */
static void test_threaded_passes(void)
{
    size_t nt = 0;
    Triangle *tri = cube_sphere(80, &nt);
    CHECK(tri != NULL);
    if (!tri) return;
    CHECK(nt > 65536);
    tri[7].p1.y = NAN;
    tri[nt - 100].p2.x = INFINITY;
    KdInput in = { NULL, 0, tri, nt, NULL, 0, NULL, 0, NULL, 0, NULL, 0 };
    KdTree one;
    Error err = { 0 };
    CHECK(kd_build(&in, 1, &one, &err) == ST_OK);
    CHECK_EQ_INT(one.stats.n_skipped, 2);
    CHECK_MSG(one.stats.n_leaves - one.stats.n_empty_leaves > 2048, "%u leaves, %u empty", one.stats.n_leaves, one.stats.n_empty_leaves);
    uint64_t h = TREE_HASH(&one);
    const int threads[] = { 2, 3, 0 };
    for (int i = 0; i < 3; i++) {
        KdTree t;
        if (kd_build(&in, threads[i], &t, &err) != ST_OK) {
            CHECK_MSG(0, "%s", err.msg);
            continue;
        }
        CHECK_EQ_INT(t.stats.n_skipped, 2);
        CHECK_MSG(TREE_HASH(&t) == h, "%d threads: %016llx, one thread: %016llx", threads[i],
                  (unsigned long long)TREE_HASH(&t), (unsigned long long)h);
        kd_free(&t);
    }
    kd_free(&one);
    free(tri);
}


/* Kd-tree against every triangle on rays a renderer traces over a scanned mesh: from
 * outside at points of the mesh, from points of the surface into the hemisphere (like
 * diffuse bounces) and toward other points of it (like shadow rays). */
static void check_mesh_brute_force(const char *what, int rays)
{
    MeshScene m;
    if (mesh_scene_open(&m, what)) {
        CHECK(!"mesh loads");
        mesh_scene_close(&m);
        return;
    }
    uint nt = (uint)m.scene.n_triangles;
    vec3 c = v3_scale(v3_add(m.tree.lo, m.tree.hi), 0.5f);
    float r = 0.5f * v3_len(v3_sub(m.tree.hi, m.tree.lo));
    rng_seed(61);
    int bad = 0, hits = 0;
    for (int i = 0; i < rays; i++) {
        const Triangle *a = &m.scene.triangles[(uint)(frand() * nt) % nt];
        const Triangle *b = &m.scene.triangles[(uint)(frand() * nt) % nt];
        vec3 pa = triangle_point(a, frand(), frand()), pb = triangle_point(b, frand(), frand());
        vec3 ng = v3_norm(v3_cross(v3_sub(a->p1, a->p0), v3_sub(a->p2, a->p0)));
        /* off the surface by about pa's error bound, as the integrators spawn rays */
        vec3 off = spawn_offset(pa, v3_scale(v3_abs(pa), K_ROUND_ERR(7)), frand() < 0.5f ? ng : v3_neg(ng));
        Ray ray;
        switch (i % 6) {
        case 4:   /* camera-like, through a corner or an edge (two or more triangles at one t) */
            pa = (i / 6) % 2 ? a->p0 : triangle_point(a, frand(), 0.0f);
            /* fall through */
        case 0:   /* camera-like, from a sphere around the mesh */
            ray = make_ray(v3_add(c, v3_scale(v3_norm(vrand(-1.0f, 1.0f)), 2.0f * r)), v3s(0.0f), 0.0f, K_INF);
            ray.d = v3_sub(pa, ray.o);
            break;
        case 1:   /* diffuse-like */
            ray = make_ray(off, vrand(-1.0f, 1.0f), 0.0f, K_INF);
            break;
        case 2:   /* shadow-like: to another point of the surface */
            ray = make_ray(off, v3_sub(pb, off), 0.0f, 1.0f - 1e-4f);
            break;
        default:  /* anywhere in the box, a positive tmin */
            ray = make_ray(v3_add(m.tree.lo, v3_mul(v3_sub(m.tree.hi, m.tree.lo), vrand(0.0f, 1.0f))),
                           vrand(-1.0f, 1.0f), frange(0.0f, 0.1f) * r, K_INF);
            break;
        }
        const SceneView *v = walk_bvh ? &m.wide_view : &m.view;
        Hit kd = trace_closest(v, ray);
        RayPre rp;
        ray_prepare(ray, &rp);
        Hit bf = { ray.tmax, NO_INDEX, 0.0f, 0.0f, NO_INDEX, 0u, 0u, 0u };
        for (uint id = 0; id < nt; id++) {
            Ray rr = ray;
            rr.tmax = bf.t;
            Hit h;
            if (triangle_intersect(&rp, &m.scene.triangles[id], rr, &h)) {
                h.prim = id;
                bf = h;
            }
        }
        /* the same triangle (the lowest id of those at the least t) with the same t, u, v */
        int ok = kd.prim == bf.prim;
        if (ok && kd.prim != NO_INDEX) ok = kd.t == bf.t && kd.u == bf.u && kd.v == bf.v;
        ok = ok && trace_any(v, ray) == (bf.prim != NO_INDEX);
        if (!ok && bad++ < 3)
            fprintf(stderr, "  %s ray %d: %s %u t=%.9g, brute force %u t=%.9g\n", what, i, walk_bvh ? "BVH" : "kd",
                    kd.prim, kd.t, bf.prim, bf.t);
        hits += bf.prim != NO_INDEX;
    }
    CHECK_EQ_INT(bad, 0);
    CHECK(hits > rays / 4);
    fprintf(stderr, "  %s, %s: %u triangles, %d rays (%d hit), %d disagree with brute force\n", what,
            walk_bvh ? "BVH" : "kd-tree", nt, rays, hits, bad);
    mesh_scene_close(&m);
}

static void test_real_meshes(void)
{
    const char *res3 = "../shared/models/bunny/bun_zipper_res3.ply";
    int have_res3 = shared_model_present(res3, "only the small bunny is checked");
    for (walk_bvh = 0; walk_bvh < 2; walk_bvh++) {
        check_mesh_brute_force("tests/data/models/bun_zipper_res4.ply", 20000);
        if (have_res3) check_mesh_brute_force(res3, 8000);
    }
    walk_bvh = 0;
}

/* From inside a closed mesh, a million rays aimed exactly at its vertices and at points
 * of its edges: not one may slip out between the triangles. */
static void watertight_mesh(void)
{
    MeshScene m;
    if (mesh_scene_open(&m, "sphere:20000")) {
        CHECK(!"sphere builds");
        mesh_scene_close(&m);
        return;
    }
    uint nt = (uint)m.scene.n_triangles;
    rng_seed(71);
    int misses = 0, any_misses = 0;
    const int rays = 1000000;
    for (int i = 0; i < rays; i++) {
        const Triangle *t = &m.scene.triangles[(uint)(frand() * nt) % nt];
        const vec3 *corner[3] = { &t->p0, &t->p1, &t->p2 };
        int k = (int)(frand() * 3.0f) % 3;
        vec3 target = *corner[k];
        if (i % 2) {   /* a point of the edge from corner k to the next */
            vec3 next = *corner[(k + 1) % 3];
            target = v3_add(target, v3_scale(v3_sub(next, target), frand()));
        }
        vec3 o = vrand(-0.3f, 0.3f);
        if (i % 5 == 0) o = v3s(0.0f);
        if (i % 7 == 0) {
            /* d with two zero components: the origin moved in along the target's largest
             * coordinate, which keeps it inside the sphere */
            float ax = fabsf(target.x), ay = fabsf(target.y), az = fabsf(target.z);
            o = target;
            if (ax >= ay && ax >= az) o.x *= 0.2f;
            else if (ay >= az) o.y *= 0.2f;
            else o.z *= 0.2f;
        }
        Ray ray = make_ray(o, v3_sub(target, o), 0.0f, K_INF);
        const SceneView *v = walk_bvh ? &m.wide_view : &m.view;
        Hit h = trace_closest(v, ray);
        if (h.prim == NO_INDEX) {
            if (misses++ < 3) {
                RayPre rp;
                ray_prepare(ray, &rp);
                int bf = 0;
                for (uint id = 0; id < nt; id++) { Hit hh; bf += triangle_intersect(&rp, &m.scene.triangles[id], ray, &hh); }
                fprintf(stderr, "  miss: o=(%.9g %.9g %.9g) target=(%.9g %.9g %.9g) brute force hits %d\n", o.x, o.y, o.z, target.x,
                        target.y, target.z, bf);
            }
        }
        any_misses += !trace_any(v, ray);
    }
    CHECK_EQ_INT(misses, 0);
    CHECK_EQ_INT(any_misses, 0);
    fprintf(stderr, "  %s, closed sphere of %u triangles: %d rays at vertices and edges from inside, %d misses\n",
            walk_bvh ? "BVH" : "kd-tree", nt, rays, misses);
    mesh_scene_close(&m);
}

/* From inside a closed mesh, rays at its vertices and edges: through the kd-tree, then
 * the BVH (whose boxes are exactly the triangles' bounds: a ray at a vertex grazes
 * them). */
static void test_watertight_mesh(void)
{
    for (walk_bvh = 0; walk_bvh < 2; walk_bvh++) watertight_mesh();
    walk_bvh = 0;
}

int main(void)
{
    RUN(test_sphere);
    RUN(test_triangle);
    RUN(test_watertight);
    RUN(test_group_intersect);
    RUN(test_box);
    RUN(test_plane);
    RUN(test_structure);
    RUN(test_against_brute_force);
    RUN(test_ellipsoids);
    RUN(test_pairs);
    RUN(test_packets);
    RUN(test_packets_wide);
    RUN(test_bvh_structure);
    RUN(test_bvh_degenerate);
    RUN(test_bvh_deterministic);
    RUN(test_empty_scene);
    RUN(test_bad_primitives);
    RUN(test_flat_on_split_planes);
    RUN(test_deterministic);
    RUN(test_pinned_trees);
    RUN(test_threaded_passes);
    RUN(test_real_meshes);
    RUN(test_watertight_mesh);
    scene_clear();
    return harness_report();
}
