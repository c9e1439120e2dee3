/*
 * fuzz_mtl.c — the MTL material library reader (host/io/mtl.c) on arbitrary text. Every
 * material it keeps must have a name and values the kernels can use (finite, albedo
 * and emission not negative).
 */
#include "fuzz.h"
#include "io/mtl.h"

#include <math.h>
#include <string.h>

FUZZ_SEEDS("mtl");

static int usable(vec3 v) { return fuzz_finite3(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f; }

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = fuzz_text(data, size);
    if (!text) return 0;
    MtlLibrary lib;
    memset(&lib, 0, sizeof lib);
    Error err = { 0 };
    /* in a folder that does not exist, so map_Kd paths resolve without scanning */
    Status st = mtl_parse("fuzz-no-such-folder/fuzz.mtl", text, size, &lib, &err);
    if (st) FUZZ_ASSERT(st == ST_INPUT && err.msg[0]);
    for (size_t i = 0; i < lib.n; i++) {
        const MtlMaterial *mm = &lib.items[i];
        FUZZ_ASSERT(mm->name != NULL);
        FUZZ_ASSERT(usable(mm->m.albedo) && usable(mm->m.emission));
        FUZZ_ASSERT(mtl_find(&lib, mm->name, strlen(mm->name)) != NULL);
    }
    mtl_free(&lib);
    error_clear(&err);
    free(text);
    return 0;
}
