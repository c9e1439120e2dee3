/*
 * fuzz_scene.c — the scene reader (host/io/scene_parse.c) on arbitrary text, and, for a
 * scene that loads, everything that prepares it for the devices (lights, camera,
 * the tree) at a small image size. Included files and meshes are looked up beside
 * "fuzz.scene" in the current folder (the project root), so the inputs can pull in the
 * shipped scenes and test meshes.
 */
#include "fuzz.h"
#include "render/render_scene.h"
#include "scene/scene.h"

#include <math.h>

FUZZ_SEEDS("scene");

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    s.keep_animation = 1;   /* a camera_path becomes the animation, posed halfway below */
    Status st = scene_load_text("fuzz.scene", (const char *)data, size, &s, &err);
    if (st == ST_OK && s.animation) {
        st = s.animation->pose(s.animation, &s, s.animation->end / 2, &err);
        if (st) FUZZ_ASSERT(st == ST_INPUT && err.msg[0]);
        else FUZZ_ASSERT(fuzz_finite3(s.camera.from) && fuzz_finite3(s.camera.at) && isfinite(s.camera.vfov));
    }
    if (st) {
        FUZZ_ASSERT((st == ST_INPUT || st == ST_IO) && err.msg[0]);
    } else {
        size_t n_prims = s.n_spheres + s.n_triangles + s.n_boxes + s.n_planes + s.n_instances;
        for (size_t i = 0; i < s.n_spheres; i++)
            FUZZ_ASSERT(s.spheres[i].material < s.n_materials && s.spheres[i].radius > 0.0f);
        for (size_t i = 0; i < s.n_triangles; i++) FUZZ_ASSERT(s.triangles[i].material < s.n_materials);
        for (size_t i = 0; i < s.n_boxes; i++) FUZZ_ASSERT(s.boxes[i].material < s.n_materials);
        for (size_t i = 0; i < s.n_planes; i++) FUZZ_ASSERT(s.planes[i].material < s.n_materials);
        /* the tree build is O(n log n); keep one input's work small */
        if (n_prims <= 4096) {
            s.image.width = s.image.width < 16 ? s.image.width : 16;
            s.image.height = s.image.height < 16 ? s.image.height : 16;
            RenderScene rs;
            st = render_scene_prepare(&s, 1, &rs, &err);
            if (st) FUZZ_ASSERT(st == ST_INPUT && err.msg[0]);
            else FUZZ_ASSERT(rs.kd.n_nodes + rs.bvh.n_nodes >= 1 && isfinite(rs.ds.params.camera.corner.x));
            render_scene_free(&rs);
        }
    }
    scene_free(&s);
    error_clear(&err);
    return 0;
}
