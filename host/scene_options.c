/* scene_options.c — see scene_options.h. */
#include "scene_options.h"

#include "base/limit.h"
#include "io/mesh_load.h"
#include "io/mesh_view.h"
#include "scene/scene_param.h"

#include <stdlib.h>
#include <string.h>

Status scene_options_before_load(const Options *o, Scene *s, Error *err)
{
    if (o->camera && mesh_kind(o->scene_path) != MESH_GLTF)
        return error_set(err, ST_USAGE, "--camera picks a glTF file's camera; '%s' is not a .gltf or .glb file",
                         o->scene_path);
    s->gltf_camera = o->camera;
    s->keep_animation = o->frames_first >= 0 || o->anim_time >= 0.0 ? KEEP_ANIMATION_NEEDED
                      : o->shutter_close > o->shutter_open || o->shutter_fraction > 0.0 ? KEEP_ANIMATION_IF_ANY
                      : KEEP_ANIMATION_NO;
    s->size_overridden = o->width >= 0 || o->height >= 0;
    return ST_OK;
}

static void apply_overrides(const Options *o, Scene *s)
{
    if (o->spp >= 0) s->image.spp = (uint)o->spp;
    if (o->width >= 0) s->image.width = (uint)o->width;
    if (o->height >= 0) s->image.height = (uint)o->height;
    if (o->seed >= 0) s->image.seed = (uint)o->seed;
    if (o->sampler >= 0) s->image.sampler = (uint)o->sampler;
    if (o->accel >= 0) s->accel = (uint)o->accel;
    if (o->max_depth >= 0) s->image.max_depth = (uint)o->max_depth;
    if (o->split >= 0) s->image.split = (uint)o->split;
    if (o->clamp > 0.0) s->image.clamp_indirect = (float)o->clamp;
    if (o->integrator >= 0) s->integrator = (uint)o->integrator;
    if (o->gamma >= 0) s->linear_output = o->gamma == 1;
    if (o->shadows >= 0) s->shadows = o->shadows;
}

/* Scene parameter `key` (its first key_len bytes) set to the value_len bytes at value. */
static Status set_param(Scene *s, const char *key, size_t key_len, const char *value, size_t value_len, Error *err)
{
    char *k = malloc(key_len + 1), *v = malloc(value_len + 1);
    Status st = k && v ? ST_OK : error_set(err, ST_INTERNAL, "out of memory");
    if (st == ST_OK) {
        memcpy(k, key, key_len);
        k[key_len] = '\0';
        memcpy(v, value, value_len);
        v[value_len] = '\0';
        st = scene_param_set(s, k, v, err);
    }
    free(k);
    free(v);
    return st;
}

/* --set KEY=VALUE, in order, before the flags that override a parameter (--spp beats
 * --set image.spp, as it beats the scene file): those of the camera (`camera` 1) or
 * the others (0). The camera's come after a bare mesh's framing camera is made, which
 * they would otherwise be lost under. */
static Status apply_sets(const Options *o, Scene *s, int camera, Error *err)
{
    for (unsigned i = 0; i < o->n_sets; i++) {
        const char *eq = strchr(o->sets[i], '=');
        size_t n = (size_t)(eq - o->sets[i]);
        if ((strncmp(o->sets[i], "camera.", 7) == 0) != camera) continue;
        Status st = set_param(s, o->sets[i], n, eq + 1, strlen(eq + 1), err);
        if (st) return st;
    }
    return ST_OK;
}

/* --lookat and --fov, through the parameters --set reaches (camera.from, .at, .up and
 * .fov): one way into the camera whatever the flag and the scene's format. options.c
 * checked the values. */
