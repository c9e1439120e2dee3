/*
 * bench_traverse.c -- kd-tree and 8-wide BVH traversal against Embree 3, on exactly the
 * same rays.
 *
 *   bench_traverse [--reps N] [--size N] [--local N] [--builds N] [--no-pocl] [--no-embree]
 *                  [--embree-robust] [MESH ...]
 *
 * MESH is an .obj or .ply file, or "sphere:N" (a closed bumpy sphere of about N
 * triangles, mesh_make_sphere). Without meshes: every mesh of ../shared/models that is
 * present (bunny, dragon, the Cornell box variants, Sponza) and sphere:1000000.
 *
 * The ray set of a mesh (fixed, so runs compare):
 *   primary  SIZE x SIZE rays (1024 x 1024 by default) through the pixel centres of a
 *            pinhole camera with a 40 degree field of view, looking at the centre c of the
 *            bounding box from direction (0.35, 0.3, 1), at 1.05 r / sin(20 deg) from it
 *            (r = half the box diagonal): the bounding sphere just fits. Unit directions.
 *   diffuse  for each primary hit, one cosine-weighted direction about the geometric
 *            normal turned toward the camera, from the hit point offset off the surface
 *            (spawn_offset, kernels/geom/surface.h); random numbers from rng.h keyed by
 *            the pixel, so the set is the same on every run.
 *   shadow   for each primary hit, one ray from the same offset point to a point light at
 *            c + 2 r * normalize(-0.5, 1, 0.35), direction = light - origin, t in (0,
 *            1 - 1e-4).
 * Primary and diffuse rays are traced as closest-hit and as any-hit queries, shadow rays
 * as any-hit queries.
 *
 * Before anything is timed, the hits of the scalar C traversal are compared with
 * Embree's rtcIntersect1/rtcOccluded1 (same triangle, or t within 1e-4 relative; any-hit:
 * the same answer) and with PoCL's (bit for bit), and the counts that disagree printed.
 * Then Mrays/s, the median of --reps runs (5), for: PoCL (kernels/entry.cl) walking the
 * kd-tree with one ray per work-item (PoCL-1: k_trace_closest1/k_trace_any1), two in
 * turns (PoCL-2: k_trace_closest/k_trace_any) and packets of eight consecutive rays
 * (PoCL-8: k_trace_closest8/k_trace_any8, trace_packet), and walking the BVH, the
 * renderer's walk, with one ray per work-item (PoCL-W: k_trace_closest_wide/
 * k_trace_any_wide, as k_intersect and k_shadow call it), eight consecutive rays one
 * after another per work-item (PoCL-WL: k_trace_closest_lanes/k_trace_any_lanes, as
 * k_path_lanes, the renderer's kernel on CPUs, calls it for its lanes) and in packets
 * of eight consecutive rays (PoCL-W8: k_trace_closest_wide8/
 * k_trace_any_wide8, trace_packet_wide), each on a sub-device of 1 compute unit and on
 * the whole device, the program built per mesh as the renderer builds its own for a
 * scene of it: the scene's features (-D CLPT_FEATURES: no instances, spheres or motion
 * compiled in) and k_path_lanes' walk as a call, with the kd-tree for the kd columns
 * (the kd-tree kernels checked bit for bit against the C kd walk, the
 * BVH's against the C BVH walk;
 * "BVH vs kd" counts rays whose closest hit, all of it, or occlusion differs between
 * the trees: both follow one tie rule, leaf_test); the
 * scalar C traversal (kernels compiled as C) of the kd-tree in pairs (C, compiled here for
 * any x86-64) and of the BVH (C-W: the scalar device's own walk, ScalarPaths' closest and
 * any of the build it picks for the mesh, which on a processor with AVX2 or AVX-512 is
 * the build for that; its name is printed) on 1 and 2 threads; Embree rtcIntersect1 /
 * rtcOccluded1 and rtcIntersect8 / rtcOccluded8 packets (8 consecutive rays) on 1 and 2
 * threads; the ratios of each PoCL kernel to Embree single rays per CPU-second (issue 3
 * asked 0.5 or more on bunny and dragon, issue 12 asks 1.0 for every kind of ray). Per
 * mesh also: the kd-tree build time (2 threads and
 * 1), its SAH cost and bytes per triangle (nodes + leaf lists), the BVH's build time (2
 * threads), nodes, leaves and bytes per triangle, and Embree's
 * RTC_BUILD_QUALITY_HIGH build time (2 and 1 threads) and the bytes its build allocated;
 * with --builds N, N more rounds of the kd-tree, BVH and Embree builds in turns (2
 * threads), their medians and the medians of the rounds' ratios to Embree's.
 * With --embree-robust, Embree's scene has RTC_SCENE_FLAG_ROBUST: watertight triangle
 * tests and conservative box tests, the guarantees clpt's walks always have (a ray
 * through a shared edge or vertex hits one of its triangles; the default mode may miss
 * both). Results are printed as Markdown tables for bench/RESULTS.md.
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh.h"
#include "accel/kdtree.h"
#include "device/device.h"
#include "device/kernel_features.h"
#include "device/scalar_paths.h"
#include "io/mesh_load.h"
#include "device/ocl_program.h"
#include "render/render_scene.h"
#include "sample/rng.h"
#include "sample/sampling.h"
#include "geom/surface.h"
#include "base/timer.h"
#include "accel/traverse.h"

#include "bench_embree.h"
#include "bench_util.h"

#define MAX_REPS 31
#define MAX_THREADS 2

/* ------------------------------------------------------------------ options */

typedef struct {
    int reps, size, pocl, embree;
    int embree_robust;           /* --embree-robust: RTC_SCENE_FLAG_ROBUST */
    int threads[MAX_THREADS];
    size_t local;                /* OpenCL work-group size (64, as the renderer), 0 = the driver's choice */
    int builds;                  /* --builds: rounds of kd-tree and Embree builds in turns (0: none) */
} Options;

static size_t pocl_local;

/* CPU time of the whole process (every thread, PoCL's and Embree's included) taken by
 * the last timed run: the machines this runs on are shared, and CPU time, unlike wall
 * time, does not count the time other jobs had the cores. */
static double last_cpu_seconds;

/* ------------------------------------------------------------------ the mesh */

typedef struct {
    const char *name;
    Scene scene;
    KdTree tree;
    double kd_build_1;           /* one-thread build, seconds */
    Bvh bvh;                     /* the 8-wide BVH (one thread) */
    DeviceScene ds;              /* both trees and the triangles, every other buffer empty */
    SceneView view;
    const ScalarPaths *paths;    /* the scalar device's build of the kernels for this mesh */
    double load_seconds;
} Mesh;

