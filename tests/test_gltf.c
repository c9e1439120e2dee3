/*
 * test_gltf.c — the glTF 2.0 reader (host/io/gltf.c): the hand-made files of
 * tests/data/gltf/ (written by make_gltf.py) load into exactly the triangles, normals,
 * uvs, transforms, cameras, lights and materials they describe; and the three Blender
 * exports of ../shared/models/gltf load and render: the Cornell box against the OBJ
 * Cornell box through the same camera, the material spheres with different highlights,
 * the Suzanne with its embedded checker texture; extras.gltf's TANGENT, TEXCOORD_1,
 * COLOR_0 and sampler through the kernels' shading functions. The bad files are in
 * tests/data/bad/gltf-* (test_bad_input.c). Run from the project root.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "util/kmath.h"
#include "io/gltf.h"
#include "io/mesh_load.h"
#include "io/scene_load.h"
#include "render_util.h"
#include "scene/instance.h"

#include "integrator/shade_path.h"     /* the kernels' shading functions, compiled as C (test_extras) */
#include "accel/alpha.h"

#define DIR_GLTF "tests/data/gltf/"
#define SHARED "../shared/models/"

static void check_v3(vec3 a, double x, double y, double z, double tol)
{
    CHECK_NEAR(a.x, x, tol);
    CHECK_NEAR(a.y, y, tol);
    CHECK_NEAR(a.z, z, tol);
}

/* Loads a glTF file as a mesh (its own materials); 0 when it failed. */
static int load_mesh(const char *path, Scene *s)
{
    scene_init(s);
    Error err = { 0 };
    MeshOptions o = mesh_options(NO_INDEX);
    Status st = mesh_load(path, s, &o, &err);
    CHECK_MSG(st == ST_OK, "%s: %s", path, err.msg);
    error_clear(&err);
    return st == ST_OK;
}

/* One triangle whose material is `material_json`, loaded from memory through the same
 * path as a .gltf file; ST_OK and the scene, or the error. */
static Status load_triangle(const char *material_json, Scene *s, Error *err)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},"
             "\"material\":0}]}],\"materials\":[%s],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
             "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
             "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}",
             material_json);
    scene_init(s);
    return scene_load_bytes("alpha.gltf", text, strlen(text), SCENE_FORMAT_AUTO, s, NULL, err);
}

/* The material of load_triangle's triangle when its material is `json`; NULL (and a
 * failed check) when the file did not load. */
static const Material *triangle_material(const char *json, Scene *s)
{
    Error err = { 0 };
    Status st = load_triangle(json, s, &err);
    CHECK_MSG(st == ST_OK, "%s: %s", json, err.msg);
    error_clear(&err);
    return st == ST_OK ? &s->materials[s->triangles[0].material] : NULL;
}

/* A material the reader refuses, and the message it must give. */
typedef struct {
    const char *json, *msg;
} RefusedMaterial;

/* The material `json` on load_triangle's triangle: refused (ST_INPUT) with `msg` as the
 * whole message when `exact`, else within it. */
static void check_refused(const char *json, const char *msg, int exact)
{
    Scene s;
    Error err = { 0 };
    Status st = load_triangle(json, &s, &err);
    CHECK_EQ_INT(st, ST_INPUT);
    if (exact)
        CHECK_MSG(strcmp(err.msg, msg) == 0, "got '%s'", err.msg);
    else
        CHECK_STR_CONTAINS(err.msg, msg);
    fprintf(stderr, "  %s\n", err.msg);
    error_clear(&err);
    scene_free(&s);
}

/* check_refused for each case's json as the object of the material's extension
 * `extension`, its message within the error's. */
static void check_refused_extension(const char *extension, const RefusedMaterial *cases, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        char json[256];
        snprintf(json, sizeof json, "{\"extensions\":{\"%s\":%s}}", extension, cases[i].json);
        check_refused(json, cases[i].msg, 0);
    }
}

/* KHR_materials_volume, _specular and _sheen map onto the principled material: a volume
 * with thickness > 0 is a solid (no MAT_THIN) with sigma_a = -ln(attenuationColor) /
 * attenuationDistance; thickness 0 stays a thin wall; the specular and sheen factors
 * are copied; the three are no longer warned about as ignored. */
static void test_volume_specular_sheen(void)
{
    Scene s;
    const Material *m = triangle_material("{\"extensions\":{"
                                          "\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
                                          "\"KHR_materials_volume\":{\"thicknessFactor\":0.1,"
                                          "\"attenuationColor\":[0.5,0.25,1],\"attenuationDistance\":2},"
                                          "\"KHR_materials_specular\":{\"specularFactor\":0.3,"
                                          "\"specularColorFactor\":[1,0.5,2]},"
                                          "\"KHR_materials_sheen\":{\"sheenColorFactor\":[0.9,0.8,0.7],"
                                          "\"sheenRoughnessFactor\":0.6}}}", &s);
    if (m) {
        CHECK((m->flags & MAT_THIN) == 0u);
        check_v3(m->absorption, log(2.0) / 2.0, log(4.0) / 2.0, 0.0, 1e-6);
        CHECK_NEAR(m->specular_factor, 0.3, 1e-6);
        check_v3(m->specular_color, 1.0, 0.5, 2.0, 0);
        check_v3(m->sheen_color, 0.9, 0.8, 0.7, 1e-6);
        CHECK_NEAR(m->sheen_roughness, 0.6, 1e-6);
        CHECK(m->texture_specular == NO_INDEX && m->texture_sheen_color == NO_INDEX);
        CHECK_EQ_INT(s.n_warnings, 0);
    }
    scene_free(&s);
    /* thickness 0 (the default): the thin wall of KHR_materials_transmission stays */
    m = triangle_material("{\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
                          "\"KHR_materials_volume\":{\"attenuationColor\":[0.5,0.5,0.5]}}}", &s);
    if (m) {
        CHECK((m->flags & MAT_THIN) != 0u);
        check_v3(m->specular_color, 1.0, 1.0, 1.0, 0);
        CHECK_NEAR(m->specular_factor, 1.0, 0);
    }
    scene_free(&s);
    /* values out of range are errors naming the JSON path */
    check_refused("{\"extensions\":{\"KHR_materials_sheen\":{\"sheenRoughnessFactor\":2}}}",
                  "materials[0].extensions.KHR_materials_sheen.sheenRoughnessFactor: expected a number from 0 to 1", 0);
}

/* KHR_materials_diffuse_transmission onto the principled material: the factor and
 * colour copied, a thin wall unless KHR_materials_volume makes a solid; factors
 * outside [0, 1] and textures naming no texture are errors with the JSON path. */
static void test_diffuse_transmission(void)
{
    Scene s;
    const Material *m = triangle_material("{\"extensions\":{\"KHR_materials_diffuse_transmission\":{"
                                          "\"diffuseTransmissionFactor\":0.75,\"diffuseTransmissionColorFactor\":[1,0.5,0.25]}}}", &s);
    if (m) {
        CHECK((m->flags & MAT_THIN) != 0u);
        CHECK_NEAR(m->diffuse_transmission, 0.75, 0);
        check_v3(m->diffuse_transmission_color, 1.0, 0.5, 0.25, 0);
        CHECK(m->texture_diffuse_transmission == NO_INDEX && m->texture_diffuse_transmission_color == NO_INDEX);
        CHECK_EQ_INT(s.n_warnings, 0);
    }
    scene_free(&s);
    /* with a volume: a solid; without the extension: none, the colour white */
    m = triangle_material("{\"extensions\":{\"KHR_materials_diffuse_transmission\":{\"diffuseTransmissionFactor\":1},"
                          "\"KHR_materials_volume\":{\"thicknessFactor\":0.2}}}", &s);
    if (m) CHECK((m->flags & MAT_THIN) == 0u);
    scene_free(&s);
    m = triangle_material("{}", &s);
    if (m) {
        CHECK(m->diffuse_transmission == 0.0f && (m->flags & MAT_THIN) == 0u);
        check_v3(m->diffuse_transmission_color, 1.0, 1.0, 1.0, 0);
    }
    scene_free(&s);
    static const RefusedMaterial bad[] = {
        { "{\"diffuseTransmissionFactor\":1.5}",
          "alpha.gltf: materials[0].extensions.KHR_materials_diffuse_transmission.diffuseTransmissionFactor: "
          "expected a number from 0 to 1" },
        { "{\"diffuseTransmissionFactor\":-0.1}",
          "alpha.gltf: materials[0].extensions.KHR_materials_diffuse_transmission.diffuseTransmissionFactor: "
          "expected a number from 0 to 1" },
        { "{\"diffuseTransmissionColorFactor\":[1,1.2,1]}",
          "alpha.gltf: materials[0].extensions.KHR_materials_diffuse_transmission.diffuseTransmissionColorFactor[1]: "
          "expected a number from 0 to 1" },
        { "{\"diffuseTransmissionColorFactor\":[1,1]}",
          "alpha.gltf: materials[0].extensions.KHR_materials_diffuse_transmission.diffuseTransmissionColorFactor: "
          "expected an array of 3 numbers" },
        { "{\"diffuseTransmissionTexture\":{\"index\":3}}",
          "alpha.gltf: materials[0].extensions.KHR_materials_diffuse_transmission.diffuseTransmissionTexture.index: textures[3] does not "
          "exist (the file has 0)" },
        { "{\"diffuseTransmissionColorTexture\":{\"index\":-1}}",
          "alpha.gltf: materials[0].extensions.KHR_materials_diffuse_transmission.diffuseTransmissionColorTexture"
          ".index: textures[-1] does not exist (the file has 0)" },
    };
    check_refused_extension("KHR_materials_diffuse_transmission", bad, sizeof bad / sizeof bad[0]);
}

