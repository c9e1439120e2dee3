/*
 * nvdb_writer.h — a minimal NanoVDB (.nvdb, ABI 32) writer for the tests, the fuzz
 * seeds and the example scenes: float grids whose voxels lie in one lower node
 * (a 128^3 block aligned to 128), one root tile, one upper node, one leaf per 8^3
 * block that holds a voxel. Written from the layout docs/media.md and host/io/nanovdb.c
 * describe, independently of the reader's code, so that the reader is checked against
 * the format rather than against itself. Codec none or ZIP (zlib).
 */
#ifndef CLPT_NVDB_WRITER_H
#define CLPT_NVDB_WRITER_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

typedef struct {
    const char *name;
    int ox, oy, oz;            /* index of the first voxel */
    int nx, ny, nz;            /* the dense block (x fastest in `values`) */
    const float *values;
    double voxel[3];           /* index-to-world: world = voxel * index + offset */
    double offset[3];
    uint32_t type, cls;        /* 1 float, 2 fog volume unless set otherwise (0 = default) */
} NvdbGrid;

static void nvdbw_u16(unsigned char *p, uint16_t v) { memcpy(p, &v, 2); }
static void nvdbw_u32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void nvdbw_u64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static void nvdbw_f32(unsigned char *p, float v) { memcpy(p, &v, 4); }
static void nvdbw_f64(unsigned char *p, double v) { memcpy(p, &v, 8); }

/* The metadata's name key, which NanoVDB's own reader (32.3, pbrt-v4's) compares
 * before the name: h = 67 h + byte + (h >> 56) over the name's bytes. */
static uint64_t nvdbw_name_key(const char *name)
{
    uint64_t h = 0;
    for (const unsigned char *c = (const unsigned char *)name; *c; c++) h = h * 67u + *c + (h >> 56);
    return h;
}

#define NVDBW_VERSION ((32u << 21) | (7u << 10) | 0u)

