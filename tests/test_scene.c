/* test_scene.c — the scene file reader: every statement and key, the shipped scenes,
 * and the error messages for malformed input. Run from the project root. */
#include "harness.h"

#include "util/kmath.h"
#include "io/lexer.h"
#include "scene/scene.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define GEN_WEEKEND_NO_MAIN
#include "../tools/gen_weekend.c"

/* ------------------------------------------------------------------ temp files */

static char tmp_dir[64];
static char *tmp_files[64];
static int n_tmp_files;

/* Writes `text` to tmp_dir/name and returns the path (owned by the test run). */
static const char *write_tmp(const char *name, const char *text)
{
    char *path = malloc(strlen(tmp_dir) + strlen(name) + 2);
    sprintf(path, "%s/%s", tmp_dir, name);
    FILE *f = fopen(path, "wb");
    if (f) {
        fwrite(text, 1, strlen(text), f);
        fclose(f);
    }
    int seen = 0;
    for (int i = 0; i < n_tmp_files; i++)
        if (strcmp(tmp_files[i], path) == 0) seen = 1;
    if (!seen && n_tmp_files < 64) {
        tmp_files[n_tmp_files++] = path;
        return path;
    }
    /* already listed: return the listed copy */
    for (int i = 0; i < n_tmp_files; i++)
        if (strcmp(tmp_files[i], path) == 0) {
            free(path);
            return tmp_files[i];
        }
    return path;
}

static void tmp_cleanup(void)
{
    for (int i = 0; i < n_tmp_files; i++) {
        unlink(tmp_files[i]);
        free(tmp_files[i]);
    }
    rmdir(tmp_dir);
}

/* Loads `text` as scene file `name` into *s (initialised here). */
static Status load_text(const char *name, const char *text, Scene *s, Error *err)
{
    scene_init(s);
    memset(err, 0, sizeof *err);
    return scene_load(write_tmp(name, text), s, err);
}

static int vec_eq(vec3 a, float x, float y, float z) { return a.x == x && a.y == y && a.z == z; }

/* ------------------------------------------------------------------ the lexer */

static void test_lexer(void)
{
    static const char text[] = "key{ [1.5e3]\t\"a \\\"b\\\\\" # comment\r\n  0x1p-2 +7 -0 }";
    Lexer lx;
    Error err = {0};
    CHECK_EQ_INT(lex_open_text(&lx, "mem", text, sizeof text - 1, &err), ST_OK);
    struct { TokenKind kind; const char *text; uint line, col; } want[] = {
        {TOK_WORD, "key", 1, 1},   {TOK_LBRACE, "{", 1, 4},   {TOK_LBRACKET, "[", 1, 6},
        {TOK_WORD, "1.5e3", 1, 7}, {TOK_RBRACKET, "]", 1, 12}, {TOK_STRING, "a \"b\\", 1, 14},
        {TOK_WORD, "0x1p-2", 2, 3}, {TOK_WORD, "+7", 2, 10},  {TOK_WORD, "-0", 2, 13},
        {TOK_RBRACE, "}", 2, 16},  {TOK_EOF, "", 2, 17},      {TOK_EOF, "", 2, 17},
    };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        Token t;
        CHECK_EQ_INT(lex_next(&lx, &t, &err), ST_OK);
        CHECK_MSG(t.kind == want[i].kind && t.len == strlen(want[i].text) &&
                      memcmp(t.text, want[i].text, t.len) == 0 && t.line == want[i].line &&
                      t.col == want[i].col,
                  "token %zu: kind %d '%.*s' at %u:%u", i, t.kind, (int)t.len, t.text, t.line, t.col);
        float f;
        if (i == 3) CHECK(tok_float(&t, &f) == 0 && f == 1500.0f);
        if (i == 6) CHECK(tok_float(&t, &f) == 0 && f == 0.25f);
        unsigned long long u;
        if (i == 7) CHECK(tok_uint(&t, &u) == 0 && u == 7);
        if (i == 8) CHECK(tok_uint(&t, &u) != 0);
        if (i == 0) CHECK(tok_is(&t, "key") && !tok_is(&t, "ke") && !tok_is(&t, "keys"));
        if (i == 5) CHECK(!tok_is(&t, "a \"b\\"));   /* strings are never keywords */
    }
    lex_close(&lx);

    static const char nums[] = "18446744073709551615 18446744073709551616 1e-50 0x1p200 12a";
    CHECK_EQ_INT(lex_open_text(&lx, "mem", nums, sizeof nums - 1, &err), ST_OK);
    Token t;
    unsigned long long u = 0;
    float f = 1.0f;
    lex_next(&lx, &t, &err);
    CHECK(tok_uint(&t, &u) == 0 && u == 18446744073709551615ull);
    lex_next(&lx, &t, &err);
    CHECK(tok_uint(&t, &u) != 0);                 /* 2^64 does not fit */
    lex_next(&lx, &t, &err);
    CHECK(tok_float(&t, &f) == 0 && f == 0.0f);   /* underflow is a finite zero */
    lex_next(&lx, &t, &err);
    CHECK(tok_float(&t, &f) != 0);                /* beyond float range */
    lex_next(&lx, &t, &err);
    CHECK(tok_float(&t, &f) != 0 && tok_uint(&t, &u) != 0);
    lex_close(&lx);
}

/* ------------------------------------------------------------------ good input */

