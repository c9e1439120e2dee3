/*
 * pbrt_volume.c — pbrt-v4's media that clpt holds as a density grid made at load time
 * (docs/media.md, docs/pbrt.md): "nanovdb" (a .nvdb file, io/nanovdb.h), "cloud"
 * (pbrt-v4's procedural cloud, baked into a grid) and "rgbgrid" (per-voxel RGB
 * coefficients, kept as one colour times a density). Part of the pbrt-v4 reader
 * (pbrt_reader.h); pbrt_medium.c dispatches to pbrt_volume_medium.
 *
 * Each becomes clpt's grid medium (kernels/medium/grid.h): coefficients per unit of
 * density and a grid of cell-centred densities in a box that a transform places.
 */
#include "io/pbrt_reader.h"

#include "base/noise.h"
#include "util/kmath.h"
#include "io/nanovdb.h"
#include "scene/media.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NAME_LEN(t) (int)((t)->len > 40 ? 40 : (t)->len)

/* The values the density grids of one scene may hold once a grid made at load (a
 * NanoVDB file's, a baked cloud) is added: 2^27 floats, 512 MiB. A few bytes of scene
 * text can ask for a 16 MiB cloud or a file's 64 MiB grid, again and again; this bounds
 * the memory (and a cloud's bake, about 3 s a 2^22 cells, to 32 of them). */
#define PBRT_MADE_GRID_BUDGET (1u << 27)

static Status grid_budget(Parser *p, const Lexer *lx, const Token *name, size_t cells)
{
    if (cells <= PBRT_MADE_GRID_BUDGET && p->s->n_grid_data <= PBRT_MADE_GRID_BUDGET - cells) return ST_OK;
    return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": its grid of %zu cells would take the scene's "
                        "density grids past 2^27 values (512 MiB)", NAME_LEN(name), name->text, cells);
}

/* ------------------------------------------------------------------ nanovdb */

/* One value of dense grid t at continuous cell coordinates x (cell c's centre at c):
 * trilinear between its cells, those outside it 0 (a fog volume's background, which
 * NanoVDB's trilinear sampler reads beyond the active voxels). */
static double dense_trilinear(const NanoDense *t, const double x[3])
{
    unsigned n[3] = { t->nx, t->ny, t->nz };
    double f[3], v = 0.0;
    long i0[3];
    for (int a = 0; a < 3; a++) {
        double fl = floor(x[a]);
        if (!(fl > -2.0 && fl < (double)n[a] + 1.0)) return 0.0;   /* far outside (or NaN) */
        i0[a] = (long)fl;
        f[a] = x[a] - fl;
    }
    for (int c = 0; c < 8; c++) {
        long ix = i0[0] + (c & 1), iy = i0[1] + ((c >> 1) & 1), iz = i0[2] + ((c >> 2) & 1);
        if (ix < 0 || iy < 0 || iz < 0 || ix >= (long)n[0] || iy >= (long)n[1] || iz >= (long)n[2]) continue;
        double w = (c & 1 ? f[0] : 1.0 - f[0]) * (c & 2 ? f[1] : 1.0 - f[1]) * (c & 4 ? f[2] : 1.0 - f[2]);
        v += w * t->density[((size_t)iz * n[1] + (size_t)iy) * n[0] + (size_t)ix];
    }
    return v;
}

/* The temperature grid t at the centres of the cells of density grid d, as pbrt-v4's
 * NanoVDBMedium looks it up (its own map and trilinear sampler): each centre taken to
 * the medium's space by d's map, to t's index space by the inverse of t's, and sampled
 * there. Both grids usually share their map and box, where this copies t. *out: d's
 * nx ny nz values (free it); 0 when t's map is singular (it is then no grid). */
