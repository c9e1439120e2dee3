/*
 * viewer.h — `clpt --interactive SCENE`: a window (SDL2) that shows the scene rendering
 * progressively while the user moves the camera (docs/viewer.md).
 *
 * The window's thread takes input and draws; rendering runs in its own thread
 * (viewer_render.h) through the same scheduler and devices as a command-line render,
 * so a frame saved after N samples per pixel is, bit for bit, the image of
 * `clpt SCENE --spp N` with the camera P prints.
 */
#ifndef CLPT_VIEWER_H
#define CLPT_VIEWER_H

#include "io/image_write.h"
#include "render/denoise.h"
#include "render/render_scene.h"
#include "scene/scene.h"

/* OpenCL paths per wave unless --wave-paths says otherwise. A camera change cancels the
 * running batch between bounces of its waves: with the usual 2^16 paths on a CPU a
 * bounce took 0.3-0.5 s on two busy cores (the new view waited that long), with 2^14
 * about 0.1 s, at no loss of speed measured. The image does not depend on it. */
#define VIEWER_WAVE_PATHS 16384u

typedef struct {
    const char *scene_path;       /* names the saves: SCENE-view-NNN.png */
    const Scene *scene;           /* its camera is the first view; spp the cap */
    const RenderScene *rs;        /* params as prepared for the command line */
    Device **devices;
    size_t n_devices;
    DeviceConfig device_config;   /* as the devices were opened (previews open them again) */
    ImageStyle style;             /* the command line's encoding, and its --view and
                                   * --exposure: the first look shown, and the PNG saves' */
    uint fixed_batch;             /* --batch */
    Denoiser *denoiser;           /* --denoise: opened by the caller, denoising starts on;
                                   * NULL: the N key opens Open Image Denoise itself */
    int stats;                    /* --stats: timings on stdout at the end */
    int quiet;
} ViewerConfig;

/* Connects to the display, before anything slow is done: without one (no DISPLAY, no
 * video driver) it fails with ST_DEVICE and a message that says so. There is no
 * matching close: the process ends soon after the window, which viewer_run destroys,
 * and SDL_Quit would unload the X libraries SDL opened, leaving what they never free
 * in memory no tool can name (LeakSanitizer reports it from an "unknown module"). */
Status viewer_open_display(Error *err);
/* Opens the window and runs until Esc or the window is closed. */
Status viewer_run(const ViewerConfig *cfg, Error *err);

#endif /* CLPT_VIEWER_H */
