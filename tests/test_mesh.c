/* test_mesh.c — what the mesh readers share (host/scene/transform.c, host/scene/mesh_sink.c,
 * host/io/mesh_load.c, host/io/mesh_text.c): transforms and the sink,
 * case-insensitive paths, the procedural sphere; the mesh block of scene files with its
 * transform keys; a bare mesh shown on its own (host/io/mesh_view.c), in-process and
 * through the command line. */
#include "harness.h"

#include "cli_util.h"
#include "util/kmath.h"
#include "io/mesh_load.h"
#include "io/mesh_text.h"
#include "io/mesh_view.h"
#include "io/path.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static int near3(vec3 a, double x, double y, double z, double tol)
{
    return fabs(a.x - x) <= tol && fabs(a.y - y) <= tol && fabs(a.z - z) <= tol;
}

/* ------------------------------------------------------------------ transforms */

static void test_transforms(void)
{
    Transform id = transform_identity();
    CHECK(transform_is_identity(&id));
    CHECK(transform_det(&id) == 1.0);
    /* quarter turns are exact: axes go to axes */
    Transform ry = transform_rotate(0.0, 1.0, 0.0, 90.0);
    vec3 p = transform_point(&ry, v3(1.0f, 2.0f, 3.0f));
    CHECK(p.x == 3.0f && p.y == 2.0f && p.z == -1.0f);
    Transform rz = transform_rotate(0.0, 0.0, 5.0, -270.0);   /* axis length does not matter */
    p = transform_point(&rz, v3(1.0f, 0.0f, 0.0f));
    CHECK(p.x == 0.0f && p.y == 1.0f && p.z == 0.0f);
    /* any angle about any axis: a rotation (orthonormal, det 1) that keeps the axis */
    Transform r = transform_rotate(1.0, 2.0, 3.0, 37.0);
    CHECK_NEAR(transform_det(&r), 1.0, 1e-12);
    p = transform_point(&r, v3(1.0f, 2.0f, 3.0f));
    CHECK(near3(p, 1.0, 2.0, 3.0, 1e-6));
    /* 120 degrees about (1,1,1) cycles the axes */
    Transform cyc = transform_rotate(1.0, 1.0, 1.0, 120.0);
    CHECK(near3(transform_point(&cyc, v3(1.0f, 0.0f, 0.0f)), 0.0, 1.0, 0.0, 1e-6));
    /* composition: scale, then rotate, then translate */
    Transform s = transform_scale(2.0, 3.0, 4.0), t = transform_translate(10.0, 20.0, 30.0);
    Transform rs = transform_compose(&ry, &s), trs = transform_compose(&t, &rs);
    p = transform_point(&trs, v3(1.0f, 1.0f, 1.0f));
    CHECK(p.x == 14.0f && p.y == 23.0f && p.z == 28.0f);
    CHECK_NEAR(transform_det(&trs), 24.0, 1e-12);
}

