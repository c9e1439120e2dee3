/*
 * test_cubemap.c — `cubeMap DIR` backgrounds (kernels/light/background.h, the course's
 * CubeMap): six solid-colour faces written for the test; a camera looking along each
 * axis sees exactly that face's bytes at its centre pixel, in the classic ray tracer and
 * in the path tracer; a mirror sphere shows the face behind the camera; the face
 * orientation of the lookup; the same bits on PoCL and the scalar device; and the
 * errors for a missing face or a folder that is not one. In the path tracer the cube
 * map is resampled into an environment light (host/scene/cube_env.c): the resampled
 * texels of a uniform map, a furnace, MIS against light and BSDF sampling alone, and
 * PoCL against the scalar device on a render lit by it.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "harness.h"
#include "render_util.h"

#include "io/classic_parse.h"
#include "io/scene_load.h"
#include "io/texture.h"
#include "scene/cube_env.h"
#include "light/background.h"

#include <stb_image_write.h>

static char dir[64];           /* a temporary folder for this test's files */

/* The faces' colours as bytes, in the order of enum CubeFace. */
static const unsigned char face_rgb[6][3] = {
    { 200, 10, 20 },   /* left   -x */
    { 10, 200, 30 },   /* right  +x */
    { 40, 50, 210 },   /* up     +y */
    { 250, 250, 5 },   /* down   -y */
    { 60, 120, 180 },  /* front  +z */
    { 90, 30, 150 },   /* back   -z */
};
static const char *const face_name[6] = { "left", "right", "up", "down", "front", "back" };

/* Writes DIR/sub/NAME.png for every face but `skip` (-1: none), each w x h of its colour
 * (h x w images of one colour: orientation cannot show; test_orientation pins it), or
 * all of colour `uniform` where that is not NULL. */
static void write_faces_of(const char *sub, int skip, const unsigned char *uniform)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, sub);
    mkdir(path, 0755);
    for (int f = 0; f < 6; f++) {
        if (f == skip) continue;
        unsigned char px[2 * 3 * 3];
        for (int i = 0; i < 6; i++) memcpy(px + 3 * i, uniform ? uniform : face_rgb[f], 3);
        snprintf(path, sizeof path, "%s/%s/%s.png", dir, sub, face_name[f]);
        stbi_write_png(path, 3, 2, 3, px, 9);
    }
}

static void write_faces(const char *sub, int skip) { write_faces_of(sub, skip, NULL); }

static Status load_text(const char *text, Scene *s, Error *err)
{
    char path[256];
    snprintf(path, sizeof path, "%s/scene.txt", dir);
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    scene_init(s);
    memset(err, 0, sizeof *err);
    return classic_load(path, s, err);
}

