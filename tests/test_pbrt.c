/* test_pbrt.c — the pbrt-v4 reader (host/io/pbrt_parse.c): directives, transforms,
 * shapes, materials, lights and warnings of the scenes in tests/data/pbrt/, the image's
 * orientation (pbrt's left-handed camera space), and a scene rendered from its .pbrt
 * and its clpt-format twin, bit for bit. Run from the project root. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "cli_util.h"
#include "harness.h"
#include "util/kmath.h"
#include "io/pbrt_parse.h"
#include "io/scene_load.h"
#include "render_util.h"
#include "scene/blackbody.h"
#include "scene/camera.h"
#include "io/image_write.h"
#include "scene/mesh_sink.h"
#include "scene/octa_env.h"
#include "scene/instance.h"
#include "scene/scene.h"
#include "scene/subdiv.h"

#define DIR "tests/data/pbrt/"

static Status load(const char *path, Scene *s, Error *err)
{
    scene_init(s);
    SceneKind kind = 0;
    Status st = scene_load_file(path, SCENE_FORMAT_AUTO, s, &kind, err);
    if (!st) CHECK_EQ_INT(kind, SCENE_KIND_PBRT);
    return st;
}

static Status load_text(const char *text, Scene *s, Error *err)
{
    scene_init(s);
    return scene_load_bytes(DIR "inline.pbrt", text, strlen(text), SCENE_FORMAT_AUTO, s, NULL, err);
}

#define CHECK_V3(v, X, Y, Z, tol)                                                      \
    do {                                                                               \
        CHECK_NEAR((v).x, X, tol);                                                     \
        CHECK_NEAR((v).y, Y, tol);                                                     \
        CHECK_NEAR((v).z, Z, tol);                                                     \
    } while (0)

static void test_detect(void)
{
    CHECK(pbrt_detect("# c\n  LookAt 0 0 0 0 0 1 0 1 0", 26));
    CHECK(pbrt_detect("WorldBegin", 10));
    CHECK(!pbrt_detect("camera { }", 10));
    CHECK(!pbrt_detect("PerspectiveCamera {", 19));
    CHECK_EQ_INT(scene_load_kind("x.PBRT", "", 0, SCENE_FORMAT_AUTO), SCENE_KIND_PBRT);
    CHECK_EQ_INT(scene_load_kind("x.txt", "Shape \"sphere\"", 14, SCENE_FORMAT_AUTO), SCENE_KIND_PBRT);
}

static void test_basic(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load(DIR "basic.pbrt", &s, &err), ST_OK);
    CHECK_EQ_INT(s.image.width, 64);
    CHECK_EQ_INT(s.image.height, 48);
    CHECK_EQ_INT(s.image.spp, 8);
    CHECK_EQ_INT(s.image.max_depth, 6);
    CHECK_EQ_INT(s.n_spheres, 2);
    CHECK_EQ_INT(s.n_triangles, 4);
    CHECK_V3(s.camera.from, 0, 1.5, 5, 1e-6);
    CHECK_NEAR(s.camera.vfov, 40, 1e-5);   /* landscape: fov is the vertical one */
    CHECK(s.camera.mirror_x);
    CHECK_V3(s.spheres[0].center, -0.9, 0.6, 0, 1e-6);
    CHECK_V3(s.spheres[1].center, 0.9, 0.6, 0, 1e-6);
    CHECK_NEAR(s.spheres[1].radius, 0.6, 1e-6);
    CHECK_EQ_INT(s.materials[s.spheres[1].material].type, MAT_DIELECTRIC);
    /* the area light faces down (Rotate 90 about x turns +z to -y) */
    const Triangle *t = &s.triangles[2];
    vec3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0);
    CHECK(e1.z * e2.x - e1.x * e2.z < 0);
    CHECK(s.materials[t->material].emission.y > 0);
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
}

static void test_transforms(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load(DIR "transforms.pbrt", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_spheres, 6);
    if (s.n_spheres == 6) {
        CHECK_V3(s.spheres[0].center, 0, 1, 0, 1e-6);   /* Rotate 90 about z, then x 1 */
        CHECK_V3(s.spheres[1].center, 2, 3, 4, 0);      /* Transform is column by column */
        CHECK_V3(s.spheres[2].center, 1, 1, 0, 0);      /* ConcatTransform */
        CHECK_NEAR(s.spheres[2].radius, 0.5, 0);
        CHECK_V3(s.spheres[3].center, 1, 1, 2, 0);      /* CoordSysTransform */
        CHECK_V3(s.spheres[4].center, 0, 0, 10, 1e-6);  /* the camera's system */
    }
    /* the sphere under Scale 1 2 1 is an analytic ellipsoid, 2 units tall: the unit
     * sphere under diag(0.5, 1, 0.5), bounded by the sphere of radius |M|_F */
    CHECK_EQ_INT(s.n_triangles, 2);
    CHECK_EQ_INT(s.n_sphere_xforms, 1);
    if (s.n_spheres == 6 && s.n_sphere_xforms == 1) {
        CHECK_EQ_INT(s.spheres[5].xform, 1);
        const float *m = s.sphere_xforms[0].to_world, *mi = s.sphere_xforms[0].to_object;
        CHECK_NEAR(m[0], 0.5, 0);
        CHECK_NEAR(m[5], 1, 0);
        CHECK_NEAR(m[10], 0.5, 0);
        CHECK_NEAR(mi[5], 1, 0);
        CHECK_NEAR(mi[10], 2, 0);
        CHECK_NEAR(s.spheres[5].radius, sqrt(1.5), 1e-6);
        CHECK_EQ_INT(s.spheres[0].xform, 0);
    }
    /* ReverseOrientation swaps the winding */
    size_t n = s.n_triangles;
    CHECK_V3(s.triangles[n - 2].p1, 0, 1, 0, 0);
    CHECK_V3(s.triangles[n - 1].p1, 1, 0, 0, 0);
    CHECK_EQ_INT(s.camera.type, CAMERA_ORTHOGRAPHIC);
    CHECK_NEAR(s.camera.ortho_height, 4, 0);   /* [-1, 1] across the shorter side */
    scene_free(&s);
}

/* coateddiffuse and coatedconductor become MAT_LAYERED (kernels/bsdf/layered.h) with each
 * of pbrt-v4's parameters, and pbrt's defaults where none is given. */
static void test_coated(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load(DIR "coated.pbrt", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_spheres, 5);
    if (s.n_spheres != 5) goto out;
    const Material *m[5];
    for (int i = 0; i < 5; i++) {
        m[i] = &s.materials[s.spheres[i].material];
        CHECK_EQ_INT(m[i]->type, MAT_LAYERED);
    }
    /* coateddiffuse, everything given */
    CHECK_EQ_INT(m[0]->layer_base, LAYER_BASE_DIFFUSE);
    CHECK_V3(m[0]->albedo, 0.2, 0.4, 0.6, 1e-6);
    CHECK_NEAR(m[0]->roughness, sqrt(0.02), 1e-6);   /* alpha 0.01 and 0.04, not remapped */
    CHECK_NEAR(m[0]->anisotropy, 0.75 / 0.9, 1e-6);
    CHECK_NEAR(m[0]->ior, 1.33, 1e-6);
    CHECK_NEAR(m[0]->layer_thickness, 0.05, 1e-7);
    CHECK_V3(m[0]->layer_albedo, 0.1, 0.2, 0.3, 1e-6);
    CHECK_NEAR(m[0]->layer_g, 0.4, 1e-7);
    CHECK_EQ_INT(m[0]->layer_depth, 20);
    CHECK_EQ_INT(m[0]->layer_samples, 3);
    /* coatedconductor, everything given: gold under a coat */
    vec3 eta, k;
    material_metal_preset("Au", 2, &eta, &k);
    CHECK_EQ_INT(m[1]->layer_base, LAYER_BASE_CONDUCTOR);
    CHECK_V3(m[1]->eta, eta.x, eta.y, eta.z, 0);
    CHECK_V3(m[1]->k, k.x, k.y, k.z, 0);
    CHECK_NEAR(m[1]->roughness, 0.5, 1e-6);   /* remapped: alpha = sqrt(0.0625) */
    CHECK_NEAR(m[1]->anisotropy, 0, 0);
    CHECK_NEAR(m[1]->ior, 1.4, 1e-6);
    /* alpha 0.5 and 0.25: roughness (0.5 * 0.25)^(1/4), anisotropy (1 - 0.5) / 0.9 */
    CHECK_NEAR(m[1]->base_roughness, pow(0.125, 0.25), 1e-6);
    CHECK_NEAR(m[1]->base_anisotropy, 0.5 / 0.9, 1e-6);
    CHECK_NEAR(m[1]->layer_thickness, 0.2, 1e-7);
    CHECK_V3(m[1]->layer_albedo, 0.5, 0.5, 0.5, 0);
    CHECK_NEAR(m[1]->layer_g, -0.3, 1e-7);
    CHECK_EQ_INT(m[1]->layer_depth, 7);
    CHECK_EQ_INT(m[1]->layer_samples, 2);
    /* a conductor's reflectance: pbrt's index eta 1, k = 2 sqrt(r) / sqrt(1 - r) */
    CHECK_V3(m[2]->eta, 1, 1, 1, 0);
    CHECK_V3(m[2]->k, 2 * sqrt(0.5) / sqrt(0.5), 2 * sqrt(0.8) / sqrt(0.2), 2 * sqrt(0.25) / sqrt(0.75), 1e-5);
    /* pbrt-v4's defaults: reflectance 0.5, smooth, eta 1.5, thickness 0.01, no medium,
     * maxdepth 10, nsamples 1; an eta of 0 is 1 */
    CHECK_EQ_INT(m[3]->layer_base, LAYER_BASE_DIFFUSE);
    CHECK_V3(m[3]->albedo, 0.5, 0.5, 0.5, 0);
    CHECK_NEAR(m[3]->roughness, 0, 0);
    CHECK_NEAR(m[3]->ior, 1.5, 0);
    CHECK_NEAR(m[3]->layer_thickness, 0.01, 1e-9);
    CHECK_V3(m[3]->layer_albedo, 0, 0, 0, 0);
    CHECK_NEAR(m[3]->layer_g, 0, 0);
    CHECK_EQ_INT(m[3]->layer_depth, 10);
    CHECK_EQ_INT(m[3]->layer_samples, 1);
    CHECK_NEAR(m[4]->ior, 1, 0);
out:
    scene_free(&s);
}

static void test_materials_lights(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load(DIR "materials.pbrt", &s, &err), ST_OK);
    /* portrait: fov spans the width */
    CHECK_NEAR(s.camera.vfov, 360 / M_PI * atan(tan(20 * M_PI / 180) * 32 / 24), 1e-4);
    CHECK_NEAR(s.camera.aperture, 0.2, 1e-7);
    CHECK_NEAR(s.camera.focus_dist, 4, 0);
    CHECK(s.camera.mirror_x);
    CHECK_EQ_INT(s.n_spheres, 10);
    if (s.n_spheres != 10) goto out;
    /* an imagemap texture, found beside the scene, gives a diffuse material's colour */
    CHECK_EQ_INT(s.n_textures, 1);
    CHECK_EQ_INT(s.materials[s.spheres[9].material].texture, 0);
    const Material *m[9];
    for (int i = 0; i < 9; i++) m[i] = &s.materials[s.spheres[i].material];
    CHECK_EQ_INT(m[0]->type, MAT_DIFFUSE);
    CHECK_V3(m[0]->albedo, 0.25, 0.5, 0.75, 0);
    vec3 eta, k;
    material_metal_preset("Ag", 2, &eta, &k);
    CHECK_EQ_INT(m[1]->type, MAT_CONDUCTOR);
    CHECK_V3(m[1]->eta, eta.x, eta.y, eta.z, 0);
    CHECK_V3(m[1]->k, k.x, k.y, k.z, 0);
    CHECK_NEAR(m[1]->roughness, 0.5, 1e-6);   /* alpha = sqrt(0.0625) = 0.25 */
    CHECK(m[2]->flags & MAT_F0);
    CHECK_V3(m[2]->specular, 0.9, 0.6, 0.3, 1e-6);
    CHECK_NEAR(m[2]->roughness, sqrt(0.02), 1e-6);
    CHECK_NEAR(m[2]->anisotropy, 0.75 / 0.9, 1e-6);
    CHECK_EQ_INT(m[3]->type, MAT_DIELECTRIC);
    CHECK_NEAR(m[3]->ior, 1.5185, 1e-6);
    CHECK(m[4]->flags & MAT_THIN);
    CHECK_NEAR(m[4]->ior, 1.33, 1e-6);
    CHECK_EQ_INT(m[5]->type, MAT_LAYERED);
    CHECK_EQ_INT(m[5]->layer_base, LAYER_BASE_DIFFUSE);
    CHECK_V3(m[5]->albedo, 0.2, 0.4, 0.6, 1e-6);
    CHECK(m[6]->flags & MAT_INTERFACE);   /* "interface": a boundary, no surface */
    CHECK_EQ_INT(m[7]->type, MAT_MIX);   /* "a" and "b", b three times in four */
    CHECK_EQ_INT(s.materials[m[7]->mix_a].type, MAT_DIFFUSE);
    CHECK_EQ_INT(s.materials[m[7]->mix_b].type, MAT_DIELECTRIC);
    CHECK_NEAR(m[7]->mix_amount, 0.75, 0);
    CHECK_EQ_INT(m[7]->mix_texture, NO_INDEX);
    CHECK_V3(m[8]->emission, 2, 4, 6, 0);
    CHECK(m[8]->flags & MAT_TWO_SIDED);
    CHECK_EQ_INT(m[8]->type, MAT_DIFFUSE);
    CHECK_EQ_INT(s.n_delta_lights, 3);
    if (s.n_delta_lights == 3) {
        const Light *l = s.delta_lights;
        CHECK_EQ_INT(l[0].type, LIGHT_POINT);
        CHECK_V3(l[0].position, 1, 2, 3, 0);
        CHECK_V3(l[0].intensity, 5, 5, 5, 0);
        CHECK_EQ_INT(l[1].type, LIGHT_SPOT);
        CHECK_V3(l[1].direction, 0, -1, 0, 0);
        CHECK_NEAR(l[1].cos_outer, cos(20 * M_PI / 180), 1e-7);
        CHECK_NEAR(l[1].cos_inner, cos(15 * M_PI / 180), 1e-7);
        CHECK_EQ_INT(l[2].type, LIGHT_DIRECTIONAL);
        CHECK_V3(l[2].direction, 0, -1, 0, 0);
        vec3 c = l[2].intensity;   /* a warm white of luminance 1 */
        CHECK_NEAR(0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z, 1, 1e-3);
        CHECK(c.x > c.y && c.y > c.z);
    }
    CHECK_EQ_INT(s.bg_type, BG_CONSTANT);
    CHECK_V3(s.bg_color, 0.5, 0.5, 0.5, 0);
    CHECK_EQ_INT(s.n_warnings, 0);
