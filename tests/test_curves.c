/*
 * test_curves.c — the curves and surfaces of revolution of Tsinghua's PA2/PA3 format
 * (host/scene/curve.c, kernels/geom/revsurface.h): curve points against closed forms, the
 * B-spline's basis and its Bezier pieces, ray hits and normals on profiles whose surface
 * is known (a cylinder, a cone, a paraboloid), the same bits on PoCL and the scalar
 * device, renders of the exact surface against a fine mesh of it, and the reader.
 *
 * Tolerances: the kernel accepts a root when Newton's last step moved t by less than
 * 1e-5 relative and the point is within REV_TOL (1e-4) of the surface's size from it, so
 * a hit distance is checked to 2e-4 relative (the float rounding of A t^2 + 2Bt + C
 * adds a few ulps more) and a normal, which follows the curve's derivative at the
 * root's s, to 1e-3.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "render_util.h"

#include "geom/intersect.h"
#include "geom/surface.h"
#include "io/classic_parse.h"
#include "scene/curve.h"

/* ----------------------------------------------------------------- curves */

static void test_bezier_points(void)
{
    /* cubic: the ends, the midpoint (P0 + 3 P1 + 3 P2 + P3) / 8, the end tangents */
    const float p[8] = { 0, 0, 1, 2, 3, 2, 4, 0 };
    double xy[2], d[2];
    curve_bezier_eval(p, 3, 0.0, xy, d);
    CHECK(xy[0] == 0.0 && xy[1] == 0.0);
    CHECK_NEAR(d[0], 3.0, 1e-12);
    CHECK_NEAR(d[1], 6.0, 1e-12);
    curve_bezier_eval(p, 3, 1.0, xy, d);
    CHECK(xy[0] == 4.0 && xy[1] == 0.0);
    CHECK_NEAR(d[0], 3.0, 1e-12);
    CHECK_NEAR(d[1], -6.0, 1e-12);
    curve_bezier_eval(p, 3, 0.5, xy, d);
    CHECK_NEAR(xy[0], 2.0, 1e-12);
    CHECK_NEAR(xy[1], 1.5, 1e-12);
    /* degree 6 against the Bernstein sum C(6,i) s^i (1-s)^(6-i) P_i */
    const float q[14] = { 0, 0, 0.8f, 0, 1.1f, 0.2f, 1.4f, 0.6f, 1.5f, 0.9f, 1.5f, 1.1f, 1.6f, 1.2f };
    static const double binom[7] = { 1, 6, 15, 20, 15, 6, 1 };
    for (int k = 0; k <= 10; k++) {
        double s = k / 10.0, want[2] = { 0, 0 };
        for (int i = 0; i <= 6; i++)
            for (int c = 0; c < 2; c++) want[c] += binom[i] * pow(s, i) * pow(1.0 - s, 6 - i) * q[2 * i + c];
        curve_bezier_eval(q, 6, s, xy, d);
        CHECK_NEAR(xy[0], want[0], 1e-12);
        CHECK_NEAR(xy[1], want[1], 1e-12);
    }
}

/* The course's B-spline: its basis sums to 1 and is never negative over [t_3, t_n], and
 * the cubic Bezier pieces curve_to_segments makes draw the same curve. */
