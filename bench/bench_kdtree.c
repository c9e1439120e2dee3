/*
 * bench_kdtree.c -- kd-tree build time, tree statistics and scalar traversal rate.
 *
 *   bench_kdtree MESH [threads] [rays]
 *
 * MESH is an ASCII PLY file (vertex x y z, then faces as vertex lists, fanned into
 * triangles), an OBJ file (only its v and f lines), "soup:N" (N random triangles in a unit cube) or "sphere:N" (a sphere
 * tessellated into about N triangles). The tree is built with the given threads (0 =
 * all cores) and with one thread, and the two node arrays must be identical. Rays go
 * from points around the mesh towards points inside its box; before timing, the
 * first ones are checked against brute force. Traversal is the kernel code compiled
 * as C on one core.
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "kdtree.h"
#include "traverse.cl"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

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

/* Just enough PLY for the Stanford scans: ASCII, x y z among the vertex properties,
 * one face list property. */
static int load_ply(const char *path, Mesh *m)
{
    FILE *f = fopen(path, "r");
    if (!f) { fprintf(stderr, "%s: %s\n", path, strerror(errno)); return -1; }
    char line[512];
    long nv = 0, nf = 0;
    int nprops = 0, ix = -1, iy = -1, iz = -1, in_vertex = 0;
    while (fgets(line, sizeof line, f)) {
        char name[64];
        if (sscanf(line, "element vertex %ld", &nv) == 1) { in_vertex = 1; continue; }
        if (sscanf(line, "element face %ld", &nf) == 1) { in_vertex = 0; continue; }
        if (in_vertex && sscanf(line, "property float %63s", name) == 1) {
            if (!strcmp(name, "x")) ix = nprops;
            if (!strcmp(name, "y")) iy = nprops;
            if (!strcmp(name, "z")) iz = nprops;
            nprops++;
        }
        if (!strncmp(line, "end_header", 10)) break;
    }
    if (ix < 0 || iy < 0 || iz < 0 || nv <= 0) { fclose(f); fprintf(stderr, "%s: unsupported PLY\n", path); return -1; }
    vec3 *v = malloc((size_t)nv * sizeof *v);
    if (!v) { fclose(f); return -1; }
    for (long i = 0; i < nv; i++) {
        float p[16] = { 0 };
        for (int j = 0; j < nprops; j++)
            if (fscanf(f, "%f", &p[j < 16 ? j : 15]) != 1) { free(v); fclose(f); return -1; }
        v[i] = v3(p[ix], p[iy], p[iz]);
    }
    for (long i = 0; i < nf; i++) {
        int k;
        long idx[64];
        if (fscanf(f, "%d", &k) != 1 || k < 3 || k > 64) break;
        for (int j = 0; j < k; j++)
            if (fscanf(f, "%ld", &idx[j]) != 1) { k = 0; break; }
        for (int j = 2; j < k; j++)
            if (idx[0] < nv && idx[j - 1] < nv && idx[j] < nv && mesh_add(m, v[idx[0]], v[idx[j - 1]], v[idx[j]]))
                { free(v); fclose(f); return -1; }
    }
    free(v);
    fclose(f);
    return 0;
}