static int temperature_on_density(const NanoDense *d, const NanoDense *t, float **out)
{
    Transform t_from_medium;
    if (!transform_invert(&t->index_to_world, &t_from_medium)) return 0;
    Transform t_from_d = transform_compose(&t_from_medium, &d->index_to_world);
    size_t cells = (size_t)d->nx * d->ny * d->nz;
    float *v = malloc(cells * sizeof(float));
    if (!v) return -1;
    for (unsigned z = 0; z < d->nz; z++)
        for (unsigned y = 0; y < d->ny; y++)
            for (unsigned x = 0; x < d->nx; x++) {
                double c[3] = { d->lo[0] + d->stride * (x + 0.5), d->lo[1] + d->stride * (y + 0.5),
                                d->lo[2] + d->stride * (z + 0.5) }, q[3];
                for (int r = 0; r < 3; r++) {
                    double idx = t_from_d.m[r][0] * c[0] + t_from_d.m[r][1] * c[1] + t_from_d.m[r][2] * c[2] +
                                 t_from_d.m[r][3];
                    q[r] = (idx - t->lo[r]) / t->stride - 0.5;   /* t's cell coordinates */
                }
                double k = dense_trilinear(t, q);
                v[((size_t)z * d->ny + y) * d->nx + x] = (float)(k > 3.4e38 ? 3.4e38 : k);
            }
    *out = v;
    return 1;
}

/* "filename" (beside the main file), "gridname" (default "density"); the emission:
 * the "temperaturename" grid (default "temperature"; none in the file: no glow, as in
 * pbrt-v4), its blackbody times "Lescale" (1), temperatureoffset/temperaturescale as a
 * uniformgrid's (pbrt_medium_temperature). */
static Status nanovdb_medium(Parser *p, const Lexer *lx, const Token *name, Medium *out)
{
    Status st;
    vec3 sa, ss;
    float g;
    double le_scale = 1.0;
    GridTemperature how;
    if ((st = pbrt_medium_coefficients(p, lx, name, 1, &sa, &ss, &g)) ||
        (st = pbrt_get_float(p, lx, "Lescale", &le_scale)) || (st = pbrt_medium_temperature(p, lx, &how)))
        return st;
    if (!(le_scale >= 0.0) || !(le_scale <= 1e30))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "Lescale"), "a number in [0, 1e30]");
    const Token *f = NULL, *gn = NULL, *tn = NULL;
    if ((st = pbrt_get_string(p, lx, "filename", &f)) || (st = pbrt_get_string(p, lx, "gridname", &gn)) ||
        (st = pbrt_get_string(p, lx, "temperaturename", &tn)))
        return st;
    if (!f)
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": a \"nanovdb\" medium needs \"string "
                            "filename\"", NAME_LEN(name), name->text);
    char grid_name[256], temp_name[256];
    snprintf(grid_name, sizeof grid_name, "%.*s", gn ? (int)(gn->len > 255 ? 255 : gn->len) : 7,
             gn ? gn->text : "density");
    snprintf(temp_name, sizeof temp_name, "%.*s", tn ? (int)(tn->len > 255 ? 255 : tn->len) : 11,
             tn ? tn->text : "temperature");
    char *path = pbrt_beside_main(p, f);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    char *data = NULL;
    size_t len = 0;
    NanoDense dense, temp;
    memset(&dense, 0, sizeof dense);
    memset(&temp, 0, sizeof temp);
    st = lex_read_file(path, &data, &len, p->err);
    if (!st) st = nanovdb_read_grid(path, (const unsigned char *)data, len, grid_name, &dense, p->err);
    int has_temperature = !st && le_scale > 0.0 && nanovdb_has_grid((const unsigned char *)data, len, temp_name);
    if (has_temperature && (st = nanovdb_read_grid(path, (const unsigned char *)data, len, temp_name, &temp, p->err)))
        free(dense.density);
    free(data);
    free(path);
    if (st) {
        if (st == ST_IO || st == ST_INPUT) reader_annotate(lx, f, p->err);
        return st;
    }
    float *kelvin = NULL;   /* the temperature at the density's cells */
    int made = has_temperature ? temperature_on_density(&dense, &temp, &kelvin) : 0;
    free(temp.density);
    if (made < 0) {
        free(dense.density);
        return error_set(p->err, ST_INTERNAL, "out of memory for the temperature grid of \"%.*s\"", NAME_LEN(name),
                         name->text);
    }
    if (kelvin && (st = pbrt_medium_glow_check(p, lx, name, sa, le_scale))) {
        free(dense.density);
        free(kelvin);
        return st;
    }
    /* the dense box starts at index lo; folding lo into the transform keeps the box's
     * numbers small (exact in single precision) whatever the grid's index offset */
    Transform to_index = transform_translate(dense.lo[0], dense.lo[1], dense.lo[2]);
    Transform medium_from_box = transform_compose(&dense.index_to_world, &to_index);
    Transform world_from_box = transform_compose(&p->g.ctm, &medium_from_box);
    vec3 hi = v3((float)(dense.hi[0] - dense.lo[0]), (float)(dense.hi[1] - dense.lo[1]),
                 (float)(dense.hi[2] - dense.lo[2]));
    uint grid;
    /* the file's map may be any finite affine map: the box must land inside the scene's
     * coordinates, and the kernels' float matrix back to the grid must be finite */
    size_t cells = (size_t)dense.nx * dense.ny * dense.nz;
    /* the temperatures count against the budget too (and their table, 12 289 floats) */
    if ((st = grid_budget(p, lx, name, kelvin ? 2 * cells + 1 + 3 * GRID_BLACKBODY_STEPS : cells))) {
        free(dense.density);
        free(kelvin);
        return st;
    }
    int placeable = 1;
    for (int c = 0; c < 8; c++) {
        vec3 corner = transform_point(&world_from_box, v3(c & 1 ? hi.x : 0.0f, c & 2 ? hi.y : 0.0f, c & 4 ? hi.z : 0.0f));
        placeable &= fabsf(corner.x) <= SCENE_MAX_COORDINATE && fabsf(corner.y) <= SCENE_MAX_COORDINATE &&
                     fabsf(corner.z) <= SCENE_MAX_COORDINATE;
    }
    st = placeable ? scene_add_grid(p->s, dense.density, dense.nx, dense.ny, dense.nz, v3s(0.0f), hi, &world_from_box,
                                    &grid, p->err)
                   : ST_OK;
    free(dense.density);
    if (!st && placeable && kelvin) st = scene_grid_set_temperature(p->s, grid, kelvin, how, p->err);
    free(kelvin);
    if (st) return st;
    for (int i = 0; placeable && i < 12; i++) placeable = isfinite(p->s->grids[grid].to_grid[i]);
    if (!placeable)
        return lex_error_at(lx, f, p->err, "MakeNamedMedium \"%.*s\": the grid's index-to-world map and the "
                            "transform place its box beyond the scene's coordinates (2^62) or squash it to nothing",
                            NAME_LEN(name), name->text);
    if (dense.stride > 1u) {
        char key[96];
        snprintf(key, sizeof key, "nanovdb-stride:%.*s", NAME_LEN(name), name->text);
        if ((st = warn_once(p, lx, f, key, "MakeNamedMedium \"%.*s\": its grid of %lld x %lld x %lld voxels is more "
                            "than %u cells; resampled to %u x %u x %u (the mean of %u^3 voxels a cell)",
                            NAME_LEN(name), name->text, (long long)(dense.bbox_max[0] - dense.bbox_min[0] + 1),
                            (long long)(dense.bbox_max[1] - dense.bbox_min[1] + 1),
                            (long long)(dense.bbox_max[2] - dense.bbox_min[2] + 1), NANOVDB_MAX_CELLS, dense.nx,
                            dense.ny, dense.nz, dense.stride)))
            return st;
    }
    *out = medium_grid(sa, ss, g, grid);
    if (kelvin) *out = medium_with_emission(*out, v3s((float)le_scale));
    return ST_OK;
}