static void test_bspline(void)
{
    enum { N = 8 };
    const float p[2 * N] = { 0, 0, 0.6f, 0, 0.9f, 0.3f, 1, 1, 0.5f, 1.8f, 0.35f, 2.4f, 0.5f, 2.9f, 0.6f, 3 };
    float seg[6 * N];
    unsigned ns, deg;
    curve_to_segments(CURVE_BSPLINE, p, N, seg, &ns, &deg);
    CHECK_EQ_INT(ns, N - 3);
    CHECK_EQ_INT(deg, 3);
    double h = 1.0 / (N + 3), worst_sum = 0.0, worst_piece = 0.0, lowest = 1.0;
    for (int k = 0; k <= 200; k++) {
        double t = 3 * h + (N - 3) * h * k / 200.0, xy[2], basis[N];
        curve_bspline_eval(p, N, t, xy, basis);
        double sum = 0.0;
        for (int i = 0; i < N; i++) {
            sum += basis[i];
            if (basis[i] < lowest) lowest = basis[i];
        }
        worst_sum = fmax(worst_sum, fabs(sum - 1.0));
        unsigned j = (unsigned)((t - 3 * h) / h);
        if (j >= ns) j = ns - 1;
        double s = (t - (3 + j) * h) / h, b[2], d[2];
        curve_bezier_eval(seg + 2 * 3 * j, 3, s, b, d);
        worst_piece = fmax(worst_piece, fmax(fabs(b[0] - xy[0]), fabs(b[1] - xy[1])));
    }
    /* the course's knots i / (n + 3): the drawn part starts at t_3 at (P0 + 4 P1 + P2) / 6
     * and ends at t_n at (P5 + 4 P6 + P7) / 6 */
    double e[2];
    curve_bspline_eval(p, N, 3.0 / (N + 3), e, NULL);
    CHECK_NEAR(e[0], ((double)p[0] + 4.0 * p[2] + p[4]) / 6.0, 1e-12);
    CHECK_NEAR(e[1], ((double)p[1] + 4.0 * p[3] + p[5]) / 6.0, 1e-12);
    curve_bspline_eval(p, N, (double)N / (N + 3), e, NULL);
    CHECK_NEAR(e[0], ((double)p[10] + 4.0 * p[12] + p[14]) / 6.0, 1e-12);
    CHECK_NEAR(e[1], ((double)p[11] + 4.0 * p[13] + p[15]) / 6.0, 1e-12);
    fprintf(stderr, "  B-spline: |sum of basis - 1| <= %.2g, lowest basis value %.3g, pieces within %.2g\n",
            worst_sum, lowest, worst_piece);
    CHECK(worst_sum < 1e-12);
    CHECK(lowest >= -1e-15);
    CHECK(worst_piece < 1e-6);    /* the pieces' points are rounded to float */
}

/* -------------------------------------------------------------- intersection */

/* A surface of revolution about the y axis from the cubic Bezier p (4 (x, y) pairs). */
static RevSurface make_rev(const float *p, float axis_x, float axis_z)
{
    Scene s;
    scene_init(&s);
    RevSurface r;
    memset(&r, 0, sizeof r);
    r.axis_x = axis_x;
    r.axis_z = axis_z;
    r.n_segments = 1;
    r.degree = 3;
    CHECK(scene_add_revsurface(&s, r, p, NULL) == ST_OK);
    RevSurface out = s.revsurfaces[0];
    scene_free(&s);
    return out;
}

static Ray ray_of(vec3 o, vec3 d)
{
    Ray r;
    r.o = o;
    r.d = d;
    r.tmin = 0.0f;
    r.tmax = 1e30f;
    return r;
}

/* Shoots o + t d at rev (profile p) and checks the hit's t and unit normal. */
static void check_hit(RevSurface rev, const float *p, vec3 o, vec3 d, double want_t, vec3 want_n)
{
    Hit h;
    int hit = revsurface_intersect(rev, p, ray_of(o, d), &h);
    CHECK_MSG(hit, "ray (%g %g %g) + t (%g %g %g) missed", (double)o.x, (double)o.y, (double)o.z, (double)d.x,
              (double)d.y, (double)d.z);
    if (!hit) return;
    CHECK_MSG(fabs(h.t - want_t) <= 2e-4 * fmax(1.0, fabs(want_t)), "t %.7g, expected %.7g", (double)h.t, want_t);
    vec3 q = v3_madd(o, d, h.t);
    vec3 n = revsurface_normal(rev, p, q, h.u, h.v);
    CHECK_MSG(fabsf(n.x - want_n.x) < 1e-3f && fabsf(n.y - want_n.y) < 1e-3f && fabsf(n.z - want_n.z) < 1e-3f,
              "normal %g %g %g, expected %g %g %g", (double)n.x, (double)n.y, (double)n.z, (double)want_n.x,
              (double)want_n.y, (double)want_n.z);
}