/* KHR_materials_volume_scatter over a volume and a diffuse transmission: a subsurface
 * walk whose weight is the diffuse transmission's share, sigma_t = -ln(c) / d split by
 * the extension's single-scattering albedo (multiscatter 0 gives 0, 1 gives 1, 0.5 gives
 * 1 - (4.09712 + 2.104315 - sqrt(9.59217 + 20.8404 + 4.42815))^2), g copied, no
 * Beer-Lambert absorption left; without what it needs, a warning; bad values, errors. */
static void test_volume_scatter(void)
{
    Scene s;
    const Material *m = triangle_material("{\"name\":\"wax\",\"extensions\":{"
                                          "\"KHR_materials_volume\":{\"thicknessFactor\":1,"
                                          "\"attenuationColor\":[0.5,0.25,0.125],\"attenuationDistance\":2},"
                                          "\"KHR_materials_diffuse_transmission\":{\"diffuseTransmissionFactor\":0.8},"
                                          "\"KHR_materials_volume_scatter\":{\"multiscatterColor\":[0,0.5,1],"
                                          "\"scatterAnisotropy\":0.3}}}", &s);
    if (m) {
        CHECK((m->flags & MAT_THIN) == 0u);
        CHECK_NEAR(m->subsurface, 0.8, 1e-6);
        CHECK(m->diffuse_transmission == 0.0f);
        check_v3(m->absorption, 0.0, 0.0, 0.0, 0);
        CHECK(m->medium_in >= 1u && m->medium_in <= s.n_media);
        if (m->medium_in >= 1u && m->medium_in <= s.n_media) {
            const Medium *md = &s.media[m->medium_in - 1u];
            double r = 4.09712 + 4.20863 * 0.5 - sqrt(9.59217 + 41.6808 * 0.5 + 17.7126 * 0.25), a = 1.0 - r * r;
            double t[3] = { log(2.0) / 2.0, log(4.0) / 2.0, log(8.0) / 2.0 };
            check_v3(md->sigma_s, 0.0, t[1] * a, t[2], 1e-5);
            check_v3(md->sigma_a, t[0], t[1] * (1.0 - a), 0.0, 1e-5);
            CHECK_NEAR(md->g, 0.3, 1e-6);
            fprintf(stderr, "  multiscatter 0.5: single-scattering albedo %.4f\n", a);
        }
        CHECK_EQ_INT(s.n_warnings, 0);
    }
    scene_free(&s);
    /* nothing scatters: a thin wall, no attenuation, no diffuse transmission */
    static const char *const ignored[] = {
        "{\"extensions\":{\"KHR_materials_diffuse_transmission\":{\"diffuseTransmissionFactor\":1},"
        "\"KHR_materials_volume_scatter\":{\"multiscatterColor\":[1,1,1]}}}",
        "{\"extensions\":{\"KHR_materials_volume\":{\"thicknessFactor\":1},"
        "\"KHR_materials_diffuse_transmission\":{\"diffuseTransmissionFactor\":1},"
        "\"KHR_materials_volume_scatter\":{\"multiscatterColor\":[1,1,1]}}}",
        "{\"extensions\":{\"KHR_materials_volume\":{\"thicknessFactor\":1,\"attenuationDistance\":1,"
        "\"attenuationColor\":[0.5,0.5,0.5]},\"KHR_materials_volume_scatter\":{\"multiscatterColor\":[1,1,1]}}}",
    };
    static const char *const why[] = { "KHR_materials_volume with thicknessFactor > 0",
                                        "KHR_materials_volume's attenuationDistance and attenuationColor",
                                        "KHR_materials_diffuse_transmission" };
    for (int i = 0; i < 3; i++) {
        if (triangle_material(ignored[i], &s)) {
            CHECK_EQ_INT(s.n_warnings, 1);
            CHECK_EQ_INT((int)s.n_media, 0);
            char want[200];
            snprintf(want, sizeof want, "alpha.gltf: materials[0].extensions.KHR_materials_volume_scatter: ignored: "
                     "nothing scatters inside without %s", why[i]);
            if (s.n_warnings == 1) CHECK_STR_CONTAINS(s.warnings[0], want);
        }
        scene_free(&s);
    }
    static const RefusedMaterial bad[] = {
        { "{\"multiscatterColor\":[0.5,-0.5,0.5]}",
          "alpha.gltf: materials[0].extensions.KHR_materials_volume_scatter.multiscatterColor[1]: expected a number "
          "from 0 to 1" },
        { "{\"scatterAnisotropy\":1}",
          "alpha.gltf: materials[0].extensions.KHR_materials_volume_scatter.scatterAnisotropy: expected a number "
          "between -1 and 1, both excluded" },
        { "{\"scatterAnisotropy\":-3}",
          "alpha.gltf: materials[0].extensions.KHR_materials_volume_scatter.scatterAnisotropy: expected a number "
          "from -1 to 1" },
    };
    check_refused_extension("KHR_materials_volume_scatter", bad, sizeof bad / sizeof bad[0]);
}

/* alphaMode and alphaCutoff become the principled material's alpha mode (kernels/accel/alpha.h
 * renders them; test_alpha.c checks the pixels); emissiveTexture its emission texture. */
static void test_alpha_modes(void)
{
    static const struct { const char *json; uint flags; float alpha, cutoff; } ok[] = {
        { "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,0.25]}}", 0u, 0.25f, 0.5f },
        { "{\"alphaMode\":\"OPAQUE\"}", 0u, 1.0f, 0.5f },
        { "{\"alphaMode\":\"MASK\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,0.25]}}", MAT_ALPHA_MASK,
          0.25f, 0.5f },
        { "{\"alphaMode\":\"MASK\",\"alphaCutoff\":0.125}", MAT_ALPHA_MASK, 1.0f, 0.125f },
        { "{\"alphaMode\":\"BLEND\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,0.75]}}", MAT_ALPHA_BLEND,
          0.75f, 0.5f },
    };
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        Scene s;
        const Material *m = triangle_material(ok[i].json, &s);
        if (m) {
            CHECK(m->type == MAT_PRINCIPLED);
            CHECK((m->flags & MAT_ALPHA_ANY) == ok[i].flags);
            CHECK(m->alpha == ok[i].alpha);
            CHECK(m->alpha_cutoff == ok[i].cutoff);
            CHECK(m->texture_emission == NO_INDEX);
        }
        scene_free(&s);
    }
    static const RefusedMaterial bad[] = {
        { "{\"alphaMode\":\"CUTOUT\"}", "alpha.gltf: materials[0].alphaMode: expected \"OPAQUE\", \"MASK\" or \"BLEND\"" },
        { "{\"alphaMode\":1}", "alpha.gltf: materials[0].alphaMode: expected \"OPAQUE\", \"MASK\" or \"BLEND\"" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) check_refused(bad[i].json, bad[i].msg, 1);
}

/* KHR_texture_transform's scale of 1e308 is infinite as a float, and its lookups were
 * NaN texel indices (issue 39): refused at load, named by its JSON path. */