/* ------------------------------------------------------------------ cloud */

/* pbrt-v4's CloudMedium density at p of the medium's space (PBR 4th ed., sec. 11.3,
 * "CloudMedium"): p scaled by the frequency and, with wispiness, pushed twice along the
 * noise's gradient; five octaves of noise (weights 1/2, 1/4, ..., frequencies 1.99^i);
 * scaled by (1 - y) 4.5 density and clamped to [0, 1], plus 2 max(0, 0.5 - y) (a floor
 * of fog below y = 0.5), clamped to [0, 1]. */
float pbrt_cloud_density(float x, float y, float z, float density, float wispiness, float frequency)
{
    float q[3] = { frequency * x, frequency * y, frequency * z };
    if (wispiness > 0.0f) {
        float vomega = 0.05f * wispiness, vlambda = 10.0f;
        for (int i = 0; i < 2; i++) {
            float d[3];
            noise3_gradient(vlambda * q[0], vlambda * q[1], vlambda * q[2], d);
            for (int a = 0; a < 3; a++) q[a] += vomega * d[a];
            vomega *= 0.5f;
            vlambda *= 1.99f;
        }
    }
    float d = 0.0f, omega = 0.5f, lambda = 1.0f;
    for (int i = 0; i < 5; i++) {
        d += omega * noise3(lambda * q[0], lambda * q[1], lambda * q[2]);
        omega *= 0.5f;
        lambda *= 1.99f;
    }
    d = (1.0f - y) * 4.5f * density * d;
    d = d < 0.0f ? 0.0f : d > 1.0f ? 1.0f : d;
    d += 2.0f * (0.5f - y > 0.0f ? 0.5f - y : 0.0f);
    return d > 1.0f ? 1.0f : d;
}

