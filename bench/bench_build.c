/*
 * bench_build.c -- the default BVH's load and build time on a large unique mesh,
 * against Embree 3's RTC_BUILD_QUALITY_HIGH build of the same triangles (issue 42:
 * "a 10-million-triangle unique mesh loads and builds at least as fast as Embree's
 * HIGH build per triangle, memory per triangle stated").
 *
 *   bench_build [--tris N] [--rounds R] [--no-embree]
 *
 * The mesh is mesh_make_sphere's closed bumpy sphere (host/scene/mesh_sink.c) of at
 * least N triangles (default 10,000,000): deterministic, every triangle its own (no
 * instancing), made through the mesh sink every file reader appends through, so the
 * "load" column is the scene side of a load less the file's parsing. Each round, on 1
 * and then 2 threads, in turns: clpt loads the mesh into a Scene and builds its BVH
 * (bvh_build, what render_scene.c builds for a scene without instances: binned SAH,
 * collapse to 8-wide nodes, leaf records), then Embree builds the same triangles
 * (rtcCommitScene; the vertex copy into Embree's buffers is not timed). Printed: each
 * round, then the medians over R rounds (default 3) and the median of the rounds'
 * build ratios clpt / Embree; bytes per triangle: clpt's BVH nodes plus leaf records
 * (the arrays it keeps and uploads; in brackets the node array as allocated, room for
 * a wide node per binary node, mostly never touched), Embree's as its memory monitor
 * counts what rtcCommitScene allocates and has not freed when it returns (as
 * bench_traverse measures it). Neither counts the triangles themselves (clpt's Scene,
 * Embree's vertex and index buffers). --no-embree times clpt alone (for profiling).
 *
 * Checked before the numbers mean anything: every clpt build's nodes and leaf records
 * hash (SHA-256) to the same digest, whatever the threads (the tree must not depend on
 * them, and a change to the build that should keep the tree can be checked against the
 * printed digest), and Embree's scene bounds equal clpt's root box.
 */
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include <embree3/rtcore.h>

#include "accel/bvh.h"
#include "base/sha256.h"
#include "base/timer.h"
#include "bench_embree.h"
#include "bench_util.h"
#include "scene/mesh_sink.h"
#include "scene/scene.h"

#define MAX_ROUNDS 15

typedef struct {
    double load_s, build_s, embree_s;
    double bytes, alloc, embree_bytes;  /* per triangle */
} Round;

/* ------------------------------------------------------------------ clpt */

typedef struct {
    size_t n_triangles;
    double load_s, build_s;
    double build_cpu_s;              /* CPU seconds of the build, every thread */
    double bytes_per_tri;            /* nodes and leaf records written */
    double alloc_per_tri;            /* the node array as allocated (see below) */
    char digest[65];
    vec3 lo, hi;
} ClptRun;

/* Loads the mesh into sc (left loaded for Embree) and builds its BVH. */
static int clpt_run(Scene *sc, size_t min_tris, int threads, ClptRun *r)
{
    Error err = { 0 };
    scene_init(sc);
    double t0 = timer_now();
    if (mesh_make_sphere(sc, min_tris, 0, &err)) {
        fprintf(stderr, "bench_build: %s\n", err.msg);
        return -1;
    }
    r->load_s = timer_now() - t0;
    r->n_triangles = sc->n_triangles;
    KdInput in = { .triangles = sc->triangles, .n_triangles = sc->n_triangles };
    Bvh bvh;
    t0 = timer_now();
    double c0 = bench_cpu_now();
    if (bvh_build(&in, threads, &bvh, &err)) {
        fprintf(stderr, "bench_build: %s\n", err.msg);
        return -1;
    }
    r->build_s = timer_now() - t0;
    r->build_cpu_s = bench_cpu_now() - c0;
    size_t bytes = (size_t)bvh.n_nodes * sizeof *bvh.nodes + (size_t)bvh.n_leaf_prims * sizeof *bvh.leaf_prims;
    r->bytes_per_tri = (double)bytes / (double)(r->n_triangles ? r->n_triangles : 1);
    /* bvh_collapse allocates room for a wide node per binary node (2 leaves - 1, plus
     * one) before it knows how many it writes; pages_alloc_large's untouched pages are
     * address space, not memory, so this is the upper bound, not the resident size */
    size_t alloc = (size_t)2 * bvh.stats.n_leaves * sizeof *bvh.nodes + ((size_t)bvh.n_leaf_prims + 1) * sizeof *bvh.leaf_prims;
    r->alloc_per_tri = (double)alloc / (double)(r->n_triangles ? r->n_triangles : 1);
    Sha256 h;
    unsigned char d[SHA256_DIGEST_SIZE];
    sha256_init(&h);
    sha256_update(&h, bvh.nodes, (size_t)bvh.n_nodes * sizeof *bvh.nodes);
    sha256_update(&h, bvh.leaf_prims, (size_t)bvh.n_leaf_prims * sizeof *bvh.leaf_prims);
    sha256_final(&h, d);
    sha256_hex(d, r->digest);
    r->lo = bvh.lo;
    r->hi = bvh.hi;
    bvh_free(&bvh);
    return 0;
}

/* ------------------------------------------------------------------ Embree */

/* Builds sc's triangles with RTC_BUILD_QUALITY_HIGH on `threads` threads; the build's
 * seconds and allocated bytes into *seconds, *bytes, its bounds into lo, hi. */