static void test_cylinder_and_cone(void)
{
    /* x = 1 for y in 0..1 (a straight cubic): the cylinder of radius 1 */
    const float cyl[8] = { 1, 0, 1, 1.0f / 3, 1, 2.0f / 3, 1, 1 };
    RevSurface r = make_rev(cyl, 0.0f, 0.0f);
    check_hit(r, cyl, v3(0, 0.5f, 5), v3(0, 0, -1), 4.0, v3(0, 0, 1));
    check_hit(r, cyl, v3(0.6f, 0.3f, 5), v3(0, 0, -1), 4.2, v3(0.6f, 0, 0.8f));
    check_hit(r, cyl, v3(-5, 0.9f, 0), v3(2, 0, 0), 2.0, v3(-1, 0, 0));
    /* from inside: the far wall, with the same outward normal */
    check_hit(r, cyl, v3(0, 0.5f, 0), v3(0, 0, 1), 1.0, v3(0, 0, 1));
    /* a slanted ray: enters at x^2 + z^2 = 1 with y = 0.2 + 0.1 t */
    {
        vec3 o = v3(3, 0.2f, 0.5f), d = v3(-1, 0.1f, 0);
        double t = 3.0 - sqrt(1.0 - 0.25);
        check_hit(r, cyl, o, d, t, v3((float)(3.0 - t), 0, 0.5f));
    }
    Hit h;
    CHECK(!revsurface_intersect(r, cyl, ray_of(v3(0, 1.5f, 5), v3(0, 0, -1)), &h));     /* above it */
    CHECK(!revsurface_intersect(r, cyl, ray_of(v3(1.2f, 0.5f, 5), v3(0, 0, -1)), &h));  /* beside it */
    CHECK(!revsurface_intersect(r, cyl, ray_of(v3(0, 0.5f, 5), v3(0, 0, 1)), &h));      /* behind the origin */

    /* x = 1 - y: a cone of half-angle 45 degrees about an axis at (2, 0, -1) */
    const float cone[8] = { 1, 0, 2.0f / 3, 1.0f / 3, 1.0f / 3, 2.0f / 3, 0, 1 };
    RevSurface c = make_rev(cone, 2.0f, -1.0f);
    float h2 = 0.70710678f;
    check_hit(c, cone, v3(2, 0.25f, 4), v3(0, 0, -1), 5.0 - 0.75, v3(0, h2, h2));
    check_hit(c, cone, v3(-3, 0.5f, -1), v3(1, 0, 0), 5.0 - 0.5, v3(-h2, h2, 0));
    /* a vertical ray 0.5 beside the axis: d.y is all there is (A = 0), the hit at
     * y = 1 - 0.5 */
    check_hit(c, cone, v3(2.5f, 3, -1), v3(0, -1, 0), 2.5, v3(h2, h2, 0));
}

/* y = x^2 + z^2 for 0 <= y <= 1: the profile (s, s^2) is the quadratic Bezier (0, 0),
 * (1/2, 0), (1, 1), raised to degree 3. Rays from random points against the quadratic's
 * nearest root. */
static void test_paraboloid(void)
{
    const float par[8] = { 0, 0, 1.0f / 3, 0, 2.0f / 3, 1.0f / 3, 1, 1 };
    RevSurface r = make_rev(par, 0.0f, 0.0f);
    unsigned state = 7u, checked = 0;
    for (int i = 0; i < 200; i++) {
        double v[6];
        for (int k = 0; k < 6; k++) {
            state = state * 1664525u + 1013904223u;
            v[k] = (double)(state >> 8) / 16777216.0;
        }
        /* from a point around the bowl towards a point inside it */
        double ang = 2 * M_PI * v[0];
        double o[3] = { 2.5 * cos(ang), 0.2 + 1.5 * v[1], 2.5 * sin(ang) };
        double tr = 0.6 * v[2], ta = 2 * M_PI * v[3], ty = tr * tr + (1.0 - tr * tr) * v[4];
        double target[3] = { tr * cos(ta), ty, tr * sin(ta) }, d[3];
        for (int k = 0; k < 3; k++) d[k] = target[k] - o[k];
        vec3 of = v3((float)o[0], (float)o[1], (float)o[2]), df = v3((float)d[0], (float)d[1], (float)d[2]);
        /* (dx^2 + dz^2) t^2 + (2 ox dx + 2 oz dz - dy) t + ox^2 + oz^2 - oy = 0, with the
         * float ray's own numbers */
        double ox = of.x, oy = of.y, oz = of.z, dx = df.x, dy = df.y, dz = df.z;
        double a = dx * dx + dz * dz, b = 2 * (ox * dx + oz * dz) - dy, c = ox * ox + oz * oz - oy;
        double disc = b * b - 4 * a * c, best = INFINITY;
        if (disc < 0) continue;
        double roots[2] = { (-b - sqrt(disc)) / (2 * a), (-b + sqrt(disc)) / (2 * a) };
        for (int k = 0; k < 2; k++) {
            double y = oy + roots[k] * dy;
            if (roots[k] > 0 && y >= 0 && y <= 1 && roots[k] < best) best = roots[k];
        }
        if (!isfinite(best)) continue;
        /* grazing hits (the ray nearly tangent) are ill-conditioned for any solver */
        double px = ox + best * dx, pz = oz + best * dz;
        double gn[3] = { -2 * px, 1, -2 * pz }, gl = sqrt(gn[0] * gn[0] + 1 + gn[2] * gn[2]);
        double dl = sqrt(dx * dx + dy * dy + dz * dz);
        double cosang = fabs(gn[0] * dx + gn[1] * dy + gn[2] * dz) / (gl * dl);
        if (cosang < 0.05) continue;
        /* the cross product dP/ds x dP/dtheta of (s, s^2): (2s cos, -s, 2s sin) / .. =
         * minus the gradient: the normal points away from the inside of the bowl */
        vec3 want = v3((float)(-gn[0] / gl), (float)(-gn[1] / gl), (float)(-gn[2] / gl));
        check_hit(r, par, of, df, best, want);
        checked++;
    }
    fprintf(stderr, "  paraboloid: %u rays checked against the closed form\n", checked);
    CHECK(checked > 100);
}