static void test_texture_transform_range(void)
{
    static const char *const tex = "],\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"unread.png\"}],"
                                   "\"extensionsUsed\":[\"KHR_texture_transform\"";
    static const struct { const char *scale, *msg; } cases[] = {
        { "[1e308, 1]", "alpha.gltf: materials[0].pbrMetallicRoughness.baseColorTexture.extensions."
                        "KHR_texture_transform: the texture's map has an entry that is not finite as a float: inf "
                        "(row 1, column 1); clpt takes finite entries of at most 16777216 in size" },
        { "[1, 3e7]", "alpha.gltf: materials[0].pbrMetallicRoughness.baseColorTexture.extensions."
                      "KHR_texture_transform: the texture's map has the entry 3e+07 (row 2, column 2); clpt takes "
                      "finite entries of at most 16777216 in size" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char mat[600];
        snprintf(mat, sizeof mat, "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"extensions\":"
                 "{\"KHR_texture_transform\":{\"scale\":%s}}}}}%s", cases[i].scale, tex);
        check_refused(mat, cases[i].msg, 1);
    }
}

/* A glTF document from memory, as a file named `name` in folder `dir` would load
 * (scene_load_bytes, so that the load's budget of input applies). */
static Status load_text(const char *name, const char *text, Scene *s, Error *err)
{
    scene_init(s);
    return scene_load_bytes(name, text, strlen(text), SCENE_FORMAT_AUTO, s, NULL, err);
}

/* The top of a one-node document over buffer 0's first 36 bytes, one triangle, with
 * `rest` after it (buffers, images, materials, more nodes). */
#define ONE_TRIANGLE_DOC                                                                                \
    "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]," \
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","               \
    "\"min\":[0,0,0],\"max\":[1,1,0]}],"

/* Images that share a source decode it once (issue 39: a 20 KB GLB whose hundreds of
 * images named one buffer view decoded each again, 2.1 GB and 20 s): three images on
 * one buffer view and two on one data: URI, in five materials, make two textures of
 * 4 x 4 texels, not five. The buffer: a triangle's corners (36 bytes), then a 4 x 4
 * orange PNG (75 bytes). */
static void test_shared_image_sources(void)
{
    static const char b64[] = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAiVBORw0KGgoAAAANSUhEUgAAAAQAAAAECAYAAACp"
                              "8Z5+AAAAEklEQVR42mP438DwHxkzkC4AAFBPJ+ERcipZAAAAAElFTkSuQmCC";
    static const char png_b64[] = "iVBORw0KGgoAAAANSUhEUgAAAAQAAAAECAYAAACp8Z5+AAAAEklEQVR42mP438DwHxkzkC4AAFBPJ+ERcipZ"
                                  "AAAAAElFTkSuQmCC";
    char text[4096];
    snprintf(text, sizeof text, ONE_TRIANGLE_DOC
             "\"buffers\":[{\"byteLength\":111,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":75}],"
             "\"images\":[{\"bufferView\":1,\"mimeType\":\"image/png\"},{\"bufferView\":1,\"mimeType\":\"image/png\"},"
             "{\"bufferView\":1,\"mimeType\":\"image/png\"},{\"uri\":\"data:image/png;base64,%s\"},"
             "{\"uri\":\"data:image/png;base64,%s\"}],"
             "\"textures\":[{\"source\":0},{\"source\":1},{\"source\":2},{\"source\":3},{\"source\":4}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}},"
             "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":1}}},"
             "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":2}}},"
             "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":3}}},"
             "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":4}}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0},"
             "{\"attributes\":{\"POSITION\":0},\"material\":1},{\"attributes\":{\"POSITION\":0},\"material\":2},"
             "{\"attributes\":{\"POSITION\":0},\"material\":3},{\"attributes\":{\"POSITION\":0},\"material\":4}]}]}",
             b64, png_b64, png_b64);
    Scene s;
    Error err = { 0 };
    CHECK_MSG(load_text("shared.gltf", text, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_textures, 2);
    CHECK_EQ_INT(s.n_texels, 2 * 16);
    CHECK_EQ_INT(s.n_triangles, 5);
    error_clear(&err);
    scene_free(&s);
}

/* Buffers that name one file read it once (issue 39: once per buffer): three buffers
 * on a 64 KiB file load within a budget of input (CLPT_MAX_LOAD_BYTES) that holds two
 * reads of it, not three. */
static void test_shared_buffer_file(void)
{
    char dir[] = "/tmp/clpt-test-gltf-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char bin[96], gltf[96];
    snprintf(bin, sizeof bin, "%s/mesh data.bin", dir);
    snprintf(gltf, sizeof gltf, "%s/shared.gltf", dir);
    FILE *f = fopen(bin, "wb");
    CHECK(f != NULL);
    if (!f) return;
    const float corners[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    fwrite(corners, sizeof corners, 1, f);
    for (int i = 0; i < 65536 - 36; i++) fputc(0, f);
    fclose(f);
    /* "%20" is the file name's space (percent-decoded, as URIs are) */
    f = fopen(gltf, "wb");
    CHECK(f != NULL);
    if (!f) return;
    fprintf(f, ONE_TRIANGLE_DOC "\"bufferViews\":[{\"buffer\":2,\"byteLength\":36}],\"buffers\":["
            "{\"byteLength\":65536,\"uri\":\"mesh%%20data.bin\"},{\"byteLength\":65536,\"uri\":\"mesh%%20data.bin\"},"
            "{\"byteLength\":36,\"uri\":\"./mesh%%20data.bin\"}],"
            "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}");
    fclose(f);
    setenv("CLPT_MAX_LOAD_BYTES", "140000", 1);
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    Status st = scene_load_file(gltf, SCENE_FORMAT_AUTO, &s, NULL, &err);
    unsetenv("CLPT_MAX_LOAD_BYTES");
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_triangles, 1);
    error_clear(&err);
    scene_free(&s);
    unlink(bin);
    unlink(gltf);
    rmdir(dir);
}

/* A strip of 1-byte indices makes a triangle per byte, and each mesh that copies it
 * as many again: a 4 MB strip in 16 nodes made 2^26 triangles (issue 39). A file makes
 * at most 2^20 + one per byte of it and its buffers; the primitive that would pass that
 * is refused before it makes any, named with its node. Here 4096 zero indices (a strip
 * of degenerate triangles, dropped quickly) in 300 meshes of one node each. One mesh
 * in 300 nodes is an object made once and instanced: within the bound. */
