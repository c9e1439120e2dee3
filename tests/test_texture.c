/*
 * test_texture.c — texture lookups (kernels/material/texture.h) and image loading (host/io/texture.c):
 * the sRGB decoding and the other functions of kmath.h built from + - * / sqrt against
 * libm in double, bilinear filtering at known points, repeat, clamp and mirror per axis,
 * nearest, checkerboards,
 * the surface parameterisations, and reading images through stb_image.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"

#include "integrator/shade_path.h"     /* kernels/material/texture.h and what it needs, compiled as C */
#include "io/texture.h"    /* host/io/texture.h: this folder's include path finds host/ first */
#include "scene/texel_pack.h"
#include "texture_util.h"

#include <stb_image_write.h>

/* ---------------------------------------------------------------- kmath */

static void test_srgb_decode(void)
{
    double worst = 0.0;
    for (int i = 0; i < 256; i++) {
        double c = i / 255.0;
        double want = c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
        double got = k_srgb_to_linear((float)i / 255.0f);
        double e = fabs(got - want);
        if (e > worst) worst = e;
    }
    fprintf(stderr, "  sRGB decode: worst error %.3g over the 256 byte values\n", worst);
    CHECK(worst < 1e-6);
    CHECK(k_srgb_to_linear(0.0f) == 0.0f);
    CHECK(k_srgb_to_linear(1.0f) == 1.0f);                 /* white stays exactly white */
    CHECK_NEAR(k_srgb_to_linear(128.0f / 255.0f), 0.2158605, 1e-6);
    CHECK_NEAR(k_srgb_to_linear(0.04045f), 0.04045 / 12.92, 1e-9);
    /* texel_fetch reads the table tools/srgb_table.c wrote: the function's very bits */
    int differ = 0;
    for (int i = 0; i < 256; i++) {
        float f = k_srgb_to_linear((float)i / 255.0f);
        if (memcmp(&f, &srgb_to_linear_table[i], sizeof f)) differ++;
    }
    CHECK_EQ_INT(differ, 0);
}

static void test_exp_log_pow(void)
{
    double worst_log = 0.0, worst_exp = 0.0, worst_pow = 0.0;
    for (int i = 0; i < 20000; i++) {
        double x = pow(10.0, -30.0 + 60.0 * i / 20000.0);
        double want_log = log2((double)(float)x);
        double e = fabs(k_log2((float)x) - want_log) / (fabs(want_log) > 1.0 ? fabs(want_log) : 1.0);
        if (e > worst_log) worst_log = e;
        double y = -120.0 + 240.0 * i / 20000.0;
        double r = fabs(k_exp2((float)y) / exp2((double)(float)y) - 1.0);
        if (r > worst_exp) worst_exp = r;
        double b = (i % 1000 + 0.5) / 1000.0, n = (double)(i / 1000) * 13.0;   /* Phong: cos^n */
        double want = pow((double)(float)b, (double)(float)n);
        if (want > 1e-30) {
            double rp = fabs(k_pow((float)b, (float)n) / want - 1.0);
            if (rp > worst_pow) worst_pow = rp;
        }
    }
    fprintf(stderr, "  log2 error %.3g (relative above 1), exp2 rel error %.3g, pow rel error %.3g (exponents to 247)\n",
            worst_log, worst_exp, worst_pow);
    CHECK(worst_log < 3e-7);
    CHECK(worst_exp < 3e-7);
    CHECK(worst_pow < 2e-5);
    CHECK(k_pow(0.0f, 0.0f) == 1.0f && k_pow(0.0f, 3.0f) == 0.0f && k_pow(1.0f, 1e6f) == 1.0f);
    CHECK(k_pow(0.5f, 1.0f) == 0.5f || fabs(k_pow(0.5f, 1.0f) - 0.5) < 1e-7);
    CHECK(k_exp2(-200.0f) == 0.0f && isinf(k_exp2(200.0f)));
    CHECK(k_exp2(-140.0f) > 0.0f);                          /* subnormal results */
    CHECK(isinf(k_log2(0.0f)) && k_log2(0.0f) < 0.0f);
    CHECK_NEAR(k_log2(1e-40f), log2((double)1e-40f), 2e-5);  /* subnormal arguments (ulp 1.5e-5) */
    CHECK(k_exp2(0.0f) == 1.0f && k_exp2(3.0f) == 8.0f);
}