/* The bake's resolution: PBRT_CLOUD_CELLS_PER_PERIOD cells per lattice period of the
 * noise's finest octave (frequency x 1.99^4 periods a unit), at most
 * PBRT_CLOUD_MAX_CELLS in all (the same factor fewer on every axis), at least 2 an
 * axis. */
#define PBRT_CLOUD_CELLS_PER_PERIOD 2.0
#ifndef CLPT_FUZZ_BUILD
#define PBRT_CLOUD_MAX_CELLS (1u << 22)
#else
/* `make fuzz` builds with CLPT_FUZZ_BUILD: a bake of 2^22 cells takes about 12 s under
 * the fuzzer's instrumentation, past libFuzzer's 10 s for one input (scenes/cloud.pbrt
 * is a seed), where 2^15 cells run the same code in a tenth of a second. */
#define PBRT_CLOUD_MAX_CELLS (1u << 15)
#endif

void pbrt_cloud_resolution(vec3 lo, vec3 hi, float frequency, unsigned n[3])
{
    double per_unit = PBRT_CLOUD_CELLS_PER_PERIOD * fabs((double)frequency) * pow(1.99, 4.0);
    double ext[3] = { hi.x - lo.x, hi.y - lo.y, hi.z - lo.z };
    double want[3], cells = 1.0;
    for (int a = 0; a < 3; a++) {
        want[a] = ceil(ext[a] * per_unit);
        if (!(want[a] >= 2.0)) want[a] = 2.0;
        if (want[a] > 4096.0) want[a] = 4096.0;
        cells *= want[a];
    }
    double shrink = cells > PBRT_CLOUD_MAX_CELLS ? cbrt(cells / PBRT_CLOUD_MAX_CELLS) : 1.0;
    for (;;) {
        double total = 1.0;
        for (int a = 0; a < 3; a++) {
            double v = floor(want[a] / shrink);
            n[a] = v < 2.0 ? 2u : (unsigned)v;
            total *= n[a];
        }
        if (total <= PBRT_CLOUD_MAX_CELLS) return;
        shrink *= 1.01;
    }
}

/* density (1), wispiness (1), frequency (5), g, sigma_a, sigma_s (no scale: pbrt-v4's
 * cloud reads none), p0 p1 (the unit cube), baked at cell centres into a grid. */
