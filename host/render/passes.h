/*
 * passes.h — the render passes of the classic ray tracer after the main image: the
 * adaptive supersampling pass, and the auxiliary images (normals, depth, albedo).
 *
 * Each pass changes a few render parameters (the integrator, a pixel mask, the pixel
 * sampling), hands them to the devices (update_params: the scene's other buffers stay
 * as loaded) and renders with the scheduler as the main image did, so it runs on every
 * selected device and gives the same bits on any of them. After the pass the devices
 * get the main render's parameters back.
 */
#ifndef CLPT_PASSES_H
#define CLPT_PASSES_H

#include "render/denoise.h"
#include "render/film.h"
#include "render/render_scene.h"
#include "render/schedule.h"

typedef struct {
    Device **devices;
    size_t n_devices;
    RenderScene *rs;                 /* its params are changed during a pass, restored after */
    const ScheduleConfig *cfg;       /* progress, stop flag, warnings of the main render */
    Denoiser *denoiser;              /* opened before the render when --denoise asks; else NULL */
    /* Called with the denoised image once it is written (the live display); NULL: none */
    void (*on_denoised)(void *ctx, const float *rgb);
    void *on_denoised_ctx;
} PassContext;

/* Marks (mask[i] = 1) every pixel whose colour, clamped to [0,1], differs from one of its
 * 4 neighbours by more than `threshold` in some channel, and both of the pair; returns
 * how many are marked. */
size_t passes_mark_edges(const float *rgb, uint width, uint height, float threshold, uint *mask);

/* The adaptive pass: `rgb` holds the main image (`base_spp` samples per pixel); renders
 * `extra` more jittered samples in every pixel passes_mark_edges marks and averages them
 * in. *marked receives the number of such pixels, *seconds the pass's time. An
 * interrupted pass averages in what it finished. */
Status passes_adaptive(const PassContext *pc, float *rgb, uint base_spp, float threshold, uint extra,
                       size_t *marked, double *seconds, Error *err);

/* How distances become the depth image's grey (misses are black, and +inf in
 * DEPTH_RAW):
 *  DEPTH_AUTO   inverse distance normalised over the image, near/d: white at the nearest
 *               hit, falling to black at the farthest, which keeps contrast in the
 *               foreground when a plane runs to the horizon;
 *  DEPTH_RANGE  linear, white at `near`, black at `far` and beyond; near > far turns it
 *               round (black near, white far, as the courses' -depth);
 *  DEPTH_RAW    the distance itself, +inf where no sample hit (for .pfm files and
 *               the EXR output's Z channel). */
typedef enum { DEPTH_AUTO, DEPTH_RANGE, DEPTH_RAW } DepthMode;
typedef struct {
    DepthMode mode;
    double near, far;
} DepthScale;

/* Turns n resolved depth pixels (mean distance x coverage, coverage, 0) into grey. */
void passes_depth_grey(float *rgb, size_t n, const DepthScale *scale);

/* Renders auxiliary image `aov` (INTEGRATOR_AOV_*) with `spp` samples per pixel (the main
 * image's pixel sampling) into rgb: normals as (n + 1) / 2, albedo as it is, depth as
 * grey by `depth`. */
Status passes_aov(const PassContext *pc, uint aov, uint spp, const DepthScale *depth, float *rgb,
                  double *seconds, Error *err);

/* Renders auxiliary image `aov` (INTEGRATOR_AOV_*, or a denoiser's feature
 * INTEGRATOR_FEATURE_*) as data, as the EXR output's channels and the library (api/)
 * hold it: the normal signed (the pixel's mean normal, misses counting 0), the mean
 * distance to the pixel's hits in every channel (+inf where none), the albedo as it is. */
Status passes_aov_data(const PassContext *pc, unsigned aov, uint spp, float *rgb, double *seconds, Error *err);

/* Samples per pixel of the emission added back after denoising (passes_denoise), per
 * sample of the image: the emission feature costs one camera ray a sample where a path
 * costs several, so four times the image's samples cost about one more bounce of its
 * paths, and halve the noise of how much of an edge pixel a lamp covers. */
#define PASSES_EMISSION_SPP_FACTOR 4u

/* Whether passes_denoise leaves the directly seen emission out of what it denoises: the
 * emission feature traces the path tracer's own camera rays, so only a path-traced
 * image whose pixels all have their `spp` samples (`uniform`: no noise threshold) holds
 * exactly that emission; a scene with media is left whole (the camera's rays may be
 * dimmed before they reach a lamp). */
int passes_emission_splits(const RenderParams *p, int uniform);

/* Auxiliary image or feature `aov` as passes_aov_data makes it, as a film of samples
 * [first, end) of a render of `spp` samples per pixel (end 0: all): the film a --denoise
 * part keeps in its checkpoint (checkpoint.h). Free *film with film_free, also after a
 * failure. */
Status passes_data_film(const PassContext *pc, unsigned aov, uint spp, uint first, uint end, Film *film,
                        double *seconds, Error *err);