static void test_camera_and_image(void)
{
    Scene s;
    Error err;
    Status st = load_text("cam.scene",
                          "camera { from 1 2 3 at 4 5.5 -6 up 0 0 1 fov 30 aperture 0.25 focus 7.5 }\n"
                          "image { width 640 height 480 spp 16 depth 3 seed 4294967295 split 4 }\n",
                          &s, &err);
    CHECK_EQ_INT(st, ST_OK);
    CHECK(vec_eq(s.camera.from, 1, 2, 3));
    CHECK(vec_eq(s.camera.at, 4, 5.5f, -6));
    CHECK(vec_eq(s.camera.up, 0, 0, 1));
    CHECK(s.camera.vfov == 30.0f);
    CHECK(s.camera.aperture == 0.25f);
    CHECK(s.camera.focus_dist == 7.5f);
    CHECK_EQ_INT(s.image.width, 640);
    CHECK_EQ_INT(s.image.height, 480);
    CHECK_EQ_INT(s.image.spp, 16);
    CHECK_EQ_INT(s.image.max_depth, 3);
    CHECK_EQ_INT(s.image.seed, 4294967295u);
    CHECK_EQ_INT(s.image.split, 4);
    CHECK(s.path && strstr(s.path, "cam.scene"));
    scene_free(&s);
    /* split auto: the pilot's choice (the default) */
    CHECK_EQ_INT(load_text("auto.scene", "image { split auto }\n", &s, &err), ST_OK);
    CHECK_EQ_INT(s.image.split, SCENE_SPLIT_AUTO);
    scene_free(&s);
}

static void test_defaults_kept(void)
{
    Scene s;
    Error err;
    /* a partial block keeps the defaults of the keys it leaves out */
    Status st = load_text("partial.scene", "camera { fov 50 }\nimage { spp 2 }\n", &s, &err);
    CHECK_EQ_INT(st, ST_OK);
    CHECK(vec_eq(s.camera.from, 0, 0, 0));
    CHECK(vec_eq(s.camera.at, 0, 0, -1));
    CHECK(vec_eq(s.camera.up, 0, 1, 0));
    CHECK(s.camera.vfov == 50.0f);
    CHECK(s.camera.aperture == 0.0f);
    CHECK(s.camera.focus_dist == 0.0f);
    CHECK_EQ_INT(s.image.width, 512);
    CHECK_EQ_INT(s.image.height, 512);
    CHECK_EQ_INT(s.image.spp, 2);
    CHECK_EQ_INT(s.image.max_depth, 8);
    CHECK_EQ_INT(s.image.seed, 1);
    CHECK_EQ_INT(s.image.split, SCENE_SPLIT_AUTO);
    CHECK_EQ_INT(s.bg_type, BG_CONSTANT);
    CHECK(vec_eq(s.bg_color, 0, 0, 0));
    scene_free(&s);

    st = load_text("empty.scene", "# nothing but a comment\n\n", &s, &err);
    CHECK_EQ_INT(st, ST_OK);
    CHECK_EQ_INT(s.n_materials + s.n_spheres + s.n_triangles + s.n_boxes + s.n_planes, 0);
    scene_free(&s);
}

static void test_backgrounds(void)
{
    Scene s;
    Error err;
    CHECK_EQ_INT(load_text("bg1.scene", "background { color 0.1 0.2 0.3 }", &s, &err), ST_OK);
    CHECK_EQ_INT(s.bg_type, BG_CONSTANT);
    CHECK(vec_eq(s.bg_color, 0.1f, 0.2f, 0.3f));
    scene_free(&s);
    CHECK_EQ_INT(load_text("bg2.scene", "background { zenith 0.5 0.7 1 horizon 1 1 1 }", &s, &err), ST_OK);
    CHECK_EQ_INT(s.bg_type, BG_SKY);
    CHECK(vec_eq(s.bg_color, 1, 1, 1));
    CHECK(vec_eq(s.bg_zenith, 0.5f, 0.7f, 1));
    scene_free(&s);
}

static void test_materials(void)
{
    Scene s;
    Error err;
    Status st = load_text("mat.scene",
                          "material red { type diffuse albedo 0.9 0.1 0.1 }\n"
                          "material \"brushed \\\"steel\\\" \\\\ 2\" { fuzz 0.3 albedo 0.8 0.8 0.8 type metal }\n"
                          "material mirror { type metal albedo 1 1 1 }\n"
                          "material glass { type dielectric ior 1.33 }\n"
                          "material glass2 { type dielectric }\n"
                          "material lamp { type emissive radiance 4 3 2 }\n"
                          "material glow { type diffuse albedo 0.5 0.5 0.5 emission 0.25 0.5 1 sides 2 }\n",
                          &s, &err);
    CHECK_EQ_INT(st, ST_OK);
    CHECK_EQ_INT(s.n_materials, 7);
    if (s.n_materials == 7) {
        CHECK_EQ_INT(s.materials[6].type, MAT_DIFFUSE);
        CHECK(vec_eq(s.materials[6].emission, 0.25f, 0.5f, 1.0f));
        CHECK(vec_eq(s.materials[0].emission, 0.0f, 0.0f, 0.0f));
        CHECK_EQ_INT(s.materials[6].flags, MAT_TWO_SIDED);
        CHECK_EQ_INT(s.materials[5].flags, 0);
        CHECK_EQ_INT(s.materials[0].type, MAT_DIFFUSE);
        CHECK(vec_eq(s.materials[0].albedo, 0.9f, 0.1f, 0.1f));
        CHECK_EQ_INT(s.materials[0].texture, NO_INDEX);
        CHECK_EQ_INT(s.materials[1].type, MAT_METAL);
        CHECK(s.materials[1].fuzz == 0.3f);
        CHECK(vec_eq(s.materials[1].albedo, 0.8f, 0.8f, 0.8f));
        CHECK(strcmp(s.material_names[1], "brushed \"steel\" \\ 2") == 0);
        CHECK(s.materials[2].fuzz == 0.0f);   /* default */
        CHECK_EQ_INT(s.materials[3].type, MAT_DIELECTRIC);
        CHECK(s.materials[3].ior == 1.33f);
        CHECK(s.materials[4].ior == 1.5f);    /* default */
        CHECK_EQ_INT(s.materials[5].type, MAT_EMISSIVE);
        CHECK(vec_eq(s.materials[5].emission, 4, 3, 2));
        CHECK_EQ_INT(scene_find_material(&s, "glass"), 3);
        CHECK_EQ_INT(scene_find_material(&s, "brushed \"steel\" \\ 2"), 1);
    }
    scene_free(&s);
}