static int mesh_open(Mesh *m, const char *name, Error *err)
{
    memset(m, 0, sizeof *m);
    m->name = name;
    scene_init(&m->scene);
    double t0 = timer_now();
    Status st;
    if (strncmp(name, "sphere:", 7) == 0) {
        st = mesh_make_sphere(&m->scene, (size_t)atol(name + 7), 0, err);
    } else {
        MeshOptions o = mesh_options(0);   /* one material: only geometry matters here */
        st = mesh_load(name, &m->scene, &o, err);
    }
    m->load_seconds = timer_now() - t0;
    if (st) return -1;
    KdInput in = { .triangles = m->scene.triangles, .n_triangles = m->scene.n_triangles };
    KdTree one;
    if (kd_build(&in, 1, &one, err)) return -1;
    m->kd_build_1 = one.stats.build_seconds;
    kd_free(&one);
    if (kd_build(&in, 2, &m->tree, err)) return -1;
    if (bvh_build(&in, 2, &m->bvh, err)) return -1;
    m->ds.params.n_triangles = (uint)m->scene.n_triangles;
    m->ds.triangles = m->scene.triangles;
    render_scene_use_kdtree(&m->ds, &m->tree);
    render_scene_use_bvh(&m->ds, &m->bvh);
    device_scene_view(&m->ds, &m->view);
    m->paths = scalar_paths_pick(kernel_scene_features(&m->ds));
    return 0;
}

static void mesh_close(Mesh *m)
{
    kd_free(&m->tree);
    bvh_free(&m->bvh);
    scene_free(&m->scene);
}

/* ------------------------------------------------------------------ rays */

/* The queries: closest and any hit of the primary and diffuse rays, any hit of the
 * shadow rays (the any-hit sets share the closest-hit sets' rays). */
#define N_SETS 5

typedef struct {
    const char *name;
    Ray *rays;
    int owns;                    /* rays belongs to this set */
    uint n;
    int any;                     /* any-hit or closest-hit */
    Hit *ref_hits;               /* scalar C results: closest */
    uint *ref_occ;               /* any */
    Hit *wide_hits;              /* the same through the 8-wide BVH */
    uint *wide_occ;
} RaySet;

static vec3 unit_d(double x, double y, double z)
{
    double l = sqrt(x * x + y * y + z * z);
    return v3((float)(x / l), (float)(y / l), (float)(z / l));
}

/* ------------------------------------------------------------------ scalar C tracing */

typedef struct {
    const SceneView *sc;
    const ScalarPaths *paths;    /* WALK_WIDE: the scalar device's build for the mesh */
    const RaySet *set;
    int walk;                    /* WALK_*: the kd-tree one ray or two at a time, or the BVH */
    Hit *hits;
    uint *occ;
    atomic_uint next;
} TraceJob;

#define CHUNK 1024u
enum { WALK_SINGLE, WALK_PAIRS, WALK_WIDE };

static void *trace_worker(void *arg)
{
    TraceJob *j = arg;
    const RaySet *s = j->set;
    for (;;) {
        uint begin = atomic_fetch_add(&j->next, CHUNK);
        if (begin >= s->n) break;
        uint end = s->n - begin < CHUNK ? s->n : begin + CHUNK;
        uint i = begin;
        if (j->walk == WALK_WIDE) {
            for (; i < end; i++) {
                if (s->any) j->occ[i] = (uint)j->paths->any(j->sc, &s->rays[i]);
                else j->paths->closest(j->sc, &s->rays[i], &j->hits[i]);
            }
        } else if (j->walk == WALK_PAIRS && s->any) {
            for (; i + 1 < end; i += 2) {
                int a, b;
                trace_any2(j->sc, s->rays[i], s->rays[i + 1], &a, &b);
                j->occ[i] = (uint)a;
                j->occ[i + 1] = (uint)b;
            }
        } else if (j->walk == WALK_PAIRS) {
            for (; i + 1 < end; i += 2) trace_closest2(j->sc, s->rays[i], s->rays[i + 1], &j->hits[i], &j->hits[i + 1]);
        }
        if (s->any)
            for (; i < end; i++) j->occ[i] = (uint)trace_any_in(j->sc, TREE_KD, s->rays[i]);
        else
            for (; i < end; i++) j->hits[i] = trace_closest_in(j->sc, TREE_KD, s->rays[i]);
    }
    return NULL;
}

/* Traces the set with `threads` threads by `walk` (WALK_*); returns the seconds it
 * took. */
static double trace_c(const Mesh *m, const RaySet *s, int threads, int walk, Hit *hits, uint *occ)
{
    TraceJob j;
    j.sc = &m->view;
    j.paths = m->paths;
    j.set = s;
    j.walk = walk;
    j.hits = hits;
    j.occ = occ;
    atomic_init(&j.next, 0u);
    pthread_t tid[MAX_THREADS];
    double c0 = bench_cpu_now(), t0 = timer_now();
    int started = 0;
    for (int i = 1; i < threads; i++)
        if (pthread_create(&tid[started], NULL, trace_worker, &j) == 0) started++;
    trace_worker(&j);
    for (int i = 0; i < started; i++) pthread_join(tid[i], NULL);
    last_cpu_seconds = bench_cpu_now() - c0;
    return timer_now() - t0;
}

