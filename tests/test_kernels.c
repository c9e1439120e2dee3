/*
 * test_kernels.c — every kernel run through OpenCL (the first OpenCL CPU device: PoCL
 * here) and through the scalar C path on the same inputs, outputs compared.
 *
 * Both sides compile the same source (kernels/), use the same random numbers and avoid
 * every operation whose rounding is implementation-defined, so the goal is identical
 * bits; the assertions use the stated tolerances (hits: same primitive and t within 1e-5
 * relative; colours within 1e-5 relative) and the test prints how many results were
 * bit-identical.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "ocl_program.h"
#include "render_scene.h"

/* the kernel stage functions, compiled as C: the reference */
#include "film.cl"
#include "raygen.cl"
#include "shade.cl"
#include "traverse.cl"

typedef struct {
    OclDeviceInfo dev;
    cl_context ctx;
    cl_command_queue q;
    cl_program prog;
    cl_mem scene[10];
    int ok;
} Cl;

static Cl cl;
static Scene scene;
static RenderScene rs;
static SceneView view;    /* the C side's view of the same scene */

static unsigned rng_state = 12345u;
static float frand(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) * (1.0f / 16777216.0f);
}
static float frange(float lo, float hi) { return lo + (hi - lo) * frand(); }
static vec3 vrand(float lo, float hi) { return v3(frange(lo, hi), frange(lo, hi), frange(lo, hi)); }

/* A small scene with every primitive type and material type, and lights of each
 * lightable shape. */
static void build_scene(void)
{
    scene_init(&scene);
    scene.image.width = 32;
    scene.image.height = 24;
    scene.image.max_depth = 6;
    scene.image.seed = 99;
    scene.camera.from = v3(0.0f, 2.0f, 9.0f);
    scene.camera.at = v3(0.0f, 0.5f, 0.0f);
    scene.camera.aperture = 0.2f;
    scene.camera.focus_dist = 8.0f;
    scene.bg_type = BG_SKY;
    scene.bg_color = v3(1.0f, 1.0f, 1.0f);
    scene.bg_zenith = v3(0.5f, 0.7f, 1.0f);
    uint diffuse, metal, glass, lamp, glow;
    scene_add_material(&scene, "diffuse", material_diffuse(v3(0.7f, 0.5f, 0.3f)), &diffuse, NULL);
    scene_add_material(&scene, "metal", material_metal(v3(0.9f, 0.9f, 0.8f), 0.2f), &metal, NULL);
    scene_add_material(&scene, "glass", material_dielectric(1.5f), &glass, NULL);
    scene_add_material(&scene, "lamp", material_emissive(v3(6.0f, 5.0f, 4.0f)), &lamp, NULL);
    Material g = material_diffuse(v3s(0.4f));
    g.emission = v3(0.5f, 0.2f, 0.1f);
    scene_add_material(&scene, "glow", g, &glow, NULL);
    uint mats[] = { diffuse, metal, glass, diffuse, glow };
    for (int i = 0; i < 12; i++) {
        Sphere s = { vrand(-3.0f, 3.0f), frange(0.2f, 0.8f), mats[i % 5], NO_INDEX, 0, 0 };
        scene_add_sphere(&scene, s, NULL);
    }
    Sphere light_sphere = { v3(0.0f, 5.0f, 0.0f), 0.5f, lamp, NO_INDEX, 0, 0 };
    scene_add_sphere(&scene, light_sphere, NULL);
    for (int i = 0; i < 30; i++) {
        vec3 c = vrand(-3.0f, 3.0f);
        Triangle t = { v3_add(c, vrand(-1.0f, 1.0f)), mats[i % 5], v3_add(c, vrand(-1.0f, 1.0f)), NO_INDEX,
                       v3_add(c, vrand(-1.0f, 1.0f)), NO_INDEX };
        scene_add_triangle(&scene, t, NULL);
    }
    Triangle lt = { v3(-1.0f, 4.0f, -1.0f), lamp, v3(1.0f, 4.0f, -1.0f), NO_INDEX, v3(0.0f, 4.0f, 1.0f), NO_INDEX };
    scene_add_triangle(&scene, lt, NULL);
    for (int i = 0; i < 4; i++) {
        vec3 lo = vrand(-3.0f, 2.0f);
        Box b = { lo, mats[i % 5], v3_add(lo, vrand(0.2f, 1.0f)), NO_INDEX };
        scene_add_box(&scene, b, NULL);
    }
    Box lb = { v3(2.0f, 3.0f, 2.0f), lamp, v3(2.5f, 3.2f, 2.4f), NO_INDEX };
    scene_add_box(&scene, lb, NULL);
    Plane floor = { v3(0.0f, 1.0f, 0.0f), -3.5f, diffuse, 0, 0, 0 };
    scene_add_plane(&scene, floor, NULL);
    Error err = { 0 };
    Status st = render_scene_prepare(&scene, 1, &rs, &err);
    if (st) fprintf(stderr, "scene setup failed: %s\n", err.msg);
    view.params = &rs.ds.params;
    view.nodes = rs.ds.nodes;
    view.leaf_prims = rs.ds.leaf_prims;
    view.spheres = rs.ds.spheres;
    view.triangles = rs.ds.triangles;
    view.boxes = rs.ds.boxes;
    view.planes = rs.ds.planes;
    view.materials = rs.ds.materials;
    view.lights = rs.ds.lights;
    view.shading = rs.ds.shading;
}