/* Rays leaving the surface (from spawn_offset with the hit's error bound, as the
 * integrators start them) do not find it again right away: Newton runs from the ray's
 * entry into the segment's shell, polishes a root to the floats' rounding and accepts
 * only roots that close, so the hit point lies within the offset. (Without those three,
 * 7 of these rays hit the vase again: shadow acne.) */
static void test_leaving_rays(void)
{
    const float ctrl[16] = { 0, 0, 0.6f, 0, 0.9f, 0.3f, 1, 1, 0.5f, 1.8f, 0.35f, 2.4f, 0.5f, 2.9f, 0.6f, 3 };
    float xy[48];
    unsigned ns, deg;
    curve_to_segments(CURVE_BSPLINE, ctrl, 8, xy, &ns, &deg);
    Scene s;
    scene_init(&s);
    RevSurface r;
    memset(&r, 0, sizeof r);
    r.n_segments = ns;
    r.degree = deg;
    r.axis_x = -1.3f;
    CHECK(scene_add_revsurface(&s, r, xy, NULL) == ST_OK);
    RevSurface rev = s.revsurfaces[0];
    unsigned state = 99u, hits = 0, again = 0;
    for (int i = 0; i < 4000; i++) {
        float v[5];
        for (int k = 0; k < 5; k++) {
            state = state * 1664525u + 1013904223u;
            v[k] = (float)(state >> 8) / 16777216.0f;
        }
        vec3 o = v3(-1.3f + 8.0f * (v[0] - 0.5f), 4.0f * v[1] - 0.5f, 9.0f);
        vec3 target = v3(-1.3f + 1.6f * (v[2] - 0.5f), 3.0f * v[3], 0.0f);
        Ray ray = ray_of(o, v3_sub(target, o));
        Hit h;
        if (!revsurface_intersect(rev, s.rev_points, ray, &h)) continue;
        hits++;
        vec3 q = v3_madd(ray.o, ray.d, h.t);
        vec3 n = revsurface_normal(rev, s.rev_points, q, h.u, h.v);
        if (v3_dot(n, ray.d) > 0.0f) n = v3_neg(n);
        /* towards a light above and in front, on the side the ray came from */
        vec3 l = v3_sub(v3(-5.0f + 3.0f * v[4], 8.0f, 6.0f), q);
        if (v3_dot(l, n) <= 0.0f) continue;
        Ray out = ray_of(spawn_offset(q, revsurface_point_error(rev, ray, h.t), n), l);
        out.tmax = 1.0f;
        Hit h2;
        if (revsurface_intersect(rev, s.rev_points, out, &h2) && h2.t * v3_len(l) < 1e-3f) again++;
    }
    fprintf(stderr, "  %u hits, %u rays leaving them hit the surface again within 1e-3\n", hits, again);
    CHECK(hits > 1000);
    CHECK_EQ_INT(again, 0);
    scene_free(&s);
}

/* ------------------------------------------------------------------ scenes */