out:
    scene_free(&s);
}

static void test_warnings(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load(DIR "warnings.pbrt", &s, &err), ST_OK);
    static const char *want[] = {
        DIR "warnings.pbrt:2: PixelFilter is not supported; ignored",
        DIR "warnings.pbrt:3: Film: parameter \"float iso\" is not supported; ignored",
        DIR "warnings.pbrt:5: Shape \"cone\" is not supported; skipped",
        DIR "warnings.pbrt:7: Shape: parameter \"float wobble\" is not supported; ignored",
        DIR "warnings.pbrt:9: medium \"vapour\" is not supported; \"fog\" is left empty (vacuum)",
    };
    CHECK_EQ_INT(s.n_warnings, 5);
    for (size_t i = 0; i < 5 && i < s.n_warnings; i++)
        CHECK_MSG(strcmp(s.warnings[i], want[i]) == 0, "got '%s'", s.warnings[i]);
    CHECK_EQ_INT(s.n_spheres, 2);
    scene_free(&s);
}

/* ActiveTransform takes a bare word (pbrt-v4's killeroo-moving.pbrt) and picks which of
 * the two transforms (start and end time) the transform directives change; AttributeEnd
 * restores the setting and WorldBegin makes both active. A Shape whose two transforms
 * differ moves: an object of its own and a moving instance (test_pbrt_motion.c renders
 * them). */
static void test_active_transform(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("ActiveTransform EndTime\n"
                           "Translate 0 0 100\n"
                           "WorldBegin\n"
                           "AttributeBegin\n"
                           "  ActiveTransform StartTime\n"
                           "  Translate 1 0 0\n"
                           "  ActiveTransform EndTime\n"
                           "  Translate 10 0 0\n"
                           "  ActiveTransform All\n"
                           "  Translate 0 2 0\n"
                           "  Shape \"sphere\"\n"
                           "  AttributeBegin\n"
                           "    ActiveTransform EndTime\n"
                           "  AttributeEnd\n"
                           "  Translate 0 0 3\n"
                           "  Shape \"sphere\"\n"
                           "AttributeEnd\n"
                           "Shape \"sphere\"\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_spheres, 3);
    CHECK_EQ_INT(s.n_instances, 2);
    CHECK_EQ_INT(s.n_motion_keys, 4);
    if (s.n_instances == 2 && s.n_motion_keys == 4) {
        /* the start poses (1 2 0) and (1 2 3), the end ones (10 2 0) and (10 2 3) */
        for (int i = 0; i < 2; i++) {
            CHECK_NEAR(s.instances[i].to_world[3], 1, 0);
            CHECK_NEAR(s.instances[i].to_world[7], 2, 0);
            CHECK_NEAR(s.instances[i].to_world[11], 3 * i, 0);
            CHECK_V3(s.motion_keys[2 * i].translate, 1, 2, 3 * i, 0);
            CHECK_V3(s.motion_keys[2 * i + 1].translate, 10, 2, 3 * i, 0);
        }
    }
    if (s.n_spheres == 3) CHECK_V3(s.spheres[2].center, 0, 0, 0, 0);
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    /* anything but the three words is an error */
    Status st = load_text("WorldBegin\nActiveTransform \"StartTime\"\n", &s, &err);
    CHECK_EQ_INT(st, ST_INPUT);
    CHECK_MSG(strstr(err.msg, "StartTime, EndTime or All") != NULL, "got '%s'", err.msg);
    scene_free(&s);
}

/* Material "" and "none" are pbrt-v4's "no material" (a medium's boundary, as
 * "interface"; pbrt-v4-scenes' clouds.pbrt): a boundary rays pass straight through
 * (MAT_INTERFACE, docs/media.md), no warning */
static void test_no_material(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("WorldBegin\n"
                           "Material \"\" Shape \"sphere\"\n"
                           "Material \"none\" Shape \"sphere\"\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_spheres, 2);
    for (size_t i = 0; i < 2 && i < s.n_spheres; i++) {
        const Material *m = &s.materials[s.spheres[i].material];
        CHECK(m->flags & MAT_INTERFACE);
    }
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
}


static void expect_error(const char *text, const char *msg);

/* NamedMaterial before its MakeNamedMaterial, as pbrt-v4 allows (it resolves names once
 * the scene is read; pbrt-v4-scenes' contemporary-bathroom.pbrt includes materials.pbrt
 * last): the shapes, and an area light's copy, take the later definition. A mix may not
 * name a material before it is defined (pbrt-v4 creates mixes in order, too). */
static void test_named_material_later(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("WorldBegin\n"
                           "AttributeBegin\n"
                           "  NamedMaterial \"light\"\n"
                           "  AreaLightSource \"diffuse\" \"rgb L\" [ 2 2 2 ] \"bool twosided\" true\n"
                           "  Shape \"sphere\"\n"
                           "AttributeEnd\n"
                           "NamedMaterial \"light\"\n"
                           "Translate 3 0 0 Shape \"sphere\"\n"
                           "MakeNamedMaterial \"light\" \"string type\" \"conductor\"\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_spheres, 2);
    if (s.n_spheres == 2) {
        const Material *lit = &s.materials[s.spheres[0].material];
        const Material *plain = &s.materials[s.spheres[1].material];
        CHECK_EQ_INT(lit->type, MAT_CONDUCTOR);
        CHECK(lit->emission.x > 0);
        CHECK(lit->flags & MAT_TWO_SIDED);
        CHECK_EQ_INT(plain->type, MAT_CONDUCTOR);
        CHECK(v3_is_zero(plain->emission));
    }
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    expect_error("WorldBegin\nNamedMaterial \"a\"\n"
                 "MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"a\" \"a\"]\n",
                 DIR "inline.pbrt:3:63: material 'a' is not defined (MakeNamedMaterial defines it)");
}

static void test_include(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load(DIR "main-include.pbrt", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_spheres, 1);
    CHECK_EQ_INT(s.n_triangles, 2 + 2 + 6);   /* two bilinear patches, the PLY pyramid */
    scene_free(&s);
    CHECK_EQ_INT(load(DIR "self-include.pbrt", &s, &err), ST_INPUT);
    CHECK_MSG(strstr(err.msg, "includes nested more than 16 deep") != NULL, "got '%s'", err.msg);
    scene_free(&s);
}

/* Writes `text` to `path`, through gzip when `gz`. */
static void write_file(const char *path, const char *text, size_t len, int gz)
{
    if (gz) {
        gzFile g = gzopen(path, "wb");
        CHECK(g != NULL);
        if (!g) return;
        CHECK_EQ_INT(gzwrite(g, text, (unsigned)len), (int)len);
        CHECK_EQ_INT(gzclose(g), Z_OK);
        return;
    }
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f) return;
    CHECK_EQ_INT(fwrite(text, 1, len, f), len);
    fclose(f);
}

/* pbrt-v4-scenes (hair, bunny-fur, ganesha) Include .pbrt.gz files and read .ply.gz
 * meshes: the compressed pair loads the very triangles of the plain pair. */
static void test_gzip(void)
{
    char dir[] = "/tmp/clpt-test-gz-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    static const char *const ply =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n1 1 0\n0 1 2\n3 0 1 2\n3 0 2 3\n";
    static const char *const inc = "Translate 0 0 1\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] "
                                   "\"integer indices\" [ 0 1 2 ]\n";
    char path[4][96], scene[2][96];
    const char *names[4] = { "inc.pbrt", "inc.pbrt.gz", "mesh.ply", "mesh.ply.gz" };
    for (int i = 0; i < 4; i++) {
        snprintf(path[i], sizeof path[i], "%s/%s", dir, names[i]);
        write_file(path[i], i < 2 ? inc : ply, strlen(i < 2 ? inc : ply), i & 1);
    }
    for (int gz = 0; gz < 2; gz++) {
        char text[256];
        int n = snprintf(text, sizeof text,
                         "WorldBegin\nAttributeBegin\nInclude \"inc.pbrt%s\"\nAttributeEnd\n"
                         "Shape \"plymesh\" \"string filename\" \"mesh.ply%s\"\n",
                         gz ? ".gz" : "", gz ? ".gz" : "");
        snprintf(scene[gz], sizeof scene[gz], "%s/%s", dir, gz ? "gz.pbrt" : "plain.pbrt");
        write_file(scene[gz], text, (size_t)n, 0);
    }
    Scene a, b;
    Error err = { 0 };
    CHECK_EQ_INT(load(scene[0], &a, &err), ST_OK);
    CHECK_EQ_INT(load(scene[1], &b, &err), ST_OK);
    CHECK_EQ_INT(a.n_triangles, 3);
    CHECK_EQ_INT(b.n_triangles, a.n_triangles);
    if (a.n_triangles == 3 && b.n_triangles == 3) {
        CHECK(memcmp(a.triangles, b.triangles, 3 * sizeof *a.triangles) == 0);
        CHECK_NEAR(a.triangles[0].p0.z, 1.0f, 0.0f); /* the include's Translate held */
    }
    scene_free(&a);
    scene_free(&b);

    /* cut short: the first half of the gzip file */
    char cut[96];
    snprintf(cut, sizeof cut, "%s/cut.ply.gz", dir);
    FILE *f = fopen(path[3], "rb");
    char bytes[512];
    size_t n = f ? fread(bytes, 1, sizeof bytes, f) : 0;
    if (f) fclose(f);
    CHECK(n > 20);
    write_file(cut, bytes, n / 2, 0);
    char msg[256];
    snprintf(msg, sizeof msg, "'%s': the gzip data is cut short", cut);
    CHECK_EQ_INT(load(cut, &a, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, msg) == 0, "got '%s', expected '%s'", err.msg, msg);
    scene_free(&a);
    /* not gzip at all: the plain PLY named .gz */
    snprintf(cut, sizeof cut, "%s/plain.ply.gz", dir);
    write_file(cut, ply, strlen(ply), 0);
    snprintf(msg, sizeof msg, "'%s': not valid gzip data (zlib: incorrect header check)", cut);
    CHECK_EQ_INT(load(cut, &a, &err), ST_INPUT);
    CHECK_MSG(strcmp(err.msg, msg) == 0, "got '%s', expected '%s'", err.msg, msg);
    scene_free(&a);
    /* through Include, the error names the compressed file */
    snprintf(path[0], sizeof path[0], "%s/bad.pbrt", dir);
    write_file(path[0], "Include \"plain.ply.gz\"\n", 23, 0);
    CHECK_EQ_INT(load(path[0], &a, &err), ST_INPUT);
    CHECK_MSG(strstr(err.msg, "plain.ply.gz': not valid gzip data (zlib: incorrect header check)") != NULL,
              "got '%s'", err.msg);
    scene_free(&a);
    error_clear(&err);

    const char *all[] = { "inc.pbrt", "inc.pbrt.gz", "mesh.ply", "mesh.ply.gz", "plain.pbrt", "gz.pbrt",
                          "cut.ply.gz", "plain.ply.gz", "bad.pbrt" };
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) {
        snprintf(path[0], sizeof path[0], "%s/%s", dir, all[i]);
        unlink(path[0]);
    }
    rmdir(dir);
}

/* A 510 KB .pbrt.gz inflated to 536 MB, and includes added such files up without end
 * (issue 39): one load's files count against one budget, a .gz file inflated, set by
 * CLPT_MAX_LOAD_BYTES (16 GiB by default). A 1 MiB comment compressed to about 1 KB,
 * included twice by a file included twice: the fourth passes a 3.5 MiB budget. */
static void test_load_budget(void)
{
    char dir[] = "/tmp/clpt-test-budget-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    size_t big = (size_t)1 << 20;
    char *text = malloc(big);
    CHECK(text != NULL);
    if (!text) return;
    memset(text, ' ', big);
    text[0] = '#';
    text[big - 1] = '\n';
    char bomb[96], mid[96], top[96];
    snprintf(bomb, sizeof bomb, "%s/bomb.pbrt.gz", dir);
    snprintf(mid, sizeof mid, "%s/mid.pbrt", dir);
    snprintf(top, sizeof top, "%s/top.pbrt", dir);
    write_file(bomb, text, big, 1);
    free(text);
    static const char inc_bomb[] = "Include \"bomb.pbrt.gz\"\nInclude \"bomb.pbrt.gz\"\n";
    static const char inc_mid[] = "WorldBegin\nInclude \"mid.pbrt\"\nInclude \"mid.pbrt\"\n";
    write_file(mid, inc_bomb, strlen(inc_bomb), 0);
    write_file(top, inc_mid, strlen(inc_mid), 0);
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load(top, &s, &err), ST_OK);     /* the default budget */
    scene_free(&s);
    setenv("CLPT_MAX_LOAD_BYTES", "3670016", 1);
    char msg[400];
    snprintf(msg, sizeof msg, "'%s': reading it takes this load's input to more than 3670016 bytes (the files of one "
             "scene together, .gz files inflated; CLPT_MAX_LOAD_BYTES sets the budget)", bomb);
    CHECK_EQ_INT(load(top, &s, &err), ST_INPUT);
    CHECK_MSG(strstr(err.msg, msg) != NULL, "got '%s', expected it to end '%s'", err.msg, msg);
    scene_free(&s);
    setenv("CLPT_MAX_LOAD_BYTES", "4200000", 1);   /* four bombs and the two files */
    CHECK_EQ_INT(load(top, &s, &err), ST_OK);
    scene_free(&s);
    setenv("CLPT_MAX_LOAD_BYTES", "3 GB", 1);
    CHECK_EQ_INT(load(top, &s, &err), ST_USAGE);
    CHECK_MSG(strcmp(err.msg, "CLPT_MAX_LOAD_BYTES='3 GB': expected a whole number of bytes") == 0, "got '%s'",
              err.msg);
    scene_free(&s);
    unsetenv("CLPT_MAX_LOAD_BYTES");
    error_clear(&err);
    unlink(bomb);
    unlink(mid);
    unlink(top);
    rmdir(dir);
}

