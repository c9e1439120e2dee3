/*
 * fuzz_obj.c — the Wavefront OBJ reader (host/io/obj.c) on arbitrary text. Every triangle
 * it appends must be finite, carry the given material, and point at a shading record
 * that exists.
 */
#include "fuzz.h"
#include "util/kmath.h"
#include "io/obj.h"

#include <math.h>
#include <string.h>

FUZZ_SEEDS("obj");

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* obj_parse wants the text NUL-terminated */
    char *text = fuzz_text(data, size);
    if (!text) return 0;
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    uint m = NO_INDEX;
    if (scene_add_material(&s, "m", material_diffuse(v3(0.5f, 0.5f, 0.5f)), &m, &err) == ST_OK) {
        Status st = obj_parse("fuzz.obj", text, size, &s, m, &err);
        if (st) FUZZ_ASSERT(st == ST_INPUT && err.msg[0]);
        fuzz_check_triangles(&s, m);
    }
    scene_free(&s);
    error_clear(&err);
    free(text);
    return 0;
}
