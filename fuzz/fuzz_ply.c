/*
 * fuzz_ply.c — the PLY reader (host/io/ply.c) on arbitrary bytes: ascii and both binary
 * encodings, with header counts that need not match the data. Every triangle it appends
 * must be finite, carry the given material and point at a shading record that exists.
 */
#include "fuzz.h"
#include "util/kmath.h"
#include "io/ply.h"

#include <math.h>
#include <string.h>

FUZZ_SEEDS("ply");

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* ply_parse wants a NUL after the data */
    char *copy = fuzz_text(data, size);
    if (!copy) return 0;
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    uint m = NO_INDEX;
    if (scene_add_material(&s, "m", material_diffuse(v3(0.5f, 0.5f, 0.5f)), &m, &err) == ST_OK) {
        MeshOptions o = mesh_options(m);
        Status st = ply_parse("fuzz.ply", copy, size, &s, &o, &err);
        if (st) FUZZ_ASSERT(st == ST_INPUT && err.msg[0]);
        fuzz_check_triangles(&s, m);
    }
    scene_free(&s);
    error_clear(&err);
    free(copy);
    return 0;
}
