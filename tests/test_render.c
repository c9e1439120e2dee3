/*
 * test_render.c — whole images: light transport against an analytic answer (the white
 * furnace), OpenCL (PoCL) against the scalar C device, and the same image bits on any
 * device mix and batch size.
 */
#include <stdlib.h>

#include "harness.h"
#include "base/pages.h"
#include "util/kmath.h"
#include "render_util.h"

/* A diffuse sphere of albedo 0.5 that also emits 0.5, seen from its centre: the
 * radiance L satisfies L = 0.5 + 0.5 L everywhere, so every pixel's expected value is 1
 * (minus 0.5^(depth+1) for the paths cut at the maximum depth). */
static void furnace_scene(Scene *s, uint spp)
{
    scene_init(s);
    s->image.width = 24;
    s->image.height = 24;
    s->image.spp = spp;
    s->image.max_depth = 24;
    s->image.seed = 7;
    s->camera.from = v3(0.0f, 0.0f, 0.0f);
    s->camera.at = v3(0.0f, 0.0f, -1.0f);
    s->camera.vfov = 90.0f;
    Material m = material_diffuse(v3s(0.5f));
    m.emission = v3s(0.5f);
    m.flags = MAT_TWO_SIDED;   /* seen from inside */
    uint mi;
    scene_add_material(s, "furnace", m, &mi, NULL);
    Sphere sp = { v3(0.0f, 0.0f, 0.0f), 1.0f, mi, NO_INDEX, 0, 0 };
    scene_add_sphere(s, sp, NULL);
}

static void check_furnace_split(const char *devices, uint split)
{
    Scene s;
    furnace_scene(&s, 64);
    s.image.split = split;
    Film f;
    Error err = { 0 };
    Status st = render_util_run(&s, devices, 0, &f, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) {
        double mean = film_mean(&f);
        fprintf(stderr, "  furnace on %s, split %u: image mean %.5f (expected 1.0)\n", devices, split, mean);
        CHECK_NEAR(mean, 1.0, 0.025);
    }
    film_free(&f);
    scene_free(&s);
    error_clear(&err);
}

static void test_furnace_scalar(void) { check_furnace_split("scalar", 1); }
static void test_furnace_opencl(void) { check_furnace_split(TEST_OPENCL, 1); }
/* First-hit splitting is unbiased: three continuations of each camera sample, each
 * weighted a third, give the furnace's 1 too. */
static void test_furnace_split(void)
{
    check_furnace_split("scalar", 3);
    check_furnace_split(TEST_OPENCL, 3);
}

/* With first-hit splitting, each device restarts a camera sample's path from its first
 * hit in the same steps (path_run, path_run_lanes, the scalar device's render_path), so
 * the films are equal bit for bit: the Cornell box (k_path_lanes on PoCL), the same with
 * independent random numbers (k_path), and the furnace's sphere (k_path). */
static void check_split_matches(const char *file, uint sampler)
{
    Scene a, b;
    Error err = { 0 };
    Status st = ST_OK;
    if (file) {
        scene_init(&a);
        scene_init(&b);
        if ((st = scene_load(file, &a, &err)) || (st = scene_load(file, &b, &err))) {
            CHECK_MSG(0, "%s", err.msg);
            scene_free(&a);
            scene_free(&b);
            error_clear(&err);
            return;
        }
        a.image.width = b.image.width = 48;
        a.image.height = b.image.height = 48;
        a.image.spp = b.image.spp = 8;
    } else {
        furnace_scene(&a, 8);
        furnace_scene(&b, 8);
    }
    a.image.split = b.image.split = 3;
    a.image.sampler = b.image.sampler = sampler;
    Film fa, fb, f1;
    memset(&fa, 0, sizeof fa);
    memset(&fb, 0, sizeof fb);
    memset(&f1, 0, sizeof f1);
    CHECK_MSG((st = render_util_run(&a, TEST_OPENCL, 0, &fa, &err)) == ST_OK, "%s", err.msg);
    CHECK_MSG((st = render_util_run(&b, "scalar", 0, &fb, &err)) == ST_OK, "%s", err.msg);
    b.image.split = 1;
    CHECK_MSG((st = render_util_run(&b, "scalar", 0, &f1, &err)) == ST_OK, "%s", err.msg);
    if (fa.sum && fb.sum && f1.sum) {
        size_t n = (size_t)fa.width * fa.height * 3u, exact = 0, same_as_one = 0;
        for (size_t i = 0; i < n; i++) {
            exact += fa.sum[i] == fb.sum[i];
            same_as_one += fb.sum[i] == f1.sum[i];
        }
        fprintf(stderr, "  %s, split 3: %zu of %zu channel sums identical on OpenCL and scalar; %zu as split 1's\n",
                file ? file : "furnace", exact, n, same_as_one);
        CHECK_EQ_INT(exact, n);
        CHECK(same_as_one < n / 2);   /* it did split */
    }
    film_free(&fa);
    film_free(&fb);
    film_free(&f1);
    scene_free(&a);
    scene_free(&b);
    error_clear(&err);
}