/* The sink: transformed corners and normals, a mirror keeps the winding side. */
static void test_sink(void)
{
    Scene sc;
    scene_init(&sc);
    Error err = { 0 };
    MeshSink k;
    const vec3 tri[3] = { v3(0.0f, 0.0f, 0.0f), v3(1.0f, 0.0f, 0.0f), v3(0.0f, 1.0f, 0.0f) };
    const vec3 n[3] = { v3(0.0f, 0.0f, 1.0f), v3(1.0f, 0.0f, 1.0f), v3(0.0f, 0.0f, 3.0f) };
    const float uv[6] = { 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f };
    Transform mirror = transform_scale(-1.0, 1.0, 1.0);
    CHECK_EQ_INT(mesh_sink_open(&k, &sc, &mirror, "m", &err), ST_OK);
    CHECK(k.mirrored);
    CHECK_EQ_INT(mesh_sink_triangle(&k, tri, n, uv, 4), ST_OK);
    CHECK_EQ_INT(sc.n_triangles, 1);
    CHECK_EQ_INT(sc.n_shading, 1);
    if (sc.n_triangles == 1 && sc.n_shading == 1) {
        const Triangle *t = &sc.triangles[0];
        /* corners 1 and 2 swapped, so the winding normal is still +z */
        CHECK(near3(t->p1, 0.0, 1.0, 0.0, 0.0) && near3(t->p2, -1.0, 0.0, 0.0, 0.0));
        vec3 ng = v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0));
        CHECK(ng.z > 0.0f);
        const TriShading *sh = &sc.shading[0];
        CHECK_EQ_INT(sh->flags, TRI_HAS_NORMALS | TRI_HAS_UV);
        CHECK(near3(sh->n0, 0.0, 0.0, 1.0, 0.0));
        CHECK(near3(sh->n1, 0.0, 0.0, 1.0, 0.0));                       /* the old corner 2 */
        CHECK(near3(sh->n2, -0.70710678, 0.0, 0.70710678, 1e-7));      /* the old corner 1, mirrored */
        CHECK(sh->uv1[0] == 0.0f && sh->uv1[1] == 1.0f && sh->uv2[0] == 1.0f);
        CHECK_EQ_INT(t->material, 4);
    }
    /* a transform that flattens everything is refused */
    Transform flat = transform_scale(1.0, 0.0, 1.0);
    CHECK_EQ_INT(mesh_sink_open(&k, &sc, &flat, "flat.obj", &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "flat.obj: the mesh transform is singular");
    /* a normal the transform cannot turn (zero) drops the triangle's normals only */
    CHECK_EQ_INT(mesh_sink_open(&k, &sc, NULL, "m", &err), ST_OK);
    const vec3 zero[3] = { v3(0.0f, 0.0f, 0.0f), v3(0.0f, 0.0f, 1.0f), v3(0.0f, 0.0f, 1.0f) };
    CHECK_EQ_INT(mesh_sink_triangle(&k, tri, zero, uv, 0), ST_OK);
    CHECK_EQ_INT(sc.n_shading, 2);
    if (sc.n_shading == 2) CHECK_EQ_INT(sc.shading[1].flags, TRI_HAS_UV);
    scene_free(&sc);
}

static void test_paths(void)
{
    char dir[] = "/tmp/clpt-mesh-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char sub[128], file[160];
    snprintf(sub, sizeof sub, "%s/Textures", dir);
    mkdir(sub, 0700);
    snprintf(file, sizeof file, "%s/Brick Wall.PNG", sub);
    FILE *f = fopen(file, "w");
    if (f) fclose(f);
    char beside[160];
    snprintf(beside, sizeof beside, "%s/scene.mtl", dir);
    char want[200];
    snprintf(want, sizeof want, "%s/Textures/Brick Wall.PNG", dir);
    const char *names[] = { "Textures/Brick Wall.PNG", "textures/brick wall.png", "TEXTURES\\BRICK WALL.png" };
    for (int i = 0; i < 3; i++) {
        char *p;
        path_resolve(beside, names[i], strlen(names[i]), PATH_ANY_CASE, &p);
        CHECK_MSG(p && strcmp(p, want) == 0, "%s -> %s", names[i], p ? p : "(null)");
        free(p);
    }
    /* nothing matches: the path as written (the texture loader reports it) */
    char *p;
    path_resolve(beside, "textures/none.png", 17, PATH_ANY_CASE, &p);
    char none[200];
    snprintf(none, sizeof none, "%s/textures/none.png", dir);
    CHECK(p && strcmp(p, none) == 0);
    free(p);
    /* absolute names are kept as they are */
    path_resolve(beside, file, strlen(file), PATH_ANY_CASE, &p);
    CHECK(p && strcmp(p, file) == 0);
    free(p);
    remove(file);
    rmdir(sub);
    rmdir(dir);
    CHECK_EQ_INT(mesh_kind("a/b.OBJ"), MESH_OBJ);
    CHECK_EQ_INT(mesh_kind("b.ply"), MESH_PLY);
    CHECK_EQ_INT(mesh_kind("b.ply.gz"), MESH_PLY); /* inflated as it is read */
    CHECK_EQ_INT(mesh_kind("d/b.OBJ.gz"), MESH_OBJ);
    CHECK_EQ_INT(mesh_kind("b.gltf.gz"), MESH_NONE);
    CHECK_EQ_INT(mesh_kind("ply.gz"), MESH_NONE);
    CHECK_EQ_INT(mesh_kind(".ply.gz"), MESH_PLY);
    CHECK_EQ_INT(mesh_kind("dir.obj/scene"), MESH_NONE);
}

