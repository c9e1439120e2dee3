/*
 * viewer_render.h — the viewer's render thread: renders the current view progressively
 * with the batch scheduler (render/schedule.h) on the devices the program opened, and
 * publishes each step as a resolved image for the window to show.
 *
 * Why a thread of its own: a batch of even one sample per pixel takes about 0.1 s for
 * the Cornell box at 512 x 512 on two cores, and much longer for big meshes; the window
 * must take input at 30+ frames per second meanwhile. So the window's thread only
 * handles events and draws, and this thread runs schedule_run in passes. A camera
 * change raises the scheduler's stop flag, which cancels the batches of the old view
 * within milliseconds (ScheduleConfig.poll_seconds; devices drop a cancelled batch
 * whole), and the next pass renders the new view from sample 0.
 *
 * Passes: the film of a view holds samples [0, n) after each pass, n = 1, 2, 4, 8, ...
 * up to the cap (the scene's spp), each pass a schedule_run resumed from the ranges the
 * film holds (ScheduleConfig.done). Between passes the film is exactly a command-line
 * render of n samples; during a pass the scheduler's ticks publish what is finished.
 * Pausing cancels the pass; the film keeps its whole batches and the next pass renders
 * only the others.
 *
 * Denoising (the N key, or --denoise): after each pass that completes (the film holds
 * samples [0, n) exactly, n = 1, 2, 4, ...) the render thread denoises that frame with
 * Open Image Denoise and publishes it beside the noisy one: once per finished pass, so
 * once per displayed step of the doubling, never per tick. The albedo and normal
 * features (through mirrors and glass, as --denoise's) are rendered once per view, at
 * VIEWER_FEATURE_SPP samples per pixel, on the same devices. A denoise takes from
 * milliseconds (OIDN on a GPU) to seconds (1920 x 1080 on two busy cores: 40 s), so it
 * is cancellable like a pass: the stop flag that a camera change, a pause or quitting
 * raises (and N off, during a denoise) is OIDN's progress monitor's answer too
 * (denoiser_set_cancel), and a cancelled denoise shows nothing; the next view does not
 * wait for it, and quitting does not either. The library is opened at the first request.
 *
 * Preview: when one sample per pixel of the whole image took longer than
 * VIEWER_PREVIEW_AFTER seconds, every new view is first rendered at 1 spp in an image k
 * times smaller each way (k chosen so that it takes about a fortieth of a second) and
 * shown enlarged, then the full passes start. Devices render one image size, so the
 * preview has its own devices: the same ones opened a second time with the scene at
 * the small size (the kd-tree and scene are uploaded twice; the kernels come from the
 * cache), opened once, when the first slow pass is seen.
 */
#ifndef CLPT_VIEWER_RENDER_H
#define CLPT_VIEWER_RENDER_H

#include <pthread.h>
#include <signal.h>
#include <stdint.h>

#include "render/batch_queue.h"
#include "render/denoise.h"
#include "render/film.h"
#include "render/schedule.h"
#include "scene/scene.h"

/* A pass of 1 spp slower than this (seconds) makes new views start with a preview. */
#define VIEWER_PREVIEW_AFTER 0.1
/* Samples per pixel of the denoiser's albedo and normal images, once per view: a
 * feature sample traces a ray or a few (mirrors), far less than a path. */
#define VIEWER_FEATURE_SPP 4u

