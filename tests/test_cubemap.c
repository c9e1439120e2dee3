/*
 * test_cubemap.c — `cubeMap DIR` backgrounds (kernels/background.h, the course's
 * CubeMap): six solid-colour faces written for the test; a camera looking along each
 * axis sees exactly that face's bytes at its centre pixel, in the classic ray tracer and
 * in the path tracer; a mirror sphere shows the face behind the camera; the face
 * orientation of the lookup; the same bits on PoCL and the scalar device; and the
 * errors for a missing face or a folder that is not one.
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
#include "background.h"

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
 * (h x w images of one colour: orientation cannot show; test_orientation pins it). */
static void write_faces(const char *sub, int skip)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, sub);
    mkdir(path, 0755);
    for (int f = 0; f < 6; f++) {
        if (f == skip) continue;
        unsigned char px[2 * 3 * 3];
        for (int i = 0; i < 6; i++) memcpy(px + 3 * i, face_rgb[f], 3);
        snprintf(path, sizeof path, "%s/%s/%s.png", dir, sub, face_name[f]);
        stbi_write_png(path, 3, 2, 3, px, 9);
    }
}

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
            float *a = render(&s, "scalar"), *b = render(&s, "cpu");
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
        float *a = render(&s, "scalar"), *b = render(&s, "cpu");
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
    float *a = render(&s, "scalar"), *b = render(&s, "cpu");
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

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/clpt-test-cubemap-XXXXXX");
    if (!mkdtemp(dir)) {
        fprintf(stderr, "cannot make a temporary folder\n");
        return 1;
    }
    write_faces("cube", -1);
    RUN(test_axes);
    RUN(test_mirror);
    RUN(test_orientation);
    RUN(test_errors);
    RUN(test_clpt_format);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return harness_report();
}
