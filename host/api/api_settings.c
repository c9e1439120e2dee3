/* api_settings.c — render settings: the command line's options, set one at a time
 * through the program's own option table (options.c), so that every flag is reachable
 * with the same names, parsing and messages, and no second list to keep. */
#include "api/api.h"

#include <stdlib.h>
#include <string.h>

#include "options.h"

clpt_settings *clpt_settings_create(clpt_context *ctx)
{
    if (!ctx) return NULL;
    clpt_settings *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->ctx = ctx;
    options_init(&s->o);
    return s;
}

void clpt_settings_free(clpt_settings *s)
{
    if (!s) return;
    for (size_t i = 0; i < s->n_strings; i++) free(s->strings[i]);
    free(s->strings);
    free(s);
}

/* Options of the program that a render into memory has no use for: they name files
 * the program writes, what it prints, or how it runs; each with the reason. */
static const char *refused_reason(const char *name)
{
    static const struct {
        const char *name, *why;
    } refused[] = {
        { "output", "the library renders into your memory (clpt_image)" },
        { "progressive-output", "the progress callback sees the render as it goes" },
        { "exr-float", "it is about EXR files; the library gives 32-bit floats" },
        { "gamma", "it is about 8-bit files; the library gives linear floats" },
        { "depth-range", "it scales the 8-bit depth image; the library gives distances" },
        { "device", "choose devices with clpt_context_set_devices" },
        { "list-devices", "use clpt_device_count and clpt_device_name" },
        { "interactive", "the viewer is the program's" },
        { "frames", "an animation's numbered files are the program's (docs/animation.md)" },
        { "fps", "an animation's numbered files are the program's (docs/animation.md)" },
        { "mpi-broadcast", "MPI jobs are the program's" },
        { "mpi-timeout", "MPI jobs are the program's" },
        { "stats", "it prints to stdout" },
        { "profile", "it prints to stdout" },
        { "quiet", "the library prints nothing but warnings (clpt_context_set_warning_callback)" },
        { "help", "see docs/api.md" },
        { "version", "use clpt_version" },
    };
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++)
        if (strcmp(name, refused[i].name) == 0) return refused[i].why;
    return NULL;
}

clpt_status clpt_settings_set(clpt_settings *s, const char *name, const char *value)
{
    if (!s) return CLPT_ERROR_USAGE;
    clpt_context *ctx = s->ctx;
    error_clear(&ctx->err);
    if (!name || !value) return api_fail(ctx, ST_USAGE, "clpt_settings_set needs a name and a value");
    const char *bare = strncmp(name, "--", 2) == 0 ? name + 2 : name;
    const char *why = refused_reason(bare);
    if (why) return api_fail(ctx, ST_USAGE, "'%s' is not a render setting: %s", bare, why);
    /* text flags keep a pointer to their value: the copy lives as long as the settings */
    char **grown = realloc(s->strings, (s->n_strings + 1) * sizeof *grown);
    if (!grown) return api_fail(ctx, ST_INTERNAL, "out of memory");
    s->strings = grown;
    char *copy = strdup(value);
    if (!copy) return api_fail(ctx, ST_INTERNAL, "out of memory");
    s->strings[s->n_strings++] = copy;
    /* a failed value leaves the settings as they were */
    Options o = s->o;
    Status st = options_set(&o, bare, copy, &ctx->err);
    if (st == ST_OK) s->o = o;
    return (clpt_status)st;
}

Status api_render_options(const clpt_scene *scene, const clpt_settings *settings, Options *o, Error *err)
{
    if (settings) *o = settings->o;
    else options_init(o);
    if (settings && settings->ctx != scene->ctx)
        return error_set(err, ST_USAGE, "the scene and the settings belong to different contexts");
    o->scene_path = scene->name;
    o->quiet = 1;
    return options_finish(o, err);
}