/* ObjectBegin/End make a scene object whose shapes keep their own CTM; each
 * ObjectInstance places it under the CTM of the moment (pbrt-v4's render-from-instance);
 * flattened, the instances are the copies the reader made before objects. */
static void test_instances(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load(DIR "instances.pbrt", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_objects, 1);
    CHECK_EQ_INT(s.n_instances, 2);
    CHECK_EQ_INT(s.n_triangles, 1);
    CHECK_EQ_INT(s.n_spheres, 1);
    if (s.n_instances == 2 && s.n_triangles == 1 && s.n_spheres == 1) {
        CHECK_V3(s.triangles[0].p1, 1, 1, 0, 0);   /* the object's own Translate 0 1 0 */
        CHECK_V3(s.spheres[0].center, 0, 1, 0, 0);
        CHECK(s.instances[0].flags & INST_IDENTITY);
        const float *m = s.instances[1].to_world;   /* Translate 5 0 0 . Scale 2 2 2 */
        CHECK(m[0] == 2 && m[5] == 2 && m[10] == 2 && m[3] == 5 && m[7] == 0 && m[11] == 0);
        CHECK_EQ_INT(s.instances[1].material, NO_INDEX);
    }
    CHECK_EQ_INT(scene_flatten_instances(&s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 2);
    CHECK_EQ_INT(s.n_spheres, 2);
    if (s.n_triangles == 2 && s.n_spheres == 2) {
        CHECK_V3(s.triangles[0].p1, 1, 1, 0, 0);
        CHECK_V3(s.triangles[1].p1, 7, 2, 0, 0);   /* (1, 1, 0) scaled by 2, moved by 5 */
        CHECK_V3(s.spheres[0].center, 0, 1, 0, 0);
        CHECK_V3(s.spheres[1].center, 5, 2, 0, 0);   /* radius 1: an ellipsoid of scale 2 */
        CHECK(s.spheres[1].xform && s.sphere_xforms[s.spheres[1].xform - 1].to_world[0] == 1.0f);
        CHECK(s.triangles[1].shading != NO_INDEX && s.shading[s.triangles[1].shading].n0.z == 1);
    }
    scene_free(&s);

    /* a name defined again serves the instances after it; an object whose emitters are
     * triangles is instanced (they are lights under every instance); one that holds an
     * emitting sphere is instanced under a similarity and copied, with a warning, under
     * any other transform (its sphere a mesh light, facing out); a singular instance is
     * skipped */
    CHECK_EQ_INT(load_text("ObjectBegin \"a\" Shape \"sphere\" ObjectEnd ObjectInstance \"a\"\n"
                           "ObjectBegin \"a\" Shape \"sphere\" \"float radius\" 2 ObjectEnd ObjectInstance \"a\"\n"
                           "ObjectBegin \"lamp\" AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
                           "  Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] ObjectEnd\n"
                           "ObjectInstance \"lamp\" Translate 3 0 0 ObjectInstance \"lamp\"\n"
                           "ObjectBegin \"ball\" AreaLightSource \"diffuse\" \"rgb L\" [1 1 1] Shape \"sphere\"\n"
                           "ObjectEnd ObjectInstance \"ball\" Translate 0 3 0 ObjectInstance \"ball\"\n"
                           "AttributeBegin Scale 1 2 1 ObjectInstance \"ball\" AttributeEnd\n"
                           "Scale 0 1 1 ObjectInstance \"a\"\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_objects, 4);
    CHECK_EQ_INT(s.n_instances, 6);
    CHECK_EQ_INT(s.n_spheres, 3);   /* one in each object "a", one in "ball" */
    CHECK_EQ_INT(s.n_triangles, 1 + 2 * 64 * 32 - 2 * 64);   /* "lamp"'s, the squashed ball's mesh */
    if (s.n_instances == 6 && s.n_objects == 4) {
        CHECK_EQ_INT(s.instance_objects[0], 0);
        CHECK_EQ_INT(s.instance_objects[1], 1);
        CHECK_EQ_INT(s.instance_objects[2], 2);
        CHECK_EQ_INT(s.instance_objects[3], 2);
        CHECK_EQ_INT(s.instance_objects[4], 3);
        CHECK_EQ_INT(s.instance_objects[5], 3);
        CHECK(strcmp(s.objects[1].name, "a#1") == 0);
        CHECK(strcmp(s.objects[2].name, "lamp") == 0);
    }
    size_t outward = 0, glowing = 0;
    /* the copy's centre: the object's sphere at (3, 0, 0) (the CTM at its Shape), placed
     * by Translate 3 0 0, Translate 0 3 0, Scale 1 2 1 */
    for (size_t i = 1; i < s.n_triangles; i++) {
        const Triangle *t = &s.triangles[i];
        vec3 w = v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0));
        vec3 c = v3_sub(v3_scale(v3_add(v3_add(t->p0, t->p1), t->p2), 1.0f / 3.0f), v3(6, 3, 0));
        outward += v3_dot(w, c) > 0;
        glowing += !v3_is_zero(s.materials[t->material].emission);
    }
    CHECK_EQ_INT(outward, s.n_triangles - 1);
    CHECK_EQ_INT(glowing, s.n_triangles - 1);
    CHECK_EQ_INT(s.n_warnings, 2);
    if (s.n_warnings == 2) {
        CHECK_STR_CONTAINS(s.warnings[0], "inline.pbrt:8: ObjectInstance \"ball\" holds an emitting sphere under a "
                           "transform that is no similarity: its shapes are copied (an instanced ellipsoid is no "
                           "light)");
        CHECK_STR_CONTAINS(s.warnings[1], "inline.pbrt:9: ObjectInstance \"a\" under a singular transform is skipped");
    }
    scene_free(&s);

    expect_error("ObjectInstance \"nothing\"",
                 DIR "inline.pbrt:1:16: object 'nothing' is not defined (ObjectBegin defines it)");
    expect_error("CoordSysTransform \"nowhere\"",
                 DIR "inline.pbrt:1:19: coordinate system 'nowhere' is not defined (CoordinateSystem defines it)");
    expect_error("ObjectBegin \"a\"\nAttributeEnd\nObjectEnd", DIR "inline.pbrt:3:1: ObjectEnd inside an "
                 "AttributeBegin of its object, or after one that closes more than it opened");
    expect_error("ObjectBegin \"a\"\nShape \"sphere\"",
                 DIR "inline.pbrt:1:1: ObjectBegin \"a\" has no ObjectEnd before the end of the file");
    expect_error("Shape \"sphere\"\n  ObjectEnd", DIR "inline.pbrt:2:3: ObjectEnd without ObjectBegin");
    expect_error("ObjectBegin \"a\"\nObjectBegin \"b\"",
                 DIR "inline.pbrt:2:1: ObjectBegin \"b\" inside ObjectBegin \"a\" (objects do not nest)");
    expect_error("ObjectBegin \"a\" Shape \"sphere\" ObjectEnd\nObjectBegin \"b\" ObjectInstance \"a\"",
                 DIR "inline.pbrt:2:17: ObjectInstance inside ObjectBegin \"b\" (objects hold shapes, not instances)");
}

/* One scene two ways: its object placed by ObjectInstance, and its shapes written out
 * under the same transforms. */
#define INST_HEAD                                                                                         \
    "LookAt 0 3 9  0 0.6 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n"                             \
    "Film \"rgb\" \"integer xresolution\" 48 \"integer yresolution\" 36\n"                                \
    "Sampler \"independent\" \"integer pixelsamples\" 16\nIntegrator \"path\" \"integer maxdepth\" 4\n"   \
    "WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.3 0.35 0.4]\n"                                     \
    "AttributeBegin AreaLightSource \"diffuse\" \"rgb L\" [6 6 6]\n"                                      \
    "  Shape \"trianglemesh\" \"point3 P\" [-1 4 -1 1 4 -1 1 4 1 -1 4 1] \"integer indices\" [0 1 2 0 2 3]\n" \
    "AttributeEnd\n"                                                                                      \
    "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"                                            \
    "Shape \"trianglemesh\" \"point3 P\" [-6 0 -6 6 0 -6 6 0 6 -6 0 6] \"integer indices\" [0 2 1 0 3 2]\n"
#define INST_SHAPES                                                                                       \
    "  AttributeBegin Material \"diffuse\" \"rgb reflectance\" [0.8 0.25 0.2]\n"                          \
    "    Translate 0 0.5 0 Shape \"sphere\" \"float radius\" 0.5 AttributeEnd\n"                          \
    "  Material \"conductor\" \"float roughness\" 0.3\n"                                                  \
    "  Shape \"trianglemesh\" \"point3 P\" [0.6 0 -0.3 1.2 0 -0.3 1.2 0.6 0.3 0.6 0.6 0.3]\n"             \
    "    \"integer indices\" [0 1 2 0 2 3]\n"
#define INST_OBJECT "ObjectBegin \"thing\"\n" INST_SHAPES "ObjectEnd\n"
#define PLACE_INST(xf) "AttributeBegin " xf " ObjectInstance \"thing\" AttributeEnd\n"
#define PLACE_COPY(xf) "AttributeBegin " xf "\n" INST_SHAPES "AttributeEnd\n"
#define MOVED_A "Translate 2.6 0 0"
#define MOVED_B "Translate -2.4 0 0.5 Rotate 35 0 1 0 Scale 1 1.4 1"
#define MOVED_C "Translate 0 0 -2 Scale -1 1 1"

static const char inst_identity[] = INST_HEAD INST_OBJECT PLACE_INST("");
static const char copy_identity[] = INST_HEAD PLACE_COPY("");
static const char inst_moved[] = INST_HEAD INST_OBJECT PLACE_INST("") PLACE_INST(MOVED_A) PLACE_INST(MOVED_B)
    PLACE_INST(MOVED_C);
static const char copy_moved[] = INST_HEAD PLACE_COPY("") PLACE_COPY(MOVED_A) PLACE_COPY(MOVED_B) PLACE_COPY(MOVED_C);

static Status render_text(const char *text, const char *devices, Film *f, Error *err)
{
    Scene s;
    Status st = load_text(text, &s, err);
    if (!st) st = render_util_run(&s, devices, 0, f, err);
    scene_free(&s);
    return st;
}

/* An identity ObjectInstance renders bit for bit as its shapes written out; moved,
 * rotated, stretched and mirrored ones the same mean within noise; PoCL renders the
 * instances bit for bit as the scalar device. */
static void test_instances_render(void)
{
    Film a, b;
    Error err = { 0 };
    CHECK_MSG(render_text(inst_identity, "scalar", &a, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_text(copy_identity, "scalar", &b, &err) == ST_OK, "%s", err.msg);
    if (a.sum && b.sum) {
        size_t n = (size_t)a.width * a.height * 3u, same = film_sums_same(&a, &b);
        fprintf(stderr, "  identity ObjectInstance: %zu of %zu channel sums identical to the shapes written out\n",
                same, n);
        CHECK(same == n);
    }
    film_free(&a);
    film_free(&b);
    CHECK_MSG(render_text(inst_moved, "scalar", &a, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_text(copy_moved, "scalar", &b, &err) == ST_OK, "%s", err.msg);
    if (a.sum && b.sum) {
        double ma = film_mean(&a), mb = film_mean(&b);
        size_t n = (size_t)a.width * a.height * 3u, same = film_sums_same(&a, &b);
        fprintf(stderr, "  moved ObjectInstances: mean %.6f, written out %.6f; %zu of %zu channel sums identical\n",
                ma, mb, same, n);
        CHECK(fabs(ma - mb) < 0.01 * mb);
        CHECK(same > n / 2);
    }
    film_free(&b);
    Film c;
    Status sc = render_text(inst_moved, TEST_OPENCL, &c, &err);
    CHECK_MSG(sc == ST_OK, "%s", err.msg);
    if (!sc && a.sum) {
        size_t n = (size_t)a.width * a.height * 3u, same = film_sums_same(&a, &c);
        fprintf(stderr, "  moved ObjectInstances: %zu of %zu channel sums identical on OpenCL and scalar\n", same, n);
        CHECK(same == n);
        film_free(&c);
    }
    film_free(&a);
}

/* --stats counts the instances and the triangles they place. */
static void test_instances_stats(void)
{
    char scene[64];
    write_temp(scene, sizeof scene, ".pbrt", inst_moved);
    CliResult r;
    cli_run((const char *[]){ scene, "-q", "--device", "scalar", "--spp", "1", "--stats", "-o",
                              CLPT_BUILD_DIR "/test-pbrt-inst.pfm", NULL }, &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_STR_CONTAINS(r.out, "instances: 4 of 1 objects; triangles: 6 unique (2 in objects), 8 instanced "
                       "(12 with the world's)");
    unlink(scene);
    unlink(CLPT_BUILD_DIR "/test-pbrt-inst.pfm");
}

/* An emitting object: a quad lamp, a triangle lamp and a sphere lamp of three colours,
 * with a dark block, placed three times (rotated; stretched; mirrored and scaled). Its
 * emitting triangles are lights under each instance (LIGHT_INSTANCED), and its sphere
 * under the two similarities; the stretched one is copied, its sphere a mesh light, as
 * the shapes written out make it. So the scene renders the same mean as the shapes
 * written out within noise, with as many lights. */
#define LAMP_SHAPES                                                                                        \
    "  AttributeBegin AreaLightSource \"diffuse\" \"rgb L\" [5 4 3]\n"                                      \
    "    Shape \"trianglemesh\" \"point3 P\" [-0.4 1.5 -0.4 0.4 1.5 -0.4 0.4 1.5 0.4 -0.4 1.5 0.4]\n"         \
    "      \"integer indices\" [0 2 1 0 3 2] AttributeEnd\n"                                                 \
    "  AttributeBegin AreaLightSource \"diffuse\" \"rgb L\" [1 3 6]\n"                                      \
    "    Shape \"trianglemesh\" \"point3 P\" [0.6 0.2 0 1.1 0.2 0 0.8 0.9 0] AttributeEnd\n"                 \
    "  AttributeBegin AreaLightSource \"diffuse\" \"rgb L\" [2 5 2]\n"                                      \
    "    Translate -0.8 0.4 0 Shape \"sphere\" \"float radius\" 0.15 AttributeEnd\n"                         \
    "  Material \"diffuse\" \"rgb reflectance\" [0.6 0.6 0.3]\n"                                            \
    "  Shape \"trianglemesh\" \"point3 P\" [-0.5 0 -0.5 0.5 0 -0.5 0.5 1 0.5 -0.5 1 0.5]\n"                \
    "    \"integer indices\" [0 1 2 0 2 3]\n"
#define LAMP_A "Translate 2.4 0 0 Rotate 30 0 1 0"
#define LAMP_B "Translate -2.4 0 0.5 Scale 1 1.4 0.7"
#define LAMP_C "Translate 0 0 -2 Scale -1.2 1.2 1.2"
#define PLACE_LAMP(xf) "AttributeBegin " xf " ObjectInstance \"lamp\" AttributeEnd\n"
#define COPY_LAMP(xf) "AttributeBegin " xf "\n" LAMP_SHAPES "AttributeEnd\n"
static const char lamp_inst[] = INST_HEAD "ObjectBegin \"lamp\"\n" LAMP_SHAPES "ObjectEnd\n" PLACE_LAMP(LAMP_A)
    PLACE_LAMP(LAMP_B) PLACE_LAMP(LAMP_C);
static const char lamp_copy[] = INST_HEAD COPY_LAMP(LAMP_A) COPY_LAMP(LAMP_B) COPY_LAMP(LAMP_C);

/* The instanced lamps: an object, two instances and a copy, with its warning; the same mean as the copies
 * within noise; PoCL renders them bit for bit as the scalar device; --stats counts the
 * instances and their lights. */
static void test_instanced_emitters(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_MSG(load_text(lamp_inst, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_objects, 1);
    CHECK_EQ_INT(s.n_instances, 2);
    CHECK_EQ_INT(s.n_warnings, 1);
    scene_free(&s);
    Film a, b, c;
    CHECK_MSG(render_text(lamp_inst, "scalar", &a, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_text(lamp_copy, "scalar", &b, &err) == ST_OK, "%s", err.msg);
    if (a.sum && b.sum) {
        double ma = film_mean(&a), mb = film_mean(&b);
        fprintf(stderr, "  instanced lamps: mean %.6f, written out %.6f (%.2f%%)\n", ma, mb, 100.0 * (ma - mb) / mb);
        CHECK(fabs(ma - mb) < 0.01 * mb);
    }
    if (b.sum) film_free(&b);
    Status sc = render_text(lamp_inst, TEST_OPENCL, &c, &err);
    CHECK_MSG(sc == ST_OK, "%s", err.msg);
    if (!sc && a.sum) {
        size_t n = (size_t)a.width * a.height * 3u, same = film_sums_same(&a, &c);
        fprintf(stderr, "  instanced lamps: %zu of %zu channel sums identical on OpenCL and scalar\n", same, n);
        CHECK(same == n);
        film_free(&c);
    }
    if (a.sum) film_free(&a);

    char scene[64];
    write_temp(scene, sizeof scene, ".pbrt", lamp_inst);
    CliResult r;
    cli_run((const char *[]){ scene, "-q", "--device", "scalar", "--spp", "1", "--stats", "-o",
                              CLPT_BUILD_DIR "/test-pbrt-lamp.pfm", NULL }, &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_STR_CONTAINS(r.out, "instances: 2 of 1 objects; triangles: 3982 unique (5 in objects), 10 instanced");
    /* as many lights as the copies make: each instance's quad, triangle and sphere */
    const char *lights = strstr(r.out, " materials, ");
    unlink(scene);
    write_temp(scene, sizeof scene, ".pbrt", lamp_copy);
    CliResult rc;
    cli_run((const char *[]){ scene, "-q", "--device", "scalar", "--spp", "1", "--stats", "-o",
                              CLPT_BUILD_DIR "/test-pbrt-lamp.pfm", NULL }, &rc);
    CHECK_EQ_INT(rc.status, 0);
    const char *copy_lights = strstr(rc.out, " materials, ");
    CHECK(lights && copy_lights && atoi(lights + 12) == atoi(copy_lights + 12) && atoi(lights + 12) > 9);
    if (lights && copy_lights)
        fprintf(stderr, "  instanced lamps: %d lights, written out %d\n", atoi(lights + 12), atoi(copy_lights + 12));
    unlink(scene);
    unlink(CLPT_BUILD_DIR "/test-pbrt-lamp.pfm");
}

/* pbrt's camera space is left-handed: seen from +z with y up, world +x is on the left. */
static void test_orientation(void)
{
    static const char text[] = "LookAt 0 0 5  0 0 0  0 1 0\n"
                               "Camera \"perspective\" \"float fov\" 40\n"
                               "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 8\n"
                               "Sampler \"independent\" \"integer pixelsamples\" 1\n"
                               "WorldBegin\n"
                               "AreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ]\n"
                               "Translate 1 0 0\n"
                               "Shape \"sphere\" \"float radius\" 0.5\n";
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text(text, &s, &err), ST_OK);
    Film f;
    if (render_util_run(&s, "scalar", 0, &f, &err) == ST_OK) {
        float rgb[16 * 8 * 3];
        film_resolve(&f, rgb);
        double left = 0, right = 0;
        for (int y = 0; y < 8; y++)
            for (int x = 0; x < 16; x++) *(x < 8 ? &left : &right) += rgb[(y * 16 + x) * 3];
        CHECK(left > 0 && right == 0);
        film_free(&f);
    } else {
        CHECK_MSG(0, "%s", err.msg);
    }
    scene_free(&s);
}

/* Sum of the triangles' areas from `first`, and how many face +z (or outward from the
 * z axis when `radial`) by their winding. */
static double mesh_area(const Scene *s, size_t first, int radial, size_t *facing)
{
    double area = 0;
    *facing = 0;
    for (size_t i = first; i < s->n_triangles; i++) {
        const Triangle *t = &s->triangles[i];
        vec3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0);
        vec3 w = v3(e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x);
        area += 0.5 * sqrt((double)w.x * w.x + (double)w.y * w.y + (double)w.z * w.z);
        vec3 c = v3_add(v3_add(t->p0, t->p1), t->p2);
        double side = radial ? (double)w.x * c.x + (double)w.y * c.y : (double)w.z;
        if (side > 0) (*facing)++;
    }
    return area;
}

/* pbrt's disk and cylinder become meshes of 64 segments a turn on pbrt's side:
 * areas of the 64-gon (and of its band), ReverseOrientation turning them over, a
 * partial annulus staying inside its radii and angle, and bad sizes refused. */
static void test_disk_cylinder(void)
{
    const double polygon = 64.0 / 2.0 * sin(2 * M_PI / 64.0) / M_PI;   /* 64-gon area / circle's */
    Scene s;
    Error err = { 0 };
    size_t facing;
    CHECK_EQ_INT(load_text("Shape \"disk\" \"float radius\" 2 \"float height\" 0.5\n", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 64);
    CHECK_NEAR(mesh_area(&s, 0, 0, &facing), polygon * M_PI * 4, 1e-4);
    CHECK_EQ_INT(facing, 64);
    for (size_t i = 0; i < s.n_triangles; i++) CHECK_NEAR(s.triangles[i].p0.z, 0.5, 1e-7);
    scene_free(&s);
    CHECK_EQ_INT(load_text("ReverseOrientation\nShape \"disk\"\n", &s, &err), ST_OK);
    mesh_area(&s, 0, 0, &facing);
    CHECK_EQ_INT(facing, 0);
    scene_free(&s);
    /* half an annulus: 32 segments, two triangles each */
    CHECK_EQ_INT(load_text("Shape \"disk\" \"float radius\" 2 \"float innerradius\" 1 \"float phimax\" 180\n", &s,
                           &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 64);
    CHECK_NEAR(mesh_area(&s, 0, 0, &facing), polygon * M_PI * (4 - 1) / 2, 1e-4);
    CHECK_EQ_INT(facing, 64);
    for (size_t i = 0; i < s.n_triangles; i++) {
        const vec3 q[3] = { s.triangles[i].p0, s.triangles[i].p1, s.triangles[i].p2 };
        for (int c = 0; c < 3; c++) {
            double r = sqrt((double)q[c].x * q[c].x + (double)q[c].y * q[c].y);
            CHECK(r > 1 - 1e-6 && r < 2 + 1e-6 && q[c].y > -1e-6);
        }
    }
    scene_free(&s);
    /* zmin and zmax in either order; the side faces outward */
    CHECK_EQ_INT(load_text("Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" 1 \"float zmax\" -1\n", &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_triangles, 128);
    CHECK_NEAR(mesh_area(&s, 0, 1, &facing), 64 * 2 * 0.5 * sin(M_PI / 64) * 2, 1e-4);
    CHECK_EQ_INT(facing, 128);
    scene_free(&s);
    /* a disk lamp (killeroo-coated-gold's) emits toward +z, or away when reversed */
    for (int reverse = 0; reverse < 2; reverse++) {
        char text[512];
        snprintf(text, sizeof text,
                 "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n"
                 "Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n"
                 "Sampler \"independent\" \"integer pixelsamples\" 1\nWorldBegin\n%s"
                 "AreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ]\nShape \"disk\" \"float radius\" 1\n",
                 reverse ? "ReverseOrientation\n" : "");
        CHECK_EQ_INT(load_text(text, &s, &err), ST_OK);
        Film f;
        if (render_util_run(&s, "scalar", 0, &f, &err) == ST_OK) {
            float rgb[8 * 8 * 3];
            film_resolve(&f, rgb);
            CHECK_MSG(reverse ? rgb[(4 * 8 + 4) * 3] == 0.0f : rgb[(4 * 8 + 4) * 3] == 1.0f, "%s disk: centre %g",
                      reverse ? "reversed" : "plain", (double)rgb[(4 * 8 + 4) * 3]);
            film_free(&f);
        } else {
            CHECK_MSG(0, "%s", err.msg);
        }
        scene_free(&s);
    }
    expect_error("Shape \"cylinder\" \"float zmin\" 1 \"float zmax\" 1",
                 DIR "inline.pbrt:1:7: the cylinder's zmin and zmax are equal: it has no side");
    expect_error("Shape \"disk\" \"float radius\" 1 \"float innerradius\" 1",
                 DIR "inline.pbrt:1:31: parameter 'innerradius' must be in [0, radius)");
    expect_error("Shape \"disk\" \"float phimax\" 0",
                 DIR "inline.pbrt:1:14: parameter 'phimax' must be in (0, 360]");
}

/* compare.pbrt and compare.scene describe one scene: the same image, bit for bit. */
static void test_compare(void)
{
    Scene a, b;
    Error err = { 0 };
    CHECK_EQ_INT(load(DIR "compare.pbrt", &a, &err), ST_OK);
    scene_init(&b);
    CHECK_EQ_INT(scene_load_file(DIR "compare.scene", SCENE_FORMAT_AUTO, &b, NULL, &err), ST_OK);
    CHECK(!a.camera.mirror_x);
    Film fa, fb;
    Status sa = render_util_run(&a, "scalar", 0, &fa, &err);
    Status sb = render_util_run(&b, "scalar", 0, &fb, &err);
    CHECK_EQ_INT(sa, ST_OK);
    CHECK_EQ_INT(sb, ST_OK);
    if (!sa && !sb) {
        size_t n = (size_t)fa.width * fa.height * 3;
        CHECK_EQ_INT(fa.width, 40);
        CHECK(fa.width == fb.width && fa.height == fb.height && memcmp(fa.sum, fb.sum, n * sizeof *fa.sum) == 0);
        CHECK(film_mean(&fa) > 0.05);
    }
    if (!sa) film_free(&fa);
    if (!sb) film_free(&fb);
    scene_free(&a);
    scene_free(&b);
}

static void expect_error(const char *text, const char *msg)
{
    Scene s;
    Error err = { 0 };
    Status st = load_text(text, &s, &err);
    CHECK_EQ_INT(st, ST_INPUT);
    CHECK_MSG(strcmp(err.msg, msg) == 0, "got '%s', expected '%s'", err.msg, msg);
    scene_free(&s);
}

/* MakeNamedMedium "homogeneous" (sigma_a, sigma_s, scale, g), MediumInterface (one name
 * for both sides, or inside and outside; "" vacuum) kept by AttributeBegin/End, the
 * camera in the outside medium at Camera, shapes bound to the media of the moment. */
static void test_media(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 0.2 0.3]\n"
                           "  \"rgb sigma_s\" [1 2 3] \"float scale\" 2 \"float g\" 0.5\n"
                           "MakeNamedMedium \"smoke\" \"string type\" \"homogeneous\"\n"
                           "MediumInterface \"\" \"fog\"\n"
                           "Camera \"perspective\"\n"
                           "WorldBegin\n"
                           "AttributeBegin\n"
                           "  MediumInterface \"smoke\" \"fog\"\n"
                           "  Material \"interface\"\n"
                           "  Shape \"sphere\" \"float radius\" 1\n"
                           "  MediumInterface \"fog\"\n"
                           "  Shape \"sphere\" \"float radius\" 0.5\n"
                           "AttributeEnd\n"
                           "Shape \"sphere\" \"float radius\" 2\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_media, 2);
    CHECK_EQ_INT(s.n_spheres, 3);
    if (s.n_media == 2 && s.n_spheres == 3) {
        CHECK_V3(s.media[0].sigma_a, 0.2, 0.4, 0.6, 1e-7);
        CHECK_V3(s.media[0].sigma_s, 2, 4, 6, 0);
        CHECK_NEAR(s.media[0].g, 0.5, 0);
        CHECK_V3(s.media[1].sigma_a, 1, 1, 1, 0);   /* pbrt-v4's defaults */
        CHECK_V3(s.media[1].sigma_s, 1, 1, 1, 0);
        CHECK_EQ_INT(s.camera_medium, 1);           /* the outside one at Camera: fog */
        const Material *m0 = &s.materials[s.spheres[0].material], *m1 = &s.materials[s.spheres[1].material],
                       *m2 = &s.materials[s.spheres[2].material];
        CHECK(m0->flags & MAT_INTERFACE);
        CHECK_EQ_INT(m0->medium_in, 2);
        CHECK_EQ_INT(m0->medium_out, 1);
        CHECK_EQ_INT(m1->medium_in, m1->medium_out);   /* fog on both sides: no boundary */
        CHECK(!(m2->flags & MAT_INTERFACE));           /* the default material, restored state */
        CHECK_EQ_INT(m2->medium_in, 0);
        CHECK_EQ_INT(m2->medium_out, 1);
    }
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    expect_error("WorldBegin\nMediumInterface \"haze\"\n",
                 DIR "inline.pbrt:2:17: medium 'haze' is not defined (MakeNamedMedium defines it)");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"string preset\" \"Wholemilk\"\n",
                 DIR "inline.pbrt:2:65: MakeNamedMedium \"m\": the preset \"Wholemilk\" is not supported (give \"rgb sigma_a\" and "
                 "\"rgb sigma_s\" instead)");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float g\" 1\n",
                 DIR "inline.pbrt:2:49: parameter 'g' must be a number in (-1, 1)");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [-1 0 0]\n",
                 DIR "inline.pbrt:2:49: parameter 'sigma_a' must be an rgb colour >= 0");
}

/* Media emission: a homogeneous medium's "Le" times its "Lescale" (a float), a
 * uniformgrid's "Le" and its "Lescale" grid (a value per cell, as the density). */
static void test_media_emission(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("MakeNamedMedium \"glow\" \"string type\" \"homogeneous\" \"rgb Le\" [1 2 3]\n"
                           "  \"float Lescale\" 2\n"
                           "MakeNamedMedium \"dark\" \"string type\" \"homogeneous\"\n"
                           "MakeNamedMedium \"fire\" \"string type\" \"uniformgrid\" \"rgb Le\" [4 2 1]\n"
                           "  \"integer nx\" 2 \"float density\" [1 0.5] \"float Lescale\" [0 3]\n"
                           "WorldBegin\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_media, 3);
    CHECK_EQ_INT(s.n_grids, 1);
    if (s.n_media == 3 && s.n_grids == 1) {
        CHECK_V3(s.media[0].emission, 2, 4, 6, 0);
        CHECK(s.media[0].flags & MEDIUM_EMISSIVE);
        CHECK_V3(s.media[1].emission, 0, 0, 0, 0);
        CHECK(!(s.media[1].flags & MEDIUM_EMISSIVE));
        CHECK_V3(s.media[2].emission, 4, 2, 1, 0);
        const GridMedium *g = &s.grids[0];
        CHECK(g->emission_at != 0u);
        CHECK_NEAR(s.grid_data[g->emission_at + 0], 0, 0);
        CHECK_NEAR(s.grid_data[g->emission_at + 1], 3, 0);
    }
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb Le\" [1 -1 0]\n",
                 DIR "inline.pbrt:2:49: parameter 'Le' must be an rgb colour >= 0");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb Le\" [1 1 1] "
                 "\"float Lescale\" -1\n",
                 DIR "inline.pbrt:2:66: parameter 'Lescale' must be a number in [0, 1e30]");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"rgb Le\" [1 1 1] "
                 "\"integer nx\" 2 \"float density\" [1 1] \"float Lescale\" [1]\n",
                 DIR "inline.pbrt:2:103: MakeNamedMedium \"m\": nx ny nz 2 1 1 are 2 cells, but \"Lescale\" has 1 "
                 "values");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"rgb Le\" [1 1 1] "
                 "\"float density\" [1] \"float Lescale\" [-2]\n",
                 DIR "inline.pbrt:2:86: MakeNamedMedium \"m\": Lescale -2 (value 0) must be a finite number >= 0");
    /* Le times sigma_a is a float, but not times the grid's largest Lescale */
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"rgb Le\" [1 1 1] "
                 "\"rgb sigma_a\" [1e10 1 1] \"integer nx\" 2 \"float density\" [1 1] \"float Lescale\" [1 1e30]\n",
                 DIR "inline.pbrt:2:17: MakeNamedMedium \"m\": its Lescale grid's 1e+30 (value 1), times Le and "
                 "sigma_a or times the largest density, is beyond the largest float (about 3.4e38)");
}

