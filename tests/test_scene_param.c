/* test_scene_param.c — scene parameters by path (scene/scene_param.h) and the --set
 * flag that reaches them. */
#include "harness.h"
#include "cli_util.h"

#include "io/scene_load.h"
#include "scene/scene_param.h"

static const char *const scene_text =
    "camera { from 0 1 5 at 0 1 0 fov 40 }\n"
    "image { width 32 height 24 spp 4 }\n"
    "material red { type diffuse albedo 0.8 0.1 0.1 }\n"
    "material glass { type dielectric ior 1.5 }\n"
    "sphere { center 0 1 0 radius 1 material red }\n"
    "light { type point position 0 5 0 intensity 10 10 10 }\n";

static void load(Scene *s)
{
    Error err = { 0 };
    scene_init(s);
    CHECK(scene_load_text("t.scene", scene_text, strlen(scene_text), s, &err) == ST_OK);
    error_clear(&err);
}

static void test_sets(void)
{
    Scene s;
    Error err = { 0 };
    load(&s);
    CHECK(scene_param_set(&s, "camera.fov", "30", &err) == ST_OK && s.camera.vfov == 30.0f);
    CHECK(scene_param_set(&s, "camera.eye", "1,2,3", &err) == ST_OK && s.camera.from.y == 2.0f);
    CHECK(scene_param_set(&s, "camera.look_at", "0 0 0", &err) == ST_OK && s.camera.at.z == 0.0f);
    CHECK(scene_param_set(&s, "image.spp", "16", &err) == ST_OK && s.image.spp == 16);
    CHECK(scene_param_set(&s, "image.split", "3", &err) == ST_OK && s.image.split == 3);
    CHECK(scene_param_set(&s, "image.split", "auto", &err) == ST_OK && s.image.split == SCENE_SPLIT_AUTO);
    CHECK(scene_param_set(&s, "material.red.albedo", "0.2,0.3,0.4", &err) == ST_OK);
    CHECK(s.materials[0].albedo.y == 0.3f);
    CHECK(scene_param_set(&s, "material.red.albedo", "0.5", &err) == ST_OK && s.materials[0].albedo.z == 0.5f);
    CHECK(scene_param_set(&s, "material.glass.ior", "1.33", &err) == ST_OK && s.materials[1].ior == 1.33f);
    CHECK(scene_param_set(&s, "light.0.intensity", "5", &err) == ST_OK && s.delta_lights[0].intensity.x == 5.0f);
    CHECK(scene_param_set(&s, "light.0.direction", "0,0,-2", &err) == ST_OK && s.delta_lights[0].direction.z == -1.0f);
    error_clear(&err);
    scene_free(&s);
}