static cl_mem buffer(size_t bytes, const void *src)
{
    cl_int rc;
    if (bytes < 16) bytes = 16;
    cl_mem m = clCreateBuffer(cl.ctx, CL_MEM_READ_WRITE | (src ? CL_MEM_COPY_HOST_PTR : 0), bytes,
                              (void *)(uintptr_t)src, &rc);
    CHECK_MSG(rc == CL_SUCCESS, "clCreateBuffer: %s", ocl_error_name(rc));
    return m;
}

static void read_back(cl_mem m, size_t bytes, void *dst)
{
    cl_int rc = clEnqueueReadBuffer(cl.q, m, CL_TRUE, 0, bytes, dst, 0, NULL, NULL);
    CHECK_MSG(rc == CL_SUCCESS, "clEnqueueReadBuffer: %s", ocl_error_name(rc));
}

static cl_kernel kernel(const char *name)
{
    cl_kernel k = NULL;
    Error err = { 0 };
    Status st = ocl_program_kernel(cl.prog, &cl.dev, name, &k, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    return k;
}

#define SET(k, i, v) CHECK(clSetKernelArg(k, i, sizeof(v), &(v)) == CL_SUCCESS)

static void run(cl_kernel k, size_t n)
{
    cl_int rc = clEnqueueNDRangeKernel(cl.q, k, 1, NULL, &n, NULL, 0, NULL, NULL);
    CHECK_MSG(rc == CL_SUCCESS, "clEnqueueNDRangeKernel: %s", ocl_error_name(rc));
    CHECK(clFinish(cl.q) == CL_SUCCESS);
}

static void set_scene_args(cl_kernel k)
{
    for (cl_uint i = 0; i < 10; i++) SET(k, i, cl.scene[i]);
}

static int setup_opencl(void)
{
    OclDeviceInfo *devs = NULL;
    size_t n = 0;
    Error err = { 0 };
    if (ocl_enumerate(&devs, &n, &err) != ST_OK || n == 0) {
        fprintf(stderr, "no OpenCL device: %s\n", err.msg);
        free(devs);
        return 0;
    }
    cl.dev = devs[0];
    for (size_t i = 0; i < n; i++)
        if (devs[i].type & CL_DEVICE_TYPE_CPU) { cl.dev = devs[i]; break; }
    free(devs);
    cl_int rc;
    cl.ctx = clCreateContext(NULL, 1, &cl.dev.id, NULL, NULL, &rc);
    if (rc != CL_SUCCESS) return 0;
    cl.q = clCreateCommandQueue(cl.ctx, cl.dev.id, 0, &rc);
    if (rc != CL_SUCCESS) return 0;
    OclProgramStats ps;
    if (ocl_program_build(cl.ctx, &cl.dev, NULL, NULL, &cl.prog, &ps, &err) != ST_OK) {
        fprintf(stderr, "%s\n%s\n", err.msg, err.detail ? err.detail : "");
        error_clear(&err);
        return 0;
    }
    const DeviceScene *ds = &rs.ds;
    const RenderParams *p = &ds->params;
    cl.scene[0] = buffer(sizeof *p, p);
    cl.scene[1] = buffer(p->n_nodes * sizeof(KdNode), ds->nodes);
    cl.scene[2] = buffer(p->n_leaf_prims * sizeof(uint), ds->leaf_prims);
    cl.scene[3] = buffer(p->n_spheres * sizeof(Sphere), ds->spheres);
    cl.scene[4] = buffer(p->n_triangles * sizeof(Triangle), ds->triangles);
    cl.scene[5] = buffer(p->n_boxes * sizeof(Box), ds->boxes);
    cl.scene[6] = buffer(p->n_planes * sizeof(Plane), ds->planes);
    cl.scene[7] = buffer(ds->n_materials * sizeof(Material), ds->materials);
    cl.scene[8] = buffer(p->n_lights * sizeof(Light), ds->lights);
    cl.scene[9] = buffer(ds->n_shading * sizeof(TriShading), ds->shading);
    return 1;
}

static int rel_close(float a, float b, float tol)
{
    if (a == b) return 1;
    float m = k_fmax(k_fabs(a), k_fabs(b));
    return k_fabs(a - b) <= tol * (m > 1.0f ? m : 1.0f);
}
static int v3_close(vec3 a, vec3 b, float tol)
{
    return rel_close(a.x, b.x, tol) && rel_close(a.y, b.y, tol) && rel_close(a.z, b.z, tol);
}

static void test_layout(void)
{
    uint host[] = { sizeof(vec3), sizeof(Ray), sizeof(Hit), sizeof(KdNode), sizeof(Sphere), sizeof(Triangle),
                    sizeof(TriShading), sizeof(Box), sizeof(Plane), sizeof(Material), sizeof(Light),
                    sizeof(Camera), sizeof(RenderParams), sizeof(PathState), offsetof(RenderParams, bg_color),
                    offsetof(RenderParams, width), offsetof(RenderParams, bounds_lo), offsetof(PathState, bsdf_pdf),
                    offsetof(Material, albedo), offsetof(Light, position), offsetof(Camera, lens_u),
                    offsetof(TriShading, uv0) };
    enum { N = sizeof host / sizeof host[0] };
    uint dev[N];
    cl_mem out = buffer(sizeof dev, NULL);
    cl_kernel k = kernel("k_layout");
    SET(k, 0, out);
    run(k, 1);
    read_back(out, sizeof dev, dev);
    for (int i = 0; i < N; i++) CHECK_MSG(dev[i] == host[i], "layout entry %d: device %u, host %u", i, dev[i], host[i]);
    clReleaseKernel(k);
    clReleaseMemObject(out);
}

enum { LAYERS = 3 };

static void test_raygen(void)
{
    const RenderParams *p = &rs.ds.params;
    uint npix = p->width * p->height, n = npix * LAYERS, first_pixel = 0, first_sample = 5;
    cl_mem paths = buffer(n * sizeof(PathState), NULL), rays = buffer(n * sizeof(Ray), NULL),
           queue = buffer(n * sizeof(uint), NULL);
    cl_kernel k = kernel("k_raygen");
    SET(k, 0, cl.scene[0]);
    SET(k, 1, first_pixel);
    SET(k, 2, first_sample);
    SET(k, 3, npix);
    SET(k, 4, n);
    SET(k, 5, paths);
    SET(k, 6, rays);
    SET(k, 7, queue);
    run(k, n);
    PathState *dp = malloc(n * sizeof *dp);
    Ray *dr = malloc(n * sizeof *dr);
    uint *dq = malloc(n * sizeof *dq);
    read_back(paths, n * sizeof *dp, dp);
    read_back(rays, n * sizeof *dr, dr);
    read_back(queue, n * sizeof *dq, dq);
    uint exact = 0, bad = 0;
    for (uint i = 0; i < n; i++) {
        PathState cp;
        Ray cr;
        raygen_path(p, i % npix, first_sample + i / npix, &cp, &cr);
        exact += memcmp(&cp, &dp[i], sizeof cp) == 0 && memcmp(&cr, &dr[i], sizeof cr) == 0;
        if (dp[i].pixel != cp.pixel || dp[i].sample != cp.sample || dp[i].rng_key != cp.rng_key ||
            !v3_close(dr[i].o, cr.o, 1e-6f) || !v3_close(dr[i].d, cr.d, 1e-6f) || dq[i] != i)
            bad++;
    }
    fprintf(stderr, "  k_raygen: %u of %u paths bit-identical to C\n", exact, n);
    CHECK_MSG(bad == 0, "%u of %u camera rays differ", bad, n);
    free(dp);
    free(dr);
    free(dq);
    clReleaseKernel(k);
    clReleaseMemObject(paths);
    clReleaseMemObject(rays);
    clReleaseMemObject(queue);
}

/* Random rays through the scene's box, from inside and outside it. */
static Ray random_ray(void)
{
    Ray r;
    r.o = vrand(-6.0f, 6.0f);
    r.d = v3_norm(v3_sub(vrand(-3.0f, 3.0f), r.o));
    if (frand() < 0.1f) r.d.x = 0.0f;          /* zero direction components too */
    r.tmin = 0.0f;
    r.tmax = frand() < 0.2f ? frange(0.5f, 5.0f) : INFINITY;
    return r;
}

static void test_intersect(void)
{
    enum { N = 20000 };
    Ray *rays = malloc(N * sizeof *rays);
    uint *queue = malloc(N * sizeof *queue);
    for (uint i = 0; i < N; i++) {
        rays[i] = random_ray();
        queue[i] = N - 1 - i;                   /* a permuted queue, as after compaction */
    }
    cl_mem rb = buffer(N * sizeof *rays, rays), qb = buffer(N * sizeof *queue, queue), hb = buffer(N * sizeof(Hit), NULL);
    cl_kernel k = kernel("k_intersect");
    set_scene_args(k);
    uint n = N;
    SET(k, 10, qb);
    SET(k, 11, n);
    SET(k, 12, rb);
    SET(k, 13, hb);
    run(k, N + 100);                            /* surplus work-items must do nothing */
    Hit *dh = malloc(N * sizeof *dh);
    read_back(hb, N * sizeof *dh, dh);
    uint exact = 0, bad = 0, hits = 0;
    for (uint i = 0; i < N; i++) {
        Hit ch = trace_closest(&view, rays[i]);
        hits += ch.prim != NO_INDEX;
        exact += memcmp(&ch, &dh[i], sizeof ch) == 0;
        if (ch.prim != dh[i].prim || (ch.prim != NO_INDEX && !rel_close(ch.t, dh[i].t, 1e-5f))) bad++;
    }
    fprintf(stderr, "  k_intersect: %u rays, %u hits, %u bit-identical to C\n", (uint)N, hits, exact);
    CHECK(hits > N / 4);
    CHECK_MSG(bad == 0, "%u of %u hits differ", bad, (uint)N);
    free(rays);
    free(queue);
    free(dh);
    clReleaseKernel(k);
    clReleaseMemObject(rb);
    clReleaseMemObject(qb);
    clReleaseMemObject(hb);
}

/* Shade and shadow: path states at various bounces with random throughput, the hits of
 * random rays (computed once in C and given to both sides). */
static void test_shade_and_shadow(void)
{
    enum { N = 20000 };
    const RenderParams *p = &rs.ds.params;
    PathState *ps = malloc(N * sizeof *ps);
    Ray *rays = malloc(N * sizeof *rays);
    Hit *hits = malloc(N * sizeof *hits);
    uint *queue = malloc(N * sizeof *queue);
    for (uint i = 0; i < N; i++) {
        raygen_path(p, i % (p->width * p->height), i, &ps[i], &rays[i]);
        if (i % 2) rays[i] = random_ray();
        ps[i].bounce = i % (p->max_depth + 1);
        ps[i].throughput = vrand(0.05f, 1.0f);
        ps[i].radiance = vrand(0.0f, 0.5f);
        ps[i].flags = (i % 3 == 0) ? PATH_SPECULAR : 0u;
        ps[i].bsdf_pdf = frange(0.05f, 1.0f);
        hits[i] = trace_closest(&view, rays[i]);
        queue[i] = i;
    }
    cl_mem pb = buffer(N * sizeof *ps, ps), rb = buffer(N * sizeof *rays, rays), hb = buffer(N * sizeof *hits, hits),
           qb = buffer(N * sizeof *queue, queue), srb = buffer(N * sizeof(Ray), NULL),
           nqb = buffer(N * sizeof(uint), NULL), sqb = buffer(N * sizeof(uint), NULL);
    /* bounce 1 of a wave: the shade kernel counts its shadow rays into count slot 3 and
     * the next queue into slot 4 (entry.cl) */
    cl_uint init_counts[5 * QUEUE_COUNT_STRIDE] = { 0 }, slot = 3;
    cl_mem cb = buffer(sizeof init_counts, init_counts);
    cl_kernel k = kernel("k_shade");
    set_scene_args(k);
    uint n = N;
    SET(k, 10, qb);
    SET(k, 11, n);
    SET(k, 12, rb);
    SET(k, 13, hb);
    SET(k, 14, pb);
    SET(k, 15, srb);
    SET(k, 16, nqb);
    SET(k, 17, sqb);
    SET(k, 18, cb);
    SET(k, 19, slot);
    run(k, N + 100);
    PathState *dps = malloc(N * sizeof *dps);
    Ray *drays = malloc(N * sizeof *drays), *dshadow = malloc(N * sizeof *dshadow);
    uint *dnext = malloc(N * sizeof *dnext), *dshq = malloc(N * sizeof *dshq), all_counts[5 * QUEUE_COUNT_STRIDE],
         counts[2];
    read_back(pb, N * sizeof *dps, dps);
    read_back(rb, N * sizeof *drays, drays);
    read_back(srb, N * sizeof *dshadow, dshadow);
    read_back(nqb, N * sizeof *dnext, dnext);
    read_back(sqb, N * sizeof *dshq, dshq);
    read_back(cb, sizeof all_counts, all_counts);
    counts[0] = all_counts[4 * QUEUE_COUNT_STRIDE];
    counts[1] = all_counts[3 * QUEUE_COUNT_STRIDE];

    /* The C side, and the flags each path should have produced. */
    uint *flags = calloc(N, sizeof *flags);
    PathState *cps = malloc(N * sizeof *cps);
    Ray *crays = malloc(N * sizeof *crays), *cshadow = calloc(N, sizeof *cshadow);
    uint n_cont = 0, n_shadow = 0, exact = 0, bad = 0;
    for (uint i = 0; i < N; i++) {
        cps[i] = ps[i];
        crays[i] = rays[i];
        flags[i] = shade_path(&view, &crays[i], hits[i], &cps[i], &cshadow[i]);
        n_cont += (flags[i] & SHADE_CONTINUE) != 0;
        n_shadow += (flags[i] & SHADE_SHADOW) != 0;
    }
    CHECK_EQ_INT(counts[0], n_cont);
    CHECK_EQ_INT(counts[1], n_shadow);
    /* queue membership as sets: every continuing path exactly once */
    uint *seen = calloc(N, sizeof *seen);
    for (uint i = 0; i < counts[0] && i < N; i++) seen[dnext[i]] |= 1u;
    for (uint i = 0; i < counts[1] && i < N; i++) seen[dshq[i]] |= 2u;
    for (uint i = 0; i < N; i++) {
        if (seen[i] != (flags[i] & 3u)) bad++;
        int same = memcmp(&cps[i], &dps[i], sizeof cps[i]) == 0;
        if ((flags[i] & SHADE_CONTINUE) && memcmp(&crays[i], &drays[i], sizeof crays[i])) same = 0;
        if ((flags[i] & SHADE_SHADOW) && memcmp(&cshadow[i], &dshadow[i], sizeof cshadow[i])) same = 0;
        exact += same;
        if (!v3_close(cps[i].radiance, dps[i].radiance, 1e-5f) || !v3_close(cps[i].throughput, dps[i].throughput, 1e-5f) ||
            !v3_close(cps[i].shadow_L, dps[i].shadow_L, 1e-5f) || cps[i].bounce != dps[i].bounce ||
            cps[i].flags != dps[i].flags)
            bad++;
        else if ((flags[i] & SHADE_CONTINUE) && !v3_close(crays[i].d, drays[i].d, 1e-5f))
            bad++;
    }
    fprintf(stderr, "  k_shade: %u paths, %u continue, %u shadow rays, %u bit-identical to C\n", (uint)N, n_cont,
            n_shadow, exact);
    CHECK(n_cont > N / 10);
    CHECK(n_shadow > N / 20);
    CHECK_MSG(bad == 0, "%u of %u shaded paths differ", bad, (uint)N);

    /* k_shadow over the shadow queue the device produced */
    cl_kernel ks = kernel("k_shadow");
    set_scene_args(ks);
    uint ns = counts[1];
    SET(ks, 10, sqb);
    SET(ks, 11, ns);
    SET(ks, 12, srb);
    SET(ks, 13, pb);
    run(ks, ns + 50);
    read_back(pb, N * sizeof *dps, dps);
    uint occluded = 0, sbad = 0, sexact = 0;
    for (uint i = 0; i < N; i++) {
        if (!(flags[i] & SHADE_SHADOW)) continue;
        int occ = trace_any(&view, cshadow[i]);
        occluded += (uint)occ;
        shadow_resolve(&cps[i], occ);
        sexact += memcmp(&cps[i].radiance, &dps[i].radiance, sizeof(vec3)) == 0;
        if (!v3_close(cps[i].radiance, dps[i].radiance, 1e-5f)) sbad++;
    }
    fprintf(stderr, "  k_shadow: %u shadow rays, %u occluded, %u bit-identical to C\n", n_shadow, occluded, sexact);
    CHECK(occluded > 0 && occluded < n_shadow);
    CHECK_MSG(sbad == 0, "%u of %u shadow results differ", sbad, n_shadow);

    free(ps); free(rays); free(hits); free(queue); free(dps); free(drays); free(dshadow);
    free(dnext); free(dshq); free(flags); free(cps); free(crays); free(cshadow); free(seen);
    clReleaseKernel(k);
    clReleaseKernel(ks);
    cl_mem ms[] = { pb, rb, hb, qb, srb, nqb, sqb, cb };
    for (size_t i = 0; i < sizeof ms / sizeof ms[0]; i++) clReleaseMemObject(ms[i]);
}

/* A wave that starts at pixel 100 of a 600-pixel image and wraps around it three times
 * and a bit: pixels get three or four of its paths. */
static void test_film(void)
{
    uint n_film = 600, first_pixel = 100, n_paths = 2000;
    PathState *ps = calloc(n_paths, sizeof *ps);
    for (uint i = 0; i < n_paths; i++) {
        ps[i].radiance = vrand(0.0f, 3.0f);
        if (i % 97 == 0) ps[i].radiance.x = NAN;           /* dropped, not propagated */
        if (i % 89 == 0) ps[i].radiance.y = 1e30f;         /* clamped */
        if (i % 83 == 0) ps[i].radiance.z = -1.0f;         /* dropped */
    }
    int64_t *film = calloc((size_t)n_film * 3, sizeof *film), *cfilm = calloc((size_t)n_film * 3, sizeof *cfilm);
    for (uint i = 0; i < n_film * 3; i++) film[i] = cfilm[i] = (int64_t)i * 1000;   /* already holds samples */
    cl_mem pb = buffer((size_t)n_paths * sizeof *ps, ps), fb = buffer((size_t)n_film * 3 * sizeof *film, film);
    cl_kernel k = kernel("k_film");
    SET(k, 0, pb);
    SET(k, 1, first_pixel);
    SET(k, 2, n_film);
    SET(k, 3, n_paths);
    SET(k, 4, fb);
    run(k, n_film);
    read_back(fb, (size_t)n_film * 3 * sizeof *film, film);
    for (uint i = 0; i < n_paths; i++) film_add(cfilm, (first_pixel + i) % n_film, ps[i].radiance);
    uint bad = 0;
    for (uint i = 0; i < n_film * 3; i++) bad += film[i] != cfilm[i];
    CHECK_MSG(bad == 0, "%u film entries differ (fixed point must match exactly)", bad);
    CHECK(film_fixed(NAN) == 0 && film_fixed(-2.0f) == 0 && film_fixed(INFINITY) == film_fixed(FILM_MAX_SAMPLE));
    CHECK(film_fixed(1.0f) == ((int64_t)1 << FILM_FRAC_BITS));
    free(ps);
    free(film);
    free(cfilm);
    clReleaseKernel(k);
    clReleaseMemObject(pb);
    clReleaseMemObject(fb);
}

int main(void)
{
    build_scene();
    cl.ok = setup_opencl();
    if (!cl.ok) {
        /* make test installs PoCL: no OpenCL device is a failure, not a skip */
        harness_failed++;
        fprintf(stderr, "FAIL no OpenCL device to compare against\n");
        return harness_report();
    }
    RUN(test_layout);
    RUN(test_raygen);
    RUN(test_intersect);
    RUN(test_shade_and_shadow);
    RUN(test_film);
    for (int i = 0; i < 10; i++) clReleaseMemObject(cl.scene[i]);
    clReleaseProgram(cl.prog);
    clReleaseCommandQueue(cl.q);
    clReleaseContext(cl.ctx);
    render_scene_free(&rs);
    scene_free(&scene);
    return harness_report();
}
