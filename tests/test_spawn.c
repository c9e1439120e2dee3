/*
 * test_spawn.c — rays spawned from a surface must not hit that surface again, at any
 * scene scale and from any camera distance (issue 39).
 *
 * Each scene is a furnace: one convex or flat diffuse surface of albedo 0.5 under a
 * white background of radiance 1, path depth 1, no lights. A camera ray that hits the
 * surface bounces once; the bounce leaves the surface on its outer side and can only
 * escape, carrying exactly albedo x background = 0.5. So every pixel is 0.5 to the
 * last bit, and a pixel below it is a bounce that hit the surface it left (the
 * self-intersection that showed as dark rings on a sphere seen from 1000 radii). The
 * camera frames a part of the surface with a narrow field of view so that every pixel
 * sees it. Each image is rendered on PoCL and on the scalar device, which must agree
 * bit for bit.
 */
#include <stdlib.h>

#include "harness.h"
#include "util/kmath.h"
#include "render_util.h"

#define FURNACE_ALBEDO 0.5
#define FURNACE_SIZE 12u   /* pixels a side: enough pixels to see a ring, cheap to render */
#define FURNACE_SPP 4u

static const double scene_scales[] = { 1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6 };
static const double camera_distances[] = { 4.0, 1e2, 1e3, 1e4 };   /* in object sizes */
#define N_SCALES (sizeof scene_scales / sizeof scene_scales[0])
#define N_DISTANCES (sizeof camera_distances / sizeof camera_distances[0])

/* Where the object sits, in object sizes: off the origin, so that its coordinates are
 * larger than its size, as in a real scene. */
static const double object_centre[3] = { 2.0, 1.0, -3.0 };

static vec3 scaled(double x, double y, double z, double s)
{
    return v3((float)(x * s), (float)(y * s), (float)(z * s));
}

/* An empty furnace: white background, depth 1, a small image; the diffuse material
 * is material 0. */
static void furnace_init(Scene *s)
{
    scene_init(s);
    s->image.width = FURNACE_SIZE;
    s->image.height = FURNACE_SIZE;
    s->image.spp = FURNACE_SPP;
    s->image.max_depth = 1;
    s->image.seed = 3;
    s->bg_type = BG_CONSTANT;
    s->bg_color = v3s(1.0f);
    uint mi;
    scene_add_material(s, "furnace", material_diffuse(v3s((float)FURNACE_ALBEDO)), &mi, NULL);
}

/* A camera `dist` from point `at` (doubles) in direction `dir` (any length), whose
 * vertical field of view spans `half` either side of `at`, at that distance. */
static void furnace_camera(Scene *s, const double at[3], const double dir[3], double dist, double half)
{
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    s->camera.from = scaled(at[0] + dir[0] / len * dist, at[1] + dir[1] / len * dist,
                            at[2] + dir[2] / len * dist, 1.0);
    s->camera.at = scaled(at[0], at[1], at[2], 1.0);
    s->camera.up = v3(0.0f, 1.0f, 0.0f);
    s->camera.vfov = (float)(2.0 * atan(half / dist) * 180.0 / M_PI);
}

/* A sphere of radius `scale` at object_centre * scale, seen from `dist` radii: the
 * image's corners lie at 0.85 of the silhouette's radius, so every pixel is on it. */
static void sphere_furnace(Scene *s, double scale, double dist)
{
    furnace_init(s);
    double c[3] = { object_centre[0] * scale, object_centre[1] * scale, object_centre[2] * scale };
    Sphere sp = { scaled(object_centre[0], object_centre[1], object_centre[2], scale), (float)scale, 0u,
                  NO_INDEX, 0, 0 };
    scene_add_sphere(s, sp, NULL);
    const double dir[3] = { 1.0, 0.7, 0.4 };
    /* the silhouette's radius seen from the centre's distance d is r d / sqrt(d^2 - r^2) */
    double silhouette = scale * dist / sqrt(dist * dist - 1.0);
    furnace_camera(s, c, dir, dist * scale, 0.6 * silhouette);
}

