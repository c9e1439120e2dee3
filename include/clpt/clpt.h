/*
 * clpt.h — the public C interface of clpt, the OpenCL path tracer (docs/api.md).
 *
 *     clpt_context *ctx = clpt_context_create();
 *     clpt_scene *scene = NULL;
 *     clpt_settings *set = clpt_settings_create(ctx);
 *     if (clpt_context_set_devices(ctx, "scalar") != CLPT_OK ||
 *         clpt_scene_load(ctx, "scene.glb", &scene) != CLPT_OK ||
 *         clpt_settings_set(set, "spp", "64") != CLPT_OK)
 *         fprintf(stderr, "%s\n", clpt_last_error(ctx));
 *     unsigned w, h;
 *     clpt_render_size(scene, set, &w, &h);
 *     float *rgb = malloc((size_t)w * h * 3 * sizeof *rgb);
 *     clpt_image img = { w, h, rgb };
 *     clpt_render(scene, set, &img, NULL, NULL);
 *     ...
 *     clpt_scene_free(scene); clpt_settings_free(set); clpt_context_free(ctx);
 *
 * Errors. Every call that can fail returns a clpt_status; the message of the last
 * failure of a context (or of a scene or settings made from it) is clpt_last_error(ctx),
 * the same words the command line prints after "clpt: error: ".
 *
 * Threads. A context and the scenes and settings made from it belong to one thread at
 * a time (calls on them must not overlap); different contexts may be used from
 * different threads at once. The progress callback runs on the thread that called
 * clpt_render. Nothing here keeps state between contexts, except what the process
 * shares anyway: the OpenCL runtime, the kernel cache folder on disk (CLPT_CACHE_DIR),
 * and the environment variables clpt reads (docs/api.md, "Process-wide state").
 *
 * Symbols: only clpt_* functions are exported by libclpt.so.
 */
#ifndef CLPT_CLPT_H
#define CLPT_CLPT_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The library's version, CLPT_VERSION_MAJOR, _MINOR and _PATCH (semantic: a new MAJOR
 * breaks this interface, and is the SONAME's number, libclpt.so.MAJOR), written by the
 * build from the one VERSION file into clpt/clpt_version.h and installed beside this. */
#include "clpt/clpt_version.h"

#if defined(__GNUC__)
#define CLPT_API __attribute__((visibility("default")))
#else
#define CLPT_API
#endif

/* The same numbers as the program's exit codes (docs/exit-codes.md). */
typedef enum {
    CLPT_OK = 0,
    CLPT_ERROR_INTERNAL = 1,     /* a bug, or out of memory */
    CLPT_ERROR_USAGE = 2,        /* a bad argument: unknown setting, bad value, wrong buffer size */
    CLPT_ERROR_INPUT = 3,        /* a malformed scene, mesh or checkpoint file */
    CLPT_ERROR_IO = 4,           /* a file could not be read or written */
    CLPT_ERROR_DEVICE = 5,       /* no usable device, or every device failed */
    CLPT_INTERRUPTED = 6,        /* cancelled (progress callback): the image holds what finished */
    CLPT_NOTHING_RENDERED = 7    /* cancelled or out of time before the first batch finished */
} clpt_status;

typedef struct clpt_context clpt_context;
typedef struct clpt_scene clpt_scene;
typedef struct clpt_settings clpt_settings;

/* "0.2.0": the version of the library loaded (may differ from the header's). */
CLPT_API const char *clpt_version(void);

/* ------------------------------------------------------------------ contexts */

/* A new context, rendering on the default devices (as clpt without --device: every
 * OpenCL GPU, else the OpenCL CPU devices, else the scalar device). NULL only when
 * memory runs out. */
CLPT_API clpt_context *clpt_context_create(void);
/* Frees the context; its scenes and settings must be freed first. NULL is allowed. */
CLPT_API void clpt_context_free(clpt_context *ctx);

/* The message of the last failed call on ctx or on a scene or settings made from it
 * ("" when none failed yet). Valid until the next call on them. */
CLPT_API const char *clpt_last_error(const clpt_context *ctx);

/* Chooses the devices as --device SPEC does: a comma-separated list of indices from
 * clpt_device_count/clpt_device_name, "all", "gpu", "cpu" (OpenCL CPU devices),
 * "scalar", or part of a device or platform name; NULL or "" is the default. A spec
 * that matches no device fails here, with the list of devices in the message. */
CLPT_API clpt_status clpt_context_set_devices(clpt_context *ctx, const char *spec);

/* Every device, as --list-devices shows them (OpenCL devices first, then the scalar
 * device). The strings live as long as the context. */