/* A uniformgrid's "temperature" grid (pbrt-v4's GridMedium): each cell's blackbody,
 * T = (value - temperatureoffset) * temperaturescale per cell, then a table of colours
 * up to the hottest (pbrt's BlackbodySpectrum, peak 1); the medium's emission 1 1 1
 * times the "Lescale" grid when given; "temperaturecutoff" is the offset's older name. */
static void test_grid_temperature(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("MakeNamedMedium \"fire\" \"string type\" \"uniformgrid\" \"integer nx\" 3\n"
                           "  \"float density\" [1 1 1] \"float temperature\" [20 1100 2900]\n"
                           "  \"float temperatureoffset\" 100 \"float temperaturescale\" 2 \"float Lescale\" [1 2 3]\n"
                           "MakeNamedMedium \"old\" \"string type\" \"uniformgrid\" \"float density\" [1]\n"
                           "  \"float temperature\" [1600] \"float temperaturecutoff\" 100\n"
                           "WorldBegin\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_grids, 2);
    if (s.n_media == 2 && s.n_grids == 2) {
        BlackbodyTable t;
        blackbody_table_init(&t);
        vec3 k2000 = blackbody_rgb_peak_normalised(&t, 2000.0), k5600 = blackbody_rgb_peak_normalised(&t, 5600.0);
        CHECK_V3(s.media[0].emission, 1, 1, 1, 0);
        CHECK(s.media[0].flags & MEDIUM_EMISSIVE);
        const GridMedium *g = &s.grids[0];
        CHECK(g->temperature_at != 0u && g->emission_at != 0u);
        /* kelvin per cell: (20 - 100) 2 (at or below 100 K: no glow), 2000, 5600 */
        const float *kelvin = s.grid_data + g->temperature_at;
        CHECK_V3(v3(kelvin[0], kelvin[1], kelvin[2]), -160, 2000, 5600, 0);
        /* the table runs to the hottest: its last step is 5600 K */
        CHECK_NEAR(kelvin[3], (GRID_BLACKBODY_STEPS - 1u) / 5600.0f, 0);
        const float *top = kelvin + 4 + 3 * (GRID_BLACKBODY_STEPS - 1u);
        CHECK_V3(v3(top[0], top[1], top[2]), k5600.x, k5600.y, k5600.z, 0);
        CHECK_V3(v3(kelvin[4], kelvin[5], kelvin[6]), 0, 0, 0, 0);
        CHECK_NEAR(s.grid_data[g->emission_at + 2], 3, 0);
        const float *old = s.grid_data + s.grids[1].temperature_at;
        CHECK_NEAR(old[0], 1500, 0);
        /* a blackbody reddens as it cools: red above green above blue */
        CHECK(k2000.x > k2000.y && k2000.y > k2000.z && k2000.x > 0.0f);
    }
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1] "
                 "\"float temperature\" [1000] \"float temperaturescale\" -1\n",
                 DIR "inline.pbrt:2:96: parameter 'temperaturescale' must be a number in [0, 1e30]");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 2 "
                 "\"float density\" [1 1] \"float temperature\" [1000]\n",
                 DIR "inline.pbrt:2:86: MakeNamedMedium \"m\": nx ny nz 2 1 1 are 2 cells, but \"temperature\" has 1 "
                 "values");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1] "
                 "\"float temperature\" [-5]\n",
                 DIR "inline.pbrt:2:69: MakeNamedMedium \"m\": temperature -5 (value 0) must be a finite number >= 0");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1] "
                 "\"float temperature\" [1e39]\n",
                 DIR "inline.pbrt:2:90: expected a finite number, found '1e39'");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1] "
                 "\"float temperature\" [1000] \"float temperatureoffset\" 1e31\n",
                 DIR "inline.pbrt:2:96: parameter 'temperatureoffset' must be a number in [-1e30, 1e30]");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1] "
                 "\"float temperature\" [1000] \"rgb Le\" [1 1 1]\n",
                 DIR "inline.pbrt:2:96: MakeNamedMedium \"m\": a \"uniformgrid\" has \"Le\" or \"temperature\", not "
                 "both");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1] "
                 "\"float temperature\" [1000] \"rgb sigma_a\" [1e10 1 1] \"float Lescale\" [1e30]\n",
                 DIR "inline.pbrt:2:17: MakeNamedMedium \"m\": its emission (Lescale times sigma_a and a blackbody's "
                 "colour, up to 256) is beyond the largest float (about 3.4e38)");
}

