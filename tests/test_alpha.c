/*
 * test_alpha.c — see-through principled surfaces (alpha_mode mask and blend,
 * kernels/accel/alpha.h) and principled emission textures, rendered whole: analytic pixels
 * for a mask, the expected mean of a blend, and PoCL against the scalar device bit for
 * bit. Run from the project root.
 *
 * The scenes look straight down at a diffuse floor (albedo 0.5) under a directional
 * light of irradiance pi, through quads at height 1; depth 1 (direct light only). A floor
 * point lit through a hole has radiance 0.5 / pi * pi = 0.5; a shadowed one, 0. The
 * quads' tops are black metal (F0 = 0), which reflects almost nothing.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <stb_image_write.h>

#include "harness.h"
#include "util/kmath.h"
#include "render_util.h"

static char tmp_dir[64];

/* tmp_dir/name, in a static buffer (one path in use at a time). */
static const char *tmp_path(const char *name)
{
    static char path[128];
    snprintf(path, sizeof path, "%s/%s", tmp_dir, name);
    return path;
}

static void write_text(const char *name, const char *text)
{
    FILE *f = fopen(tmp_path(name), "wb");
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

/* A 1x1 RGBA PNG. */
static void write_png1(const char *name, unsigned char r, unsigned char g, unsigned char b, unsigned char a)
{
    unsigned char px[4] = { r, g, b, a };
    CHECK(stbi_write_png(tmp_path(name), 1, 1, 4, px, 4) != 0);
}

#define SCENE_HEAD                                                                     \
    "camera { from 0 2 0 at 0 0 0 up 0 0 -1 fov 30 }\n"                                \
    "material floor { type diffuse albedo 0.5 0.5 0.5 }\n"                             \
    "plane { point 0 0 0 normal 0 1 0 material floor }\n"                              \
    "light { type directional direction 0 -1 0 intensity 3.14159265 3.14159265 3.14159265 }\n"

/* Left (x < -0.05): alpha 0.3 under the default cutoff 0.5, cut out. Right, top half
 * of the image (z < 0): alpha 0.7 over a cutoff 0.6, opaque. Right, bottom half:
 * alpha 1 times a texture whose alpha channel is 0, cut out. The camera's image x is
 * world +x and its top is world -z. */
static const char mask_scene[] = "image { width 32 height 32 spp 16 depth 1 seed 3 }\n" SCENE_HEAD
    "texture clear { type image file \"clear.png\" encoding linear }\n"
    "material hole { type principled albedo 0 0 0 metallic 1 alpha 0.3 alpha_mode mask }\n"
    "material solid { type principled albedo 0 0 0 metallic 1 alpha 0.7 alpha_mode mask alpha_cutoff 0.6 }\n"
    "material cut { type principled albedo 1 1 1 metallic 1 texture clear alpha_mode mask }\n"
    "quad { v0 -3 1 -3  v1 -3 1 3  v2 -0.05 1 3  v3 -0.05 1 -3  material hole }\n"
    "quad { v0 0.05 1 -3  v1 0.05 1 0  v2 3 1 0  v3 3 1 -3  material solid }\n"
    "quad { v0 0.05 1 0  v1 0.05 1 3  v2 3 1 3  v3 3 1 0  material cut }\n";

/* One quad over the whole view, kept by a ray with probability 0.4: a camera ray
 * reaches the floor with probability 0.6 and the floor's shadow ray gets out with
 * probability 0.6, so the mean is 0.5 x 0.36 = 0.18 (plus the black metal's ~0). */
#define BLEND_BODY                                                                     \
    SCENE_HEAD                                                                         \
    "material veil { type principled albedo 0 0 0 metallic 1 alpha 0.4 alpha_mode blend }\n" \
    "quad { v0 -3 1 -3  v1 -3 1 3  v2 3 1 3  v3 3 1 -3  material veil }\n"
static const char blend_scene[] = "image { width 32 height 32 spp 16 depth 1 seed 3 }\n" BLEND_BODY;
/* 256 spp: the per-sample standard deviation 0.5 x sqrt(0.36 x 0.64) = 0.24 over
 * 32 x 32 x 256 samples leaves 0.0005 on the mean */
static const char blend_scene_256[] = "image { width 32 height 32 spp 256 depth 1 seed 3 }\n" BLEND_BODY;

/* A glowing principled quad facing the camera, emission 2 times a linear texture
 * (128, 64, 255)/255, over a black background: the pixels are that, exactly. */
static const char glow_scene[] =
    "image { width 16 height 16 spp 4 depth 2 seed 3 }\n"
    "camera { from 0 2 0 at 0 0 0 up 0 0 -1 fov 30 }\n"
    "texture glow { type image file \"glow.png\" encoding linear }\n"
    "material lamp { type principled albedo 0 0 0 metallic 1 emission 1 1 1 strength 2 emission_texture glow }\n"
    "quad { v0 -3 1 -3  v1 -3 1 3  v2 3 1 3  v3 3 1 -3  material lamp }\n";

/* Loads scene text `text` (written as tmp_dir/name) and renders it on `devices`. */
static Status render_text(const char *name, const char *text, const char *devices, Film *film, Error *err)
{
    write_text(name, text);
    Scene s;
    scene_init(&s);
    Status st = scene_load(tmp_path(name), &s, err);
    if (!st) st = render_util_run(&s, devices, 0, film, err);
    scene_free(&s);
    return st;
}

/* Pixel (x, y)'s red channel (top row first). */
static float pixel_r(const float *rgb, uint width, uint x, uint y)
{
    return rgb[3u * (y * width + x)];
}

static void check_mask(const char *devices)
{
    Film f;
    Error err = { 0 };
    Status st = render_text("mask.scene", mask_scene, devices, &f, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) {
        float *rgb = malloc((size_t)f.width * f.height * 3u * sizeof *rgb);
        film_resolve(&f, rgb);
        /* away from the quads' edges (x = +-0.05 at height 1, z = 0): 3 pixels */
        int lit_bad = 0, dark_bad = 0, lit = 0, dark = 0;
        for (uint y = 0; y < f.height; y++)
            for (uint x = 0; x < f.width; x++) {
                if ((x >= 13 && x <= 18) || (x > 16 && y >= 13 && y <= 18)) continue;
                float r = pixel_r(rgb, f.width, x, y);
                if (x > 16 && y < 16) {
                    dark++;
                    dark_bad += !(r >= 0.0f && r < 1e-3f);
                } else {
                    lit++;
                    lit_bad += !(k_fabs(r - 0.5f) < 1e-5f);
                }
            }
        fprintf(stderr, "  mask on %s: %d lit pixels (0.5), %d not; %d dark (the opaque quad), %d not\n",
                devices, lit - lit_bad, lit_bad, dark - dark_bad, dark_bad);
        CHECK(lit > 400 && dark > 100);
        CHECK_EQ_INT(lit_bad, 0);
        CHECK_EQ_INT(dark_bad, 0);
        free(rgb);
    }
    film_free(&f);
    error_clear(&err);
}

static void test_mask_scalar(void) { check_mask("scalar"); }
static void test_mask_opencl(void) { check_mask(TEST_OPENCL); }

static void test_blend_mean(void)
{
    Film f;
    Error err = { 0 };
    Status st = render_text("blend.scene", blend_scene_256, "scalar", &f, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) {
        double mean = film_mean(&f);
        fprintf(stderr, "  blend alpha 0.4: image mean %.5f (expected 0.18 +- 0.0005)\n", mean);
        CHECK_NEAR(mean, 0.18, 0.0025);
    }
    film_free(&f);
    error_clear(&err);
}

static void test_emission_texture(void)
{
    Film f;
    Error err = { 0 };
    Status st = render_text("glow.scene", glow_scene, "scalar", &f, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) {
        float *rgb = malloc((size_t)f.width * f.height * 3u * sizeof *rgb);
        film_resolve(&f, rgb);
        int bad = 0;
        for (uint i = 0; i < f.width * f.height; i++)
            bad += !(k_fabs(rgb[3 * i] - 2.0f * 128.0f / 255.0f) < 1e-5f &&
                     k_fabs(rgb[3 * i + 1] - 2.0f * 64.0f / 255.0f) < 1e-5f &&
                     k_fabs(rgb[3 * i + 2] - 2.0f) < 1e-5f);
        fprintf(stderr, "  emission texture: pixel 0 = %.5f %.5f %.5f (expected %.5f %.5f 2)\n", rgb[0], rgb[1],
                rgb[2], 2.0 * 128.0 / 255.0, 2.0 * 64.0 / 255.0);
        CHECK_EQ_INT(bad, 0);
        free(rgb);
    }
    film_free(&f);
    error_clear(&err);
}

/* Every scene above on PoCL and the scalar device: the same film, bit for bit. */
static void test_opencl_matches_scalar(void)
{
    static const struct {
        const char *name, *text;
    } scenes[] = { { "mask.scene", mask_scene }, { "blend.scene", blend_scene }, { "glow.scene", glow_scene } };
    for (size_t k = 0; k < sizeof scenes / sizeof scenes[0]; k++) {
        Film fa, fb;
        Error err = { 0 };
        Status sa = render_text(scenes[k].name, scenes[k].text, TEST_OPENCL, &fa, &err);
        CHECK_MSG(sa == ST_OK, "%s", err.msg);
        Status sb = render_text(scenes[k].name, scenes[k].text, "scalar", &fb, &err);
        CHECK_MSG(sb == ST_OK, "%s", err.msg);
        if (sa == ST_OK && sb == ST_OK) {
            size_t n = (size_t)fa.width * fa.height * 3u, same = 0;
            for (size_t i = 0; i < n; i++) same += fa.sum[i] == fb.sum[i];
            fprintf(stderr, "  %s: %zu of %zu channel sums identical on OpenCL and scalar\n", scenes[k].name, same, n);
            CHECK(same == n);
        }
        film_free(&fa);
        film_free(&fb);
        error_clear(&err);
    }
}

int main(void)
{
    snprintf(tmp_dir, sizeof tmp_dir, "/tmp/clpt-alpha-XXXXXX");
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    write_png1("clear.png", 200, 200, 200, 0);
    write_png1("glow.png", 128, 64, 255, 255);
    RUN(test_mask_scalar);
    RUN(test_mask_opencl);
    RUN(test_blend_mean);
    RUN(test_emission_texture);
    RUN(test_opencl_matches_scalar);
    static const char *const files[] = { "clear.png", "glow.png", "mask.scene", "blend.scene", "glow.scene" };
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) unlink(tmp_path(files[i]));
    rmdir(tmp_dir);
    return harness_report();
}
