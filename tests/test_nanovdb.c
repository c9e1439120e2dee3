/* test_nanovdb.c — the NanoVDB reader (host/io/nanovdb.c) on files written by
 * tests/nvdb_writer.h (tests/data/nanovdb/gen_nvdb.c), and pbrt-v4's media that clpt
 * makes into density grids (host/io/pbrt_volume.c): "nanovdb", "cloud", "rgbgrid". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "nvdb_writer.h"
#include "base/noise.h"
#include "io/lexer.h"
#include "io/nanovdb.h"
#include "io/pbrt_reader.h"
#include "io/scene_load.h"
#include "scene/scene.h"
#include "util/kmath.h"

#define NDIR "tests/data/nanovdb/"
#define BAD "tests/data/bad/"

static Status read_file_grid(const char *path, const char *name, NanoDense *d, Error *err)
{
    char *data;
    size_t len;
    Status st = lex_read_file(path, &data, &len, err);
    if (st) return st;
    st = nanovdb_read_grid(path, (const unsigned char *)data, len, name, d, err);
    free(data);
    return st;
}

static Status load_text(const char *text, Scene *s, Error *err)
{
    scene_init(s);
    return scene_load_bytes(NDIR "inline.pbrt", text, strlen(text), SCENE_FORMAT_AUTO, s, NULL, err);
}

/* ramp.nvdb: 6x5x4 voxels at index (8, 16, 130), value x + 10 y + 100 z of the voxel's
 * place in the block; voxels 0.5 wide, offset (1, 2, 3). */
static void check_ramp(const NanoDense *d)
{
    CHECK_EQ_INT(d->nx, 6);
    CHECK_EQ_INT(d->ny, 5);
    CHECK_EQ_INT(d->nz, 4);
    CHECK_EQ_INT(d->stride, 1);
    int bad = 0;
    for (int z = 0; z < 4; z++)
        for (int y = 0; y < 5; y++)
            for (int x = 0; x < 6; x++) bad += d->density[(z * 5 + y) * 6 + x] != (float)(x + 10 * y + 100 * z);
    CHECK_EQ_INT(bad, 0);
    CHECK_NEAR(d->lo[0], 7.5, 0);
    CHECK_NEAR(d->lo[2], 129.5, 0);
    CHECK_NEAR(d->hi[1], 20.5, 0);
    CHECK_NEAR(d->index_to_world.m[0][0], 0.5, 0);
    CHECK_NEAR(d->index_to_world.m[1][1], 0.5, 0);
    CHECK_NEAR(d->index_to_world.m[0][1], 0, 0);
    CHECK_NEAR(d->index_to_world.m[2][3], 3, 0);
    CHECK_EQ_INT((int)d->bbox_max[2], 133);
}

static void test_ramp(void)
{
    NanoDense d;
    Error err = { 0 };
    CHECK_EQ_INT(read_file_grid(NDIR "ramp.nvdb", "density", &d, &err), ST_OK);
    if (d.density) check_ramp(&d);
    free(d.density);
    /* ZIP, two grids */
    CHECK_EQ_INT(read_file_grid(NDIR "ramp-zip.nvdb", "density", &d, &err), ST_OK);
    if (d.density) check_ramp(&d);
    free(d.density);
    CHECK_EQ_INT(read_file_grid(NDIR "ramp-zip.nvdb", "temperature", &d, &err), ST_OK);
    if (d.density) {
        CHECK_NEAR(d.density[0], 1000, 0);
        CHECK_NEAR(d.density[119], 1119, 0);
    }
    free(d.density);
    CHECK_EQ_INT(read_file_grid(NDIR "ramp.nvdb", "smoke", &d, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "ramp.nvdb: no grid named \"smoke\" (the file has \"density\")") == 0, "got '%s'",
              err.msg);
    error_clear(&err);
}

/* A grid whose active box holds more than NANOVDB_MAX_CELLS voxels is resampled: each
 * cell the mean of k^3 voxels (background 0 where the file has none). */
