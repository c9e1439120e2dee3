/*
 * test_classic.c — the classic scene format (host/io/classic_parse.c): every keyword, the
 * format's defaults, transforms, material scoping, CRLF, where mesh and texture files
 * are looked for, format detection, and malformed files with their file:line:column
 * messages; the light, texture and phong additions to our own format; the command-line
 * flags of the classic ray tracer.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "harness.h"
#include "cli_util.h"
#include "render_util.h"

#include "base/limit.h"
#include "io/classic_parse.h"
#include "io/scene_load.h"
#include "util/kmath.h"
#include "scene/instance.h"
#include "scene/mesh_sink.h"
#include "scene/scene.h"

#include <stb_image_write.h>

static char dir[64];           /* a temporary folder for this test's files */

static void write_file(const char *name, const char *text)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* Loads `text` written to DIR/name as a classic scene. */
static Status load(const char *name, const char *text, Scene *s, Error *err)
{
    char path[256];
    write_file(name, text);
    snprintf(path, sizeof path, "%s/%s", dir, name);
    scene_init(s);
    memset(err, 0, sizeof *err);
    return classic_load(path, s, err);
}

static int near3(vec3 a, double x, double y, double z, double tol)
{
    return fabs(a.x - x) <= tol && fabs(a.y - y) <= tol && fabs(a.z - z) <= tol;
}

static const char *camera = "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }\n";

/* ---------------------------------------------------------------- every keyword */

static const char *everything =
    "PerspectiveCamera {\n"
    "    center 0 1 10\n"
    "    direction 0 0 -2\n"
    "    up 0 1 0\n"
    "    angle 40\n"
    "    width 320\n"
    "    height 240\n"
    "}\n"
    "Lights {\n"
    "    numLights 4\n"
    "    DirectionalLight { direction 0 -2 0 color 0.5 0.5 0.5 }\n"
    "    PointLight { position 1 2 3 color 1 0.5 0.25 falloff 0.1 }\n"
    "    PointLight { position 0 5 0 color 1 1 1 attenuation 1 0.5 0.25 }\n"
    "    SpotLight { position 0 4 0 direction 0 -1 0 color 2 2 2 angle 60 innerAngle 30 }\n"
    "}\n"
    "Background { color 0.1 0.2 0.3 ambientLight 0.05 0.06 0.07 }\n"
    "Materials {\n"
    "    numMaterials 5\n"
    "    Material { }\n"
    "    PhongMaterial {\n"
    "        diffuseColor 0.5 0.6 0.7\n"
    "        specularColor 0.2 0.3 0.4\n"
    "        shininess 25\n"
    "        reflectiveColor 0.1 0.2 0.3\n"
    "        transparentColor 0.4 0.5 0.6\n"
    "        indexOfRefraction 1.33\n"
    "        texture tex.png\n"
    "    }\n"
    "    PhongMaterial { diffuseColor 0.9 0.1 0.1 exponent 7 }\n"
    "    Material { diffuseColor 0.1 0.1 0.9 }\n"
    "    Checkerboard { Transform { UniformScale 2 } materialIndex 2 materialIndex 3 }\n"
    "}\n"
    "Group {\n"
    "    numObjects 5\n"
    "    MaterialIndex 1\n"
    "    Sphere { center 1 2 3 radius 0.5 }\n"
    "    Plane { normal 0 2 0 offset -2 }\n"
    "    MaterialIndex 4\n"
    "    Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 }\n"
    "    TriangleMesh { obj_file quad.obj }\n"
    "    Group {\n"
    "        numObjects 1\n"
    "        MaterialIndex 2\n"
    "        Transform {\n"
    "            Translate 1 0 0\n"
    "            Scale 2 2 2\n"
    "            UniformScale 1\n"
    "            XRotate 0\n"
    "            YRotate 0\n"
    "            ZRotate 0\n"
    "            Rotate { 0 1 0 0 }\n"
    "            Matrix4f { 1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1 }\n"
    "            Matrix { 1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1 }\n"
    "            Sphere { center 0 0 0 radius 1 }\n"
    "        }\n"
    "    }\n"
    "}\n";