/* The ray sets of a mesh (see the top of this file). */
static int make_rays(Mesh *m, int size, RaySet sets[N_SETS])
{
    double lo[3] = { m->tree.lo.x, m->tree.lo.y, m->tree.lo.z }, hi[3] = { m->tree.hi.x, m->tree.hi.y, m->tree.hi.z };
    double c[3], r = 0.0;
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5 * (lo[a] + hi[a]);
        r += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    r = sqrt(r);
    double half = 20.0 * M_PI / 180.0, dist = 1.05 * r / sin(half), tn = tan(half);
    vec3 w = unit_d(0.35, 0.3, 1.0);    /* from the centre toward the eye */
    double eye[3] = { c[0] + w.x * dist, c[1] + w.y * dist, c[2] + w.z * dist };
    /* camera basis: forward f = -w, right = f x up, true up = right x f */
    double f[3] = { -w.x, -w.y, -w.z };
    double rt[3] = { -f[2], 0.0, f[0] };          /* f x (0,1,0) */
    double rl = sqrt(rt[0] * rt[0] + rt[2] * rt[2]);
    rt[0] /= rl;
    rt[2] /= rl;
    double up[3] = { rt[1] * f[2] - rt[2] * f[1], rt[2] * f[0] - rt[0] * f[2], rt[0] * f[1] - rt[1] * f[0] };
    vec3 light = v3((float)(c[0] + 2.0 * r * -0.5 / 1.1726), (float)(c[1] + 2.0 * r * 1.0 / 1.1726),
                    (float)(c[2] + 2.0 * r * 0.35 / 1.1726));   /* |(-0.5, 1, 0.35)| = 1.1726 */

    uint n = (uint)size * (uint)size;
    RaySet *p = &sets[0], *d = &sets[2], *s = &sets[4];
    memset(sets, 0, N_SETS * sizeof *sets);
    p->name = "primary";
    d->name = "diffuse";
    s->name = "shadow";
    s->any = 1;
    p->owns = d->owns = s->owns = 1;
    p->rays = malloc(n * sizeof *p->rays);
    d->rays = malloc(n * sizeof *d->rays);
    s->rays = malloc(n * sizeof *s->rays);
    Hit *hits = malloc(n * sizeof *hits);
    if (!p->rays || !d->rays || !s->rays || !hits) return -1;
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            double sx = (2.0 * (x + 0.5) / size - 1.0) * tn, sy = (1.0 - 2.0 * (y + 0.5) / size) * tn;
            Ray ray;
            ray.o = v3((float)eye[0], (float)eye[1], (float)eye[2]);
            ray.d = unit_d(f[0] + sx * rt[0] + sy * up[0], f[1] + sx * rt[1] + sy * up[1],
                           f[2] + sx * rt[2] + sy * up[2]);
            ray.tmin = 0.0f;
            ray.tmax = K_INF;
            p->rays[(size_t)y * size + x] = ray;
        }
    p->n = n;
    trace_c(m, p, 2, WALK_SINGLE, hits, NULL);
    for (uint i = 0; i < n; i++) {
        if (hits[i].prim == NO_INDEX) continue;
        const Triangle *t = &m->scene.triangles[hits[i].prim];
        const Ray *pr = &p->rays[i];
        float b0 = 1.0f - hits[i].u - hits[i].v;
        vec3 pt = v3_add(v3_add(v3_scale(t->p0, b0), v3_scale(t->p1, hits[i].u)), v3_scale(t->p2, hits[i].v));
        vec3 ng = v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0));
        if (v3_is_zero(ng)) continue;
        ng = v3_norm(ng);
        if (v3_dot(ng, pr->d) > 0.0f) ng = v3_neg(ng);
        vec3 o = spawn_offset(pt, triangle_point_error(*t, b0, hits[i].u, hits[i].v, pt), ng);
        /* the independent sampler, so the ray set stays the one of earlier results */
        RngKey key = { rng_path_key(1u, i, 0u), 0u, SAMPLER_INDEPENDENT, 0u };
        vec3 l = sample_cosine_hemisphere(rng_uniform(key, 1u, DIM_BSDF_U), rng_uniform(key, 1u, DIM_BSDF_V));
        vec3 tb, bb;
        k_onb(ng, &tb, &bb);
        Ray dr = { o, 0.0f, k_to_world(l, tb, bb, ng), K_INF };
        Ray sr = { o, 0.0f, v3_sub(light, o), 1.0f - 1e-4f };
        d->rays[d->n++] = dr;
        s->rays[s->n++] = sr;
    }
    free(hits);
    sets[1] = *p;
    sets[3] = *d;
    sets[1].owns = sets[3].owns = 0;
    sets[1].any = sets[3].any = 1;
    for (int k = 0; k < N_SETS; k++) {
        sets[k].ref_hits = malloc((sets[k].n + 1) * sizeof *sets[k].ref_hits);
        sets[k].ref_occ = malloc((sets[k].n + 1) * sizeof *sets[k].ref_occ);
        sets[k].wide_hits = malloc((sets[k].n + 1) * sizeof *sets[k].wide_hits);
        sets[k].wide_occ = malloc((sets[k].n + 1) * sizeof *sets[k].wide_occ);
        if (!sets[k].ref_hits || !sets[k].ref_occ || !sets[k].wide_hits || !sets[k].wide_occ) return -1;
        trace_c(m, &sets[k], 2, WALK_SINGLE, sets[k].ref_hits, sets[k].ref_occ);
        trace_c(m, &sets[k], 2, WALK_WIDE, sets[k].wide_hits, sets[k].wide_occ);
    }
    return 0;
}

static void rays_free(RaySet sets[N_SETS])
{
    for (int k = 0; k < N_SETS; k++) {
        if (sets[k].owns) free(sets[k].rays);
        free(sets[k].ref_hits);
        free(sets[k].ref_occ);
        free(sets[k].wide_hits);
        free(sets[k].wide_occ);
    }
}

/* ------------------------------------------------------------------ PoCL */

/* The kernels' scene arguments come first, in kernels/scene_buffers.h order. */
#define SC_N SCENE_BUF_COUNT

/* The PoCL kernels (kernels/entry.cl): their labels, their closest-hit and any-hit
 * kernels, rays per work-item, and whether they walk the BVH (else the kd-tree). */
typedef enum {
    POCL_SINGLE, POCL_PAIRS, POCL_PACKETS, POCL_WIDE, POCL_WIDE_LANES, POCL_WIDE_PACKETS, N_KERNELS
} PoclKernel;
static const struct {
    const char *label, *closest, *any;
    uint rays_per_item;
    int wide;
} pocl_kernels[N_KERNELS] = {
    [POCL_SINGLE] = { "PoCL-1", "k_trace_closest1", "k_trace_any1", 1, 0 },
    [POCL_PAIRS] = { "PoCL-2", "k_trace_closest", "k_trace_any", 2, 0 },
    [POCL_PACKETS] = { "PoCL-8", "k_trace_closest8", "k_trace_any8", 8, 0 },
    [POCL_WIDE] = { "PoCL-W", "k_trace_closest_wide", "k_trace_any_wide", 1, 1 },
    [POCL_WIDE_LANES] = { "PoCL-WL", "k_trace_closest_lanes", "k_trace_any_lanes", PATH_LANES, 1 },
    [POCL_WIDE_PACKETS] = { "PoCL-W8", "k_trace_closest_wide8", "k_trace_any_wide8", 8, 1 },
};

typedef struct {
    int ok;
    OclDeviceInfo info;
    cl_device_id sub;            /* the 1-compute-unit sub-device, or NULL */
    cl_context ctx;
    cl_command_queue q;
    cl_kernel k[N_KERNELS][2];   /* per PoclKernel: closest-hit, any-hit */
    cl_program prog;
    unsigned features;           /* the CLPT_FEATURES prog was built with (0: none built) */
    cl_mem scene[SC_N], rays, out;
    size_t rays_cap;
} Pocl;

static int pocl_fail(const char *what, cl_int rc)
{
    fprintf(stderr, "bench_traverse: %s failed: %s\n", what, ocl_error_name(rc));
    return -1;
}

/* A context, queue and program for the device (or its sub-device when sub is set). */
static int pocl_open(Pocl *pc, const OclDeviceInfo *dev, cl_device_id sub)
{
    memset(pc, 0, sizeof *pc);
    pc->info = *dev;
    pc->sub = sub;
    if (sub) {
        pc->info.id = sub;
        pc->info.compute_units = 1;
    }
    cl_int rc;
    pc->ctx = clCreateContext(NULL, 1, &pc->info.id, NULL, NULL, &rc);
    if (rc != CL_SUCCESS) return pocl_fail("clCreateContext", rc);
    pc->q = clCreateCommandQueue(pc->ctx, pc->info.id, 0, &rc);
    if (rc != CL_SUCCESS) return pocl_fail("clCreateCommandQueue", rc);
    pc->ok = 1;
    return 0;
}

