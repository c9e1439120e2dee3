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
    if (o->integrator >= 0) s->integrator = (uint)o->integrator;
    if (o->gamma >= 0) s->linear_output = o->gamma == 1;
    if (o->shadows >= 0) s->shadows = o->shadows;
}

/* --set KEY=VALUE, in order, before the flags that override a parameter (--spp beats
 * --set image.spp, as it beats the scene file). */
static Status apply_sets(const Options *o, Scene *s, Error *err)
{
    for (unsigned i = 0; i < o->n_sets; i++) {
        const char *eq = strchr(o->sets[i], '=');
        size_t n = (size_t)(eq - o->sets[i]);
        char *key = malloc(n + 1);
        if (!key) return error_set(err, ST_INTERNAL, "out of memory");
        memcpy(key, o->sets[i], n);
        key[n] = '\0';
        Status st = scene_param_set(s, key, eq + 1, err);
        free(key);
        if (st) return st;
    }
    return ST_OK;
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
    Status st = apply_sets(o, s, err);
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
    if ((st = apply_crop(o, s, err))) return st;
    if (o->range_end > (long)s->image.spp)
        return error_set(err, ST_USAGE, "--sample-range %ld:%ld goes past the render's %u samples per pixel",
                         o->range_first, o->range_end, s->image.spp);
    if (o->adaptive > 0.0 && s->integrator != INTEGRATOR_WHITTED)
        return error_set(err, ST_USAGE, "--adaptive needs the whitted integrator (--integrator whitted)");
    return ST_OK;
}