static void write_assets(void)
{
    write_file("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                           "f 1/1 2/2 3/3 4/4\n");
    unsigned char px[12] = { 255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255 };
    char path[256];
    snprintf(path, sizeof path, "%s/tex.png", dir);
    stbi_write_png(path, 2, 2, 3, px, 6);
}

static void test_every_keyword(void)
{
    Scene s;
    Error err;
    Status st = load("everything.txt", everything, &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st) {
        scene_free(&s);
        return;
    }
    /* how the course's renderer draws it */
    CHECK_EQ_INT(s.integrator, INTEGRATOR_WHITTED);
    CHECK_EQ_INT(s.linear_output, 1);
    CHECK_EQ_INT(s.image.spp, 1);
    /* camera and image size */
    CHECK_EQ_INT(s.camera.type, CAMERA_PERSPECTIVE);
    CHECK(near3(s.camera.from, 0, 1, 10, 0));
    CHECK(near3(s.camera.at, 0, 1, 9, 1e-6));                 /* direction made unit */
    CHECK(s.camera.vfov == 40.0f);
    CHECK_EQ_INT(s.image.width, 320);
    CHECK_EQ_INT(s.image.height, 240);
    /* lights: intensity pi x colour, the format's attenuations */
    CHECK_EQ_INT(s.n_delta_lights, 4);
    if (s.n_delta_lights == 4) {
        const Light *l = s.delta_lights;
        CHECK_EQ_INT(l[0].type, LIGHT_DIRECTIONAL);
        CHECK(near3(l[0].direction, 0, -1, 0, 0));
        CHECK(near3(l[0].intensity, 0.5 * M_PI, 0.5 * M_PI, 0.5 * M_PI, 1e-6));
        CHECK_EQ_INT(l[1].type, LIGHT_POINT);
        CHECK(near3(l[1].position, 1, 2, 3, 0));
        CHECK(l[1].atten0 == 0.0f && l[1].atten1 == 0.0f && l[1].atten2 == 0.1f);
        CHECK(near3(l[1].intensity, M_PI, 0.5 * M_PI, 0.25 * M_PI, 1e-6));
        CHECK(l[2].atten0 == 1.0f && l[2].atten1 == 0.5f && l[2].atten2 == 0.25f);
        CHECK_EQ_INT(l[3].type, LIGHT_SPOT);
        CHECK_NEAR(l[3].cos_outer, 0.5, 1e-6);
        CHECK_NEAR(l[3].cos_inner, sqrt(3.0) / 2, 1e-6);
        CHECK(l[3].atten0 == 1.0f && l[3].atten2 == 0.0f);    /* no falloff by default */
    }
    CHECK(near3(s.bg_color, 0.1, 0.2, 0.3, 1e-7));
    CHECK(near3(s.ambient, 0.05, 0.06, 0.07, 1e-7));
    /* materials: the defaults, every Phong field, the texture, the checkerboard */
    CHECK_EQ_INT(s.n_materials, 5);
    if (s.n_materials == 5) {
        Material m0 = s.materials[0], m1 = s.materials[1], m2 = s.materials[2], m4 = s.materials[4];
        CHECK_EQ_INT(m0.type, MAT_PHONG);
        CHECK(near3(m0.albedo, 1, 1, 1, 0) && v3_is_zero(m0.specular) && m0.shininess == 0.0f);
        CHECK(v3_is_zero(m0.reflective) && v3_is_zero(m0.transparent) && m0.ior == 1.0f);
        CHECK(m0.texture == NO_INDEX);
        CHECK(near3(m1.albedo, 0.5, 0.6, 0.7, 1e-7) && near3(m1.specular, 0.2, 0.3, 0.4, 1e-7));
        CHECK(m1.shininess == 25.0f && m1.ior == 1.33f);
        CHECK(near3(m1.reflective, 0.1, 0.2, 0.3, 1e-7) && near3(m1.transparent, 0.4, 0.5, 0.6, 1e-7));
        CHECK(m1.texture != NO_INDEX);
        if (m1.texture != NO_INDEX) {
            Texture t = s.textures[m1.texture];
            /* classic textures are linear, as the course reads them */
            CHECK(t.type == TEX_IMAGE && t.width == 2 && t.height == 2 && t.flags == 0u);
        }
        CHECK(m2.shininess == 7.0f);
        CHECK(m4.texture != NO_INDEX && near3(m4.albedo, 0.9, 0.1, 0.1, 1e-7));
        if (m4.texture != NO_INDEX) {
            Texture t = s.textures[m4.texture];
            CHECK(t.type == TEX_CHECKER && (t.flags & TEX_SOLID));
            CHECK(near3(t.color0, 0.9, 0.1, 0.1, 1e-7) && near3(t.color1, 0.1, 0.1, 0.9, 1e-7));
            CHECK(t.m[0] == 2.0f && t.m[5] == 2.0f && t.m[10] == 2.0f && t.m[3] == 0.0f);
        }
    }
    /* objects */
    CHECK_EQ_INT(s.n_spheres, 2);
    CHECK_EQ_INT(s.n_planes, 1);
    CHECK_EQ_INT(s.n_triangles, 3);
    if (s.n_spheres == 2) {
        CHECK(near3(s.spheres[0].center, 1, 2, 3, 0) && s.spheres[0].radius == 0.5f);
        CHECK_EQ_INT(s.spheres[0].material, 1);
        CHECK(near3(s.spheres[1].center, 1, 0, 0, 1e-6) && fabs(s.spheres[1].radius - 2.0f) < 1e-6);
        CHECK_EQ_INT(s.spheres[1].material, 2);
    }
    if (s.n_planes == 1) {
        CHECK(near3(s.planes[0].normal, 0, 1, 0, 1e-7));
        CHECK_NEAR(s.planes[0].offset, -1.0, 1e-6);           /* 2y = -2 */
        CHECK_EQ_INT(s.planes[0].material, 1);
    }
    if (s.n_triangles == 3) {
        CHECK_EQ_INT(s.triangles[0].material, 4);
        CHECK(s.triangles[1].shading != NO_INDEX);            /* the OBJ's texture coordinates */
    }
    scene_free(&s);
}

static void test_orthographic(void)
{
    Scene s;
    Error err;
    Status st = load("ortho.txt", "OrthographicCamera { center 0 0 5 lookat 0 0 0 up 0 1 0 size 4 }\n"
                                   "Group { numObjects 1 Sphere { center 0 0 0 radius 1 } }\n", &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.camera.type, CAMERA_ORTHOGRAPHIC);
    CHECK(s.camera.ortho_height == 4.0f);
    CHECK(near3(s.camera.at, 0, 0, 4, 1e-6));
    /* no lights and no ambientLight: flat colours, as the course's parser draws it */
    CHECK(near3(s.ambient, 1, 1, 1, 0));
    CHECK(near3(s.bg_color, 0.5, 0.5, 0.5, 0));               /* the format's background */
    /* no materials at all: a white one is made for the sphere */
    CHECK_EQ_INT(s.n_materials, 1);
    scene_free(&s);
}

/* ---------------------------------------------------------------- transforms */

static Status load_objects(const char *objects, Scene *s, Error *err)
{
    char text[4096];
    snprintf(text, sizeof text, "%sMaterials { numMaterials 2 Material { } Material { diffuseColor 1 0 0 texture tex.png } }\n"
             "Lights { numLights 1 PointLight { position 0 9 0 color 1 1 1 } }\n%s", camera, objects);
    return load("objects.txt", text, s, err);
}

static void test_transforms(void)
{
    Scene s;
    Error err;
    /* the first transformation listed is the last applied: T(S(p)) */
    CHECK_EQ_INT(load_objects("Group { numObjects 1 Transform { Translate 1 2 3 Scale 2 2 2 "
                              "Sphere { center 1 0 0 radius 1 } } }", &s, &err), ST_OK);
    if (s.n_spheres == 1) {
        CHECK(near3(s.spheres[0].center, 3, 2, 3, 1e-6));
        CHECK_NEAR(s.spheres[0].radius, 2.0, 1e-6);
    }
    scene_free(&s);
    /* right-handed rotations: +x about +y by 90 degrees is -z; Rotate about z: +x to +y;
     * Matrix4f lists columns, Matrix rows (the same translation written both ways) */
    CHECK_EQ_INT(load_objects("Group { numObjects 4\n"
                              " Transform { YRotate 90 Triangle { vertex0 1 0 0 vertex1 0 1 0 vertex2 0 0 1 } }\n"
                              " Transform { Rotate { 0 0 2 90 } Triangle { vertex0 1 0 0 vertex1 0 1 0 vertex2 0 0 1 } }\n"
                              " Transform { Matrix4f { 1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1 } "
                              "Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 } }\n"
                              " Transform { Matrix { 1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1 } "
                              "Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 } }\n"
                              "}", &s, &err), ST_OK);
    if (s.n_triangles == 4) {
        CHECK(near3(s.triangles[0].p0, 0, 0, -1, 1e-6));
        CHECK(near3(s.triangles[0].p2, 1, 0, 0, 1e-6));
        CHECK(near3(s.triangles[1].p0, 0, 1, 0, 1e-6));
        CHECK(near3(s.triangles[1].p1, -1, 0, 0, 1e-6));
        CHECK(near3(s.triangles[2].p0, 5, 6, 7, 0));
        CHECK(near3(s.triangles[3].p1, 6, 6, 7, 0));
    }
    scene_free(&s);
    /* nested transforms compose; a plane moves and tilts with its transform; a mirror
     * keeps a triangle's outward side outward */
    CHECK_EQ_INT(load_objects("Group { numObjects 4\n"
                              " Transform { Translate 1 0 0 Transform { UniformScale 2 Sphere { center 1 0 0 radius 1 } } }\n"
                              " Transform { Translate 0 2 0 Plane { normal 0 1 0 offset -1 } }\n"
                              " Transform { Scale 1 2 1 Plane { normal 1 1 0 offset 0 } }\n"
                              " Transform { Scale -1 1 1 Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 } }\n"
                              "}", &s, &err), ST_OK);
    if (s.n_spheres == 1) {
        CHECK(near3(s.spheres[0].center, 3, 0, 0, 1e-6));
        CHECK_NEAR(s.spheres[0].radius, 2.0, 1e-6);
    }
    if (s.n_planes == 2) {
        CHECK(near3(s.planes[0].normal, 0, 1, 0, 1e-7));
        CHECK_NEAR(s.planes[0].offset, 1.0, 1e-6);
        CHECK(near3(s.planes[1].normal, 2 / sqrt(5.0), 1 / sqrt(5.0), 0, 1e-6));
        CHECK_NEAR(s.planes[1].offset, 0.0, 1e-6);
    }
    if (s.n_triangles == 1) {
        Triangle t = s.triangles[0];
        vec3 n = v3_cross(v3_sub(t.p1, t.p0), v3_sub(t.p2, t.p0));
        CHECK(n.z > 0.0f);
    }
    scene_free(&s);
    /* a sphere that a transform squashes, or a textured one it turns, becomes an exact
     * ellipsoid: the unit sphere under the transform times the sphere's own place */
    CHECK_EQ_INT(load_objects("Group { numObjects 2\n"
                              " Transform { Scale 1 0.5 1 Sphere { center 0 2 0 radius 3 } }\n"
                              " MaterialIndex 1 Transform { YRotate 45 Sphere { radius 1 } }\n"
                              "}", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_spheres, 2);
    CHECK_EQ_INT(s.n_sphere_xforms, 2);
    CHECK_EQ_INT(s.n_triangles, 0);
    if (s.n_spheres == 2 && s.n_sphere_xforms == 2) {
        CHECK(s.spheres[0].xform == 1u && s.spheres[1].xform == 2u);
        const float *m = s.sphere_xforms[0].to_world;
        static const float want[12] = { 3, 0, 0, 0, 0, 1.5f, 0, 1, 0, 0, 3, 0 };
        int same = 1;
        for (int i = 0; i < 12; i++) same &= fabsf(m[i] - want[i]) < 1e-6f;
        CHECK(same);
        CHECK_EQ_INT(s.spheres[1].material, 1);
    }
    scene_free(&s);
    /* a singular transform flattens its object */
    CHECK_EQ_INT(load_objects("Group { numObjects 1 Transform { Scale 0 1 1 Sphere { radius 1 } } }", &s, &err),
                 ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "singular");
    scene_free(&s);
}

/* Each sphere that a transform squashed became 9,024 triangles: 1,000 of them in a 65
 * KB file made 9 million triangles and took 4.6 GB, and past 116 of them the scene was
 * refused (CLPT_MAX_TESSELLATED_TRIANGLES). As ellipsoids they are a Sphere and a
 * SphereXform each, 128 bytes. */
static void test_squashed_spheres_memory(void)
{
    enum { N = 1000 };
    size_t cap = 200 + (size_t)N * 80, len = 0;
    char *objects = malloc(cap);
    if (!objects) abort();
    len += (size_t)snprintf(objects, cap, "Group { numObjects %d\n", N);
    for (int i = 0; i < N; i++)
        len += (size_t)snprintf(objects + len, cap - len, "Transform { Scale 1 0.5 1 Sphere { radius 1 } }\n");
    snprintf(objects + len, cap - len, "}\n");
    char *text = malloc(cap + 1024);
    if (!text) abort();
    snprintf(text, cap + 1024, "%sMaterials { numMaterials 1 Material { } }\n%s", camera, objects);
    Scene s;
    Error err;
    Status st = load("ellipsoids.txt", text, &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    size_t bytes = s.n_spheres * sizeof(Sphere) + s.n_sphere_xforms * sizeof(SphereXform) +
                   s.n_triangles * sizeof(Triangle) + s.n_shading * sizeof(TriShading);
    fprintf(stderr, "  %d squashed spheres: %zu bytes of primitives (%zu per sphere)\n", N, bytes, bytes / N);
    CHECK_EQ_INT(s.n_spheres, N);
    CHECK_EQ_INT(s.n_triangles, 0);
    CHECK(bytes <= (size_t)N * (sizeof(Sphere) + sizeof(SphereXform)));
    scene_free(&s);
    free(text);
    free(objects);
}

/* A RevSurface that a transform tilts still becomes a mesh (16 x 96 quads a segment,
 * 3,072 triangles for one cubic): those meshes hold at most
 * CLPT_MAX_TESSELLATED_TRIANGLES, so the 342nd such surface is an error naming it. */
static void test_revsurface_tessellation_limit(void)
{
    enum { N = 342 };
    const char *one = "Transform { ZRotate 90 RevSurface { profile BezierCurve { controls [ 1 0 0 ] [ 2 1 0 ] "
                      "[ 1 2 0 ] [ 1 3 0 ] } } }\n";
    size_t cap = 1024 + (size_t)N * (strlen(one) + 1), len = 0;
    char *text = malloc(cap);
    if (!text) abort();
    len += (size_t)snprintf(text, cap, "%sMaterials { numMaterials 1 Material { } }\nGroup { numObjects %d\n", camera,
                            N);
    for (int i = 0; i < N; i++) len += (size_t)snprintf(text + len, cap - len, "%s", one);
    snprintf(text + len, cap - len, "}\n");
    Scene s;
    Error err;
    CHECK_EQ_INT(load("tilted.txt", text, &s, &err), ST_INPUT);
    int line = 2;
    for (const char *q = camera; *q; q++) line += *q == '\n';
    char want[512];
    snprintf(want, sizeof want, "%s/tilted.txt:%d:24: its transform tilts this RevSurface's axis, which makes it a "
             "mesh of 3072 triangles, and the scene's meshes made from tilted surfaces would then hold more than "
             "1048576 (CLPT_MAX_TESSELLATED_TRIANGLES)", dir, line + N);
    CHECK_MSG(strcmp(err.msg, want) == 0, "%s", err.msg);
    CHECK(s.n_triangles <= CLPT_MAX_TESSELLATED_TRIANGLES);
    scene_free(&s);
    free(text);
}

/* MaterialIndex ignores the group hierarchy, as in the course's parser; objects before
 * any MaterialIndex get material 0. */
static void test_material_scoping(void)
{
    Scene s;
    Error err;
    CHECK_EQ_INT(load_objects("Group { numObjects 3\n"
                              " Sphere { radius 1 }\n"
                              " Group { numObjects 1 MaterialIndex 1 Sphere { radius 1 } }\n"
                              " Sphere { radius 2 }\n"
                              "}", &s, &err), ST_OK);
    if (s.n_spheres == 3) {
        CHECK_EQ_INT(s.spheres[0].material, 0);
        CHECK_EQ_INT(s.spheres[1].material, 1);
        CHECK_EQ_INT(s.spheres[2].material, 1);
    }
    CHECK(v3_is_zero(s.ambient));                              /* lights, no ambientLight */
    scene_free(&s);
}

static void test_crlf(void)
{
    size_t n = strlen(everything);
    char *crlf = malloc(2 * n + 1), *o = crlf;
    for (size_t i = 0; i < n; i++) {
        if (everything[i] == '\n') *o++ = '\r';
        *o++ = everything[i];
    }
    *o = '\0';
    Scene a, b;
    Error err;
    CHECK_EQ_INT(load("lf.txt", everything, &a, &err), ST_OK);
    CHECK_EQ_INT(load("crlf.txt", crlf, &b, &err), ST_OK);
    CHECK_EQ_INT(a.n_triangles, b.n_triangles);
    CHECK_EQ_INT(a.n_materials, b.n_materials);
    CHECK(a.n_spheres == b.n_spheres && memcmp(a.spheres, b.spheres, a.n_spheres * sizeof *a.spheres) == 0);
    /* an error's column is unchanged by the CR (load initialises the scene again) */
    scene_free(&a);
    CHECK_EQ_INT(load("bad.txt", "PerspectiveCamera {\r\n  centre 0 0 0\r\n}\r\n", &a, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "bad.txt:2:3: expected a PerspectiveCamera field");
    free(crlf);
    scene_free(&a);
    scene_free(&b);
}

/* Mesh and texture files: beside the scene, else from the current folder. */
static void test_paths(void)
{
    char sub[128], cwd[1024], text[1024];
    snprintf(sub, sizeof sub, "%s/scenes", dir);
    mkdir(sub, 0755);
    CHECK(getcwd(cwd, sizeof cwd) != NULL);
    snprintf(text, sizeof text, "%sGroup { numObjects 1 TriangleMesh { obj_file quad.obj } }\n", camera);
    write_file("scenes/beside.txt", text);
    write_file("scenes/quad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    char path[256];
    Scene s;
    Error err = {0};
    /* beside the scene: one triangle (DIR/scenes/quad.obj), not DIR/quad.obj's two */
    snprintf(path, sizeof path, "%s/scenes/beside.txt", dir);
    scene_init(&s);
    CHECK_EQ_INT(classic_load(path, &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 1);
    scene_free(&s);
    /* only in the current folder (a course's code folder) */
    char sub2[160];
    snprintf(sub2, sizeof sub2, "%s/scenes/elsewhere", dir);
    mkdir(sub2, 0755);
    write_file("scenes/elsewhere/x.txt", text);
    snprintf(path, sizeof path, "%s/scenes/elsewhere/x.txt", dir);
    CHECK(chdir(dir) == 0);
    scene_init(&s);
    CHECK_EQ_INT(classic_load(path, &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 2);                            /* DIR/quad.obj */
    scene_free(&s);
    CHECK(chdir(cwd) == 0);
    /* neither: an I/O error at the file name, naming both places */
    scene_init(&s);
    CHECK_EQ_INT(classic_load(path, &s, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "x.txt:2:46: cannot open 'quad.obj'");
    CHECK_STR_CONTAINS(err.msg, "elsewhere/quad.obj");
    scene_free(&s);
    error_clear(&err);
}

static void test_detect(void)
{
    CHECK(classic_detect("PerspectiveCamera {", 19));
    CHECK(classic_detect("\r\n  # a comment\n\tOrthographicCamera{", 36));
    const char *tops[] = { "Lights {", "Background {", "Materials {", "Group {" };
    for (int i = 0; i < 4; i++) CHECK(classic_detect(tops[i], strlen(tops[i])));
    CHECK(!classic_detect("camera { from 0 0 0 }", 21));
    CHECK(!classic_detect("PerspectiveCameraX {", 20));
    CHECK(!classic_detect("", 0));
    CHECK(!classic_detect("# only a comment", 16));
    /* auto detection loads either format */
    char path[256];
    Scene s;
    Error err = {0};
    write_file("ours.scene", "camera { from 0 0 5 }\nsphere { center 0 0 0 radius 1 material { type diffuse albedo 1 1 1 } }\n");
    snprintf(path, sizeof path, "%s/ours.scene", dir);
    scene_init(&s);
    CHECK_EQ_INT(scene_load_file(path, SCENE_FORMAT_AUTO, &s, NULL, &err), ST_OK);
    CHECK_EQ_INT(s.integrator, INTEGRATOR_PATH);
    CHECK_EQ_INT(s.n_spheres, 1);
    scene_free(&s);
    write_file("theirs.txt", "# a course scene\nPerspectiveCamera { center 0 0 5 direction 0 0 -1 up 0 1 0 angle 30 }\n"
                             "Group { numObjects 1 Sphere { center 0 0 0 radius 1 } }\n");
    snprintf(path, sizeof path, "%s/theirs.txt", dir);
    scene_init(&s);
    CHECK_EQ_INT(scene_load_file(path, SCENE_FORMAT_AUTO, &s, NULL, &err), ST_OK);
    CHECK_EQ_INT(s.integrator, INTEGRATOR_WHITTED);
    scene_free(&s);
    /* forcing the wrong format is an error of that format */
    scene_init(&s);
    CHECK_EQ_INT(scene_load_file(path, SCENE_FORMAT_CLPT, &s, NULL, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "theirs.txt:2:1: expected a statement");
    scene_free(&s);
    error_clear(&err);
}

/* Group and Transform are read recursively: 40,000 levels of either overflowed the
 * stack (a segmentation fault); past CLPT_MAX_NESTING levels they are an error, and up
 * to it they load. */
static void test_nesting_limit(void)
{
    static const char *const opens[] = { "Transform { Translate 0 0 0 ", "Group { numObjects 1 " };
    for (int g = 0; g < 2; g++) {
        size_t depths[2] = { CLPT_MAX_NESTING - 1, 40000 };   /* inside the top Group */
        for (int k = 0; k < 2; k++) {
            size_t n = depths[k], ol = strlen(opens[g]);
            size_t cap = strlen(camera) + 64 + n * (ol + 2);
            char *text = malloc(cap);
            if (!text) continue;
            size_t o = (size_t)snprintf(text, cap, "%sGroup { numObjects 1 ", camera);
            for (size_t i = 0; i < n; i++, o += ol) memcpy(text + o, opens[g], ol);
            o += (size_t)snprintf(text + o, cap - o, "Sphere { radius 1 }");
            for (size_t i = 0; i <= n; i++, o += 2) memcpy(text + o, " }", 2);
            Scene s;
            Error err = {0};
            scene_init(&s);
            Status st = classic_load_text("x.txt", text, o, &s, &err);
            if (k == 0) {
                CHECK_MSG(st == ST_OK, "%zu levels: %s", n + 1, err.msg);
                CHECK_EQ_INT(s.n_spheres + (s.n_triangles > 0), 1);
            } else {
                char want[160];
                snprintf(want, sizeof want, "x.txt:2:%zu: Group and Transform blocks nested more than %d deep",
                         21 + (size_t)(CLPT_MAX_NESTING - 1) * ol + 1, CLPT_MAX_NESTING);
                CHECK_EQ_INT(st, ST_INPUT);
                CHECK_MSG(strcmp(err.msg, want) == 0, "got %s, expected %s", err.msg, want);
            }
            scene_free(&s);
            error_clear(&err);
            free(text);
        }
    }
}

/* The matrices of the classic format are affine: a projective last row is refused. */
static void test_projective_matrix(void)
{
    Scene s;
    Error err = {0};
    CHECK_EQ_INT(load_objects("Group { numObjects 1 Transform { Matrix4f { 1 0 0 0.5  0 1 0 0  0 0 1 0  0 0 0 1 } "
                              "Sphere { radius 1 } } }", &s, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "objects.txt:4:45: the matrix's last row is 0.5 0 0 1; it must be 0 0 0 1 (an affine transform)");
    scene_free(&s);
    error_clear(&err);
}

/* ---------------------------------------------------------------- malformed files */

static void test_errors(void)
{
    static const struct { const char *text, *message; Status status; } cases[] = {
        { "Camera { }", "x.txt:1:1: expected a scene block (PerspectiveCamera, OrthographicCamera, Lights, "
                        "Background, Materials, Group), found 'Camera'", ST_INPUT },
        { "Group { numObjects 1 }", "x.txt:1:22: the Group at line 1 declares numObjects 1 but has 0", ST_INPUT },
        { "Group { numObjects 2\n Sphere { radius 1 }\n}",
          "x.txt:3:1: the Group at line 1 declares numObjects 2 but has 1", ST_INPUT },
        { "Group { numObjects 1\n Sphere { radius 1 }\n Sphere { radius 1 } }",
          "x.txt:3:2: expected '}' closing the Group (numObjects 1), found 'Sphere'", ST_INPUT },
        { "Materials { numMaterials 1 Material { } }\nGroup { numObjects 1 MaterialIndex 1 Sphere { radius 1 } }",
          "x.txt:2:36: expected a material index in 0..0, found '1'", ST_INPUT },
        { "Group { numObjects 1 MaterialIndex 0 Sphere { radius 1 } }",
          "x.txt:1:36: expected a material index, but no materials are defined before it, found '0'", ST_INPUT },
        { "Lights { numLights 2 PointLight { position 0 0 0 color 1 1 1 } }",
          "x.txt:1:64: the Lights block at line 1 declares numLights 2 but has 1", ST_INPUT },
        { "Lights { numLights 1 AreaLight { } }",
          "x.txt:1:22: expected a light (DirectionalLight, PointLight, SpotLight), found 'AreaLight'", ST_INPUT },
        { "Materials { numMaterials 1 Noise { } }",
          "x.txt:1:28: expected a material (PhongMaterial, Material, Checkerboard), found 'Noise'", ST_INPUT },
        { "Group { numObjects 1 Sphere { center 0 0 0 } }", "x.txt:1:22: the Sphere block needs 'radius'", ST_INPUT },
        { "Group { numObjects 1 Sphere { centre 0 0 0 } }",
          "x.txt:1:31: expected a Sphere field (center, radius) or '}', found 'centre'", ST_INPUT },
        { "Group { numObjects 1 Sphere { radius 1 radius 2 } }",
          "x.txt:1:40: 'radius' repeated in the Sphere block (first given at 1:31)", ST_INPUT },
        { "Group { numObjects 1 Sphere { radius abc } }",
          "x.txt:1:38: expected a number > 0 for 'radius', found 'abc'", ST_INPUT },
        { "Group { numObjects 1 Sphere { radius -1 } }",
          "x.txt:1:38: expected a number > 0 for 'radius', found '-1'", ST_INPUT },
        { "Materials { numMaterials 1 Material { diffuseColor 1 -1 0 } }",
          "x.txt:1:54: expected 3 numbers >= 0 (a colour) for 'diffuseColor', found '-1'", ST_INPUT },
        { "Materials { numMaterials 1 Material { shininess 2 exponent 3 } }",
          "x.txt:1:51: a Material block takes 'shininess' or 'exponent', not both", ST_INPUT },
        { "Lights { numLights 1 PointLight { position 0 0 0 color 1 1 1 attenuation 0 0 0 } }",
          "x.txt:1:62: 'attenuation' is constant linear quadratic, not all 0", ST_INPUT },
        { "Lights { numLights 1 PointLight { position 0 0 0 color 1 1 1 falloff 1 attenuation 1 0 0 } }",
          "x.txt:1:72: a PointLight block takes 'falloff' or 'attenuation', not both", ST_INPUT },
        { "Group { numObjects 1 Sphere { radius 1 }", "x.txt:1:41: expected '}' to close the Group block opened at line 1, found end of file", ST_INPUT },
        { "Group { numObjects 1 Sphere { radius 1 ", "x.txt:1:40: expected '}' to close the Sphere block opened "
                                                    "at line 1, found end of file", ST_INPUT },
        { "Group { numObjects 1 Transform { Translate 1 0 0 } }",
          "x.txt:1:50: expected a transformation (Translate, Scale, UniformScale, XRotate, YRotate, ZRotate, "
          "Rotate, Matrix4f, Matrix) or the object it applies to, found '}'", ST_INPUT },
        { "Group { numObjects 1 Transform { Rotate 0 1 0 90 Sphere { radius 1 } } }",
          "x.txt:1:41: expected '{' before Rotate's axis and degrees, found '0'", ST_INPUT },
        { "Group { numObjects 1 Transform { Matrix4f { 1 0 0 } Sphere { radius 1 } } }",
          "x.txt:1:51: expected 16 numbers for the matrix, found '}'", ST_INPUT },
        { "Group { numObjects 1 Transform { Translate 1 0 0 Cube { } } }",
          "x.txt:1:50: expected an object (Group, Sphere, Plane, Triangle, TriangleMesh, Transform, RevSurface, "
          "BezierCurve, BsplineCurve) or MaterialIndex, found 'Cube'", ST_INPUT },
        { "Group { numObjects 1 Sphere { radius 1 } }", "x.txt:1:43: the scene has no camera", ST_INPUT },
        { "PerspectiveCamera { center 0 0 0 direction 0 1 0 up 0 2 0 angle 30 }",
          "x.txt:1:50: 'up' is parallel to the view direction", ST_INPUT },
        { "PerspectiveCamera { center 0 0 0 direction 0 0 -1 up 0 1 0 angle 180 }",
          "x.txt:1:60: 'angle' is the field of view in degrees, in (0, 180); found 180", ST_INPUT },
        { "PerspectiveCamera { center 0 0 0 direction 0 0 -1 up 0 1 0 size 3 }",
          "x.txt:1:60: 'size' belongs to the OrthographicCamera; a PerspectiveCamera has 'angle'", ST_INPUT },
        { "PerspectiveCamera { center 0 0 0 direction 0 0 0 up 0 1 0 angle 30 }",
          "x.txt:1:44: expected a non-zero vector (3 numbers) for 'direction', found 0 0 0", ST_INPUT },
        { "OrthographicCamera { center 0 0 0 up 0 1 0 size 3 }",
          "x.txt:1:1: the OrthographicCamera block needs 'direction' (or 'lookat')", ST_INPUT },
        { "PerspectiveCamera { center 0 0 0 direction 0 0 -1 up 0 1 0 angle 30 width 0 }",
          "x.txt:1:75: expected a whole number in 1..16384 for 'width', found '0'", ST_INPUT },
        { "Background { color 0 0 0 }\nBackground { color 0 0 0 }", "x.txt:2:1: a second Background block", ST_INPUT },
        { "Group { numObjects 1 TriangleMesh { obj_file nowhere.obj } }",
          "x.txt:1:46: cannot open 'nowhere.obj'", ST_IO },
        { "Materials { numMaterials 1 Material { texture nowhere.png } }",
          "x.txt:1:47: cannot open 'nowhere.png'", ST_IO },
        { "Materials { numMaterials 1 Material { texture quad.obj } }",
          "x.txt:1:47: '", ST_INPUT },
        { "Group { numObjects 1 TriangleMesh { obj_file broken.obj } }",
          "broken.obj:2:1: expected", ST_INPUT },
    };
    write_file("broken.obj", "v 0 0 0\nbogus 1 2 3\n");
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        Scene s;
        Error err;
        Status st = load("x.txt", cases[i].text, &s, &err);
        CHECK_MSG(st == cases[i].status, "case %zu: status %d, expected %d (%s)", i, st, cases[i].status, err.msg);
        const char *at = strstr(err.msg, cases[i].message);
        CHECK_MSG(at != NULL, "case %zu:\n    got:      %s\n    expected: ...%s", i, err.msg, cases[i].message);
        error_clear(&err);
        scene_free(&s);
    }
    /* an error inside a mesh names the scene line that read it */
    Scene s;
    Error err;
    load("x.txt", cases[sizeof cases / sizeof cases[0] - 1].text, &s, &err);
    CHECK_STR_CONTAINS(err.msg, "(in the TriangleMesh of ");
    CHECK_STR_CONTAINS(err.msg, "x.txt:1:22)");
    scene_free(&s);
}

/* ---------------------------------------------------------------- our format */

static void test_scene_format_additions(void)
{
    char path[256];
    write_file("ours2.scene",
               "texture grid { type image file tex.png wrap clamp encoding linear scale 4 }\n"
               "texture board { type checker color0 1 1 1 color1 0 0 0 space solid scale 2 }\n"
               "material shiny { type phong albedo 0.5 0.5 0.5 specular 0.4 0.4 0.4 shininess 60\n"
               "                 reflective 0.1 0.1 0.1 transparent 0.2 0.2 0.2 ior 1.3 texture grid }\n"
               "material floor { type diffuse albedo 1 1 1 texture board }\n"
               "light { type point position 0 4 0 intensity 10 10 10 }\n"
               "light { type spot position 0 4 0 direction 0 -1 0 intensity 5 5 5 angle 40 inner 20 attenuation 1 0 0 }\n"
               "light { type directional direction 1 -1 0 intensity 2 2 2 }\n"
               "background { color 0 0 0 ambient 0.1 0.1 0.1 }\n"
               "sphere { center 0 0 0 radius 1 material shiny }\n");
    snprintf(path, sizeof path, "%s/ours2.scene", dir);
    Scene s;
    Error err = {0};
    scene_init(&s);
    Status st = scene_load(path, &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_textures, 2);
    CHECK_EQ_INT(s.n_delta_lights, 3);
    if (st == ST_OK && s.n_textures == 2 && s.n_delta_lights == 3) {
        Texture g = s.textures[0], b = s.textures[1];
        CHECK(g.type == TEX_IMAGE && g.flags == TEX_CLAMP && g.m[0] == 4.0f && g.m[5] == 4.0f);
        CHECK(b.type == TEX_CHECKER && b.flags == TEX_SOLID && b.m[10] == 2.0f);
        Material m = s.materials[scene_find_material(&s, "shiny")];
        CHECK(m.type == MAT_PHONG && m.shininess == 60.0f && m.ior == 1.3f && m.texture == 0);
        CHECK(near3(m.transparent, 0.2, 0.2, 0.2, 1e-7) && near3(m.reflective, 0.1, 0.1, 0.1, 1e-7));
        CHECK_EQ_INT(s.materials[scene_find_material(&s, "floor")].texture, 1);
        const Light *l = s.delta_lights;
        CHECK(l[0].type == LIGHT_POINT && l[0].atten2 == 1.0f && l[0].atten0 == 0.0f);  /* inverse square */
        CHECK(near3(l[0].intensity, 10, 10, 10, 0));
        CHECK(l[1].type == LIGHT_SPOT && l[1].atten0 == 1.0f && l[1].atten2 == 0.0f);
        CHECK_NEAR(l[1].cos_outer, cos(40 * M_PI / 180), 1e-6);
        CHECK(l[2].type == LIGHT_DIRECTIONAL && near3(l[2].direction, M_SQRT1_2, -M_SQRT1_2, 0, 1e-6));
        CHECK(near3(s.ambient, 0.1, 0.1, 0.1, 1e-7));
        /* the light list: no area lights, then the three delta lights */
        CHECK_EQ_INT(scene_prepare_lights(&s, &err), ST_OK);
        CHECK_EQ_INT(s.n_lights, 3);
        CHECK(s.n_lights == 3 && s.lights[2].cdf == 1.0f && s.lights[0].pick_pdf > 0.0f);
    }
    scene_free(&s);
    static const struct { const char *text, *message; } bad[] = {
        { "material m { type diffuse albedo 1 1 1 texture nope }", "1:48: texture 'nope' is not defined" },
        { "light { type area intensity 1 1 1 }", "1:14: expected a light type (point, spot, directional), found 'area'" },
        { "light { type directional position 0 0 0 intensity 1 1 1 }", "1:26: a directional light has no 'position'" },
        { "light { type point }", "1:1: the light block needs 'intensity'" },
        { "texture t { type image }", "1:1: an image texture needs 'file'" },
        { "texture t { type checker file x.png }", "1:26: an checker texture has no 'file'" },
        { "texture t { type checker space world }", "1:32: expected uv or solid, found 'world'" },
        { "texture t { type noise }", "1:18: expected a texture type (image, checker), found 'noise'" },
        { "material m { type phong albedo 1 1 1 fuzz 0.1 }", "1:38: expected a phong material key (type, albedo, ior" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        write_file("bad.scene", bad[i].text);
        snprintf(path, sizeof path, "%s/bad.scene", dir);
        scene_init(&s);
        CHECK_EQ_INT(scene_load(path, &s, &err), ST_INPUT);
        CHECK_MSG(strstr(err.msg, bad[i].message) != NULL, "case %zu:\n    got:      %s\n    expected: ...%s", i,
                  err.msg, bad[i].message);
        scene_free(&s);
    }
    error_clear(&err);
}

/* The shipped classic scenes and their counterparts load, in the format they claim. */
static void test_shipped_scenes(void)
{
    static const char *const names[] = { "spheres", "glass", "mesh", "textured", "ortho" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        for (int ours = 0; ours < 2; ours++) {
            char path[128];
            snprintf(path, sizeof path, "scenes/classic/%s.%s", names[i], ours ? "scene" : "txt");
            Scene s;
            Error err = {0};
            scene_init(&s);
            Status st = scene_load_file(path, SCENE_FORMAT_AUTO, &s, NULL, &err);
            CHECK_MSG(st == ST_OK, "%s: %s", path, err.msg);
            CHECK_EQ_INT(s.integrator, ours ? INTEGRATOR_PATH : INTEGRATOR_WHITTED);
            CHECK(s.n_delta_lights >= 2);
            CHECK(s.n_spheres + s.n_triangles > 0);
            error_clear(&err);
            scene_free(&s);
        }
}

/* ---------------------------------------------------------------- the command line */

static void test_cli(void)
{
    char scene[256], out[256], bmp[256];
    snprintf(scene, sizeof scene, "%s/cli.txt", dir);
    snprintf(out, sizeof out, "%s/cli.png", dir);
    snprintf(bmp, sizeof bmp, "%s/cli.bmp", dir);
    write_file("cli.txt", "PerspectiveCamera { center 0 0 5 direction 0 0 -1 up 0 1 0 angle 30 width 24 height 16 }\n"
                          "Lights { numLights 1 PointLight { position 2 2 5 color 1 1 1 } }\n"
                          "Group { numObjects 1 Sphere { center 0 0 0 radius 1 } }\n");
    CliResult *r = malloc(sizeof *r);
    const char *bad[][8] = {
        { scene, "--integrator", "photon", NULL },
        { scene, "--format", "mitsuba", NULL },
        { scene, "--aov", "normal,motion", NULL },
        { scene, "--gamma", "2.2", NULL },
        { scene, "--adaptive", "0", NULL },
        { scene, "--adaptive", "0.1", "--integrator", "path", NULL },
        { scene, "--depth-range", "5,5", NULL },    /* 5,1 inverts the ramp (accepted) */
    };
    const char *expect[] = { "--integrator expects 'path' or 'whitted'", "--format expects", "--aov expects",
                             "--gamma expects", "--adaptive expects a threshold", "--adaptive needs the whitted",
                             "--depth-range expects NEAR,FAR" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        cli_run(bad[i], r);
        CHECK_EQ_INT(r->status, 2);
        CHECK_STR_CONTAINS(r->err, expect[i]);
    }
    /* the wrong format forced: an input error */
    const char *forced[] = { scene, "--format", "clpt", "-o", out, "-q", NULL };
    cli_run(forced, r);
    CHECK_EQ_INT(r->status, 3);
    /* a BMP with every auxiliary image, detected format, adaptive pass */
    const char *ok[] = { scene, "-o", bmp, "--aov", "normal,depth,albedo", "--adaptive", "0.05", "--device", "scalar",
                         "--format", "classic", "--depth-range", "18,8", NULL };
    cli_run(ok, r);
    CHECK_MSG(r->status == 0, "%s", r->err);
    CHECK_STR_CONTAINS(r->err, "adaptive pass:");
    const char *aovs[] = { "cli-normal.bmp", "cli-depth.bmp", "cli-albedo.bmp", "cli.bmp" };
    for (int i = 0; i < 4; i++) {
        char p[300];
        snprintf(p, sizeof p, "%s/%s", dir, aovs[i]);
        struct stat sb;
        CHECK_MSG(stat(p, &sb) == 0 && sb.st_size == 54 + 24 * 3 * 16, "%s", p);
        unlink(p);
    }
    free(r);
}

static Triangle tri(vec3 a, vec3 b, vec3 c)
{
    Triangle t;
    memset(&t, 0, sizeof t);
    t.p0 = a;
    t.p1 = b;
    t.p2 = c;
    t.shading = NO_INDEX;
    t.light = NO_INDEX;
    return t;
}

/* Smooth mesh normals weigh every face the same (Fall 2019's Mesh.cpp sums unit face
 * normals): a big face (+z, area 8) and a small one (+x, area 0.5) sharing the vertex
 * at the origin give it (1, 0, 1) / sqrt 2, where area weights would give (0.06, 0, 1).
 * Faces whose normals cancel at a corner stay flat; triangles before `first` are left
 * alone; a face that meets the others at the origin through a vertex of its own (a
 * vertex index not shared) keeps its own normal there, as the course's loader does. */
static void test_smooth_normals(void)
{
    Scene s;
    scene_init(&s);
    Error err = {0};
    vec3 o = v3s(0.0f);
    scene_add_triangle(&s, tri(v3(9, 9, 9), v3(10, 9, 9), v3(9, 10, 9)), &err);    /* before first */
    scene_add_triangle(&s, tri(o, v3(4, 0, 0), v3(0, 4, 0)), &err);
    scene_add_triangle(&s, tri(o, v3(0, 0, 1), v3(0, -1, 0)), &err);
    scene_add_triangle(&s, tri(v3(5, 0, 0), v3(6, 0, 0), v3(5, 1, 0)), &err);      /* a face and its */
    scene_add_triangle(&s, tri(v3(5, 0, 0), v3(5, 1, 0), v3(6, 0, 0)), &err);      /* back: cancel */
    scene_add_triangle(&s, tri(o, v3(0, -1, 0), v3(-1, 0, 0)), &err);               /* unshared */
    const uint keys[15] = { 0, 1, 2, 0, 3, 4, 5, 6, 7, 5, 7, 6, 8, 9, 10 };
    CHECK(mesh_smooth_normals(&s, 1, keys, 11, &err) == ST_OK);
    if (s.triangles[5].shading != NO_INDEX) {
        const TriShading *c = &s.shading[s.triangles[5].shading];
        CHECK(near3(c->n0, 0, 0, -1, 0) && near3(c->n1, 0, 0, -1, 0) && near3(c->n2, 0, 0, -1, 0));
    }
    CHECK(s.triangles[0].shading == NO_INDEX);
    CHECK(s.triangles[3].shading == NO_INDEX && s.triangles[4].shading == NO_INDEX);
    CHECK(s.triangles[1].shading != NO_INDEX && s.triangles[2].shading != NO_INDEX);
    if (s.triangles[1].shading != NO_INDEX && s.triangles[2].shading != NO_INDEX) {
        const TriShading *a = &s.shading[s.triangles[1].shading], *b = &s.shading[s.triangles[2].shading];
        double h = sqrt(0.5);
        CHECK(a->flags == TRI_HAS_NORMALS);
        CHECK(near3(a->n0, h, 0, h, 1e-6) && near3(b->n0, h, 0, h, 1e-6));
        CHECK(near3(a->n1, 0, 0, 1, 0) && near3(a->n2, 0, 0, 1, 0));
        CHECK(near3(b->n1, 1, 0, 0, 0) && near3(b->n2, 1, 0, 0, 0));
    }
    scene_free(&s);
}

/* An OBJ cube (unit, no vn) written with 8 shared vertices, or with 24, four per face.
 * Each face is two triangles. */
static void write_cube(const char *name, int shared)
{
    static const int quads[6][4] = { { 0, 1, 3, 2 }, { 4, 6, 7, 5 }, { 0, 4, 5, 1 },
                                     { 2, 3, 7, 6 }, { 0, 2, 6, 4 }, { 1, 5, 7, 3 } };
    char text[2048];
    size_t n = 0;
    for (int f = 0; f < (shared ? 1 : 6); f++)
        for (int c = 0; c < 8; c++) {
            int k = shared ? c : quads[f][c % 4];
            if (!shared && c >= 4) break;
            n += (size_t)snprintf(text + n, sizeof text - n, "v %d %d %d\n", k >> 2 & 1, k >> 1 & 1, k & 1);
        }
    for (int f = 0; f < 6; f++) {
        int v[4];
        for (int j = 0; j < 4; j++) v[j] = 1 + (shared ? quads[f][j] : 4 * f + j);
        n += (size_t)snprintf(text + n, sizeof text - n, "f %d %d %d\nf %d %d %d\n", v[0], v[1], v[2], v[0], v[2],
                              v[3]);
    }
    write_file(name, text);
}

/* MIT 6.837 Fall 2019 smooths a mesh over shared vertex *indices*: a cube whose faces
 * share no vertex renders faceted (every corner normal its face's), one of 8 shared
 * vertices smooth (every corner normal leans toward the three faces meeting there,
 * each triangle counted once, as the course sums them), and the faceted one under a
 * mirroring transform too (an instance, carried to the world as the kd-tree takes
 * it). Tsinghua's dialect (a sized camera) stays flat. */
static void test_mesh_normals_by_index(void)
{
    write_cube("cube24.obj", 0);
    write_cube("cube8.obj", 1);
    const char *files[3] = { "cube24.obj", "cube8.obj", "cube24.obj" };
    const char *xf[3] = { "", "", "Scale 1 1 -1 " };
    for (int i = 0; i < 3; i++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "%sMaterials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n"
                 "Group { numObjects 1 MaterialIndex 0 Transform { %sTriangleMesh { obj_file %s } } }\n", camera,
                 xf[i], files[i]);
        Scene s;
        Error err;
        Status st = load("cube.txt", text, &s, &err);
        /* the mirrored cube is an instance: its copy in the world (what the kd-tree
         * renders) is checked */
        if (!st) st = scene_flatten_instances(&s, &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        CHECK_EQ_INT(s.n_triangles, 12);
        int faceted = 0, diagonal = 0;
        for (size_t t = 0; !st && t < s.n_triangles; t++) {
            const Triangle *tr = &s.triangles[t];
            if (tr->shading == NO_INDEX) continue;
            vec3 e1 = v3_sub(tr->p1, tr->p0), e2 = v3_sub(tr->p2, tr->p0);
            vec3 ng = v3_norm(v3_cross(e1, e2));
            const TriShading *sh = &s.shading[tr->shading];
            vec3 n[3] = { sh->n0, sh->n1, sh->n2 };
            for (int j = 0; j < 3; j++) {
                faceted += v3_dot(n[j], ng) > 0.999999f;
                diagonal += fabsf(n[j].x) > 0.3f && fabsf(n[j].y) > 0.3f && fabsf(n[j].z) > 0.3f &&
                            v3_dot(n[j], ng) > 0.3f;
            }
        }
        fprintf(stderr, "  %s%s: %d of 36 corner normals are their face's, %d lean to three faces\n", files[i],
                i == 2 ? " mirrored" : "", faceted, diagonal);
        CHECK_EQ_INT(faceted, i == 1 ? 0 : 36);
        CHECK_EQ_INT(diagonal, i == 1 ? 36 : 0);
        scene_free(&s);
    }
}

/* ---------------------------------------------------------------- instances and ellipsoids */

/* The scene's linear image on the scalar device (NULL, the error reported, on failure). */
static float *render_rgb(Scene *s)
{
    float *rgb = malloc((size_t)s->image.width * s->image.height * 3 * sizeof *rgb);
    Error err = {0};
    Status st = rgb ? render_util_rgb_mis(s, RENDER_UTIL_SCENE_MIS, "scalar", rgb, &err) : ST_INTERNAL;
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st) {
        free(rgb);
        return NULL;
    }
    return rgb;
}

/* The mean absolute difference of two images of n pixels, and how many pixels differ
 * by more than `far` in some channel. */
static double mean_abs_diff(const float *a, const float *b, size_t n, double far, size_t *n_far)
{
    double sum = 0.0;
    *n_far = 0;
    for (size_t i = 0; i < n; i++) {
        double worst = 0.0;
        for (int c = 0; c < 3; c++) {
            double d = fabs((double)a[3 * i + c] - b[3 * i + c]);
            sum += d;
            if (d > worst) worst = d;
        }
        *n_far += worst > far;
    }
    return sum / (3.0 * (double)n);
}

static const char *lit_header =
    "PerspectiveCamera { center 0.5 1.5 7 lookat 0 0 0 up 0 1 0 angle 40 width 96 height 72 }\n"
    "Lights { numLights 2 PointLight { position -3 5 4 color 0.9 0.85 0.8 } "
    "DirectionalLight { direction 1 -1.5 -0.5 color 0.3 0.3 0.3 } }\n"
    "Background { color 0.2 0.25 0.3 ambientLight 0.1 0.1 0.1 }\n"
    "Materials { numMaterials 3 Material { diffuseColor 0.55 0.55 0.55 } "
    "PhongMaterial { diffuseColor 0.2 0.7 0.3 specularColor 0.5 0.5 0.5 shininess 60 } "
    "PhongMaterial { diffuseColor 0.8 0.3 0.2 texture tex.png } }\n";

/* The same OBJ under three transforms (one a mirror) is one object placed three times;
 * under another material it is a second object; outside any Transform it is read into
 * the world as before, and so are all meshes of a file that places none twice. Each image equals the one of the meshes carried to the world
 * vertex by vertex (scene_flatten_instances, what the kd-tree renders, as the reader did
 * before) within float rounding. */
static void test_mesh_instances(void)
{
    write_cube("cube24.obj", 0);
    char text[4096];
    snprintf(text, sizeof text,
             "%sGroup { numObjects 6 MaterialIndex 0 Plane { normal 0 1 0 offset -1 }\n"
             " MaterialIndex 1\n"
             " Transform { Translate -2 -1 0 YRotate 30 TriangleMesh { obj_file cube24.obj } }\n"
             " Transform { Translate 0 -1 -1 Scale 1.3 0.7 0.9 TriangleMesh { obj_file cube24.obj } }\n"
             " Transform { Translate 1.5 -1 0.5 Rotate { 1 0 1 40 } Scale -1 1 0.8 "
             "TriangleMesh { obj_file cube24.obj } }\n"
             " MaterialIndex 2 Transform { Translate -0.5 0.2 1 UniformScale 0.6 "
             "TriangleMesh { obj_file cube24.obj } }\n"
             " TriangleMesh { obj_file cube24.obj }\n"
             "}\n", lit_header);
    Scene s, flat;
    Error err;
    Status st = load("instances.txt", text, &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_objects, 2);
    CHECK_EQ_INT(s.n_instances, 4);
    CHECK_EQ_INT(s.n_triangles, 3 * 12);        /* two objects and the world's copy */
    if (s.n_instances == 4) {
        CHECK_EQ_INT(s.instance_objects[0], 0);
        CHECK_EQ_INT(s.instance_objects[2], 0);
        CHECK_EQ_INT(s.instance_objects[3], 1);
    }
    Status fst = load("instances.txt", text, &flat, &err);
    if (!fst) fst = scene_flatten_instances(&flat, &err);
    CHECK_MSG(fst == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(flat.n_triangles, 5 * 12);
    float *a = st ? NULL : render_rgb(&s), *b = fst ? NULL : render_rgb(&flat);
    if (a && b) {
        size_t n = (size_t)s.image.width * s.image.height, n_far;
        double mad = mean_abs_diff(a, b, n, 0.05, &n_far);
        fprintf(stderr, "  instanced vs copied meshes: mean abs difference %.2e, %zu of %zu pixels off by > 0.05\n",
                mad, n_far, n);
        CHECK(mad < 1e-4);
        CHECK(n_far <= 2);
    }
    free(a);
    free(b);
    scene_free(&s);
    scene_free(&flat);

    /* a mesh placed once is carried into the world, as before: no object is left */
    snprintf(text, sizeof text, "%sGroup { numObjects 2 MaterialIndex 1\n"
             " Transform { Translate 5 0 0 TriangleMesh { obj_file cube24.obj } }\n"
             " MaterialIndex 2 Transform { Translate -5 0 0 TriangleMesh { obj_file cube24.obj } } }\n", lit_header);
    st = load("once.txt", text, &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_objects, 0);
    CHECK_EQ_INT(s.n_instances, 0);
    CHECK_EQ_INT(s.n_triangles, 24);
    int moved = 1;
    for (size_t i = 0; i < s.n_triangles; i++)
        moved &= fabsf(s.triangles[i].p0.x) >= 4.0f && fabsf(s.triangles[i].p0.x) <= 6.0f;   /* a unit cube */
    CHECK(moved);
    scene_free(&s);

    /* the shipped example: one cube placed eight times, four ellipsoids */
    scene_init(&s);
    error_clear(&err);
    st = scene_load_file("scenes/classic/instances.txt", SCENE_FORMAT_AUTO, &s, NULL, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_objects, 1);
    CHECK_EQ_INT(s.n_instances, 8);
    CHECK_EQ_INT(s.n_triangles, 12);
    CHECK_EQ_INT(s.n_sphere_xforms, 4);
    scene_free(&s);

    /* --stats: one mesh stored, three placed */
    char scene[256], out[256];
    snprintf(scene, sizeof scene, "%s/three.txt", dir);
    snprintf(out, sizeof out, "%s/three.pfm", dir);
    snprintf(text, sizeof text,
             "%sGroup { numObjects 3 MaterialIndex 1\n"
             " Transform { Translate -2 0 0 TriangleMesh { obj_file cube24.obj } }\n"
             " Transform { YRotate 45 TriangleMesh { obj_file cube24.obj } }\n"
             " Transform { Translate 2 0 0 Scale 1 2 1 TriangleMesh { obj_file cube24.obj } }\n"
             "}\n", lit_header);
    write_file("three.txt", text);
    CliResult *r = malloc(sizeof *r);
    if (!r) abort();
    const char *args[] = { scene, "--stats", "--width", "16", "--height", "12", "--device", "scalar", "-o", out,
                           NULL };
    cli_run(args, r);
    CHECK_EQ_INT(r->status, 0);
    CHECK_STR_CONTAINS(r->out, "instances: 3 of 1 objects; triangles: 12 unique (12 in objects), 36 instanced");
    free(r);
}

/* The old tessellation of a classic sphere (48 bands x 96 segments, the sphere's
 * normals and (u, v) at its corners) as an OBJ of the unit sphere. */
static void write_tessellated_sphere(const char *name)
{
    enum { NB = 48, NS = 96 };
    size_t cap = 1u << 20, n = 0;
    char *text = malloc(cap);
    if (!text) abort();
    for (int bi = 0; bi <= NB; bi++)
        for (int sj = 0; sj <= NS; sj++) {
            double theta = M_PI * bi / NB, phi = 2.0 * M_PI * sj / NS;
            double x = -sin(theta) * sin(phi), y = cos(theta), z = -sin(theta) * cos(phi);
            n += (size_t)snprintf(text + n, cap - n, "v %.9g %.9g %.9g\nvn %.9g %.9g %.9g\nvt %.9g %.9g\n", x, y,
                                  z, x, y, z, (double)sj / NS, 1.0 - (double)bi / NB);
        }
    for (int i = 0; i < NB; i++)
        for (int j = 0; j < NS; j++) {
            int k[4] = { 1 + i * (NS + 1) + j, 1 + i * (NS + 1) + j + 1, 1 + (i + 1) * (NS + 1) + j + 1,
                         1 + (i + 1) * (NS + 1) + j };
            if (i < NB - 1)
                n += (size_t)snprintf(text + n, cap - n, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", k[0], k[0], k[0], k[3],
                                      k[3], k[3], k[2], k[2], k[2]);
            if (i > 0)
                n += (size_t)snprintf(text + n, cap - n, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", k[0], k[0], k[0], k[2],
                                      k[2], k[2], k[1], k[1], k[1]);
        }
    write_file(name, text);
    free(text);
}

/* A squashed, turned sphere (plain and textured) renders as the old 9,024-triangle
 * mesh did, within that mesh's error (its facets stray up to 1 - cos(pi / 96) = 5.4e-4
 * of the radius inside the sphere, and its normals are interpolated); its silhouette
 * is exact: with flat colours and an orthographic camera, each pixel is the object's
 * exactly when the ray through the pixel's centre meets the analytic ellipsoid. The
 * kd-tree draws it the same. */
static void test_squashed_sphere_image(void)
{
    write_tessellated_sphere("sphere48.obj");
    const char *xf = "Translate 0 0.2 0 ZRotate 30 Scale 1.6 0.7 1";
    char text[4096];
    Scene exact, mesh, kd;
    Error err;
    for (int shape = 0; shape < 2; shape++) {
        snprintf(text, sizeof text,
                 "%sGroup { numObjects 3 MaterialIndex 0 Plane { normal 0 1 0 offset -1 }\n"
                 " MaterialIndex 1 Transform { Translate -1.2 0 0 %s %s }\n"
                 " MaterialIndex 2 Transform { Translate 1.6 0 0 YRotate 60 %s %s }\n}\n", lit_header, xf,
                 shape ? "TriangleMesh { obj_file sphere48.obj }" : "Sphere { radius 1 }", xf,
                 shape ? "TriangleMesh { obj_file sphere48.obj }" : "Sphere { radius 1 }");
        Status st = load("squashed.txt", text, shape ? &mesh : &exact, &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        if (st) return;
    }
    CHECK_EQ_INT(exact.n_sphere_xforms, 2);
    CHECK_EQ_INT(exact.n_triangles, 0);
    load("squashed.txt", text, &kd, &err);
    snprintf(text, sizeof text,
             "%sGroup { numObjects 3 MaterialIndex 0 Plane { normal 0 1 0 offset -1 }\n"
             " MaterialIndex 1 Transform { Translate -1.2 0 0 %s Sphere { radius 1 } }\n"
             " MaterialIndex 2 Transform { Translate 1.6 0 0 YRotate 60 %s Sphere { radius 1 } }\n}\n", lit_header,
             xf, xf);
    scene_free(&kd);
    Status kst = load("squashed.txt", text, &kd, &err);
    kd.accel = ACCEL_KDTREE;
    float *a = render_rgb(&exact), *b = render_rgb(&mesh), *k = kst ? NULL : render_rgb(&kd);
    size_t n = (size_t)exact.image.width * exact.image.height, n_far = 0, kd_far = 0;
    if (a && b) {
        double mad = mean_abs_diff(a, b, n, 0.1, &n_far);
        fprintf(stderr, "  ellipsoids vs the old 9,024-triangle meshes: mean abs difference %.2e, %zu of %zu "
                "pixels off by > 0.1\n", mad, n_far, n);
        CHECK(mad < 2e-3);
        CHECK(n_far <= n / 200);
    }
    if (a && k) {
        double mad = mean_abs_diff(a, k, n, 0.0, &kd_far);
        fprintf(stderr, "  kd-tree vs BVH: mean abs difference %.2e, %zu pixels differ\n", mad, kd_far);
        CHECK(kd_far == 0);
    }
    free(a);
    free(b);
    free(k);
    scene_free(&exact);
    scene_free(&mesh);
    scene_free(&kd);

    /* the silhouette: flat colours (no lights), a black background, the view down -z */
    enum { W = 120, H = 80 };
    for (int shape = 0; shape < 2; shape++) {
        snprintf(text, sizeof text,
                 "OrthographicCamera { center 0 0 5 direction 0 0 -1 up 0 1 0 size 4 width %d height %d }\n"
                 "Background { color 0 0 0 }\n"
                 "Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n"
                 "Group { numObjects 1 Transform { ZRotate 30 Scale 1.6 0.7 1 %s } }\n", W, H,
                 shape ? "TriangleMesh { obj_file sphere48.obj }" : "Sphere { radius 1 }");
        Scene s;
        Status st = load("silhouette.txt", text, &s, &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        float *rgb = st ? NULL : render_rgb(&s);
        size_t wrong = 0, near_edge = 0;
        double c = cos(M_PI / 6.0), sn = sin(M_PI / 6.0);
        for (int j = 0; rgb && j < H; j++)
            for (int i = 0; i < W; i++) {
                /* the pixel centre's ray, turned back by -30 degrees and unsquashed */
                double x = ((i + 0.5) / W - 0.5) * 4.0 * W / H, y = (0.5 - (j + 0.5) / H) * 4.0;
                double xo = (c * x + sn * y) / 1.6, yo = (-sn * x + c * y) / 0.7, q = xo * xo + yo * yo;
                if (fabs(q - 1.0) < 1e-5) {
                    near_edge++;
                    continue;
                }
                wrong += (rgb[3 * ((size_t)j * W + i)] > 0.5f) != (q < 1.0);
            }
        fprintf(stderr, "  %s: %zu of %d pixels on the wrong side of the silhouette (%zu within 1e-5 of it)\n",
                shape ? "the old mesh" : "the ellipsoid", wrong, W * H, near_edge);
        if (!shape) CHECK_EQ_INT(wrong, 0);
        free(rgb);
        scene_free(&s);
    }
}

/* Mirroring transforms keep outward normals outward: with the view down -z through an
 * orthographic camera, the first hit's normal (the normal image, (n + 1) / 2, not
 * turned to face the viewer) points back at the camera on every pixel of a mirrored
 * mesh and a mirrored ellipsoid, instanced (BVH) and copied (kd-tree), as on the same
 * objects unmirrored. */
static void test_mirror_normals(void)
{
    write_cube("cube24.obj", 0);
    enum { W = 64, H = 32 };
    for (int mirror = 0; mirror < 2; mirror++)
        for (int accel = 0; accel < 2; accel++) {
            char text[2048];
            const char *m = mirror ? "Scale -1 1 1 " : "";
            snprintf(text, sizeof text,
                     "OrthographicCamera { center 0 0 5 direction 0 0 -1 up 0 1 0 size 3 width %d height %d }\n"
                     "Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n"
                     "Group { numObjects 3\n"
                     " Transform { Translate -1.5 0 0 %sRotate { 1 1 0 35 } Translate -0.5 -0.5 -0.5 "
                     "TriangleMesh { obj_file cube24.obj } }\n"
                     " Transform { Translate 100 0 0 TriangleMesh { obj_file cube24.obj } }\n"
                     " Transform { Translate 1.5 0 0 %sRotate { 1 1 0 35 } Scale 1 0.6 0.8 Sphere { radius 1 } }\n"
                     "}\n", W, H, m, m);
            Scene s;
            Error err;
            Status st = load("mirror.txt", text, &s, &err);
            CHECK_MSG(st == ST_OK, "%s", err.msg);
            if (st) continue;
            CHECK_EQ_INT(s.n_instances, 2);     /* placed twice (the second out of view): shared */
            s.integrator = INTEGRATOR_AOV_NORMAL;
            s.accel = accel ? ACCEL_KDTREE : ACCEL_BVH;
            float *rgb = render_rgb(&s);
            size_t hits = 0, inward = 0;
            for (size_t p = 0; rgb && p < (size_t)W * H; p++) {
                float nx = 2 * rgb[3 * p] - 1, ny = 2 * rgb[3 * p + 1] - 1, nz = 2 * rgb[3 * p + 2] - 1;
                if (fabsf(nx) + fabsf(ny) + fabsf(nz) < 0.5f) continue;    /* a miss: grey */
                hits++;
                inward += nz <= 0.0f;
            }
            fprintf(stderr, "  %s, %s: %zu of %zu hit pixels with an inward normal\n",
                    mirror ? "mirrored" : "unmirrored", accel ? "kd-tree" : "BVH", inward, hits);
            CHECK(hits > (size_t)W * H / 8);
            CHECK_EQ_INT(inward, 0);
            free(rgb);
            scene_free(&s);
        }
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/clpt-test-classic-XXXXXX");
    if (!mkdtemp(dir)) {
        fprintf(stderr, "cannot make a temporary folder\n");
        return 1;
    }
    write_assets();
    RUN(test_every_keyword);
    RUN(test_orthographic);
    RUN(test_transforms);
    RUN(test_squashed_spheres_memory);
    RUN(test_revsurface_tessellation_limit);
    RUN(test_material_scoping);
    RUN(test_crlf);
    RUN(test_paths);
    RUN(test_detect);
    RUN(test_errors);
    RUN(test_nesting_limit);
    RUN(test_projective_matrix);
    RUN(test_scene_format_additions);
    RUN(test_shipped_scenes);
    RUN(test_smooth_normals);
    RUN(test_mesh_normals_by_index);
    RUN(test_cli);
    RUN(test_mesh_instances);
    RUN(test_squashed_sphere_image);
    RUN(test_mirror_normals);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return harness_report();
}