/* One grid's buffer (malloc'd), its size in *len. */
static unsigned char *nvdbw_grid(const NvdbGrid *g, size_t *len)
{
    int lx = g->ox & ~127, ly = g->oy & ~127, lz = g->oz & ~127;   /* the lower node */
    int leaf_used[4096] = { 0 };
    int n_leaves = 0;
    for (int z = 0; z < g->nz; z++)
        for (int y = 0; y < g->ny; y++)
            for (int x = 0; x < g->nx; x++) {
                int i = g->ox + x - lx, j = g->oy + y - ly, k = g->oz + z - lz;
                if (i < 0 || i > 127 || j < 0 || j > 127 || k < 0 || k > 127) abort();   /* one lower node only */
                int n = ((i >> 3) << 8) | ((j >> 3) << 4) | (k >> 3);
                if (!leaf_used[n]) leaf_used[n] = ++n_leaves;
            }
    size_t grid = 0, tree = 672, root = tree + 64, upper = root + 64 + 32, lower = upper + 270400,
           leaves = lower + 33856, size = leaves + (size_t)n_leaves * 2144;
    unsigned char *b = calloc(1, size);
    if (!b) return NULL;
    /* GridData */
    nvdbw_u64(b + grid, 0x304244566f6e614eull);   /* "NanoVDB0": older readers (pbrt-v4's 32.3) know only this */
    nvdbw_u64(b + grid + 8, ~0ull);               /* checksum disabled */
    nvdbw_u32(b + grid + 16, NVDBW_VERSION);
    nvdbw_u32(b + grid + 28, 1);                  /* grid count */
    nvdbw_u64(b + grid + 32, size);
    strncpy((char *)b + grid + 40, g->name, 255);
    for (int a = 0; a < 3; a++) {   /* the map: float and double, forward and inverse */
        nvdbw_f32(b + 296 + 4 * (4 * a), (float)g->voxel[a]);
        nvdbw_f32(b + 296 + 36 + 4 * (4 * a), (float)(1.0 / g->voxel[a]));
        nvdbw_f32(b + 296 + 72 + 4 * a, (float)g->offset[a]);
        nvdbw_f64(b + 296 + 88 + 8 * (4 * a), g->voxel[a]);
        nvdbw_f64(b + 296 + 160 + 8 * (4 * a), 1.0 / g->voxel[a]);
        nvdbw_f64(b + 296 + 232 + 8 * a, g->offset[a]);
    }
    nvdbw_f32(b + 296 + 84, 1.0f);
    nvdbw_f64(b + 296 + 256, 1.0);
    int lo[3] = { g->ox, g->oy, g->oz }, hi[3] = { g->ox + g->nx - 1, g->oy + g->ny - 1, g->oz + g->nz - 1 };
    for (int a = 0; a < 3; a++) {
        nvdbw_f64(b + 560 + 8 * a, g->offset[a] + g->voxel[a] * lo[a]);
        nvdbw_f64(b + 584 + 8 * a, g->offset[a] + g->voxel[a] * (hi[a] + 1));
        nvdbw_f64(b + 608 + 8 * a, g->voxel[a]);
    }
    nvdbw_u32(b + 632, g->cls ? g->cls : 2u);
    nvdbw_u32(b + 636, g->type ? g->type : 1u);
    /* TreeData: offsets from the tree to the first leaf, lower, upper, root */
    nvdbw_u64(b + tree + 0, leaves - tree);
    nvdbw_u64(b + tree + 8, lower - tree);
    nvdbw_u64(b + tree + 16, upper - tree);
    nvdbw_u64(b + tree + 24, root - tree);
    nvdbw_u32(b + tree + 32, (uint32_t)n_leaves);
    nvdbw_u32(b + tree + 36, 1);
    nvdbw_u32(b + tree + 40, 1);
    nvdbw_u64(b + tree + 56, (uint64_t)g->nx * g->ny * g->nz);
    /* root: the active box, one tile holding the upper node */
    for (int a = 0; a < 3; a++) {
        nvdbw_u32(b + root + 4 * a, (uint32_t)lo[a]);
        nvdbw_u32(b + root + 12 + 4 * a, (uint32_t)hi[a]);
    }
    nvdbw_u32(b + root + 24, 1);
    uint64_t key = ((uint64_t)((uint32_t)lx >> 12) << 42) | ((uint64_t)((uint32_t)ly >> 12) << 21) |
                   (uint64_t)((uint32_t)lz >> 12);
    nvdbw_u64(b + root + 64, key);
    nvdbw_u64(b + root + 64 + 8, upper - root);
    nvdbw_u32(b + root + 64 + 16, 1);
    /* upper: the lower node's entry */
    int ux = lx & ~4095, uy = ly & ~4095, uz = lz & ~4095;
    for (int a = 0; a < 3; a++) nvdbw_u32(b + upper + 4 * a, (uint32_t)(a == 0 ? ux : a == 1 ? uy : uz));
    unsigned un = (unsigned)((((lx - ux) >> 7) << 10) | (((ly - uy) >> 7) << 5) | ((lz - uz) >> 7));
    b[upper + 4128 + 4 * (un >> 5) + ((un & 31) >> 3)] |= (unsigned char)(1u << (un & 7));
    nvdbw_u64(b + upper + 8256 + 8 * un, lower - upper);
    /* lower: one entry per leaf */
    nvdbw_u32(b + lower, (uint32_t)lx);
    nvdbw_u32(b + lower + 4, (uint32_t)ly);
    nvdbw_u32(b + lower + 8, (uint32_t)lz);
    for (unsigned n = 0; n < 4096; n++) {
        if (!leaf_used[n]) continue;
        size_t leaf = leaves + (size_t)(leaf_used[n] - 1) * 2144;
        b[lower + 544 + 4 * (n >> 5) + ((n & 31) >> 3)] |= (unsigned char)(1u << (n & 7));
        nvdbw_u64(b + lower + 1088 + 8 * n, leaf - lower);
        nvdbw_u32(b + leaf, (uint32_t)(lx + (int)((n >> 8) & 15) * 8));
        nvdbw_u32(b + leaf + 4, (uint32_t)(ly + (int)((n >> 4) & 15) * 8));
        nvdbw_u32(b + leaf + 8, (uint32_t)(lz + (int)(n & 15) * 8));
    }
    for (int z = 0; z < g->nz; z++)
        for (int y = 0; y < g->ny; y++)
            for (int x = 0; x < g->nx; x++) {
                int i = g->ox + x - lx, j = g->oy + y - ly, k = g->oz + z - lz;
                unsigned n = (unsigned)(((i >> 3) << 8) | ((j >> 3) << 4) | (k >> 3));
                size_t leaf = leaves + (size_t)(leaf_used[n] - 1) * 2144;
                unsigned v = (unsigned)(((i & 7) << 6) | ((j & 7) << 3) | (k & 7));
                b[leaf + 16 + (v >> 3)] |= (unsigned char)(1u << (v & 7));   /* active */
                nvdbw_f32(b + leaf + 96 + 4 * v, g->values[((size_t)z * g->ny + y) * g->nx + x]);
            }
    *len = size;
    return b;
}