static int embree_run(const Scene *sc, int threads, double *seconds, double *bytes, float lo[3], float hi[3])
{
    char cfg[64];
    snprintf(cfg, sizeof cfg, "threads=%d", threads);
    RTCDevice dev = rtcNewDevice(cfg);
    if (!dev) {
        fprintf(stderr, "bench_build: rtcNewDevice failed (error %d)\n", (int)rtcGetDeviceError(NULL));
        return -1;
    }
    size_t n = sc->n_triangles;
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = bench_embree_triangles(dev, sc->triangles, n);
    int rc = -1;
    if (g) {
        rtcAttachGeometry(scene, g);
        long long allocated = 0;
        rc = bench_embree_commit(dev, scene, seconds, &allocated);
        *bytes = (double)allocated / (double)(n ? n : 1);
        struct RTCBounds b;
        rtcGetSceneBounds(scene, &b);
        lo[0] = b.lower_x, lo[1] = b.lower_y, lo[2] = b.lower_z;
        hi[0] = b.upper_x, hi[1] = b.upper_y, hi[2] = b.upper_z;
    }
    if (g) rtcReleaseGeometry(g);
    rtcReleaseScene(scene);
    rtcReleaseDevice(dev);
    return rc;
}

/* ------------------------------------------------------------------ main */

static double median_of(const Round *r, int n, size_t field)
{
    double v[MAX_ROUNDS];
    for (int i = 0; i < n; i++) v[i] = *(const double *)(const void *)((const char *)&r[i] + field);
    return bench_median(v, n);
}

int main(int argc, char **argv)
{
    size_t min_tris = 10000000;
    int rounds = 3, embree = 1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--tris") && i + 1 < argc) min_tris = (size_t)atol(argv[++i]);
        else if (!strcmp(argv[i], "--rounds") && i + 1 < argc) rounds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--no-embree")) embree = 0;
        else {
            fprintf(stderr, "usage: bench_build [--tris N] [--rounds R] [--no-embree]\n");
            return 2;
        }
    }
    if (rounds < 1 || rounds > MAX_ROUNDS || min_tris < 1) {
        fprintf(stderr, "bench_build: --rounds takes 1 to %d, --tris at least 1\n", MAX_ROUNDS);
        return 2;
    }
    const int thread_counts[2] = { 1, 2 };
    Round res[2][MAX_ROUNDS];
    char first_digest[65] = "";
    size_t n_tris = 0;
    int bad = 0;
    bench_print_load("before");
    for (int r = 0; r < rounds; r++)
        for (int ti = 0; ti < 2; ti++) {
            int threads = thread_counts[ti];
            Scene sc;
            ClptRun c;
            if (clpt_run(&sc, min_tris, threads, &c)) return 1;
            n_tris = c.n_triangles;
            if (!first_digest[0]) memcpy(first_digest, c.digest, sizeof first_digest);
            if (strcmp(first_digest, c.digest)) {
                printf("round %d, %d threads: the BVH differs (sha256 %s, first %s)\n", r + 1, threads, c.digest,
                       first_digest);
                bad = 1;
            }
            Round *o = &res[ti][r];
            o->load_s = c.load_s;
            o->build_s = c.build_s;
            o->bytes = c.bytes_per_tri;
            o->alloc = c.alloc_per_tri;
            o->embree_s = o->embree_bytes = 0.0;
            if (embree) {
                float lo[3], hi[3];
                if (embree_run(&sc, threads, &o->embree_s, &o->embree_bytes, lo, hi)) {
                    fprintf(stderr, "bench_build: Embree's build failed\n");
                    return 1;
                }
                if (lo[0] != c.lo.x || lo[1] != c.lo.y || lo[2] != c.lo.z || hi[0] != c.hi.x || hi[1] != c.hi.y ||
                    hi[2] != c.hi.z) {
                    printf("round %d: Embree's bounds differ from clpt's root box\n", r + 1);
                    bad = 1;
                }
            }
            scene_free(&sc);
            printf("round %d, %d thread%s: %zu triangles, clpt load %.3f s, BVH build %.3f s (%.3f CPU s); Embree "
                   "HIGH build %.3f s; ratio %.2f\n", r + 1, threads, threads > 1 ? "s" : "", n_tris, o->load_s,
                   o->build_s, c.build_cpu_s, o->embree_s, o->embree_s > 0.0 ? o->build_s / o->embree_s : 0.0);
            fflush(stdout);
        }
    bench_print_load("after");
    printf("\nBVH sha256 %s (the same in every round and thread count: %s)\n", first_digest, bad ? "NO" : "yes");
    printf("\nmedians of %d rounds (ratio: the median of the rounds' clpt build / Embree build; below 1 is faster "
           "than Embree)\n\n", rounds);
    printf("| triangles | threads | clpt load s | clpt build s | Embree HIGH build s | build ratio | "
           "clpt load+build / Embree | clpt bytes/tri (allocated) | Embree bytes/tri |\n");
    printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int ti = 0; ti < 2; ti++) {
        Round *rs = res[ti];
        double ratio[MAX_ROUNDS], whole[MAX_ROUNDS];
        for (int r = 0; r < rounds; r++) {
            ratio[r] = rs[r].embree_s > 0.0 ? rs[r].build_s / rs[r].embree_s : 0.0;
            whole[r] = rs[r].embree_s > 0.0 ? (rs[r].load_s + rs[r].build_s) / rs[r].embree_s : 0.0;
        }
        printf("| %zu | %d | %.3f | %.3f | %.3f | %.2f | %.2f | %.1f (%.1f) | %.1f |\n", n_tris, thread_counts[ti],
               median_of(rs, rounds, offsetof(Round, load_s)), median_of(rs, rounds, offsetof(Round, build_s)),
               median_of(rs, rounds, offsetof(Round, embree_s)), bench_median(ratio, rounds),
               bench_median(whole, rounds), median_of(rs, rounds, offsetof(Round, bytes)),
               median_of(rs, rounds, offsetof(Round, alloc)), median_of(rs, rounds, offsetof(Round, embree_bytes)));
    }
    return bad;
}
