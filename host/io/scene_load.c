/* scene_load.c — read the input once, then parse it in its format (scene_load.h). */
#include "io/scene_load.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "util/kmath.h"
#include "io/classic_parse.h"
#include "io/gltf.h"
#include "io/gltf_anim.h"
#include "io/lexer.h"
#include "io/mesh_load.h"
#include "io/mesh_view.h"
#include "io/pbrt_parse.h"

SceneKind scene_load_kind(const char *path, const char *text, size_t len, SceneFormat format)
{
    switch (format) {
    case SCENE_FORMAT_CLPT: return SCENE_KIND_CLPT;
    case SCENE_FORMAT_CLASSIC: return SCENE_KIND_CLASSIC;
    case SCENE_FORMAT_PBRT: return SCENE_KIND_PBRT;
    case SCENE_FORMAT_AUTO: break;
    }
    if (mesh_kind(path) != MESH_NONE) return SCENE_KIND_MESH;
    size_t n = strlen(path);
    if ((n > 5 && strcasecmp(path + n - 5, ".pbrt") == 0) || (n > 8 && strcasecmp(path + n - 8, ".pbrt.gz") == 0) ||
        pbrt_detect(text, len)) return SCENE_KIND_PBRT;
    return classic_detect(text, len) ? SCENE_KIND_CLASSIC : SCENE_KIND_CLPT;
}

/* A glTF file as the whole scene: through its own camera when it has one (then it is no
 * bare mesh to frame again), else as a mesh preview. A file with no light of its own
 * gets the preview's sky so that it is not black. */
static Status gltf_scene(const char *path, const char *text, size_t len, Scene *s, SceneKind *kind,
                         const MeshOptions *o, Error *err)
{
    GltfView v = { s->gltf_camera, 0, 0 };
    /* --frames: the file and its animation kept to pose each frame (gltf_anim.h) */
    Status st = s->keep_animation ? gltf_parse_animated(path, text, len, s, o, &v, err)
                                  : gltf_parse(path, text, len, s, o, &v, err);
    if (st) return st;
    if (!v.has_camera) return mesh_view_frame(path, s, err);
    if (kind) *kind = SCENE_KIND_CLPT;
    Status path_st = scene_set_path(s, path, err);
    if (path_st) return path_st;
    if (!v.has_lights) {
        s->bg_type = BG_SKY;
        s->bg_color = v3(0.35f, 0.38f, 0.42f);
        s->bg_zenith = v3(0.18f, 0.28f, 0.5f);
    }
    return ST_OK;
}

/* scene_load_bytes within a load already begun (lex_load_begin). */
static Status load_bytes(const char *path, const char *text, size_t len, SceneFormat format, Scene *s,
                         SceneKind *kind, Error *err)
{
    /* dropped here too, for bytes that did not come through lex_read_input */
    size_t bom = lex_bom_length(text, len);
    text += bom;
    len -= bom;
    SceneKind k = scene_load_kind(path, text, len, format);
    if (kind) *kind = k;
    if (k == SCENE_KIND_CLASSIC) return classic_load_text(path, text, len, s, err);
    if (k == SCENE_KIND_CLPT) return scene_load_text(path, text, len, s, err);
    if (k == SCENE_KIND_PBRT) return pbrt_load_text(path, text, len, s, err);
    MeshOptions o = mesh_options(NO_INDEX);
    if (mesh_kind(path) == MESH_GLTF) return gltf_scene(path, text, len, s, kind, &o, err);
    Status st = mesh_parse(path, text, len, s, &o, err);
    return st ? st : mesh_view_frame(path, s, err);
}

/* Each load counts the text its files take against one budget (lex_load_begin), the
 * file named here included. */
Status scene_load_bytes(const char *path, const char *text, size_t len, SceneFormat format, Scene *s,
                        SceneKind *kind, Error *err)
{
    Status st = lex_load_begin(err);
    if (st) return st;
    st = lex_load_count(path, len, err);
    if (!st) st = load_bytes(path, text, len, format, s, kind, err);
    lex_load_end();
    return st;
}

Status scene_load_file(const char *path, SceneFormat format, Scene *s, SceneKind *kind, Error *err)
{
    Status st = lex_load_begin(err);
    if (st) return st;
    char *text;
    size_t len;
    st = lex_read_input(path, &text, &len, err);
    if (!st) {
        st = load_bytes(path, text, len, format, s, kind, err);
        free(text);
    }
    lex_load_end();
    return st;
}