typedef struct {
    /* set by viewer_render_start, then read-only */
    Device **devices;
    size_t n_devices;
    const DeviceScene *scene;     /* what the devices loaded */
    DeviceConfig device_config;   /* to open the preview's devices */
    RenderParams params;          /* the scene's; the camera is replaced per view */
    uint spp_cap;
    uint fixed_batch;             /* --batch (tests); 0: adaptive */
    pthread_t thread;
    int started;
    pthread_mutex_t lock;
    pthread_cond_t wake;

    /* requests, under lock */
    SceneCamera camera;
    unsigned gen;                 /* incremented by each camera change */
    int paused, quit;
    int denoise;                  /* show denoised frames: denoise each finished pass */
    volatile sig_atomic_t stop;   /* the running pass's stop flag */

    /* the published frame, under lock */
    float *rgb;                   /* width * height * 3 linear, top row first */
    uint64_t samples;             /* per pixel in rgb */
    unsigned frame_gen;           /* the view it shows */
    int frame_prefix;             /* it holds samples [0, samples) exactly */
    unsigned frame_seq;           /* incremented by each publication */
    double view_samples, view_seconds;   /* rendered for this view, for Msamples/s */
    Status failure;               /* ST_OK, or why rendering stopped for good */
    char failure_msg[1024];
    /* the published denoised frame, under lock */
    float *denoised;              /* width * height * 3, of view denoised_gen */
    uint64_t denoised_samples;    /* per pixel in the frame it was made from */
    unsigned denoised_gen;        /* its view; 0: none yet */
    unsigned denoised_seq;        /* incremented by each publication */
    int denoise_state;            /* 0 not opened yet, 1 open, -1 unavailable (said once) */
    int denoising;                /* the render thread is in a denoise (N off then stops it):
                                   * 1 its features, 2 the colour's filter */
    unsigned denoise_cancels;     /* denoises cancelled by the stop flag (--stats) */
    unsigned denoise_count;       /* denoises done, and their time (--stats) */
    double denoise_seconds, denoise_last;

    /* the render thread's own */
    Film film;
    BatchSet done;
    float *spare;                 /* the next frame, swapped with rgb when published */
    unsigned my_gen;
    SceneCamera camera_shown;     /* the view being rendered */
    int view_ok;                  /* the current view's camera could be set up */
    double one_spp_seconds;       /* the last first pass of a view, 0 before */

    /* the denoiser's: the library, this view's features, the frames in and out */
    Denoiser *denoiser;
    int own_denoiser;             /* opened here (not given by the caller): closed here */
    unsigned feature_gen;         /* the view albedo and normal hold; 0: none */
    float *albedo, *normal, *noisy, *denoise_out;
    /* the view's directly seen emission, left out of the denoiser and added back as
     * --denoise does, accumulated along its passes: [0] the frame's own samples [0, n),
     * [1] samples [0, 4n); of view emission_gen (0: none) */
    Film emission[2];
    unsigned emission_gen;
    unsigned tried_gen;           /* the last (view, spp) denoised or tried */
    uint64_t tried_samples;

    /* the preview: its devices, their image size, film and parameters */
    int preview_state;            /* 0 not needed yet, 1 ready, -1 could not be opened */
    Device **preview_devices;
    size_t n_preview;
    uint preview_factor;
    Film preview_film;
    float *preview_rgb;
    RenderParams preview_params;
} ViewerRender;

/* Starts rendering view `camera` of the scene the devices loaded (its size, seed,
 * integrator), up to `spp_cap` samples per pixel. denoiser: an open Open Image Denoise
 * (--denoise: denoising starts on), or NULL (opened when viewer_render_set_denoise
 * first asks); the caller keeps and closes its own. */
Status viewer_render_start(ViewerRender *vr, Device **devices, size_t n, const DeviceScene *scene,
                           const DeviceConfig *device_config, const SceneCamera *camera, uint spp_cap,
                           uint fixed_batch, Denoiser *denoiser, Error *err);
/* Denoising of each finished pass on or off (the window shows vr->denoised when on). */
void viewer_render_set_denoise(ViewerRender *vr, int on);
/* A new view: the old one's batches are cancelled and accumulation restarts at 0. */
void viewer_render_set_camera(ViewerRender *vr, const SceneCamera *camera);
void viewer_render_set_paused(ViewerRender *vr, int paused);
/* Stops the thread and frees everything; returns the rendering failure, if any (its
 * message in err). */
Status viewer_render_stop(ViewerRender *vr, Error *err);

#endif /* CLPT_VIEWER_RENDER_H */