/* Each refusal says what was expected, and leaves the scene as it was. */
static void test_errors(void)
{
    static const struct {
        const char *key, *value, *msg;
    } cases[] = {
        { "camera.fov", "0", "scene parameter 'camera.fov' expects a number in (0, 180), got '0'" },
        { "camera.fov", "40,", "scene parameter 'camera.fov' expects a number in (0, 180), got '40,'" },
        { "camera.up", "0,0,0", "scene parameter 'camera.up' expects a direction, three numbers not all 0 "
                                "(\"0,1,0\"), got '0,0,0'" },
        { "image.spp", "1.5", "scene parameter 'image.spp' expects an integer in [1, 1000000], got '1.5'" },
        { "image.split", "0", "scene parameter 'image.split' expects auto or an integer in [1, 64], got '0'" },
        { "image.split", "Auto", "scene parameter 'image.split' expects auto or an integer in [1, 64], got 'Auto'" },
        { "material.red.albedo", "-1", "scene parameter 'material.red.albedo' expects a colour: one number >= 0 "
                                       "or three (\"0.8,0.2,0.2\"), got '-1'" },
        /* finite as a double, +inf as the float the scene stores (found by fuzz_param) */
        { "material.red.albedo", "1e39", "scene parameter 'material.red.albedo' expects a colour: one number >= 0 "
                                         "or three (\"0.8,0.2,0.2\"), got '1e39'" },
        { "material.red.albdo", "1", "unknown scene parameter 'material.red.albdo': a material has albedo, "
                                     "emission, radiance, specular, reflective, transparent, eta, k, "
                                     "specular_color, sheen_color, ior, fuzz, shininess, roughness, anisotropy, "
                                     "metallic, transmission, clearcoat, clearcoat_roughness, alpha, "
                                     "specular_factor, sheen_roughness (did you mean 'albedo'?)" },
        { "material.blue.albedo", "1", "scene parameter 'material.blue.albedo': the scene has no material named "
                                       "'blue'" },
        { "light.1.intensity", "1", "scene parameter 'light.1.intensity': the scene has 1 point, spot or "
                                    "directional light (emitting surfaces are set as material.NAME.emission)" },
        { "light.x.intensity", "1", "scene parameter 'light.x.intensity' must be light.N.PARAM, N from 0" },
        { "imgae.spp", "1", "unknown scene parameter 'imgae.spp': a path starts with camera., image., "
                            "background., material.NAME. or light.N. (did you mean 'image.spp'?)" },
    };
    Scene s;
    load(&s);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        Error err = { 0 };
        CHECK(scene_param_set(&s, cases[i].key, cases[i].value, &err) == ST_USAGE);
        CHECK_MSG(strcmp(err.msg, cases[i].msg) == 0, "%s=%s: got \"%s\"", cases[i].key, cases[i].value, err.msg);
        error_clear(&err);
    }
    CHECK(s.camera.vfov == 40.0f && s.image.spp == 4 && s.materials[0].albedo.x == 0.8f);
    scene_free(&s);
}

/* --set on the command line: the image changes as the scene file's edit would change
 * it, and a bad path is a usage error (exit 2) before anything renders. */
static void test_flag(void)
{
    char edited[64], plain[64];
    write_temp(plain, sizeof plain, ".scene", scene_text);
    char *text = malloc(strlen(scene_text) + 64);
    strcpy(text, scene_text);
    char *fov = strstr(text, "fov 40");
    memcpy(fov, "fov 25", 6);
    write_temp(edited, sizeof edited, ".scene", text);
    free(text);
    CliResult *r = malloc(sizeof *r);
    const char *a1[] = { plain, "--device", "scalar", "-q", "--set", "camera.fov=25", "-o", TEST_TMP("clpt-test-set-a.pfm"),
                         NULL };
    cli_run(a1, r);
    CHECK_MSG(r->status == 0, "%s", r->err);
    const char *a2[] = { edited, "--device", "scalar", "-q", "-o", TEST_TMP("clpt-test-set-b.pfm"), NULL };
    cli_run(a2, r);
    CHECK(r->status == 0);
    CHECK(files_equal(TEST_TMP("clpt-test-set-a.pfm"), TEST_TMP("clpt-test-set-b.pfm")));
    const char *a3[] = { plain, "--device", "scalar", "--set", "camera.fvo=25", "-o", TEST_TMP("clpt-test-set-c.pfm"), NULL };
    cli_run(a3, r);
    CHECK(r->status == 2);
    CHECK_STR_CONTAINS(r->err, "clpt: error: unknown scene parameter 'camera.fvo'");
    CHECK(!file_exists(TEST_TMP("clpt-test-set-c.pfm")));
    const char *a4[] = { plain, "--set", "camera.fov", NULL };
    cli_run(a4, r);
    CHECK(r->status == 2);
    CHECK_STR_CONTAINS(r->err, "--set expects KEY=VALUE");
    free(r);
    remove(plain);
    remove(edited);
    remove(TEST_TMP("clpt-test-set-a.pfm"));
    remove(TEST_TMP("clpt-test-set-b.pfm"));
}

int main(void)
{
    RUN(test_sets);
    RUN(test_errors);
    RUN(test_flag);
    return harness_report();
}
