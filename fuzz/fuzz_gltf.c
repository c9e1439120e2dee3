/*
 * fuzz_gltf.c — the glTF reader (host/io/gltf.c) on arbitrary bytes: GLB containers
 * whose chunk lengths need not match, JSON whose accessors, views and buffers need not
 * fit their data, node trees with cycles, images that are not images. Every error must
 * carry a message; every triangle it appends must be finite and carry one of the
 * scene's materials; its tangents, colours and second uvs must be sound
 * (fuzz_check_extras); a camera it sets must be finite. A file that loads is read
 * again with its animations (io/gltf_anim.h) and posed halfway and at the end, under
 * the same checks. fuzz_glb.c takes the GLB container apart more closely.
 */
#include "fuzz.h"
#include "util/kmath.h"
#include "io/gltf.h"
#include "io/gltf_anim.h"

#include <math.h>
#include <string.h>

FUZZ_SEEDS("gltf glb");

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *copy = fuzz_text(data, size);
    if (!copy) return 0;
    /* the two containers: a GLB by its magic, else JSON; the name only tells the
     * reader which to expect */
    const char *name = size >= 4 && memcmp(data, "glTF", 4) == 0 ? "fuzz.glb" : "fuzz.gltf";
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    MeshOptions o = mesh_options(NO_INDEX);
    GltfView view = { NULL, 0, 0 };
    Status st = gltf_parse(name, copy, size, &s, &o, &view, &err);
    /* ST_IO: a buffer or image file the input names is not there */
    if (st) FUZZ_ASSERT((st == ST_INPUT || st == ST_IO) && err.msg[0]);
    fuzz_check_triangles(&s, NO_INDEX);
    fuzz_check_extras(&s);
    if (st == ST_OK && view.has_camera)
        FUZZ_ASSERT(fuzz_finite3(s.camera.from) && fuzz_finite3(s.camera.at) && isfinite(s.camera.vfov));
    scene_free(&s);
    error_clear(&err);
    if (st == ST_OK) {
        scene_init(&s);
        st = gltf_parse_animated(name, copy, size, &s, &o, &view, &err);
        if (st) FUZZ_ASSERT((st == ST_INPUT || st == ST_IO) && err.msg[0]);
        for (int i = 1; st == ST_OK && i <= 2; i++) {
            st = s.animation->pose(s.animation, &s, s.animation->end * i / 2, &err);
            if (st) FUZZ_ASSERT(st == ST_INPUT && err.msg[0]);
            fuzz_check_triangles(&s, NO_INDEX);
            fuzz_check_extras(&s);
        }
        scene_free(&s);
        error_clear(&err);
    }
    free(copy);
    return 0;
}