CLPT_API size_t clpt_device_count(clpt_context *ctx);
CLPT_API const char *clpt_device_name(clpt_context *ctx, size_t i);      /* NULL past the end */
CLPT_API const char *clpt_device_kind(clpt_context *ctx, size_t i);      /* "opencl" or "scalar" */
CLPT_API const char *clpt_device_type(clpt_context *ctx, size_t i);      /* "GPU", "CPU" ... */
CLPT_API const char *clpt_device_platform(clpt_context *ctx, size_t i);  /* "" for the scalar device */
/* What SPEC names the device by: an OpenCL device's index; -1 for the scalar device
 * (chosen as "scalar") and past the end. */
CLPT_API int clpt_device_index(clpt_context *ctx, size_t i);

/* Warnings (a device dropped, a texture missing) go to `fn`; the default prints
 * "clpt: warning: MESSAGE" to stderr; fn NULL drops them. */
typedef void (*clpt_warning_fn)(void *user, const char *message);
CLPT_API void clpt_context_set_warning_callback(clpt_context *ctx, clpt_warning_fn fn, void *user);

/* ------------------------------------------------------------------ scenes */

/* Reads a scene in any format clpt reads (its own, pbrt-v4, glTF, .obj/.ply meshes,
 * the courses' format), told from the name and the content. */
CLPT_API clpt_status clpt_scene_load(clpt_context *ctx, const char *path, clpt_scene **out);
/* The same from `len` bytes of text (a glTF .glb's bytes too); `name` is the name the
 * messages use, its extension tells a mesh or glTF file, and files the scene names are
 * read from beside it. */
CLPT_API clpt_status clpt_scene_load_string(clpt_context *ctx, const char *text, size_t len, const char *name,
                                            clpt_scene **out);
/* Sets a scene parameter by path, as --set KEY=VALUE does (docs/api.md, "Scene
 * parameters"): "camera.fov" "40", "material.red.albedo" "0.8,0.2,0.2",
 * "light.0.intensity" "10,10,10", "image.spp" "16". Checked now; an unknown path or a
 * bad value fails with what was expected. */
CLPT_API clpt_status clpt_scene_set(clpt_scene *scene, const char *key, const char *value);
CLPT_API void clpt_scene_free(clpt_scene *scene);

/* ------------------------------------------------------------------ settings */

/* Render settings, starting as the command line with no flags. */
CLPT_API clpt_settings *clpt_settings_create(clpt_context *ctx);
/* Sets one command-line option by its long name, with or without "--" ("spp", "64";
 * "integrator", "whitted"; "aov", "normal,depth"; "checkpoint", "run.ckpt"), parsed
 * and checked as the command line does; a switch takes "1"/"on"/"true" or
 * "0"/"off"/"false". Options about files the program writes or what it prints
 * (--output, --stats ...) are refused with the reason. */
CLPT_API clpt_status clpt_settings_set(clpt_settings *settings, const char *name, const char *value);
CLPT_API void clpt_settings_free(clpt_settings *settings);

/* ------------------------------------------------------------------ rendering */

/* The size of the image `scene` renders with `settings` (settings may be NULL): with a
 * crop ("crop", "pixel-bounds", a pbrt Film's cropwindow), the window's. */
CLPT_API clpt_status clpt_render_size(clpt_scene *scene, const clpt_settings *settings, unsigned *width,
                                      unsigned *height);

/* The caller's memory, top row first, width and height as clpt_render_size gives:
 *   rgb     width * height * 3 floats: linear radiance (as the program's .pfm output)
 *   albedo  width * height * 3 floats, or NULL: the first hit's albedo
 *   normal  width * height * 3 floats, or NULL: the first hit's unit normal, signed
 *           (the mean over the pixel's samples; 0 where nothing is hit)
 *   depth   width * height floats, or NULL: the mean distance to the first hit, +inf
 *           where nothing is hit
 * An auxiliary image is rendered when its pointer is not NULL (after the main image,
 * with as many samples per pixel). `spp` receives the samples per pixel in rgb (with
 * the setting "noise-threshold", the most a pixel got). With "denoise", rgb is the
 * denoised image (docs/api.md). */
typedef struct {
    unsigned width, height;
    float *rgb;
    float *albedo;
    float *normal;
    float *depth;
    unsigned spp;
} clpt_image;

/* Called on the rendering thread about every 0.1 s and at the end: `done` of `total`
 * samples per pixel (the auxiliary images' passes counted in). Returning non-zero
 * cancels the render: within about a second it returns CLPT_INTERRUPTED, the image
 * holding the whole batches finished (and a checkpoint, when one is set, them). */
typedef int (*clpt_progress_fn)(void *user, unsigned done, unsigned total);

/* Renders `scene` with `settings` (NULL: the defaults) into `image`. With the settings
 * "checkpoint" and "resume" it saves and continues renders as the program does
 * (docs/checkpoint.md): a resumed render ends with the bits of an uninterrupted one.
 * The result is the program's, bit for bit, for the same scene and settings. */
CLPT_API clpt_status clpt_render(clpt_scene *scene, const clpt_settings *settings, clpt_image *image,
                                 clpt_progress_fn progress, void *user);

#ifdef __cplusplus
}
#endif

#endif /* CLPT_CLPT_H */