/* An ellipsoid: the unit sphere under scale (2, 1, 0.5) times `scale`, turned 30
 * degrees about (1, 1, 0), at object_centre * scale, seen from `dist` sizes away. Its
 * smallest semi-axis is 0.5 * scale, so a field of view 0.3 * scale either side of the
 * centre sees only the ellipsoid. The spawn offset is bounded through the transform
 * (surface.h, sphere_xform_point). */
static void ellipsoid_furnace(Scene *s, double scale, double dist)
{
    furnace_init(s);
    double c[3] = { object_centre[0] * scale, object_centre[1] * scale, object_centre[2] * scale };
    Transform t = transform_translate(c[0], c[1], c[2]), r = transform_rotate(1.0, 1.0, 0.0, 30.0),
              sc = transform_scale(2.0 * scale, 1.0 * scale, 0.5 * scale);
    Transform m = transform_compose(&r, &sc);
    m = transform_compose(&t, &m);
    CHECK_EQ_INT(scene_add_ellipsoid(s, &m, 0u, NULL), ST_OK);
    const double dir[3] = { 1.0, 0.7, 0.4 };
    furnace_camera(s, c, dir, dist * scale, 0.3 * scale);
}

/* A cube of half-size `scale` seen from `dist` half-sizes off its corner along a
 * diagonal-ish direction: three faces, and two edges, fill the image. */
static void box_furnace(Scene *s, double scale, double dist)
{
    furnace_init(s);
    Box b;
    memset(&b, 0, sizeof b);
    b.lo = scaled(object_centre[0] - 1.0, object_centre[1] - 1.0, object_centre[2] - 1.0, scale);
    b.hi = scaled(object_centre[0] + 1.0, object_centre[1] + 1.0, object_centre[2] + 1.0, scale);
    b.material = 0u;
    b.light = NO_INDEX;
    scene_add_box(s, b, NULL);
    double corner[3] = { (object_centre[0] + 1.0) * scale, (object_centre[1] + 1.0) * scale,
                         (object_centre[2] + 1.0) * scale };
    const double dir[3] = { 1.0, 0.8, 0.6 };
    furnace_camera(s, corner, dir, dist * scale, 0.5 * scale);
}

/* A tilted infinite plane through object_centre * scale, seen from `dist` (times the
 * scale) at 30 degrees above it; `tilted` 0 takes the plane y = const instead. */
static void plane_furnace(Scene *s, double scale, double dist, int tilted)
{
    furnace_init(s);
    double n[3] = { tilted ? 0.15 : 0.0, 1.0, tilted ? -0.25 : 0.0 };
    double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int i = 0; i < 3; i++) n[i] /= nl;
    double c[3] = { object_centre[0] * scale, object_centre[1] * scale, object_centre[2] * scale };
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = v3((float)n[0], (float)n[1], (float)n[2]);
    pl.offset = (float)(n[0] * c[0] + n[1] * c[1] + n[2] * c[2]);
    pl.material = 0u;
    scene_add_plane(s, pl, NULL);
    /* 30 degrees up from a horizontal direction in the plane: sin 30 along the normal */
    double h[3] = { 1.0, 0.0, 0.4 }, hn = n[0] * h[0] + n[1] * h[1] + n[2] * h[2];
    for (int i = 0; i < 3; i++) h[i] -= hn * n[i];
    double hl = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    double dir[3];
    for (int i = 0; i < 3; i++) dir[i] = h[i] / hl * cos(M_PI / 6.0) + n[i] * sin(M_PI / 6.0);
    /* the field of view's edges at +-0.2 of the distance stay below the horizon */
    furnace_camera(s, c, dir, dist * scale, 0.2 * dist * scale);
}