static void test_resample(void)
{
    char *data;
    size_t len;
    Error err = { 0 };
    CHECK_EQ_INT(lex_read_file(NDIR "ramp.nvdb", &data, &len, &err), ST_OK);
    if (!data) return;
    /* the root's box max (grid at 200, root at 736 of it): 300 voxels an axis */
    int32_t hi[3] = { 8 + 299, 16 + 299, 130 + 299 };
    memcpy(data + 200 + 736 + 12, hi, sizeof hi);
    NanoDense d;
    CHECK_EQ_INT(nanovdb_read_grid("big", (const unsigned char *)data, len, "density", &d, &err), ST_OK);
    free(data);
    if (!d.density) return;
    CHECK_EQ_INT(d.stride, 2);
    CHECK_EQ_INT(d.nx, 150);
    CHECK_EQ_INT(d.nz, 150);
    CHECK((uint64_t)d.nx * d.ny * d.nz <= NANOVDB_MAX_CELLS);
    /* cell (0,0,0): voxels x 0..1, y 0..1, z 0..1 of the ramp: mean 0.5 + 5 + 50 */
    CHECK_NEAR(d.density[0], 55.5, 1e-4);
    /* cell (2, 2, 0): x 4..5, y 4..5 (y 5 is beyond the data: 0), z 0..1 */
    double want = 0;
    for (int z = 0; z < 2; z++)
        for (int x = 4; x < 6; x++) want += x + 40 + 100 * z;
    CHECK_NEAR(d.density[(0 * 150 + 2) * 150 + 2], want / 8, 1e-4);
    CHECK_NEAR(d.density[(100 * 150 + 100) * 150 + 100], 0, 0);
    CHECK_NEAR(d.hi[0] - d.lo[0], 300, 0);
    free(d.density);
}

static void expect_bad(const char *file, const char *msg)
{
    NanoDense d;
    Error err = { 0 };
    CHECK_EQ_INT(read_file_grid(file, "density", &d, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, msg) == 0, "got '%s', expected '%s'", err.msg, msg);
    CHECK(d.density == NULL);
    error_clear(&err);
}

static void test_bad_files(void)
{
    expect_bad(BAD "nvdb-magic.nvdb",
               BAD "nvdb-magic.nvdb: not a NanoVDB file (it does not start with \"NanoVDB0\" or \"NanoVDB2\")");
    expect_bad(BAD "nvdb-truncated.nvdb",
               BAD "nvdb-truncated.nvdb: byte 24: grid 0 claims 307232 bytes of data, but the file has 4800 left");
    expect_bad(BAD "nvdb-version.nvdb.gz",
               BAD "nvdb-version.nvdb.gz: NanoVDB version 29.3.0; clpt reads version 32 files");
    expect_bad(BAD "nvdb-blosc.nvdb.gz",
               BAD "nvdb-blosc.nvdb.gz: grid \"density\" is BLOSC-compressed, which clpt does not read (write the "
               "file uncompressed or with ZIP)");
    expect_bad(BAD "nvdb-name-size.nvdb.gz",
               BAD "nvdb-name-size.nvdb.gz: byte 152: grid 0's name of 2147483647 bytes runs past the end of the "
               "file");
    expect_bad(BAD "nvdb-type.nvdb.gz",
               BAD "nvdb-type.nvdb.gz: grid \"density\" holds double values (type 2); clpt reads float grids");
    expect_bad(BAD "nvdb-offset.nvdb.gz",
               BAD "nvdb-offset.nvdb.gz: grid \"density\": the node at byte 736 of the grid points to an upper node at "
               "offset 1099511627776, outside the grid's 307232 bytes");
    expect_bad(BAD "nvdb-grid-size.nvdb.gz",
               BAD "nvdb-grid-size.nvdb.gz: grid \"density\" claims 307432 bytes but stores 307232 uncompressed");
    expect_bad(BAD "nvdb-negative.nvdb.gz",
               BAD "nvdb-negative.nvdb.gz: grid \"density\": voxel (8, 16, 130) has the value -1; a density or "
               "temperature must be finite and >= 0");
    /* every prefix of a good file is refused with a message, never read past its end */
    char *data;
    size_t len;
    Error err = { 0 };
    CHECK_EQ_INT(lex_read_file(NDIR "ramp-zip.nvdb", &data, &len, &err), ST_OK);
    int quiet = 0;
    for (size_t n = 0; data && n < len; n++) {
        unsigned char *cut = malloc(n ? n : 1);
        memcpy(cut, data, n);
        NanoDense d;
        Status st = nanovdb_read_grid("cut", cut, n, "density", &d, &err);
        quiet += st != ST_INPUT || !err.msg[0];
        if (!st) free(d.density);
        error_clear(&err);
        free(cut);
    }
    CHECK_EQ_INT(quiet, 0);
    free(data);
}