static void test_inverse_trig(void)
{
    double worst_atan2 = 0.0, worst_acos = 0.0;
    for (int i = 0; i < 20000; i++) {
        double a = 2.0 * M_PI * i / 20000.0 - M_PI;
        float y = (float)sin(a) * 3.0f, x = (float)cos(a) * 3.0f;
        double e = fabs(k_atan2(y, x) - atan2((double)y, (double)x));
        if (e > worst_atan2) worst_atan2 = e;
        float c = (float)(-1.0 + 2.0 * i / 19999.0);
        double ea = fabs(k_acos(c) - acos((double)c));
        if (ea > worst_acos) worst_acos = ea;
    }
    fprintf(stderr, "  atan2 abs error %.3g, acos abs error %.3g\n", worst_atan2, worst_acos);
    CHECK(worst_atan2 < 1e-6);
    CHECK(worst_acos < 1e-6);
    CHECK(k_atan2(0.0f, 0.0f) == 0.0f);
    CHECK_NEAR(k_atan2(0.0f, -1.0f), M_PI, 1e-6);
    CHECK_NEAR(k_atan2(-1.0f, 0.0f), -M_PI / 2, 1e-6);
    CHECK_NEAR(k_acos(2.0f), 0.0, 1e-7);                   /* clamped */
}

/* ---------------------------------------------------------------- lookups */

static Scene scene;
static RenderParams params;
static SceneView view;

/* A scene with no geometry, only textures, for evaluating lookups directly. */
static void view_setup(void)
{
    memset(&params, 0, sizeof params);
    memset(&view, 0, sizeof view);
    params.n_textures = (uint)scene.n_textures;
    view.params = &params;
    view.textures = scene.textures;
    view.texels = scene.texels;
}

/* A 2x2 float (linear) texture: top row (v near 1) red, green; bottom row blue, white. */
static uint float_texture(uint flags)
{
    float px[12] = { 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1 };
    uint bits[12], offset, index;
    memcpy(bits, px, sizeof bits);
    Error err = {0};
    CHECK(scene_add_texels(&scene, bits, 12, &offset, &err) == ST_OK);
    Texture t = texture_make_checker(v3s(0.0f), v3s(0.0f), 1.0f, 0);
    t.type = TEX_IMAGE;
    t.flags = TEX_FLOAT | flags;
    t.offset = offset;
    t.width = 2;
    t.height = 2;
    texture_set_scale_offset(&t, 1.0f, 1.0f, 0.0f, 0.0f);
    CHECK(scene_add_texture(&scene, NULL, NULL, t, &index, &err) == ST_OK);
    return index;
}

static int v3_near(vec3 a, double x, double y, double z, double tol)
{
    return fabs(a.x - x) <= tol && fabs(a.y - y) <= tol && fabs(a.z - z) <= tol;
}

static void test_bilinear_and_wrap(void)
{
    scene_init(&scene);
    uint rep = float_texture(0), clamp = float_texture(TEX_CLAMP);
    view_setup();
    Texture r = scene.textures[rep], c = scene.textures[clamp];
    /* texel centres give the texels exactly */
    CHECK(v3_near(texture_image(&view, r, 0.25f, 0.75f), 1, 0, 0, 0.0));
    CHECK(v3_near(texture_image(&view, r, 0.75f, 0.75f), 0, 1, 0, 0.0));
    CHECK(v3_near(texture_image(&view, r, 0.25f, 0.25f), 0, 0, 1, 0.0));
    CHECK(v3_near(texture_image(&view, r, 0.75f, 0.25f), 1, 1, 1, 0.0));
    /* the middle: the mean of the four */
    CHECK(v3_near(texture_image(&view, r, 0.5f, 0.5f), 0.5, 0.5, 0.5, 1e-7));
    /* between two centres, a quarter of the way: 3/4 of the nearer one */
    CHECK(v3_near(texture_image(&view, r, 0.375f, 0.75f), 0.75, 0.25, 0, 1e-7));
    /* the left edge: repeat blends with the right column, clamp does not */
    CHECK(v3_near(texture_image(&view, r, 0.0f, 0.75f), 0.5, 0.5, 0, 1e-7));
    CHECK(v3_near(texture_image(&view, c, 0.0f, 0.75f), 1, 0, 0, 0.0));
    /* far outside: repeat is periodic, clamp holds the edge texel */
    CHECK(v3_near(texture_image(&view, r, 7.25f, -2.25f), 1, 0, 0, 1e-6));
    CHECK(v3_near(texture_image(&view, c, 7.25f, -2.25f), 1, 1, 1, 0.0));
    CHECK(v3_near(texture_image(&view, r, -0.75f, 0.75f), 1, 0, 0, 1e-6));
    /* NaN coordinates do not crash or poison */
    vec3 n = texture_image(&view, r, NAN, NAN);
    CHECK(n.x == n.x && n.y == n.y && n.z == n.z);
    scene_free(&scene);
}