/* A whole file of `n` grids in one segment, codec 0 (none) or 1 (ZIP); malloc'd. */
static unsigned char *nvdb_write(const NvdbGrid *grids, int n, unsigned codec, size_t *len)
{
    unsigned char *blob[8];
    size_t blen[8], stored[8], total = 16;
    if (n > 8) return NULL;
    for (int i = 0; i < n; i++) {
        size_t raw;
        unsigned char *g = nvdbw_grid(&grids[i], &raw);
        if (!g) return NULL;
        blen[i] = raw;
        if (codec == 1) {
            uLongf c = compressBound((uLong)raw);
            unsigned char *z = malloc(8 + c);
            if (!z || compress(z + 8, &c, g, (uLong)raw) != Z_OK) abort();
            nvdbw_u64(z, c);
            free(g);
            blob[i] = z;
            stored[i] = 8 + c;
        } else {
            blob[i] = g;
            stored[i] = raw;
        }
        total += 176 + strlen(grids[i].name) + 1 + stored[i];
    }
    unsigned char *f = calloc(1, total);
    if (!f) return NULL;
    nvdbw_u64(f, 0x304244566f6e614eull);   /* "NanoVDB0", as the grid's */
    nvdbw_u32(f + 8, NVDBW_VERSION);
    nvdbw_u16(f + 12, (uint16_t)n);
    nvdbw_u16(f + 14, (uint16_t)codec);
    size_t at = 16;
    for (int i = 0; i < n; i++) {
        const NvdbGrid *g = &grids[i];
        unsigned char *m = f + at;
        nvdbw_u64(m, blen[i]);
        nvdbw_u64(m + 8, stored[i]);
        nvdbw_u64(m + 16, nvdbw_name_key(g->name));
        nvdbw_u64(m + 24, (uint64_t)g->nx * g->ny * g->nz);
        nvdbw_u32(m + 32, g->type ? g->type : 1u);
        nvdbw_u32(m + 36, g->cls ? g->cls : 2u);
        int lo[3] = { g->ox, g->oy, g->oz }, hi[3] = { g->ox + g->nx - 1, g->oy + g->ny - 1, g->oz + g->nz - 1 };
        for (int a = 0; a < 3; a++) {
            nvdbw_f64(m + 40 + 8 * a, g->offset[a] + g->voxel[a] * lo[a]);
            nvdbw_f64(m + 64 + 8 * a, g->offset[a] + g->voxel[a] * (hi[a] + 1));
            nvdbw_u32(m + 88 + 4 * a, (uint32_t)lo[a]);
            nvdbw_u32(m + 100 + 4 * a, (uint32_t)hi[a]);
            nvdbw_f64(m + 112 + 8 * a, g->voxel[a]);
        }
        nvdbw_u32(m + 136, (uint32_t)strlen(g->name) + 1);
        nvdbw_u16(m + 168, (uint16_t)codec);
        nvdbw_u32(m + 172, NVDBW_VERSION);
        memcpy(m + 176, g->name, strlen(g->name) + 1);
        at += 176 + strlen(g->name) + 1;
    }
    for (int i = 0; i < n; i++) {
        memcpy(f + at, blob[i], stored[i]);
        at += stored[i];
        free(blob[i]);
    }
    *len = total;
    return f;
}

#endif /* CLPT_NVDB_WRITER_H */