/* Just the geometry of an OBJ: "v x y z" and "f a/.. b/.. c/.." (negative = relative). */
static int load_obj(const char *path, Mesh *m)
{
    FILE *f = fopen(path, "r");
    if (!f) { fprintf(stderr, "%s: %s\n", path, strerror(errno)); return -1; }
    vec3 *v = NULL;
    size_t nv = 0, cap = 0;
    char line[4096];
    int rc = 0;
    while (!rc && fgets(line, sizeof line, f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            if (nv == cap) {
                cap = cap ? 2 * cap : 4096;
                vec3 *nvp = realloc(v, cap * sizeof *v);
                if (!nvp) { rc = -1; break; }
                v = nvp;
            }
            float x, y, z;
            if (sscanf(line + 2, "%f %f %f", &x, &y, &z) == 3) v[nv++] = v3(x, y, z);
        } else if (line[0] == 'f' && line[1] == ' ') {
            long idx[64];
            int k = 0;
            for (char *tok = strtok(line + 2, " \t\r\n"); tok && k < 64; tok = strtok(NULL, " \t\r\n")) {
                long i = strtol(tok, NULL, 10);
                idx[k++] = i < 0 ? (long)nv + i : i - 1;
            }
            for (int j = 2; j < k; j++)
                if (idx[0] >= 0 && idx[j - 1] >= 0 && idx[j] >= 0 && (size_t)idx[0] < nv &&
                    (size_t)idx[j - 1] < nv && (size_t)idx[j] < nv)
                    rc |= mesh_add(m, v[idx[0]], v[idx[j - 1]], v[idx[j]]);
        }
    }
    free(v);
    fclose(f);
    return rc;
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

static vec3 sphere_point(int i, int j, int nu, int nv)
{
    float su, cu, sv, cv;
    k_sincos(K_TWO_PI * (float)i / (float)nu, &su, &cu);
    k_sincos(K_PI * (float)j / (float)nv, &sv, &cv);
    return v3(sv * cu, cv, sv * su);
}

static int make_sphere(Mesh *m, long n)
{
    int nv = (int)sqrt((double)n / 4.0) + 2, nu = 2 * nv;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            vec3 a = sphere_point(i, j, nu, nv), b = sphere_point(i + 1, j, nu, nv);
            vec3 c = sphere_point(i + 1, j + 1, nu, nv), d = sphere_point(i, j + 1, nu, nv);
            if (mesh_add(m, a, b, c) || mesh_add(m, a, c, d)) return -1;
        }
    return 0;
}

static Hit brute_closest(const SceneView *sc, Ray ray)
{
    RayPre rp = ray_prepare(ray);
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
    if (argc < 2) {
        fprintf(stderr, "usage: %s MESH.ply|MESH.obj|soup:N|sphere:N [threads] [rays]\n", argv[0]);
        return 2;
    }
    int threads = argc > 2 ? atoi(argv[2]) : 0;
    long n_rays = argc > 3 ? atol(argv[3]) : 1000000;
    Mesh m = { 0 };
    double t0 = now();
    int rc = !strncmp(argv[1], "soup:", 5) ? make_soup(&m, atol(argv[1] + 5))
           : !strncmp(argv[1], "sphere:", 7) ? make_sphere(&m, atol(argv[1] + 7))
           : strstr(argv[1], ".obj") ? load_obj(argv[1], &m)
           : load_ply(argv[1], &m);
    if (rc) return 1;
    printf("mesh %s: %zu triangles (loaded in %.2f s)\n", argv[1], m.n, now() - t0);

    KdInput in = { NULL, 0, m.t, m.n, NULL, 0 };
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
    printf("nodes %u, leaves %u (%u empty), max depth %u, %.2f prims/leaf, %u leaf ids\n",
           s->n_nodes, s->n_leaves, s->n_empty_leaves, s->max_depth, s->mean_prims_per_leaf,
           tree.n_leaf_prims);
    printf("SAH cost %.2f (single leaf %.0f), %zu bytes = %.2f bytes/triangle, %.2f refs/triangle\n",
           s->sah_cost, s->leaf_sah_cost, s->bytes, (double)s->bytes / (double)(m.n ? m.n : 1),
           (s->mean_prims_per_leaf * (s->n_leaves - s->n_empty_leaves)) / (double)(m.n ? m.n : 1));

    RenderParams params;
    memset(&params, 0, sizeof params);
    params.n_triangles = (uint)m.n;
    params.n_nodes = tree.n_nodes;
    params.n_leaf_prims = tree.n_leaf_prims;
    params.bounds_lo = tree.lo;
    params.bounds_hi = tree.hi;
    SceneView sc = { &params, tree.nodes, tree.leaf_prims, NULL, m.t, NULL, NULL, NULL, NULL, NULL };

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

    double t = now();
    long hits = 0;
    for (long i = 0; i < n_rays; i++) hits += trace_closest(&sc, rays[i]).prim != NO_INDEX;
    double closest = now() - t;
    t = now();
    long any = 0;
    for (long i = 0; i < n_rays; i++) any += trace_any(&sc, rays[i]);
    double anyt = now() - t;
    printf("closest: %.2f Mrays/s (%ld hits), any: %.2f Mrays/s (%ld hits), 1 core, scalar C\n",
           n_rays / closest * 1e-6, hits, n_rays / anyt * 1e-6, any);
    free(rays);
    kd_free(&tree);
    kd_free(&tree1);
    free(m.t);
    return bad || !same || hits != any;
}