static void test_triangle_bound(void)
{
    for (int shared = 0; shared < 2; shared++) {
        size_t idx_b64 = 4096 / 3 * 4 + 4, cap = 160 * 300 + idx_b64 + 4096;
        char *text = malloc(cap);
        CHECK(text != NULL);
        if (!text) return;
        size_t n = (size_t)snprintf(text, cap, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[");
        for (int i = 0; i < 300; i++) n += (size_t)snprintf(text + n, cap - n, "%s%d", i ? "," : "", i);
        n += (size_t)snprintf(text + n, cap - n, "]}],\"nodes\":[");
        for (int i = 0; i < 300; i++) n += (size_t)snprintf(text + n, cap - n, "%s{\"mesh\":%d}", i ? "," : "", shared ? 0 : i);
        n += (size_t)snprintf(text + n, cap - n, "],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,"
                              "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5121,"
                              "\"count\":4096,\"type\":\"SCALAR\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},"
                              "{\"buffer\":1,\"byteLength\":4096}],\"buffers\":[{\"byteLength\":36,\"uri\":\"data:;base64,"
                              "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"},{\"byteLength\":4096,\"uri\":\"data:;base64,");
        for (size_t i = 0; i < 4096 / 3 * 4 + 4; i++) text[n++] = 'A';
        n += (size_t)snprintf(text + n, cap - n, "\"}],\"meshes\":[");
        for (int i = 0; i < (shared ? 1 : 300); i++)
            n += (size_t)snprintf(text + n, cap - n, "%s{\"primitives\":[{\"attributes\":{\"POSITION\":0},"
                                  "\"indices\":1,\"mode\":5}]}", i ? "," : "");
        n += (size_t)snprintf(text + n, cap - n, "]}");
        Scene s;
        Error err = { 0 };
        Status st = load_text("strip.gltf", text, &s, &err);
        if (shared) {
            CHECK_MSG(st == ST_OK, "%s", err.msg);
            CHECK_EQ_INT(s.n_objects, 1);
            scene_free(&s);
            free(text);
            continue;
        }
        CHECK(st == ST_INPUT);
        /* the bound: 2^20 + the 4132 buffer bytes + the document's bytes */
        char msg[400];
        size_t bound = ((size_t)1 << 20) + 4132 + n, per = 4094, node = bound / per;
        snprintf(msg, sizeof msg, "strip.gltf: meshes[%zu].primitives[0] (in nodes[%zu]): its 4094 triangles bring the "
                 "file's to %zu, more than the %zu a file of its size may make (2^20 and one per byte of the file and "
                 "its buffers, at most 2^26; every node's copy counts)", node, node, (node + 1) * per, bound);
        CHECK_MSG(strcmp(err.msg, msg) == 0, "got      '%s'\n  expected '%s'", err.msg, msg);
        error_clear(&err);
        scene_free(&s);
        free(text);
    }
}

/* glTF URIs are RFC 3986's: percent-encoded bytes are decoded (test_shared_buffer_file
 * reads "mesh%20data.bin"), a path may leave the file's folder, and what is not a
 * relative file name is refused, named by its JSON path. */
static void test_uri_policy(void)
{
    static const struct { const char *uri, *msg; } cases[] = {
        { "https://example.com/a.bin", "uri.gltf: buffers[0].uri: the URI's scheme 'https:' is not read (clpt reads "
                                       "data: URIs and file names relative to the glTF file)" },
        { "file:///etc/passwd", "uri.gltf: buffers[0].uri: the URI's scheme 'file:' is not read (clpt reads data: "
                                "URIs and file names relative to the glTF file)" },
        { "/etc/passwd", "uri.gltf: buffers[0].uri: an absolute path (clpt reads data: URIs and file names relative "
                         "to the glTF file)" },
        { "%2Fetc/passwd", "uri.gltf: buffers[0].uri: an absolute path (clpt reads data: URIs and file names "
                           "relative to the glTF file)" },
        { "a%2", "uri.gltf: buffers[0].uri: character 2 of the URI: '%' not followed by two hex digits (a "
                 "percent-encoded byte)" },
        { "a%00.bin", "uri.gltf: buffers[0].uri: character 2 of the URI: %00, a NUL, cannot be part of a file name" },
        { "../no-such-folder-clpt/a%20b.bin", "uri.gltf: buffers[0].uri: cannot open '../no-such-folder-clpt/a "
                                              "b.bin': No such file or directory" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[1024];
        snprintf(text, sizeof text, ONE_TRIANGLE_DOC "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                 "\"buffers\":[{\"byteLength\":36,\"uri\":\"%s\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}", cases[i].uri);
        Scene s;
        Error err = { 0 };
        Status st = load_text("uri.gltf", text, &s, &err);
        CHECK(st == ST_INPUT || st == ST_IO);
        CHECK_MSG(strcmp(err.msg, cases[i].msg) == 0, "%s: got '%s'", cases[i].uri, err.msg);
        error_clear(&err);
        scene_free(&s);
    }
}

/* Winding normal of triangle i, unnormalised. */
static vec3 winding(const Scene *s, size_t i)
{
    const Triangle *t = &s->triangles[i];
    return v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0));
}

static void test_strided(void)
{
    Scene s;
    if (!load_mesh(DIR_GLTF "strided.gltf", &s)) return;
    CHECK_EQ_INT(s.n_triangles, 2);
    CHECK_EQ_INT(s.n_shading, 2);
    if (s.n_triangles == 2 && s.n_shading == 2) {
        check_v3(s.triangles[0].p2, 1, 1, 0, 0);
        check_v3(s.triangles[1].p2, 0, 1, 0, 0);
        const TriShading *sh = &s.shading[s.triangles[0].shading];
        CHECK_EQ_INT(sh->flags, TRI_HAS_NORMALS | TRI_HAS_UV);
        check_v3(sh->n1, 0, 0, 1, 0);
        /* normalized bytes 255 -> 1; glTF's v flipped to clpt's */
        CHECK_NEAR(sh->uv1[0], 1.0, 0);
        CHECK_NEAR(sh->uv1[1], 1.0, 0);
        CHECK_NEAR(sh->uv2[0], 1.0, 0);
        CHECK_NEAR(sh->uv2[1], 0.0, 0);
        CHECK(winding(&s, 0).z > 0 && winding(&s, 1).z > 0);
    }
    scene_free(&s);
}

static void test_sparse(void)
{
    Scene s;
    if (!load_mesh(DIR_GLTF "sparse.gltf", &s)) return;
    CHECK_EQ_INT(s.n_triangles, 2);
    if (s.n_triangles == 2) {
        check_v3(s.triangles[0].p1, 1, 0, 0, 0);     /* normalized short 32767 -> 1 */
        /* the sparse value, normalized shorts as the accessor's */
        check_v3(s.triangles[0].p2, 16384 / 32767.0, 16384 / 32767.0, 8192 / 32767.0, 1e-7);
        check_v3(s.triangles[1].p1, 16384 / 32767.0, 16384 / 32767.0, 8192 / 32767.0, 1e-7);
        check_v3(s.triangles[1].p2, 0, 1, 0, 0);
        CHECK_EQ_INT(s.triangles[0].shading, NO_INDEX);
    }
    scene_free(&s);
}

static void test_strips(void)
{
    Scene s;
    if (!load_mesh(DIR_GLTF "strips.gltf", &s)) return;
    CHECK_EQ_INT(s.n_triangles, 6);
    for (size_t i = 0; i < s.n_triangles; i++) {
        vec3 n = winding(&s, i);
        CHECK_MSG(n.z > 0 && n.x == 0 && n.y == 0, "triangle %zu faces %g %g %g", i, (double)n.x, (double)n.y,
                  (double)n.z);
    }
    if (s.n_triangles == 6) {
        /* strip: (0 1 2), (2 1 3), (2 3 4); fan: (1 2 0), (2 3 0), (3 4 0) */
        check_v3(s.triangles[1].p0, 0, 1, 0, 0);
        check_v3(s.triangles[1].p1, 1, 0, 0, 0);
        check_v3(s.triangles[5].p2, 0, 0, 1, 0);
    }
    scene_free(&s);
}

static void test_glb_and_external(void)
{
    const char *files[] = { DIR_GLTF "triangle.glb", DIR_GLTF "external.gltf" };
    for (int f = 0; f < 2; f++) {
        Scene s;
        harness_current = files[f];
        if (!load_mesh(files[f], &s)) continue;
        CHECK_EQ_INT(s.n_triangles, 1);
        if (s.n_triangles == 1) {
            check_v3(s.triangles[0].p1, 1, 0, 0, 0);
            check_v3(s.triangles[0].p2, 0, 1, 0, 0);
        }
        /* no material in the file: glTF's default, white metallic 1 roughness 1 */
        if (s.n_triangles == 1) {
            const Material *m = &s.materials[s.triangles[0].material];
            CHECK_EQ_INT(m->type, MAT_PRINCIPLED);
            CHECK_NEAR(m->metallic, 1.0, 0);
        }
        scene_free(&s);
    }
}

static void test_textures(void)
{
    Scene s;
    if (!load_mesh(DIR_GLTF "textured.gltf", &s)) return;
    CHECK_EQ_INT(s.n_triangles, 3);
    if (s.n_triangles != 3) {
        scene_free(&s);
        return;
    }
    const Material *tinted = &s.materials[s.triangles[0].material];
    const Material *plain = &s.materials[s.triangles[1].material];
    /* the texture as given: the PNG's texels, sRGB; the same image read linear for the
     * metallic-roughness and normal maps, once */
    CHECK(plain->texture != NO_INDEX && plain->texture_rm != NO_INDEX);
    if (plain->texture == NO_INDEX || plain->texture_rm == NO_INDEX || tinted->texture == NO_INDEX) {
        scene_free(&s);
        return;
    }
    const Texture *t = &s.textures[plain->texture];
    CHECK_EQ_INT(t->flags, TEX_SRGB);
    CHECK_EQ_INT(t->width, 2);
    CHECK_EQ_INT(s.texels[t->offset + 1], 0xffff4000u);   /* (0, 64, 255), alpha 255 */
    CHECK_EQ_INT(s.textures[plain->texture_rm].flags, 0);
    CHECK_EQ_INT(plain->texture_normal, plain->texture_rm);
    CHECK_NEAR(plain->normal_scale, 0.5, 0);
    /* tinted: linear floats, texel x baseColorFactor */
    const Texture *tt = &s.textures[tinted->texture];
    CHECK_EQ_INT(tt->flags, TEX_FLOAT);
    static const float factor[3] = { 0.5f, 1.0f, 0.25f };
    static const unsigned char texel[4][3] = { { 255, 128, 0 }, { 0, 64, 255 }, { 10, 20, 30 }, { 200, 100, 50 } };
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) {
            float v;
            memcpy(&v, &s.texels[tt->offset + 3 * i + k], sizeof v);
            CHECK_NEAR(v, k_srgb_to_linear((float)texel[i][k] / 255.0f) * factor[k], 0);
        }
    /* KHR_texture_transform, rotation pi/2, scale (2, 3), offset (0.5, 0.25): glTF's
     * (u, w) -> (-3 w + 0.5, 2 u + 0.25), and w = 1 - v on both sides, so clpt's
     * (u, v) -> (3 v - 2.5, -2 u + 0.75) */
    const Material *moved = &s.materials[s.triangles[2].material];
    CHECK(moved->texture != NO_INDEX && moved->texture != plain->texture);
    if (moved->texture != NO_INDEX) {
        const float *m = s.textures[moved->texture].m;
        static const double want[8] = { 0, 3, 0, -2.5, -2, 0, 0, 0.75 };
        for (int i = 0; i < 8; i++) CHECK_NEAR(m[i], want[i], 1e-6);
        CHECK_EQ_INT(s.textures[moved->texture].offset, t->offset);   /* the same texels */
    }
    scene_free(&s);
}

