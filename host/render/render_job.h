/*
 * render_job.h — one render run, as the program (main.c) and the library (api/) both
 * make it: the scene prepared for the devices, the film (from a checkpoint when
 * resuming), the devices, the scheduler or the adaptive rounds, checkpoints, the final
 * image resolved, and the passes after it (whitted's edge pass, the auxiliary images,
 * the denoiser).
 *
 * A feature of the render lives here once; the callers differ only in where the images
 * go (files, or the caller's memory) and in how they talk to the user (a progress bar,
 * a live display, a callback). Their hooks get the job (ScheduleConfig.ctx is the job)
 * and find their own state in `user`.
 *
 * The steps, in the order a caller runs them (each frees nothing on failure:
 * render_job_free releases whatever was made):
 *     render_job_init            settings, warnings, the caller's state
 *     render_job_open_denoiser   --denoise: OIDN loaded before anything slow
 *     render_job_prepare_scene   kd-tree and device buffers
 *     render_job_prepare_film    the render's identity, the film, --resume
 *     render_job_open_devices    the chosen devices, each given the scene
 *     render_job_configure       the scheduler's settings (the caller then adds hooks)
 *     render_job_run             the render; its status kept apart in render_st
 *     render_job_final_checkpoint, render_job_resolve, then the passes
 *     render_job_free
 */
#ifndef CLPT_RENDER_JOB_H
#define CLPT_RENDER_JOB_H

#include "render/adaptive.h"
#include "render/checkpoint.h"
#include "render/denoise.h"
#include "render/passes.h"
#include "render/render_scene.h"
#include "render/schedule.h"
#include "render/split_pilot.h"

/* What a run is asked: the command line's options that shape the render (the app
 * layer fills it from its Options: job_options.h). */
typedef struct {
    const char *device_spec;       /* --device; NULL: the default */
    DeviceConfig device;           /* threads, kernel folder, wave size, profiling, launch */
    const char *checkpoint_path;   /* NULL: no checkpoints */
    double checkpoint_seconds;
    const char *resume_path;       /* NULL: a fresh film */
    long range_first, range_end;   /* --sample-range; range_end < 0: every sample */
    double time_limit;             /* seconds; 0: none */
    uint batch;                    /* > 0: a fixed batch size */
    AdaptiveSettings adaptive;     /* --noise-threshold; threshold 0: every pixel gets spp */
    double edge_threshold;         /* --adaptive: whitted's edge pass; 0: none */
    uint edge_spp;                 /* its extra samples per marked pixel */
    int denoise;                   /* --denoise */
    int quiet;                     /* nothing said on stderr but warnings */
} RenderJobSettings;

/* The hook called after each round of an adaptive render, with the job and the state
 * (progressive output, the library's progress); checkpoints are the job's. */
typedef void (*RenderJobRoundFn)(void *job, const AdaptiveFilm *af);

typedef struct {
    RenderJobSettings set;
    DeviceWarn warn;               /* every warning of the run, said once each */
    void *warn_ctx;
    void *user;                    /* the caller's state, for its hooks */
    RenderJobRoundFn on_round;     /* NULL: none */

    RenderScene rs;
    const Scene *scene;            /* as render_job_prepare_scene left it (not owned) */
    Film film;                     /* uniform sampling's image; film.samples also counts an
                                    * adaptive render's */
    int adaptive;                  /* set.adaptive.threshold > 0: the image is af's */
    AdaptiveFilm af;
    Checkpoint resume;
    CheckpointId checkpoint_id;    /* when keyed (a checkpoint, a resume, MPI ranks) */
    int checkpoint_failed;         /* a periodic checkpoint's failure was said */
    double last_checkpoint;        /* an adaptive render's rounds: when one was written */
    Device **devs;
    size_t n_devs;
    size_t n_local_devs;           /* devs[0..n_local_devs): this process's own, not MPI ranks */
    Denoiser *denoiser;            /* opened by render_job_open_denoiser */
    ScheduleConfig cfg;
    ScheduleStats stats;
    Status render_st;              /* the render's own status (render_job_run) */
    SplitPilot split_pilot;        /* --split auto's choice, and what the pilot measured */
    uint passes_spp;               /* samples per pixel of the passes finished (progress) */
} RenderJob;

void render_job_init(RenderJob *job, const RenderJobSettings *set, DeviceWarn warn, void *warn_ctx, void *user);
void render_job_free(RenderJob *job);

/* --denoise: the library loaded now, so that a machine without it says so in a second
 * instead of after the render. Nothing to do without --denoise. */
Status render_job_open_denoiser(RenderJob *job, Error *err);

/* kd-tree and device buffers for `scene` (render_scene_prepare), which the job reads
 * until it is freed. */
Status render_job_prepare_scene(RenderJob *job, Scene *scene, Error *err);

