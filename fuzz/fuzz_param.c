/*
 * fuzz_param.c — scene parameters by path (host/scene/scene_param.c: --set KEY=VALUE and
 * the library's clpt_scene_set) on arbitrary text. The input is lines "KEY=VALUE" (or a
 * line without '=', taken as a key with an empty value), applied in turn to a small
 * scene with a camera, named materials of several types and delta lights. Each must
 * succeed or fail with ST_USAGE and a message, leave the scene as it was when it fails,
 * and never make a material, light or camera value that is not a number.
 */
#include "fuzz.h"
#include "scene/scene_param.h"

FUZZ_SEEDS("params");

static const char scene_text[] =
    "camera { from 0 1 5  at 0 1 0  up 0 1 0  fov 40 }\n"
    "image { width 8 height 8 spp 1 }\n"
    "material red { type diffuse albedo 0.8 0.1 0.1 }\n"
    "material gold { type conductor eta 0.2 0.4 1.4 k 3.9 2.4 1.6 roughness 0.2 }\n"
    "material glass { type dielectric ior 1.5 }\n"
    "material lamp { type emissive radiance 4 4 4 }\n"
    "sphere { center 0 1 0 radius 1 material red }\n"
    "sphere { center 2 1 0 radius 0.5 material gold }\n"
    "sphere { center -2 1 0 radius 0.5 material glass }\n"
    "sphere { center 0 4 0 radius 0.2 material lamp }\n"
    "light { type point position 0 3 2 intensity 5 5 5 }\n"
    "light { type spot position 0 3 0 direction 0 -1 0 intensity 9 9 9 angle 30 }\n";

static void check_scene(const Scene *s)
{
    for (size_t i = 0; i < s->n_materials; i++) {
        const Material *m = &s->materials[i];
        FUZZ_ASSERT(fuzz_finite3(m->albedo) && fuzz_finite3(m->emission));
    }
    for (size_t i = 0; i < s->n_lights; i++) FUZZ_ASSERT(fuzz_finite3(s->lights[i].intensity));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096) return 0;
    char *text = fuzz_text(data, size);
    if (!text) return 0;
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    FUZZ_ASSERT(scene_load_text("fuzz.scene", scene_text, sizeof scene_text - 1, &s, &err) == ST_OK);
    for (char *line = text; line;) {
        char *next = strchr(line, '\n');
        if (next) *next++ = '\0';
        char *eq = strchr(line, '=');
        const char *value = "";
        if (eq) {
            *eq = '\0';
            value = eq + 1;
        }
        Status st = scene_param_set(&s, line, value, &err);
        FUZZ_ASSERT(st == ST_OK || (st == ST_USAGE && err.msg[0]));
        error_clear(&err);
        check_scene(&s);
        line = next;
    }
    scene_free(&s);
    free(text);
    return 0;
}