/* glTF's sampler modes per axis (texture.h): for u (or v) outside [0, 1], repeat keeps
 * the fraction, clamp the edge texel, mirror flips every other period (u = 1.25 reads as
 * 0.75, -0.25 as 0.25, 2.25 as 0.25); each axis on its own; nearest takes the texel the
 * point lies in. The 2 x 2 texture: top row red, green; bottom blue, white. */
static void test_wrap_modes(void)
{
    scene_init(&scene);
    uint rep = float_texture(0), mir = float_texture(TEX_MIRROR_U | TEX_MIRROR_V);
    uint cu = float_texture(TEX_CLAMP_U), mv = float_texture(TEX_MIRROR_V), near = float_texture(TEX_NEAREST);
    uint both = float_texture(TEX_CLAMP_U | TEX_MIRROR_U);
    view_setup();
    Texture r = scene.textures[rep], m = scene.textures[mir], c = scene.textures[cu], v = scene.textures[mv];
    Texture n = scene.textures[near], b = scene.textures[both];
    /* u outside [0, 1] on the top row's texel centres (v = 0.75) */
    CHECK(v3_near(texture_image(&view, r, 1.25f, 0.75f), 1, 0, 0, 1e-6));    /* repeat: 0.25, red */
    CHECK(v3_near(texture_image(&view, m, 1.25f, 0.75f), 0, 1, 0, 1e-6));    /* mirror: 0.75, green */
    CHECK(v3_near(texture_image(&view, m, -0.25f, 0.75f), 1, 0, 0, 1e-6));   /* mirror: 0.25, red */
    CHECK(v3_near(texture_image(&view, m, 2.25f, 0.75f), 1, 0, 0, 1e-6));    /* period 2: 0.25 */
    CHECK(v3_near(texture_image(&view, m, -1.25f, 0.75f), 0, 1, 0, 1e-6));   /* 0.75 */
    CHECK(v3_near(texture_image(&view, c, 1.25f, 0.75f), 0, 1, 0, 0.0));     /* clamp: the right edge */
    CHECK(v3_near(texture_image(&view, c, -7.0f, 0.75f), 1, 0, 0, 0.0));     /* ... and the left */
    CHECK(v3_near(texture_image(&view, b, 1.25f, 0.75f), 0, 1, 0, 0.0));     /* clamp wins over mirror */
    /* the mirror's edge: the edge texel twice, so no blend with the far side */
    CHECK(v3_near(texture_image(&view, m, 1.0f, 0.75f), 0, 1, 0, 0.0));
    CHECK(v3_near(texture_image(&view, r, 1.0f, 0.75f), 0.5, 0.5, 0, 1e-7));
    /* per axis: clamp u with v repeating (v = -0.75 is 0.25, the bottom row); mirror v
     * with u repeating (v = 1.25 is 0.75, the top row; u = 1.75 is 0.75) */
    CHECK(v3_near(texture_image(&view, c, 1.25f, -0.75f), 1, 1, 1, 1e-6));
    CHECK(v3_near(texture_image(&view, v, 1.75f, 1.25f), 0, 1, 0, 1e-6));
    CHECK(v3_near(texture_image(&view, r, 1.75f, 1.25f), 1, 1, 1, 1e-6));   /* repeat v: 0.25 */
    /* nearest: 0.4 lies in the left texel; bilinear blends 0.7 of it with 0.3 green */
    CHECK(v3_near(texture_image(&view, n, 0.4f, 0.75f), 1, 0, 0, 0.0));
    CHECK(v3_near(texture_image(&view, r, 0.4f, 0.75f), 0.7, 0.3, 0, 1e-6));
    CHECK(v3_near(texture_image(&view, n, 0.6f, 0.2f), 1, 1, 1, 0.0));
    CHECK(v3_near(texture_image(&view, n, -0.4f, 0.75f), 0, 1, 0, 0.0));   /* repeats: 0.6 */
    /* NaN and huge coordinates stay inside the image */
    vec3 q = texture_image(&view, m, NAN, 3e9f);
    CHECK(q.x == q.x && q.y == q.y && q.z == q.z);
    scene_free(&scene);
}

/* A map's infinite or huge coordinate (a transform of scale 1e308 is infinite as a
 * float; times u = 0 it is NaN) gives a defined texel: an infinity that repeats or
 * mirrors reads as 0, clamped it holds the edge, and nothing is NaN (issue 39: the
 * weights were NaN, and the NaN texel index was undefined behaviour). */