/* The bench program built for `features` (CLPT_FEATURES, kernels/types.h) unless it
 * already is: the code the renderer's program has for a scene of the mesh (see
 * bench_mesh), not every feature's, whose instance and primitive cases the walk would
 * carry otherwise. */
static int pocl_program(Pocl *pc, unsigned features)
{
    if (pc->prog && pc->features == features) return 0;
    for (int kp = 0; kp < N_KERNELS; kp++)
        for (int any = 0; any < 2; any++)
            if (pc->k[kp][any]) clReleaseKernel(pc->k[kp][any]);
    memset(pc->k, 0, sizeof pc->k);
    if (pc->prog) clReleaseProgram(pc->prog);
    pc->prog = NULL;
    pc->features = 0;
    char options[48];
    snprintf(options, sizeof options, "-D CLPT_FEATURES=0x%xu", features);
    Error err = { 0 };
    Status st = ocl_program_build_source(pc->ctx, &pc->info, clpt_bench_kernel_source,
                                         clpt_bench_kernel_source_len, options, &pc->prog, NULL, &err);
    for (int kp = 0; kp < N_KERNELS && st == ST_OK; kp++) {
        st = ocl_program_kernel(pc->prog, &pc->info, pocl_kernels[kp].closest, &pc->k[kp][0], &err);
        if (st == ST_OK) st = ocl_program_kernel(pc->prog, &pc->info, pocl_kernels[kp].any, &pc->k[kp][1], &err);
    }
    if (st != ST_OK) {
        fprintf(stderr, "bench_traverse: %s\n", err.msg);
        error_clear(&err);
        return -1;
    }
    pc->features = features;
    return 0;
}

static void pocl_release_buffers(Pocl *pc)
{
    for (int i = 0; i < SC_N; i++)
        if (pc->scene[i]) clReleaseMemObject(pc->scene[i]);
    if (pc->rays) clReleaseMemObject(pc->rays);
    if (pc->out) clReleaseMemObject(pc->out);
    memset(pc->scene, 0, sizeof pc->scene);
    pc->rays = pc->out = NULL;
    pc->rays_cap = 0;
}

static void pocl_close(Pocl *pc)
{
    pocl_release_buffers(pc);
    for (int kp = 0; kp < N_KERNELS; kp++)
        for (int any = 0; any < 2; any++)
            if (pc->k[kp][any]) clReleaseKernel(pc->k[kp][any]);
    if (pc->prog) clReleaseProgram(pc->prog);
    if (pc->q) clReleaseCommandQueue(pc->q);
    if (pc->ctx) clReleaseContext(pc->ctx);
    if (pc->sub) clReleaseDevice(pc->sub);
    memset(pc, 0, sizeof *pc);
}

/* made as the renderer makes them (ocl_buffer): the scene's read at random, on huge
 * pages, the rays and hits in order, as a wave's */
static cl_mem pocl_buffer(Pocl *pc, OclReads reads, const void *src, size_t bytes)
{
    cl_int rc;
    const char *call;
    cl_mem m = ocl_buffer(pc->ctx, CL_DEVICE_TYPE_CPU, CL_MEM_READ_WRITE, reads, bytes, bytes ? src : NULL, &call, &rc);
    if (!m) pocl_fail(call, rc);
    return m;
}

static int pocl_upload(Pocl *pc, const Mesh *m, uint max_rays)
{
    pocl_release_buffers(pc);
    for (unsigned i = 0; i < SC_N; i++) {
        SceneBufferBytes b = device_scene_buffer(&m->ds, i);
        pc->scene[i] = pocl_buffer(pc, OCL_READ_AT_RANDOM, b.data, b.bytes);
    }
    pc->rays = pocl_buffer(pc, OCL_READ_IN_ORDER, NULL, (size_t)max_rays * sizeof(Ray));
    pc->out = pocl_buffer(pc, OCL_READ_IN_ORDER, NULL, (size_t)max_rays * sizeof(Hit));
    for (int i = 0; i < SC_N; i++)
        if (!pc->scene[i]) return -1;
    if (!pc->rays || !pc->out) return -1;
    for (int kp = 0; kp < 2 * N_KERNELS; kp++) {
        cl_kernel k = pc->k[kp / 2][kp % 2];
        for (cl_uint i = 0; i < SC_N; i++)
            if (clSetKernelArg(k, i, sizeof(cl_mem), &pc->scene[i]) != CL_SUCCESS) return -1;
        if (clSetKernelArg(k, SC_N, sizeof(cl_mem), &pc->rays) != CL_SUCCESS ||
            clSetKernelArg(k, SC_N + 2, sizeof(cl_mem), &pc->out) != CL_SUCCESS)
            return -1;
    }
    return 0;
}

/* One table cell of a rate, or "-" for one not measured (a device left out by --no-pocl
 * or --no-embree, or absent): 0.00 would read as a measured rate. */
static void print_rate(double v)
{
    if (v > 0.0) printf(" %.2f |", v);
    else printf(" - |");
}

/* A row's rates: each PoCL kernel's at both thread counts, then the other columns'. */
static void print_rates(const double pocl[N_KERNELS][MAX_THREADS], const double *others, int n_others)
{
    for (int kp = 0; kp < N_KERNELS; kp++)
        for (int t = 0; t < MAX_THREADS; t++) print_rate(pocl[kp][t]);
    for (int i = 0; i < n_others; i++) print_rate(others[i]);
}

/* The PoCL kernels' column heads, at a and at b threads, each label followed by suffix. */
static void print_pocl_heads(const char *suffix, int a, int b)
{
    for (int kp = 0; kp < N_KERNELS; kp++)
        printf(" %s%s %dt | %s%s %dt |", pocl_kernels[kp].label, suffix, a, pocl_kernels[kp].label, suffix, b);
}

/* Traces the set (its rays already uploaded) with kernel `kind`; returns seconds, or -1. */
static double pocl_trace(Pocl *pc, const RaySet *s, PoclKernel kind)
{
    cl_kernel k = pc->k[kind][s->any != 0];
    cl_uint n = s->n;
    if (clSetKernelArg(k, SC_N + 1, sizeof n, &n) != CL_SUCCESS) return -1.0;
    size_t items = (n + pocl_kernels[kind].rays_per_item - 1u) / pocl_kernels[kind].rays_per_item;
    size_t local = pocl_local, global = local ? (items + local - 1) / local * local : items;
    double c0 = bench_cpu_now(), t0 = timer_now();
    cl_int rc = clEnqueueNDRangeKernel(pc->q, k, 1, NULL, &global, local ? &local : NULL, 0, NULL, NULL);
    if (rc == CL_SUCCESS) rc = clFinish(pc->q);
    if (rc != CL_SUCCESS) {
        pocl_fail("k_trace", rc);
        return -1.0;
    }
    last_cpu_seconds = bench_cpu_now() - c0;
    return timer_now() - t0;
}

