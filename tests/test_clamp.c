/*
 * test_clamp.c — --clamp V (kernels/integrator/shade_path.h, clamp_indirect): light
 * that reached the camera through two or more bounces is limited per sample. A lamp
 * inside a glass bulb lights the floor only through the glass (its shadow rays stop
 * at the glass), by paths that BSDF sampling finds rarely and that are then very
 * bright: fireflies. Clamped, they are gone, every pixel is at most its unclamped
 * value, the first hit's direct light is untouched, and PoCL gives the scalar device's
 * bytes.
 */
#include <stdlib.h>
#include <unistd.h>

#include "cli_util.h"
#include "harness.h"

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static const char *bulb_text =
    "image { width 64 height 48 spp 16 depth 6 }\n"
    "camera { from 0 2 -5 at 0 0.6 0 up 0 1 0 fov 45 }\n"
    "background { color 0 0 0 }\n"
    "material floor { type diffuse albedo 0.8 0.8 0.8 }\n"
    "material glass { type dielectric ior 1.5 }\n"
    "material lamp { type emissive radiance 50 50 50 }\n"
    "plane { point 0 0 0 normal 0 1 0 material floor }\n"
    "sphere { center 0 1.2 0.5 radius 0.5 material glass }\n"
    "sphere { center 0 1.2 0.5 radius 0.2 material lamp }\n";

static char dir[64], bulb[128];
static CliResult r;

static void path_in_dir(char *out, size_t size, const char *name)
{
    snprintf(out, size, "%s/%s", dir, name);
}

/* A PFM written by clpt (little-endian, "-1.0" scale, bottom row first); NULL if it
 * cannot be read. */
static float *pfm_read(const char *path, unsigned *w, unsigned *h)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char magic[3] = { 0 };
    float scale = 0.0f;
    float *rgb = NULL;
    if (fscanf(f, "%2s %u %u %f", magic, w, h, &scale) == 4 && fgetc(f) == '\n') {
        size_t n = (size_t)*w * *h * 3u;
        rgb = malloc(n * sizeof *rgb);
        if (rgb && fread(rgb, sizeof *rgb, n, f) != n) {
            free(rgb);
            rgb = NULL;
        }
    }
    fclose(f);
    return rgb;
}

static size_t count_above(const float *rgb, size_t n_pixels, float limit)
{
    size_t k = 0;
    for (size_t i = 0; i < n_pixels; i++)
        k += rgb[3 * i] > limit || rgb[3 * i + 1] > limit || rgb[3 * i + 2] > limit;
    return k;
}

static void test_fireflies_removed(void)
{
    char plain[128], clamped[128], scalar[128];
    path_in_dir(plain, sizeof plain, "plain.pfm");
    path_in_dir(clamped, sizeof clamped, "clamped.pfm");
    path_in_dir(scalar, sizeof scalar, "clamped-scalar.pfm");
    cli_run(ARGS(bulb, "-q", "--device", "cpu", "-o", plain), &r);
    CHECK_EQ_INT(r.status, 0);
    cli_run(ARGS(bulb, "-q", "--device", "cpu", "--clamp", "1", "-o", clamped), &r);
    CHECK_EQ_INT(r.status, 0);
    cli_run(ARGS(bulb, "-q", "--device", "scalar", "--clamp", "1", "-o", scalar), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK(files_equal(clamped, scalar));
    unsigned w = 0, h = 0;
    float *a = pfm_read(plain, &w, &h), *b = pfm_read(clamped, &w, &h);
    CHECK(a && b);
    if (a && b) {
        size_t n = (size_t)w * h;
        int never_brighter = 1;
        for (size_t i = 0; i < n * 3u; i++) never_brighter &= b[i] <= a[i];
        CHECK(never_brighter);
        /* what stays above 1 is the lamp seen through the glass: direct, not clamped */
        size_t before = count_above(a, n, 1.0f), after = count_above(b, n, 1.0f);
        fprintf(stderr, "  pixels above 1: %zu unclamped, %zu with --clamp 1\n", before, after);
        CHECK(after * 5 < before);
        CHECK(after > 0);
    }
    free(a);
    free(b);
}

/* At --max-depth 1 every contribution is the first hit's direct light (its light
 * sample, the emission its scattered ray finds) or what the camera sees: --clamp
 * changes no bit. At depth 2 the second hit's light is clamped. The Cornell box's
 * plain triangles would take PoCL's float8 kernel, which --clamp turns off. */
static void test_direct_light_untouched(void)
{
    char a[128], b[128];
    path_in_dir(a, sizeof a, "direct.pfm");
    path_in_dir(b, sizeof b, "direct-clamped.pfm");
    const char *box = "scenes/cornell-box.scene";
    cli_run(ARGS(box, "-q", "--width", "32", "--height", "32", "--spp", "4", "--max-depth", "1", "--device", "cpu",
                 "-o", a), &r);
    CHECK_EQ_INT(r.status, 0);
    cli_run(ARGS(box, "-q", "--width", "32", "--height", "32", "--spp", "4", "--max-depth", "1", "--device", "scalar",
                 "--clamp", "0.001", "-o", b), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK(files_equal(a, b));
    cli_run(ARGS(box, "-q", "--width", "32", "--height", "32", "--spp", "4", "--max-depth", "2", "--device", "cpu",
                 "--clamp", "0.001", "-o", a, "--stats"), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_STR_CONTAINS(r.out, "megakernel k_path");
    CHECK(strstr(r.out, "k_path_lanes") == NULL);
    cli_run(ARGS(box, "-q", "--width", "32", "--height", "32", "--spp", "4", "--max-depth", "2", "--device", "scalar",
                 "--clamp", "0.001", "-o", b), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK(files_equal(a, b));
    path_in_dir(b, sizeof b, "depth2.pfm");
    cli_run(ARGS(box, "-q", "--width", "32", "--height", "32", "--spp", "4", "--max-depth", "2", "--device", "cpu",
                 "-o", b), &r);
    CHECK(!files_equal(a, b));
}

static void test_refusals(void)
{
    char out[128];
    path_in_dir(out, sizeof out, "refused.png");
    cli_run(ARGS(bulb, "-o", out, "--clamp", "0"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --clamp expects a radiance limit in (0, 65536], got '0'\n");
    cli_run(ARGS(bulb, "-o", out, "--clamp", "1", "--integrator", "whitted"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --clamp limits the path tracer's indirect light (--integrator path); the "
                              "whitted integrator has none\n");
    CHECK(!file_exists(out));
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/clpt-test-clamp-XXXXXX");
    if (!mkdtemp(dir)) perror("mkdtemp");
    path_in_dir(bulb, sizeof bulb, "bulb.scene");
    FILE *f = fopen(bulb, "w");
    if (f) {
        fputs(bulb_text, f);
        fclose(f);
    }
    RUN(test_refusals);
    RUN(test_fireflies_removed);
    RUN(test_direct_light_untouched);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return harness_report();
}