static void test_hostile_coordinates(void)
{
    scene_init(&scene);
    uint modes[4] = { float_texture(0), float_texture(TEX_MIRROR_U | TEX_MIRROR_V), float_texture(TEX_CLAMP),
                      float_texture(TEX_NEAREST) };
    view_setup();
    const float hostile[5] = { INFINITY, -INFINITY, NAN, 3e38f, -3e38f };
    for (int m = 0; m < 4; m++) {
        Texture t = scene.textures[modes[m]];
        for (int i = 0; i < 5; i++)
            for (int j = 0; j < 5; j++) {
                TexFootprint f = texture_footprint(t, hostile[i], hostile[j]);
                CHECK_MSG(f.xa < 2 && f.xb < 2 && f.ya < 2 && f.yb < 2 && f.fx == f.fx && f.fy == f.fy,
                          "mode %d at (%g, %g): texels x %u %u, y %u %u, weights %g %g", m, hostile[i], hostile[j],
                          f.xa, f.xb, f.ya, f.yb, f.fx, f.fy);
                vec3 c = texture_image(&view, t, hostile[i], hostile[j]);
                CHECK_MSG(isfinite(c.x) && isfinite(c.y) && isfinite(c.z), "mode %d at (%g, %g): (%g, %g, %g)", m,
                          hostile[i], hostile[j], c.x, c.y, c.z);
            }
        if (m == 2) continue;   /* clamped, +inf is the far edge */
        vec3 inf = texture_image(&view, t, INFINITY, -INFINITY), zero = texture_image(&view, t, 0.0f, 0.0f);
        CHECK_MSG(memcmp(&inf, &zero, sizeof inf) == 0, "mode %d: (inf, -inf) gives (%g, %g, %g), (0, 0) (%g, %g, %g)",
                  m, inf.x, inf.y, inf.z, zero.x, zero.y, zero.z);
    }
    scene_free(&scene);
}

static void test_srgb_texels(void)
{
    scene_init(&scene);
    uint px[2] = { 128u | 64u << 8 | 255u << 16 | 255u << 24, 0xffffffffu }, offset, a, b;
    Error err = {0};
    CHECK(scene_add_texels(&scene, px, 2, &offset, &err) == ST_OK);
    Texture t = texture_make_checker(v3s(0.0f), v3s(0.0f), 1.0f, 0);
    t.type = TEX_IMAGE;
    t.offset = offset;
    t.width = 2;
    t.height = 1;
    t.flags = TEX_SRGB;
    CHECK(scene_add_texture(&scene, NULL, NULL, t, &a, &err) == ST_OK);
    t.flags = 0;                                            /* the same bytes, linear */
    CHECK(scene_add_texture(&scene, NULL, NULL, t, &b, &err) == ST_OK);
    view_setup();
    vec3 s = texel_fetch(&view, scene.textures[a], 0, 0), l = texel_fetch(&view, scene.textures[b], 0, 0);
    CHECK_NEAR(s.x, 0.2158605, 1e-6);
    CHECK_NEAR(s.y, 0.0512695, 1e-6);
    CHECK(s.z == 1.0f);
    CHECK_NEAR(l.x, 128.0 / 255.0, 1e-7);
    CHECK_NEAR(l.y, 64.0 / 255.0, 1e-7);
    /* filtering happens after decoding: halfway between 0.2158 and 1 in linear terms */
    vec3 mid = texture_image(&view, scene.textures[a], 0.5f, 0.5f);
    CHECK_NEAR(mid.x, 0.5 * (0.2158605 + 1.0), 1e-6);
    scene_free(&scene);
}

static void test_checker(void)
{
    Texture t = texture_make_checker(v3(1, 0, 0), v3(0, 0, 1), 2.0f, 1);   /* cells 0.5 wide */
    CHECK(v3_near(texture_checker(t, v3(0.1f, 0.2f, 0.3f)), 1, 0, 0, 0.0));
    CHECK(v3_near(texture_checker(t, v3(1.1f, 0.2f, 0.3f)), 0, 0, 1, 0.0));
    CHECK(v3_near(texture_checker(t, v3(-0.1f, 0.2f, 0.3f)), 0, 0, 1, 0.0));
    CHECK(v3_near(texture_checker(t, v3(-0.1f, -0.2f, 0.3f)), 1, 0, 0, 0.0));
    CHECK(v3_near(texture_checker(t, v3(1e7f, 3.0f, 0.0f)), 0, 0, 1, 0.0));
    /* a solid checker through texture_eval: the matrix scales by 2 */
    scene_init(&scene);
    uint index;
    Error err = {0};
    CHECK(scene_add_texture(&scene, NULL, NULL, t, &index, &err) == ST_OK);
    view_setup();
    Surface s;
    memset(&s, 0, sizeof s);
    s.ng = v3(0, 1, 0);
    /* on the plane y = 0, exactly on a cell boundary: every point of a cell the same
     * colour whatever the rounding of y (the lookup is a hair below the surface) */
    int same = 1;
    for (int i = 0; i < 100; i++) {
        float y = (i % 3 - 1) * 1e-7f;
        s.p = v3(0.1f + 0.003f * (float)i, y, 0.2f);
        vec3 c = texture_eval(&view, index, s, s.ng);
        same &= v3_near(c, 0, 0, 1, 0.0);                   /* floor(-eps) = -1: odd */
    }
    CHECK(same);
    scene_free(&scene);
}