/* MakeNamedMedium "nanovdb": the grid placed by its map and the current transform,
 * sigma_a, sigma_s times scale; the temperature grid (here on the density's voxels)
 * made kelvin by temperatureoffset and temperaturescale, its glow times Lescale. */
static void test_pbrt_nanovdb(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("Translate 10 0 0\n"
                           "MakeNamedMedium \"smoke\" \"string type\" \"nanovdb\" \"string filename\" \"ramp-zip.nvdb\"\n"
                           "  \"rgb sigma_a\" [0.5 0.5 0.5] \"rgb sigma_s\" [1 2 3] \"float scale\" 2 \"float Lescale\" 3\n"
                           "  \"float temperatureoffset\" 500 \"float temperaturescale\" 2\n"
                           "WorldBegin\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_media, 1);
    CHECK_EQ_INT(s.n_grids, 1);
    if (s.n_media == 1 && s.n_grids == 1) {
        CHECK_EQ_INT(s.media[0].type, MEDIUM_GRID);
        CHECK_NEAR(s.media[0].sigma_s.z, 6, 0);
        const GridMedium *g = &s.grids[0];
        CHECK_EQ_INT(g->nx, 6);
        CHECK_EQ_INT(g->ny, 5);
        CHECK_EQ_INT(g->nz, 4);
        /* voxel (8, 16, 130)'s value sits at world (10 + 1 + 4, 2 + 8, 3 + 65): the
         * centre of the first cell, (0.5/6, 0.5/5, 0.5/4) of the unit cube */
        const float *m = g->to_grid;
        double p[3] = { 15, 10, 68 }, want[3] = { 0.5 / 6, 0.5 / 5, 0.5 / 4 };
        for (int r = 0; r < 3; r++)
            CHECK_NEAR(m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3], want[r], 1e-5);
        CHECK_NEAR(s.grid_data[g->density_at + 7], 11, 0);   /* x 1, y 1 */
        /* the temperatures 1000 + i: kelvin (1000 + i - 500) 2 */
        CHECK(g->temperature_at != 0u);
        CHECK_NEAR(s.grid_data[g->temperature_at], 1000, 0);
        CHECK_NEAR(s.grid_data[g->temperature_at + 119], 1238, 0);
        CHECK_NEAR(s.media[0].emission.y, 3, 0);
        CHECK(s.media[0].flags & MEDIUM_EMISSIVE);
    }
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    /* Lescale 0: no glow, the temperature grid not read */
    CHECK_EQ_INT(load_text("MakeNamedMedium \"smoke\" \"string type\" \"nanovdb\" \"string filename\" \"ramp-zip.nvdb\"\n"
                           "  \"float Lescale\" 0\n", &s, &err), ST_OK);
    if (s.n_grids == 1) CHECK(s.grids[0].temperature_at == 0u && !(s.media[0].flags & MEDIUM_EMISSIVE));
    scene_free(&s);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"ramp-zip.nvdb\" "
                           "\"float Lescale\" -1\n", &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:79: parameter 'Lescale' must be a number in [0, 1e30]") == 0,
              "got '%s'", err.msg);
    scene_free(&s);
    error_clear(&err);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"ramp-zip.nvdb\" "
                           "\"float Lescale\" 1e30 \"rgb sigma_a\" [1 1e10 1]\n", &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:17: MakeNamedMedium \"m\": its emission (Lescale times sigma_a and a "
                     "blackbody's colour, up to 256) is beyond the largest float (about 3.4e38)") == 0, "got '%s'",
              err.msg);
    scene_free(&s);
    error_clear(&err);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"ramp-zip.nvdb\" "
                           "\"float temperaturescale\" -2\n", &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:79: parameter 'temperaturescale' must be a number in [0, 1e30]") == 0,
              "got '%s'", err.msg);
    scene_free(&s);
    error_clear(&err);
    /* a file's error carries the line that named it */
    CHECK_EQ_INT(load_text("MakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" "
                           "\"../bad/nvdb-type.nvdb.gz\"\n", &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:63: " NDIR "../bad/nvdb-type.nvdb.gz: grid \"density\" holds "
                     "double values (type 2); clpt reads float grids") == 0, "got '%s'", err.msg);
    scene_free(&s);
    error_clear(&err);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"m\" \"string type\" \"nanovdb\"\n", &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:17: MakeNamedMedium \"m\": a \"nanovdb\" medium needs \"string "
                     "filename\"") == 0, "got '%s'", err.msg);
    scene_free(&s);
    error_clear(&err);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"none.nvdb\"\n",
                           &s, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "inline.pbrt:1:63: cannot open");
    scene_free(&s);
    error_clear(&err);
}