static Status cloud_medium(Parser *p, const Lexer *lx, const Token *name, Medium *out)
{
    Status st;
    vec3 sa, ss;
    float g;
    if ((st = pbrt_medium_coefficients(p, lx, name, 0, &sa, &ss, &g))) return st;
    double density = 1.0, wisp = 1.0, freq = 5.0;
    if ((st = pbrt_get_float(p, lx, "density", &density)) || (st = pbrt_get_float(p, lx, "wispiness", &wisp)) ||
        (st = pbrt_get_float(p, lx, "frequency", &freq)))
        return st;
    if (!(fabs(density) <= 1e30)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "density"), "a finite number");
    if (!(fabs(wisp) <= 1e6)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "wispiness"), "a number in [-1e6, 1e6]");
    if (!(fabs(freq) <= 1e6)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "frequency"), "a number in [-1e6, 1e6]");
    vec3 lo = v3s(0.0f), hi = v3s(1.0f);
    if ((st = pbrt_get_point(p, lx, "p0", &lo)) || (st = pbrt_get_point(p, lx, "p1", &hi))) return st;
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z) || !(fabsf(lo.x) < 1e30f && fabsf(lo.y) < 1e30f &&
        fabsf(lo.z) < 1e30f && fabsf(hi.x) < 1e30f && fabsf(hi.y) < 1e30f && fabsf(hi.z) < 1e30f))
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": p1 must be greater than p0 on every "
                            "axis, found p0 %g %g %g, p1 %g %g %g", NAME_LEN(name), name->text, (double)lo.x,
                            (double)lo.y, (double)lo.z, (double)hi.x, (double)hi.y, (double)hi.z);
    unsigned n[3];
    pbrt_cloud_resolution(lo, hi, (float)freq, n);
    size_t cells = (size_t)n[0] * n[1] * n[2];
    if ((st = grid_budget(p, lx, name, cells))) return st;
    float *d = malloc(cells * sizeof(float));
    if (!d) return error_set(p->err, ST_INTERNAL, "out of memory for the cloud \"%.*s\"", NAME_LEN(name), name->text);
    for (unsigned z = 0; z < n[2]; z++)
        for (unsigned y = 0; y < n[1]; y++)
            for (unsigned x = 0; x < n[0]; x++) {
                float px = lo.x + (hi.x - lo.x) * ((float)x + 0.5f) / (float)n[0];
                float py = lo.y + (hi.y - lo.y) * ((float)y + 0.5f) / (float)n[1];
                float pz = lo.z + (hi.z - lo.z) * ((float)z + 0.5f) / (float)n[2];
                d[((size_t)z * n[1] + y) * n[0] + x] =
                    pbrt_cloud_density(px, py, pz, (float)density, (float)wisp, (float)freq);
            }
    uint grid;
    st = scene_add_grid(p->s, d, n[0], n[1], n[2], lo, hi, &p->g.ctm, &grid, p->err);
    free(d);
    if (st) return st;
    *out = medium_grid(sa, ss, g, grid);
    return ST_OK;
}

/* ------------------------------------------------------------------ rgbgrid */

/* An "rgb" parameter of n colours: its values, or NULL when absent; an error when
 * present with another type or count, or a negative or non-finite value. */
static Status rgb_array(Parser *p, const Lexer *lx, const Token *name, const char *key, double cells,
                        const double **out)
{
    *out = NULL;
    Param *pa = pbrt_param_find(p, key);
    if (!pa) return ST_OK;
    if (pa->type != PT_RGB) return pbrt_param_type_error(p, lx, pa, "rgb values");
    if ((double)pa->n != 3.0 * cells)
        return lex_error_at(lx, &pa->decl, p->err, "MakeNamedMedium \"%.*s\": nx ny nz are %.0f cells, but \"%s\" "
                            "has %zu numbers (3 a cell)", NAME_LEN(name), name->text, cells, key, pa->n);
    const double *v = p->pl.nums + pa->first;
    for (size_t i = 0; i < pa->n; i++)
        if (!(v[i] >= 0.0) || !(v[i] <= 3.4e38))
            return lex_error_at(lx, &pa->decl, p->err, "MakeNamedMedium \"%.*s\": \"%s\" value %zu is %g; it must be "
                                "a finite number >= 0", NAME_LEN(name), name->text, key, i, v[i]);
    *out = v;
    return ST_OK;
}

/* Rec. 709 luminance, the weights of an RGB colour's brightness. */
static double luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

/* The integral of the CIE 1931 y-bar curve (pbrt-v4's CIE_Y_integral). pbrt-v4 divides
 * the Le of its homogeneous and uniformgrid media by their illuminant's luminance
 * (media.cpp, "LeScale /= SpectrumToPhotometric(Le)"), which makes an RGB Le of 1 1 1 a
 * radiance of 1 on its RGB film, but not the rgbgrid's "Le" grid: there 1 1 1 renders
 * as 106.857 (measured: the same grid as a uniformgrid and as an rgbgrid in pbrt-v4, the
 * ratio 106.857 in every channel). clpt reads the rgbgrid as pbrt-v4 renders it. */
#define PBRT_RGBGRID_LE_UNIT 106.856895

/* An rgbgrid's emission: the count voxel colours vle (x fastest) times le_scale > 0 as
 * one colour *le (their sum over the sum of their luminances, times le_scale and
 * PBRT_RGBGRID_LE_UNIT) and a new
 * array *scale of each voxel's luminance (NULL, *le 0 0 0, when every Le is black);
 * *uniform 0 when the voxels' hues differ. With sigma_a sa and the densities d it must
 * fit single precision (grid_emission_fits). */