/* Loads nodes.gltf as a whole scene with --camera `camera`. */
static Status load_nodes(const char *camera, Scene *s, Error *err)
{
    scene_init(s);
    s->gltf_camera = camera;
    SceneKind kind;
    Status st = scene_load_file(DIR_GLTF "nodes.gltf", SCENE_FORMAT_AUTO, s, &kind, err);
    if (!st) CHECK_EQ_INT(kind, SCENE_KIND_CLPT);   /* its own camera: not framed again */
    return st;
}

static void test_nodes(void)
{
    Scene s;
    Error err = { 0 };
    Status st = load_nodes(NULL, &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st) return;
    /* child scale 2, then the parent's 90 degrees about +y and (10, 0, 0) */
    CHECK_EQ_INT(s.n_triangles, 1);
    if (s.n_triangles == 1) {
        check_v3(s.triangles[0].p0, 10, 0, 0, 1e-6);
        check_v3(s.triangles[0].p1, 10, 0, -2, 1e-6);
        check_v3(s.triangles[0].p2, 10, 2, 0, 1e-6);
    }
    /* the first camera: the node "front" at (0, 0, 5) under the parent */
    CHECK_EQ_INT(s.camera.type, CAMERA_PERSPECTIVE);
    check_v3(s.camera.from, 15, 0, 0, 1e-5);
    check_v3(s.camera.at, 14, 0, 0, 1e-5);
    check_v3(s.camera.up, 0, 1, 0, 1e-6);
    CHECK_NEAR(s.camera.vfov, 0.5 * 180.0 / M_PI, 1e-4);
    CHECK_EQ_INT(s.image.height, s.image.width / 2);   /* aspectRatio 2 */
    /* lights: photometric / 683 */
    CHECK_EQ_INT(s.n_delta_lights, 3);
    if (s.n_delta_lights == 3) {
        const Light *l = s.delta_lights;
        CHECK_EQ_INT(l[0].type, LIGHT_POINT);
        check_v3(l[0].position, 1, 2, 3, 1e-6);
        check_v3(l[0].intensity, 1, 0.5, 0.25, 1e-6);
        CHECK_EQ_INT(l[1].type, LIGHT_DIRECTIONAL);
        check_v3(l[1].direction, 0, -1, 0, 1e-6);
        check_v3(l[1].intensity, 2, 2, 2, 1e-6);
        CHECK_EQ_INT(l[2].type, LIGHT_SPOT);
        check_v3(l[2].direction, 0, 0, -1, 1e-6);
        CHECK_NEAR(l[2].cos_outer, cos(0.5), 1e-6);
        CHECK_NEAR(l[2].cos_inner, cos(0.25), 1e-6);
        CHECK_NEAR(l[2].intensity.x, 0.1, 1e-6);
        /* between the cones, KHR_lights_punctual's reference falloff: the linear ramp in
         * the cosine, squared (not clpt's smoothstep, 1.2-1.9 times brighter there) */
        CHECK_EQ_INT(l[2].spot_falloff, SPOT_GLTF);
        const double angles[5] = { 0.2, 0.3, 0.375, 0.45, 0.55 };
        for (int i = 0; i < 5; i++) {
            double c = cos(angles[i]), ramp = (c - cos(0.5)) / (cos(0.25) - cos(0.5));
            ramp = fmin(fmax(ramp, 0.0), 1.0);
            CHECK_NEAR(spot_falloff(l[2], (float)c), ramp * ramp, 2e-5);
        }
    }
    /* the material with every extension */
    if (s.n_triangles == 1) {
        const Material *m = &s.materials[s.triangles[0].material];
        CHECK_EQ_INT(m->type, MAT_PRINCIPLED);
        check_v3(m->albedo, 0.5, 0.25, 0.125, 0);
        CHECK_NEAR(m->metallic, 0.5, 0);
        CHECK_NEAR(m->roughness, 0.75, 0);
        check_v3(m->emission, 4, 2, 0, 0);
        CHECK_NEAR(m->ior, 1.33, 1e-6);
        CHECK_NEAR(m->transmission, 0.5, 0);
        CHECK_NEAR(m->clearcoat, 0.7, 1e-6);
        CHECK_NEAR(m->clearcoat_roughness, 0.2, 1e-6);
        CHECK_EQ_INT(m->flags, MAT_TWO_SIDED | MAT_THIN);
    }
    /* the unsupported extension only in extensionsUsed: one warning naming it */
    CHECK_EQ_INT(s.n_warnings, 1);
    if (s.n_warnings == 1)
        CHECK_STR_CONTAINS(s.warnings[0], "the extension 'EXT_unknown_thing' (extensionsUsed) is ignored");
    scene_free(&s);

    /* --camera by index, by the camera's name and by its node's name */
    const char *picks[] = { "1", "top", "front" };
    for (int i = 0; i < 3; i++) {
        st = load_nodes(picks[i], &s, &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        if (st == ST_OK && i < 2) {
            CHECK_EQ_INT(s.camera.type, CAMERA_ORTHOGRAPHIC);
            CHECK_NEAR(s.camera.ortho_height, 6.0, 0);
            check_v3(s.camera.from, 0, 10, 0, 1e-6);
            check_v3(s.camera.at, 0, 9, 0, 1e-6);
        } else if (st == ST_OK) {
            check_v3(s.camera.from, 15, 0, 0, 1e-5);
        }
        scene_free(&s);
    }
    st = load_nodes("side", &s, &err);
    CHECK_EQ_INT(st, ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "tests/data/gltf/nodes.gltf: no camera 'side'");
    scene_free(&s);
    error_clear(&err);
}

/* mesh { file "x.gltf" } in clpt's format, with its transform keys. */
static void test_mesh_block(void)
{
    static const char text[] =
        "material m { type diffuse albedo 0.5 0.5 0.5 }\n"
        "mesh { file \"strips.gltf\" scale 2 translate 0 0 5 }\n"
        "mesh { file \"strips.gltf\" material m }\n";
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    Status st = scene_load_text(DIR_GLTF "t.scene", text, strlen(text), &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_triangles, 12);
    if (s.n_triangles == 12) {
        check_v3(s.triangles[1].p0, 0, 2, 5, 0);
        CHECK_EQ_INT(s.materials[s.triangles[0].material].type, MAT_PRINCIPLED);
        CHECK_EQ_INT(s.triangles[6].material, scene_find_material(&s, "m"));
    }
    scene_free(&s);
    error_clear(&err);
}

/* ------------------------------------------------------------------ the Blender files */

typedef struct {
    float *rgb;
    uint w, h;
} Image;

/* Renders the scene on the scalar device at its own (small) size. */
static int render(Scene *s, Image *img)
{
    Film film;
    Error err = { 0 };
    Status st = render_util_run(s, "scalar", 0, &film, &err);
    CHECK_MSG(st == ST_OK, "render: %s", err.msg);
    error_clear(&err);
    if (st) return 0;
    img->w = film.width;
    img->h = film.height;
    img->rgb = malloc((size_t)img->w * img->h * 3u * sizeof *img->rgb);
    film_resolve(&film, img->rgb);
    film_free(&film);
    return 1;
}

static int load_scene(const char *path, Scene *s, uint w, uint h, uint spp)
{
    scene_init(s);
    Error err = { 0 };
    Status st = scene_load_file(path, SCENE_FORMAT_AUTO, s, NULL, &err);
    CHECK_MSG(st == ST_OK, "%s: %s", path, err.msg);
    error_clear(&err);
    s->image.width = w;
    s->image.height = h;
    s->image.spp = spp;
    s->image.max_depth = 4;
    return st == ST_OK;
}

static double rmse(const Image *a, const Image *b)
{
    double sum = 0.0;
    size_t n = (size_t)a->w * a->h * 3u;
    for (size_t i = 0; i < n; i++) {
        double d = fmin(a->rgb[i], 1.0) - fmin(b->rgb[i], 1.0);   /* as 8-bit output clips */
        sum += d * d;
    }
    return sqrt(sum / (double)n);
}

/* The OBJ Cornell box through the glTF's camera, rendered at `seed`. */
static int render_obj_box(const SceneCamera *cam, uint w, uint h, uint seed, Image *img)
{
    static const char text[] = "mesh { file \"cornell-box/CornellBox-Original.obj\" }\n";
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    Status st = scene_load_text(SHARED "box.scene", text, strlen(text), &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    error_clear(&err);
    int ok = 0;
    if (st == ST_OK) {
        s.camera = *cam;
        s.image.width = w;
        s.image.height = h;
        s.image.spp = 16;
        s.image.max_depth = 4;
        s.image.seed = seed;
        ok = render(&s, img);
    }
    scene_free(&s);
    return ok;
}

static void test_cornell_box(void)
{
    const char *path = SHARED "gltf/cornell-box.glb";
    if (!shared_model_present(path, "the glTF Cornell box test") ||
        !shared_model_present(SHARED "cornell-box/CornellBox-Original.obj", "the glTF Cornell box test"))
        return;
    Scene s;
    Image g = { 0 }, o1 = { 0 }, o2 = { 0 };
    if (!load_scene(path, &s, 64, 36, 16)) return;
    CHECK_EQ_INT(s.camera.type, CAMERA_PERSPECTIVE);
    check_v3(s.camera.from, 0, 1, 3.9, 1e-6);
    CHECK_NEAR(s.camera.vfov, 39.3, 0.01);
    SceneCamera cam = s.camera;
    if (render(&s, &g) && render_obj_box(&cam, 64, 36, 1, &o1) && render_obj_box(&cam, 64, 36, 2, &o2)) {
        double d = rmse(&g, &o1), noise = rmse(&o1, &o2);
        fprintf(stderr, "  cornell-box.glb vs CornellBox-Original.obj: RMSE %.4f; OBJ seed 1 vs 2: %.4f\n", d, noise);
        /* the same box up to noise and the principled material's 4% specular layer,
         * which the OBJ's Lambertian walls lack (docs/gltf.md) */
        CHECK_MSG(d < 1.5 * noise, "RMSE %.4f against noise %.4f", d, noise);
    }
    free(g.rgb);
    free(o1.rgb);
    free(o2.rgb);
    scene_free(&s);
}

/* Mean luminance and peak luminance of the pixels within r of (cx, cy). */
static void region_stats(const Image *img, double cx, double cy, double r, double *mean, double *peak)
{
    double sum = 0.0;
    int n = 0;
    *peak = 0.0;
    for (uint y = 0; y < img->h; y++)
        for (uint x = 0; x < img->w; x++) {
            double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
            if (dx * dx + dy * dy > r * r) continue;
            const float *p = img->rgb + 3u * ((size_t)y * img->w + x);
            double l = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            sum += l;
            n++;
            *peak = fmax(*peak, l);
        }
    *mean = n ? sum / n : 0.0;
}

/* Where the pinhole camera sees point p, in pixels, and how many pixels a length r
 * at p spans. */
static void project(const SceneCamera *c, uint w, uint h, vec3 p, double r, double *px, double *py, double *pr)
{
    vec3 f = v3_norm(v3_sub(c->at, c->from));
    vec3 right = v3_norm(v3_cross(f, c->up));
    vec3 up = v3_cross(right, f);
    vec3 d = v3_sub(p, c->from);
    double z = v3_dot(d, f), t = tan(c->vfov * M_PI / 360.0);
    *px = w * 0.5 + v3_dot(d, right) / z / t * h * 0.5;
    *py = h * 0.5 - v3_dot(d, up) / z / t * h * 0.5;
    *pr = r / z / t * h * 0.5;
}

static void test_material_spheres(void)
{
    const char *path = SHARED "gltf/material-spheres.glb";
    if (!shared_model_present(path, "the glTF material spheres test")) return;
    Scene s;
    Image img = { 0 };
    if (!load_scene(path, &s, 160, 90, 32)) return;
    CHECK_EQ_INT(s.n_delta_lights, 2);   /* the sun and the point light */
    if (!render(&s, &img)) {
        scene_free(&s);
        return;
    }
    /* the spheres' centres, by their nodes: x from -2 to 2 by roughness, z 0
     * (metallic 0) and -1 (metallic 1); radius 0.4 */
    double mean[2][5], peak[2][5];
    for (int row = 0; row < 2; row++)
        for (int i = 0; i < 5; i++) {
            double px, py, pr;
            project(&s.camera, img.w, img.h, v3((float)(i - 2), 0.4f, (float)-row), 0.4, &px, &py, &pr);
            region_stats(&img, px, py, 0.8 * pr, &mean[row][i], &peak[row][i]);
        }
    for (int row = 0; row < 2; row++) {
        fprintf(stderr, "  metallic %d, roughness 0..1: mean", row);
        for (int i = 0; i < 5; i++) fprintf(stderr, " %.3f", mean[row][i]);
        fprintf(stderr, "; peak");
        for (int i = 0; i < 5; i++) fprintf(stderr, " %.2f", peak[row][i]);
        fprintf(stderr, "\n");
    }
    /* the smooth spheres mirror the lights as small bright highlights that roughness
     * spreads out and dims (at roughness 0 the sun, a delta light, has no reflection
     * but the point light's, 0.032 wide: the peak is at roughness 0 or 0.25), and
     * neighbours differ */
    for (int row = 0; row < 2; row++) {
        CHECK_MSG(fmax(peak[row][0], peak[row][1]) > 2.0 * peak[row][4], "row %d: peak %.3f / %.3f at roughness "
                  "0 / 0.25, %.3f at 1", row, peak[row][0], peak[row][1], peak[row][4]);
        for (int i = 0; i < 4; i++)
            CHECK_MSG(fabs(mean[row][i] - mean[row][i + 1]) > 0.002 || fabs(peak[row][i] - peak[row][i + 1]) > 0.05,
                      "row %d: spheres %d and %d look the same", row, i, i + 1);
    }
    /* the metals are no red plastic */
    for (int i = 0; i < 5; i++)
        CHECK_MSG(fabs(mean[0][i] - mean[1][i]) > 0.002, "roughness %d: metal and plastic look the same", i);
    free(img.rgb);
    scene_free(&s);
}

static void test_suzanne_texture(void)
{
    const char *path = SHARED "gltf/textured-suzanne.glb";
    if (!shared_model_present(path, "the glTF Suzanne texture test")) return;
    Scene s;
    Image with = { 0 }, without = { 0 };
    if (!load_scene(path, &s, 96, 54, 8)) return;
    uint m = scene_find_material(&s, "checker");
    CHECK(m != NO_INDEX);
    if (m == NO_INDEX) {
        scene_free(&s);
        return;
    }
    uint t = s.materials[m].texture;
    CHECK(t != NO_INDEX && t < s.n_textures);
    if (t != NO_INDEX) {
        /* the 256 x 256 PNG inside the GLB, decoded from memory, sRGB */
        CHECK_EQ_INT(s.textures[t].width, 256);
        CHECK_EQ_INT(s.textures[t].height, 256);
        CHECK_EQ_INT(s.textures[t].flags, TEX_SRGB);
    }
    /* the texture changes the image where the Suzanne is, and only there */
    if (render(&s, &with)) {
        s.materials[m].texture = NO_INDEX;
        if (render(&s, &without)) {
            double d = rmse(&with, &without);
            fprintf(stderr, "  Suzanne with and without its texture: RMSE %.4f\n", d);
            CHECK_MSG(d > 0.02, "the texture changes the image by RMSE %.4f only", d);
        }
    }
    free(with.rgb);
    free(without.rgb);
    scene_free(&s);
}


/* The surface at the centroid of triangle `tri` of the prepared scene, seen from +z. */
static Surface centroid_surface(const SceneView *v, const Scene *s, size_t tri)
{
    const Triangle *t = &s->triangles[tri];
    vec3 c = v3_scale(v3_add(v3_add(t->p0, t->p1), t->p2), 1.0f / 3.0f);
    Ray r;
    r.o = v3_add(c, v3(0.0f, 0.0f, 1.0f));
    r.d = v3(0.0f, 0.0f, -1.0f);
    r.tmin = 0.0f;
    r.tmax = 2.0f;
    Hit h;
    h.t = 1.0f;
    h.prim = (uint)(s->n_spheres + tri);
    h.u = h.v = 1.0f / 3.0f;
    h.inst = NO_INDEX;
    return surface_at(v, r, h);
}

/* extras.gltf (make_gltf.py): three quads of two triangles, 0-1 with TANGENT, 2-3 with
 * TEXCOORD_1, 4-5 with COLOR_0, checked through the kernels' own functions against
 * hand computations, in an albedo image, and PoCL against the scalar device. */
static void test_extras(void)
{
    Scene s;
    if (!load_scene(DIR_GLTF "extras.gltf", &s, 48, 12, 4)) return;
    CHECK_EQ_INT(s.n_triangles, 6);
    CHECK_EQ_INT(s.n_tri_extras, 6);
    CHECK_EQ_INT(s.n_tri_extra_of, s.n_shading);
    if (s.n_triangles != 6 || s.n_tri_extras != 6) {
        scene_free(&s);
        return;
    }
    /* the .glb (buffer and images in its BIN chunk) loads into the same */
    Scene g;
    if (load_scene(DIR_GLTF "extras.glb", &g, 48, 12, 4)) {
        CHECK(g.n_triangles == 6 && memcmp(g.triangles, s.triangles, 6 * sizeof *g.triangles) == 0);
        CHECK(g.n_tri_extras == 6 && memcmp(g.tri_extras, s.tri_extras, 6 * sizeof *g.tri_extras) == 0);
        CHECK(g.n_texels == s.n_texels && memcmp(g.texels, s.texels, s.n_texels * sizeof *s.texels) == 0);
    }
    scene_free(&g);
    const TriExtra *e0 = &s.tri_extras[s.tri_extra_of[s.triangles[0].shading]];
    CHECK_EQ_INT(e0->flags, EXTRA_TANGENT);
    CHECK(e0->tangent[1][0] == 0.0f && e0->tangent[1][1] == 1.0f && e0->tangent[1][3] == 1.0f);
    RenderScene rs;
    Error err = { 0 };
    Status st = render_scene_prepare(&s, 0, &rs, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st) {
        error_clear(&err);
        scene_free(&s);
        return;
    }
    SceneView view;
    device_scene_view(&rs.ds, &view);

    /* TANGENT: the map's texel (255, 128, 255) read linearly is (1, 1/255, 1) in
     * tangent space; with the given tangent t = +y, n = +z and w = 1 the bitangent is
     * n x t = -x, so the normal is (-1/255, 1, 1) normalised. The uvs alone would give
     * t = +x, b = +y: (1, 1/255, 1). */
    Surface sf = centroid_surface(&view, &s, 0);
    Material m = s.materials[sf.material];
    vec3 n = material_normal(&view, m, sf);
    double k = 1.0 / 255.0, len = sqrt(k * k + 2.0);
    check_v3(n, -k / len, 1.0 / len, 1.0 / len, 1e-6);
    /* w = -1 turns the bitangent to +x; a tangent along the normal has no direction
     * across it, so the uvs' frame takes over (the view reads the scene's own arrays) */
    TriExtra *e = &s.tri_extras[sf.extra];
    for (int c = 0; c < 3; c++) e->tangent[c][3] = -1.0f;
    check_v3(material_normal(&view, m, sf), k / len, 1.0 / len, 1.0 / len, 1e-6);
    for (int c = 0; c < 3; c++) {
        e->tangent[c][1] = 0.0f;
        e->tangent[c][2] = 1.0f;
    }
    check_v3(material_normal(&view, m, sf), 1.0 / len, k / len, 1.0 / len, 1e-6);

    /* TEXCOORD_1: the texture reads (0.75, 0.25) of the 2 x 2 image (the top row's right
     * texel, (0, 64, 255) sRGB) where TEXCOORD_0 at the centroid, (2/3, 1/3), would
     * read the bottom row's right one, (200, 100, 50); nearest, so exactly the texel */
    sf = centroid_surface(&view, &s, 2);
    m = s.materials[sf.material];
    CHECK(m.texture != NO_INDEX);
    if (m.texture != NO_INDEX) {
        CHECK_EQ_INT(s.textures[m.texture].flags, TEX_SRGB | TEX_UV1 | TEX_NEAREST | TEX_MIRROR_U | TEX_CLAMP_V);
        vec3 c = texture_eval(&view, m.texture, sf, sf.ng);
        check_v3(c, 0.0, k_srgb_to_linear(64.0f / 255.0f), 1.0, 0.0);
    }

    /* COLOR_0 (255, 128, 64, 191) times baseColorFactor 0.8; its alpha times alpha 1 */
    sf = centroid_surface(&view, &s, 4);
    m = s.materials[sf.material];
    check_v3(material_albedo(&view, m, sf, sf.ng), 0.8 * 1.0, 0.8 * 128.0 / 255.0, 0.8 * 64.0 / 255.0, 1e-6);
    CHECK_NEAR(material_alpha(&view, m, sf), 191.0 / 255.0, 1e-6);
    render_scene_free(&rs);

    /* the albedo image: quad 2's middle (x = 3.5 of the camera's -0.4 .. 4.4) has the
     * colour's ratios */
    Film f;
    s.integrator = INTEGRATOR_AOV_ALBEDO;
    st = render_util_run(&s, "scalar", 0, &f, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) {
        float *rgb = malloc((size_t)f.width * f.height * 3u * sizeof *rgb);
        film_resolve(&f, rgb);
        const float *px = rgb + 3u * (6u * f.width + 39u);
        fprintf(stderr, "  COLOR_0 quad's albedo pixel: %.6f %.6f %.6f\n", px[0], px[1], px[2]);
        CHECK_NEAR(px[0], 0.8, 1e-5);
        CHECK_NEAR(px[1] / px[0], 128.0 / 255.0, 1e-5);
        CHECK_NEAR(px[2] / px[0], 64.0 / 255.0, 1e-5);
        free(rgb);
        film_free(&f);
    }
    error_clear(&err);

    /* the path tracer through all three on PoCL and the scalar device: the same bits */
    s.integrator = INTEGRATOR_PATH;
    Film a, b;
    Status sa = render_util_run(&s, "scalar", 0, &a, &err);
    CHECK_MSG(sa == ST_OK, "%s", err.msg);
    error_clear(&err);
    Status sb = render_util_run(&s, TEST_OPENCL, 0, &b, &err);
    CHECK_MSG(sb == ST_OK, "%s", err.msg);
    error_clear(&err);
    if (sa == ST_OK && sb == ST_OK) {
        size_t nf = (size_t)a.width * a.height * 3u;
        float *ra = malloc(nf * sizeof *ra), *rb = malloc(nf * sizeof *rb);
        film_resolve(&a, ra);
        film_resolve(&b, rb);
        CHECK(memcmp(ra, rb, nf * sizeof *ra) == 0);
        free(ra);
        free(rb);
    }
    if (sa == ST_OK) film_free(&a);
    if (sb == ST_OK) film_free(&b);
    scene_free(&s);
}

/* ------------------------------------------------------------------ instancing */

/* A file rendered small on `devices`; flattened into copies first when `flatten`. */
static Status render_gltf(const char *path, const char *devices, int flatten, Film *f, Error *err)
{
    Scene s;
    scene_init(&s);
    Status st = scene_load_file(path, SCENE_FORMAT_AUTO, &s, NULL, err);
    s.image.width = 48;
    s.image.height = 36;
    s.image.spp = 16;
    s.image.max_depth = 4;
    if (!st && flatten) st = scene_flatten_instances(&s, err);
    if (!st) st = render_util_run(&s, devices, 0, f, err);
    scene_free(&s);
    return st;
}

/* Two renders of one scene whose rays differ by roundings: the same mean within noise. */
static void check_same_scene(const char *what, const char *a_path, int a_flat, const char *b_path, int b_flat)
{
    Film a, b;
    Error err = { 0 };
    Status sa = render_gltf(a_path, "scalar", a_flat, &a, &err);
    CHECK_MSG(sa == ST_OK, "%s", err.msg);
    Status sb = render_gltf(b_path, "scalar", b_flat, &b, &err);
    CHECK_MSG(sb == ST_OK, "%s", err.msg);
    if (!sa && !sb) {
        double ma = film_mean(&a), mb = film_mean(&b);
        size_t n = (size_t)a.width * a.height * 3u, same = film_sums_same(&a, &b);
        fprintf(stderr, "  %s: mean %.6f vs %.6f; %zu of %zu channel sums identical\n", what, ma, mb, same, n);
        CHECK(fabs(ma - mb) < 0.01 * mb);
        CHECK(same > n / 2);
    }
    if (!sa) film_free(&a);
    if (!sb) film_free(&b);
}

/* A mesh in two or more nodes is one object with an instance per node (the node's world
 * matrix; a mirroring parent's too); EXT_mesh_gpu_instancing makes an instance per entry,
 * node . T . R . S; a mesh in one node stays a copy. Each renders as its copies. */
static void test_instancing(void)
{
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    CHECK_MSG(scene_load_file(DIR_GLTF "instancing-reuse.gltf", SCENE_FORMAT_AUTO, &s, NULL, &err) == ST_OK, "%s",
              err.msg);
    CHECK_EQ_INT(s.n_objects, 1);
    CHECK_EQ_INT(s.n_instances, 4);
    CHECK_EQ_INT(s.n_triangles, 14);   /* the floor's 2, the cube's 12 once */
    if (s.n_instances == 4) {
        CHECK(!(s.instances[0].flags & INST_MIRROR) && (s.instances[3].flags & INST_MIRROR));
        const float *m = s.instances[3].to_world;   /* (-1, 1, 1) . (x + 1, y + 0.5, z - 2) */
        CHECK(m[0] == -1 && m[3] == -1 && m[7] == 0.5f && m[11] == -2);
    }
    scene_free(&s);
    scene_init(&s);
    CHECK_MSG(scene_load_file(DIR_GLTF "instancing-copies.gltf", SCENE_FORMAT_AUTO, &s, NULL, &err) == ST_OK, "%s",
              err.msg);
    CHECK_EQ_INT(s.n_objects, 0);
    CHECK_EQ_INT(s.n_triangles, 50);
    scene_free(&s);
    scene_init(&s);
    CHECK_MSG(scene_load_file(DIR_GLTF "instancing-gpu.gltf", SCENE_FORMAT_AUTO, &s, NULL, &err) == ST_OK, "%s",
              err.msg);
    CHECK_EQ_INT(s.n_objects, 1);
    CHECK_EQ_INT(s.n_instances, 4);
    if (s.n_instances == 4) {
        const float *m = s.instances[0].to_world;   /* node (0, 0, 2) . entry 0: (-1.5, 0.3, 0), scale 0.3 */
        CHECK_NEAR(m[0], 0.3, 1e-6);
        CHECK_NEAR(m[3], -1.5, 1e-6);
        CHECK_NEAR(m[7], 0.3, 1e-6);
        CHECK_NEAR(m[11], 2, 1e-6);
    }
    scene_free(&s);

    check_same_scene("reused mesh vs a mesh per node", DIR_GLTF "instancing-reuse.gltf", 0,
                     DIR_GLTF "instancing-copies.gltf", 0);
    check_same_scene("reused mesh vs its instances flattened", DIR_GLTF "instancing-reuse.gltf", 0,
                     DIR_GLTF "instancing-reuse.gltf", 1);
    check_same_scene("EXT_mesh_gpu_instancing vs its entries as nodes", DIR_GLTF "instancing-gpu.gltf", 0,
                     DIR_GLTF "instancing-gpu-copies.gltf", 0);

    /* PoCL (or the GPU) renders the instances bit for bit as the scalar device */
    Film a, b;
    Status sa = render_gltf(DIR_GLTF "instancing-gpu.gltf", TEST_OPENCL, 0, &a, &err);
    CHECK_MSG(sa == ST_OK, "%s", err.msg);
    Status sb = render_gltf(DIR_GLTF "instancing-gpu.gltf", "scalar", 0, &b, &err);
    CHECK_MSG(sb == ST_OK, "%s", err.msg);
    if (!sa && !sb) {
        size_t n = (size_t)a.width * a.height * 3u, same = film_sums_same(&a, &b);
        fprintf(stderr, "  EXT_mesh_gpu_instancing: %zu of %zu channel sums identical on OpenCL and scalar\n", same, n);
        CHECK(same == n);
    }
    if (!sa) film_free(&a);
    if (!sb) film_free(&b);
}

/* A mesh that emits light is an object like any other (its triangles are lights under
 * every instance, LIGHT_INSTANCED); what stays copies: a glTF read inside a clpt object
 * (instances nest one level deep); a node scaled to nothing places no instance. */
static void test_instancing_copies(void)
{
    Scene s;
    Error err = { 0 };
    /* one triangle in three nodes, the last scaled by s; emitting or not */
#define THREE_NODES(material, s)                                                                                 \
    "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],"                             \
    "\"nodes\":[{\"mesh\":0},{\"mesh\":0,\"translation\":[2,0,0]},{\"mesh\":0,\"scale\":[" s "]}],"              \
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","                     \
    "\"min\":[0,0,0],\"max\":[1,1,0]}],"                                                                        \
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"                          \
    "\"materials\":[" material "],"                                                                             \
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"buffers\":[{\"byteLength\":36,\"uri\":\"data:;base64," \
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}"
    CHECK_MSG(load_text("plain.gltf", THREE_NODES("{}", "0,0,0"), &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_objects, 1);
    CHECK_EQ_INT(s.n_instances, 2);
    CHECK(s.n_warnings == 1 && strcmp(s.warnings[0], "plain.gltf: mesh instances under a singular transform (a scale "
                                      "of 0) are skipped: 1") == 0);
    scene_free(&s);
    const char *fixed = THREE_NODES("{\"emissiveFactor\":[1,1,1]}", "1,1,1");
    CHECK_MSG(load_text("lamp.gltf", fixed, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_objects, 1);
    CHECK_EQ_INT(s.n_instances, 3);
    CHECK_EQ_INT(s.n_triangles, 1);
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);

    static const char in_object[] = "camera { from 0 3 9 at 0 0 0 }\n"
                                    "object o { mesh { file \"instancing-reuse.gltf\" } }\n"
                                    "instance o { translate 1 0 0 }\n";
    scene_init(&s);
    CHECK_MSG(scene_load_bytes(DIR_GLTF "in-object.scene", in_object, strlen(in_object), SCENE_FORMAT_AUTO, &s, NULL,
                               &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_objects, 1);
    CHECK_EQ_INT(s.n_instances, 1);
    CHECK_EQ_INT(s.n_triangles, 50);
    scene_free(&s);
}

/* The emissive triangle in three nodes, lit floor below: the instanced lamps (one
 * object, three instances, a light each) render the same mean as their copies within
 * noise, and PoCL the same bits as the scalar device. */
static void test_instanced_emitters(void)
{
    static const char lamp[] = THREE_NODES("{\"emissiveFactor\":[4,3,2]}", "1,1.5,1");
    const char *gltf = CLPT_BUILD_DIR "/test-gltf-lamp.gltf";
    FILE *f = fopen(gltf, "wb");
    CHECK(f && fwrite(lamp, 1, strlen(lamp), f) == strlen(lamp));
    if (f) fclose(f);
    /* the scene's path is beside the glTF: its file name is relative to it */
    static const char text[] = "image { width 48 height 36 spp 16 depth 4 }\n"
                               "camera { from 1.5 2 6 at 1.5 0.2 0 fov 45 }\n"
                               "material ground { type diffuse albedo 0.5 0.5 0.5 }\n"
                               "plane { point 0 -0.5 0 normal 0 1 0 material ground }\n"
                               "mesh { file \"test-gltf-lamp.gltf\" }\n";
    Film film[3];
    Status st[3];
    for (int i = 0; i < 3; i++) {
        Scene s;
        Error err = { 0 };
        scene_init(&s);
        st[i] = scene_load_bytes(CLPT_BUILD_DIR "/lamp.scene", text, strlen(text), SCENE_FORMAT_AUTO, &s, NULL, &err);
        if (!st[i] && i == 0) {
            CHECK_EQ_INT(s.n_objects, 1);
            CHECK_EQ_INT(s.n_instances, 3);
        }
        if (!st[i] && i == 1) st[i] = scene_flatten_instances(&s, &err);
        if (!st[i]) st[i] = render_util_run(&s, i == 2 ? TEST_OPENCL : "scalar", 0, &film[i], &err);
        CHECK_MSG(st[i] == ST_OK, "%s", err.msg);
        scene_free(&s);
    }
    if (!st[0] && !st[1]) {
        double ma = film_mean(&film[0]), mb = film_mean(&film[1]);
        fprintf(stderr, "  instanced emissive mesh: mean %.6f, copies %.6f (%.2f%%)\n", ma, mb, 100.0 * (ma - mb) / mb);
        CHECK(mb > 0 && fabs(ma - mb) < 0.01 * mb);
    }
    if (!st[0] && !st[2]) {
        size_t n = (size_t)film[0].width * film[0].height * 3u, same = film_sums_same(&film[0], &film[2]);
        fprintf(stderr, "  instanced emissive mesh: %zu of %zu channel sums identical on OpenCL and scalar\n", same, n);
        CHECK(same == n);
    }
    for (int i = 0; i < 3; i++)
        if (!st[i]) film_free(&film[i]);
    unlink(gltf);
}

int main(void)
{
    RUN(test_volume_specular_sheen);
    RUN(test_strided);
    RUN(test_sparse);
    RUN(test_strips);
    RUN(test_glb_and_external);
    RUN(test_textures);
    RUN(test_nodes);
    RUN(test_mesh_block);
    RUN(test_alpha_modes);
    RUN(test_volume_specular_sheen);
    RUN(test_diffuse_transmission);
    RUN(test_volume_scatter);
    RUN(test_texture_transform_range);
    RUN(test_shared_image_sources);
    RUN(test_shared_buffer_file);
    RUN(test_triangle_bound);
    RUN(test_uri_policy);
    RUN(test_extras);
    RUN(test_instancing);
    RUN(test_instancing_copies);
    RUN(test_instanced_emitters);
    RUN(test_cornell_box);
    RUN(test_material_spheres);
    RUN(test_suzanne_texture);
    return harness_report();
}