/* MakeNamedMedium "uniformgrid": the density grid (x fastest) over p0 p1 placed by the
 * current transform, sigma_a and sigma_s times scale per unit of density. */
static void test_uniform_grid(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("Translate 1 0 0\n"
                           "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"rgb sigma_a\" [0.5 0.5 0.5]\n"
                           "  \"rgb sigma_s\" [1 2 3] \"float scale\" 2 \"float g\" 0.3\n"
                           "  \"integer nx\" 2 \"integer ny\" 1 \"integer nz\" 1 \"float density\" [0.25 4]\n"
                           "  \"point3 p0\" [0 0 0] \"point3 p1\" [2 1 1]\n"
                           "WorldBegin\n",
                           &s, &err),
                 ST_OK);
    CHECK_EQ_INT(s.n_media, 1);
    CHECK_EQ_INT(s.n_grids, 1);
    if (s.n_media == 1 && s.n_grids == 1) {
        CHECK_EQ_INT(s.media[0].type, MEDIUM_GRID);
        CHECK_V3(s.media[0].sigma_a, 1, 1, 1, 0);
        CHECK_V3(s.media[0].sigma_s, 2, 4, 6, 0);
        const GridMedium *g = &s.grids[0];
        CHECK_EQ_INT(g->nx, 2);
        CHECK_EQ_INT(g->nz, 1);
        CHECK_NEAR(s.grid_data[g->density_at + 1], 4, 0);
        CHECK_NEAR(g->max_density, 4, 0);
        /* world x = 1 is the box's x = 0; world x = 3 its x = 1 (unit cube) */
        CHECK_NEAR(g->to_grid[0] * 3.0f + g->to_grid[3], 1.0, 1e-6);
        CHECK_NEAR(g->to_grid[0] * 1.0f + g->to_grid[3], 0.0, 1e-6);
    }
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 2 "
                 "\"float density\" [1 2 3]\n",
                 DIR "inline.pbrt:2:64: MakeNamedMedium \"m\": nx ny nz 2 1 1 are 2 cells, but \"density\" has 3 "
                 "values");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [-1]\n",
                 DIR "inline.pbrt:2:49: MakeNamedMedium \"m\": density -1 (value 0) must be a finite number >= 0");
    expect_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [1] "
                 "\"point3 p0\" [0 0 0] \"point3 p1\" [1 0 1]\n",
                 DIR "inline.pbrt:2:17: MakeNamedMedium \"m\": p1 must be greater than p0 on every axis, found p0 0 0 "
                 "0, p1 1 0 1");
}