static Status rgb_grid_emission(Parser *p, const Lexer *lx, const Token *name, const double *vle, size_t count,
                                double le_scale, vec3 sa, const float *d, vec3 *le, float **scale, int *uniform)
{
    double sum[3] = { 0, 0, 0 }, sum_y = 0.0, first[3] = { 0, 0, 0 };
    int have_first = 0;
    *uniform = 1;
    *le = v3s(0.0f);
    *scale = NULL;
    for (size_t i = 0; i < count; i++) {
        const double *c = vle + 3 * i;
        double y = luminance(c[0], c[1], c[2]);
        for (int k = 0; k < 3; k++) sum[k] += c[k];
        sum_y += y;
        if (!(y > 0.0)) continue;
        if (!have_first)
            for (int k = 0; k < 3; k++) first[k] = c[k] / y;
        else
            for (int k = 0; k < 3; k++) *uniform &= fabs(c[k] / y - first[k]) <= 1e-6 * (1.0 + first[k]);
        have_first = 1;
    }
    if (!(sum_y > 0.0)) return ST_OK;   /* black everywhere */
    double col[3], sa_le = 0.0;
    for (int k = 0; k < 3; k++) {
        col[k] = le_scale * PBRT_RGBGRID_LE_UNIT * sum[k] / sum_y;
        sa_le = fmax(sa_le, col[k] * (double)v3_get(sa, k));
    }
    float *v = malloc(count * sizeof(float));
    if (!v) return error_set(p->err, ST_INTERNAL, "out of memory");
    for (size_t i = 0; i < count; i++) v[i] = (float)luminance(vle[3 * i], vle[3 * i + 1], vle[3 * i + 2]);
    size_t top;
    if (!grid_emission_fits(d, v, count, sa_le, 1.0, &top)) {
        free(v);
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": its Le (voxel %zu) times Lescale and "
                            "sigma_a, or times the density, is beyond the largest float (about 3.4e38)",
                            NAME_LEN(name), name->text, top);
    }
    *le = v3((float)col[0], (float)col[1], (float)col[2]);
    *scale = v;
    return ST_OK;
}

/* pbrt-v4's RGBGridMedium: "rgb sigma_a" and/or "rgb sigma_s", nx ny nz colours each
 * (a missing one is 1 everywhere, as pbrt's), times `scale`, over p0 p1; g. clpt's grid
 * holds one density, so each voxel keeps d = the luminance of its sigma_a + sigma_s,
 * and the medium the colours A = sum sigma_a / sum d and S = sum sigma_s / sum d: exact
 * when every voxel has the same colour (in proportion), and the grid's total extinction
 * per channel is kept whatever they are. A one-time warning says so. Its emission "rgb
 * Le" (nx ny nz colours, which pbrt-v4 allows only with "sigma_a") times "Lescale" (1)
 * becomes the same way one colour, C = sum Le / sum lum(Le), times an emission scale
 * per voxel, lum(Le): exact when every voxel's Le has the same hue (and the sigma
 * colours are uniform), else the mean hue and a one-time warning. */