/* The procedural sphere is closed: every edge is used once in each direction. */
static void test_sphere_is_closed(void)
{
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    CHECK_EQ_INT(mesh_make_sphere(&s, 2000, 0, &err), ST_OK);
    size_t n = s.n_triangles;
    CHECK(n >= 2000 && n < 2600);
    /* directed edges as sorted (from, to) vertex-position keys; each must appear once,
     * and its reverse once */
    typedef struct { float a[3], b[3]; } Edge;
    Edge *e = malloc(3 * n * sizeof *e);
    size_t m = 0;
    int outward = 0;
    for (size_t i = 0; i < n; i++) {
        const Triangle *t = &s.triangles[i];
        const vec3 *c[3] = { &t->p0, &t->p1, &t->p2 };
        for (int j = 0; j < 3; j++) {
            const vec3 *a = c[j], *b = c[(j + 1) % 3];
            Edge ed = { { a->x, a->y, a->z }, { b->x, b->y, b->z } };
            e[m++] = ed;
        }
        vec3 ng = v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0));
        vec3 mid = v3_scale(v3_add(v3_add(t->p0, t->p1), t->p2), 1.0f / 3.0f);
        outward += v3_dot(ng, mid) > 0.0f;
    }
    CHECK_EQ_INT(outward, (long long)n);
    size_t unmatched = 0;
    for (size_t i = 0; i < m && unmatched < 5; i++) {
        int fwd = 0, rev = 0;
        for (size_t j = 0; j < m; j++) {
            fwd += !memcmp(e[j].a, e[i].a, sizeof e[i].a) && !memcmp(e[j].b, e[i].b, sizeof e[i].b);
            rev += !memcmp(e[j].a, e[i].b, sizeof e[i].b) && !memcmp(e[j].b, e[i].a, sizeof e[i].a);
        }
        unmatched += fwd != 1 || rev != 1;
    }
    CHECK_EQ_INT(unmatched, 0);
    free(e);
    scene_free(&s);
}

/* ------------------------------------------------------------------ scene files */

