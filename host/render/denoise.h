/*
 * denoise.h — Intel Open Image Denoise (OIDN), loaded at run time, on a finished image.
 *
 * OIDN is not linked: denoiser_open finds libOpenImageDenoise.so.2 with dlopen (beside
 * the program, where tools/oidn_fetch.sh puts it, else the system's library path) and
 * resolves the few functions of its documented C API that clpt calls. So the program
 * builds, starts and renders without it, and only --denoise asks for it.
 *
 * denoiser_run runs OIDN's "RT" filter as its documentation recommends for final
 * frames: the albedo and normal features are denoised first, each by an RT filter of
 * its own, and the colour is then filtered with them as clean features ("cleanAux"),
 * as an HDR image. Inputs are width x height x 3 floats, top row first: the linear
 * colour, the albedo (0..1) and the signed world-space normal (-1..1, 0 where nothing
 * is hit). See docs/denoise.md.
 */
#ifndef CLPT_DENOISE_H
#define CLPT_DENOISE_H

#include <signal.h>

#include "base/status.h"

typedef struct Denoiser Denoiser;

/* The environment variable that names the only folder the library is looked for in
 * (tests point it at an empty folder; users at a copy of their own). */
#define DENOISE_DIR_ENV "CLPT_OIDN_DIR"

/* Loads OIDN and opens its default device (a GPU OIDN supports, else the CPU). Without
 * the library: ST_DEVICE, "--denoise needs Intel Open Image Denoise ..." naming where
 * it was looked for and the command that fetches it; a library that does not load or
 * lacks a function, or a device that cannot start: ST_DEVICE with OIDN's reason. */
Status denoiser_open(Denoiser **out, Error *err);

/* Denoises `color` into `out` (which may be `color`) with the features `albedo` and
 * `normal` (either may be NULL: OIDN then filters without it). The inputs are left as
 * they are; values OIDN cannot take (not finite, negative colour, features out of
 * range) are cleaned on the way in, and the output is finite. ST_DEVICE with OIDN's
 * message when it fails, ST_INTERNAL when memory runs out. */
Status denoiser_run(Denoiser *d, const float *color, const float *albedo, const float *normal, unsigned width,
                    unsigned height, float *out, Error *err);

/* Prefilters the features in place (each through an RT filter of its own, as
 * denoiser_run does first), so that several colour images of one view (the viewer's
 * passes) are denoised with them by denoiser_run_clean without filtering them again:
 * a third of the work per image. Either may be NULL. */
Status denoiser_clean_features(Denoiser *d, float *albedo, float *normal, unsigned width, unsigned height,
                               Error *err);
/* denoiser_run with features denoiser_clean_features has already prefiltered. */
Status denoiser_run_clean(Denoiser *d, const float *color, const float *albedo, const float *normal, unsigned width,
                          unsigned height, float *out, Error *err);

/* A flag that stops the denoiser's work when raised (NULL: none): checked before each
 * of its filters and, through OIDN's progress monitor, by OIDN itself between pieces of
 * a filter's work, so a raised flag ends denoiser_run, denoiser_run_clean or
 * denoiser_clean_features within a fraction of a second with ST_INTERRUPTED ("denoising
 * was cancelled"), the outputs then unspecified. The viewer raises it when the view
 * changes, it pauses or quits: OIDN's filter has no other way to be stopped. The flag
 * must outlive the denoiser's use of it. */
void denoiser_set_cancel(Denoiser *d, const volatile sig_atomic_t *cancel);

/* The file the library was loaded from, and its device's kind ("CPU", "CUDA", ...). */
const char *denoiser_library(const Denoiser *d);
const char *denoiser_device_kind(const Denoiser *d);

/* Releases the device and unloads the library; NULL is fine. */
void denoiser_close(Denoiser *d);

#endif /* CLPT_DENOISE_H */
