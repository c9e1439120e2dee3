/*
 * fuzz_classic.c — the reader of the MIT 6.837 scene family (host/io/classic_parse.c,
 * docs/classic-format.md) on arbitrary text, and, for a scene that loads, everything
 * that prepares it for the devices at a small image size. Meshes and textures are
 * looked up beside "fuzz.txt" in the current folder (the project root).
 */
#include "io/classic_parse.h"
#include "fuzz.h"
#include "render/render_scene.h"

#include <math.h>

FUZZ_SEEDS("txt");

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    Status st = classic_load_text("fuzz.txt", (const char *)data, size, &s, &err);
    if (st) {
        FUZZ_ASSERT((st == ST_INPUT || st == ST_IO) && err.msg[0]);
    } else {
        for (size_t i = 0; i < s.n_spheres; i++)
            FUZZ_ASSERT(s.spheres[i].material < s.n_materials && s.spheres[i].radius > 0.0f);
        for (size_t i = 0; i < s.n_triangles; i++) FUZZ_ASSERT(s.triangles[i].material < s.n_materials);
        for (size_t i = 0; i < s.n_planes; i++) FUZZ_ASSERT(s.planes[i].material < s.n_materials);
        if (s.n_spheres + s.n_triangles + s.n_boxes <= 4096) {
            s.image.width = s.image.width < 16 ? s.image.width : 16;
            s.image.height = s.image.height < 16 ? s.image.height : 16;
            RenderScene rs;
            st = render_scene_prepare(&s, 1, &rs, &err);
            if (st) FUZZ_ASSERT(st == ST_INPUT && err.msg[0]);
            render_scene_free(&rs);
        }
    }
    scene_free(&s);
    error_clear(&err);
    return 0;
}
