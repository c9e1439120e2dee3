/* test_obj.c — the Wavefront OBJ loader: index forms, triangulation, shading records,
 * line endings, exact number parsing, and the messages for malformed files; MTL
 * materials and their mapping onto ours, texture paths, transforms. */
#include "harness.h"

#include "util/kmath.h"
#include "io/mtl.h"
#include "io/obj.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int vec_eq(vec3 a, float x, float y, float z) { return a.x == x && a.y == y && a.z == z; }

/* Parses `text` as "t.obj" into a fresh scene (material 7). */
static Status parse(const char *text, Scene *s, Error *err)
{
    scene_init(s);
    memset(err, 0, sizeof *err);
    return obj_parse("t.obj", text, strlen(text), s, 7, err);
}

static const char *square =
    "v 0 0 0\n"
    "v 1 0 0\n"
    "v 1 1 0\n"
    "v 0 1 0\n"
    "vt 0 0\n"
    "vt 1 0\n"
    "vt 1 1\n"
    "vt 0 1\n"
    "vn 0 0 2\n"      /* not unit: the loader normalises */
    "vn 0 1 1\n";

static void test_index_forms(void)
{
    char text[1024];
    snprintf(text, sizeof text, "%s%s", square,
             "f 1 2 3\n"
             "f 1/1 2/2 3/3\n"
             "f 1//1 2//1 3//2\n"
             "f 1/1/1 2/2/1 3/3/2\n");
    Scene s;
    Error err;
    CHECK_EQ_INT(parse(text, &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 4);
    CHECK_EQ_INT(s.n_shading, 3);
    if (s.n_triangles == 4 && s.n_shading == 3) {
        for (int i = 0; i < 4; i++) {
            CHECK(vec_eq(s.triangles[i].p0, 0, 0, 0));
            CHECK(vec_eq(s.triangles[i].p1, 1, 0, 0));
            CHECK(vec_eq(s.triangles[i].p2, 1, 1, 0));
            CHECK_EQ_INT(s.triangles[i].material, 7);
            CHECK_EQ_INT(s.triangles[i].light, NO_INDEX);
        }
        CHECK_EQ_INT(s.triangles[0].shading, NO_INDEX);
        CHECK_EQ_INT(s.triangles[1].shading, 0);
        CHECK_EQ_INT(s.triangles[2].shading, 1);
        CHECK_EQ_INT(s.triangles[3].shading, 2);
        const TriShading *a = &s.shading[0], *b = &s.shading[1], *c = &s.shading[2];
        CHECK_EQ_INT(a->flags, TRI_HAS_UV);
        CHECK(a->uv0[0] == 0 && a->uv0[1] == 0 && a->uv1[0] == 1 && a->uv1[1] == 0);
        CHECK(a->uv2[0] == 1 && a->uv2[1] == 1);
        CHECK_EQ_INT(b->flags, TRI_HAS_NORMALS);
        CHECK(vec_eq(b->n0, 0, 0, 1) && vec_eq(b->n1, 0, 0, 1));
        CHECK_NEAR(b->n2.y, 0.70710678, 1e-7);
        CHECK_NEAR(b->n2.z, 0.70710678, 1e-7);
        CHECK_EQ_INT(c->flags, TRI_HAS_NORMALS | TRI_HAS_UV);
        CHECK(c->uv2[0] == 1 && c->uv2[1] == 1 && vec_eq(c->n0, 0, 0, 1));
    }
    scene_free(&s);
}

static void test_negative_indices_and_fan(void)
{
    Scene s;
    Error err;
    /* a pentagon by relative indices, then one more vertex and a triangle that mixes
     * absolute and relative indices */
    const char *text =
        "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\n"
        "vt 0.5 0.25\n"
        "f -5/-1 -4/-1 -3/-1 -2/-1 -1/-1\n"
        "v 9 9 9\n"
        "f 1 -1 -2\n";
    CHECK_EQ_INT(parse(text, &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 4);
    if (s.n_triangles == 4) {
        /* fan (v0 vk vk+1) */
        CHECK(vec_eq(s.triangles[0].p0, 0, 0, 0) && vec_eq(s.triangles[0].p1, 2, 0, 0) &&
              vec_eq(s.triangles[0].p2, 3, 1, 0));
        CHECK(vec_eq(s.triangles[1].p0, 0, 0, 0) && vec_eq(s.triangles[1].p1, 3, 1, 0) &&
              vec_eq(s.triangles[1].p2, 1, 2, 0));
        CHECK(vec_eq(s.triangles[2].p0, 0, 0, 0) && vec_eq(s.triangles[2].p1, 1, 2, 0) &&
              vec_eq(s.triangles[2].p2, -1, 1, 0));
        CHECK(vec_eq(s.triangles[3].p0, 0, 0, 0) && vec_eq(s.triangles[3].p1, 9, 9, 9) &&
              vec_eq(s.triangles[3].p2, -1, 1, 0));
        CHECK_EQ_INT(s.n_shading, 3);
        if (s.n_shading == 3) CHECK(s.shading[2].uv1[0] == 0.5f && s.shading[2].uv1[1] == 0.25f);
        CHECK_EQ_INT(s.triangles[3].shading, NO_INDEX);
    }
    scene_free(&s);
}

static void test_line_forms(void)
{
    Scene s;
    Error err;
    /* CRLF, comments, blank and white-space-only lines, ignored statements, a \
     * continuation, tabs, an optional w and vertex colour, 1- and 3-number vt */
    const char *text =
        "# header\r\n"
        "mtllib box.mtl\r\n"
        "\r\n"
        "   \t \r\n"
        "o thing\r\n"
        "g group one\r\n"
        "v\t0 0 0 1\r\n"
        "v 1 0 0 0.5 0.5 0.5\r\n"
        "v 1 1 0   # a trailing comment\r\n"
        "vt 0.25\r\n"
        "vt 0.5 0.75 0\r\n"
        "usemtl red\r\n"
        "s off\r\n"
        "l 1 2\r\n"
        "p 1\r\n"
        "f 1/1 2/2 \\\r\n"
        "  3/2\r\n"
        "f 1 2 \\\n3";     /* no final newline */
    CHECK_EQ_INT(parse(text, &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 2);
    CHECK_EQ_INT(s.n_shading, 1);
    if (s.n_triangles == 2 && s.n_shading == 1) {
        CHECK(vec_eq(s.triangles[0].p2, 1, 1, 0));
        CHECK(vec_eq(s.triangles[1].p1, 1, 0, 0));
        CHECK(s.shading[0].uv0[0] == 0.25f && s.shading[0].uv0[1] == 0.0f);
        CHECK(s.shading[0].uv2[0] == 0.5f && s.shading[0].uv2[1] == 0.75f);
    }
    scene_free(&s);
}

static void test_zero_normal_is_flat(void)
{
    Scene s;
    Error err;
    CHECK_EQ_INT(parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 0\nvt 0 0\n"
                       "f 1//1 2//1 3//2\nf 1/1/1 2/1/1 3/1/2\n", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 2);
    CHECK_EQ_INT(s.n_shading, 1);   /* the first has nothing left; the second keeps its uv */
    if (s.n_triangles == 2 && s.n_shading == 1) {
        CHECK_EQ_INT(s.triangles[0].shading, NO_INDEX);
        CHECK_EQ_INT(s.triangles[1].shading, 0);
        CHECK_EQ_INT(s.shading[0].flags, TRI_HAS_UV);
    }
    scene_free(&s);
}

/* The fast number path must give strtof's float, bit for bit, for every input: plain
 * decimals of 1 to 12 digits with the point anywhere, signs, some exponents. Each
 * vertex gets a (degenerate) triangle of its own so its x can be read back. */
static void test_numbers_exact(void)
{
    enum { N = 50000 };
    size_t cap = (size_t)N * 48 + 1;
    char *text = malloc(cap);
    float *want = malloc(N * sizeof *want);
    size_t o = 0;
    uint64_t x = 0x1234567887654321ull;
    for (int i = 0; i < N; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        char num[40];
        int digits = (int)(x % 12) + 1, point = (int)((x >> 8) % (uint64_t)(digits + 1));
        int k = 0;
        if ((x >> 20) & 1) num[k++] = (x >> 21) & 1 ? '-' : '+';
        uint64_t y = x >> 24;
        for (int d = 0; d < digits; d++) {
            if (d == point && d > 0) num[k++] = '.';
            num[k++] = (char)('0' + (y % 10));
            y /= 10;
        }
        if ((x >> 59) == 0) k += snprintf(num + k, sizeof num - (size_t)k, "e%d", (int)((x >> 4) % 20) - 10);
        num[k] = '\0';
        want[i] = strtof(num, NULL);
        o += (size_t)snprintf(text + o, cap - o, "v %s 0 0\nf -1 -1 -1\n", num);
    }
    Scene s;
    Error err;
    CHECK_EQ_INT(parse(text, &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, N);
    int bad = 0;
    for (size_t i = 0; i < s.n_triangles && i < N; i++)
        if (memcmp(&s.triangles[i].p0.x, &want[i], sizeof(float)) != 0 && bad++ < 5)
            CHECK_MSG(0, "vertex %zu: %.9g, strtof gives %.9g", i, (double)s.triangles[i].p0.x,
                      (double)want[i]);
    CHECK_EQ_INT(bad, 0);
    scene_free(&s);
    free(text);
    free(want);
}

/* Loads `text` and checks status and message "t.obj<rest...>". */
static void check_bad(const char *text, const char *rest)
{
    Scene s;
    Error err;
    Status st = parse(text, &s, &err);
    CHECK_MSG(st == ST_INPUT, "status %d for: %s", st, text);
    CHECK_MSG(strncmp(err.msg, "t.obj", 5) == 0 && strncmp(err.msg + 5, rest, strlen(rest)) == 0,
              "\n    got:      %s\n    expected: t.obj%s", err.msg, rest);
    scene_free(&s);
}

static void test_bad_input(void)
{
    const char *v3 = "v 0 0 0\nv 1 0 0\nv 1 1 0\n";
    char text[512];
#define BAD(tail, rest)                                   \
    do {                                                  \
        snprintf(text, sizeof text, "%s%s", v3, tail);    \
        check_bad(text, rest);                            \
    } while (0)
    BAD("f 0 1 2\n", ":4:3: expected a vertex index in 1..3 or -3..-1, found '0'");
    BAD("f 1 2 4\n", ":4:7: expected a vertex index in 1..3 or -3..-1, found '4'");
    BAD("f 1 2 -4\n", ":4:7: expected a vertex index in 1..3 or -3..-1, found '-4'");
    BAD("f 1 2 99999999999999999999\n", ":4:7: expected a vertex index in 1..3 or -3..-1");
    BAD("f 1 2\n", ":4:1: expected at least 3 vertices in a face, found 2");
    BAD("f\n", ":4:1: expected at least 3 vertices in a face, found 0");
    BAD("f 1 2 x\n", ":4:7: expected a vertex index, found 'x'");
    BAD("f 1/1 2 3\n", ":4:3: expected a texture coordinate index (none is defined before this line), found '1/1'");
    BAD("vt 0 0\nf 1/2 2/1 3/1\n", ":5:3: expected a texture coordinate index in 1..1 or -1..-1, found '1/2'");
    BAD("vn 0 0 1\nf 1//1 2//1 3//2\n", ":5:13: expected a normal index in 1..1 or -1..-1, found '3//2'");
    BAD("f 1/ 2 3\n", ":4:3: expected a texture coordinate index, found '1/'");
    BAD("f 1// 2 3\n", ":4:3: expected a normal index, found '1//'");
    BAD("f 1/1/1/1 2 3\n", ":4:3: expected a texture coordinate index (none");
    BAD("vt 0 0\nvn 0 0 1\nf 1/1/1/1 2 3\n", ":6:3: expected a face vertex (v, v/vt, v//vn or v/vt/vn), found '1/1/1/1'");
    BAD("f 1 2 3x\n", ":4:7: expected a face vertex (v, v/vt, v//vn or v/vt/vn), found '3x'");
    BAD("v 1.2.3 0 0\n", ":4:3: expected 3 coordinates after 'v', found '1.2.3'");
    BAD("v 1 2\n", ":4:6: expected 3 coordinates after 'v', found end of line");
    BAD("v 1 nan 2\n", ":4:5: expected 3 coordinates after 'v', found 'nan'");
    BAD("v 1 2 1e39\n", ":4:7: expected 3 coordinates after 'v', found '1e39'");
    BAD("v 1 2 3 4 5 6 7 8\n", ":4:17: expected end of line, found '8'");
    BAD("v 1 2 3 w\n", ":4:9: expected a number (w or r g b) after 'v x y z', found 'w'");
    BAD("vn 1 2\n", ":4:7: expected 3 coordinates after 'vn', found end of line");
    BAD("vt\n", ":4:3: expected a texture coordinate after 'vt', found end of line");
    BAD("vt 1 2 3 4\n", ":4:10: expected end of line, found '4'");
    BAD("curv 0 1 1 2\n", ":4:1: expected an OBJ statement (v, vt, vn, f, o, g, s, usemtl, mtllib, l, p), found 'curv'");
    BAD("\r\n\r\nf 1 2 5\r\n", ":6:7: expected a vertex index in 1..3 or -3..-1, found '5'");
    BAD("f 1 \\\n 2 \\\n 5\n", ":6:2: expected a vertex index in 1..3 or -3..-1, found '5'");
    BAD("f 1 \\\n 2\n", ":4:1: expected at least 3 vertices in a face, found 2");
#undef BAD
    check_bad("f 1 2 3\n", ":1:3: expected a vertex index (none is defined before this line), found '1'");
    /* a NUL byte inside the text is reported, not taken as the end */
    Scene s;
    Error err;
    scene_init(&s);
    static const char nul[] = "v 0 0 0\nv 1\0 0 0\n";
    Status st = obj_parse("t.obj", nul, sizeof nul - 1, &s, 0, &err);
    CHECK_EQ_INT(st, ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "t.obj:2:3: expected 3 coordinates after 'v', found '1\\x00'");
    scene_free(&s);
}

static void test_files(void)
{
    Scene s;
    Error err = {0};
    scene_init(&s);
    CHECK_EQ_INT(obj_load("tests/data/no-such.obj", &s, 0, &err), ST_IO);
    CHECK(strcmp(err.msg, "cannot open 'tests/data/no-such.obj': No such file or directory") == 0);
    scene_free(&s);

    /* the shared Cornell box models: negative indices and quads, v//vn with CRLF */
    if (!shared_model_present("../shared/models/cornell-box/CornellBox-Sphere.obj", "the Cornell box OBJs are not read"))
        return;
    scene_init(&s);
    Status st = obj_load("../shared/models/cornell-box/CornellBox-Original.obj", &s, 2, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_triangles, 36);
    CHECK_EQ_INT(s.n_shading, 0);
    scene_free(&s);
    scene_init(&s);
    st = obj_load("../shared/models/cornell-box/CornellBox-Sphere.obj", &s, 2, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_triangles, 2188);
    CHECK_EQ_INT(s.n_shading, 2188);
    /* 2176 faces are v/vt/vn, 12 are v//vn; all normals come out unit */
    int n_uv = 0, n_normals = 0;
    double worst = 0.0;
    for (size_t i = 0; i < s.n_shading; i++) {
        const TriShading *sh = &s.shading[i];
        n_uv += (sh->flags & TRI_HAS_UV) != 0;
        n_normals += (sh->flags & TRI_HAS_NORMALS) != 0;
        worst = fmax(worst, fabs(v3_len(sh->n0) - 1.0));
        worst = fmax(worst, fabs(v3_len(sh->n2) - 1.0));
    }
    CHECK_EQ_INT(n_uv, 2176);
    CHECK_EQ_INT(n_normals, 2188);
    CHECK(worst < 1e-6);
    scene_free(&s);
}

/* ------------------------------------------------------------------ MTL */

static int color_is(vec3 c, float r, float g, float b) { return c.x == r && c.y == g && c.z == b; }

static const MtlMaterial *find(const MtlLibrary *lib, const char *name)
{
    return mtl_find(lib, name, strlen(name));
}

static void test_mtl_mapping(void)
{
    MtlLibrary lib;
    memset(&lib, 0, sizeof lib);
    Error err = {0};
    Status st = mtl_load("tests/data/mtl/materials.mtl", &lib, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(lib.n, 7);
    const MtlMaterial *m;
    if ((m = find(&lib, "red")) != NULL) {
        CHECK_EQ_INT(m->m.type, MAT_DIFFUSE);
        CHECK(color_is(m->m.albedo, 0.8f, 0.1f, 0.1f));
        CHECK(m->m.shininess == 10.0f && m->texture == NULL);
    } else CHECK(!"red");
    if ((m = find(&lib, "lamp")) != NULL) {
        CHECK_EQ_INT(m->m.type, MAT_EMISSIVE);
        CHECK(color_is(m->m.emission, 17.0f, 12.0f, 4.0f));
    } else CHECK(!"lamp");
    if ((m = find(&lib, "glass")) != NULL) {
        CHECK_EQ_INT(m->m.type, MAT_DIELECTRIC);
        CHECK(m->m.ior == 1.33f);
        CHECK(color_is(m->m.specular, 0.3f, 0.3f, 0.3f) && m->m.shininess == 200.0f);
    } else CHECK(!"glass");
    if ((m = find(&lib, "mirror")) != NULL) {
        CHECK_EQ_INT(m->m.type, MAT_METAL);
        CHECK(color_is(m->m.albedo, 0.9f, 0.8f, 0.7f));
        CHECK_NEAR(m->m.fuzz, sqrt(2.0 / 2000.0), 1e-7);
    } else CHECK(!"mirror");
    if ((m = find(&lib, "glossy")) != NULL) {
        /* Ks and Ns are kept for the shader, the type stays diffuse; a single Kd is grey */
        CHECK_EQ_INT(m->m.type, MAT_DIFFUSE);
        CHECK(color_is(m->m.albedo, 0.5f, 0.5f, 0.5f));
        CHECK(color_is(m->m.specular, 0.8f, 0.8f, 0.8f) && m->m.shininess == 40.0f);
    } else CHECK(!"glossy");
    if ((m = find(&lib, "textured")) != NULL) {
        /* options skipped, the name matched without regard to case, folder included */
        CHECK_MSG(m->texture && strcmp(m->texture, "tests/data/mtl/textures/brick.png") == 0, "%s",
                  m->texture ? m->texture : "(none)");
    } else CHECK(!"textured");
    if ((m = find(&lib, "dissolved")) != NULL) CHECK_EQ_INT(m->m.type, MAT_DIELECTRIC);
    else CHECK(!"dissolved");
    mtl_free(&lib);
}

static void check_mtl_bad(const char *text, const char *want)
{
    MtlLibrary lib;
    memset(&lib, 0, sizeof lib);
    Error err = {0};
    Status st = mtl_parse("t.mtl", text, strlen(text), &lib, &err);
    CHECK_MSG(st == ST_INPUT, "%s: status %d", text, (int)st);
    CHECK_MSG(strstr(err.msg, want) != NULL, "got \"%s\", want \"%s\"", err.msg, want);
    mtl_free(&lib);
}

static void test_mtl_errors(void)
{
    check_mtl_bad("newmtl a\nKd 1 x 1\n", "t.mtl:2:6: expected a colour (1 or 3 numbers >= 0) after 'Kd', found 'x'");
    check_mtl_bad("newmtl a\nKd 1 1\n", "t.mtl:2:7: expected a colour (1 or 3 numbers >= 0) after 'Kd', found end of line");
    check_mtl_bad("newmtl a\nKe -1 0 0\n", "t.mtl:2:4: expected a colour (1 or 3 numbers >= 0) after 'Ke', found '-1'");
    check_mtl_bad("newmtl a\nNs\n", "t.mtl:2:3: expected a number >= 0 after 'Ns', found end of line");
    check_mtl_bad("newmtl a\nd 2\n", "t.mtl:2:1: expected a value in [0, 1], found 'd'");
    check_mtl_bad("newmtl a\nillum 2.5\n", "t.mtl:2:1: expected an illumination model 0..10 after 'illum'");
    check_mtl_bad("newmtl a\nKd 1 1 1 1\n", "t.mtl:2:10: expected end of line, found '1'");
    check_mtl_bad("Kd 1 1 1\n", "t.mtl:1:1: expected 'newmtl' before the first material statement, found 'Kd'");
    check_mtl_bad("newmtl\n", "t.mtl:1:7: expected a material name after 'newmtl', found end of line");
    check_mtl_bad("newmtl a\nmap_Kd -zoom 2 x.png\n", "t.mtl:2:8: expected a texture option");
    /* unknown statements are extensions: ignored */
    MtlLibrary lib;
    memset(&lib, 0, sizeof lib);
    Error err = {0};
    const char *text = "newmtl a\r\nPr 0.5\r\nfoo bar\r\nKd 0.25 0.5 1\r\n";
    CHECK_EQ_INT(mtl_parse("t.mtl", text, strlen(text), &lib, &err), ST_OK);
    CHECK_EQ_INT(lib.n, 1);
    if (lib.n == 1) CHECK(color_is(lib.items[0].m.albedo, 0.25f, 0.5f, 1.0f));
    mtl_free(&lib);
}

/* usemtl picks the MTL's materials, added to the scene once each, in order of use. */
static void test_obj_materials(void)
{
    Scene s;
    scene_init(&s);
    Error err = {0};
    Status st = obj_load("tests/data/mtl/scene.obj", &s, NO_INDEX, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_triangles, 11);
    /* default (first face), red, lamp, glass, mirror, glossy, textured, dissolved */
    CHECK_EQ_INT(s.n_materials, 8);
    if (s.n_triangles == 11 && s.n_materials == 8) {
        static const uint want[11] = { 0, 1, 2, 3, 4, 5, 6, 6, 7, 1, 0 };
        for (int i = 0; i < 11; i++) CHECK_EQ_INT(s.triangles[i].material, want[i]);
        CHECK_EQ_INT(s.materials[0].type, MAT_DIFFUSE);
        CHECK(color_is(s.materials[0].albedo, MESH_DEFAULT_ALBEDO, MESH_DEFAULT_ALBEDO, MESH_DEFAULT_ALBEDO));
        CHECK_EQ_INT(s.materials[2].type, MAT_EMISSIVE);
        CHECK_EQ_INT(s.materials[3].type, MAT_DIELECTRIC);
        CHECK_EQ_INT(s.materials[4].type, MAT_METAL);
        CHECK(scene_material_texture(&s, 6) && strcmp(scene_material_texture(&s, 6), "tests/data/mtl/textures/brick.png") == 0);
        CHECK(scene_material_texture(&s, 1) == NULL);
        /* the map_Kd image is loaded as the material's albedo texture */
        CHECK(s.materials[6].texture != NO_INDEX && s.n_textures == 1);
        CHECK_EQ_INT(s.materials[1].texture, NO_INDEX);
        CHECK(scene_material_texture(&s, 99) == NULL);
    }
    scene_free(&s);
    /* a material given by the caller replaces them all, and the MTL is not read */
    scene_init(&s);
    CHECK_EQ_INT(obj_load("tests/data/mtl/scene.obj", &s, 5, &err), ST_OK);
    CHECK_EQ_INT(s.n_materials, 0);
    for (size_t i = 0; i < s.n_triangles; i++) CHECK_EQ_INT(s.triangles[i].material, 5);
    scene_free(&s);
    /* an MTL that is not there: every face gets the default material */
    scene_init(&s);
    CHECK_EQ_INT(obj_load("tests/data/mtl/no-mtl.obj", &s, NO_INDEX, &err), ST_OK);
    CHECK_EQ_INT(s.n_materials, 1);
    CHECK_EQ_INT(s.n_triangles, 1);
    scene_free(&s);
    /* an error inside an MTL names the MTL's line */
    scene_init(&s);
    const char *bad = "mtllib clpt-test-bad.mtl\n";
    FILE *f = fopen(TEST_TMP("clpt-test-bad.mtl"), "w");
    if (f) {
        fputs("newmtl x\nKd 1 1 q\n", f);
        fclose(f);
    }
    st = obj_parse(TEST_TMP("clpt-test-scene.obj"), bad, strlen(bad), &s, NO_INDEX, &err);
    CHECK_EQ_INT(st, ST_INPUT);
    char want[512];
    snprintf(want, sizeof want, "%s:2:8: expected a colour", TEST_TMP("clpt-test-bad.mtl"));
    CHECK_STR_CONTAINS(err.msg, want);
    remove(TEST_TMP("clpt-test-bad.mtl"));
    scene_free(&s);
}

/* The Sponza's MTL names its textures in another case than the files have. */
static void test_sponza(void)
{
    const char *path = "../shared/models/sponza-dabrovic/sponza.obj";
    if (!shared_model_present(path, "skipped")) return;
    Scene s;
    scene_init(&s);
    Error err = {0};
    Status st = obj_load(path, &s, NO_INDEX, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_triangles, 66450);
    int textures = 0, missing = 0;
    for (size_t i = 0; i < s.n_materials; i++) {
        const char *t = scene_material_texture(&s, (uint)i);
        if (!t) continue;
        textures++;
        FILE *tf = fopen(t, "rb");
        if (tf) fclose(tf);
        else if (missing++ < 3) fprintf(stderr, "  missing texture %s\n", t);
    }
    CHECK(textures > 10);
    CHECK_EQ_INT(missing, 0);
    scene_free(&s);
}

/* A transform moves the corners and turns the normals (inverse transpose). */
static void test_obj_transform(void)
{
    const char *text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 1 0\nf 1//1 2//1 3//1\n";
    Scene s;
    scene_init(&s);
    Error err = {0};
    MeshOptions o = mesh_options(0);
    o.xf = transform_scale(2.0, 1.0, 1.0);
    CHECK_EQ_INT(obj_parse_with("t.obj", text, strlen(text), &s, &o, &err), ST_OK);
    CHECK_EQ_INT(s.n_shading, 1);
    if (s.n_shading == 1) {
        CHECK(vec_eq(s.triangles[0].p1, 2, 0, 0));
        /* (1, 1, 0) under the inverse transpose diag(1/2, 1, 1): (0.5, 1, 0), made unit */
        CHECK_NEAR(s.shading[0].n0.x, 0.5 / sqrt(1.25), 1e-7);
        CHECK_NEAR(s.shading[0].n0.y, 1.0 / sqrt(1.25), 1e-7);
    }
    scene_free(&s);
}

/* Appends text to a growing buffer (aborts the test program when memory runs out). */
static void put(char **buf, size_t *len, size_t *cap, const char *text)
{
    size_t n = strlen(text);
    if (*len + n + 1 > *cap) {
        *cap = (*len + n + 1) * 2;
        *buf = realloc(*buf, *cap);
        if (!*buf) abort();
    }
    memcpy(*buf + *len, text, n + 1);
    *len += n;
}

static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    int ok = fputs(text, f) >= 0;
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* n MTL materials, and an OBJ whose faces use each of them in turn: each 'newmtl' and
 * each 'usemtl' searched the library from the start (23 s and 65 s for 80,000). Sets
 * the CPU seconds of reading the library and the OBJ; checks what they read. */
static void read_many_materials(int n, double *mtl_secs, double *obj_secs)
{
    *mtl_secs = *obj_secs = 0;
    char dir[] = "/tmp/clpt-test-obj-XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK_MSG(0, "mkdtemp failed");
        return;
    }
    char mtl_path[64], obj_path[64], line[96];
    snprintf(mtl_path, sizeof mtl_path, "%s/many.mtl", dir);
    snprintf(obj_path, sizeof obj_path, "%s/many.obj", dir);
    char *mtl = NULL, *obj = NULL;
    size_t mtl_len = 0, mtl_cap = 0, obj_len = 0, obj_cap = 0;
    put(&obj, &obj_len, &obj_cap, "mtllib many.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for (int i = 0; i < n; i++) {
        snprintf(line, sizeof line, "newmtl m%d\nKd 0.5 0.25 %d\n", i, i % 2);
        put(&mtl, &mtl_len, &mtl_cap, line);
        snprintf(line, sizeof line, "usemtl m%d\nf 1 2 3\nmtllib many.mtl\n", n - 1 - i);
        put(&obj, &obj_len, &obj_cap, line);
    }
    CHECK(write_file(mtl_path, mtl) == 0);

    MtlLibrary lib;
    memset(&lib, 0, sizeof lib);
    Error err = { 0 };
    double t0 = cpu_seconds();
    Status st = mtl_parse(mtl_path, mtl, mtl_len, &lib, &err);
    *mtl_secs = cpu_seconds() - t0;
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(lib.n, n);
    char last_name[16];
    int last_len = snprintf(last_name, sizeof last_name, "m%d", n - 1);
    const MtlMaterial *last = mtl_find(&lib, last_name, (size_t)last_len);
    CHECK(last && last == &lib.items[n - 1] && last->m.albedo.z == (float)((n - 1) % 2));
    mtl_free(&lib);

    Scene s;
    scene_init(&s);
    t0 = cpu_seconds();
    st = obj_parse(obj_path, obj, obj_len, &s, NO_INDEX, &err);
    *obj_secs = cpu_seconds() - t0;
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_triangles, n);
    CHECK_EQ_INT(s.n_materials, n);
    if (s.n_triangles == (size_t)n && s.n_materials == (size_t)n) {
        /* the first face uses the last material, the last face m0 (even: Kd z 0) */
        CHECK(s.materials[s.triangles[0].material].albedo.z == (float)((n - 1) % 2));
        CHECK(s.materials[s.triangles[n - 1].material].albedo.z == 0.0f);
    }
    scene_free(&s);
    free(mtl);
    free(obj);
    remove(mtl_path);
    remove(dir);
}

static void test_many_materials(void)
{
    enum { N = 80000 };
    double mtl_n, obj_n, mtl_8n, obj_8n;
    read_many_materials(N / GROWTH_FACTOR, &mtl_n, &obj_n);
    read_many_materials(N, &mtl_8n, &obj_8n);
    CHECK_LINEAR("newmtl", mtl_n, mtl_8n);
    CHECK_LINEAR("usemtl and mtllib", obj_n, obj_8n);
}

/* An MTL file or a map_Kd image that cannot be opened is a warning naming where it is
 * named; the faces and the material render without it. */
static void test_missing_files_warn(void)
{
    char dir[] = "/tmp/clpt-test-obj-XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK_MSG(0, "mkdtemp failed");
        return;
    }
    char mtl_path[64], obj_path[64], want[256];
    snprintf(mtl_path, sizeof mtl_path, "%s/t.mtl", dir);
    snprintf(obj_path, sizeof obj_path, "%s/t.obj", dir);
    CHECK(write_file(mtl_path, "newmtl red\nKd 1 0 0\n  map_Kd  -clamp on red.png\n") == 0);
    const char *obj = "mtllib gone.mtl t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    Status st = obj_parse(obj_path, obj, strlen(obj), &s, NO_INDEX, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_warnings, 2);
    if (s.n_warnings == 2) {
        snprintf(want, sizeof want, "%s:1:8: cannot open '%s/gone.mtl': No such file or directory; the faces "
                 "that use its materials get the default material", obj_path, dir);
        CHECK_MSG(strcmp(s.warnings[0], want) == 0, "%s", s.warnings[0]);
        snprintf(want, sizeof want, "%s:3:21: cannot open '%s/red.png': No such file or directory; the "
                 "material is rendered without this map_Kd texture", mtl_path, dir);
        CHECK_MSG(strcmp(s.warnings[1], want) == 0, "%s", s.warnings[1]);
    }
    CHECK_EQ_INT(s.n_materials, 1);
    CHECK_EQ_INT(s.n_textures, 0);
    if (s.n_materials == 1) {
        CHECK_EQ_INT(s.materials[0].texture, NO_INDEX);
        CHECK(s.materials[0].albedo.x == 1.0f && s.materials[0].albedo.y == 0.0f);
        CHECK(scene_material_texture(&s, 0) == NULL);
    }
    scene_free(&s);
    /* a map_Kd file that is there but not an image is still an error */
    char png_path[64];
    snprintf(png_path, sizeof png_path, "%s/red.png", dir);
    CHECK(write_file(png_path, "not an image") == 0);
    scene_init(&s);
    st = obj_parse(obj_path, obj, strlen(obj), &s, NO_INDEX, &err);
    CHECK_EQ_INT(st, ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "red.png");
    scene_free(&s);
    error_clear(&err);
    remove(png_path);
    remove(mtl_path);
    remove(dir);
}

int main(void)
{
    RUN(test_index_forms);
    RUN(test_negative_indices_and_fan);
    RUN(test_line_forms);
    RUN(test_zero_normal_is_flat);
    RUN(test_numbers_exact);
    RUN(test_bad_input);
    RUN(test_files);
    RUN(test_mtl_mapping);
    RUN(test_mtl_errors);
    RUN(test_obj_materials);
    RUN(test_sponza);
    RUN(test_obj_transform);
    RUN(test_many_materials);
    RUN(test_missing_files_warn);
    return harness_report();
}