static const char *scene_text(void)
{
    return "PerspectiveCamera { center 0 1.5 7 direction 0 -0.15 -1 up 0 1 0 angle 35 width 48 height 40 }\n"
           "Lights { numLights 1 PointLight { position -4 6 5 color 0.9 0.9 0.9 } }\n"
           "Background { color 0.2 0.2 0.3 ambientLight 0.1 0.1 0.1 }\n"
           "Materials { numMaterials 2 PhongMaterial { diffuseColor 0.2 0.4 0.8 specularColor 0.5 0.5 0.5 "
           "shininess 30 }\n PhongMaterial { diffuseColor 0.8 0.5 0.2 reflectiveColor 0.3 0.3 0.3 } }\n"
           "Group { numObjects 4\n"
           "  Plane { normal 0 1 0 offset -1 }\n"
           "  MaterialIndex 0\n"
           "  Transform { Translate -1.2 -1 0 RevSurface { profile BsplineCurve { controls [ 0 0 0 ] "
           "[ 0.6 0 0 ] [ 0.9 0.3 0 ] [ 1 1 0 ] [ 0.5 1.8 0 ] [ 0.35 2.4 0 ] [ 0.5 2.9 0 ] [ 0.6 3 0 ] } } }\n"
           "  MaterialIndex 1\n"
           "  Transform { Translate 1.3 -1 0.5 UniformScale 0.7 RevSurface { profile BezierCurve { controls "
           "[ 0 0 0 ] [ 0.8 0 0 ] [ 1.1 0.2 0 ] [ 1.4 0.6 0 ] [ 1.5 0.9 0 ] [ 1.5 1.1 0 ] [ 1.6 1.2 0 ] } } }\n"
           "  Transform { Translate 0 1.2 -2 ZRotate 30 RevSurface { profile BezierCurve { controls "
           "[ 0.5 0 0 ] [ 0.7 0.3 0 ] [ 0.4 0.6 0 ] [ 0.3 1 0 ] } } }\n"
           "}\n";
}