static int pocl_put_rays(Pocl *pc, const RaySet *s)
{
    if (s->n == 0) return 0;
    return clEnqueueWriteBuffer(pc->q, pc->rays, CL_TRUE, 0, s->n * sizeof(Ray), s->rays, 0, NULL, NULL) ==
                   CL_SUCCESS
               ? 0
               : -1;
}

/* Rays whose PoCL result is not bit-identical to the scalar C one (of the same tree). */
static long pocl_compare(Pocl *pc, const RaySet *s, int wide)
{
    const Hit *ref_hits = wide ? s->wide_hits : s->ref_hits;
    const uint *ref_occ = wide ? s->wide_occ : s->ref_occ;
    if (s->n == 0) return 0;
    size_t bytes = s->n * (s->any ? sizeof(uint) : sizeof(Hit));
    void *buf = malloc(bytes);
    if (!buf) return -1;
    long bad = -1;
    if (clEnqueueReadBuffer(pc->q, pc->out, CL_TRUE, 0, bytes, buf, 0, NULL, NULL) == CL_SUCCESS) {
        bad = 0;
        for (uint i = 0; i < s->n; i++) {
            if (s->any) bad += ((uint *)buf)[i] != ref_occ[i];
            else bad += memcmp(&((Hit *)buf)[i], &ref_hits[i], sizeof(Hit)) != 0;
        }
    }
    free(buf);
    return bad;
}

/* ------------------------------------------------------------------ Embree */


typedef struct {
    RTCDevice dev;
    RTCScene scene;
    double build_seconds;
    long long build_bytes;
} Embree;

static int embree_robust;         /* --embree-robust */

static int embree_build(Embree *e, const Mesh *m, int threads)
{
    memset(e, 0, sizeof *e);
    char cfg[64];
    snprintf(cfg, sizeof cfg, "threads=%d", threads);
    e->dev = rtcNewDevice(cfg);
    if (!e->dev) {
        fprintf(stderr, "bench_traverse: rtcNewDevice failed (error %d)\n", (int)rtcGetDeviceError(NULL));
        return -1;
    }
    size_t n = m->scene.n_triangles;
    e->scene = rtcNewScene(e->dev);
    rtcSetSceneBuildQuality(e->scene, RTC_BUILD_QUALITY_HIGH);
    if (embree_robust) rtcSetSceneFlags(e->scene, RTC_SCENE_FLAG_ROBUST);
    RTCGeometry g = bench_embree_triangles(e->dev, m->scene.triangles, n);
    if (!g) return -1;
    rtcAttachGeometry(e->scene, g);
    rtcReleaseGeometry(g);
    long long allocated = 0;
    int rc = bench_embree_commit(e->dev, e->scene, &e->build_seconds, &allocated);
    e->build_bytes = allocated;
    return rc;
}

static void embree_free(Embree *e)
{
    if (e->scene) rtcReleaseScene(e->scene);
    if (e->dev) rtcReleaseDevice(e->dev);
    memset(e, 0, sizeof *e);
}

static void embree_ray(const Ray *r, struct RTCRay *er)
{
    er->org_x = r->o.x;
    er->org_y = r->o.y;
    er->org_z = r->o.z;
    er->tnear = r->tmin;
    er->dir_x = r->d.x;
    er->dir_y = r->d.y;
    er->dir_z = r->d.z;
    er->time = 0.0f;
    er->tfar = r->tmax;
    er->mask = 0xffffffffu;
    er->id = 0;
    er->flags = 0;
}

typedef struct {
    RTCScene scene;
    const RaySet *set;
    int packets;
    Hit *hits;                   /* closest: prim and t; may be NULL */
    uint *occ;
    atomic_uint next;
} EmbreeJob;

static void *embree_worker(void *arg)
{
    EmbreeJob *j = arg;
    const RaySet *s = j->set;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (;;) {
        uint begin = atomic_fetch_add(&j->next, CHUNK);
        if (begin >= s->n) break;
        uint end = s->n - begin < CHUNK ? s->n : begin + CHUNK;
        if (!j->packets) {
            for (uint i = begin; i < end; i++) {
                if (s->any) {
                    struct RTCRay r;
                    embree_ray(&s->rays[i], &r);
                    rtcOccluded1(j->scene, &ctx, &r);
                    if (j->occ) j->occ[i] = r.tfar < 0.0f;
                } else {
                    struct RTCRayHit rh;
                    embree_ray(&s->rays[i], &rh.ray);
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(j->scene, &ctx, &rh);
                    if (j->hits) {
                        j->hits[i].prim = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? NO_INDEX : rh.hit.primID;
                        j->hits[i].t = rh.ray.tfar;
                    }
                }
            }
            continue;
        }
        for (uint i = begin; i < end; i += 8) {
            int valid[8];
            struct RTCRayHit8 rh;
            for (uint k = 0; k < 8; k++) {
                valid[k] = i + k < end ? -1 : 0;
                const Ray *r = &s->rays[i + k < end ? i + k : i];
                rh.ray.org_x[k] = r->o.x;
                rh.ray.org_y[k] = r->o.y;
                rh.ray.org_z[k] = r->o.z;
                rh.ray.tnear[k] = r->tmin;
                rh.ray.dir_x[k] = r->d.x;
                rh.ray.dir_y[k] = r->d.y;
                rh.ray.dir_z[k] = r->d.z;
                rh.ray.time[k] = 0.0f;
                rh.ray.tfar[k] = r->tmax;
                rh.ray.mask[k] = 0xffffffffu;
                rh.ray.id[k] = k;
                rh.ray.flags[k] = 0;
                rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            }
            if (s->any) {
                rtcOccluded8(valid, j->scene, &ctx, &rh.ray);
                if (j->occ)
                    for (uint k = 0; k < 8 && i + k < end; k++) j->occ[i + k] = rh.ray.tfar[k] < 0.0f;
            } else {
                rtcIntersect8(valid, j->scene, &ctx, &rh);
                if (j->hits)
                    for (uint k = 0; k < 8 && i + k < end; k++) {
                        j->hits[i + k].prim = rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID ? NO_INDEX : rh.hit.primID[k];
                        j->hits[i + k].t = rh.ray.tfar[k];
                    }
            }
        }
    }
    return NULL;
}

static double embree_trace(RTCScene scene, const RaySet *s, int packets, int threads, Hit *hits, uint *occ)
{
    EmbreeJob j;
    j.scene = scene;
    j.set = s;
    j.packets = packets;
    j.hits = hits;
    j.occ = occ;
    atomic_init(&j.next, 0u);
    pthread_t tid[MAX_THREADS];
    int started = 0;
    double c0 = bench_cpu_now(), t0 = timer_now();
    for (int i = 1; i < threads; i++)
        if (pthread_create(&tid[started], NULL, embree_worker, &j) == 0) started++;
    embree_worker(&j);
    for (int i = 0; i < started; i++) pthread_join(tid[i], NULL);
    last_cpu_seconds = bench_cpu_now() - c0;
    return timer_now() - t0;
}

/* Rays where our scalar result and Embree's disagree: different hit status, or
 * different triangles whose t differ by more than 1e-4 relative. */