static Status rgb_grid(Parser *p, const Lexer *lx, const Token *name, Medium *out)
{
    Status st;
    double scale = 1.0, g = 0.0, le_scale = 1.0;
    if ((st = pbrt_get_float(p, lx, "scale", &scale)) || (st = pbrt_get_float(p, lx, "g", &g)) ||
        (st = pbrt_get_float(p, lx, "Lescale", &le_scale)))
        return st;
    if (!(scale >= 0.0) || !(scale <= 1e30))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "scale"), "a number in [0, 1e30]");
    if (!(le_scale >= 0.0) || !(le_scale <= 1e30))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "Lescale"), "a number in [0, 1e30]");
    if (!(g > -1.0 && g < 1.0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "g"), "a number in (-1, 1)");
    long n[3];
    double cells;
    if ((st = pbrt_medium_grid_size(p, lx, name, n, &cells))) return st;
    const double *va, *vs, *vle;
    if ((st = rgb_array(p, lx, name, "sigma_a", cells, &va)) || (st = rgb_array(p, lx, name, "sigma_s", cells, &vs)) ||
        (st = rgb_array(p, lx, name, "Le", cells, &vle)))
        return st;
    if (!va && !vs)
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": an \"rgbgrid\" needs \"rgb sigma_a\" and/or "
                            "\"rgb sigma_s\"", NAME_LEN(name), name->text);
    if (vle && !va)
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": an \"rgbgrid\" with \"Le\" needs \"rgb "
                            "sigma_a\" (what absorbs emits)", NAME_LEN(name), name->text);
    vec3 lo, hi;
    if ((st = pbrt_medium_box(p, lx, name, &lo, &hi))) return st;
    size_t count = (size_t)cells;
    float *d = malloc(count * sizeof(float));
    if (!d) return error_set(p->err, ST_INTERNAL, "out of memory");
    double sum_a[3] = { 0, 0, 0 }, sum_s[3] = { 0, 0, 0 }, sum_d = 0.0;
    int uniform = 1;   /* every voxel's colours proportional to the first's */
    double first[6] = { 0 };
    for (size_t i = 0; i < count; i++) {
        double c[6];
        for (int k = 0; k < 3; k++) {
            c[k] = va ? va[3 * i + k] : 1.0;
            c[3 + k] = vs ? vs[3 * i + k] : 1.0;
            sum_a[k] += c[k];
            sum_s[k] += c[3 + k];
        }
        double di = luminance(c[0] + c[3], c[1] + c[4], c[2] + c[5]);
        if (di > 0.0 && first[0] + first[1] + first[2] + first[3] + first[4] + first[5] == 0.0)
            for (int k = 0; k < 6; k++) first[k] = c[k] / di;
        else if (di > 0.0)
            for (int k = 0; k < 6; k++) uniform &= fabs(c[k] / di - first[k]) <= 1e-6 * (1.0 + first[k]);
        sum_d += di;
        d[i] = (float)di;
    }
    vec3 sa = v3s(0.0f), ss = v3s(0.0f);
    if (sum_d > 0.0) {
        sa = v3((float)(scale * sum_a[0] / sum_d), (float)(scale * sum_a[1] / sum_d), (float)(scale * sum_a[2] / sum_d));
        ss = v3((float)(scale * sum_s[0] / sum_d), (float)(scale * sum_s[1] / sum_d), (float)(scale * sum_s[2] / sum_d));
    }
    vec3 t = v3_add(sa, ss);
    if (!isfinite(t.x) || !isfinite(t.y) || !isfinite(t.z)) {
        free(d);
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": its extinction (sigma_a + sigma_s, times "
                            "scale) is beyond the largest float (about 3.4e38)", NAME_LEN(name), name->text);
    }
    vec3 le = v3s(0.0f);
    float *emission = NULL;
    int le_uniform = 1;
    if (vle && le_scale > 0.0 && (st = rgb_grid_emission(p, lx, name, vle, count, le_scale, sa, d, &le, &emission,
                                                         &le_uniform))) {
        free(d);
        return st;
    }
    uint grid;
    st = scene_add_grid(p->s, d, (uint)n[0], (uint)n[1], (uint)n[2], lo, hi, &p->g.ctm, &grid, p->err);
    free(d);
    if (!st && emission) st = scene_grid_set_emission(p->s, grid, emission, p->err);
    free(emission);
    if (st) return st;
    if (!uniform && (st = warn_once(p, lx, name, "rgbgrid-colours", "MakeNamedMedium \"%.*s\": clpt's grids hold one "
                                    "density, so the rgbgrid's voxel colours become one colour times their luminance "
                                    "(docs/media.md)", NAME_LEN(name), name->text)))
        return st;
    if (!le_uniform && (st = warn_once(p, lx, name, "rgbgrid-le", "MakeNamedMedium \"%.*s\": clpt's grids hold one "
                                       "emission colour, so the rgbgrid's voxel Le colours become one colour times "
                                       "their luminance (docs/media.md)", NAME_LEN(name), name->text)))
        return st;
    *out = medium_with_emission(medium_grid(sa, ss, (float)g, grid), le);
    return ST_OK;
}

int pbrt_volume_type(const Token *type)
{
    return pbrt_tok_eq(type, "nanovdb") || pbrt_tok_eq(type, "cloud") || pbrt_tok_eq(type, "rgbgrid");
}

Status pbrt_volume_medium(Parser *p, const Lexer *lx, const Token *name, const Token *type, Medium *out)
{
    if (pbrt_tok_eq(type, "nanovdb")) return nanovdb_medium(p, lx, name, out);
    if (pbrt_tok_eq(type, "cloud")) return cloud_medium(p, lx, name, out);
    return rgb_grid(p, lx, name, out);
}