static void load_scene(Scene *s)
{
    scene_init(s);
    Error err = { 0 };
    const char *t = scene_text();
    Status st = classic_load_text("curves.txt", t, strlen(t), s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
}

/* What the reader makes of the profiles: B-spline pieces, one Bezier segment, the
 * scaled and moved axis, and a mesh for the surface whose axis a rotation tilts. */
static void test_reader(void)
{
    Scene s;
    load_scene(&s);
    CHECK_EQ_INT(s.n_revsurfaces, 2);
    if (s.n_revsurfaces == 2) {
        RevSurface a = s.revsurfaces[0], b = s.revsurfaces[1];
        CHECK_EQ_INT(a.n_segments, 5);
        CHECK_EQ_INT(a.degree, 3);
        CHECK(a.axis_x == -1.2f && a.axis_z == 0.0f);
        /* a B-spline starts and ends short of its end control points: (P0 + 4P1 + P2)/6 */
        CHECK_NEAR(a.lo.y, -1.0 + 0.3 / 6, 1e-6);
        CHECK_NEAR(a.hi.y, -1.0 + (2.4 + 4 * 2.9 + 3) / 6, 1e-6);
        CHECK_EQ_INT(b.n_segments, 1);
        CHECK_EQ_INT(b.degree, 6);
        CHECK(b.axis_x == 1.3f && b.axis_z == 0.5f);
        /* the last control point (1.6, 1.2) scaled by 0.7 and lifted by -1 */
        const float *last = s.rev_points + 2 * (b.first + 6);
        CHECK_NEAR(last[0], 1.12, 1e-6);
        CHECK_NEAR(last[1], -1.0 + 0.84, 1e-6);
        CHECK_NEAR(b.hi.x - b.axis_x, 1.12, 1e-6);
    }
    CHECK_EQ_INT(s.n_rev_points, 2 * (16 + 7));
    CHECK_EQ_INT(s.n_triangles, 2 * 16 * 96);
    scene_free(&s);
}

static float *render(Scene *s, const char *devices, Film *film)
{
    Error err = { 0 };
    Status st = render_util_run(s, devices, 0, film, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    size_t n = (size_t)film->width * film->height * 3u;
    float *rgb = calloc(n ? n : 1, sizeof *rgb);
    if (st == ST_OK) film_resolve(film, rgb);
    error_clear(&err);
    return rgb;
}

/* The scene through both integrators and the normal image: PoCL's film has the very
 * bits of the scalar device's. */
static void test_devices_agree(void)
{
    const uint modes[3] = { INTEGRATOR_WHITTED, INTEGRATOR_PATH, INTEGRATOR_AOV_NORMAL };
    for (int m = 0; m < 3; m++) {
        Scene s;
        load_scene(&s);
        s.integrator = modes[m];
        s.image.spp = modes[m] == INTEGRATOR_PATH ? 2 : 1;
        Film a, b;
        free(render(&s, "scalar", &a));
        free(render(&s, TEST_OPENCL, &b));
        size_t n = (size_t)a.width * a.height * 3u;
        CHECK_MSG(a.width == b.width && a.height == b.height && memcmp(a.sum, b.sum, n * sizeof *a.sum) == 0,
                  "integrator %u: PoCL and scalar films differ", modes[m]);
        film_free(&a);
        film_free(&b);
        scene_free(&s);
    }
}

/* The vase of scene_text alone, exact or as a mesh of `steps` x `around` quads per
 * segment, seen from a camera 64 x 64, as the image `mode`. */
static float *render_vase(int mesh, uint mode)
{
    const float ctrl[16] = { 0, 0, 0.6f, 0, 0.9f, 0.3f, 1, 1, 0.5f, 1.8f, 0.35f, 2.4f, 0.5f, 2.9f, 0.6f, 3 };
    float xy[48];
    unsigned ns, deg;
    curve_to_segments(CURVE_BSPLINE, ctrl, 8, xy, &ns, &deg);
    Scene s;
    scene_init(&s);
    s.image.width = s.image.height = 64;
    s.image.spp = 1;
    s.image.max_depth = 1;
    s.integrator = mode;
    s.camera.from = v3(0.5f, 2.5f, 5.0f);
    s.camera.at = v3(0.0f, 1.2f, 0.0f);
    s.camera.up = v3(0.0f, 1.0f, 0.0f);
    s.camera.vfov = 40.0f;
    uint m;
    scene_add_material(&s, "m", material_phong(v3s(0.8f), v3s(0.0f), 0.0f), &m, NULL);
    Error err = { 0 };
    if (mesh) {
        Transform id = transform_identity();
        CHECK(curve_mesh_revsurface(&s, xy, ns, deg, &id, m, 24, 256, &err) == ST_OK);
    } else {
        RevSurface r;
        memset(&r, 0, sizeof r);
        r.material = m;
        r.n_segments = ns;
        r.degree = deg;
        CHECK(scene_add_revsurface(&s, r, xy, &err) == ST_OK);
    }
    Film f;
    float *rgb = render(&s, "scalar", &f);
    film_free(&f);
    scene_free(&s);
    return rgb;
}

/* The exact surface against a mesh of 24 x 256 quads per segment: they cover the same
 * pixels but for a few on the silhouette, at the same depth, with the same normals
 * (the mesh's are interpolated from the exact ones at its corners). */
static void test_against_mesh(void)
{
    float *de = render_vase(0, INTEGRATOR_AOV_DEPTH), *dm = render_vase(1, INTEGRATOR_AOV_DEPTH);
    float *ne = render_vase(0, INTEGRATOR_AOV_NORMAL), *nm = render_vase(1, INTEGRATOR_AOV_NORMAL);
    uint both = 0, differ = 0;
    double worst_depth = 0.0, sum_normal = 0.0, worst_normal = 0.0;
    for (uint i = 0; i < 64 * 64; i++) {
        int he = de[3 * i + 1] > 0.5f, hm = dm[3 * i + 1] > 0.5f;
        if (he != hm) {
            differ++;
            continue;
        }
        if (!he) continue;
        both++;
        worst_depth = fmax(worst_depth, fabs(de[3 * i] - dm[3 * i]) / de[3 * i]);
        double e = 0.0;
        for (int k = 0; k < 3; k++) e = fmax(e, 2.0 * fabs(ne[3 * i + k] - nm[3 * i + k]));
        sum_normal += e;
        worst_normal = fmax(worst_normal, e);
    }
    fprintf(stderr, "  exact vs mesh: %u pixels hit by both, %u by one only; depth within %.2g (relative), "
            "normals within %.3g (mean %.2g)\n", both, differ, worst_depth, worst_normal,
            both ? sum_normal / both : 0.0);
    CHECK(both > 600);
    CHECK(differ <= 6);
    CHECK(worst_depth < 2e-3);
    CHECK(both && sum_normal / both < 5e-3);
    CHECK(worst_normal < 0.05);
    free(de);
    free(dm);
    free(ne);
    free(nm);
}

int main(void)
{
    RUN(test_bezier_points);
    RUN(test_bspline);
    RUN(test_cylinder_and_cone);
    RUN(test_paraboloid);
    RUN(test_leaving_rays);
    RUN(test_reader);
    RUN(test_against_mesh);
    RUN(test_devices_agree);
    return harness_report();
}