static long embree_compare(const RaySet *s, const Hit *eh, const uint *eo)
{
    long bad = 0;
    for (uint i = 0; i < s->n; i++) {
        if (s->any) {
            bad += eo[i] != s->ref_occ[i];
            continue;
        }
        const Hit *a = &s->ref_hits[i], *b = &eh[i];
        if (a->prim == NO_INDEX || b->prim == NO_INDEX) bad += a->prim != b->prim;
        else if (a->prim != b->prim) bad += !(fabsf(a->t - b->t) <= 1e-4f * fmaxf(fabsf(a->t), 1e-30f));
    }
    return bad;
}

/* ------------------------------------------------------------------ one mesh */


typedef struct {
    double pocl[N_KERNELS][MAX_THREADS], c[MAX_THREADS], cw[MAX_THREADS], e1[MAX_THREADS], e8[MAX_THREADS];   /* Mrays/s */
    double cpu_pocl[N_KERNELS][MAX_THREADS], cpu_c[MAX_THREADS], cpu_cw[MAX_THREADS], cpu_e1[MAX_THREADS],
        cpu_e8[MAX_THREADS];
                                 /* Mrays per CPU-second */
    long pocl_diff, embree_diff;
    long wide_diff;              /* rays whose BVH answer is not the kd-tree's (C, both) */
    uint hits;
} SetResult;

static double rate(uint n, double *secs, int reps)
{
    double m = bench_median(secs, reps);
    return m > 0.0 ? n / m * 1e-6 : 0.0;
}

/* --builds N: the kd-tree's, the BVH's and Embree's HIGH builds in turns, N rounds on
 * the larger thread count, so that a busy spell hits all alike; medians of the times and
 * of each round's ratios to Embree's. One build of each, as the line above has, swings by 20-30% on a shared
 * machine. (Not on one thread: once a device of more threads has run, an Embree device
 * made with threads=1 builds on more.) */
static void build_rounds(const Mesh *m, const Options *o)
{
    KdInput in = { .triangles = m->scene.triangles, .n_triangles = m->scene.n_triangles };
    int threads = o->threads[MAX_THREADS - 1];
    double kd[MAX_REPS], bvh[MAX_REPS], em[MAX_REPS], kd_ratio[MAX_REPS], bvh_ratio[MAX_REPS];
    int n = 0;
    for (int r = 0; r < o->builds; r++) {
        Error err = { 0 };
        KdTree tree;
        Bvh wide;
        Embree e;
        Status st = kd_build(&in, threads, &tree, &err);
        if (!st) {
            kd[n] = tree.stats.build_seconds;
            kd_free(&tree);
            st = bvh_build(&in, threads, &wide, &err);
        }
        if (st) {
            fprintf(stderr, "bench_traverse: tree build: %s\n", err.msg);
            error_clear(&err);
            return;
        }
        bvh[n] = wide.stats.build_seconds;
        bvh_free(&wide);
        int ok = embree_build(&e, m, threads) == 0;
        em[n] = e.build_seconds;
        embree_free(&e);
        if (!ok) return;
        kd_ratio[n] = kd[n] / em[n];
        bvh_ratio[n] = bvh[n] / em[n];
        n++;
    }
    printf("builds in turns, %d rounds, %d threads: kd-tree %.3f s, BVH %.3f s, Embree HIGH %.3f s (medians); "
           "kd / Embree %.2f, BVH / Embree %.2f (medians of the rounds' ratios)\n",
           n, threads, bench_median(kd, n), bench_median(bvh, n), bench_median(em, n), bench_median(kd_ratio, n), bench_median(bvh_ratio, n));
}