/* A tilted square of two triangles, 2 * half * scale a side, seen from `dist` (times
 * the scale) on its front side at its middle; a lamp facing away below it makes it a
 * scene the PoCL device shades eight paths at a time (k_path_lanes), and adds nothing
 * to the image. A square 1000 times larger than its distance from the origin is the
 * hard case: the watertight test's t for a ray leaving it rounds in units of its
 * corners' distances. */
static void quad_furnace(Scene *s, double scale, double dist, double half)
{
    furnace_init(s);
    const double e1[3] = { 1.0, 0.2, 0.0 }, e2[3] = { 0.0, 0.3, -1.0 };   /* normal along +y mostly */
    const double *o = object_centre;
    double q[4][3];
    for (int i = 0; i < 3; i++) {
        q[0][i] = o[i] - half * (e1[i] + e2[i]);
        q[1][i] = o[i] + half * (e1[i] - e2[i]);
        q[2][i] = o[i] + half * (e1[i] + e2[i]);
        q[3][i] = o[i] - half * (e1[i] - e2[i]);
    }
    Triangle t0 = { scaled(q[0][0], q[0][1], q[0][2], scale), 0u, scaled(q[1][0], q[1][1], q[1][2], scale),
                    NO_INDEX, scaled(q[2][0], q[2][1], q[2][2], scale), NO_INDEX };
    Triangle t1 = { scaled(q[0][0], q[0][1], q[0][2], scale), 0u, scaled(q[2][0], q[2][1], q[2][2], scale),
                    NO_INDEX, scaled(q[3][0], q[3][1], q[3][2], scale), NO_INDEX };
    scene_add_triangle(s, t0, NULL);
    scene_add_triangle(s, t1, NULL);
    /* the lamp: a small triangle 3 sizes below, emitting downwards */
    Material lamp = material_diffuse(v3s(0.0f));
    lamp.type = MAT_EMISSIVE;
    lamp.emission = v3s(1.0f);
    uint li;
    scene_add_material(s, "lamp", lamp, &li, NULL);
    Triangle tl = { scaled(o[0], o[1] - 3.0, o[2], scale), li, scaled(o[0] + 0.5, o[1] - 3.0, o[2], scale),
                    NO_INDEX, scaled(o[0], o[1] - 3.0, o[2] + 0.5, scale), NO_INDEX };
    scene_add_triangle(s, tl, NULL);
    double n[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
    double c[3] = { o[0] * scale, o[1] * scale, o[2] * scale };
    const double dir[3] = { n[0] + 0.6, n[1], n[2] + 0.3 };
    furnace_camera(s, c, dir, dist * scale, 0.5 * scale);
}

typedef void (*FurnaceBuild)(Scene *s, double scale, double dist, int variant);
static void build_sphere(Scene *s, double scale, double dist, int variant)
{
    (void)variant;
    sphere_furnace(s, scale, dist);
}
static void build_ellipsoid(Scene *s, double scale, double dist, int variant)
{
    (void)variant;
    ellipsoid_furnace(s, scale, dist);
}
static void build_box(Scene *s, double scale, double dist, int variant)
{
    (void)variant;
    box_furnace(s, scale, dist);
}
static void build_plane(Scene *s, double scale, double dist, int variant) { plane_furnace(s, scale, dist, variant); }
static void build_quad(Scene *s, double scale, double dist, int variant)
{
    quad_furnace(s, scale, dist, variant ? 1000.0 : 1.0);
}

/* The image's mean and its darkest pixel channel, from the film's sums. */
static void film_mean_min(const Film *f, double *mean, double *min)
{
    size_t n = (size_t)f->width * f->height * 3u;
    float *rgb = malloc(n * sizeof *rgb);
    film_resolve(f, rgb);
    double sum = 0.0, lo = INFINITY;
    for (size_t i = 0; i < n; i++) {
        sum += rgb[i];
        lo = rgb[i] < lo ? rgb[i] : lo;
    }
    free(rgb);
    *mean = sum / (double)n;
    *min = lo;
}

/* Renders one furnace on PoCL and on the scalar device; both must be 0.5 everywhere
 * (the mean within 1%, no pixel below 0.45: one bounce in 40 lost would show) and
 * equal bit for bit. Returns 1 when it passed, and prints the numbers when not. */
static int check_furnace(const char *what, FurnaceBuild build, double scale, double dist, int variant)
{
    Scene a, b;
    build(&a, scale, dist, variant);
    build(&b, scale, dist, variant);
    Film fa, fb;
    Error err = { 0 };
    Status sa = render_util_run(&a, TEST_OPENCL, 0, &fa, &err);
    CHECK_MSG(sa == ST_OK, "%s", err.msg);
    error_clear(&err);
    Status sb = render_util_run(&b, "scalar", 0, &fb, &err);
    CHECK_MSG(sb == ST_OK, "%s", err.msg);
    error_clear(&err);
    int ok = 0;
    if (sa == ST_OK && sb == ST_OK) {
        double mean_a, min_a, mean_b, min_b;
        film_mean_min(&fa, &mean_a, &min_a);
        film_mean_min(&fb, &mean_b, &min_b);
        size_t n = (size_t)fa.width * fa.height * 3u, same = 0;
        for (size_t i = 0; i < n; i++) same += fa.sum[i] == fb.sum[i];
        ok = fabs(mean_a - FURNACE_ALBEDO) <= 0.01 * FURNACE_ALBEDO && min_a >= 0.9 * FURNACE_ALBEDO &&
             fabs(mean_b - FURNACE_ALBEDO) <= 0.01 * FURNACE_ALBEDO && min_b >= 0.9 * FURNACE_ALBEDO && same == n;
        if (!ok)
            fprintf(stderr,
                    "  %s, scale %g, camera %g sizes away: OpenCL mean %.4f min %.4f, scalar mean %.4f min %.4f, "
                    "%zu of %zu channel sums identical (expected 0.5 everywhere, all identical)\n",
                    what, scale, dist, mean_a, min_a, mean_b, min_b, same, n);
    }
    if (sa == ST_OK) film_free(&fa);
    if (sb == ST_OK) film_free(&fb);
    scene_free(&a);
    scene_free(&b);
    return ok;
}

/* Every scene scale against every camera distance; one check per shape, so that a
 * failure prints each case that failed. */
static void check_all_scales(const char *what, FurnaceBuild build, int variant)
{
    int failed = 0;
    for (size_t i = 0; i < N_SCALES; i++)
        for (size_t j = 0; j < N_DISTANCES; j++)
            failed += !check_furnace(what, build, scene_scales[i], camera_distances[j], variant);
    CHECK_MSG(failed == 0, "%s: %d of %zu furnaces not 0.5 everywhere or not the same on both devices", what,
              failed, N_SCALES * N_DISTANCES);
}

static void test_sphere_furnace(void) { check_all_scales("sphere", build_sphere, 0); }
static void test_ellipsoid_furnace(void) { check_all_scales("ellipsoid", build_ellipsoid, 0); }
static void test_box_furnace(void) { check_all_scales("box", build_box, 0); }
static void test_plane_furnace(void) { check_all_scales("plane y = const", build_plane, 0); }
static void test_tilted_plane_furnace(void) { check_all_scales("tilted plane", build_plane, 1); }
static void test_quad_furnace(void) { check_all_scales("quad", build_quad, 0); }
static void test_large_quad_furnace(void) { check_all_scales("quad 1000 sizes across", build_quad, 1); }

int main(void)
{
    RUN(test_sphere_furnace);
    RUN(test_ellipsoid_furnace);
    RUN(test_box_furnace);
    RUN(test_plane_furnace);
    RUN(test_tilted_plane_furnace);
    RUN(test_quad_furnace);
    RUN(test_large_quad_furnace);
    return harness_report();
}