static void test_errors(void)
{
    expect_error("Shape \"sphere\" \"float radius\" [ 1 ",
                 DIR "inline.pbrt:1:35: expected ']' to close the values of \"float radius\" opened at line 1, "
                 "found end of file");
    expect_error("Shape \"sphere\" \"flot radius\" 1",
                 DIR "inline.pbrt:1:16: unknown parameter type 'flot' (float, integer, bool, string, texture, "
                 "point2, vector2, point3, vector3, normal, rgb, spectrum, blackbody)");
    expect_error("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 3 ]",
                 DIR "inline.pbrt:1:55: 'indices' value 2 is 3, outside the 3 points of 'P'");
    expect_error("Material \"diffuse\" \"rgb reflectance\" [ 1 1 ]",
                 DIR "inline.pbrt:1:20: parameter \"rgb reflectance\" needs 3 numbers, has 2 values");
    expect_error("Shape \"sphere\" \"float radius\" -1",
                 DIR "inline.pbrt:1:16: parameter 'radius' must be > 0");
    expect_error("Shapes \"sphere\"",
                 DIR "inline.pbrt:1:1: expected a pbrt directive (Shape, Material, LightSource, "
                 "AttributeBegin, ...), found 'Shapes'");
    expect_error("AttributeEnd", DIR "inline.pbrt:1:1: AttributeEnd without a matching begin");
    expect_error("NamedMaterial \"gold\"",
                 DIR "inline.pbrt:1:15: material 'gold' is used by NamedMaterial and never defined "
                 "(MakeNamedMaterial defines it)");
    expect_error("WorldBegin\nCamera \"perspective\"", DIR "inline.pbrt:2:1: Camera must come before WorldBegin");
    expect_error("Translate 1 x 3", DIR "inline.pbrt:1:13: expected a number (Translate x y z), found 'x'");
    expect_error("Shape \"sphere\" \"float radius\" nan",
                 DIR "inline.pbrt:1:31: expected a finite number, found 'nan'");
    expect_error("Shape \"sphere\" \"float radius\" 1e39",
                 DIR "inline.pbrt:1:31: expected a finite number, found '1e39'");
}

/* the octahedron's corners: valence 4, Warren's beta 3/32 (as pbrt), gamma
 * 1 / (4 + 3 / (8 beta)) = 1/8; a corner's limit is (1 - 4/8) of the way out (its four
 * neighbours sum to zero) */
static const double octa_p[] = { 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1 };
static const uint32_t octa_i[] = { 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5 };

/* Issue 39: 2000 squashed spheres (a 62 KB file) became 8.2 million triangles and 1.5 GB.
 * They stay analytic: 2000 spheres with 2000 transforms, 256 KB. An emitting ellipsoid
 * is still a mesh (its light needs one) and counts against the tessellation budget; an
 * instance's sphere under a squashing transform is an ellipsoid too. */