static void test_surface_uv(void)
{
    scene_init(&scene);
    Sphere sp = { v3(1, 2, 3), 2.0f, 0, NO_INDEX, 0, 0 };
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = v3(0, 1, 0);
    Error err = {0};
    scene_add_sphere(&scene, sp, &err);
    scene_add_plane(&scene, pl, &err);
    view_setup();
    params.n_spheres = 1;
    params.n_planes = 1;
    view.spheres = scene.spheres;
    view.planes = scene.planes;
    Surface s;
    memset(&s, 0, sizeof s);
    float u, v;
    s.prim = 0;
    s.ng = s.ngo = v3(0, 0, 1);                                     /* facing +z: the map's centre */
    surface_uv(&view, s, &u, &v);
    CHECK_NEAR(u, 0.5, 1e-6);
    CHECK_NEAR(v, 0.5, 1e-6);
    s.ng = s.ngo = v3(1, 0, 0);                                     /* +x: a quarter turn east */
    surface_uv(&view, s, &u, &v);
    CHECK_NEAR(u, 0.75, 1e-6);
    s.ng = s.ngo = v3(0, 1, 0);                                     /* north pole: the top row */
    surface_uv(&view, s, &u, &v);
    CHECK_NEAR(v, 1.0, 1e-6);
    s.ng = s.ngo = v3(0, -1, 0);
    surface_uv(&view, s, &u, &v);
    CHECK_NEAR(v, 0.0, 1e-6);
    /* the floor: u along +x, v along -z */
    s.prim = 1;
    s.ng = s.ngo = v3(0, 1, 0);
    s.p = v3(2.5f, 0.0f, -1.25f);
    surface_uv(&view, s, &u, &v);
    CHECK_NEAR(u, 2.5, 1e-6);
    CHECK_NEAR(v, 1.25, 1e-6);
    vec3 t = plane_tangent(v3(0, 0, 1));                    /* a wall facing +z: u along x */
    CHECK(v3_near(t, 1, 0, 0, 1e-7));
    t = plane_tangent(v3_norm(v3(1, 2, 3)));
    CHECK_NEAR(v3_dot(t, v3_norm(v3(1, 2, 3))), 0.0, 1e-6);
    CHECK_NEAR(v3_len(t), 1.0, 1e-6);
    scene_free(&scene);
}

/* ---------------------------------------------------------------- image files */

static char tmp_dir[64];

