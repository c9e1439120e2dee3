/*
 * fuzz_load.c — the one loader (host/io/scene_load.c) on arbitrary bytes: the byte order
 * mark, telling the classic, pbrt-v4 and our formats apart, and the dispatch to the readers,
 * including the scene made around a bare mesh (host/io/mesh_view.c). Each input is read
 * three times, named fuzz.scene (a scene of either format, by its content), fuzz.obj and
 * fuzz.ply (a bare mesh, by the name), so every branch sees every input. Files a scene
 * names are looked up beside these names in the current folder (the project root).
 */
#include "fuzz.h"
#include "io/classic_parse.h"
#include "io/lexer.h"
#include "io/pbrt_parse.h"
#include "io/scene_load.h"

FUZZ_SEEDS("scene txt obj ply");

/* What a loaded scene promises, whatever its kind. */
static void check_scene(const Scene *s, SceneKind kind)
{
    for (size_t i = 0; i < s->n_spheres; i++)
        FUZZ_ASSERT(s->spheres[i].material < s->n_materials && s->spheres[i].radius > 0.0f);
    for (size_t i = 0; i < s->n_triangles; i++) FUZZ_ASSERT(s->triangles[i].material < s->n_materials);
    for (size_t i = 0; i < s->n_planes; i++) FUZZ_ASSERT(s->planes[i].material < s->n_materials);
    if (kind == SCENE_KIND_MESH) {
        /* the mesh, its sun, and a camera that frames it from a finite point */
        FUZZ_ASSERT(s->n_triangles > 0 && s->n_spheres == 1 && s->bg_type == BG_SKY);
        FUZZ_ASSERT(fuzz_finite3(s->camera.from) && fuzz_finite3(s->camera.at));
        for (size_t i = 0; i < s->n_triangles; i++)
            FUZZ_ASSERT(fuzz_finite3(s->triangles[i].p0) && fuzz_finite3(s->triangles[i].p1) &&
                        fuzz_finite3(s->triangles[i].p2));
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* the mesh readers want the bytes NUL-terminated */
    char *text = fuzz_text(data, size);
    if (!text) return 0;
    size_t bom = lex_bom_length(text, size);
    int pbrt = pbrt_detect(text + bom, size - bom);
    int classic = classic_detect(text + bom, size - bom);
    static const char *const names[] = { "fuzz.scene", "fuzz.obj", "fuzz.ply" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        Scene s;
        scene_init(&s);
        Error err = { 0 };
        SceneKind kind = 0;
        Status st = scene_load_bytes(names[i], text, size, SCENE_FORMAT_AUTO, &s, &kind, &err);
        FUZZ_ASSERT(kind == (i > 0 ? SCENE_KIND_MESH : pbrt ? SCENE_KIND_PBRT : classic ? SCENE_KIND_CLASSIC
                                                                                        : SCENE_KIND_CLPT));
        if (st) FUZZ_ASSERT((st == ST_INPUT || st == ST_IO) && err.msg[0]);
        else check_scene(&s, kind);
        scene_free(&s);
        error_clear(&err);
    }
    free(text);
    return 0;
}