/* A temperature grid on voxels of its own (half as wide, shifted a quarter voxel): the
 * density's cells take it at their centres through both maps, trilinear (exact for a
 * linear temperature), 0 beyond its voxels as NanoVDB's sampler reads a fog volume. */
static void test_pbrt_nanovdb_temperature_map(void)
{
    float ones[4 * 4 * 4], temp[8 * 8 * 8];
    for (int i = 0; i < 64; i++) ones[i] = 1.0f;
    /* temperature voxel (i, j, k) at world 0.5 (i, j, k) + 0.25: T = 1000 + 100 x + 10 y + z */
    for (int k = 0; k < 8; k++)
        for (int j = 0; j < 8; j++)
            for (int i = 0; i < 8; i++)
                temp[(k * 8 + j) * 8 + i] = (float)(1000 + 100 * (0.5 * i + 0.25) + 10 * (0.5 * j + 0.25) + (0.5 * k + 0.25));
    NvdbGrid grids[2] = { { "density", 0, 0, 0, 4, 4, 4, ones, { 1, 1, 1 }, { 0, 0, 0 }, 0, 0 },
                          { "temperature", 0, 0, 0, 8, 8, 8, temp, { 0.5, 0.5, 0.5 }, { 0.25, 0.25, 0.25 }, 0, 0 } };
    size_t n;
    unsigned char *f = nvdb_write(grids, 2, 0, &n);
    char path[512], text[1024];
    test_tmp_path(path, sizeof path, "clpt-test-temperature.nvdb");
    FILE *out = fopen(path, "wb");
    CHECK(f && out && fwrite(f, 1, n, out) == n);
    if (out) fclose(out);
    free(f);
    snprintf(text, sizeof text, "MakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"%s\"\n", path);
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text(text, &s, &err), ST_OK);
    if (s.n_grids == 1 && s.grids[0].temperature_at) {
        const float *k = s.grid_data + s.grids[0].temperature_at;
        /* density cell (x, y, z) centred at world (x, y, z) */
        CHECK_NEAR(k[(2 * 4 + 1) * 4 + 3], 1000 + 300 + 10 + 2, 1e-3);
        CHECK_NEAR(k[(3 * 4 + 3) * 4 + 1], 1000 + 100 + 30 + 3, 1e-3);
        /* x = 0: half way between voxel -1 (background 0) and voxel 0 (x 0.25) */
        CHECK_NEAR(k[(2 * 4 + 2) * 4 + 0], 0.5 * (1000 + 25 + 20 + 2), 1e-3);
    }
    scene_free(&s);
    error_clear(&err);
    remove(path);
}