static void test_load_images(void)
{
    snprintf(tmp_dir, sizeof tmp_dir, "/tmp/clpt-test-texture-XXXXXX");
    CHECK(mkdtemp(tmp_dir) != NULL);
    char png[128], hdr[128], bad[128], missing[128];
    snprintf(png, sizeof png, "%s/a.png", tmp_dir);
    snprintf(hdr, sizeof hdr, "%s/a.hdr", tmp_dir);
    snprintf(bad, sizeof bad, "%s/bad.png", tmp_dir);
    snprintf(missing, sizeof missing, "%s/missing.png", tmp_dir);
    /* 3x2 RGB: distinct bytes per texel; row 0 is the top */
    unsigned char rgb[18];
    for (int i = 0; i < 18; i++) rgb[i] = (unsigned char)(i * 14);
    CHECK(stbi_write_png(png, 3, 2, 3, rgb, 9) != 0);
    float frgb[6] = { 0.5f, 2.0f, 7.0f, 0.25f, 0.125f, 1.0f };
    CHECK(stbi_write_hdr(hdr, 2, 1, 3, frgb) != 0);
    FILE *f = fopen(bad, "wb");
    if (f) {
        fputs("not an image", f);
        fclose(f);
    }

    scene_init(&scene);
    Error err = {0};
    uint a, b, c, h;
    CHECK_EQ_INT(texture_load_image(&scene, "grid", png, 0, 0, &a, &err), ST_OK);
    CHECK_EQ_INT(scene.n_texels, 6);
    Texture ta = scene.textures[a];
    CHECK(ta.type == TEX_IMAGE && ta.width == 3 && ta.height == 2 && ta.flags == TEX_SRGB);
    CHECK_EQ_INT(scene.texels[ta.offset + 4], 168u | 182u << 8 | 196u << 16 | 255u << 24);   /* x 1, y 1 */
    CHECK_EQ_INT(scene_find_texture(&scene, "grid"), a);
    /* the same file again shares the texels; a different encoding reads it again */
    CHECK_EQ_INT(texture_load_image(&scene, NULL, png, 0, 1, &b, &err), ST_OK);
    CHECK_EQ_INT(scene.n_texels, 6);
    CHECK(scene.textures[b].offset == ta.offset && scene.textures[b].flags == (TEX_SRGB | TEX_CLAMP));
    CHECK_EQ_INT(texture_load_image(&scene, NULL, png, 1, 0, &c, &err), ST_OK);
    CHECK_EQ_INT(scene.n_texels, 12);
    CHECK(scene.textures[c].flags == 0u);
    /* HDR: linear floats, 3 per texel */
    CHECK_EQ_INT(texture_load_image(&scene, NULL, hdr, 0, 0, &h, &err), ST_OK);
    Texture th = scene.textures[h];
    CHECK(th.flags == TEX_FLOAT && th.width == 2 && th.height == 1);
    view_setup();
    vec3 t0 = texel_fetch(&view, th, 0, 0);
    CHECK_NEAR(t0.x, 0.5, 0.01);          /* RGBE keeps 8 bits of mantissa */
    CHECK_NEAR(t0.y, 2.0, 0.02);
    CHECK_NEAR(t0.z, 7.0, 0.05);
    /* the 8-bit lookup decodes: texel (1, 1) holds bytes 168 182 196 */
    vec3 t1 = texel_fetch(&view, scene.textures[a], 1, 1);
    CHECK_NEAR(t1.x, pow((168 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
    /* errors */
    CHECK_EQ_INT(texture_load_image(&scene, NULL, missing, 0, 0, &a, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "cannot open");
    CHECK_STR_CONTAINS(err.msg, "missing.png");
    CHECK_EQ_INT(texture_load_image(&scene, NULL, bad, 0, 0, &a, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "not an image");
    /* a PNG chunk longer than the file is refused before stb_image reserves it (the
     * fuzzer's input declares a 1.5 GB IDAT in 8 KB) */
    CHECK_EQ_INT(texture_load_image(&scene, NULL, "tests/data/fuzz/texture/png-idat-length-stb-oom", 0, 0, &a, &err),
                 ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "the PNG chunk 'IDAT' at byte offset 33 declares 1560307124 bytes, more than the");
    /* so is a PNG cut short inside a chunk */
    long png_size = 0;
    unsigned char png_bytes[512];
    if ((f = fopen(png, "rb")) != NULL) {
        png_size = (long)fread(png_bytes, 1, sizeof png_bytes, f);
        fclose(f);
    }
    CHECK(png_size > 40);
    if ((f = fopen(bad, "wb")) != NULL) {
        fwrite(png_bytes, 1, (size_t)png_size - 20, f);
        fclose(f);
    }
    CHECK_EQ_INT(texture_load_image(&scene, NULL, bad, 0, 0, &a, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "(a truncated or corrupt file)");
    error_clear(&err);
    scene_free(&scene);
    unlink(png);
    unlink(hdr);
    unlink(bad);
    rmdir(tmp_dir);
}

/* The 4x3 pictures of tests/data/images/generate.py in every format stb_image reads
 * without compression or with run-length packets decode to the same texels, and every
 * shorter prefix of the TGA, BMP, PSD and HDR files is refused: stb_image decoded those
 * with uninitialised or zero pixels. */
static void test_truncated_images(void)
{
    static const char *const names[] = { "tiny.tga", "tiny-rle.tga", "tiny.bmp", "tiny.psd", "tiny-rle.psd",
                                         "tiny.hdr", "tiny-rle.hdr" };
    char cut_path[512];
    test_tmp_path(cut_path, sizeof cut_path, "clpt-test-cut.img");
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        char path[128];
        snprintf(path, sizeof path, "tests/data/images/%s", names[i]);
        unsigned char bytes[256];
        size_t size = 0;
        FILE *f = fopen(path, "rb");
        if (f) {
            size = fread(bytes, 1, sizeof bytes, f);
            fclose(f);
        }
        CHECK_MSG(size > 0, "%s", path);
        scene_init(&scene);
        Error err = { 0 };
        uint t;
        Status st = texture_load_image(&scene, NULL, path, 1, 0, &t, &err);
        CHECK_MSG(st == ST_OK, "%s: %s", path, err.msg);
        int is_hdr = strstr(names[i], ".hdr") != NULL;
        if (st == ST_OK && !is_hdr) {
            Texture tx = scene.textures[t];
            CHECK_EQ_INT(tx.width, 4);
            CHECK_EQ_INT(tx.height, 3);
            for (uint y = 0; y < 3 && tx.width == 4 && tx.height == 3; y++)
                for (uint x = 0; x < 4; x++) {
                    uint want = (x * 60) % 256 | ((y * 90) % 256) << 8 | (((x + y) * 40) % 256) << 16 | 255u << 24;
                    CHECK_MSG(scene.texels[tx.offset + y * 4 + x] == want, "%s: texel %u %u", path, x, y);
                }
        }
        scene_free(&scene);
        for (size_t cut = 1; cut < size; cut++) {
            if ((f = fopen(cut_path, "wb")) == NULL) break;
            fwrite(bytes, 1, cut, f);
            fclose(f);
            scene_init(&scene);
            st = texture_load_image(&scene, NULL, cut_path, 1, 0, &t, &err);
            CHECK_MSG(st == ST_INPUT, "%s cut to %zu bytes: status %d", path, cut, (int)st);
            scene_free(&scene);
            error_clear(&err);
        }
    }
    unlink(cut_path);
}

/* ------------------------------------------------------------ RGBE packing */

/* Every pixel stb_image can make of a Radiance file (mantissa bytes times ldexp(1, e -
 * 136)) has an RGBE word that decodes to the same float bits once e is at least 18 (a
 * smaller e with small mantissas needs a scale below the packer's lowest, and stays
 * float); values RGBE cannot hold have none. */
static void test_rgbe_words(void)
{
    int wrong = 0, packed = 0, missing = 0;
    for (uint e = 0; e < 256; e++)
        for (uint k = 0; k < 97; k++) {
            uint m[3] = { (k * 37u + e) & 255u, (k * 91u) & 255u, (k * 13u + 7u * e) & 255u };
            if (k == 0) m[0] = m[1] = m[2] = 0;
            if (k == 1) m[0] = m[1] = m[2] = 255;
            float f1 = e ? (float)ldexp(1.0f, (int)e - 136) : 0.0f; /* stb: 0 when e is 0 */
            float c[3] = { (float)m[0] * f1, (float)m[1] * f1, (float)m[2] * f1 };
            uint w;
            if (!rgbe_encode_exact(c, &w)) {
                missing += e >= 18 || k == 0;
                continue;
            }
            packed++;
            vec3 d = rgbe_decode(w);
            float back[3] = { d.x, d.y, d.z };
            wrong += memcmp(back, c, sizeof back) != 0;
            wrong += (w >> 24) < 10u;
        }
    fprintf(stderr, "  %d of %d stb_image pixels packed exactly\n", packed, 256 * 97);
    CHECK_EQ_INT(wrong, 0);
    CHECK_EQ_INT(missing, 0);
    CHECK(packed >= (256 - 18) * 97);
    uint w = 7u;
    CHECK(rgbe_encode_exact((float[3]){ 0.0f, 0.0f, 0.0f }, &w) && w == 10u << 24);
    CHECK(rgbe_encode_exact((float[3]){ 1.0f, 0.5f, 0.0f }, &w) && w == (129u << 24 | 64u << 8 | 128u));
    CHECK(rgbe_encode_exact((float[3]){ 255.0f * 0x1p119f, 0.0f, 1.0f * 0x1p119f }, &w) && w >> 24 == 255u);
    const float bad[][3] = { { 0.1f, 0.0f, 0.0f },          /* not a dyadic fraction of 8 bits */
                             { 1.0f, 1.0f / 512.0f, 0.0f },  /* below the shared exponent's last bit */
                             { 257.0f, 0.0f, 0.0f },         /* nine bits of mantissa */
                             { -1.0f, 0.0f, 0.0f },
                             { -0.0f, 0.0f, 0.0f },          /* would come back as +0 */
                             { INFINITY, 0.0f, 0.0f },
                             { NAN, 0.0f, 0.0f },
                             { 0x1p-130f, 0.0f, 0.0f } };     /* a scale below 2^-126 */
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) CHECK_MSG(!rgbe_encode_exact(bad[i], &w), "case %zu", i);
}

/* scene_pack_texels: exact float images become RGBE words (sharing textures keep
 * sharing), the others are copied, every texel reads as before, and a second pass
 * changes nothing. Then an .hdr file read through stb_image packs. */
static void test_pack_texels(void)
{
    scene_init(&scene);
    uint rgba[2] = { 0x11223344u, 0xff804020u };
    float exact[12] = { 1.0f, 0.5f, 0.0f, 3.0f, 0.5f, 96.0f, 0.0f, 0.0f, 0.0f, 0x1p-20f, 0x1p-19f, 0x1p-13f };
    float inexact[6] = { 0.1f, 0.2f, 0.3f, 1.0f, 1.0f, 1.0f };
    float one[3] = { 1024.0f, 4096.0f, 2048.0f };
    uint ew[12], iw[6], ow[3];
    memcpy(ew, exact, sizeof ew);
    memcpy(iw, inexact, sizeof iw);
    memcpy(ow, one, sizeof ow);
    uint t[5];
    t[0] = test_image_texture(&scene, rgba, 2, 1, TEX_SRGB);
    t[1] = test_image_texture(&scene, ew, 2, 2, TEX_FLOAT);
    t[2] = t[1] + 1u;   /* the same texels, read another way (as texture_load_image shares them) */
    Texture shared = scene.textures[t[1]];
    shared.flags |= TEX_CLAMP | TEX_NEAREST;
    CHECK(scene_add_texture(&scene, NULL, NULL, shared, &t[2], NULL) == ST_OK);
    t[3] = test_image_texture(&scene, iw, 2, 1, TEX_FLOAT);
    t[4] = test_image_texture(&scene, ow, 1, 1, TEX_FLOAT | TEX_MIRROR_U);
    scene_add_texture(&scene, "checks", NULL, texture_make_checker(v3s(1.0f), v3s(0.0f), 2.0f, 0), NULL, NULL);
    CHECK_EQ_INT(scene.n_texels, 2 + 12 + 6 + 3);
    vec3 before[5][4];
    view_setup();
    for (int i = 0; i < 5; i++)
        for (uint j = 0; j < scene.textures[t[i]].width * scene.textures[t[i]].height; j++)
            before[i][j] = texel_fetch(&view, scene.textures[t[i]], j % scene.textures[t[i]].width,
                                       j / scene.textures[t[i]].width);
    Error err = { 0 };
    for (int pass = 0; pass < 2; pass++) {
        CHECK_EQ_INT(scene_pack_texels(&scene, &err), ST_OK);
        CHECK_EQ_INT(scene.n_texels, 2 + 4 + 6 + 1);
        uint want_flags[5] = { TEX_SRGB, TEX_FLOAT | TEX_RGBE, TEX_FLOAT | TEX_RGBE | TEX_CLAMP | TEX_NEAREST,
                               TEX_FLOAT, TEX_FLOAT | TEX_RGBE | TEX_MIRROR_U };
        for (int i = 0; i < 5; i++) CHECK_EQ_INT(scene.textures[t[i]].flags, want_flags[i]);
        CHECK_EQ_INT(scene.textures[t[0]].offset, 0);
        CHECK_EQ_INT(scene.textures[t[1]].offset, 2);
        CHECK_EQ_INT(scene.textures[t[2]].offset, 2);
        CHECK_EQ_INT(scene.textures[t[3]].offset, 6);
        CHECK_EQ_INT(scene.textures[t[4]].offset, 12);
        CHECK_EQ_INT(scene.texels[12], 141u << 24 | 64u << 16 | 128u << 8 | 32u);   /* 1024 = 32 * 2^5 */
        view_setup();
        int differ = 0;
        for (int i = 0; i < 5; i++)
            for (uint j = 0; j < scene.textures[t[i]].width * scene.textures[t[i]].height; j++) {
                vec3 a = texel_fetch(&view, scene.textures[t[i]], j % scene.textures[t[i]].width,
                                     j / scene.textures[t[i]].width);
                differ += memcmp(&a, &before[i][j], sizeof a) != 0;
            }
        CHECK_EQ_INT(differ, 0);
        CHECK(texel_alpha(&view, scene.textures[t[1]], 1, 1) == 1.0f);
    }
    scene_free(&scene);

    /* a Radiance file, as the environment maps are */
    scene_init(&scene);
    uint h;
    CHECK_EQ_INT(texture_load_image(&scene, NULL, "tests/data/images/tiny-rle.hdr", 0, 0, &h, &err), ST_OK);
    size_t floats = scene.n_texels;
    view_setup();
    Texture th = scene.textures[h];
    vec3 corner = texel_fetch(&view, th, th.width - 1u, th.height - 1u);
    CHECK_EQ_INT(scene_pack_texels(&scene, &err), ST_OK);
    CHECK_EQ_INT(scene.textures[h].flags, TEX_FLOAT | TEX_RGBE);
    CHECK_EQ_INT(scene.n_texels * 3u, floats);
    view_setup();
    vec3 packed = texel_fetch(&view, scene.textures[h], th.width - 1u, th.height - 1u);
    CHECK(memcmp(&corner, &packed, sizeof corner) == 0);
    scene_free(&scene);
}

int main(void)
{
    RUN(test_srgb_decode);
    RUN(test_exp_log_pow);
    RUN(test_inverse_trig);
    RUN(test_bilinear_and_wrap);
    RUN(test_wrap_modes);
    RUN(test_hostile_coordinates);
    RUN(test_srgb_texels);
    RUN(test_checker);
    RUN(test_surface_uv);
    RUN(test_load_images);
    RUN(test_truncated_images);
    RUN(test_rgbe_words);
    RUN(test_pack_texels);
    return harness_report();
}