/* The principled keys of KHR_materials_volume, _specular and _sheen (docs/scene-format.md):
 * sigma_a = -ln(attenuation_color) / attenuation_distance; no distance, no absorption. */
static void test_principled_layers(void)
{
    Scene s;
    Error err;
    Status st = load_text("layers.scene",
                          "material a { type principled transmission 1 attenuation_color 0.5 1 0.25 "
                          "attenuation_distance 2 specular_factor 0.5 specular_color 1 0.5 2 "
                          "sheen_color 0.9 0.8 0.7 sheen_roughness 0.4 }\n"
                          "material b { type principled attenuation_color 0.5 0.5 0.5 }\n",
                          &s, &err);
    CHECK_EQ_INT(st, ST_OK);
    CHECK_EQ_INT(s.n_materials, 2);
    if (s.n_materials == 2) {
        const Material *a = &s.materials[0], *b = &s.materials[1];
        CHECK_NEAR(a->absorption.x, log(2.0) / 2.0, 1e-6);
        CHECK_NEAR(a->absorption.y, 0.0, 0);
        CHECK_NEAR(a->absorption.z, log(4.0) / 2.0, 1e-6);
        CHECK(a->specular_factor == 0.5f && vec_eq(a->specular_color, 1.0f, 0.5f, 2.0f));
        CHECK(vec_eq(a->sheen_color, 0.9f, 0.8f, 0.7f) && a->sheen_roughness == 0.4f);
        CHECK(vec_eq(b->absorption, 0.0f, 0.0f, 0.0f));
        CHECK(b->specular_factor == 1.0f && vec_eq(b->specular_color, 1.0f, 1.0f, 1.0f));
    }
    scene_free(&s);
}

/* Every documented preset loads, with the table's values (Fe and Ti: Johnson & Christy
 * 1974 at 650/550/450 nm, docs/scene-format.md). */
static void test_metal_presets(void)
{
    Scene s;
    Error err;
    Status st = load_text("metals.scene",
                          "material fe { type conductor metal Fe roughness 0.2 }\n"
                          "material ti { type conductor metal Ti }\n"
                          "material ag { type conductor metal Ag }\n"
                          "material al { type conductor metal Al }\n"
                          "material au { type conductor metal Au }\n"
                          "material cr { type conductor metal Cr }\n"
                          "material cu { type conductor metal Cu }\n"
                          "material ni { type conductor metal Ni }\n",
                          &s, &err);
    CHECK_EQ_INT(st, ST_OK);
    CHECK_EQ_INT(s.n_materials, 8);
    if (s.n_materials == 8) {
        CHECK_EQ_INT(s.materials[0].type, MAT_CONDUCTOR);
        CHECK(vec_eq(s.materials[0].eta, 2.9114f, 2.9497f, 2.5845f));
        CHECK(vec_eq(s.materials[0].k, 3.0893f, 2.9318f, 2.7670f));
        CHECK(s.materials[0].roughness == 0.2f);
        CHECK(vec_eq(s.materials[1].eta, 2.7407f, 2.5418f, 2.2670f));
        CHECK(vec_eq(s.materials[1].k, 3.8143f, 3.4345f, 3.0385f));
        for (int i = 0; i < 8; i++) CHECK_EQ_INT(s.materials[i].flags & MAT_F0, 0);
    }
    scene_free(&s);
}