static void test_squashed_spheres(void)
{
    size_t cap = 128 * 2000 + 256, len = 0;
    char *text = malloc(cap);
    for (int i = 0; i < 2000; i++)
        len += (size_t)snprintf(text + len, cap - len, "AttributeBegin Translate %d %d 0 Rotate %d 1 1 0 "
                                "Scale 1 0.3 2 Shape \"sphere\" \"float radius\" 0.4 AttributeEnd\n",
                                i % 50, i / 50, i % 360);
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text(text, &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_spheres, 2000);
    CHECK_EQ_INT(s.n_sphere_xforms, 2000);
    CHECK_EQ_INT(s.n_triangles, 0);
    if (s.n_spheres == 2000) CHECK_EQ_INT(s.spheres[1999].xform, 2000);
    scene_free(&s);
    free(text);

    static const char lamp[] = "AttributeBegin AreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ]\n"
                               "Scale 1 0.5 1 Shape \"sphere\" AttributeEnd\n";
    CHECK_EQ_INT(load_text(lamp, &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_spheres, 0);
    CHECK_EQ_INT(s.n_triangles, 64 * 32 * 2 - 2 * 64);
    scene_free(&s);

    static const char inst[] = "ObjectBegin \"o\" Scale 1 1 3 Shape \"sphere\" Translate 5 0 0 Shape \"sphere\" "
                               "ObjectEnd\n"
                               "ObjectInstance \"o\"\n"
                               "AttributeBegin Scale 2 1 1 ObjectInstance \"o\" AttributeEnd\n";
    CHECK_EQ_INT(load_text(inst, &s, &err), ST_OK);
    /* the object keeps its two ellipsoids; its instances' copies compose the transforms */
    CHECK_EQ_INT(s.n_spheres, 2);
    CHECK_EQ_INT(s.n_instances, 2);
    CHECK_EQ_INT(scene_flatten_instances(&s, &err), ST_OK);
    CHECK_EQ_INT(s.n_spheres, 4);
    CHECK_EQ_INT(s.n_sphere_xforms, 4);
    if (s.n_sphere_xforms == 4 && s.n_spheres == 4) {
        /* the second instance: Scale 2 1 1 . Scale 1 1 3 . Translate 5 0 0 */
        const float *m = s.sphere_xforms[s.spheres[3].xform - 1].to_world;
        CHECK_NEAR(m[0], 2, 0);
        CHECK_NEAR(m[3], 10, 0);
        CHECK_NEAR(m[10], 3, 0);
    }
    scene_free(&s);
}

static void test_loop_limits(void)
{
    Error err = { 0 };
    for (int levels = 0; levels <= 4; levels++) {
        SubdivMesh m;
        CHECK_EQ_INT(subdiv_loop(octa_p, 6, octa_i, 8, levels, 1u << 20, &m, &err), ST_OK);
        CHECK_EQ_INT(m.n_tris, 8u << (2 * levels));
        for (int v = 0; v < 6; v++)
            for (int c = 0; c < 3; c++) CHECK_NEAR(m.p[3 * v + c], 0.5 * octa_p[3 * v + c], 1e-12);
        /* a corner's normal points straight out */
        CHECK_NEAR(m.n[0], 1, 1e-12);
        subdiv_free(&m);
    }
    /* an irregular closed mesh (a pyramid on a square: valences 3 and 4): the limit
     * point of a control vertex is the same whether found at level 0 or after levels of
     * Loop's rules, which holds only when the even and odd rules are Loop's */
    static const double pyr_p[] = { 0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0, 1, 1, 3 };
    static const uint32_t pyr_i[] = { 0, 2, 1, 0, 3, 2, 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4 };
    SubdivMesh base, deep;
    CHECK_EQ_INT(subdiv_loop(pyr_p, 5, pyr_i, 6, 0, 1u << 20, &base, &err), ST_OK);
    CHECK_EQ_INT(subdiv_loop(pyr_p, 5, pyr_i, 6, 3, 1u << 20, &deep, &err), ST_OK);
    for (int i = 0; i < 15; i++) CHECK_NEAR(deep.p[i], base.p[i], 1e-12);
    /* the apex (valence 4): gamma 1/8, neighbours (0,0,0) (2,0,0) (2,2,0) (0,2,0) */
    CHECK_NEAR(base.p[12], 0.5 * 1 + 4.0 / 8, 1e-12);
    CHECK_NEAR(base.p[14], 0.5 * 3, 1e-12);
    subdiv_free(&base);
    subdiv_free(&deep);
    /* a lone triangle is all boundary: 3/5 of a corner and 1/5 of each neighbour, pbrt's
     * boundary limit rule (the cubic B-spline's own would be 4/6 and 1/6, so on a
     * boundary the limit found after some levels differs from level 0's, in pbrt too) */
    static const double tri_p[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    static const uint32_t tri_i[] = { 0, 1, 2 };
    CHECK_EQ_INT(subdiv_loop(tri_p, 3, tri_i, 1, 0, 1u << 20, &base, &err), ST_OK);
    CHECK_NEAR(base.p[0], 0.2, 1e-12);
    CHECK_NEAR(base.p[1], 0.2, 1e-12);
    CHECK_NEAR(base.p[3], 0.6, 1e-12);
    subdiv_free(&base);
    CHECK_EQ_INT(subdiv_loop(tri_p, 3, tri_i, 1, 11, 1u << 20, &base, &err), ST_INPUT);
    /* the reader counts a loopsubdiv's triangles before it allocates anything, and
     * against one budget for the whole scene: a 4 KB file of 33 such shapes asked for
     * 33 million triangles */
    expect_error("Shape \"loopsubdiv\" \"integer levels\" 11 \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] "
                 "\"integer indices\" [ 0 1 2 ]",
                 DIR "inline.pbrt:1:7: loopsubdiv level 11 is beyond 10 (each level makes four triangles of one: "
                 "level 11 makes 4^11 = 4194304 of each)");
    expect_error("Shape \"loopsubdiv\" \"integer levels\" 9 \"point3 P\" [ 1 0 0 -1 0 0 0 1 0 0 -1 0 0 0 1 0 0 -1 ] "
                 "\"integer indices\" [ 0 2 4 2 1 4 1 3 4 3 0 4 2 0 5 1 2 5 3 1 5 0 3 5 ]",
                 DIR "inline.pbrt:1:7: loopsubdiv to level 9 of 8 triangles makes 2097152 triangles; with the 0 "
                 "tessellated before it that is past the 1058880 a scene of 161 bytes may make (1048576 and 64 per "
                 "byte of its files)");
    {
        /* four of 4^9 triangles fill the budget exactly; the fifth is refused */
        char big[1024];
        size_t len = 0;
        for (int i = 0; i < 5; i++)
            len += (size_t)snprintf(big + len, sizeof big - len, "Shape \"loopsubdiv\" \"integer levels\" 9 "
                                    "\"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 2 ]\n");
        expect_error(big, DIR "inline.pbrt:5:7: loopsubdiv to level 9 of 1 triangles makes 262144 triangles; with "
                     "the 1048576 tessellated before it that is past the 1080256 a scene of 495 bytes may make "
                     "(1048576 and 64 per byte of its files)");
        /* an emitting sphere copied under a transform that is no similarity is a mesh,
         * counted against the same budget at each ObjectInstance */
        char *lamps = malloc(16384);
        size_t m = (size_t)snprintf(lamps, 16384, "ObjectBegin \"b\" AreaLightSource \"diffuse\" \"rgb L\" [1 1 1] "
                                    "Shape \"sphere\" ObjectEnd Scale 1 2 1\n");
        for (int i = 0; i < 600; i++) m += (size_t)snprintf(lamps + m, 16384 - m, "ObjectInstance \"b\"\n");
        /* 449 copies of 3,968 triangles fit 1048576 + 64 x 11495 bytes; the 450th does not */
        expect_error(lamps, DIR "inline.pbrt:451:16: an emitting sphere copied under a transform that is no "
                     "similarity, as a mesh, makes 3968 triangles; with the 1781632 tessellated before it that is past "
                     "the 1784256 a scene of 11495 bytes may make (1048576 and 64 per byte of its files)");
        free(lamps);
        /* a larger file may make more: the same five shapes after 4 KB of comments load */
        char *padded = malloc(8192);
        size_t n = 0;
        while (n < 4096) n += (size_t)snprintf(padded + n, 8192 - n, "# a large scene's other lines\n");
        snprintf(padded + n, 8192 - n, "%s", big);
        Scene s5;
        Error e5 = { 0 };
        CHECK_EQ_INT(load_text(padded, &s5, &e5), ST_OK);
        CHECK_EQ_INT(s5.n_triangles, 5 << 18);
        scene_free(&s5);
        error_clear(&e5);
        free(padded);
    }
    CHECK(strstr(err.msg, "makes more than 1048576 triangles") != NULL);
    /* through the reader: 8 * 4^2 triangles, the corners at their limits */
    static const char text[] = "Shape \"loopsubdiv\" \"integer levels\" 2\n"
                               "  \"point3 P\" [ 1 0 0 -1 0 0 0 1 0 0 -1 0 0 0 1 0 0 -1 ]\n"
                               "  \"integer indices\" [ 0 2 4 2 1 4 1 3 4 3 0 4 2 0 5 1 2 5 3 1 5 0 3 5 ]\n";
    Scene s;
    CHECK_EQ_INT(load_text(text, &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_triangles, 128);
    vec3 lo, hi;
    mesh_bounds(&s, 0, s.n_triangles, &lo, &hi);
    CHECK_NEAR(hi.x, 0.5, 1e-6);
    CHECK_NEAR(lo.z, -0.5, 1e-6);
    CHECK(s.n_shading == 128);
    scene_free(&s);
}

/* A floor of mix(black, white) under a white sky, seen from above: each hit is white
 * with probability amount, and a white diffuse floor under a sky of 1 sends back exactly
 * 1 (one bounce, cosine sampled, to the sky), so the image's mean is the fraction of
 * hits that chose white. */
static double mix_floor_mean(const char *amount, const char *device, Film *keep)
{
    char text[1024];
    snprintf(text, sizeof text,
             "LookAt 0 5 0  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" 30\n"
             "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n"
             "Sampler \"sobol\" \"integer pixelsamples\" 64\nIntegrator \"path\" \"integer maxdepth\" 1\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n"
             "Texture \"half\" \"float\" \"constant\" \"float value\" 0.5\n"
             "MakeNamedMaterial \"black\" \"string type\" \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
             "MakeNamedMaterial \"white\" \"string type\" \"diffuse\" \"rgb reflectance\" [1 1 1]\n"
             "Material \"mix\" \"string materials\" [\"black\" \"white\"] %s\n"
             "Shape \"bilinearmesh\" \"point3 P\" [-9 0 -9  9 0 -9  -9 0 9  9 0 9]\n", amount);
    Scene s;
    Error err = { 0 };
    double mean = -1;
    CHECK_EQ_INT(load_text(text, &s, &err), ST_OK);
    Film f;
    if (render_util_run(&s, device, 0, &f, &err) == ST_OK) {
        mean = film_mean(&f);
        if (keep) *keep = f; else film_free(&f);
    } else {
        CHECK_MSG(0, "%s", err.msg);
    }
    scene_free(&s);
    return mean;
}

/* pbrt's mix picks one material per hit (kernels/material/mix.h): amount 0 and 1 are the first
 * and second exactly, 0.5 (a float or a float texture) half of each on average, and
 * the choice is the same on PoCL and the scalar device. */
static void test_mix(void)
{
    CHECK_NEAR(mix_floor_mean("\"float amount\" 0", "scalar", NULL), 0, 0);
    CHECK_NEAR(mix_floor_mean("\"float amount\" 1", "scalar", NULL), 1, 1e-6);
    double half = mix_floor_mean("\"float amount\" 0.5", "scalar", NULL);
    double quarter = mix_floor_mean("\"float amount\" 0.25", "scalar", NULL);
    double tex = mix_floor_mean("\"texture amount\" \"half\"", "scalar", NULL);
    fprintf(stderr, "  mix means: 0.5 -> %.4f, 0.25 -> %.4f, texture 0.5 -> %.4f (16x16 px, 64 spp)\n", half,
            quarter, tex);
    /* 16384 coins: the binomial's sigma is 0.0039 at 0.5 */
    CHECK_NEAR(half, 0.5, 0.02);
    CHECK_NEAR(quarter, 0.25, 0.02);
    CHECK_NEAR(tex, 0.5, 0.02);
    Film a, b;
    if (mix_floor_mean("\"float amount\" 0.5", "scalar", &a) >= 0) {
        if (mix_floor_mean("\"float amount\" 0.5", TEST_OPENCL, &b) >= 0) {
            CHECK(memcmp(a.sum, b.sum, (size_t)a.width * a.height * 3 * sizeof *a.sum) == 0);
            film_free(&b);
        }
        film_free(&a);
    }

    /* mix.pbrt (mixes with a texture amount, nested, under an area light): PoCL and
     * scalar agree bit for bit */
    Scene m;
    Error err = { 0 };
    CHECK_EQ_INT(load(DIR "mix.pbrt", &m, &err), ST_OK);
    CHECK_EQ_INT(m.n_warnings, 0);
    /* the path tracer, the classic one (which resolves mixes too), its albedo image */
    static const uint integrators[] = { INTEGRATOR_PATH, INTEGRATOR_WHITTED, INTEGRATOR_AOV_ALBEDO };
    for (size_t i = 0; i < sizeof integrators / sizeof integrators[0]; i++) {
        m.integrator = integrators[i];
        if (render_util_run(&m, "scalar", 0, &a, &err) == ST_OK) {
            if (render_util_run(&m, TEST_OPENCL, 0, &b, &err) == ST_OK) {
                CHECK_MSG(memcmp(a.sum, b.sum, (size_t)a.width * a.height * 3 * sizeof *a.sum) == 0,
                          "integrator %u", integrators[i]);
                CHECK(film_mean(&a) > 0.01);
                film_free(&b);
            }
            film_free(&a);
        }
    }
    scene_free(&m);

    /* nesting: mixes of mixes resolve, up to MIX_MAX_DEPTH; one deeper is refused */
    char text[4096];
    size_t n = (size_t)snprintf(text, sizeof text, "MakeNamedMaterial \"m0\" \"string type\" \"diffuse\"\n");
    for (int i = 1; i <= (int)MIX_MAX_DEPTH + 1; i++)
        n += (size_t)snprintf(text + n, sizeof text - n,
                              "MakeNamedMaterial \"m%d\" \"string type\" \"mix\" \"string materials\" [\"m0\" \"m%d\"]\n",
                              i, i - 1);
    expect_error(text, DIR "inline.pbrt:10:38: mix materials nest more than 8 deep");
    expect_error("Material \"mix\" \"string materials\" [\"a\" \"b\"]",
                 DIR "inline.pbrt:1:36: material 'a' is not defined (MakeNamedMaterial defines it)");
    expect_error("Material \"mix\" \"string materials\" \"a\"",
                 DIR "inline.pbrt:1:10: a mix material needs \"string materials\" with two names");
}

/* The equal-area octahedral map (octa_env.c): its known points and a round trip both
 * ways over the sphere and the square. */
static void test_octa_mapping(void)
{
    static const struct { double d[3], u, v; } known[] = {
        { { 0, 0, 1 }, 0.5, 0.5 }, { { 1, 0, 0 }, 1, 0.5 }, { { -1, 0, 0 }, 0, 0.5 },
        { { 0, 1, 0 }, 0.5, 1 },   { { 0, -1, 0 }, 0.5, 0 }, { { 0, 0, -1 }, 1, 1 },
    };
    for (size_t i = 0; i < sizeof known / sizeof known[0]; i++) {
        double u, v, d[3];
        octa_sphere_to_square(known[i].d, &u, &v);
        CHECK_NEAR(u, known[i].u, 1e-12);
        CHECK_NEAR(v, known[i].v, 1e-12);
        octa_square_to_sphere(known[i].u, known[i].v, d);
        for (int c = 0; c < 3; c++) CHECK_NEAR(d[c], known[i].d[c], 1e-12);
    }
    double worst_d = 0, worst_uv = 0;
    uint32_t h = 12345;
    for (int i = 0; i < 100000; i++) {
        double r[3];
        for (int c = 0; c < 3; c++) {
            h = h * 1664525u + 1013904223u;
            r[c] = (h >> 8) / 16777216.0;
        }
        /* a uniform direction, and a uniform square point */
        double z = 2 * r[0] - 1, phi = 2 * M_PI * r[1], s = sqrt(1 - z * z);
        double d[3] = { s * cos(phi), s * sin(phi), z }, back[3], u, v, u2, v2;
        octa_sphere_to_square(d, &u, &v);
        octa_square_to_sphere(u, v, back);
        for (int c = 0; c < 3; c++) worst_d = fmax(worst_d, fabs(back[c] - d[c]));
        octa_square_to_sphere(r[1], r[2], back);
        octa_sphere_to_square(back, &u2, &v2);
        worst_uv = fmax(worst_uv, fmax(fabs(u2 - r[1]), fabs(v2 - r[2])));
        CHECK_NEAR(back[0] * back[0] + back[1] * back[1] + back[2] * back[2], 1, 1e-12);
    }
    CHECK(worst_d < 1e-5);
    CHECK(worst_uv < 1e-5);
    fprintf(stderr, "  octahedral round trips over 100000 points: %.2g (sphere), %.2g (square)\n", worst_d, worst_uv);
    /* equal area: as many uniform directions land in each quarter of the square's centre
     * diamond as in each corner triangle (each 1/8 of the sphere) */
    int in_diamond = 0;
    for (int i = 0; i < 80000; i++) {
        double r[2];
        for (int c = 0; c < 2; c++) {
            h = h * 1664525u + 1013904223u;
            r[c] = (h >> 8) / 16777216.0;
        }
        double z = 2 * r[0] - 1, phi = 2 * M_PI * r[1], s = sqrt(1 - z * z), d[3] = { s * cos(phi), s * sin(phi), z };
        double u, v;
        octa_sphere_to_square(d, &u, &v);
        in_diamond += fabs(u - 0.5) + fabs(v - 0.5) < 0.5;
    }
    CHECK_NEAR(in_diamond / 80000.0, 0.5, 0.01);
}

/* A pbrt infinite light with a map: an n x n octahedral square bright (10) within 20
 * degrees of light-space +z, written as an EXR, turned by `xf` into the world. Returns
 * the resampled map's brightness-weighted mean direction (world), or (0, 0, 0). */
static vec3 octa_bright_direction(const char *xf, Scene *s)
{
    enum { N = 32 };
    static float rgb[N * N * 3];
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            double d[3];
            octa_square_to_sphere((x + 0.5) / N, (y + 0.5) / N, d);
            for (int c = 0; c < 3; c++) rgb[3 * (y * N + x) + c] = d[2] > cos(20 * M_PI / 180) ? 10.0f : 0.0f;
        }
    Error err = { 0 };
    CHECK_EQ_INT(image_write_encoded(CLPT_BUILD_DIR "/test-pbrt-octa.exr", rgb, N, N,
                                     IMAGE_LINEAR | IMAGE_EXR_FLOAT, &err), ST_OK);
    char text[512];
    snprintf(text, sizeof text, "WorldBegin\n%s\nLightSource \"infinite\" \"string filename\" \"%s\" "
             "\"float scale\" 2\n", xf, "../../../" CLPT_BUILD_DIR "/test-pbrt-octa.exr");
    vec3 mean = v3(0, 0, 0);
    if (load_text(text, s, &err) != ST_OK) {
        CHECK_MSG(0, "%s", err.msg);
        return mean;
    }
    CHECK_EQ_INT(s->bg_type, BG_MAP);
    const Texture *t = &s->textures[s->bg_cubemap];
    CHECK_EQ_INT(t->width, 2 * OCTA_ENV_MIN_HEIGHT);
    CHECK_EQ_INT(t->height, OCTA_ENV_MIN_HEIGHT);
    CHECK_NEAR(s->bg_color.x, 2, 0);   /* the scale */
    const float *px = (const float *)(s->texels + t->offset);
    double sum = 0, max = 0;
    for (uint j = 0; j < t->height; j++)
        for (uint i = 0; i < t->width; i++) {
            double th = M_PI * (j + 0.5) / t->height, ph = 2 * M_PI * (i + 0.5) / t->width;
            double w = px[3 * (j * t->width + i)] * sin(th);   /* a texel's solid angle ~ sin(theta) */
            mean = v3_add(mean, v3_scale(v3((float)(sin(th) * sin(ph)), (float)cos(th), (float)(-sin(th) * cos(ph))),
                                         (float)w));
            sum += w;
            max = fmax(max, px[3 * (j * t->width + i)]);
        }
    CHECK_NEAR(max, 10, 1e-5);
    return sum > 0 ? v3_scale(mean, (float)(1 / sum)) : mean;
}

static void test_infinite_map(void)
{
    Scene s;
    /* pbrt's usual "Rotate -90 1 0 0": light-space +z (the map's centre) is world +y */
    vec3 d = octa_bright_direction("Rotate -90 1 0 0", &s);
    scene_free(&s);
    vec3 n = v3_norm(d);
    fprintf(stderr, "  bright cap: Rotate -90 1 0 0 -> (%.3f %.3f %.3f)\n", n.x, n.y, n.z);
    CHECK_V3(n, 0, 1, 0, 2e-3);
    CHECK(v3_len(d) > 0.9);   /* a cap of 20 degrees: mean cos 0.97 */
    d = v3_norm(octa_bright_direction("Rotate 90 0 1 0", &s));
    scene_free(&s);
    CHECK_V3(d, 1, 0, 0, 2e-3);
    d = v3_norm(octa_bright_direction("Rotate 90 0 1 0 Rotate -45 1 0 0", &s));
    scene_free(&s);
    CHECK_V3(d, sqrt(0.5), sqrt(0.5), 0, 2e-3);

    /* rendered: a white floor under the cap (turned to +y) sends back E / pi, E the
     * square's irradiance on +z (each of its texels spans 4 pi / N^2 steradians) */
    double E = 0;
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            double w[3];
            octa_square_to_sphere((x + 0.5) / 32, (y + 0.5) / 32, w);
            if (w[2] > cos(20 * M_PI / 180)) E += 10 * w[2] * 4 * M_PI / (32 * 32);
        }
    static const char floor_scene[] =
        "LookAt 0 5 0  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" 30\n"
        "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n"
        "Sampler \"sobol\" \"integer pixelsamples\" 64\nWorldBegin\nAttributeBegin\nRotate -90 1 0 0\n"
        "LightSource \"infinite\" \"string filename\" \"../../../" CLPT_BUILD_DIR "/test-pbrt-octa.exr\"\n"
        "AttributeEnd\nMaterial \"diffuse\" \"rgb reflectance\" [1 1 1]\n"
        "Shape \"bilinearmesh\" \"point3 P\" [-9 0 -9  9 0 -9  -9 0 9  9 0 9]\n";
    Error err = { 0 };
    CHECK_EQ_INT(load_text(floor_scene, &s, &err), ST_OK);
    Film f;
    if (render_util_run(&s, "scalar", 0, &f, &err) == ST_OK) {
        double mean = film_mean(&f);
        fprintf(stderr, "  floor under the cap: %.4f, E / pi = %.4f\n", mean, E / M_PI);
        CHECK_NEAR(mean, E / M_PI, 0.02 * E / M_PI);
        film_free(&f);
    } else {
        CHECK_MSG(0, "%s", err.msg);
    }
    scene_free(&s);

    /* the same map as a file beside its scene */
    CHECK_EQ_INT(load(DIR "envmap.pbrt", &s, &err), ST_OK);
    CHECK_EQ_INT(s.bg_type, BG_MAP);
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    /* illuminance: pbrt-v4's normalisations, pi L for a constant; for a uniform map of 1
     * its sum (2 pi / texels per upper texel x cos) is close to pi / 2 */
    CHECK_EQ_INT(load_text("LightSource \"infinite\" \"rgb L\" [0.5 1 2] \"float illuminance\" 6.2831853", &s, &err),
                 ST_OK);
    CHECK_V3(s.bg_color, 1, 2, 4, 1e-6);
    scene_free(&s);
    static float ones[32 * 32 * 3];
    for (size_t i = 0; i < sizeof ones / sizeof ones[0]; i++) ones[i] = 1;
    CHECK_EQ_INT(image_write_encoded(CLPT_BUILD_DIR "/test-pbrt-ones.exr", ones, 32, 32, IMAGE_LINEAR, &err), ST_OK);
    CHECK_EQ_INT(load_text("LightSource \"infinite\" \"string filename\" \"../../../" CLPT_BUILD_DIR
                           "/test-pbrt-ones.exr\" \"float illuminance\" 1.5707963", &s, &err), ST_OK);
    CHECK_NEAR(s.bg_color.x, 1, 0.01);
    scene_free(&s);

    static float wide[8 * 4 * 3];
    CHECK_EQ_INT(image_write_encoded(CLPT_BUILD_DIR "/test-pbrt-wide.exr", wide, 8, 4, IMAGE_LINEAR, &err), ST_OK);
    expect_error("LightSource \"infinite\" \"string filename\" \"../../../" CLPT_BUILD_DIR "/test-pbrt-wide.exr\"",
                 DIR "inline.pbrt:1:42: the infinite light's map is 8x4; pbrt-v4's maps are square (equal-area "
                 "octahedral)");
    expect_error("LightSource \"infinite\" \"string filename\" \"sky.exr\" \"rgb L\" [1 1 1]",
                 DIR "inline.pbrt:1:13: an infinite light takes \"L\" or \"filename\", not both");
    CHECK_EQ_INT(load_text("LightSource \"infinite\" \"string filename\" \"no-such-sky.exr\"", &s, &err), ST_IO);
    CHECK_MSG(strcmp(err.msg, DIR "inline.pbrt:1:42: cannot open '" DIR "no-such-sky.exr': No such file or "
                     "directory") == 0, "got '%s'", err.msg);
    scene_free(&s);
}

/* Renders `textures` + a diffuse quad over x, y in [-2, 2] (uv = ((x + 1) / 2, (y + 1) / 2))
 * whose reflectance is texture "t", seen from +z by an orthographic camera showing
 * [-1, 1]^2 in 8 x 8 pixels, under a white sky: with one bounce a pixel is exactly its
 * reflectance. Into px (8 x 8 x 3, top row first); 0 on failure. */
static int render_reflectance(const char *textures, float *px)
{
    char text[2048];
    snprintf(text, sizeof text,
             "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"orthographic\"\n"
             "Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n"
             "Sampler \"sobol\" \"integer pixelsamples\" 4\nIntegrator \"path\" \"integer maxdepth\" 1\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n%s\n"
             "Material \"diffuse\" \"texture reflectance\" \"t\"\n"
             "Shape \"bilinearmesh\" \"point3 P\" [-2 -2 0  2 -2 0  -2 2 0  2 2 0]\n"
             "  \"point2 uv\" [-0.5 -0.5  1.5 -0.5  -0.5 1.5  1.5 1.5]\n", textures);
    Scene s;
    Error err = { 0 };
    int ok = 0;
    if (load_text(text, &s, &err) == ST_OK) {
        Film f;
        if (render_util_run(&s, "scalar", 0, &f, &err) == ST_OK) {
            film_resolve(&f, px);
            film_free(&f);
            ok = 1;
        }
    }
    if (!ok) CHECK_MSG(0, "%s", err.msg);
    scene_free(&s);
    return ok;
}

/* The four quadrants' grey (the image's left is world +x: pbrt's camera). */
static void check_quadrants(const float *px, double top_left, double top_right, double bottom_left,
                            double bottom_right)
{
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            double want = y < 4 ? (x < 4 ? top_left : top_right) : (x < 4 ? bottom_left : bottom_right);
            for (int c = 0; c < 3; c++) CHECK_NEAR(px[3 * (y * 8 + x) + c], want, 1e-5);
        }
}

