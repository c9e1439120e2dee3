/*
 * fuzz_pbrt.c — the pbrt-v4 reader (host/io/pbrt_parse.c) on arbitrary text, and, for a
 * scene that loads, everything that prepares it for the devices (lights, camera,
 * the tree) at a small image size. Included files and PLY meshes are looked up beside
 * "fuzz.pbrt" in the current folder (the project root), so inputs can pull in
 * tests/data/pbrt/ and the test meshes.
 */
#include "fuzz.h"
#include "io/pbrt_parse.h"
#include "render/render_scene.h"
#include "scene/scene.h"

FUZZ_SEEDS("pbrt");

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    Status st = pbrt_load_text("fuzz.pbrt", (const char *)data, size, &s, &err);
    if (st) {
        FUZZ_ASSERT((st == ST_INPUT || st == ST_IO) && err.msg[0]);
    } else {
        size_t n_prims = s.n_spheres + s.n_triangles;
        for (size_t i = 0; i < s.n_spheres; i++)
            FUZZ_ASSERT(s.spheres[i].material < s.n_materials && s.spheres[i].radius > 0.0f);
        for (size_t i = 0; i < s.n_triangles; i++) FUZZ_ASSERT(s.triangles[i].material < s.n_materials);
        for (size_t i = 0; i < s.n_warnings; i++) FUZZ_ASSERT(s.warnings[i] && s.warnings[i][0]);
        /* a mix names materials that exist, nested no deeper than the kernels follow */
        for (size_t i = 0; i < s.n_materials; i++)
            if (s.materials[i].type == MAT_MIX) FUZZ_ASSERT(scene_mix_depth(&s, (uint)i) <= MIX_MAX_DEPTH);
        if (s.bg_type == BG_MAP) FUZZ_ASSERT(s.bg_cubemap < s.n_textures);
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