static void test_primitives(void)
{
    Scene s;
    Error err;
    Status st = load_text("prims.scene",
                          "# a comment line\n"
                          "material m { type diffuse albedo 0.5 0.5 0.5 }  # trailing comment\n"
                          "sphere { center 1 2 3 radius 0.5 material m }\n"
                          "sphere{center -1 -2 -3 radius 2e-1 material{type metal albedo 1 1 1}}\n"
                          "plane { point 0 2 0 normal 0 3 0 material m }\n"
                          "plane { point 1 1 0 normal 1 1 0 material m }\n"
                          "triangle { v0 0 0 0 v1 1 0 0 v2 0 1 0 material m }\n"
                          "quad { v0 0 0 0 v1 2 0 0 v2 2 2 0 v3 0 2 1 material m }\n"
                          "box { min -1 -2 -3 max 1 2 3 material { type emissive radiance 1 1 1 } }\n",
                          &s, &err);
    CHECK_EQ_INT(st, ST_OK);
    CHECK_EQ_INT(s.n_materials, 3);
    CHECK_EQ_INT(s.n_spheres, 2);
    CHECK_EQ_INT(s.n_planes, 2);
    CHECK_EQ_INT(s.n_triangles, 3);
    CHECK_EQ_INT(s.n_boxes, 1);
    if (s.n_spheres == 2) {
        CHECK(vec_eq(s.spheres[0].center, 1, 2, 3));
        CHECK(s.spheres[0].radius == 0.5f);
        CHECK_EQ_INT(s.spheres[0].material, 0);
        CHECK_EQ_INT(s.spheres[0].light, NO_INDEX);
        CHECK(s.spheres[1].radius == 0.2f);
        CHECK_EQ_INT(s.spheres[1].material, 1);   /* the inline metal */
        CHECK_EQ_INT(s.materials[1].type, MAT_METAL);
        CHECK(strcmp(s.material_names[1], "") == 0);
    }
    if (s.n_planes == 2) {
        CHECK(vec_eq(s.planes[0].normal, 0, 1, 0));
        CHECK(s.planes[0].offset == 2.0f);
        CHECK_NEAR(s.planes[1].normal.x, 0.70710678, 1e-7);
        CHECK_NEAR(s.planes[1].normal.y, 0.70710678, 1e-7);
        CHECK(s.planes[1].normal.z == 0.0f);
        CHECK_NEAR(s.planes[1].offset, 1.41421356, 1e-6);
        CHECK_EQ_INT(s.planes[1].material, 0);
    }
    if (s.n_triangles == 3) {
        CHECK(vec_eq(s.triangles[0].p1, 1, 0, 0));
        CHECK_EQ_INT(s.triangles[0].shading, NO_INDEX);
        /* quad (v0 v1 v2 v3) -> (v0 v1 v2) and (v0 v2 v3), v3 off the plane is allowed */
        CHECK(vec_eq(s.triangles[1].p0, 0, 0, 0));
        CHECK(vec_eq(s.triangles[1].p1, 2, 0, 0));
        CHECK(vec_eq(s.triangles[1].p2, 2, 2, 0));
        CHECK(vec_eq(s.triangles[2].p0, 0, 0, 0));
        CHECK(vec_eq(s.triangles[2].p1, 2, 2, 0));
        CHECK(vec_eq(s.triangles[2].p2, 0, 2, 1));
        CHECK_EQ_INT(s.triangles[2].material, 0);
    }
    if (s.n_boxes == 1) {
        CHECK(vec_eq(s.boxes[0].lo, -1, -2, -3));
        CHECK(vec_eq(s.boxes[0].hi, 1, 2, 3));
        CHECK_EQ_INT(s.boxes[0].material, 2);
        CHECK_EQ_INT(s.materials[2].type, MAT_EMISSIVE);
    }
    scene_free(&s);
}

static void test_mesh_and_include(void)
{
    write_tmp("tri.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    write_tmp("common.scene", "material shared { type diffuse albedo 0.2 0.3 0.4 }\n"
                              "image { width 8 height 4 }\n");
    Scene s;
    Error err;
    Status st = load_text("main.scene",
                          "include \"common.scene\"\n"
                          "mesh { file \"tri.obj\" material shared }\n"
                          "mesh { material { type dielectric } file tri.obj }\n",
                          &s, &err);
    CHECK_EQ_INT(st, ST_OK);
    CHECK_EQ_INT(s.image.width, 8);
    CHECK_EQ_INT(s.n_triangles, 4);
    CHECK_EQ_INT(s.n_materials, 2);
    if (s.n_triangles == 4) {
        CHECK_EQ_INT(s.triangles[0].material, 0);
        CHECK_EQ_INT(s.triangles[3].material, 1);
        CHECK(vec_eq(s.triangles[1].p2, 0, 1, 0));
    }
    scene_free(&s);
}

/* ------------------------------------------------------------------ shipped scenes */

static void test_cornell_box(void)
{
    Scene s;
    Error err = {0};
    scene_init(&s);
    Status st = scene_load("scenes/cornell-box.scene", &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_materials, 4);
    CHECK_EQ_INT(s.n_triangles, 38);  /* 19 quads: floor, light, 4 ceiling, 3 walls, 2 x 5 block faces */
    CHECK_EQ_INT(s.n_spheres + s.n_boxes + s.n_planes, 0);
    CHECK_EQ_INT(s.image.width, 512);
    CHECK_EQ_INT(s.image.height, 512);
    CHECK_EQ_INT(s.image.spp, 16);
    CHECK_EQ_INT(s.image.max_depth, 8);
    CHECK(vec_eq(s.camera.from, 278, 273, -800));
    CHECK(vec_eq(s.camera.at, 278, 273, 0));
    CHECK_NEAR(s.camera.vfov, 39.3077, 1e-4);
    uint light = scene_find_material(&s, "light");
    CHECK(light != NO_INDEX);
    int n_light = 0;
    for (size_t i = 0; i < s.n_triangles; i++) {
        if (s.triangles[i].material != light) continue;
        n_light++;
        /* the emitter faces down into the room */
        vec3 n = v3_cross(v3_sub(s.triangles[i].p1, s.triangles[i].p0),
                          v3_sub(s.triangles[i].p2, s.triangles[i].p0));
        CHECK(n.y < 0.0f);
        CHECK(s.triangles[i].p0.y == 548.8f);
    }
    CHECK_EQ_INT(n_light, 2);
    CHECK_EQ_INT(scene_prepare_lights(&s, &err), ST_OK);
    CHECK_EQ_INT(s.n_lights, 2);
    scene_free(&s);
}

