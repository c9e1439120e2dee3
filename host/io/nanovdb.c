/*
 * nanovdb.c — a NanoVDB file's float grid, resampled into a dense grid (nanovdb.h).
 *
 * The layout, as NanoVDB's headers document it (ABI 32; all little-endian):
 *   file     segments, each a 16-byte header (magic "NanoVDB0" or "NanoVDB2", version,
 *            grid count, codec), then per grid 176 bytes of metadata and its name, then
 *            the grids' data in the same order (each the size its metadata gives)
 *   grid     GridData (672 bytes: magic, version, ..., the index-to-world map at 296,
 *            class at 632, type at 636), then TreeData (64 bytes: byte offsets of the
 *            first leaf, lower, upper and root node from the tree)
 *   root     bbox of the active voxels (6 int32), tile count, background; then tiles
 *            of 32 bytes: key (the tile's origin >> 12, 21 bits an axis), child offset
 *            from the root (0: a constant tile of 4096^3 voxels), state, value
 *   upper    32^3 entries (each 128^3 voxels): masks, then a table of 8-byte
 *            entries, a value or a child offset from the node, by the child mask
 *   lower    16^3 entries of 8^3 voxels, the same way
 *   leaf     8^3 float values after an 80-byte head and 16 bytes of statistics
 * Entries are ordered x slowest, z fastest (n = x << 2L | y << L | z).
 *
 * Every offset read from the file is checked against the buffer before it is followed,
 * and the nodes visited are counted against what the buffer can hold, so a file whose
 * offsets share or cycle nodes cannot make the work grow beyond its size.
 */
#include "io/nanovdb.h"

#include "base/limit.h"

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#define MAGIC_NUMB 0x304244566f6e614eull   /* "NanoVDB0": file or grid, older writers */
#define MAGIC_GRID 0x314244566f6e614eull   /* "NanoVDB1": a grid */
#define MAGIC_FILE 0x324244566f6e614eull   /* "NanoVDB2": a file */
#define ABI_MAJOR 32u

#define FILE_HEADER 16u
#define FILE_META 176u
#define GRID_DATA 672u
#define TREE_DATA 64u
#define GRID_OFF_MAP 296u
#define MAP_OFF_MATD 88u
#define MAP_OFF_VECD 232u
#define GRID_OFF_CLASS 632u
#define GRID_OFF_TYPE 636u
#define GRID_TYPE_FLOAT 1u
#define TREE_OFF_ROOT 24u
/* sizes and offsets of a float tree's nodes (PNanoVDB's table for GridType Float) */
#define ROOT_SIZE 64u
#define ROOT_OFF_BACKGROUND 28u
#define TILE_SIZE 32u
#define TILE_OFF_VALUE 20u
#define UPPER_OFF_CHILD_MASK 4128u
#define UPPER_OFF_TABLE 8256u
#define UPPER_SIZE 270400u
#define LOWER_OFF_CHILD_MASK 544u
#define LOWER_OFF_TABLE 1088u
#define LOWER_SIZE 33856u
#define LEAF_OFF_TABLE 96u
#define LEAF_SIZE 2144u