/* A map that puts the box beyond the scene's coordinates is refused with the line. */
static void test_pbrt_nanovdb_far(void)
{
    char *data;
    size_t len;
    Error err = { 0 };
    CHECK_EQ_INT(lex_read_file(NDIR "ramp.nvdb", &data, &len, &err), ST_OK);
    if (!data) return;
    double scale = 1e20;   /* the map's matD[0][0] (grid at 200, map at 296, matD at +88) */
    memcpy(data + 200 + 296 + 88, &scale, sizeof scale);
    char path[512];
    test_tmp_path(path, sizeof path, "clpt-test-nanovdb.nvdb");
    FILE *f = fopen(path, "wb");
    CHECK(f && fwrite(data, 1, len, f) == len);
    if (f) fclose(f);
    free(data);
    char text[1024];
    snprintf(text, sizeof text, "MakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"%s\"\n", path);
    Scene s;
    CHECK_EQ_INT(load_text(text, &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:63: MakeNamedMedium \"m\": the grid's index-to-world map and the "
                     "transform place its box beyond the scene's coordinates (2^62) or squash it to nothing") == 0,
              "got '%s'", err.msg);
    scene_free(&s);
    error_clear(&err);
    remove(path);
}

/* The trilinear lookup of a cell-centred grid with its border clamped (docs/media.md). */
static float grid_lookup(const float *d, const unsigned n[3], const double u[3])
{
    int i0[3], i1[3];
    double t[3];
    for (int a = 0; a < 3; a++) {
        double x = u[a] * n[a] - 0.5;
        if (x < 0) x = 0;
        if (x > n[a] - 1) x = n[a] - 1;
        i0[a] = (int)floor(x);
        i1[a] = i0[a] + 1 < (int)n[a] ? i0[a] + 1 : i0[a];
        t[a] = x - i0[a];
    }
    double v = 0;
    for (int c = 0; c < 8; c++) {
        int ix = c & 1 ? i1[0] : i0[0], iy = c & 2 ? i1[1] : i0[1], iz = c & 4 ? i1[2] : i0[2];
        double w = (c & 1 ? t[0] : 1 - t[0]) * (c & 2 ? t[1] : 1 - t[1]) * (c & 4 ? t[2] : 1 - t[2]);
        v += w * d[((size_t)iz * n[1] + iy) * n[0] + ix];
    }
    return (float)v;
}

/* MakeNamedMedium "cloud": pbrt-v4's density, baked at the documented resolution; the
 * bake's error against the procedural density at random points is measured. */
static void test_cloud(void)
{
    CHECK_NEAR(noise3(1, 2, 3), 0, 0);   /* 0 at the lattice points */
    /* altitude: y >= 1 is empty, y <= 0 full */
    CHECK_NEAR(pbrt_cloud_density(0.3f, 1.0f, 0.7f, 1, 1, 5), 0, 0);
    CHECK_NEAR(pbrt_cloud_density(0.3f, 0.0f, 0.7f, 1, 1, 5), 1, 0);
    unsigned n[3];
    pbrt_cloud_resolution(v3s(0.0f), v3s(1.0f), 5.0f, n);
    CHECK_EQ_INT(n[0], 157);   /* 2 cells a period of 5 x 1.99^4 periods a unit */
    pbrt_cloud_resolution(v3s(0.0f), v3(4.0f, 1.0f, 4.0f), 5.0f, n);
    CHECK((uint64_t)n[0] * n[1] * n[2] <= (1u << 22));
    CHECK_EQ_INT(n[0], n[2]);

    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("MakeNamedMedium \"c\" \"string type\" \"cloud\" \"float density\" 1 \"float g\" 0.5\n"
                           "  \"rgb sigma_s\" [2 2 2] \"rgb sigma_a\" [0.1 0.1 0.1]\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_grids, 1);
    CHECK_EQ_INT(s.n_warnings, 0);
    if (s.n_grids == 1) {
        const GridMedium *g = &s.grids[0];
        unsigned gn[3] = { g->nx, g->ny, g->nz };
        CHECK_EQ_INT(g->nx, 157);
        const float *d = s.grid_data + g->density_at;
        double sum_err = 0, max_err = 0, sum = 0;
        uint32_t r = 12345;
        const int N = 200000;
        for (int i = 0; i < N; i++) {
            double u[3];
            for (int a = 0; a < 3; a++) {
                r = r * 1664525u + 1013904223u;
                u[a] = (r >> 8) / 16777216.0;
            }
            float exact = pbrt_cloud_density((float)u[0], (float)u[1], (float)u[2], 1, 1, 5);
            double e = fabs(grid_lookup(d, gn, u) - exact);
            sum_err += e;
            sum += exact;
            if (e > max_err) max_err = e;
        }
        printf("  cloud bake %ux%ux%u: mean |error| %.5f (mean density %.4f), max %.4f\n", gn[0], gn[1], gn[2],
               sum_err / N, sum / N, max_err);
        CHECK(sum_err / N < 0.02);   /* measured 0.0156: the wisps are finer than the bake (docs/media.md) */
    }
    scene_free(&s);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"c\" \"string type\" \"cloud\" \"float scale\" 2\n", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_warnings, 1);
    if (s.n_warnings == 1)
        CHECK_MSG(strcmp(s.warnings[0], NDIR "inline.pbrt:1: MakeNamedMedium \"cloud\": parameter \"float scale\" is "
                         "not supported; ignored") == 0, "got '%s'", s.warnings[0]);
    scene_free(&s);
}