static void bench_mesh(const char *name, const Options *o, Pocl pocl[MAX_THREADS], int have_pocl)
{
    Mesh m;
    Error err = { 0 };
    if (mesh_open(&m, name, &err)) {
        fprintf(stderr, "bench_traverse: %s: %s\n", name, err.msg);
        error_clear(&err);
        mesh_close(&m);
        return;
    }
    size_t nt = m.scene.n_triangles;
    const KdStats *ks = &m.tree.stats;
    Embree emb[MAX_THREADS];
    memset(emb, 0, sizeof emb);
    int have_embree = o->embree;
    for (int t = 0; t < MAX_THREADS && have_embree; t++)
        if (embree_build(&emb[t], &m, o->threads[t])) have_embree = 0;
    RaySet sets[N_SETS];
    if (make_rays(&m, o->size, sets)) {
        fprintf(stderr, "bench_traverse: out of memory for the rays\n");
        rays_free(sets);
        mesh_close(&m);
        return;
    }
    const char *base = strrchr(name, '/') ? strrchr(name, '/') + 1 : name;
    printf("\n### %s: %zu triangles (loaded in %.3f s)\n\n", base, nt, m.load_seconds);
    printf("kd-tree: build %.3f s (%d threads) / %.3f s (1 thread); %u nodes, %u leaves, depth %u, "
           "SAH cost %.2f (with the empty-space bonus %.2f; one leaf %.0f), %.1f bytes/triangle: nodes and ids "
           "%.1f, triangle corners in the leaves %.1f\n",
           ks->build_seconds, o->threads[MAX_THREADS - 1], m.kd_build_1, ks->n_nodes, ks->n_leaves,
           ks->max_depth, ks->sah_cost, ks->sah_cost_bonus, ks->leaf_sah_cost, (double)ks->bytes / (double)(nt ? nt : 1),
           (double)(ks->bytes - ks->bytes_corners) / (double)(nt ? nt : 1), (double)ks->bytes_corners / (double)(nt ? nt : 1));
    const BvhStats *bs = &m.bvh.stats;
    printf("8-wide BVH: build %.3f s (2 threads); %u nodes, %u leaves (%.1f primitives each), depth %u, "
           "%.1f bytes/triangle (nodes %.1f, leaf records %.1f)\n",
           bs->build_seconds, bs->n_nodes, bs->n_leaves, bs->mean_prims_per_leaf, bs->max_depth,
           (double)((size_t)m.bvh.n_nodes * sizeof(BvhNode) + (size_t)m.bvh.n_leaf_prims * 4u) / (double)(nt ? nt : 1),
           (double)((size_t)m.bvh.n_nodes * sizeof(BvhNode)) / (double)(nt ? nt : 1),
           (double)((size_t)m.bvh.n_leaf_prims * 4u) / (double)(nt ? nt : 1));
    printf("C-W: the scalar device's walk, its build '%s'\n", m.paths->name);
    if (have_embree) {
        char ratio[96] = "";
        /* a ratio of times below a millisecond says nothing */
        if (emb[0].build_seconds > 1e-3 && emb[MAX_THREADS - 1].build_seconds > 1e-3)
            snprintf(ratio, sizeof ratio, "; kd build / Embree build: %.2f (%d threads), %.2f (1)",
                     ks->build_seconds / emb[MAX_THREADS - 1].build_seconds, o->threads[MAX_THREADS - 1],
                     m.kd_build_1 / emb[0].build_seconds);
        printf("Embree 3 (RTC_BUILD_QUALITY_HIGH): build %.3f s (%d threads) / %.3f s (1 thread), %.1f "
               "bytes/triangle allocated by the build%s\n",
               emb[MAX_THREADS - 1].build_seconds, o->threads[MAX_THREADS - 1], emb[0].build_seconds,
               (double)emb[MAX_THREADS - 1].build_bytes / (double)(nt ? nt : 1), ratio);
        if (o->builds > 0) build_rounds(&m, o);
    }

    SetResult res[N_SETS];
    memset(res, 0, sizeof res);
    uint max_n = 0;
    for (int k = 0; k < N_SETS; k++) max_n = sets[k].n > max_n ? sets[k].n : max_n;
    int pocl_ok[MAX_THREADS] = { 0 };
    /* as the renderer's program on a CPU for this mesh: its scene's features and the
     * lanes kernel's walk (a called function), with the kd-tree for the kd columns */
    unsigned features = kernel_scene_features(&m.ds) | KF_KDTREE | KF_BVH | KF_PATH_LANES;
    for (int t = 0; t < MAX_THREADS && have_pocl; t++)
        pocl_ok[t] = pocl[t].ok && pocl_program(&pocl[t], features) == 0 && pocl_upload(&pocl[t], &m, max_n) == 0;
    Hit *eh = malloc((max_n + 1) * sizeof *eh);
    uint *eo = malloc((max_n + 1) * sizeof *eo);
    for (int k = 0; k < N_SETS && eh && eo; k++) {
        RaySet *s = &sets[k];
        SetResult *r = &res[k];
        for (uint i = 0; i < s->n; i++) {
            r->hits += s->any ? s->ref_occ[i] : s->ref_hits[i].prim != NO_INDEX;
            /* the same t: the same closest distance; another primitive only on a tie */
            if (s->any) r->wide_diff += s->ref_occ[i] != s->wide_occ[i];
            else r->wide_diff += memcmp(&s->ref_hits[i], &s->wide_hits[i], sizeof(Hit)) != 0;
        }
        /* check first */
        r->pocl_diff = r->embree_diff = -1;
        for (int t = 0; t < MAX_THREADS; t++) {
            if (!pocl_ok[t] || pocl_put_rays(&pocl[t], s)) {
                pocl_ok[t] = 0;
                continue;
            }
            long d = 0;
            for (int kp = 0; kp < N_KERNELS && pocl_ok[t]; kp++) {
                if (pocl_trace(&pocl[t], s, kp) < 0.0) pocl_ok[t] = 0;
                else d += pocl_compare(&pocl[t], s, pocl_kernels[kp].wide);
            }
            if (pocl_ok[t]) r->pocl_diff = r->pocl_diff < 0 ? d : r->pocl_diff + d;
        }
        if (have_embree) {
            embree_trace(emb[MAX_THREADS - 1].scene, s, 0, 1, eh, eo);
            r->embree_diff = embree_compare(s, eh, eo);
        }
        Hit *tmp_h = eh;
        uint *tmp_o = eo;
        for (int t = 0; t < MAX_THREADS; t++) {
            int th = o->threads[t];
            /* the variants take turns within each repetition, so that a change in the
             * machine's load affects them alike */
            double sc[MAX_REPS], cc[MAX_REPS], sw[MAX_REPS], cw[MAX_REPS], sp[N_KERNELS][MAX_REPS],
                cp[N_KERNELS][MAX_REPS], s1[MAX_REPS], c1[MAX_REPS], s8[MAX_REPS], c8[MAX_REPS];
            for (int i = 0; i < o->reps; i++) {
                sc[i] = trace_c(&m, s, th, WALK_PAIRS, tmp_h, tmp_o);
                cc[i] = last_cpu_seconds;
                sw[i] = trace_c(&m, s, th, WALK_WIDE, tmp_h, tmp_o);
                cw[i] = last_cpu_seconds;
                for (int kp = 0; kp < N_KERNELS && pocl_ok[t]; kp++) {
                    sp[kp][i] = pocl_trace(&pocl[t], s, kp);
                    cp[kp][i] = last_cpu_seconds;
                }
                if (have_embree) {
                    s1[i] = embree_trace(emb[t].scene, s, 0, th, NULL, NULL);
                    c1[i] = last_cpu_seconds;
                    s8[i] = embree_trace(emb[t].scene, s, 1, th, NULL, NULL);
                    c8[i] = last_cpu_seconds;
                }
            }
            r->c[t] = rate(s->n, sc, o->reps);
            r->cpu_c[t] = rate(s->n, cc, o->reps);
            r->cw[t] = rate(s->n, sw, o->reps);
            r->cpu_cw[t] = rate(s->n, cw, o->reps);
            for (int kp = 0; kp < N_KERNELS && pocl_ok[t]; kp++) {
                r->pocl[kp][t] = rate(s->n, sp[kp], o->reps);
                r->cpu_pocl[kp][t] = rate(s->n, cp[kp], o->reps);
            }
            if (have_embree) {
                r->e1[t] = rate(s->n, s1, o->reps);
                r->cpu_e1[t] = rate(s->n, c1, o->reps);
                r->e8[t] = rate(s->n, s8, o->reps);
                r->cpu_e8[t] = rate(s->n, c8, o->reps);
            }
        }
    }
    free(eh);
    free(eo);

    int a = o->threads[0], b = o->threads[MAX_THREADS - 1];
    printf("\n| rays | query | count | hits |");
    print_pocl_heads("", a, b);
    printf(" C %dt | C %dt | C-W %dt | C-W %dt | Embree-1 %dt | Embree-1 %dt | Embree-8 %dt | Embree-8 %dt | vs Embree | "
           "PoCL vs C | BVH vs kd |\n", a, b, a, b, a, b, a, b);
    printf("|---|---|---:|---:|");
    for (int kp = 0; kp < 2 * N_KERNELS + 8; kp++) printf("---:|");
    printf("---:|---:|---:|\n");
    for (int k = 0; k < N_SETS; k++) {
        const SetResult *r = &res[k];
        char pd[32], ed[32];
        if (r->pocl_diff < 0) snprintf(pd, sizeof pd, "-");
        else snprintf(pd, sizeof pd, "%ld differ", r->pocl_diff);
        if (r->embree_diff < 0) snprintf(ed, sizeof ed, "-");
        else snprintf(ed, sizeof ed, "%ld disagree", r->embree_diff);
        printf("| %s | %s | %u | %u |", sets[k].name, sets[k].any ? "any" : "closest", sets[k].n, r->hits);
        const double rates[] = { r->c[0], r->c[1], r->cw[0], r->cw[1], r->e1[0], r->e1[1], r->e8[0], r->e8[1] };
        print_rates(r->pocl, rates, (int)(sizeof rates / sizeof rates[0]));
        printf(" %s | %s | %ld disagree |\n", ed, pd, r->wide_diff);
    }
    printf("\nThe same runs in Mrays per CPU-second (the CPU time of the whole process: the work per core, "
           "which other jobs taking the cores do not change; with ideal scaling the %d-thread columns equal "
           "the 1-thread ones), and PoCL over Embree single rays:\n\n", b);
    printf("| rays |");
    print_pocl_heads("", a, b);
    printf(" C %dt | C %dt | C-W %dt | C-W %dt | Embree-1 %dt | Embree-1 %dt | Embree-8 %dt | Embree-8 %dt |", a, b, a, b,
           a, b, a, b);
    print_pocl_heads("/Embree-1", a, b);
    printf("\n|---|");
    for (int kp = 0; kp < 4 * N_KERNELS + 8; kp++) printf("---:|");
    printf("\n");
    for (int k = 0; k < N_SETS; k++) {
        const SetResult *r = &res[k];
        printf("| %s %s |", sets[k].name, sets[k].any ? "any" : "closest");
        const double rates[] = { r->cpu_c[0],  r->cpu_c[1],  r->cpu_cw[0], r->cpu_cw[1],
                                 r->cpu_e1[0], r->cpu_e1[1], r->cpu_e8[0], r->cpu_e8[1] };
        print_rates(r->cpu_pocl, rates, (int)(sizeof rates / sizeof rates[0]));
        for (int kp = 0; kp < N_KERNELS; kp++)
            for (int t = 0; t < MAX_THREADS; t++)
                print_rate(r->cpu_e1[t] > 0.0 ? r->cpu_pocl[kp][t] / r->cpu_e1[t] : 0.0);
        printf("\n");
    }
    fflush(stdout);
    for (int t = 0; t < MAX_THREADS; t++) embree_free(&emb[t]);
    rays_free(sets);
    mesh_close(&m);
}