static Status apply_camera_flags(const Options *o, Scene *s, Error *err)
{
    static const char *const lookat_keys[3] = { "camera.from", "camera.at", "camera.up" };
    const char *p = o->lookat;
    Status st = ST_OK;
    for (int i = 0; p && i < 3 && !st; i++) {
        /* the i-th three numbers: up to the third comma, or the end */
        const char *end = p;
        for (int commas = 0; *end && !(*end == ',' && ++commas == 3); end++) {}
        st = set_param(s, lookat_keys[i], strlen(lookat_keys[i]), p, (size_t)(end - p), err);
        p = *end ? end + 1 : end;
    }
    if (st || !o->fov) return st;
    if (s->camera.type == CAMERA_ORTHOGRAPHIC)
        return error_set(err, ST_USAGE, "--fov sets a perspective camera's field of view; the scene's camera is "
                         "orthographic");
    return scene_param_set(s, "camera.fov", o->fov, err);
}

/* --crop or --pixel-bounds replaces the scene's window (pbrt's cropwindow), and must
 * select pixels of the image as the flags and the scene sized it. A crop, the flags'
 * or the scene's, rules out --adaptive, which compares each pixel with its neighbours:
 * at the window's edge some would be missing, and the pixels would not be the whole
 * render's. */
static Status apply_crop(const Options *o, Scene *s, Error *err)
{
    if (o->crop_kind) s->crop = (SceneCrop){ o->crop_kind, o->crop[0], o->crop[1], o->crop[2], o->crop[3] };
    CropWindow w;
    if (o->crop_kind && !crop_window(&s->crop, s->image.width, s->image.height, &w))
        return error_set(err, ST_USAGE, o->crop_kind == CROP_PIXELS ? "--pixel-bounds %s goes past the %ux%u image"
                                                                    : "--crop %s selects no pixel of the %ux%u image",
                         o->crop_text, s->image.width, s->image.height);
    if (s->crop.kind != CROP_NONE && o->adaptive > 0.0)
        return error_set(err, ST_USAGE, "--adaptive cannot render a crop (%s): it compares each pixel with its "
                         "neighbours, which the window's edge leaves out", o->crop_kind == CROP_PIXELS
                         ? "--pixel-bounds" : o->crop_kind ? "--crop" : "the scene's crop window");
    return ST_OK;
}

Status scene_options_apply(const Options *o, Scene *s, int bare_mesh, Error *err)
{
    Status st = apply_sets(o, s, 0, err);
    if (st) return st;
    apply_overrides(o, s);
    /* the size rendered, whichever reader or flag set it (a pbrt Film's sides are
     * checked one by one, and an image block's product is left to this check when a
     * flag replaces its size) */
    int flags = o->width >= 0 || o->height >= 0;
    if ((st = limit_pixels(s->image.width, s->image.height, flags ? ST_USAGE : ST_INPUT,
                           flags ? "--width/--height" : o->scene_path, err)))
        return st;
    /* a mesh file given in place of a scene is shown by a camera that frames it */
    if (bare_mesh && (st = mesh_view_fit(s, err))) return st;
    /* then what the flags say of the camera, which replaces that framing */
    if ((st = apply_sets(o, s, 1, err)) || (st = apply_camera_flags(o, s, err))) return st;
    if ((st = apply_crop(o, s, err))) return st;
    if (o->range_end > (long)s->image.spp)
        return error_set(err, ST_USAGE, "--sample-range %ld:%ld goes past the render's %u samples per pixel",
                         o->range_first, o->range_end, s->image.spp);
    if (o->adaptive > 0.0 && s->integrator != INTEGRATOR_WHITTED)
        return error_set(err, ST_USAGE, "--adaptive needs the whitted integrator (--integrator whitted)");
    if (o->clamp > 0.0 && s->integrator != INTEGRATOR_PATH)
        return error_set(err, ST_USAGE, "--clamp limits the path tracer's indirect light (--integrator path); the "
                         "whitted integrator has none");
    if (o->noise_threshold > 0.0 && s->integrator != INTEGRATOR_PATH)
        return error_set(err, ST_USAGE, "--noise-threshold needs the path tracer (--integrator path); the whitted "
                         "integrator has --adaptive");
    return ST_OK;
}

Status scene_options_apply_camera(const Options *o, Scene *s, Error *err)
{
    Status st = apply_sets(o, s, 1, err);
    return st ? st : apply_camera_flags(o, s, err);
}