/* Texture "checkerboard" and "scale": tex1 where pbrt puts it (the cell at the origin of
 * texture space, and every cell whose integer coordinates sum to an even number), in
 * 2D on (u, v) with uscale/vscale/udelta/vdelta and in 3D in the texture's own space;
 * scale folds into a checkerboard's colours, a constant, or an image's copied texels. */
static void test_checkerboard_scale(void)
{
    float px[8 * 8 * 3];
    /* 2D: cell (0, 0) is x, y in [-1, 0): the bottom right of the image */
    if (render_reflectance("Texture \"t\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 2 "
                           "\"rgb tex1\" [0.2 0.2 0.2] \"rgb tex2\" [0.8 0.8 0.8]", px))
        check_quadrants(px, 0.2, 0.8, 0.8, 0.2);
    /* udelta 1 moves every cell by one: the colours swap */
    if (render_reflectance("Texture \"t\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 2 "
                           "\"float udelta\" 1 \"rgb tex1\" [0.2 0.2 0.2] \"rgb tex2\" [0.8 0.8 0.8]", px))
        check_quadrants(px, 0.8, 0.2, 0.2, 0.8);
    /* 3D, moved up half a cell in z so the surface (looked up 1e-4 behind itself) lies
     * in cells with z index 0: the cell x, y in [0, 1) is tex1, the top left */
    if (render_reflectance("AttributeBegin\nTranslate 0 0 -0.5\n"
                           "Texture \"t\" \"spectrum\" \"checkerboard\" \"integer dimension\" 3 "
                           "\"rgb tex1\" [0.2 0.2 0.2] \"rgb tex2\" [0.8 0.8 0.8]\nAttributeEnd", px))
        check_quadrants(px, 0.2, 0.8, 0.8, 0.2);
    /* a constant texture as tex2, the defaults (tex1 1), and a scale of it by 0.5 */
    if (render_reflectance("Texture \"k\" \"float\" \"constant\" \"float value\" 0.6\n"
                           "Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 2 "
                           "\"texture tex2\" \"k\"\n"
                           "Texture \"t\" \"spectrum\" \"scale\" \"texture tex\" \"c\" \"float scale\" 0.5", px))
        check_quadrants(px, 0.5, 0.3, 0.3, 0.5);
    /* two constants: one constant; a scale texture given as the scale */
    if (render_reflectance("Texture \"k\" \"float\" \"constant\" \"float value\" 0.5\n"
                           "Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 2\n"
                           "Texture \"t\" \"spectrum\" \"scale\" \"rgb tex\" [0.5 0.5 0.5] \"texture scale\" \"c\"",
                           px))
        check_quadrants(px, 0.5, 0, 0, 0.5);

    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("Texture \"k\" \"spectrum\" \"scale\" \"rgb tex\" [0.5 0.25 1] \"float scale\" 0.5\n"
                           "Material \"diffuse\" \"texture reflectance\" \"k\"\nShape \"sphere\"", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_textures, 0);
    if (s.n_spheres == 1) CHECK_V3(s.materials[s.spheres[0].material].albedo, 0.25, 0.125, 0.5, 0);
    scene_free(&s);
    /* an image times 2: a float copy of its texels, doubled */
    CHECK_EQ_INT(load_text("Texture \"i\" \"spectrum\" \"imagemap\" \"string filename\" \"tiny.png\"\n"
                           "Texture \"k\" \"spectrum\" \"scale\" \"texture tex\" \"i\" \"float scale\" 2\n",
                           &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_textures, 2);
    if (s.n_textures == 2) {
        const Texture *a = &s.textures[0], *b = &s.textures[1];
        CHECK(b->flags & TEX_FLOAT);
        CHECK(a->width == b->width && a->height == b->height);
        uint c = s.texels[a->offset];
        float f[3];
        memcpy(f, s.texels + b->offset, sizeof f);
        for (int k = 0; k < 3; k++)
            CHECK_NEAR(f[k], 2 * k_srgb_to_linear((float)((c >> (8 * k)) & 255u) / 255.0f), 1e-6);
    }
    scene_free(&s);
    /* a texture as a checkerboard's colour: its mean, with a warning */
    CHECK_EQ_INT(load_text("Texture \"i\" \"spectrum\" \"imagemap\" \"string filename\" \"tiny.png\"\n"
                           "Texture \"c\" \"spectrum\" \"checkerboard\" \"texture tex1\" \"i\"\n", &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_warnings, 1);
    if (s.n_warnings == 1)
        CHECK_MSG(strcmp(s.warnings[0], DIR "inline.pbrt:2: a checkerboard's \"tex1\" is a texture: its mean colour "
                         "is used") == 0, "got '%s'", s.warnings[0]);
    scene_free(&s);
    /* pbrt-v4's wrap: repeat is clpt's own, clamp its clamp to the edge, black a warning */
    CHECK_EQ_INT(load_text("Texture \"r\" \"spectrum\" \"imagemap\" \"string filename\" \"tiny.png\" "
                           "\"string wrap\" \"repeat\"\n"
                           "Texture \"c\" \"spectrum\" \"imagemap\" \"string filename\" \"tiny.png\" "
                           "\"string wrap\" \"clamp\"\n"
                           "Texture \"b\" \"spectrum\" \"imagemap\" \"string filename\" \"tiny.png\" "
                           "\"string wrap\" \"black\"\n",
                           &s, &err), ST_OK);
    CHECK_EQ_INT(s.n_textures, 3);
    if (s.n_textures == 3) {
        CHECK_EQ_INT(s.textures[0].flags & TEX_CLAMP, 0);
        CHECK_EQ_INT(s.textures[1].flags & TEX_CLAMP, TEX_CLAMP);
        CHECK_EQ_INT(s.textures[2].flags & TEX_CLAMP, 0);
    }
    CHECK_EQ_INT(s.n_warnings, 1);
    if (s.n_warnings == 1)
        CHECK_MSG(strcmp(s.warnings[0], DIR "inline.pbrt:3: texture wrap \"black\" is not supported; repeat is "
                         "used") == 0, "got '%s'", s.warnings[0]);
    scene_free(&s);
    expect_error("Texture \"c\" \"float\" \"checkerboard\" \"integer dimension\" 4",
                 DIR "inline.pbrt:1:36: parameter 'dimension' must be 2 or 3");
    expect_error("Texture \"c\" \"float\" \"scale\" \"texture tex\" \"nope\"",
                 DIR "inline.pbrt:1:43: texture 'nope' is not defined");
}

/* The first pixel of a PFM file (bottom row first, as PFM stores it; a uniform image
 * makes that moot), or -1s when the file cannot be read. */
static void pfm_first_pixel(const char *path, float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = -1;
    FILE *f = fopen(path, "rb");
    if (!f) return;
    int w, h;
    double scale;
    if (fscanf(f, "PF %d %d %lf", &w, &h, &scale) == 3 && fgetc(f) == '\n' && fread(rgb, 4, 3, f) == 3) {
    }
    fclose(f);
}

/* Film "filename" is the output without -o (relative to the current folder, as pbrt
 * writes it, not to the scene's); with -o, -o wins; a name clpt cannot write is an error
 * at the name. */
static void test_film_filename(void)
{
    static const char out[] = CLPT_BUILD_DIR "/test-pbrt-film.pfm";
    char scene[64], text[512];
    snprintf(text, sizeof text,
             "Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 3 \"string filename\" \"%s\"\n"
             "Sampler \"sobol\" \"integer pixelsamples\" 1\nWorldBegin\n"
             "LightSource \"infinite\" \"rgb L\" [0.25 0.5 1]\n", out);
    write_temp(scene, sizeof scene, ".pbrt", text);
    unlink(out);
    CliResult r;
    cli_run((const char *[]){ scene, "-q", "--device", "scalar", NULL }, &r);
    CHECK_EQ_INT(r.status, 0);
    float px[3];
    pfm_first_pixel(out, px);
    CHECK_NEAR(px[0], 0.25, 1e-6);
    CHECK_NEAR(px[1], 0.5, 1e-6);
    CHECK_NEAR(px[2], 1.0, 1e-6);
    /* -o wins */
    unlink(out);
    cli_run((const char *[]){ scene, "-q", "--device", "scalar", "-o", TEST_TMP("clpt-test-film-o.pfm"), NULL },
            &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK(file_exists(TEST_TMP("clpt-test-film-o.pfm")));
    CHECK(!file_exists(out));
    unlink(TEST_TMP("clpt-test-film-o.pfm"));
    unlink(scene);

    expect_error("Film \"rgb\" \"string filename\" \"render.tga\"\n",
                 DIR "inline.pbrt:1:30: Film \"filename\" 'render.tga' is not an image clpt writes (.png, .ppm, "
                 ".bmp, .pfm, .exr, .hdr)");
    Scene s;
    Error err = { 0 };
    CHECK_EQ_INT(load_text("Film \"rgb\" \"string filename\" \"a.EXR\"\n", &s, &err), ST_OK);
    CHECK(s.output_hint && strcmp(s.output_hint, "a.EXR") == 0);
    scene_free(&s);
}

int main(void)
{
    RUN(test_film_filename);
    RUN(test_mix);
    RUN(test_octa_mapping);
    RUN(test_infinite_map);
    RUN(test_checkerboard_scale);
    RUN(test_loop_limits);
    RUN(test_squashed_spheres);
    RUN(test_detect);
    RUN(test_basic);
    RUN(test_transforms);
    RUN(test_materials_lights);
    RUN(test_coated);
    RUN(test_warnings);
    RUN(test_active_transform);
    RUN(test_no_material);
    RUN(test_media);
    RUN(test_uniform_grid);
    RUN(test_media_emission);
    RUN(test_grid_temperature);
    RUN(test_named_material_later);
    RUN(test_include);
    RUN(test_instances);
    RUN(test_orientation);
    RUN(test_disk_cylinder);
    RUN(test_compare);
    RUN(test_instances_render);
    RUN(test_instances_stats);
    RUN(test_instanced_emitters);
    RUN(test_errors);
    RUN(test_gzip);
    RUN(test_load_budget);
    return harness_report();
}