/* Grids made at load are bounded in all: a scene whose grids already hold nearly 2^27
 * values refuses another (the count is set by hand: nothing that large is allocated). */
static void test_grid_budget(void)
{
    const char *text = "MakeNamedMedium \"c\" \"string type\" \"cloud\"\n";
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    s.n_grid_data = (1u << 27) - 1000u;
    CHECK_EQ_INT(scene_load_bytes(NDIR "inline.pbrt", text, strlen(text), SCENE_FORMAT_AUTO, &s, NULL, &err),
                 ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:17: MakeNamedMedium \"c\": its grid of 3869893 cells would take "
                     "the scene's density grids past 2^27 values (512 MiB)") == 0, "got '%s'", err.msg);
    s.n_grid_data = 0;
    scene_free(&s);
    error_clear(&err);
}

/* MakeNamedMedium "rgbgrid": one density (each voxel's luminance of sigma_a + sigma_s)
 * times one colour (the totals over the densities' total). */
static void test_rgbgrid(void)
{
    Scene s;
    Error err = { 0 };
    /* the second voxel is the first's colour, twice as dense: exact, no warning */
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"integer nx\" 2\n"
                           "  \"rgb sigma_a\" [0.1 0.2 0.3 0.2 0.4 0.6] \"rgb sigma_s\" [1 1 1 2 2 2] \"float scale\" 3\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_grids, 1);
    CHECK_EQ_INT(s.n_warnings, 0);
    if (s.n_grids == 1 && s.n_media == 1) {
        const float *d = s.grid_data + s.grids[0].density_at;
        double y = 0.2126 * 1.1 + 0.7152 * 1.2 + 0.0722 * 1.3;
        CHECK_NEAR(d[0], y, 1e-6);
        CHECK_NEAR(d[1], 2 * y, 1e-6);
        /* density x colour gives back each voxel's coefficients, times scale */
        CHECK_NEAR(d[1] * s.media[0].sigma_a.z, 3 * 0.6, 1e-5);
        CHECK_NEAR(d[0] * s.media[0].sigma_s.y, 3 * 1, 1e-5);
    }
    scene_free(&s);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"integer nx\" 2\n"
                           "  \"rgb sigma_s\" [1 0 0 0 0 1]\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_warnings, 1);
    if (s.n_warnings == 1)
        CHECK_MSG(strcmp(s.warnings[0], NDIR "inline.pbrt:1: MakeNamedMedium \"r\": clpt's grids hold one density, so "
                         "the rgbgrid's voxel colours become one colour times their luminance (docs/media.md)") == 0,
                  "got '%s'", s.warnings[0]);
    scene_free(&s);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"integer nx\" 2\n"
                           "  \"rgb sigma_a\" [1 1 1]\n", &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:2:3: MakeNamedMedium \"r\": nx ny nz are 2 cells, but \"sigma_a\" has "
                     "3 numbers (3 a cell)") == 0, "got '%s'", err.msg);
    scene_free(&s);
    error_clear(&err);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\"\n", &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:17: MakeNamedMedium \"r\": an \"rgbgrid\" needs \"rgb sigma_a\" "
                     "and/or \"rgb sigma_s\"") == 0, "got '%s'", err.msg);
    scene_free(&s);
    error_clear(&err);
}