static void test_split_opencl_matches_scalar(void)
{
    check_split_matches("scenes/cornell-box.scene", SAMPLER_SOBOL);
    check_split_matches("scenes/cornell-box.scene", SAMPLER_INDEPENDENT);
    check_split_matches(NULL, SAMPLER_SOBOL);
}

/* The Cornell box on PoCL and on the scalar device: both run the same kernel source on
 * the same random numbers, so they must agree (the goal is bit for bit; the stated
 * tolerance is a mean absolute difference under 1e-3 of the image mean). */
static void test_opencl_matches_scalar(void)
{
    Scene a, b;
    Error err = { 0 };
    scene_init(&a);
    scene_init(&b);
    Status st = scene_load("scenes/cornell-box.scene", &a, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    st = scene_load("scenes/cornell-box.scene", &b, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    a.image.width = b.image.width = 64;
    a.image.height = b.image.height = 64;
    a.image.spp = b.image.spp = 16;
    Film fa, fb;
    CHECK((st = render_util_run(&a, TEST_OPENCL, 0, &fa, &err)) == ST_OK);
    if (st) fprintf(stderr, "  %s\n", err.msg);
    CHECK((st = render_util_run(&b, "scalar", 0, &fb, &err)) == ST_OK);
    if (st) fprintf(stderr, "  %s\n", err.msg);
    if (fa.sum && fb.sum) {
        size_t n = (size_t)fa.width * fa.height * 3u;
        float *ra = malloc(n * sizeof *ra), *rb = malloc(n * sizeof *rb);
        film_resolve(&fa, ra);
        film_resolve(&fb, rb);
        double diff = 0.0, mean = 0.0;
        size_t exact = 0;
        for (size_t i = 0; i < n; i++) {
            diff += fabs((double)ra[i] - (double)rb[i]);
            mean += rb[i];
            exact += fa.sum[i] == fb.sum[i];
        }
        diff /= (double)n;
        mean /= (double)n;
        fprintf(stderr, "  OpenCL vs scalar: mean %.5f, mean abs difference %.3g, %zu of %zu channel sums identical\n",
                mean, diff, exact, n);
        CHECK(mean > 0.01);
        CHECK(diff < 1e-3 * mean);
        free(ra);
        free(rb);
    }
    film_free(&fa);
    film_free(&fb);
    scene_free(&a);
    scene_free(&b);
    error_clear(&err);
}

/* Renders spp samples with the one device d as it is loaded now; 0 on failure. */
static int render_on(Device *d, const RenderParams *p, uint spp, Film *film)
{
    Error err = { 0 };
    ScheduleConfig cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = spp;
    ScheduleStats stats;
    memset(&stats, 0, sizeof stats);
    Status st = film_init(film, p->width, p->height, &err);
    if (st == ST_OK) st = schedule_run(&d, 1, &cfg, film, &stats, &err);
    schedule_stats_free(&stats);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    error_clear(&err);
    return st == ST_OK;
}

static int films_equal(const Film *a, const Film *b)
{
    size_t n = (size_t)a->width * a->height * 3u;
    return a->sum && b->sum && a->samples == b->samples && memcmp(a->sum, b->sum, n * sizeof *a->sum) == 0;
}

/* One change of the params block and pixel list, made with update_params on a loaded
 * device, must give the very film a device given the changed scene whole gives. */
static void check_update(const DeviceDesc *desc, RenderScene *rs, const RenderParams *changed, const uint *list)
{
    Error err = { 0 };
    Device *kept = NULL, *fresh = NULL;
    Film before, updated, reloaded;
    memset(&before, 0, sizeof before);
    memset(&updated, 0, sizeof updated);
    memset(&reloaded, 0, sizeof reloaded);
    DeviceScene ds = rs->ds;
    Status st = device_open(desc, NULL, &kept, &err);
    if (st == ST_OK) st = kept->ops->load_scene(kept, &ds, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK && render_on(kept, &ds.params, 4, &before)) {
        st = kept->ops->update_params(kept, changed, list, &err);
        CHECK_MSG(st == ST_OK, "update_params: %s", err.msg);
        if (st == ST_OK) render_on(kept, changed, 4, &updated);
    }
    ds.params = *changed;
    ds.pixel_list = list;
    st = device_open(desc, NULL, &fresh, &err);
    if (st == ST_OK) st = fresh->ops->load_scene(fresh, &ds, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) render_on(fresh, changed, 4, &reloaded);
    CHECK_MSG(films_equal(&updated, &reloaded), "device %s: update_params and a full load differ", desc->name);
    CHECK_MSG(before.sum && updated.sum && !films_equal(&before, &updated), "device %s: update_params changed nothing",
              desc->name);
    if (list && before.sum && updated.sum && changed->integrator == rs->ds.params.integrator &&
        changed->seed == rs->ds.params.seed) {
        /* the same render over a pixel list: its pixels hold the bits they hold without
         * one, the others nothing */
        size_t wrong = 0, listed = 0, n = (size_t)changed->width * changed->height;
        for (size_t i = 0; i < n; i++) {
            int in = listed < changed->pixel_list_size && list[listed] == i;
            listed += in;
            for (int c = 0; c < 3; c++) wrong += updated.sum[3 * i + c] != (in ? before.sum[3 * i + c] : 0);
        }
        CHECK_MSG(wrong == 0, "device %s: %zu film entries of the listed render differ from the whole one's",
                  desc->name, wrong);
    }
    film_free(&before);
    film_free(&updated);
    film_free(&reloaded);
    device_close(kept);
    device_close(fresh);
    error_clear(&err);
}

/* update_params (the passes' way to change the render without uploading the scene
 * again) on the scalar device and on PoCL: another seed and a deeper path, then the
 * classic integrator and the path tracer over a pixel list. */
static void check_update_params(const char *spec)
{
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    Status st = scene_load("scenes/cornell-box.scene", &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    s.image.width = 24;
    s.image.height = 16;
    s.image.max_depth = 3;
    RenderScene rs;
    memset(&rs, 0, sizeof rs);
    if (st == ST_OK) st = render_scene_prepare(&s, 0, &rs, &err);
    DeviceDesc *all = NULL;
    size_t n_all = 0, *chosen = NULL, n_chosen = 0;
    char warning[1100];
    if (st == ST_OK) st = device_list(&all, &n_all, warning, sizeof warning, &err);
    if (st == ST_OK) st = device_select(spec, all, n_all, &chosen, &n_chosen, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) {
        RenderParams p = rs.ds.params;
        p.seed = 1234u;
        p.max_depth = 9u;   /* more bounces than loaded: the OpenCL counters grow */
        check_update(&all[chosen[0]], &rs, &p, NULL);
        uint mask[24 * 16], list[24 * 16];
        for (uint i = 0; i < 24u * 16u; i++) mask[i] = (i % 3u) != 0u;
        p = rs.ds.params;
        p.integrator = INTEGRATOR_WHITTED;
        p.pixel_list_size = render_scene_list_pixels(mask, 24u * 16u, list);
        p.strata = 1;
        check_update(&all[chosen[0]], &rs, &p, list);
        /* the path tracer over a pixel list: the listed pixels as an unlisted render
         * gives them, the others empty (adaptive.c's rounds) */
        p = rs.ds.params;
        p.pixel_list_size = render_scene_list_pixels(mask, 24u * 16u, list);
        check_update(&all[chosen[0]], &rs, &p, list);
    }
    free(chosen);
    free(all);
    render_scene_free(&rs);
    scene_free(&s);
    error_clear(&err);
}

static void test_update_params_scalar(void) { check_update_params("scalar"); }
static void test_update_params_opencl(void) { check_update_params(TEST_OPENCL); }

/* ------------------------------------------------------------------ ellipsoids */

/* The ellipsoid of the tests: the unit sphere under scale (2, 1, 0.5), turned 30
 * degrees about (1, 1, 0) (issue 39's squashed spheres). */
static Transform ellipsoid_transform(void)
{
    Transform r = transform_rotate(1.0, 1.0, 0.0, 30.0), sc = transform_scale(2.0, 1.0, 0.5);
    return transform_compose(&r, &sc);
}

/* A 48 x 48 image of the ellipsoid (diffuse, albedo 0.5) under a white sky, analytic or
 * as a UV sphere of 512 x 256 quads carried by the same transform with the exact
 * normals at its corners; `integrator` the path tracer or an AOV. */
static void ellipsoid_scene(Scene *s, int mesh, uint integrator)
{
    scene_init(s);
    s->image.width = 48;
    s->image.height = 48;
    s->image.spp = 16;
    s->image.max_depth = 3;
    s->image.seed = 5;
    s->integrator = integrator;
    s->bg_type = BG_CONSTANT;
    s->bg_color = v3s(1.0f);
    s->camera.from = v3(1.0f, 2.0f, 6.0f);
    s->camera.at = v3(0.0f, 0.0f, 0.0f);
    s->camera.vfov = 45.0f;
    uint mi;
    scene_add_material(s, "clay", material_diffuse(v3s(0.5f)), &mi, NULL);
    Transform m = ellipsoid_transform();
    if (!mesh) {
        CHECK_EQ_INT(scene_add_ellipsoid(s, &m, mi, NULL), ST_OK);
        return;
    }
    double nm[3][3];
    transform_normal_matrix(&m, nm);
    enum { NU = 512, NV = 256 };
    for (int j = 0; j < NV; j++)
        for (int i = 0; i < NU; i++) {
            vec3 q[4], n[4];
            for (int c = 0; c < 4; c++) {
                int ii = i + (c == 1 || c == 2), jj = j + (c >= 2);
                double phi = 2 * M_PI * ii / NU, th = M_PI * jj / NV;
                double o[3] = { sin(th) * cos(phi), sin(th) * sin(phi), cos(th) }, w[3];
                for (int k = 0; k < 3; k++) w[k] = nm[k][0] * o[0] + nm[k][1] * o[1] + nm[k][2] * o[2];
                double l = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
                q[c] = transform_point(&m, v3((float)o[0], (float)o[1], (float)o[2]));
                n[c] = v3((float)(w[0] / l), (float)(w[1] / l), (float)(w[2] / l));
            }
            int tri[2][3] = { { 0, 2, 1 }, { 0, 3, 2 } };   /* outward winding */
            for (int t = 0; t < 2; t++) {
                if ((t == 0 && j == 0) || (t == 1 && j == NV - 1)) continue;
                TriShading sh;
                memset(&sh, 0, sizeof sh);
                sh.n0 = n[tri[t][0]];
                sh.n1 = n[tri[t][1]];
                sh.n2 = n[tri[t][2]];
                sh.flags = TRI_HAS_NORMALS;
                uint si;
                scene_add_shading(s, sh, &si, NULL);
                Triangle tr = { q[tri[t][0]], mi, q[tri[t][1]], NO_INDEX, q[tri[t][2]], si };
                scene_add_triangle(s, tr, NULL);
            }
        }
}

static Status ellipsoid_render(int mesh, uint integrator, uint accel, const char *device, float *rgb, Film *keep)
{
    Scene s;
    ellipsoid_scene(&s, mesh, integrator);
    s.accel = accel;
    Film f;
    Error err = { 0 };
    Status st = render_util_run(&s, device, 0, &f, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (!st) {
        if (rgb) film_resolve(&f, rgb);
        if (keep) *keep = f;
        else film_free(&f);
    }
    scene_free(&s);
    return st;
}

static double rmse(const float *a, const float *b, size_t n)
{
    double e = 0.0;
    for (size_t i = 0; i < n; i++) e += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return sqrt(e / (double)n);
}

/* The analytic ellipsoid looks like a fine mesh of it: its normals (the AOV, no noise)
 * and its path-traced image (16 samples: the noise bounds the tolerance). */
static void test_ellipsoid_like_mesh(void)
{
    enum { N = 48 * 48 * 3 };
    static float a[N], b[N];
    static const uint integrators[] = { INTEGRATOR_AOV_NORMAL, INTEGRATOR_PATH };
    static const double limits[] = { 0.02, 0.05 };
    for (int k = 0; k < 2; k++) {
        if (ellipsoid_render(0, integrators[k], ACCEL_BVH, "scalar", a, NULL) ||
            ellipsoid_render(1, integrators[k], ACCEL_BVH, "scalar", b, NULL))
            return;
        double e = rmse(a, b, N);
        /* the ellipsoid covers a good part of the image (so the comparison means something) */
        size_t on = 0;
        for (size_t i = 0; i < N; i += 3) on += k ? a[i] < 0.99f : (a[i] != a[0] || a[i + 1] != a[1]);
        fprintf(stderr, "  ellipsoid against a mesh of 262,144 triangles, %s: RMSE %.5f (%zu of %d pixels on it)\n",
                k ? "path traced" : "normals", e, on, N / 3);
        CHECK(on > N / 3 / 5);
        CHECK(e < limits[k]);
    }
}

/* The same image bits on PoCL and the scalar device, and through either tree. */
static void test_ellipsoid_devices_trees(void)
{
    Film fa, fb, fc;
    if (ellipsoid_render(0, INTEGRATOR_PATH, ACCEL_BVH, TEST_OPENCL, NULL, &fa)) return;
    if (ellipsoid_render(0, INTEGRATOR_PATH, ACCEL_BVH, "scalar", NULL, &fb) == ST_OK) {
        if (ellipsoid_render(0, INTEGRATOR_PATH, ACCEL_KDTREE, "scalar", NULL, &fc) == ST_OK) {
            size_t n = (size_t)fa.width * fa.height * 3u, same_dev = 0, same_tree = 0;
            for (size_t i = 0; i < n; i++) {
                same_dev += fa.sum[i] == fb.sum[i];
                same_tree += fb.sum[i] == fc.sum[i];
            }
            CHECK_EQ_INT(same_dev, n);
            CHECK_EQ_INT(same_tree, n);
            film_free(&fc);
        }
        film_free(&fb);
    }
    film_free(&fa);
}

/* A mesh whose tree is larger than a huge page: an OpenCL CPU device uses the tree's
 * arrays where the host built them (on huge pages; ocl_buffers.c) instead of copying
 * them, and renders the bits the scalar device renders from the same arrays. A GPU
 * copies everything. */
static void test_mesh_tree_in_place(void)
{
    Scene s;
    ellipsoid_scene(&s, 1, INTEGRATOR_PATH);
    s.image.spp = 4;
    Film fa, fb;
    DeviceCounters c;
    memset(&c, 0, sizeof c);
    Error err = { 0 };
    Status st = render_util_run_counted(&s, RENDER_UTIL_SCENE_MIS, TEST_OPENCL, NULL, 0, &fa, &c, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) {
        fprintf(stderr, "  %.1f MiB of the scene used in place on %s\n", (double)c.bytes_in_place / 1048576.0,
                TEST_OPENCL);
        if (!TEST_OPENCL_IS_GPU) CHECK(c.bytes_in_place >= PAGES_HUGE_BYTES);
        st = render_util_run(&s, "scalar", 0, &fb, &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        if (st == ST_OK) {
            size_t n = (size_t)fa.width * fa.height * 3u, same = 0, lit = 0;
            for (size_t i = 0; i < n; i++) {
                same += fa.sum[i] == fb.sum[i];
                lit += fa.sum[i] != 0;
            }
            CHECK_EQ_INT(same, n);
            CHECK(lit > n / 2);
            film_free(&fb);
        }
        film_free(&fa);
    }
    scene_free(&s);
    error_clear(&err);
}

int main(void)
{
    RUN(test_furnace_scalar);
    RUN(test_furnace_opencl);
    RUN(test_opencl_matches_scalar);
    RUN(test_furnace_split);
    RUN(test_split_opencl_matches_scalar);
    RUN(test_update_params_scalar);
    RUN(test_update_params_opencl);
    RUN(test_ellipsoid_like_mesh);
    RUN(test_ellipsoid_devices_trees);
    RUN(test_mesh_tree_in_place);
    return harness_report();
}