static uint16_t rd16(const unsigned char *p) { uint16_t v; memcpy(&v, p, 2); return v; }
static uint32_t rd32(const unsigned char *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static uint64_t rd64(const unsigned char *p) { uint64_t v; memcpy(&v, p, 8); return v; }
static float rdf(const unsigned char *p) { float v; memcpy(&v, p, 4); return v; }
static double rdd(const unsigned char *p) { double v; memcpy(&v, p, 8); return v; }

/* One grid of the file, as its metadata gives it. */
typedef struct {
    size_t at;             /* its data's first byte in the file */
    uint64_t file_size;    /* bytes in the file (compressed or not) */
    uint64_t grid_size;    /* bytes once read */
    unsigned codec;
} GridRef;

static int name_is(const unsigned char *name, uint32_t size, const char *want)
{
    size_t n = strlen(want);
    size_t len = 0;
    while (len < size && name[len]) len++;
    return len == n && memcmp(name, want, n) == 0;
}

/* Walks the segments; *found set when a grid named `name` is found (the first). The
 * names seen go to `names` (for the message when none matches). */
static Status find_grid(const char *path, const unsigned char *d, size_t len, const char *name, GridRef *ref,
                        int *found, char *names, size_t names_cap, Error *err)
{
    size_t pos = 0;
    *found = 0;
    if (names_cap) names[0] = '\0';
    while (pos < len) {
        if (len - pos < FILE_HEADER)
            return error_set(err, ST_INPUT, "%s: byte %zu: a segment header needs 16 bytes, %zu are left", path, pos,
                             len - pos);
        uint64_t magic = rd64(d + pos);
        if (magic != MAGIC_NUMB && magic != MAGIC_FILE) {
            if (pos == 0 && magic == MAGIC_GRID)
                return error_set(err, ST_INPUT, "%s: a raw NanoVDB grid buffer (\"NanoVDB1\"), not a .nvdb file with "
                                 "metadata", path);
            if (pos == 0)
                return error_set(err, ST_INPUT, "%s: not a NanoVDB file (it does not start with \"NanoVDB0\" or "
                                 "\"NanoVDB2\")", path);
            return error_set(err, ST_INPUT, "%s: byte %zu: expected the next segment's \"NanoVDB0\" or \"NanoVDB2\"",
                             path, pos);
        }
        uint32_t version = rd32(d + pos + 8);
        if ((version >> 21) != ABI_MAJOR)
            return error_set(err, ST_INPUT, "%s: NanoVDB version %u.%u.%u; clpt reads version 32 files", path,
                             version >> 21, (version >> 10) & 2047u, version & 1023u);
        unsigned count = rd16(d + pos + 12), codec = rd16(d + pos + 14);
        if (codec > 2u)
            return error_set(err, ST_INPUT, "%s: byte %zu: unknown codec %u (0 none, 1 ZIP, 2 BLOSC)", path, pos + 14,
                             codec);
        pos += FILE_HEADER;
        size_t meta = pos;
        for (unsigned i = 0; i < count; i++) {
            if (len - pos < FILE_META)
                return error_set(err, ST_INPUT, "%s: byte %zu: grid %u's metadata needs 176 bytes, %zu are left",
                                 path, pos, i, len - pos);
            uint32_t name_size = rd32(d + pos + 136);
            if (name_size > len - pos - FILE_META)
                return error_set(err, ST_INPUT, "%s: byte %zu: grid %u's name of %" PRIu32 " bytes runs past the end "
                                 "of the file", path, pos + 136, i, name_size);
            pos += FILE_META + name_size;
        }
        for (unsigned i = 0; i < count; i++) {
            uint32_t name_size = rd32(d + meta + 136);
            const unsigned char *gname = d + meta + FILE_META;
            uint64_t file_size = rd64(d + meta + 8), grid_size = rd64(d + meta);
            if (file_size > len - pos)
                return error_set(err, ST_INPUT, "%s: byte %zu: grid %u claims %" PRIu64 " bytes of data, but the file "
                                 "has %zu left", path, meta + 8, i, file_size, len - pos);
            if (names_cap) {
                size_t used = strlen(names), nlen = 0;
                while (nlen < name_size && gname[nlen]) nlen++;
                if (nlen > 40) nlen = 40;
                if (used + nlen + 5 < names_cap)
                    snprintf(names + used, names_cap - used, "%s\"%.*s\"", used ? ", " : "", (int)nlen,
                             (const char *)gname);
            }
            if (!*found && name_is(gname, name_size, name)) {
                *found = 1;
                ref->at = pos;
                ref->file_size = file_size;
                ref->grid_size = grid_size;
                ref->codec = codec;
            }
            pos += (size_t)file_size;
            meta += FILE_META + name_size;
        }
    }
    return ST_OK;
}

int nanovdb_has_grid(const unsigned char *data, size_t len, const char *grid_name)
{
    GridRef ref;
    int found = 0;
    Error err = { 0 };
    Status st = find_grid("", data, len, grid_name, &ref, &found, NULL, 0, &err);
    error_clear(&err);
    return st == ST_OK && found;
}

/* The grid's bytes: in the file (codec none) or inflated into *owned (ZIP). */
static Status grid_bytes(const char *path, const char *name, const unsigned char *d, const GridRef *ref,
                         const unsigned char **buf, size_t *blen, unsigned char **owned, Error *err)
{
    *owned = NULL;
    if (ref->codec == 2u)
        return error_set(err, ST_INPUT, "%s: grid \"%s\" is BLOSC-compressed, which clpt does not read (write the "
                         "file uncompressed or with ZIP)", path, name);
    if (ref->grid_size > CLPT_MAX_FILE_BYTES)
        return error_set(err, ST_INPUT, "%s: grid \"%s\" claims %" PRIu64 " bytes, more than the %" PRIu64 " clpt "
                         "reads", path, name, ref->grid_size, (uint64_t)CLPT_MAX_FILE_BYTES);
    if (ref->codec == 0u) {
        if (ref->grid_size > ref->file_size)
            return error_set(err, ST_INPUT, "%s: grid \"%s\" claims %" PRIu64 " bytes but stores %" PRIu64
                             " uncompressed", path, name, ref->grid_size, ref->file_size);
        *buf = d + ref->at;
        *blen = (size_t)ref->grid_size;
        return ST_OK;
    }
    /* ZIP: the compressed size (8 bytes), then a zlib stream of grid_size bytes */
    if (ref->file_size < 8u)
        return error_set(err, ST_INPUT, "%s: byte %zu: grid \"%s\" is ZIP-compressed but holds no compressed size",
                         path, ref->at, name);
    uint64_t csize = rd64(d + ref->at);
    if (csize > ref->file_size - 8u)
        return error_set(err, ST_INPUT, "%s: byte %zu: grid \"%s\" claims %" PRIu64 " compressed bytes, but stores %"
                         PRIu64, path, ref->at, name, csize, ref->file_size - 8u);
    /* deflate expands at most about 1032:1; a larger claim cannot be true, so nothing
     * is allocated for it */
    if (ref->grid_size > csize * 1032u + 64u)
        return error_set(err, ST_INPUT, "%s: grid \"%s\" claims to inflate %" PRIu64 " bytes to %" PRIu64
                         ", more than deflate can (1032:1)", path, name, csize, ref->grid_size);
    unsigned char *out = malloc(ref->grid_size ? (size_t)ref->grid_size : 1u);
    if (!out) return error_set(err, ST_INTERNAL, "out of memory for NanoVDB grid \"%s\"", name);
    uLongf got = (uLongf)ref->grid_size;
    int zs = uncompress(out, &got, d + ref->at + 8, (uLong)csize);
    if (zs != Z_OK || got != ref->grid_size) {
        free(out);
        return error_set(err, ST_INPUT, "%s: grid \"%s\": its ZIP data does not inflate to the %" PRIu64 " bytes it "
                         "claims (%s)", path, name, ref->grid_size, zs == Z_OK ? "a different size" : zError(zs));
    }
    *owned = out;
    *buf = out;
    *blen = (size_t)ref->grid_size;
    return ST_OK;
}

/* The walk over one grid's tree into the dense grid. */
typedef struct {
    const char *path, *name;
    const unsigned char *b;
    size_t blen;
    float background;
    int64_t lo[3], hi[3];          /* active box, inclusive */
    unsigned k;                    /* voxels per cell along an axis */
    unsigned n[3];
    float *delta;                  /* per cell: sum of (value - background) */
    uint64_t uppers, lowers, leaves, tile_cells;
    Error *err;
} Walk;

static int overlaps(const Walk *w, const int64_t o[3], int64_t size)
{
    for (int a = 0; a < 3; a++)
        if (o[a] > w->hi[a] || o[a] + size - 1 < w->lo[a]) return 0;
    return 1;
}

/* A constant tile of size^3 voxels at o: its value, times the voxels each cell shares
 * with it. Bounded: the tiles may touch at most 4 x NANOVDB_MAX_CELLS cells in all. */
static Status add_tile(Walk *w, const int64_t o[3], int64_t size, float v)
{
    if (v == w->background || !overlaps(w, o, size)) return ST_OK;
    if (!(v >= 0.0f) || !isfinite(v))
        return error_set(w->err, ST_INPUT, "%s: grid \"%s\": a tile at voxel (%" PRId64 ", %" PRId64 ", %" PRId64
                         ") has the value %g; a density or temperature must be finite and >= 0", w->path, w->name,
                         o[0], o[1], o[2], (double)v);
    int64_t c0[3], c1[3];
    for (int a = 0; a < 3; a++) {
        int64_t s = o[a] > w->lo[a] ? o[a] : w->lo[a], e = o[a] + size - 1 < w->hi[a] ? o[a] + size - 1 : w->hi[a];
        c0[a] = (s - w->lo[a]) / w->k;
        c1[a] = (e - w->lo[a]) / w->k;
    }
    uint64_t cells = (uint64_t)(c1[0] - c0[0] + 1) * (uint64_t)(c1[1] - c0[1] + 1) * (uint64_t)(c1[2] - c0[2] + 1);
    w->tile_cells += cells;
    if (w->tile_cells > 4ull * NANOVDB_MAX_CELLS)
        return error_set(w->err, ST_INPUT, "%s: grid \"%s\": its constant tiles cover the dense grid more than 4 times "
                         "over; the file is malformed", w->path, w->name);
    for (int64_t z = c0[2]; z <= c1[2]; z++)
        for (int64_t y = c0[1]; y <= c1[1]; y++)
            for (int64_t x = c0[0]; x <= c1[0]; x++) {
                /* voxels of this cell inside the tile and the active box */
                int64_t c[3] = { x, y, z }, shared = 1;
                for (int a = 0; a < 3; a++) {
                    int64_t s = w->lo[a] + c[a] * w->k, e = s + w->k - 1;
                    if (s < o[a]) s = o[a];
                    if (e > o[a] + size - 1) e = o[a] + size - 1;
                    if (e > w->hi[a]) e = w->hi[a];
                    shared *= e - s + 1;
                }
                w->delta[((size_t)z * w->n[1] + (size_t)y) * w->n[0] + (size_t)x] +=
                    (float)((double)(v - w->background) * (double)shared);
            }
    return ST_OK;
}

/* A child `off` bytes from the node at `node`, of `size` bytes, inside the buffer. */
static Status child_at(Walk *w, size_t node, int64_t off, size_t size, const char *what, size_t *child)
{
    int64_t at = (int64_t)node + off;
    if (off == 0 || at < 0 || (uint64_t)at > w->blen || w->blen - (size_t)at < size)
        return error_set(w->err, ST_INPUT, "%s: grid \"%s\": the node at byte %zu of the grid points to %s at offset %" PRId64
                         ", outside the grid's %zu bytes", w->path, w->name, node, what, off, w->blen);
    *child = (size_t)at;
    return ST_OK;
}

static Status visit_leaf(Walk *w, size_t leaf, const int64_t o[3])
{
    if (++w->leaves > w->blen / LEAF_SIZE)
        return error_set(w->err, ST_INPUT, "%s: grid \"%s\": its tree reaches more leaf nodes than its %zu bytes hold",
                         w->path, w->name, w->blen);
    const unsigned char *vals = w->b + leaf + LEAF_OFF_TABLE;
    for (unsigned n = 0; n < 512u; n++) {
        int64_t p[3] = { o[0] + (n >> 6), o[1] + ((n >> 3) & 7u), o[2] + (n & 7u) };
        if (p[0] < w->lo[0] || p[0] > w->hi[0] || p[1] < w->lo[1] || p[1] > w->hi[1] || p[2] < w->lo[2] ||
            p[2] > w->hi[2])
            continue;
        float v = rdf(vals + 4u * n);
        if (!(v >= 0.0f) || !isfinite(v))
            return error_set(w->err, ST_INPUT, "%s: grid \"%s\": voxel (%" PRId64 ", %" PRId64 ", %" PRId64 ") has "
                             "the value %g; a density or temperature must be finite and >= 0", w->path, w->name,
                             p[0], p[1], p[2], (double)v);
        size_t x = (size_t)((p[0] - w->lo[0]) / w->k), y = (size_t)((p[1] - w->lo[1]) / w->k),
               z = (size_t)((p[2] - w->lo[2]) / w->k);
        w->delta[(z * w->n[1] + y) * w->n[0] + x] += v - w->background;
    }
    return ST_OK;
}

static Status visit_lower(Walk *w, size_t lower, const int64_t o[3])
{
    if (++w->lowers > w->blen / LOWER_SIZE)
        return error_set(w->err, ST_INPUT, "%s: grid \"%s\": its tree reaches more lower nodes than its %zu bytes "
                         "hold", w->path, w->name, w->blen);
    Status st;
    for (unsigned n = 0; n < 4096u; n++) {
        int64_t c[3] = { o[0] + ((n >> 8) & 15u) * 8, o[1] + ((n >> 4) & 15u) * 8, o[2] + (n & 15u) * 8 };
        if (!overlaps(w, c, 8)) continue;
        const unsigned char *entry = w->b + lower + LOWER_OFF_TABLE + 8u * n;
        if ((rd32(w->b + lower + LOWER_OFF_CHILD_MASK + 4u * (n >> 5)) >> (n & 31u)) & 1u) {
            size_t leaf;
            if ((st = child_at(w, lower, (int64_t)rd64(entry), LEAF_SIZE, "a leaf node", &leaf)) ||
                (st = visit_leaf(w, leaf, c)))
                return st;
        } else if ((st = add_tile(w, c, 8, rdf(entry)))) {
            return st;
        }
    }
    return ST_OK;
}

static Status visit_upper(Walk *w, size_t upper, const int64_t o[3])
{
    if (++w->uppers > w->blen / UPPER_SIZE)
        return error_set(w->err, ST_INPUT, "%s: grid \"%s\": its tree reaches more upper nodes than its %zu bytes "
                         "hold", w->path, w->name, w->blen);
    Status st;
    for (unsigned n = 0; n < 32768u; n++) {
        int64_t c[3] = { o[0] + ((n >> 10) & 31u) * 128, o[1] + ((n >> 5) & 31u) * 128, o[2] + (n & 31u) * 128 };
        if (!overlaps(w, c, 128)) continue;
        const unsigned char *entry = w->b + upper + UPPER_OFF_TABLE + 8u * n;
        if ((rd32(w->b + upper + UPPER_OFF_CHILD_MASK + 4u * (n >> 5)) >> (n & 31u)) & 1u) {
            size_t lower;
            if ((st = child_at(w, upper, (int64_t)rd64(entry), LOWER_SIZE, "a lower node", &lower)) ||
                (st = visit_lower(w, lower, c)))
                return st;
        } else if ((st = add_tile(w, c, 128, rdf(entry)))) {
            return st;
        }
    }
    return ST_OK;
}

/* A root key's tile origin: 21 bits an axis of the coordinate >> 12 (x highest). */
static int64_t key_axis(uint64_t key, unsigned shift)
{
    uint32_t u = (uint32_t)(((key >> shift) & 0x1fffffu) << 12);
    return (int64_t)(int32_t)u;
}

/* The smallest k for which the box, k^3 voxels a cell, fits NANOVDB_MAX_CELLS. */
static unsigned cell_stride(const int64_t ext[3])
{
    double voxels = (double)ext[0] * (double)ext[1] * (double)ext[2];
    unsigned k = 1;
    if (voxels > NANOVDB_MAX_CELLS) k = (unsigned)floor(cbrt(voxels / NANOVDB_MAX_CELLS));
    if (k < 1) k = 1;
    for (;; k++) {
        double cells = 1.0;
        for (int a = 0; a < 3; a++) cells *= (double)((ext[a] + k - 1) / k);
        if (cells <= NANOVDB_MAX_CELLS) return k;
    }
}

static const char *type_name(uint32_t t)
{
    static const char *names[] = { "unknown", "float", "double", "int16", "int32", "int64", "vec3f", "vec3d", "mask",
                                   "half", "uint32", "boolean", "rgba8", "fp4", "fp8", "fp16", "fpn", "vec4f",
                                   "vec4d" };
    return t < sizeof names / sizeof names[0] ? names[t] : "another";
}

Status nanovdb_read_grid(const char *path, const unsigned char *data, size_t len, const char *grid_name,
                         NanoDense *out, Error *err)
{
    memset(out, 0, sizeof *out);
    GridRef ref;
    int found;
    char names[200];
    Status st = find_grid(path, data, len, grid_name, &ref, &found, names, sizeof names, err);
    if (st) return st;
    if (!found)
        return error_set(err, ST_INPUT, "%s: no grid named \"%s\" (the file has %s)", path, grid_name,
                         names[0] ? names : "no grids");
    const unsigned char *b = NULL;
    size_t blen = 0;
    unsigned char *owned = NULL;
    if ((st = grid_bytes(path, grid_name, data, &ref, &b, &blen, &owned, err))) return st;
    const char *name = grid_name;
    float *delta = NULL;
    if (blen < GRID_DATA + TREE_DATA + ROOT_SIZE) {
        st = error_set(err, ST_INPUT, "%s: grid \"%s\" has %zu bytes, fewer than a grid header, tree and root (800)",
                       path, name, blen);
        goto done;
    }
    uint64_t magic = rd64(b);
    if (magic != MAGIC_NUMB && magic != MAGIC_GRID) {
        st = error_set(err, ST_INPUT, "%s: byte %zu: grid \"%s\" does not start with \"NanoVDB0\" or \"NanoVDB1\"",
                       path, ref.at, name);
        goto done;
    }
    uint32_t version = rd32(b + 16);
    if ((version >> 21) != ABI_MAJOR) {
        st = error_set(err, ST_INPUT, "%s: grid \"%s\" is NanoVDB version %u.%u.%u; clpt reads version 32", path,
                       name, version >> 21, (version >> 10) & 2047u, version & 1023u);
        goto done;
    }
    uint32_t type = rd32(b + GRID_OFF_TYPE), cls = rd32(b + GRID_OFF_CLASS);
    if (type != GRID_TYPE_FLOAT) {
        st = error_set(err, ST_INPUT, "%s: grid \"%s\" holds %s values (type %" PRIu32 "); clpt reads float grids",
                       path, name, type_name(type), type);
        goto done;
    }
    if (cls != 0u && cls != 2u) {   /* pbrt-v4 takes fog volumes and grids of unknown class */
        st = error_set(err, ST_INPUT, "%s: grid \"%s\" is of class %" PRIu32 "%s, not a fog volume (2)", path, name,
                       cls, cls == 1u ? " (a level set)" : "");
        goto done;
    }
    /* the map: world = M index + v (row-major M, double precision) */
    Transform xf;
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) xf.m[r][c] = rdd(b + GRID_OFF_MAP + MAP_OFF_MATD + 8u * (3u * r + c));
        xf.m[r][3] = rdd(b + GRID_OFF_MAP + MAP_OFF_VECD + 8u * r);
    }
    double det = transform_det(&xf);
    int finite = 1;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) finite &= isfinite(xf.m[r][c]) && fabs(xf.m[r][c]) < 1e30;
    if (!finite || !(fabs(det) > 1e-30)) {
        st = error_set(err, ST_INPUT, "%s: grid \"%s\": its index-to-world map is not an invertible finite affine "
                       "map (determinant %g)", path, name, det);
        goto done;
    }
    uint64_t root_off = rd64(b + GRID_DATA + TREE_OFF_ROOT);
    if (root_off > blen - GRID_DATA || blen - GRID_DATA - root_off < ROOT_SIZE) {
        st = error_set(err, ST_INPUT, "%s: grid \"%s\": its root node at offset %" PRIu64 " from the tree lies "
                       "outside the grid's %zu bytes", path, name, root_off, blen);
        goto done;
    }
    size_t root = GRID_DATA + (size_t)root_off;
    uint32_t tiles = rd32(b + root + 24);
    if ((uint64_t)tiles * TILE_SIZE > blen - root - ROOT_SIZE) {
        st = error_set(err, ST_INPUT, "%s: grid \"%s\": its root claims %" PRIu32 " tiles, more than the grid's %zu "
                       "bytes hold", path, name, tiles, blen);
        goto done;
    }
    Walk w;
    memset(&w, 0, sizeof w);
    w.path = path;
    w.name = name;
    w.b = b;
    w.blen = blen;
    w.err = err;
    w.background = rdf(b + root + ROOT_OFF_BACKGROUND);
    if (!(w.background >= 0.0f) || !isfinite(w.background)) {
        st = error_set(err, ST_INPUT, "%s: grid \"%s\": its background value %g is not a density or temperature (finite, >= 0)",
                       path, name, (double)w.background);
        goto done;
    }
    int64_t ext[3];
    for (int a = 0; a < 3; a++) {
        w.lo[a] = (int32_t)rd32(b + root + 4u * a);
        w.hi[a] = (int32_t)rd32(b + root + 12u + 4u * a);
        ext[a] = w.hi[a] - w.lo[a] + 1;
    }
    if (ext[0] < 1 || ext[1] < 1 || ext[2] < 1) {
        st = error_set(err, ST_INPUT, "%s: grid \"%s\" has no active voxels (its bounding box is empty)", path, name);
        goto done;
    }
    w.k = cell_stride(ext);
    for (int a = 0; a < 3; a++) w.n[a] = (unsigned)((ext[a] + w.k - 1) / w.k);
    size_t cells = (size_t)w.n[0] * w.n[1] * w.n[2];   /* <= NANOVDB_MAX_CELLS (cell_stride) */
    delta = calloc(cells, sizeof(float));
    if (!delta) {
        st = error_set(err, ST_INTERNAL, "out of memory for NanoVDB grid \"%s\" (%zu cells)", name, cells);
        goto done;
    }
    w.delta = delta;
    for (uint32_t t = 0; t < tiles; t++) {
        const unsigned char *tile = b + root + ROOT_SIZE + (size_t)t * TILE_SIZE;
        uint64_t key = rd64(tile);
        int64_t o[3] = { key_axis(key, 42), key_axis(key, 21), key_axis(key, 0) };
        int64_t child = (int64_t)rd64(tile + 8);
        if (child == 0) {
            if ((st = add_tile(&w, o, 4096, rdf(tile + TILE_OFF_VALUE)))) goto done;
        } else if (overlaps(&w, o, 4096)) {
            size_t upper;
            if ((st = child_at(&w, root, child, UPPER_SIZE, "an upper node", &upper)) ||
                (st = visit_upper(&w, upper, o)))
                goto done;
        }
    }
    /* mean over each cell's voxels inside the active box */
    for (unsigned z = 0; z < w.n[2]; z++)
        for (unsigned y = 0; y < w.n[1]; y++)
            for (unsigned x = 0; x < w.n[0]; x++) {
                unsigned c[3] = { x, y, z };
                double voxels = 1.0;
                for (int a = 0; a < 3; a++) {
                    int64_t s = (int64_t)c[a] * w.k, e = s + w.k;
                    if (e > ext[a]) e = ext[a];
                    voxels *= (double)(e - s);
                }
                float *v = &delta[((size_t)z * w.n[1] + y) * w.n[0] + x];
                double mean = (double)w.background + (double)*v / voxels;
                *v = mean > 0.0 ? (float)mean : 0.0f;   /* rounding may dip below 0 */
            }
    out->density = delta;
    delta = NULL;
    out->nx = w.n[0];
    out->ny = w.n[1];
    out->nz = w.n[2];
    out->stride = w.k;
    for (int a = 0; a < 3; a++) {
        out->bbox_min[a] = w.lo[a];
        out->bbox_max[a] = w.hi[a];
        /* voxel i's value sits at index i (NanoVDB's trilinear sampler); clpt's
         * samples sit at cell centres, so the box starts half a voxel before (a
         * resampled cell's mean sits at the centre of its k voxels likewise) */
        out->lo[a] = (double)w.lo[a] - 0.5;
        out->hi[a] = (double)w.lo[a] - 0.5 + (double)w.k * w.n[a];
    }
    out->index_to_world = xf;
    st = ST_OK;
done:
    free(delta);
    free(owned);
    return st;
}