static void test_one_weekend(void)
{
    Scene s;
    Error err = {0};
    scene_init(&s);
    Status st = scene_load("scenes/one-weekend.scene", &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    /* ground + 481 small spheres (for this generator's random numbers) + 3 large */
    CHECK_EQ_INT(s.n_spheres, 485);
    CHECK_EQ_INT(s.n_materials, 485);
    CHECK_EQ_INT(s.bg_type, BG_SKY);
    CHECK(vec_eq(s.bg_color, 1, 1, 1));
    CHECK(vec_eq(s.bg_zenith, 0.5f, 0.7f, 1));
    CHECK_EQ_INT(s.image.width, 400);
    CHECK_EQ_INT(s.image.height, 225);
    CHECK(s.camera.aperture == 0.1f);
    CHECK(s.camera.focus_dist == 10.0f);
    CHECK(s.camera.vfov == 20.0f);
    int counts[4] = {0, 0, 0, 0};
    for (size_t i = 1; i + 3 < s.n_spheres; i++) {
        const Sphere *sp = &s.spheres[i];
        CHECK(sp->radius == 0.2f && sp->center.y == 0.2f);
        float dx = sp->center.x - 4.0f, dz = sp->center.z;
        CHECK(dx * dx + dz * dz > 0.81f);
        const Material *m = &s.materials[sp->material];
        if (m->type < 4) counts[m->type]++;
        if (m->type == MAT_METAL) CHECK(m->fuzz >= 0.0f && m->fuzz < 0.5f && m->albedo.x >= 0.5f);
    }
    CHECK_EQ_INT(counts[MAT_DIFFUSE] + counts[MAT_METAL] + counts[MAT_DIELECTRIC], 481);
    CHECK(counts[MAT_DIFFUSE] > 350 && counts[MAT_METAL] > 40 && counts[MAT_DIELECTRIC] > 10);
    if (s.n_spheres == 485) {
        CHECK(s.spheres[0].radius == 1000.0f && vec_eq(s.spheres[0].center, 0, -1000, 0));
        CHECK_EQ_INT(s.materials[s.spheres[482].material].type, MAT_DIELECTRIC);
        CHECK(vec_eq(s.materials[s.spheres[483].material].albedo, 0.4f, 0.2f, 0.1f));
        CHECK_EQ_INT(s.materials[s.spheres[484].material].type, MAT_METAL);
        CHECK(s.materials[s.spheres[484].material].fuzz == 0.0f);
    }
    scene_free(&s);
}

static void test_one_weekend_is_generated(void)
{
    char *generated = NULL, *committed = NULL;
    size_t gen_len = 0;
    FILE *mem = open_memstream(&generated, &gen_len);
    CHECK(mem != NULL);
    if (!mem) return;
    gen_weekend_write(mem);
    fclose(mem);
    FILE *f = fopen("scenes/one-weekend.scene", "rb");
    CHECK(f != NULL);
    size_t len = 0;
    if (f) {
        committed = calloc(gen_len + 2, 1);
        len = fread(committed, 1, gen_len + 1, f);
        fclose(f);
    }
    CHECK_MSG(committed && len == gen_len && memcmp(committed, generated, gen_len) == 0,
              "scenes/one-weekend.scene differs from the output of tools/gen_weekend.c; "
              "regenerate it (see the tool's header)");
    free(committed);
    free(generated);
}

static void test_mesh_scene(void)
{
    /* scenes/mesh.scene draws a mesh of the team's shared models */
    if (!shared_model_present("../shared/models/cornell-box/CornellBox-Sphere.obj", "scenes/mesh.scene is not read"))
        return;
    Scene s;
    Error err = {0};
    scene_init(&s);
    Status st = scene_load("scenes/mesh.scene", &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_triangles, 2188 + 2);  /* the OBJ's triangles + our light quad */
    CHECK_EQ_INT(s.n_shading, 2188);        /* every face of that OBJ has normals */
    CHECK_EQ_INT(s.n_materials, 2);
    /* every mesh vertex is inside the square view: its angle off the view axis is
     * below half the field of view both horizontally and vertically */
    vec3 w = v3_norm(v3_sub(s.camera.at, s.camera.from));
    vec3 u = v3_norm(v3_cross(w, s.camera.up));
    vec3 v = v3_cross(u, w);
    double t = tan(s.camera.vfov * 0.5 * M_PI / 180.0);
    double worst = 0.0;
    for (size_t i = 0; i < s.n_triangles; i++) {
        const vec3 corners[3] = {s.triangles[i].p0, s.triangles[i].p1, s.triangles[i].p2};
        for (int k = 0; k < 3; k++) {
            vec3 d = v3_sub(corners[k], s.camera.from);
            double z = v3_dot(d, w);
            CHECK(z > 0.0);
            double a = fmax(fabs(v3_dot(d, u)), fabs(v3_dot(d, v))) / z;
            if (a > worst) worst = a;
        }
    }
    CHECK_MSG(worst < t, "a vertex is outside the view: tan %.4f > %.4f", worst, t);
    CHECK(worst > 0.85 * t);   /* and the mesh fills most of it */
    scene_free(&s);
}

/* ------------------------------------------------------------------ bad input */

/* Loads `text` and checks the status and that the message is "<path><rest...>". */
static void check_bad(const char *text, Status want, const char *rest)
{
    Scene s;
    Error err;
    const char *path = write_tmp("bad.scene", text);
    Status st = load_text("bad.scene", text, &s, &err);
    CHECK_MSG(st == want, "status %d (%s), expected %d, for: %s", st, err.msg, want, text);
    size_t n = strlen(path);
    CHECK_MSG(strncmp(err.msg, path, n) == 0 && strncmp(err.msg + n, rest, strlen(rest)) == 0,
              "\n    got:      %s\n    expected: %s%s", err.msg, path, rest);
    scene_free(&s);
}

static void test_bad_syntax(void)
{
    check_bad("camera { }\ncam { }\n", ST_INPUT,
              ":2:1: expected a statement (camera, image, background, material, sphere, plane, "
              "triangle, quad, box, mesh, light, texture, medium, include, object, instance, camera_path, "
              "camera_key, instance_key), "
              "found 'cam'");
    check_bad("}", ST_INPUT, ":1:1: expected a statement (camera");
    check_bad("camera fov 30", ST_INPUT, ":1:8: expected '{' to open the camera block, found 'fov'");
    check_bad("camera { fromm 1 2 3 }", ST_INPUT,
              ":1:10: expected a camera key (type, from, at, up, fov, aperture, focus, width, medium, shutter, time) or '}', found 'fromm'");
    check_bad("camera { fov }", ST_INPUT,
              ":1:14: expected a number of degrees in (0, 180) for 'fov', found '}'");
    check_bad("camera {\n  fov 30\n", ST_INPUT,
              ":3:1: expected '}' to close the camera block opened at line 1, found end of file");
    check_bad("material m {\n type diffuse albedo 1 1", ST_INPUT,
              ":2:25: expected 3 numbers >= 0 (a colour) for 'albedo', found end of file");
    check_bad("sphere { center 0 0 0 radius 1\n material { type diffuse\n", ST_INPUT,
              ":3:1: expected '}' to close the material block opened at line 2, found end of file");
    check_bad("sphere { center 1 two 3 radius 1 }", ST_INPUT,
              ":1:19: expected 3 numbers for 'center', found 'two'");
    check_bad("material \"red { type diffuse }", ST_INPUT,
              ":1:10: expected '\"' closing the string that starts here, found end of file");
    check_bad("\n  material \"red { type diffuse }\nsphere { }", ST_INPUT,
              ":2:12: expected '\"' closing the string that starts here, found end of line");
    check_bad("material \"a\\nb\" { }", ST_INPUT,
              ":1:12: expected '\\\"' or '\\\\' (the only escapes in a string), found '\\n'");
    check_bad("camera { fov 30 fov 40 }", ST_INPUT,
              ":1:17: key 'fov' repeated in the camera block (first given at 1:10)");
    check_bad("camera { fov 30 }\n\ncamera { }", ST_INPUT, ":3:1: a second camera block (the first is at ");
    check_bad("image { width 8 }\x01", ST_INPUT, ":1:18: unexpected control byte 0x01");
    check_bad("image { spp 1.5 }", ST_INPUT,
              ":1:13: expected an integer in 1..1000000 for 'spp', found '1.5'");
    check_bad("material", ST_INPUT, ":1:9: expected a material name, found end of file");
}

static void test_bad_values(void)
{
    check_bad("image { width 0 }", ST_INPUT, ":1:15: expected an integer in 1..1048576 for 'width', found '0'");
    check_bad("image { height 16385 }", ST_INPUT, ":1:9: an image of 512x16385 pixels is larger than clpt renders");
    check_bad("image { height 1048577 }", ST_INPUT, ":1:16: expected an integer in 1..1048576 for 'height'");
    check_bad("image { width 99999999999999999999999 }", ST_INPUT,
              ":1:15: expected an integer in 1..1048576 for 'width', found '99999999999999999999999'");
    check_bad("image { depth 1025 }", ST_INPUT, ":1:15: expected an integer in 0..1024 for 'depth'");
    check_bad("image { split 0 }", ST_INPUT, ":1:15: expected auto or an integer in 1..64 for 'split', found '0'");
    check_bad("image { split 65 }", ST_INPUT, ":1:15: expected auto or an integer in 1..64 for 'split', found '65'");
    check_bad("image { split some }", ST_INPUT,
              ":1:15: expected auto or an integer in 1..64 for 'split', found 'some'");
    check_bad("image { spp -1 }", ST_INPUT, ":1:13: expected an integer in 1..1000000 for 'spp', found '-1'");
    check_bad("camera { fov 180 }", ST_INPUT, ":1:14: expected a number of degrees in (0, 180) for 'fov', found '180'");
    check_bad("camera { fov nan }", ST_INPUT, ":1:14: expected a number of degrees in (0, 180) for 'fov', found 'nan'");
    check_bad("camera { aperture -0.1 }", ST_INPUT, ":1:19: expected a number >= 0 for 'aperture'");
    check_bad("camera { focus 0 }", ST_INPUT, ":1:16: expected a distance > 0 for 'focus', found '0'");
    check_bad("camera { from 0 1e39 0 }", ST_INPUT, ":1:17: expected 3 numbers for 'from', found '1e39'");
    check_bad("camera { at inf 0 0 }", ST_INPUT, ":1:13: expected 3 numbers for 'at', found 'inf'");
    check_bad("camera { up 0 0 0 }", ST_INPUT,
              ":1:13: expected a non-zero vector (3 numbers) for 'up', found 0 0 0");
    check_bad("camera { from 1 2 3 at 1 2 3 }", ST_INPUT, ":1:21: camera 'from' and 'at' are the same point");
    check_bad("camera { from 0 5 0 at 0 0 0 }", ST_INPUT, ":1:21: camera 'up' is parallel to the view direction");
    check_bad("camera { from 0 5 0\n at 0 0 0 up 0 -2 0 }", ST_INPUT,
              ":2:11: camera 'up' is parallel to the view direction");
    check_bad("background { color 1 -0.5 1 }", ST_INPUT,
              ":1:22: expected 3 numbers >= 0 (a colour) for 'color', found '-0.5'");
    check_bad("background { color 1 1 1 horizon 1 1 1 zenith 0 0 1 }", ST_INPUT,
              ":1:26: a background is either 'color' (constant) or 'horizon' and 'zenith' (sky), not both");
    check_bad("background { horizon 1 1 1 }", ST_INPUT,
              ":1:1: a sky background needs both 'horizon' and 'zenith'");
    check_bad("background { }", ST_INPUT, ":1:1: the background block needs 'color', or 'horizon' and 'zenith'");
}

static void test_bad_materials_and_shapes(void)
{
    check_bad("sphere { center 0 0 0 radius 1 material blue }", ST_INPUT,
              ":1:41: material 'blue' is not defined (materials must be defined before they are used)");
    check_bad("sphere { center 0 0 0 radius 1 material red }\nmaterial red { type diffuse albedo 1 0 0 }",
              ST_INPUT, ":1:41: material 'red' is not defined");
    {
        const char *path = write_tmp("bad.scene", "");
        char want[512];
        snprintf(want, sizeof want, ":2:10: material 'red' is already defined (at %s:1:1)", path);
        check_bad("material red { type diffuse albedo 1 0 0 }\nmaterial red { type diffuse albedo 1 0 0 }",
                  ST_INPUT, want);
    }
    check_bad("material m { type plastic }", ST_INPUT,
              ":1:19: expected a material type (diffuse, metal, conductor, dielectric, principled, emissive, phong), found 'plastic'");
    check_bad("material m { albedo 1 1 1 }", ST_INPUT, ":1:1: the material block needs 'type' (it has no default)");
    check_bad("material m { type diffuse albedo 1 1 1 fuzz 0.5 }", ST_INPUT,
              ":1:40: expected a diffuse material key (type, albedo, emission, sides, texture) or '}', found 'fuzz'");
    check_bad("material m { type metal albedo 1 1 1 fuzz 1.5 }", ST_INPUT,
              ":1:43: expected a number in [0, 1] for 'fuzz', found '1.5'");
    check_bad("material m { type dielectric ior 0 }", ST_INPUT, ":1:34: expected a number > 0 for 'ior', found '0'");
    check_bad("material m { type emissive }", ST_INPUT, ":1:1: a material of type emissive needs 'radiance'");
    check_bad("material m { type principled attenuation_distance 0 }", ST_INPUT,
              ":1:51: expected a number > 0 for 'attenuation_distance', found '0'");
    check_bad("material \"\" { type dielectric }", ST_INPUT, ":1:10: expected a material name, found '\"\"'");
    check_bad("sphere { center 0 0 0 radius 0 material { type dielectric } }", ST_INPUT,
              ":1:30: expected a radius > 0 for 'radius', found '0'");
    check_bad("sphere { center 0 0 0 material { type dielectric } }", ST_INPUT,
              ":1:1: the sphere block needs 'radius' (it has no default)");
    check_bad("plane { point 0 0 0 normal 0 0 0 material { type dielectric } }", ST_INPUT,
              ":1:28: expected a non-zero vector (3 numbers) for 'normal', found 0 0 0");
    check_bad("box { min 0 0 0 max 1 0 1 material { type dielectric } }", ST_INPUT,
              ":1:17: box 'max' must be greater than 'min' on every axis, but on y it is 0 <= 0");
    check_bad("triangle { v0 0 0 0 v1 1 1 1 v2 2 2 2 material { type dielectric } }", ST_INPUT,
              ":1:1: degenerate triangle: the corners v0 v1 v2 lie on one line");
    check_bad("quad { v0 0 0 0 v1 1 0 0 v2 1 1 0 v3 0 0 0 material { type dielectric } }", ST_INPUT,
              ":1:1: degenerate quad: the corners v0 v2 v3 lie on one line");
}

static void test_bad_files(void)
{
    Scene s;
    Error err = {0};
    scene_init(&s);
    Status st = scene_load("tests/data/no-such-file.scene", &s, &err);
    CHECK_EQ_INT(st, ST_IO);
    CHECK(strcmp(err.msg, "cannot open 'tests/data/no-such-file.scene': No such file or directory") == 0);
    CHECK(s.path && strcmp(s.path, "tests/data/no-such-file.scene") == 0);
    scene_free(&s);

    scene_init(&s);
    st = scene_load("tests", &s, &err);   /* a folder is refused before it is read */
    CHECK_EQ_INT(st, ST_IO);
    CHECK_STR_CONTAINS(err.msg, "cannot read 'tests': it is a directory, not a file");
    scene_free(&s);

    {
        const char *path = write_tmp("bad.scene", "");
        char want[512];
        snprintf(want, sizeof want, ":2:13: cannot open '%.200s/missing.obj': No such file or directory",
                 tmp_dir);
        (void)path;
        check_bad("material m { type dielectric }\nmesh { file \"missing.obj\" material m }", ST_IO, want);
    }
    {
        const char *obj = write_tmp("broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n");
        char want[512];
        snprintf(want, sizeof want, "%s:3:7: expected a vertex index in 1..2 or -2..-1, found '3' "
                                    "(in the mesh of ", obj);
        Scene s2;
        Error e2;
        st = load_text("m.scene", "mesh { file broken.obj material { type dielectric } }", &s2, &e2);
        CHECK_EQ_INT(st, ST_INPUT);
        CHECK_MSG(strncmp(e2.msg, want, strlen(want)) == 0, "got: %s", e2.msg);
        CHECK_STR_CONTAINS(e2.msg, "m.scene:1:1)");
        scene_free(&s2);
    }
    {
        write_tmp("inner.scene", "sphere { radius -1 }\n");
        Scene s2;
        Error e2;
        st = load_text("outer.scene", "\n  include inner.scene", &s2, &e2);
        CHECK_EQ_INT(st, ST_INPUT);
        CHECK_STR_CONTAINS(e2.msg, "inner.scene:1:17: expected a radius > 0 for 'radius', found '-1' "
                                   "(included from ");
        CHECK_STR_CONTAINS(e2.msg, "outer.scene:2:3)");
        scene_free(&s2);
    }
    check_bad("include \"self.scene\"", ST_IO, ":1:9: cannot open");
    {
        write_tmp("loop.scene", "include loop.scene\n");
        Scene s2;
        Error e2;
        st = load_text("loop.scene", "include loop.scene\n", &s2, &e2);
        CHECK_EQ_INT(st, ST_INPUT);
        CHECK_STR_CONTAINS(e2.msg, "loop.scene:1:1: includes nested more than 16 deep");
        CHECK(strstr(e2.msg, "included from") == NULL);
        scene_free(&s2);
    }
}

static void test_huge_token(void)
{
    /* a 200 000-byte word and string must be reported, shortened, without overflow */
    size_t n = 200000;
    char *text = malloc(n + 64);
    strcpy(text, "camera { fov ");
    size_t o = strlen(text);
    memset(text + o, '9', n);
    strcpy(text + o + n, " }");
    check_bad(text, ST_INPUT,
              ":1:14: expected a number of degrees in (0, 180) for 'fov', found "
              "'9999999999999999999999999999999999999999...'");
    strcpy(text, "material \"");
    o = strlen(text);
    memset(text + o, 'x', n);
    strcpy(text + o + n, "\" { type foo }");
    Scene s;
    Error err;
    CHECK_EQ_INT(load_text("bad.scene", text, &s, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "found 'foo'");
    scene_free(&s);
    free(text);
}

/* tests/data/good/everything.scene uses every statement once */
static void test_data_good(void)
{
    Scene s;
    Error err = {0};
    scene_init(&s);
    Status st = scene_load("tests/data/good/everything.scene", &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_materials, 5);          /* 4 included + 1 inline */
    CHECK_EQ_INT(s.n_spheres, 2);
    CHECK_EQ_INT(s.n_planes, 1);
    CHECK_EQ_INT(s.n_boxes, 1);
    CHECK_EQ_INT(s.n_triangles, 1 + 2 + 2);  /* triangle, quad, the OBJ's quad */
    CHECK_EQ_INT(s.n_shading, 2);
    CHECK_EQ_INT(s.image.seed, 42);
    CHECK_EQ_INT(s.bg_type, BG_SKY);
    CHECK(s.camera.aperture == 0.05f);
    if (s.n_boxes == 1) CHECK_EQ_INT(s.boxes[0].material, scene_find_material(&s, "steel"));
    if (s.n_triangles == 5) {
        CHECK_EQ_INT(s.triangles[3].material, scene_find_material(&s, "red"));
        CHECK(vec_eq(s.triangles[4].p2, 1, 0, 0));   /* fan (1 4 3) (1 3 2) */
        CHECK_EQ_INT(s.shading[1].flags, TRI_HAS_NORMALS | TRI_HAS_UV);
    }
    CHECK_EQ_INT(scene_prepare_lights(&s, &err), ST_OK);
    CHECK_EQ_INT(s.n_lights, 2);             /* the lamp quad's two triangles */
    scene_free(&s);
}

/* n named materials and n/2 named textures, each texture used by the next material:
 * every definition and use searched the names from the start (78 s for 200,000
 * materials). Returns the CPU seconds of the load; checks what it read. */
static double load_many_names(int n)
{
    size_t cap = (size_t)n * 96, len = 0;
    char *text = malloc(cap);
    if (!text) abort();
    for (int i = 0; i < n; i++) {
        if (i % 2 == 0)
            len += (size_t)snprintf(text + len, cap - len, "texture t%d { type checker }\n", i);
        len += (size_t)snprintf(text + len, cap - len, "material m%d { type diffuse albedo 1 1 1%s", i,
                                i % 2 == 0 ? " texture " : " }\n");
        if (i % 2 == 0) len += (size_t)snprintf(text + len, cap - len, "t%d }\n", i);
    }
    snprintf(text + len, cap - len, "sphere { center 0 0 0 radius 1 material m%d }\n", n - 1);
    Scene s;
    Error err;
    double t0 = cpu_seconds();
    Status st = load_text("many.scene", text, &s, &err);
    double secs = cpu_seconds() - t0;
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_materials, n);
    CHECK_EQ_INT(s.n_textures, n / 2);
    int m = n / 2 + 1, t = n / 2; /* an odd material, and the even texture before it */
    char name[32];
    snprintf(name, sizeof name, "m%d", m);
    CHECK_EQ_INT(scene_find_material(&s, name), m);
    snprintf(name, sizeof name, "t%d", t);
    CHECK_EQ_INT(scene_find_texture(&s, name), t / 2);
    if (s.n_materials == (size_t)n) CHECK_EQ_INT(s.materials[t].texture, t / 2);
    if (s.n_spheres == 1) CHECK_EQ_INT(s.spheres[0].material, n - 1);
    scene_free(&s);
    free(text);
    return secs;
}

static void test_many_names(void)
{
    enum { N = 160000 };
    double secs_n = load_many_names(N / GROWTH_FACTOR), secs_8n = load_many_names(N);
    CHECK_LINEAR("named materials and textures", secs_n, secs_8n);
    /* the second definition of a name is still refused, with the first's place */
    Scene s;
    Error err;
    CHECK_EQ_INT(load_text("twice.scene", "material a { type diffuse albedo 1 1 1 }\nmaterial b { type diffuse albedo 1 1 1 }\n"
                           "material a { type diffuse albedo 1 1 1 }\n", &s, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "twice.scene:3:10: material 'a' is already defined (at ");
    scene_free(&s);
}

int main(void)
{
    snprintf(tmp_dir, sizeof tmp_dir, "/tmp/clpt-test-scene-XXXXXX");
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(test_lexer);
    RUN(test_camera_and_image);
    RUN(test_defaults_kept);
    RUN(test_backgrounds);
    RUN(test_materials);
    RUN(test_principled_layers);
    RUN(test_metal_presets);
    RUN(test_primitives);
    RUN(test_mesh_and_include);
    RUN(test_cornell_box);
    RUN(test_one_weekend);
    RUN(test_one_weekend_is_generated);
    RUN(test_mesh_scene);
    RUN(test_bad_syntax);
    RUN(test_bad_values);
    RUN(test_bad_materials_and_shapes);
    RUN(test_bad_files);
    RUN(test_huge_token);
    RUN(test_data_good);
    RUN(test_many_names);
    tmp_cleanup();
    return harness_report();
}
