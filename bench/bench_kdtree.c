/*
 * bench_kdtree.c -- kd-tree build time, tree statistics and scalar traversal rate.
 *
 *   bench_kdtree [MESH [threads [rays]]]
 *
 * MESH is a .ply or .obj file (read by host/io/mesh_load.c), "soup:N" (N random triangles in a
 * unit cube) or "sphere:N" (the closed bumpy sphere of mesh_make_sphere, about N
 * triangles); without one, the full dragon of ../shared/models (or sphere:1000000 when
 * it is not there). The tree is built with the given threads (0 = all cores, the
 * default) and with one thread, and the two node arrays must be identical. Rays go
 * from points around the mesh towards points inside its box; before timing, the
 * first ones are checked against brute force. Traversal is the kernel code compiled
 * as C on one core.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "accel/kdtree.h"
#include "base/timer.h"
#include "io/mesh_load.h"
#include "accel/traverse.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static float frand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (float)(rng_state >> 40) / 16777216.0f;
}

typedef struct { Triangle *t; size_t n, cap; } Mesh;

static int mesh_add(Mesh *m, vec3 a, vec3 b, vec3 c)
{
    if (m->n == m->cap) {
        size_t cap = m->cap ? 2 * m->cap : 1024;
        Triangle *t = realloc(m->t, cap * sizeof *t);
        if (!t) return -1;
        m->t = t;
        m->cap = cap;
    }
    Triangle tr = { a, 0, b, NO_INDEX, c, NO_INDEX };
    m->t[m->n++] = tr;
    return 0;
}

/* An .obj or .ply file through the renderer's readers (host/io/mesh_load.c). */
static int load_mesh(const char *path, Mesh *m)
{
    Scene sc;
    scene_init(&sc);
    Error err = { 0 };
    MeshOptions o = mesh_options(0);
    if (mesh_load(path, &sc, &o, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        scene_free(&sc);
        return -1;
    }
    for (size_t i = 0; i < sc.n_triangles; i++)
        if (mesh_add(m, sc.triangles[i].p0, sc.triangles[i].p1, sc.triangles[i].p2)) {
            scene_free(&sc);
            return -1;
        }
    scene_free(&sc);
    return 0;
}

static int make_soup(Mesh *m, long n)
{
    for (long i = 0; i < n; i++) {
        vec3 c = v3(frand(), frand(), frand());
        vec3 a = v3_add(c, v3((frand() - 0.5f) * 0.05f, (frand() - 0.5f) * 0.05f, (frand() - 0.5f) * 0.05f));
        vec3 b = v3_add(c, v3((frand() - 0.5f) * 0.05f, (frand() - 0.5f) * 0.05f, (frand() - 0.5f) * 0.05f));
        vec3 d = v3_add(c, v3((frand() - 0.5f) * 0.05f, (frand() - 0.5f) * 0.05f, (frand() - 0.5f) * 0.05f));
        if (mesh_add(m, a, b, d)) return -1;
    }
    return 0;
}

/* The closed bumpy sphere of mesh_make_sphere. */
static int make_sphere(Mesh *m, long n)
{
    Scene sc;
    scene_init(&sc);
    Error err = { 0 };
    int rc = mesh_make_sphere(&sc, (size_t)n, 0, &err) ? -1 : 0;
    for (size_t i = 0; i < sc.n_triangles && !rc; i++)
        rc = mesh_add(m, sc.triangles[i].p0, sc.triangles[i].p1, sc.triangles[i].p2);
    scene_free(&sc);
    return rc;
}

static Hit brute_closest(const SceneView *sc, Ray ray)
{
    RayPre rp;
    ray_prepare(ray, &rp);
    Hit best = { ray.tmax, NO_INDEX, 0.0f, 0.0f };
    for (uint i = 0; i < sc->params->n_triangles; i++) {
        Ray r = ray;
        r.tmax = best.t;
        Hit h;
        if (triangle_intersect(&rp, &sc->triangles[i], r, &h)) { h.prim = i; best = h; }
    }
    return best;
}

int main(int argc, char **argv)
{
    /* without arguments (make bench): the full dragon when it is there */
    const char *mesh = argc > 1 ? argv[1] : "../shared/models/dragon/dragon_vrip.ply";
    FILE *probe = argc > 1 ? NULL : fopen(mesh, "rb");
    if (argc < 2 && !probe) mesh = "sphere:1000000";
    if (probe) fclose(probe);
    int threads = argc > 2 ? atoi(argv[2]) : 0;
    long n_rays = argc > 3 ? atol(argv[3]) : 300000;
    Mesh m = { 0 };
    double t0 = timer_now();
    int rc = !strncmp(mesh, "soup:", 5) ? make_soup(&m, atol(mesh + 5))
           : !strncmp(mesh, "sphere:", 7) ? make_sphere(&m, atol(mesh + 7))
           : load_mesh(mesh, &m);
    if (rc) return 1;
    printf("mesh %s: %zu triangles (loaded in %.2f s)\n", mesh, m.n, timer_now() - t0);

    KdInput in = { .triangles = m.t, .n_triangles = m.n };
    KdTree tree, tree1;
    Error err = { 0 };
    if (kd_build(&in, threads, &tree, &err) != ST_OK) { fprintf(stderr, "%s\n", err.msg); return 1; }
    if (kd_build(&in, 1, &tree1, &err) != ST_OK) { fprintf(stderr, "%s\n", err.msg); return 1; }
    int same = tree.n_nodes == tree1.n_nodes && tree.n_leaf_prims == tree1.n_leaf_prims &&
               !memcmp(tree.nodes, tree1.nodes, tree.n_nodes * sizeof *tree.nodes) &&
               !memcmp(tree.leaf_prims, tree1.leaf_prims, tree.n_leaf_prims * sizeof(uint));
    const KdStats *s = &tree.stats;
    printf("build: %.3f s with %d threads, %.3f s with 1 (identical trees: %s)\n",
           s->build_seconds, threads, tree1.stats.build_seconds, same ? "yes" : "NO");
    printf("nodes %u, leaves %u (%u empty), max depth %u, %.2f prims/leaf, %u words of leaf data\n",
           s->n_nodes, s->n_leaves, s->n_empty_leaves, s->max_depth, s->mean_prims_per_leaf,
           tree.n_leaf_prims);
    printf("SAH cost %.2f (with the empty-space bonus %.2f, single leaf %.0f), %zu bytes = %.2f bytes/triangle "
           "(%.2f of them the triangles' corners in the leaves), %.2f refs/triangle\n",
           s->sah_cost, s->sah_cost_bonus, s->leaf_sah_cost, s->bytes, (double)s->bytes / (double)(m.n ? m.n : 1),
           (double)s->bytes_corners / (double)(m.n ? m.n : 1),
           (s->mean_prims_per_leaf * (s->n_leaves - s->n_empty_leaves)) / (double)(m.n ? m.n : 1));

    RenderParams params;
    memset(&params, 0, sizeof params);
    params.n_triangles = (uint)m.n;
    params.n_nodes = tree.n_nodes;
    params.n_leaf_prims = tree.n_leaf_prims;
    params.bounds_lo = tree.lo;
    params.bounds_hi = tree.hi;
    SceneView sc = { .params = &params, .nodes = tree.nodes, .leaf_prims = tree.leaf_prims, .triangles = m.t };

    vec3 c = v3_scale(v3_add(tree.lo, tree.hi), 0.5f), ext = v3_sub(tree.hi, tree.lo);
    float radius = 0.75f * v3_len(ext);
    Ray *rays = malloc((size_t)n_rays * sizeof *rays);
    if (!rays) return 1;
    for (long i = 0; i < n_rays; i++) {
        vec3 dir = v3(frand() * 2.0f - 1.0f, frand() * 2.0f - 1.0f, frand() * 2.0f - 1.0f);
        vec3 o = v3_add(c, v3_scale(v3_norm(dir), radius));
        vec3 target = v3_add(tree.lo, v3_mul(ext, v3(frand(), frand(), frand())));
        Ray r = { o, 0.0f, v3_sub(target, o), K_INF };
        rays[i] = r;
    }
    int n_check = m.n > 200000 ? 50 : 500, bad = 0;
    for (int i = 0; i < n_check && i < n_rays; i++) {
        Hit a = trace_closest(&sc, rays[i]), b = brute_closest(&sc, rays[i]);
        if (a.prim != b.prim && !(a.t == b.t)) bad++;
    }
    printf("checked %d rays against brute force: %d differ\n", n_check, bad);

    double t = timer_now();
    long hits = 0;
    for (long i = 0; i < n_rays; i++) hits += trace_closest(&sc, rays[i]).prim != NO_INDEX;
    double closest = timer_now() - t;
    t = timer_now();
    long any = 0;
    for (long i = 0; i < n_rays; i++) any += trace_any(&sc, rays[i]);
    double anyt = timer_now() - t;
    printf("closest: %.2f Mrays/s (%ld hits), any: %.2f Mrays/s (%ld hits), 1 core, scalar C\n",
           n_rays / closest * 1e-6, hits, n_rays / anyt * 1e-6, any);
    free(rays);
    kd_free(&tree);
    kd_free(&tree1);
    free(m.t);
    return bad || !same || hits != any;
}