/* ------------------------------------------------------------------ main */

static const char *const default_meshes[] = {
    "../shared/models/bunny/bun_zipper.ply",
    "../shared/models/dragon/dragon_vrip.ply",
    "../shared/models/cornell-box/CornellBox-Original.obj",
    "../shared/models/cornell-box/CornellBox-Mirror.obj",
    "../shared/models/cornell-box/CornellBox-Sphere.obj",
    "../shared/models/cornell-box/CornellBox-Glossy.obj",
    "../shared/models/cornell-box/CornellBox-Glossy-Floor.obj",
    "../shared/models/cornell-box/CornellBox-Water.obj",
    "../shared/models/cornell-box/CornellBox-Empty-CO.obj",
    "../shared/models/cornell-box/CornellBox-Empty-RG.obj",
    "../shared/models/cornell-box/CornellBox-Empty-Squashed.obj",
    "../shared/models/cornell-box/CornellBox-Empty-White.obj",
    "../shared/models/sponza-dabrovic/sponza.obj",
    "sphere:1000000",
};

int main(int argc, char **argv)
{
    Options o = { 5, 1024, 1, 1, 0, { 1, 2 }, 64, 0 };
    const char *meshes[64];
    int n_meshes = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--reps") && i + 1 < argc) o.reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) o.size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--local") && i + 1 < argc) o.local = (size_t)atol(argv[++i]);
        else if (!strcmp(argv[i], "--builds") && i + 1 < argc) o.builds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--no-pocl")) o.pocl = 0;
        else if (!strcmp(argv[i], "--no-embree")) o.embree = 0;
        else if (!strcmp(argv[i], "--embree-robust")) o.embree_robust = 1;
        else if (argv[i][0] == '-') {
            fprintf(stderr, "usage: bench_traverse [--reps N] [--size N] [--local N] [--builds N] [--no-pocl] "
                            "[--no-embree] [--embree-robust] [MESH ...]\n");
            return 2;
        } else if (n_meshes < 64) meshes[n_meshes++] = argv[i];
    }
    if (o.reps < 1) o.reps = 1;
    if (o.reps > MAX_REPS) o.reps = MAX_REPS;
    if (o.size < 1 || o.size > 4096) o.size = 1024;
    if (o.builds < 0) o.builds = 0;
    if (o.builds > MAX_REPS) o.builds = MAX_REPS;
    pocl_local = o.local;
    embree_robust = o.embree_robust;
    if (n_meshes == 0)
        for (size_t i = 0; i < sizeof default_meshes / sizeof default_meshes[0]; i++) {
            FILE *f = strncmp(default_meshes[i], "sphere:", 7) ? fopen(default_meshes[i], "rb") : NULL;
            if (f) fclose(f);
            if (f || !strncmp(default_meshes[i], "sphere:", 7)) meshes[n_meshes++] = default_meshes[i];
        }

    /* PoCL: the first OpenCL CPU device, whole and as a 1-compute-unit sub-device */
    Pocl pocl[MAX_THREADS];
    memset(pocl, 0, sizeof pocl);
    int have_pocl = 0;
    OclDeviceInfo *devs = NULL;
    size_t n_devs = 0;
    Error err = { 0 };
    if (o.pocl && ocl_enumerate(&devs, &n_devs, &err) == ST_OK) {
        for (size_t i = 0; i < n_devs && !have_pocl; i++) {
            if (!(devs[i].type & CL_DEVICE_TYPE_CPU)) continue;
            cl_device_partition_property props[] = { CL_DEVICE_PARTITION_EQUALLY, 1, 0 };
            cl_device_id sub[64];
            cl_uint n_sub = 0;
            if (clCreateSubDevices(devs[i].id, props, 64, sub, &n_sub) == CL_SUCCESS && n_sub > 0) {
                for (cl_uint k = 1; k < n_sub; k++) clReleaseDevice(sub[k]);
                if (pocl_open(&pocl[0], &devs[i], sub[0])) pocl_close(&pocl[0]);
            }
            if (pocl_open(&pocl[1], &devs[i], NULL)) pocl_close(&pocl[1]);
            have_pocl = pocl[0].ok || pocl[1].ok;
            if (have_pocl)
                printf("OpenCL: %s, %s (%s), %u compute units%s\n", devs[i].name, devs[i].platform_version,
                       devs[i].driver_version, devs[i].compute_units,
                       pocl[0].ok ? "; 1-thread runs on a sub-device of 1 compute unit" : "");
        }
    }
    error_clear(&err);
    free(devs);
    if (o.embree)
        printf("Embree %d.%d.%d%s\n", (int)RTC_VERSION_MAJOR, (int)RTC_VERSION_MINOR, (int)RTC_VERSION_PATCH,
               o.embree_robust ? ", RTC_SCENE_FLAG_ROBUST (watertight)" : "");
    printf("rays: %dx%d primary, then a diffuse and a shadow ray per primary hit; Mrays/s, median of %d runs\n",
           o.size, o.size, o.reps);
    for (int i = 0; i < n_meshes; i++) bench_mesh(meshes[i], &o, pocl, have_pocl);
    for (int t = 0; t < MAX_THREADS; t++) pocl_close(&pocl[t]);
    return 0;
}
