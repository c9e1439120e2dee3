/*
 * outputs.c — the program's output files, chosen and checked before anything slow: the
 * image (-o, the scene's own name, or the scene file's name with .png), the auxiliary
 * images, the checkpoint; that each can be written and that no two are one file.
 */
#include "outputs.h"

#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"
#include "base/file_id.h"

/* Output name when -o is not given: the scene's file name with .png, in the current
 * folder. */
static char *default_output(const char *scene_path)
{
    const char *base = strrchr(scene_path, '/');
    base = base ? base + 1 : scene_path;
    size_t n = strlen(base);
    const char *dot = strrchr(base, '.');
    if (dot && dot != base) n = (size_t)(dot - base);
    char *out = malloc(n + 5);
    if (out) {
        memcpy(out, base, n);
        memcpy(out + n, ".png", 5);
    }
    return out;
}

/* What the passes after the main image need of the command line. A --sample-range
 * part does not denoise: it keeps the denoiser's inputs for clpt merge (main.c). */
PassRequest outputs_pass_request(const Options *o)
{
    PassRequest q = { o->adaptive, o->adaptive_spp, o->aovs, { o->aov_files[0], o->aov_files[1], o->aov_files[2] },
                      o->depth_near, o->depth_far, o->exr_float, o->denoise && o->range_end < 0, o->quiet,
                      o->noise_threshold > 0.0 };
    return q;
}

/* --jpeg-quality and --png-depth shape one format: said, not ignored, for another. */
static Status outputs_check_format_flags(const Options *o, const char *output, Error *err)
{
    ImageFormat fmt = IMAGE_PNG;
    Error ignored = { 0 };
    image_format_from_path(output, &fmt, &ignored);   /* outputs_choose reports a bad one */
    error_clear(&ignored);
    if (o->jpeg_quality && fmt != IMAGE_JPEG)
        return error_set(err, ST_USAGE, "--jpeg-quality sets the quality of a JPEG output, and '%s' is none (write a "
                         ".jpg or .jpeg, or leave it out)", output);
    if (o->png_depth && fmt != IMAGE_PNG)
        return error_set(err, ST_USAGE, "--png-depth sets the bits of a PNG output, and '%s' is none (write a .png, "
                         "or leave it out)", output);
    return ST_OK;
}

/* Each output can be written: checked now, so that a missing or unwritable folder is
 * found in a second, not after hours of rendering (when nothing could be saved). */
Status outputs_check(const Options *o, const char *output, Error *err)
{
    PassRequest q = outputs_pass_request(o);
    NamedFile files[8];
    char *aov_paths[3] = { NULL, NULL, NULL };
    size_t n = 0;
    ViewLook look = { (ViewTransform)o->view, o->exposure };
    Status st = image_check_look(output, &look, err);
    if (st == ST_OK) st = outputs_check_format_flags(o, output, err);
    if (st) return st;
    /* standard output is no file of the run's: nothing to probe or compare */
    if (image_path_is_stdout(output)) st = image_stdout_check(err);
    else named_file_init(&files[n++], output, "the output image", FILE_IMAGE);
    if (st) return st;
    for (unsigned aov = INTEGRATOR_AOV_NORMAL; aov <= INTEGRATOR_AOV_ALBEDO; aov++) {
        if (!(o->aovs & (1u << aov)) || passes_aov_in_exr(&q, output, aov)) continue;
        char *path = aov_paths[aov - INTEGRATOR_AOV_NORMAL] = passes_aov_output_path(&q, output, aov);
        if (!path) {
            st = error_set(err, ST_INTERNAL, "out of memory");
            goto out;
        }
        named_file_init(&files[n++], path, "the --aov image", FILE_IMAGE);
    }
    if (o->checkpoint_path) named_file_init(&files[n++], o->checkpoint_path, "the checkpoint", FILE_CHECKPOINT);
    if (o->resume_path) named_file_init(&files[n++], o->resume_path, "the checkpoint to resume", FILE_RESUME);
    named_file_init(&files[n++], o->scene_path, "the scene", FILE_SCENE);
    if ((st = named_files_check_distinct(files, n, err))) goto out;
    for (size_t i = 0; i < n && st == ST_OK; i++)
        if (file_role_is_output(files[i].role))
            st = atomic_probe(files[i].id.path, files[i].role == FILE_CHECKPOINT ? "checkpoint" : "", err);
out:
    for (size_t i = 0; i < 3; i++) free(aov_paths[i]);
    return st;
}

/* The output's name (-o, or the scene's name with .png) and its format; a scene that
 * names its own image (outputs_from_scene) may still change the default. */
Status outputs_choose(const Options *o, const char **output, char **default_out, Error *err)
{
    ImageFormat format;
    *output = o->output;
    if (!*output && !(*output = *default_out = default_output(o->scene_path)))
        return error_set(err, ST_INTERNAL, "out of memory");
    return image_format_from_path(*output, &format, err);
}

/* Without -o, the image the scene file asks for (pbrt's Film "filename", relative to
 * the current folder as pbrt writes it) replaces the default name, and is checked as
 * the default was: the outputs are chosen before the scene is read so that a bad -o
 * fails at once, and only a scene can say this name. */
Status outputs_from_scene(const Options *o, const Scene *scene, const char **output, Error *err)
{
    if (o->output || !scene->output_hint) return ST_OK;
    ImageFormat format;
    Status st = image_format_from_path(scene->output_hint, &format, err);
    if (st) return st;
    *output = scene->output_hint;
    return outputs_check(o, *output, err);
}

char *outputs_frame_path(const char *path, long frame)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    size_t stem = dot && dot != base ? (size_t)(dot - path) : strlen(path);
    char number[32];
    int n = snprintf(number, sizeof number, "_%04ld", frame);
    size_t len = strlen(path) + (size_t)n + 1;
    char *out = malloc(len);
    if (out) snprintf(out, len, "%.*s%s%s", (int)stem, path, number, path + stem);
    return out;
}