/* A film of passes_data_film (the parts' films added up) resolved as passes_aov_data
 * resolves it: the same bits as one render of its samples. */
void passes_resolve_data(unsigned aov, const Film *film, float *rgb);

/* Samples per pixel of the emission added back: PASSES_EMISSION_SPP_FACTOR x spp. */
uint passes_emission_more_spp(uint spp);
/* Whether any of the n values is not 0: something is seen emitted. */
int passes_emission_lit(const float *e, size_t n);

/* The emission images passes_denoise uses, rendered: where passes_emission_splits and
 * something is seen emitted, *e the emission of the image's own `spp` samples and *more
 * that of passes_emission_more_spp(spp); else both NULL (the colour is denoised
 * whole). Freed by the caller, also after a failure. */
Status passes_denoise_emission(const PassContext *pc, uint spp, int uniform, float **e, float **more, int quiet,
                               Error *err);

/* out = OIDN(noisy - e, albedo, normal) + more (e and more given), else OIDN(noisy,
 * albedo, normal): the one formula of --denoise, clpt merge --denoise and the viewer.
 * `clean`: the features are prefiltered already (denoiser_run_clean). The emission has
 * no noise but a pixel's coverage, so there is nothing to denoise in it, and left in,
 * OIDN spreads a lamp's edge over its neighbours and moves the lamp's own flat value
 * (docs/denoise.md, "Emitters' edges"). The expectation is the image's: both emission
 * images estimate the same thing. */
Status passes_denoise_split(Denoiser *dn, const float *noisy, const float *albedo, const float *normal,
                            const float *e, const float *more, uint w, uint h, int clean, float *out, Error *err);

/* Denoises `noisy` (the image, `spp` samples per pixel) with the features into out (not
 * noisy): passes_denoise_emission, then passes_denoise_split. Where the emission is
 * left out (the emission feature, INTEGRATOR_FEATURE_EMISSION, traces the image's own
 * camera rays, so it is exactly the image's part), *emission and *emission_more receive
 * the two emission images when both are not NULL (the caller frees them; NULL when the
 * colour was denoised whole). */
Status passes_denoise(const PassContext *pc, uint spp, int uniform, const float *noisy, const float *albedo,
                      const float *normal, float *out, float **emission, float **emission_more, int quiet,
                      Error *err);

/* An EXR output with the denoiser's or the auxiliary images as channels: aov_rgb[0..2]
 * normal.X/Y/Z, Z, albedo.R/G/B (NULL: none), noisy.R/G/B, and the emission left out
 * and added back as emission.R/G/B and emission4x.R/G/B (both or neither). Nothing is
 * written when there is no channel to add. */
Status passes_write_exr_layers(const char *output, const float *rgb, float *const aov_rgb[3], const float *noisy,
                               const float *emission, const float *emission_more, uint w, uint h, int exr_float,
                               Error *err);

/* The file name of an auxiliary image: "out.png" and "normal" give "out-normal.png". */
char *passes_aov_path(const char *output, const char *name);

/* "normal", "depth" or "albedo" for INTEGRATOR_AOV_*, else NULL. */
const char *passes_aov_name(unsigned aov);

/* What the passes after the main image are asked for (clpt's --adaptive, --aov,
 * --depth-range, --exr-float, and the course command line's image names). */
typedef struct {
    double adaptive;              /* whitted: neighbour difference threshold, 0 = no pass */
    unsigned adaptive_spp;        /* extra samples per flagged pixel */
    unsigned aovs;                /* bit (INTEGRATOR_AOV_x): auxiliary images to write */
    const char *aov_files[3];     /* normal, depth, albedo image names; NULL: OUTPUT-normal.png etc. */
    double depth_near, depth_far; /* near == far: automatic depth grey */
    int exr_float;                /* EXR channels as 32-bit floats */
    int denoise;                  /* --denoise: the written image is the denoised one */
    int quiet;
    int varying_spp;              /* --noise-threshold: pixels have samples of their own */
} PassRequest;

/* Where auxiliary image `aov` goes: the name the course command line gave it, else
 * OUTPUT-normal.png etc. Freed by the caller; NULL when out of memory. */
char *passes_aov_output_path(const PassRequest *q, const char *output, unsigned aov);
/* Whether auxiliary image `aov` goes into the EXR output as channels: the output is an
 * .exr and the course command line gave the image no file of its own. */
int passes_aov_in_exr(const PassRequest *q, const char *output, unsigned aov);
/* The adaptive pass, the denoiser and the auxiliary images, after the main image is in
 * rgb (and written to `output`): each image to its file, or as channels of an EXR
 * output. With q->denoise the albedo and normal features are rendered (as an EXR's
 * channels hold them; through mirrors and clear glass), rgb is denoised with them and rewritten to `output`; an EXR
 * output then also holds them and the noisy colour (noisy.R/G/B). A failure here is
 * the run's failure; the main image stays written. */
Status passes_after_image(const PassRequest *q, const PassContext *pc, const char *output, const ImageStyle *style,
                          float *rgb, uint spp, Error *err);

#endif /* CLPT_PASSES_H */