/* Renders s on `devices`; the linear film (no gamma: classic output) in a new array. */
static float *render(Scene *s, const char *devices)
{
    Film film;
    Error err = {0};
    Status st = render_util_run(s, devices, 0, &film, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    size_t n = (size_t)film.width * film.height * 3u;
    float *rgb = calloc(n ? n : 1, sizeof *rgb);
    if (st == ST_OK) film_resolve(&film, rgb);
    film_free(&film);
    error_clear(&err);
    return rgb;
}

/* The 8-bit value the linear writers give (image_write.c: floor(x 255 + 0.5)). */
static int byte_of(float x) { return (int)floor((double)x * 255.0 + 0.5); }

/* Pixel `px` of both renders is face f's colour (within the film's 2^-24 steps and to
 * the byte), and PoCL gave the scalar device's bits. */
static void check_pixel(const float *a, const float *b, size_t n, size_t px, int f, const char *what)
{
    for (int c = 0; c < 3; c++) {
        float v = a[3 * px + (size_t)c];
        CHECK_MSG(fabs((double)v - face_rgb[f][c] / 255.0) < 1e-6, "%s: channel %d is %.9f, the %s face has %d",
                  what, c, (double)v, face_name[f], face_rgb[f][c]);
        CHECK_EQ_INT(byte_of(v), face_rgb[f][c]);
    }
    CHECK_MSG(memcmp(a, b, n * sizeof *a) == 0, "%s: PoCL and the scalar device differ", what);
}

/* A camera at the origin looking along each axis: the centre pixel of a 5x5 image is
 * that face's colour, in both integrators, on both devices. */
static void test_axes(void)
{
    static const struct { const char *dir, *up; int face; } views[] = {
        { "-1 0 0", "0 1 0", CUBE_LEFT }, { "1 0 0", "0 1 0", CUBE_RIGHT },
        { "0 1 0", "0 0 -1", CUBE_UP },   { "0 -1 0", "0 0 1", CUBE_DOWN },
        { "0 0 1", "0 1 0", CUBE_FRONT }, { "0 0 -1", "0 1 0", CUBE_BACK },
    };
    for (size_t i = 0; i < sizeof views / sizeof views[0]; i++)
        for (int path = 0; path < 2; path++) {
            char text[512], what[96];
            snprintf(text, sizeof text,
                     "PerspectiveCamera { center 0 0 0 direction %s up %s angle 30 width 5 height 5 }\n"
                     "Background { color 0.5 0.5 0.5 cubeMap cube }\n"
                     "Group { numObjects 0 }\n", views[i].dir, views[i].up);
            snprintf(what, sizeof what, "looking along %s, %s", views[i].dir, path ? "path tracer" : "whitted");
            Scene s;
            Error err;
            CHECK_EQ_INT(load_text(text, &s, &err), ST_OK);
            CHECK_EQ_INT(s.bg_type, BG_CUBEMAP);
            CHECK_EQ_INT(s.n_textures, 6);
            if (path) {
                s.integrator = INTEGRATOR_PATH;
                s.image.spp = 4;
            }
            float *a = render(&s, "scalar"), *b = render(&s, TEST_OPENCL);
            /* the path tracer resampled the cube map into an environment light */
            CHECK_EQ_INT(s.bg_type, path ? BG_MAP : BG_CUBEMAP);
            CHECK(path ? s.env_light != NO_INDEX : s.env_light == NO_INDEX);
            check_pixel(a, b, 5 * 5 * 3, 2 * 5 + 2, views[i].face, what);
            free(a);
            free(b);
            scene_free(&s);
            error_clear(&err);
        }
}

/* A mirror sphere in front of a camera looking down -z: the centre pixel's rays come
 * back within a few degrees of +z and show the front face (the pixels are small enough
 * that the path tracer's jitter keeps them there); the corners miss the sphere and
 * see the back face. */
static void test_mirror(void)
{
    for (int path = 0; path < 2; path++) {
        Scene s;
        Error err;
        CHECK_EQ_INT(load_text("PerspectiveCamera { center 0 0 5 direction 0 0 -1 up 0 1 0 angle 60 "
                               "width 41 height 41 }\n"
                               "Background { color 0 0 0 cubeMap cube }\n"
                               "Materials { numMaterials 1 PhongMaterial { diffuseColor 0 0 0 "
                               "reflectiveColor 1 1 1 } }\n"
                               "Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }\n",
                               &s, &err), ST_OK);
        if (path) s.integrator = INTEGRATOR_PATH;
        float *a = render(&s, "scalar"), *b = render(&s, TEST_OPENCL);
        check_pixel(a, b, 41 * 41 * 3, 20 * 41 + 20, CUBE_FRONT, path ? "mirror, path tracer" : "mirror, whitted");
        /* a corner pixel misses the sphere: the back face */
        check_pixel(a, b, 41 * 41 * 3, 0, CUBE_BACK, path ? "corner, path tracer" : "corner, whitted");
        free(a);
        free(b);
        scene_free(&s);
        error_clear(&err);
    }
}

/* The lookup itself on 2x2 faces whose four texels differ: the course's (u, v) per face
 * (v = 1 is the image's top row) and its corner-aligned bilinear filter. */
static void test_orientation(void)
{
    Scene s;
    scene_init(&s);
    /* texel (i, j) of face f: red = 10 f + 1 + i + 2 j (row j = 0 is the file's top) */
    for (uint f = 0; f < 6; f++) {
        uint px[4], offset, index;
        for (uint k = 0; k < 4; k++) px[k] = 10u * f + 1u + k;
        CHECK_EQ_INT(scene_add_texels(&s, px, 4, &offset, NULL), ST_OK);
        Texture t = texture_make_checker(v3s(0.0f), v3s(0.0f), 1.0f, 0);
        t.type = TEX_IMAGE;
        t.flags = TEX_CLAMP;
        t.offset = offset;
        t.width = 2;
        t.height = 2;
        CHECK_EQ_INT(scene_add_texture(&s, NULL, NULL, t, &index, NULL), ST_OK);
    }
    RenderParams p;
    memset(&p, 0, sizeof p);
    p.bg_type = BG_CUBEMAP;
    p.bg_cubemap = 0;
    SceneView v;
    memset(&v, 0, sizeof v);
    v.params = &p;
    v.textures = s.textures;
    v.texels = s.texels;
    /* Directions whose (u, v) put the lookup on one texel exactly: u = 0.75 gives x = 1.5,
     * column 1 (the next one clamped to it, half each); v = 1 gives y = 0 (row 0, the top)
     * and v = 0.25 or 0 gives y >= 1.5 (row 1, the bottom). Ties go to x, then y, so the
     * front and back faces cannot reach v = 1. Texel numbers as written above. */
    static const struct { float x, y, z; uint face, texel; } cases[] = {
        { 1.0f, 1.0f, 0.5f, CUBE_RIGHT, 1 },      /* u (z/x + 1)/2 = 0.75, v (y/x + 1)/2 = 1 */
        { 1.0f, -1.0f, 0.5f, CUBE_RIGHT, 3 },     /* v 0 */
        { -1.0f, 1.0f, -0.5f, CUBE_LEFT, 1 },     /* u 0.75, v 1 - (y/x + 1)/2 = 1 */
        { 0.5f, 1.0f, 1.0f, CUBE_UP, 1 },         /* u (x/y + 1)/2 = 0.75, v (z/y + 1)/2 = 1 */
        { 0.5f, -1.0f, 1.0f, CUBE_DOWN, 1 },      /* u 1 - (x/y + 1)/2 = 0.75, v 1 */
        { -0.5f, -0.5f, 1.0f, CUBE_FRONT, 3 },    /* u 1 - (x/z + 1)/2 = 0.75, v 0.25 */
        { -0.5f, -0.5f, -1.0f, CUBE_BACK, 3 },    /* u (x/z + 1)/2 = 0.75, v 1 - 0.75 */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        vec3 c = cubemap_lookup(&v, v3(cases[i].x, cases[i].y, cases[i].z));
        float want = (float)(10u * cases[i].face + 1u + cases[i].texel) / 255.0f;
        CHECK_MSG(c.x == want, "direction %g %g %g: %.6f, want the %s face's texel %u (%.6f)",
                  (double)cases[i].x, (double)cases[i].y, (double)cases[i].z, (double)c.x,
                  face_name[cases[i].face], cases[i].texel, (double)want);
    }
    vec3 zero = cubemap_lookup(&v, v3s(0.0f));
    CHECK(zero.x == 0.0f && zero.y == 0.0f && zero.z == 0.0f);
    scene_free(&s);
}

/* clpt's own format: `background { cubemap "DIR" }`, the same lookup, exclusive with
 * the colour keys. */
static void test_clpt_format(void)
{
    char path[256];
    snprintf(path, sizeof path, "%s/own.scene", dir);
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs("image { width 5 height 5 spp 4 }\ncamera { from 0 0 0 at 0 0 -1 fov 30 }\n"
              "background { cubemap \"cube\" }\n", f);
        fclose(f);
    }
    Scene s;
    Error err = {0};
    scene_init(&s);
    CHECK_EQ_INT(scene_load_file(path, SCENE_FORMAT_AUTO, &s, NULL, &err), ST_OK);
    CHECK_EQ_INT(s.integrator, INTEGRATOR_PATH);
    CHECK_EQ_INT(s.bg_type, BG_CUBEMAP);
    float *a = render(&s, "scalar"), *b = render(&s, TEST_OPENCL);
    check_pixel(a, b, 5 * 5 * 3, 2 * 5 + 2, CUBE_BACK, "clpt format, looking along -z");
    free(a);
    free(b);
    scene_free(&s);
    error_clear(&err);
    f = fopen(path, "wb");
    if (f) {
        fputs("background { color 1 1 1 cubemap \"cube\" }\n", f);
        fclose(f);
    }
    scene_init(&s);
    CHECK_EQ_INT(scene_load_file(path, SCENE_FORMAT_AUTO, &s, NULL, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "own.scene:1:26: a background is either 'cubemap' or a colour");
    scene_free(&s);
    error_clear(&err);
    f = fopen(path, "wb");
    if (f) {
        fputs("background { cubemap \"holes\" }\n", f);
        fclose(f);
    }
    scene_init(&s);
    CHECK_EQ_INT(scene_load_file(path, SCENE_FORMAT_AUTO, &s, NULL, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "own.scene:1:22: cannot open '");
    CHECK_STR_CONTAINS(err.msg, "holes/down.png'");
    scene_free(&s);
    error_clear(&err);
}

/* A face missing, and a cube map that names a file: I/O errors at the name. */
static void test_errors(void)
{
    write_faces("holes", CUBE_DOWN);
    Scene s;
    Error err;
    CHECK_EQ_INT(load_text("PerspectiveCamera { center 0 0 0 direction 0 0 -1 up 0 1 0 angle 30 }\n"
                           "Background { cubeMap holes }\nGroup { numObjects 0 }\n", &s, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "scene.txt:2:22: cannot open '");
    CHECK_STR_CONTAINS(err.msg, "holes/down.png' (nor '");
    CHECK_STR_CONTAINS(err.msg, "holes/down.bmp'): the cube map's down face");
    scene_free(&s);
    error_clear(&err);
    CHECK_EQ_INT(load_text("PerspectiveCamera { center 0 0 0 direction 0 0 -1 up 0 1 0 angle 30 }\n"
                           "Background { cubeMap cube/left.png }\nGroup { numObjects 0 }\n", &s, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "scene.txt:2:22: '");
    CHECK_STR_CONTAINS(err.msg, "cube/left.png': not a folder");
    scene_free(&s);
    error_clear(&err);
    /* a face that is not an image: the texture reader's input error, at the name */
    write_faces("junk", -1);
    char path[256];
    snprintf(path, sizeof path, "%s/junk/up.png", dir);
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs("not a picture\n", f);
        fclose(f);
    }
    CHECK_EQ_INT(load_text("PerspectiveCamera { center 0 0 0 direction 0 0 -1 up 0 1 0 angle 30 }\n"
                           "Background { cubeMap junk }\nGroup { numObjects 0 }\n", &s, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "scene.txt:2:22: ");
    CHECK_STR_CONTAINS(err.msg, "junk/up.png");
    scene_free(&s);
    error_clear(&err);
}

/* Loads clpt's own format from `text` (written to DIR/light.scene). */
static Status load_own(const char *text, Scene *s, Error *err)
{
    char path[256];
    snprintf(path, sizeof path, "%s/light.scene", dir);
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    scene_init(s);
    memset(err, 0, sizeof *err);
    return scene_load_file(path, SCENE_FORMAT_AUTO, s, NULL, err);
}

/* The resampled map's texels: in a uniform cube map every one is the faces' value
 * (the mean of equal lookups, taken in double, gives it back), so the environment
 * light's mean is that value's luminance; the map's size follows the faces'. */
static void test_env_map_uniform(void)
{
    Scene s;
    Error err;
    CHECK_EQ_INT(load_own("image { width 4 height 4 spp 1 }\ncamera { from 0 0 0 at 0 0 -1 fov 30 }\n"
                          "background { cubemap \"grey\" }\n", &s, &err), ST_OK);
    CHECK_EQ_INT(cube_env_convert(&s, &err), ST_OK);
    CHECK_EQ_INT(s.bg_type, BG_MAP);
    const Texture *t = &s.textures[s.bg_cubemap];
    CHECK_EQ_INT(t->flags, TEX_FLOAT);
    CHECK_EQ_INT(t->height, CUBE_ENV_MIN_HEIGHT);   /* 3 x 2 faces: the smallest map */
    CHECK_EQ_INT(t->width, 2 * CUBE_ENV_MIN_HEIGHT);
    float want = 128.0f / 255.0f;
    uint off = 0;
    for (size_t i = 0; i < 3u * t->width * t->height; i++) {
        float v;
        memcpy(&v, s.texels + t->offset + i, sizeof v);
        off += fabsf(v - want) > 1e-6f;
    }
    CHECK_EQ_INT(off, 0);
    /* env_dist sums sin(theta) at row centres: the sphere's area to ~1e-5 at 256 rows */
    CHECK_NEAR(s.env_mean, want, 1e-3 * want);
    CHECK(s.env_cdf != NULL);
    CHECK_EQ_INT(cube_env_height(1), CUBE_ENV_MIN_HEIGHT);
    CHECK_EQ_INT(cube_env_height(300), 600);
    CHECK_EQ_INT(cube_env_height(4096), CUBE_ENV_MAX_HEIGHT);
    scene_free(&s);
    error_clear(&err);
}

/* Renders s with MIS mode `mode` on `devices`; the linear film in a new array, NULL on
 * failure. */
static float *render_mode(Scene *s, uint mode, const char *devices, Error *err)
{
    float *rgb = malloc((size_t)s->image.width * s->image.height * 3u * sizeof *rgb);
    if (rgb && render_util_rgb_mis(s, mode, devices, rgb, err) == ST_OK) return rgb;
    free(rgb);
    return NULL;
}

/* A white diffuse sphere (albedo 1) inside a uniform cube map is lit by it alone and
 * returns it all: the pixels on it are the map's value within noise, those off it the
 * value exactly. */
static void test_furnace(void)
{
    Scene s;
    Error err;
    CHECK_EQ_INT(load_own("image { width 24 height 24 spp 64 depth 4 seed 5 }\n"
                          "camera { from 0 0.5 4 at 0 0 0 fov 40 }\n"
                          "background { cubemap \"grey\" }\n"
                          "sphere { center 0 0 0 radius 1 material { type diffuse albedo 1 1 1 } }\n", &s, &err),
                 ST_OK);
    float *img = render_mode(&s, MIS_BOTH, "scalar", &err);
    CHECK_MSG(img != NULL, "%s", err.msg);
    if (img) {
        double on = 0.0, want = 128.0 / 255.0;
        for (uint y = 8; y < 16; y++)
            for (uint x = 8; x < 16; x++) on += img[3 * (y * 24 + x) + 1] / 64.0;
        fprintf(stderr, "  furnace in a cube map of %.4f: sphere %.4f, corner %.6f\n", want, on, (double)img[1]);
        CHECK_NEAR(on, want, 0.01 * want);
        CHECK_NEAR(img[1], want, 1e-6);
        free(img);
    }
    scene_free(&s);
    error_clear(&err);
}

/* The scene of the strategy and device comparisons: a diffuse sphere on a diffuse
 * floor under the six-colour cube map, and, with `extra`, a metal and a glass sphere. */
static Status strategy_scene(Scene *s, uint spp, uint depth, int extra, Error *err)
{
    char text[1024];
    snprintf(text, sizeof text,
             "image { width 32 height 24 spp %u depth %u seed 5 }\n"
             "camera { from 0 0.5 4 at 0 0 0 fov 40 }\n"
             "background { cubemap \"cube\" }\n"
             "sphere { center 0 0 0 radius 1 material { type diffuse albedo 0.7 0.7 0.7 } }\n"
             "plane { point 0 -1 0 normal 0 1 0 material { type diffuse albedo 0.6 0.5 0.4 } }\n%s",
             spp, depth,
             extra ? "sphere { center -1.2 -0.5 1 radius 0.5 material { type metal albedo 0.9 0.8 0.7 fuzz 0.3 } }\n"
                     "sphere { center 1.2 -0.5 1 radius 0.5 material { type dielectric ior 1.5 } }\n" : "");
    return load_own(text, s, err);
}

/* Direct light only: light sampling alone, BSDF sampling alone and their MIS
 * combination agree (the image's mean and its 8x8 blocks), as for a `map` (test_envmap). */
static void test_strategies_agree(void)
{
    float *img[3] = { NULL, NULL, NULL };
    double mean[3] = { 0.0, 0.0, 0.0 }, block[3][12];
    memset(block, 0, sizeof block);
    int ok = 1;
    for (uint m = 0; m < 3; m++) {
        Scene s;
        Error err;
        CHECK_EQ_INT(strategy_scene(&s, 1024, 1, 0, &err), ST_OK);
        img[m] = render_mode(&s, m, "scalar", &err);
        CHECK_MSG(img[m] != NULL, "%s", err.msg);
        ok &= img[m] != NULL;
        scene_free(&s);
        error_clear(&err);
    }
    if (ok) {
        for (uint m = 0; m < 3; m++)
            for (uint y = 0; y < 24; y++)
                for (uint x = 0; x < 32; x++) {
                    const float *p = img[m] + 3 * (y * 32 + x);
                    double val = (p[0] + p[1] + p[2]) / 3.0;
                    mean[m] += val / (32 * 24);
                    block[m][(y / 8) * 4 + x / 8] += val / 64.0;
                }
        double worst[3] = { 0.0, 0.0, 0.0 };
        for (uint m = 1; m < 3; m++)
            for (int b = 0; b < 12; b++) {
                double rel = fabs(block[m][b] - block[0][b]) / (block[0][b] > 0.05 ? block[0][b] : 0.05);
                if (rel > worst[m]) worst[m] = rel;
            }
        fprintf(stderr, "  cube map, image mean: MIS %.4f, light sampling %.4f, BSDF sampling %.4f; worst 8x8 "
                "block difference to MIS: light %.1f%%, BSDF %.1f%%\n", mean[0], mean[1], mean[2],
                100.0 * worst[1], 100.0 * worst[2]);
        CHECK(mean[0] > 0.1);
        CHECK_NEAR(mean[1], mean[0], 0.01 * mean[0]);
        CHECK_NEAR(mean[2], mean[0], 0.01 * mean[0]);
        CHECK(worst[1] < 0.05);
        CHECK(worst[2] < 0.05);
    }
    for (int m = 0; m < 3; m++) free(img[m]);
}

/* A small render lit by the cube map (diffuse, metal and glass: every path kind) on
 * PoCL and on the scalar device: the same bits. */
static void test_opencl_matches_scalar(void)
{
    const char *devs[2] = { "scalar", TEST_OPENCL };
    float *img[2] = { NULL, NULL };
    for (int d = 0; d < 2; d++) {
        Scene s;
        Error err;
        CHECK_EQ_INT(strategy_scene(&s, 8, 6, 1, &err), ST_OK);
        img[d] = render_mode(&s, MIS_BOTH, devs[d], &err);
        CHECK_MSG(img[d] != NULL, "%s: %s", devs[d], err.msg);
        scene_free(&s);
        error_clear(&err);
    }
    if (img[0] && img[1]) {
        uint same = 0;
        for (uint i = 0; i < 32 * 24; i++) same += memcmp(img[0] + 3 * i, img[1] + 3 * i, 3 * sizeof(float)) == 0;
        fprintf(stderr, "  a cube-map-lit render: %u of %u pixels bit-identical on OpenCL and scalar\n", same, 32 * 24);
        CHECK_EQ_INT(same, 32 * 24);
    }
    free(img[0]);
    free(img[1]);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/clpt-test-cubemap-XXXXXX");
    if (!mkdtemp(dir)) {
        fprintf(stderr, "cannot make a temporary folder\n");
        return 1;
    }
    write_faces("cube", -1);
    static const unsigned char grey[3] = { 128, 128, 128 };
    write_faces_of("grey", -1, grey);
    RUN(test_axes);
    RUN(test_mirror);
    RUN(test_orientation);
    RUN(test_errors);
    RUN(test_clpt_format);
    RUN(test_env_map_uniform);
    RUN(test_furnace);
    RUN(test_strategies_agree);
    RUN(test_opencl_matches_scalar);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return harness_report();
}
