/*
 * gen_mesh.c — writes the closed bumpy sphere of mesh_make_sphere (host/scene/mesh_sink.c) with at
 * least N triangles as a binary little-endian PLY, for trying clpt on meshes of any
 * size (the 10-million-triangle check of docs/meshes.md):
 *
 *     make build/gen_mesh && build/gen_mesh 10000000 /tmp/sphere10m.ply
 *     build/clpt /tmp/sphere10m.ply --stats --spp 4 -o sphere.png
 *
 * The vertices are shared between faces as the sphere shares them; the file holds each
 * distinct vertex once.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/mesh_sink.h"

/* Vertex index of a position, by a hash table over the bit patterns. */
typedef struct { vec3 *v; uint32_t *slot; size_t n, cap; } VertexSet;

static uint32_t vs_find(VertexSet *s, vec3 p)
{
    uint32_t b[3];
    memcpy(b, &p, sizeof b);
    size_t h = ((size_t)b[0] * 73856093u) ^ ((size_t)b[1] * 19349663u) ^ ((size_t)b[2] * 83492791u);
    for (size_t i = h & (s->cap - 1);; i = (i + 1) & (s->cap - 1)) {
        uint32_t k = s->slot[i];
        if (k == UINT32_MAX) {
            s->slot[i] = (uint32_t)s->n;
            s->v[s->n] = p;
            return (uint32_t)s->n++;
        }
        if (!memcmp(&s->v[k], &p, sizeof p)) return k;
    }
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: gen_mesh TRIANGLES OUT.ply\n");
        return 2;
    }
    size_t want = (size_t)atol(argv[1]);
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    if (mesh_make_sphere(&s, want, 0, &err)) {
        fprintf(stderr, "gen_mesh: %s\n", err.msg);
        return 1;
    }
    size_t nt = s.n_triangles;
    VertexSet vs = { 0 };
    vs.cap = 1;
    while (vs.cap < 2 * nt) vs.cap <<= 1;
    vs.v = malloc(nt * sizeof *vs.v);
    vs.slot = malloc(vs.cap * sizeof *vs.slot);
    uint32_t *idx = malloc(3 * nt * sizeof *idx);
    if (!vs.v || !vs.slot || !idx) {
        fprintf(stderr, "gen_mesh: out of memory\n");
        return 1;
    }
    memset(vs.slot, 0xff, vs.cap * sizeof *vs.slot);
    for (size_t i = 0; i < nt; i++) {
        idx[3 * i] = vs_find(&vs, s.triangles[i].p0);
        idx[3 * i + 1] = vs_find(&vs, s.triangles[i].p1);
        idx[3 * i + 2] = vs_find(&vs, s.triangles[i].p2);
    }
    FILE *f = fopen(argv[2], "wb");
    if (!f) {
        perror(argv[2]);
        return 1;
    }
    fprintf(f, "ply\nformat binary_little_endian 1.0\ncomment clpt tools/gen_mesh.c: a closed bumpy sphere\n"
               "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
               "element face %zu\nproperty list uchar uint vertex_indices\nend_header\n",
            vs.n, nt);
    /* little-endian hosts only, like every machine clpt is built on */
    fwrite(vs.v, sizeof *vs.v, vs.n, f);
    for (size_t i = 0; i < nt; i++) {
        unsigned char three = 3;
        fwrite(&three, 1, 1, f);
        fwrite(&idx[3 * i], sizeof *idx, 3, f);
    }
    if (fclose(f)) {
        perror(argv[2]);
        return 1;
    }
    printf("%s: %zu triangles, %zu vertices\n", argv[2], nt, vs.n);
    free(vs.v);
    free(vs.slot);
    free(idx);
    scene_free(&s);
    return 0;
}
