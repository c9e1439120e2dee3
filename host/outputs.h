/* outputs.h — the program's output files (the image, the auxiliary images, the
 * checkpoint), chosen and checked before anything slow is done: a missing folder or
 * two outputs that are one file are found in a second, not after hours of rendering. */
#ifndef CLPT_OUTPUTS_H
#define CLPT_OUTPUTS_H

#include "option_values.h"
#include "render/passes.h"
#include "scene/scene.h"

/* What the passes after the main image need of the command line. */
PassRequest outputs_pass_request(const Options *o);

/* The output's name into *output: -o, or the scene's file name with .png in the
 * current folder (allocated into *default_out, freed by the caller); and its format
 * checked. A scene that names its own image (outputs_from_scene) may still change the
 * default. */
Status outputs_choose(const Options *o, const char **output, char **default_out, Error *err);

/* Each output can be written, none is another's file or the scene's, and the flags
 * that shape one format (--jpeg-quality, --png-depth) fit the output's. */
Status outputs_check(const Options *o, const char *output, Error *err);

/* Without -o, the image the scene file asks for (pbrt's Film "filename") replaces the
 * default name in *output, checked as the default was. */
Status outputs_from_scene(const Options *o, const Scene *scene, const char **output, Error *err);

/* --frames: frame `frame`'s file of `path` (an image, a checkpoint): the number, at
 * least four digits, after the stem and an underscore, before the extension:
 * "out.png" -> "out_0042.png", "dir/a.b.exr" -> "dir/a.b_0042.exr", "out" ->
 * "out_0042". NULL without memory. */
char *outputs_frame_path(const char *path, long frame);

#endif /* CLPT_OUTPUTS_H */
