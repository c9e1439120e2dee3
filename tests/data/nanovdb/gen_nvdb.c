/*
 * gen_nvdb.c — writes the NanoVDB files of the tests, the fuzz seeds and the example
 * scene with tests/nvdb_writer.h; run from the repository root, the output is committed:
 *     cc -Itests -O2 -o /tmp/gen_nvdb tests/data/nanovdb/gen_nvdb.c -lz -lm && /tmp/gen_nvdb
 * ramp.nvdb        a 6x5x4 float grid ("density") at index (8, 16, 130), voxels 0.5
 *                  wide, offset (1, 2, 3); value x + 10 y + 100 z (the voxel's place)
 * ramp-zip.nvdb    the same ZIP-compressed, with a "temperature" grid after it
 * scenes/nanovdb-smoke.nvdb  a 48^3 ball of smoke, ZIP (scenes/nanovdb-smoke.pbrt)
 * tests/data/bad/nvdb-*.nvdb[.gz]  ramp.nvdb broken one way each (test_nanovdb.c)
 */
#include "nvdb_writer.h"

#include <math.h>
#include <stdio.h>

static void save(const char *path, const unsigned char *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(b, 1, n, f) != n || fclose(f)) {
        perror(path);
        exit(1);
    }
}

/* Written gzipped (the reader inflates a .gz file as it reads it): the broken copies are
 * 300 KB of mostly zeros each. */
static void save_gz(const char *path, const unsigned char *b, size_t n)
{
    gzFile f = gzopen(path, "wb9");
    if (!f || gzwrite(f, b, (unsigned)n) != (int)n || gzclose(f) != Z_OK) {
        perror(path);
        exit(1);
    }
}

int main(void)
{
    float ramp[6 * 5 * 4];
    for (int z = 0; z < 4; z++)
        for (int y = 0; y < 5; y++)
            for (int x = 0; x < 6; x++) ramp[(z * 5 + y) * 6 + x] = (float)(x + 10 * y + 100 * z);
    NvdbGrid g = { "density", 8, 16, 130, 6, 5, 4, ramp, { 0.5, 0.5, 0.5 }, { 1, 2, 3 }, 0, 0 };
    size_t n;
    unsigned char *f = nvdb_write(&g, 1, 0, &n);
    save("tests/data/nanovdb/ramp.nvdb", f, n);

    /* broken copies: the grid's data starts at 16 + 176 + 8 = 200 */
    const size_t grid = 200, root = grid + 736;
    unsigned char *c = malloc(n);
    memcpy(c, f, n);
    memcpy(c, "NotNanoV", 8);
    save("tests/data/bad/nvdb-magic.nvdb", c, 8 + 100);
    save("tests/data/bad/nvdb-truncated.nvdb", f, 5000);
    memcpy(c, f, n);
    nvdbw_u32(c + 8, (29u << 21) | (3u << 10));
    save_gz("tests/data/bad/nvdb-version.nvdb.gz", c, n);
    memcpy(c, f, n);
    nvdbw_u16(c + 14, 2);
    save_gz("tests/data/bad/nvdb-blosc.nvdb.gz", c, n);
    memcpy(c, f, n);
    nvdbw_u32(c + 16 + 136, 0x7fffffffu);
    save_gz("tests/data/bad/nvdb-name-size.nvdb.gz", c, n);
    memcpy(c, f, n);
    nvdbw_u32(c + grid + 636, 2u);   /* double values */
    save_gz("tests/data/bad/nvdb-type.nvdb.gz", c, n);
    memcpy(c, f, n);
    nvdbw_u64(c + root + 64 + 8, 1ull << 40);   /* the root tile's child */
    save_gz("tests/data/bad/nvdb-offset.nvdb.gz", c, n);
    memcpy(c, f, n);
    nvdbw_u64(c + 16, n);   /* grid size larger than the data stored */
    save_gz("tests/data/bad/nvdb-grid-size.nvdb.gz", c, n);
    memcpy(c, f, n);
    nvdbw_f32(c + grid + 736 + 832 - 736 + 270400 + 33856 + 96 + 4 * 2, -1.0f);   /* voxel (8, 16, 130): the first leaf's voxel 2 */
    save_gz("tests/data/bad/nvdb-negative.nvdb.gz", c, n);
    free(c);
    free(f);

    float temp[6 * 5 * 4];
    for (int i = 0; i < 120; i++) temp[i] = 1000.0f + (float)i;
    NvdbGrid two[2] = { g, { "temperature", 8, 16, 130, 6, 5, 4, temp, { 0.5, 0.5, 0.5 }, { 1, 2, 3 }, 0, 0 } };
    f = nvdb_write(two, 2, 1, &n);
    save("tests/data/nanovdb/ramp-zip.nvdb", f, n);
    free(f);

    /* a ball of smoke: denser toward the centre, with lumps (sums of sines) */
    static float ball[48 * 48 * 48];
    for (int z = 0; z < 48; z++)
        for (int y = 0; y < 48; y++)
            for (int x = 0; x < 48; x++) {
                double px = (x + 0.5) / 24 - 1, py = (y + 0.5) / 24 - 1, pz = (z + 0.5) / 24 - 1;
                double r = sqrt(px * px + py * py + pz * pz);
                double lumps = 0.5 + 0.25 * sin(9 * px + 2) * sin(7 * py + 1) * sin(8 * pz) +
                               0.25 * sin(17 * px + 13 * pz) * sin(15 * py - 3);
                double d = r < 1 ? (1 - r) * 2 * lumps : 0;
                ball[(z * 48 + y) * 48 + x] = d > 0 ? (float)d : 0.0f;
            }
    NvdbGrid smoke = { "density", 0, 0, 0, 48, 48, 48, ball, { 1.0 / 24, 1.0 / 24, 1.0 / 24 }, { -1, 0, -1 }, 0, 0 };
    f = nvdb_write(&smoke, 1, 1, &n);
    save("scenes/nanovdb-smoke.nvdb", f, n);
    free(f);
    return 0;
}
