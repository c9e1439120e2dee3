/* test_obj.c — the Wavefront OBJ loader: index forms, triangulation, shading records,
 * line endings, exact number parsing, and the messages for malformed files. */
#include "harness.h"

#include "kmath.h"
#include "obj.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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

int main(void)
{
    RUN(test_index_forms);
    RUN(test_negative_indices_and_fan);
    RUN(test_line_forms);
    RUN(test_zero_normal_is_flat);
    RUN(test_numbers_exact);
    RUN(test_bad_input);
    RUN(test_files);
    return harness_report();
}
