/*
 * api.h — what the library's handles (include/clpt/clpt.h) hold, shared by the files
 * of host/api/: the top layer, above the program's own files, since a render through
 * the library reads its settings with the program's option table (options.c) and
 * applies them to the scene as the program does (scene_options.c).
 */
#ifndef CLPT_API_H
#define CLPT_API_H

#include <clpt/clpt.h>

#include "base/status.h"
#include "device/device.h"
#include "io/scene_load.h"
#include "option_values.h"
#include "scene/scene.h"

struct clpt_context {
    Error err;                    /* the last failure: clpt_last_error */
    char *device_spec;            /* clpt_context_set_devices; NULL: the default */
    DeviceDesc *devices;          /* device_list, made on first need */
    size_t n_devices;
    int listed;
    clpt_warning_fn warn;
    void *warn_user;
};

struct clpt_settings {
    clpt_context *ctx;
    Options o;                    /* as options_set leaves them; finished per render */
    char **strings;               /* copies of the values, which o's text flags point into */
    size_t n_strings;
};

/* A scene is kept as where it comes from and the edits made to it, and read again for
 * each render: preparing a scene for the devices changes it (lights listed, texels
 * packed, a bare mesh's camera fitted), and a render's settings may change how it is
 * read (--format, --camera, a size replaced). */
struct clpt_scene {
    clpt_context *ctx;
    char *name;                   /* the path, or the name given to a string scene */
    char *text;                   /* a string scene's bytes (text[len] = '\0'); NULL: a file */
    size_t len;
    char **keys, **values;        /* clpt_scene_set, in order */
    size_t n_sets;
};

/* Fails with `st` and the message in ctx->err (the Error of every call). */
clpt_status api_fail(clpt_context *ctx, Status st, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* Hands a warning to the context's callback. */
void api_warn(void *ctx, const char *msg);
/* The context's device listing (listed on first call). */
Status api_devices(clpt_context *ctx, Error *err);

/* The scene read as `o` asks (o->scene_path = scene->name), its own edits made, then the
 * settings applied (scene_options_apply), into `out`, initialised and empty (scene_init);
 * free it with scene_free whatever the status. */
Status api_scene_read(const clpt_scene *scene, const Options *o, Scene *out, Error *err);
/* The settings of a render: `settings` (NULL: the defaults) finished for `scene`. */
Status api_render_options(const clpt_scene *scene, const clpt_settings *settings, Options *o, Error *err);

#endif /* CLPT_API_H */