/* An rgbgrid's "Le" grid times "Lescale": one colour times an emission scale per voxel
 * (its luminance), exact when the voxels' Le share a hue; a warning when they do not;
 * "Le" without "sigma_a" and an emission past the largest float refused. */
static void test_rgbgrid_emission(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"integer nx\" 2\n"
                           "  \"rgb sigma_a\" [1 1 1 2 2 2] \"rgb sigma_s\" [1 1 1 2 2 2] \"rgb Le\" [1 0.5 0.25 2 1 0.5] "
                           "\"float Lescale\" 2\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_warnings, 0);
    if (s.n_grids == 1 && s.n_media == 1) {
        const GridMedium *g = &s.grids[0];
        const Medium *m = &s.media[0];
        CHECK(m->flags & MEDIUM_EMISSIVE);
        CHECK(g->emission_at != 0);
        /* the colour times each voxel's scale gives back its Le times Lescale, in
         * pbrt-v4's unit for an rgbgrid's Le (106.857 a unit of RGB) */
        if (g->emission_at) {
            const float *e = s.grid_data + g->emission_at;
            double unit = 106.856895;
            CHECK_NEAR(e[0] * m->emission.x, 2.0 * unit, 2e-4);
            CHECK_NEAR(e[0] * m->emission.z, 0.5 * unit, 1e-4);
            CHECK_NEAR(e[1] * m->emission.y, 2.0 * unit, 2e-4);
        }
    }
    scene_free(&s);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"integer nx\" 2\n"
                           "  \"rgb sigma_a\" [1 1 1 1 1 1] \"rgb Le\" [1 0 0 0 0 1]\n", &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_warnings, 1);
    if (s.n_warnings == 1)
        CHECK_MSG(strcmp(s.warnings[0], NDIR "inline.pbrt:1: MakeNamedMedium \"r\": clpt's grids hold one emission "
                         "colour, so the rgbgrid's voxel Le colours become one colour times their luminance "
                         "(docs/media.md)") == 0, "got '%s'", s.warnings[0]);
    scene_free(&s);
    /* Lescale 0: no emission */
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"rgb sigma_a\" [1 1 1] "
                           "\"rgb Le\" [1 1 1] \"float Lescale\" 0\n", &s, &err), ST_OK);
    CHECK(s.n_media == 1 && !(s.media[0].flags & MEDIUM_EMISSIVE) && s.grids[0].emission_at == 0);
    scene_free(&s);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"rgb sigma_s\" [1 1 1] "
                           "\"rgb Le\" [1 1 1]\n", &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:17: MakeNamedMedium \"r\": an \"rgbgrid\" with \"Le\" needs \"rgb "
                     "sigma_a\" (what absorbs emits)") == 0, "got '%s'", err.msg);
    scene_free(&s);
    error_clear(&err);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"integer nx\" 2 \"rgb sigma_a\" "
                           "[1e10 1 1 1e10 1 1] \"rgb Le\" [1 1 1 1e30 1e30 1e30]\n", &s, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, NDIR "inline.pbrt:1:17: MakeNamedMedium \"r\": its Le (voxel 1) times Lescale and "
                     "sigma_a, or times the density, is beyond the largest float (about 3.4e38)") == 0, "got '%s'",
              err.msg);
    scene_free(&s);
    error_clear(&err);
    CHECK_EQ_INT(load_text("MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"rgb sigma_a\" [1 1 1] "
                           "\"rgb Le\" [1 1 1] \"float Lescale\" -1\n", &s, &err), ST_INPUT);
    CHECK_MSG(strstr(err.msg, "parameter 'Lescale' must be a number in [0, 1e30]") != NULL, "got '%s'", err.msg);
    scene_free(&s);
    error_clear(&err);
}

int main(void)
{
    RUN(test_ramp);
    RUN(test_resample);
    RUN(test_bad_files);
    RUN(test_pbrt_nanovdb);
    RUN(test_pbrt_nanovdb_temperature_map);
    RUN(test_pbrt_nanovdb_far);
    RUN(test_cloud);
    RUN(test_rgbgrid);
    RUN(test_rgbgrid_emission);
    RUN(test_grid_budget);
    return harness_report();
}