/* An animation whose frames move only the camera (SceneAnimation.camera_only) keeps the
 * scene prepared by the frame before: render_job_take_scene hands the prepared scene out
 * of the finished job (which then frees none of it), render_job_adopt_scene gives it to
 * the new job with the camera's parameters made again from scene->camera (checked
 * as render_scene_prepare checks it), and render_job_update_devices gives the adopted
 * devices the new parameters alone: no tree is built and no buffer uploaded again. */
void render_job_take_scene(RenderJob *job, RenderScene *rs);
Status render_job_adopt_scene(RenderJob *job, Scene *scene, RenderScene *rs, Error *err);
Status render_job_update_devices(RenderJob *job, Device **devs, size_t n_devs, Error *err);

/* The render's identity where something compares or records it (a checkpoint, a
 * resume, or `keyed`: the ranks of an MPI job): it hashes every scene buffer. Then the
 * film, and with a resume path (unless `skip_resume`: an MPI worker) the checkpoint,
 * checked against this render and its --sample-range, as the film's start. */
Status render_job_prepare_film(RenderJob *job, int keyed, int skip_resume, Error *err);

/* The chosen devices (device_open_all), each given the scene. */
Status render_job_open_devices(RenderJob *job, Error *err);

/* An animation's next frame (docs/animation.md) renders on the devices the frame before
 * opened: render_job_take_devices hands them out of the finished job (which then frees
 * none), render_job_adopt_devices gives each the new job's scene. A device keeps the
 * programs it built while the scene needs no feature they lack (device.h, load_scene),
 * so the frames compile nothing again: only the scene's buffers are uploaded. */
void render_job_take_devices(RenderJob *job, Device ***devs, size_t *n_devs);
Status render_job_adopt_devices(RenderJob *job, Device **devs, size_t n_devs, Error *err);

/* The scheduler's settings from the job's: spp, the resumed samples, the range, the
 * time limit, the batch, checkpoints, warnings; ctx the job. The caller adds its own
 * hooks (progress, ticks, the stop flag) after. */
void render_job_configure(RenderJob *job);

/* The render itself, on job->devs: the scheduler, or the adaptive rounds. Its status
 * goes to job->render_st (also returned): after a failure or an interrupt, what was
 * finished is still saved. */
Status render_job_run(RenderJob *job, Error *err);

/* Whether the render finished: no failure, no interrupt, no time limit. */
int render_job_complete(const RenderJob *job);

/* The last checkpoint holds everything finished: after an interrupt, a time limit or a
 * failure it is what a resume starts from, so it is written before the image, and
 * failing to write it is then an error. After a complete render the image is what
 * matters, and a failure only a warning. ST_OK without a checkpoint path. */
Status render_job_final_checkpoint(RenderJob *job, Error *err);

/* The image as it is, linear, into rgb (width * height * 3). */
void render_job_resolve(const RenderJob *job, float *rgb);
/* The image written to path (atomically), as film_write. */
Status render_job_write_image(const RenderJob *job, const char *path, const ImageStyle *style, Error *err);

/* What the passes render with: this process's devices (not MPI ranks'), the job's
 * scene, a copy of its scheduler settings in *pcfg that renders every sample of a pass
 * (not the resumed ones, which were the main image's) with no progress bar and no
 * checkpoints, and the denoiser. */
void render_job_pass_context(RenderJob *job, ScheduleConfig *pcfg, PassContext *pc);

/* The images a render into memory is given; NULL: not asked. */
typedef struct {
    float *normal, *albedo;        /* 3 floats a pixel, as an EXR output's channels */
    float *depth;                  /* 1 float a pixel: the mean distance, +inf where none */
} RenderJobAovs;

/* The passes after the main image, into memory (the library): `rgb` holds the resolved
 * image; the edge pass (set.edge_threshold) averages into it, the auxiliary images asked
 * in `aovs` are rendered, and with set.denoise rgb is denoised with the albedo and the
 * normal (as the program's --denoise). An interrupted pass is not handed out:
 * ST_INTERRUPTED. job->passes_spp counts the passes' samples as they finish. */
Status render_job_passes_to_memory(RenderJob *job, float *rgb, const RenderJobAovs *aovs, Error *err);

/* A part (--sample-range A:B, --checkpoint PART) rendered with --denoise does not
 * denoise its share: it renders the denoiser's inputs for its samples (the albedo and
 * normal features of samples [A, B) of the whole render's count, and where the emission
 * is left out of the denoiser its emission for samples [A, B) and [4A, 4B): checkpoint.h,
 * CKPT_FEATURE_*) and writes them into its checkpoint beside its film, so that `clpt
 * merge --denoise` of the parts is the one-process --denoise image, bit for bit.
 * Nothing to do unless the part is complete and asks for --denoise. */
Status render_job_part_features(RenderJob *job, Error *err);

#endif /* CLPT_RENDER_JOB_H */