static const char *write_file(const char *name, const char *text)
{
    static char path[8][256];
    static int next;
    char *p = path[next++ % 8];
    char leaf[128];
    snprintf(leaf, sizeof leaf, "clpt-test-mesh-%s", name);
    test_tmp_path(p, 256, leaf);
    FILE *f = fopen(p, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    return p;
}

static Status load_scene_text(const char *text, Scene *s, Error *err)
{
    const char *path = write_file("s.scene", text);
    scene_init(s);
    memset(err, 0, sizeof *err);
    return scene_load(path, s, err);
}

static void test_scene_mesh_block(void)
{
    write_file("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n");
    write_file("tri.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                          "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    Scene s;
    Error err;
    Status st = load_scene_text(
        "material m { type diffuse albedo 0.5 0.5 0.5 }\n"
        "mesh { file clpt-test-mesh-tri.obj material m translate 1 2 3 }\n"
        "mesh { file clpt-test-mesh-tri.obj material m scale 2 rz 90 }\n"
        "mesh { file clpt-test-mesh-tri.ply material m scale 1 2 3 rotate 0 0 1 90 translate 0 0 1 }\n"
        "mesh { file clpt-test-mesh-tri.ply material m matrix 0 -1 0 5  1 0 0 0  0 0 1 0  0 0 0 1 }\n"
        "mesh { file clpt-test-mesh-tri.obj rx 90 ry 90 }\n"
        "mesh { file clpt-test-mesh-tri.obj material m scale -1 1 1 }\n",
        &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_triangles, 6);
    if (s.n_triangles == 6) {
        const Triangle *t = s.triangles;
        CHECK(near3(t[0].p0, 1, 2, 3, 0) && near3(t[0].p1, 2, 2, 3, 0));
        CHECK(near3(t[1].p1, 0, 2, 0, 0) && near3(t[1].p2, -2, 0, 0, 0));   /* scaled, then turned */
        CHECK(near3(t[2].p1, 0, 1, 1, 0) && near3(t[2].p2, -2, 0, 1, 0));   /* (0,2,0) turned to (-2,0,0) */
        CHECK(near3(t[3].p1, 5, 1, 0, 0) && near3(t[3].p2, 4, 0, 0, 0));
        /* rx 90 takes (0,1,0) to (0,0,1), then ry 90 takes it to (1,0,0) */
        CHECK(near3(t[4].p2, 1, 0, 0, 0));
        /* no material: the default grey */
        CHECK(t[4].material == 1 && s.materials[1].type == MAT_DIFFUSE);
        /* the shading normal turned with it: +z by rx 90 to -y, by ry 90 stays -y */
        if (t[4].shading < s.n_shading) CHECK(near3(s.shading[t[4].shading].n0, 0, -1, 0, 0));
        /* a mirror: corners swapped, winding normal still +z, shading normal still +z */
        CHECK(near3(t[5].p1, 0, 1, 0, 0) && near3(t[5].p2, -1, 0, 0, 0));
        if (t[5].shading < s.n_shading) CHECK(near3(s.shading[t[5].shading].n0, 0, 0, 1, 0));
    }
    scene_free(&s);
}

static void check_scene_bad(const char *text, const char *want)
{
    Scene s;
    Error err;
    Status st = load_scene_text(text, &s, &err);
    CHECK_MSG(st == ST_INPUT, "%s: status %d", text, (int)st);
    CHECK_MSG(strstr(err.msg, want) != NULL, "got \"%s\", want \"%s\"", err.msg, want);
    scene_free(&s);
}

static void test_scene_mesh_errors(void)
{
    write_file("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    check_scene_bad("mesh { file clpt-test-mesh-tri.obj scale 0 }",
                    "s.scene:1:42: expected a non-zero scale factor, or three (x y z) for 'scale', found '0'");
    check_scene_bad("mesh { file clpt-test-mesh-tri.obj scale 1 0 1 }", "s.scene:1:44: expected a non-zero scale");
    check_scene_bad("mesh { file clpt-test-mesh-tri.obj scale 1 2 }", "s.scene:1:46: expected a non-zero scale");
    check_scene_bad("mesh { file clpt-test-mesh-tri.obj rotate 0 0 0 45 }",
                    "s.scene:1:43: expected an axis and an angle in degrees (4 numbers, the axis not 0 0 0) for "
                    "'rotate', found the axis 0 0 0");
    check_scene_bad("mesh { file clpt-test-mesh-tri.obj rotate 0 1 0 }", "for 'rotate', found '}'");
    check_scene_bad("mesh { file clpt-test-mesh-tri.obj matrix 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 }",
                    "expected 16 numbers (a 4x4 matrix, row by row) for 'matrix', found '}'");
    check_scene_bad("mesh { file clpt-test-mesh-tri.obj matrix 1 0 0 0 0 1 0 0 0 0 1 0 0 0 1 1 }",
                    "s.scene:1:36: the last row of 'matrix' must be 0 0 0 1 (an affine transform), found 0 0 1 1");
    check_scene_bad("mesh { file clpt-test-mesh-tri.obj matrix 1 0 0 0 0 0 0 0 0 0 1 0 0 0 0 1 }",
                    "s.scene:1:36: the mesh transform is singular");
    check_scene_bad("mesh { translate 1 1 1 file clpt-test-mesh-tri.obj matrix 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 }",
                    "s.scene:1:52: 'matrix' cannot be combined with translate, rotate, rx, ry, rz or scale");
    check_scene_bad("mesh { file clpt-test-mesh-tri.stl }",
                    "s.scene:1:13: expected a mesh file name ending in .obj, .ply, .obj.gz, .ply.gz, .gltf "
                    "or .glb, found 'clpt-test-mesh-tri.stl'");
    check_scene_bad("mesh { file clpt-test-mesh-tri.obj shear 1 }",
                    "expected a mesh key (file, material, translate, rotate, rx, ry, rz, scale, matrix, interior, exterior) or '}'");
    /* the key after a one-number scale is read as a key */
    Scene s;
    Error err;
    CHECK_EQ_INT(load_scene_text("mesh { file clpt-test-mesh-tri.obj scale 3 translate 1 0 0 }", &s, &err), ST_OK);
    if (s.n_triangles == 1) CHECK(near3(s.triangles[0].p1, 4, 0, 0, 0));
    scene_free(&s);
}

/* ------------------------------------------------------------------ a bare mesh */

/* Every vertex lies inside the camera's view, for square and tall images. */
static void check_framed(const Scene *s)
{
    vec3 f = v3_norm(v3_sub(s->camera.at, s->camera.from));
    vec3 r = v3_norm(v3_cross(f, s->camera.up));
    vec3 u = v3_cross(r, f);
    double tv = tan(s->camera.vfov * M_PI / 360.0), th = tv * s->image.width / s->image.height;
    double worst = 0.0;
    for (size_t i = 0; i < s->n_triangles; i++) {
        const vec3 *p[3] = { &s->triangles[i].p0, &s->triangles[i].p1, &s->triangles[i].p2 };
        for (int j = 0; j < 3; j++) {
            vec3 d = v3_sub(*p[j], s->camera.from);
            double z = v3_dot(d, f);
            CHECK(z > 0.0);
            worst = fmax(worst, fmax(fabs(v3_dot(d, r)) / z / th, fabs(v3_dot(d, u)) / z / tv));
        }
    }
    CHECK(worst < 1.0);
    CHECK(worst > 0.4);   /* and the mesh is not lost in the middle */
}

static void test_mesh_view(void)
{
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    CHECK_EQ_INT(mesh_view_load("tests/data/models/bun_zipper_res4.ply", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 948);
    CHECK_EQ_INT(s.n_spheres, 1);
    CHECK_EQ_INT(s.bg_type, BG_SKY);
    CHECK(s.path && strcmp(s.path, "tests/data/models/bun_zipper_res4.ply") == 0);
    if (s.n_spheres == 1) {
        const Material *sun = &s.materials[s.spheres[0].material];
        CHECK(sun->emission.x > 0.0f);
        CHECK(s.spheres[0].center.y > s.camera.at.y);   /* above */
        CHECK_EQ_INT(s.triangles[0].material, 0);        /* the grey, before the sun's */
        CHECK_EQ_INT(s.materials[0].type, MAT_DIFFUSE);
    }
    check_framed(&s);
    s.image.width = 100;
    s.image.height = 400;
    CHECK_EQ_INT(mesh_view_fit(&s, &err), ST_OK);
    check_framed(&s);
    scene_free(&s);
    /* MTL materials are kept */
    scene_init(&s);
    CHECK_EQ_INT(mesh_view_load("tests/data/mtl/scene.obj", &s, &err), ST_OK);
    CHECK(s.n_materials >= 9);
    scene_free(&s);
    /* nothing to show */
    write_file("empty.obj", "v 0 0 0\n");
    scene_init(&s);
    CHECK_EQ_INT(mesh_view_load(TEST_TMP("clpt-test-mesh-empty.obj"), &s, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "clpt-test-mesh-empty.obj: the mesh has no triangles to show");
    scene_free(&s);
    /* corners near the float range: the camera that frames them would be beyond it (the
     * message named the camera, not the file) */
    write_file("far.obj", "v 2e38 0 0\nv 0 2e38 0\nv 0 0 0\nf 1 2 3\n");
    scene_init(&s);
    CHECK_EQ_INT(mesh_view_load(TEST_TMP("clpt-test-mesh-far.obj"), &s, &err), ST_INPUT);
    char want[512];
    snprintf(want, sizeof want, "%s: the mesh is too large to ", TEST_TMP("clpt-test-mesh-far.obj"));
    CHECK_STR_CONTAINS(err.msg, want);
    CHECK_STR_CONTAINS(err.msg, "beyond the largest float (about 3.4e38)");
    scene_free(&s);
    error_clear(&err);
}

/* A triangle whose corners are finite but so far apart that the kernels' float edges
 * overflow is refused by the sink, naming the mesh file and the triangle (it was kept,
 * and never hit). */
static void test_sink_huge_corners(void)
{
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    MeshSink k;
    CHECK_EQ_INT(mesh_sink_open(&k, &s, NULL, "far.ply", &err), ST_OK);
    vec3 ok[3] = { v3(1e38f, 0.0f, 0.0f), v3(0.0f, 1e38f, 0.0f), v3(0.0f, 0.0f, 1.0f) };
    vec3 far[3] = { v3(3e38f, 0.0f, 0.0f), v3(-3e38f, 0.0f, 0.0f), v3(0.0f, 1.0f, 0.0f) };
    CHECK_EQ_INT(mesh_sink_triangle(&k, ok, NULL, NULL, 0), ST_OK);
    CHECK_EQ_INT(mesh_sink_triangle(&k, far, NULL, NULL, 0), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "far.ply: the corners of triangle 2 are too far apart (their differences "
                                "overflow single precision)");
    /* and after the transform, which can carry near corners far apart */
    Transform big = transform_scale(1e30, 1e30, 1e30);
    CHECK_EQ_INT(mesh_sink_open(&k, &s, &big, "scaled.obj", &err), ST_OK);
    CHECK_EQ_INT(mesh_sink_triangle(&k, (const vec3[3]){ v3(3e8f, 0.0f, 0.0f), v3(-3e8f, 0.0f, 0.0f),
                                                          v3(0.0f, 1.0f, 0.0f) }, NULL, NULL, 0), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "scaled.obj: the corners of triangle 1 are too far apart");
    CHECK_STR_CONTAINS(err.msg, "after the mesh transform");
    scene_free(&s);
    error_clear(&err);
}

/* `clpt model.ply -o model.png` renders, with the mesh's name as the default output. */
static void test_cli(void)
{
    char out[512];
    test_tmp_path(out, sizeof out, "clpt-test-mesh.png");
    const char *args[] = { "tests/data/models/bun_zipper_res4.ply", "-o", out, "--spp", "2", "--width", "24",
                           "--height", "16", "--device", "scalar", "-q", "--stats", NULL };
    CliResult *r = malloc(sizeof *r);
    cli_run(args, r);
    CHECK_MSG(r->status == 0, "exit %d: %s", r->status, r->err);
    CHECK(file_exists(out));
    CHECK_STR_CONTAINS(r->out, "scene: 1 spheres, 948 triangles");
    CHECK_STR_CONTAINS(r->out, "bytes per primitive)");
    remove(out);
    const char *bad[] = { "tests/data/ply/no-such.ply", "-o", out, NULL };
    cli_run(bad, r);
    CHECK_EQ_INT(r->status, 4);
    CHECK_STR_CONTAINS(r->err, "cannot open 'tests/data/ply/no-such.ply'");
    free(r);
}

int main(void)
{
    RUN(test_transforms);
    RUN(test_sink);
    RUN(test_paths);
    RUN(test_sphere_is_closed);
    RUN(test_scene_mesh_block);
    RUN(test_scene_mesh_errors);
    RUN(test_mesh_view);
    RUN(test_sink_huge_corners);
    RUN(test_cli);
    return harness_report();
}
