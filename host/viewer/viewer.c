/* viewer.c — see viewer.h. The window, its input and its drawing; the rendering is in
 * viewer_render.c, the camera moves in view_camera.c. */
#include "viewer/viewer.h"

#include <SDL2/SDL.h>

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "base/timer.h"
#include "viewer/view_camera.h"
#include "viewer/viewer_render.h"

/* Display conversion: linear value -> 8-bit through a table (the window shows 10+
 * frames a second; the exact encoder is used for the saved files). */
#define LUT_SIZE 16384
/* Input is handled at least this often (milliseconds between looks at the queue). */
#define LOOP_MS 8
#define MAX_LATENCIES 1024

static const char HELP_TITLE[] =
    "W/A/S/D move  R/F Q/E up/down  drag look  wheel fwd/back  Z/X fov  Up/Down focus  "
    "Left/Right aperture  +/- exposure  V view  N denoise  Space pause  C save  P camera  F11 full screen  H help  Esc quit";

static const char HELP_TEXT[] =
    "clpt viewer keys:\n"
    "  W/A/S/D        move forward / left / back / right\n"
    "  R/F, Q/E       move up / down\n"
    "  mouse drag     look around (turn the camera)\n"
    "  mouse wheel    move forward / back along the view\n"
    "  Z/X            narrower / wider field of view\n"
    "  Up/Down        focus distance farther / nearer\n"
    "  Right/Left     aperture wider / narrower (0: pinhole)\n"
    "  +/-            exposure up / down by half a stop (display and PNG)\n"
    "  V              next view transform: standard, agx, filmic (display and PNG)\n"
    "  N              denoised view on / off (Open Image Denoise, each finished pass)\n"
    "  Space          pause / resume rendering\n"
    "  C              save the image: SCENE-view-NNN.png and .pfm\n"
    "  P              print the camera as a scene-format block\n"
    "  F11            full screen\n"
    "  H              this help (in the title bar)\n"
    "  Esc            quit\n";

typedef struct {
    const ViewerConfig *cfg;
    ViewerRender vr;
    SDL_Window *win;
    SDL_Renderer *ren;
    SDL_Texture *tex;
    uint w, h;
    unsigned char *pixels;        /* what the texture shows, w * h * 3 */
    float *save_rgb;              /* the frame being saved */
    unsigned char lut[LUT_SIZE];
    double lut_scale;             /* LUT_SIZE - 1 times the exposure factor */

    SceneCamera cam;
    unsigned gen;                 /* mirrors vr.gen: only this thread changes it */
    double step, aperture_first;
    double exposure;              /* stops */
    ViewTransform view;           /* --view, then V */
    int paused, help, fullscreen, quit;
    int denoise;                  /* N: show the denoised frames */
    int showing_denoised;         /* what is on screen is vr.denoised ... */
    unsigned shown_denoised_seq;  /* ... publication number shown_denoised_seq */
    int save_pending, refresh;
    double drag_x, drag_y;        /* mouse motion with the button down, not yet applied */
    int moved;                    /* the camera changed in this round of events */

    unsigned shown_seq, shown_gen;
    uint64_t shown_samples;
    char devices[600];
    double title_time;

    /* measurements (--stats) */
    double t_start, change_time, last_loop, longest_gap;
    unsigned long loops, draws;
    int waiting_frame;
    double latencies[MAX_LATENCIES];
    unsigned n_latencies;
} Viewer;

static int env_set(const char *name)
{
    const char *v = getenv(name);
    return v && *v;
}

/* Whether SDL's video driver draws into memory only: a window nobody can see, and an
 * interactive session nobody can use (it would render and wait for keys for ever). */
static int driver_shows_nothing(const char *driver)
{
    return SDL_strcasecmp(driver, "offscreen") == 0 || SDL_strcasecmp(driver, "dummy") == 0;
}

/* SDL falls back to its "offscreen" driver when no display answers, and SDL_VIDEODRIVER
 * may name "dummy" or "offscreen" itself: either way a window nobody can see, which is
 * refused like no display. With neither an X nor a Wayland display nor a driver named,
 * SDL is not even asked (it would print Wayland's complaints, then pick "offscreen"). */
Status viewer_open_display(Error *err)
{
    int named = env_set("SDL_VIDEODRIVER");
    const char *why = NULL;
    char sdl_msg[300] = "";
    if (!named && !env_set("DISPLAY") && !env_set("WAYLAND_DISPLAY")) {
        why = "neither DISPLAY nor WAYLAND_DISPLAY is set";
    } else if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        why = "SDL could not open it";
        snprintf(sdl_msg, sizeof sdl_msg, ": %s", SDL_GetError());
    } else {
        const char *driver = SDL_GetCurrentVideoDriver();
        if (!driver || !driver_shows_nothing(driver)) return ST_OK;
        if (named) {
            snprintf(sdl_msg, sizeof sdl_msg, "SDL_VIDEODRIVER is '%.100s', and SDL's '%.40s' video driver shows no "
                     "window", getenv("SDL_VIDEODRIVER"), driver);
            why = sdl_msg;
        } else {
            snprintf(sdl_msg, sizeof sdl_msg, "%s%.200s%s", env_set("DISPLAY") ? " (DISPLAY is '" : "",
                     env_set("DISPLAY") ? getenv("DISPLAY") : "", env_set("DISPLAY") ? "')" : "");
            why = "no display answered";
        }
        SDL_Quit();
    }
    return error_set(err, ST_DEVICE,
                     "--interactive needs a display for its window, and there is none (%s%s); render to a file "
                     "without --interactive, or run it where a display is (see docs/viewer.md)",
                     why, why == sdl_msg ? "" : sdl_msg);
}

/* ------------------------------------------------------------------ drawing */

static void lut_fill(Viewer *v)
{
    for (unsigned i = 0; i < LUT_SIZE; i++) {
        float x = (float)i / (float)(LUT_SIZE - 1);
        v->lut[i] = (v->cfg->style.encoding & IMAGE_LINEAR) ? image_to_linear8(x) : image_to_srgb8(x);
    }
    v->lut_scale = (double)(LUT_SIZE - 1) * pow(2.0, v->exposure);
}

static unsigned char lut_lookup(const Viewer *v, float x)
{
    return v->lut[x > 0.0f ? (x < (float)(LUT_SIZE - 1) ? (unsigned)x : LUT_SIZE - 1) : 0];
}

/* The look being shown: the command line's, as the keys have changed it. */
static ViewLook viewer_look(const Viewer *v)
{
    return (ViewLook){ v->view, v->exposure };
}

/* The standard view is a scale and the encoding: one table lookup per value. The others
 * mix channels (AgX) or bend them (filmic) per pixel, into display values the table then
 * encodes; the saved PNG uses the exact encoder on the same display values. */
static void frame_convert(Viewer *v, const float *rgb)
{
    size_t n = (size_t)v->w * v->h;
    if (v->view == VIEW_STANDARD) {
        float s = (float)v->lut_scale;
        for (size_t i = 0; i < 3 * n; i++) v->pixels[i] = lut_lookup(v, rgb[i] * s + 0.5f);
        return;
    }
    ViewLook look = viewer_look(v);
    const float top = (float)(LUT_SIZE - 1);
    for (size_t i = 0; i < n; i++) {
        float d[3];
        view_pixel(&look, rgb + 3 * i, d);
        for (int k = 0; k < 3; k++) v->pixels[3 * i + k] = lut_lookup(v, d[k] * top + 0.5f);
    }
}

static void frame_draw(Viewer *v)
{
    SDL_UpdateTexture(v->tex, NULL, v->pixels, (int)v->w * 3);
    SDL_RenderClear(v->ren);
    SDL_RenderCopy(v->ren, v->tex, NULL, NULL);
    SDL_RenderPresent(v->ren);
    v->draws++;
    if (v->waiting_frame && v->shown_gen == v->gen) {
        v->waiting_frame = 0;
        if (v->n_latencies < MAX_LATENCIES) v->latencies[v->n_latencies++] = timer_now() - v->change_time;
    }
}

static void title_update(Viewer *v)
{
    char title[1024];
    if (v->help) {
        SDL_SetWindowTitle(v->win, HELP_TITLE);
        return;
    }
    pthread_mutex_lock(&v->vr.lock);
    double msps = v->vr.view_seconds > 0.0 ? v->vr.view_samples / v->vr.view_seconds / 1e6 : 0.0;
    const char *failed = v->vr.failure != ST_OK ? " | rendering failed (see the terminal)" : "";
    const char *denoised = !v->denoise ? "" : v->vr.denoise_state == -1 ? " | cannot denoise (see the terminal)"
                         : v->showing_denoised ? " | denoised" : " | denoising";
    pthread_mutex_unlock(&v->vr.lock);
    const char *base = strrchr(v->cfg->scene_path, '/');
    uint64_t spp = v->shown_gen == v->gen ? v->shown_samples : 0;
    snprintf(title, sizeof title, "clpt | %s | %llu/%u spp%s | %.2f Msamples/s | %s%s%s | H: help", base ? base + 1 : v->cfg->scene_path,
             (unsigned long long)spp, v->vr.spp_cap,
             spp >= v->vr.spp_cap ? " (done)" : (v->shown_gen == v->gen && v->shown_seq && !spp ? " (preview)" : ""), msps, v->devices,
             v->paused ? " | paused" : "", failed);
    if (v->exposure != 0.0) {
        size_t len = strlen(title);
        snprintf(title + len, sizeof title - len, " | exposure %+.1f", v->exposure);
    }
    if (v->view != VIEW_STANDARD) {
        size_t len = strlen(title);
        snprintf(title + len, sizeof title - len, " | view %s", view_name(v->view));
    }
    size_t len = strlen(title);
    snprintf(title + len, sizeof title - len, "%s", denoised);
    SDL_SetWindowTitle(v->win, title);
}

/* ------------------------------------------------------------------ saving */

/* SCENE-view-NNN: the first number for which neither the PNG nor the PFM exists. */
static int save_names(const char *scene_path, char *png, char *pfm, size_t size)
{
    const char *base = strrchr(scene_path, '/');
    base = base ? base + 1 : scene_path;
    const char *dot = strrchr(base, '.');
    int n = (int)(dot && dot != base ? (size_t)(dot - base) : strlen(base));
    if (n > 200) n = 200;
    struct stat sb;
    for (unsigned k = 1; k < 100000; k++) {
        snprintf(png, size, "%.*s-view-%03u.png", n, base, k);
        snprintf(pfm, size, "%.*s-view-%03u.pfm", n, base, k);
        if (stat(png, &sb) != 0 && errno == ENOENT && stat(pfm, &sb) != 0 && errno == ENOENT) return 0;
    }
    return -1;
}

/* The PFM holds the film's radiance as the command line writes it; the PNG is what the
 * window shows: the command line's PNG with the --view and --exposure shown, byte for
 * byte. */
static void frame_save(Viewer *v, uint64_t samples)
{
    char png[300], pfm[300];
    Error err = { 0 };
    if (save_names(v->cfg->scene_path, png, pfm, sizeof png) != 0) {
        fprintf(stderr, "clpt: error: cannot save: every name up to 99999 is taken\n");
        return;
    }
    ImageStyle style = { v->cfg->style.encoding, viewer_look(v), v->cfg->style.jpeg_quality };
    Status st = image_write_encoded(pfm, v->save_rgb, v->w, v->h, v->cfg->style.encoding, &err);
    if (st == ST_OK) st = image_write_styled(png, v->save_rgb, v->w, v->h, &style, &err);
    if (st != ST_OK) {
        fprintf(stderr, "clpt: error: cannot save: %s\n", err.msg);
        error_clear(&err);
        return;
    }
    char shown[80] = "";
    if (!view_look_is_identity(&style.look))
        snprintf(shown, sizeof shown, ", the PNG as shown: view %s, exposure %+.1f", view_name(v->view), v->exposure);
    fprintf(stderr, "clpt: saved %s and %s (%llu spp%s)\n", png, pfm, (unsigned long long)samples, shown);
}

/* Takes the newest published frame when there is one (or a redraw was asked for), and
 * the frame to save when a save waits for a whole frame of the current view. With N on,
 * the newest denoised frame of the current view is shown instead, once there is one
 * (until then the noisy frames); the passes' ticks in between do not replace it. */
static void frame_take(Viewer *v)
{
    int save = 0, announce = 0;
    uint64_t save_samples = 0;
    double denoise_secs = 0.0;
    pthread_mutex_lock(&v->vr.lock);
    int denoised = v->denoise && v->vr.denoised && v->vr.denoised_gen == v->gen;
    int fresh = denoised ? !v->showing_denoised || v->vr.denoised_seq != v->shown_denoised_seq
                         : v->showing_denoised || v->vr.frame_seq != v->shown_seq;
    if ((fresh || v->refresh) && denoised) {
        frame_convert(v, v->vr.denoised);
        announce = !v->showing_denoised || v->vr.denoised_seq != v->shown_denoised_seq;
        v->shown_denoised_seq = v->vr.denoised_seq;
        v->shown_gen = v->vr.denoised_gen;
        v->shown_samples = v->vr.denoised_samples;
        denoise_secs = v->vr.denoise_last;
    } else if (fresh || v->refresh) {
        frame_convert(v, v->vr.rgb);
        v->shown_seq = v->vr.frame_seq;
        v->shown_gen = v->vr.frame_gen;
        v->shown_samples = v->vr.samples;
    }
    if (fresh || v->refresh) v->showing_denoised = denoised;
    if (v->save_pending && v->vr.frame_gen == v->gen && v->vr.frame_prefix) {
        memcpy(v->save_rgb, v->vr.rgb, (size_t)v->w * v->h * 3u * sizeof *v->save_rgb);
        save = 1;
        save_samples = v->vr.samples;
        v->save_pending = 0;
    }
    pthread_mutex_unlock(&v->vr.lock);
    if (fresh || v->refresh) frame_draw(v);
    v->refresh = 0;
    if (announce && !v->cfg->quiet)
        fprintf(stderr, "clpt: viewer: showing the %llu-spp frame denoised (Open Image Denoise, %.2f s)\n",
                (unsigned long long)v->shown_samples, denoise_secs);
    if (save) frame_save(v, save_samples);
}

/* ------------------------------------------------------------------ input */

static void camera_changed(Viewer *v)
{
    v->moved = 1;
}

static void key_down(Viewer *v, const SDL_KeyboardEvent *k)
{
    double s = v->step;
    switch (k->keysym.sym) {
    case SDLK_w: view_camera_move(&v->cam, 0, 0, s); break;
    case SDLK_s: view_camera_move(&v->cam, 0, 0, -s); break;
    case SDLK_a: view_camera_move(&v->cam, -s, 0, 0); break;
    case SDLK_d: view_camera_move(&v->cam, s, 0, 0); break;
    case SDLK_r: case SDLK_q: view_camera_move(&v->cam, 0, s, 0); break;
    case SDLK_f: case SDLK_e: view_camera_move(&v->cam, 0, -s, 0); break;
    case SDLK_z: view_camera_zoom(&v->cam, 1.0 / 1.1); break;
    case SDLK_x: view_camera_zoom(&v->cam, 1.1); break;
    case SDLK_UP: view_camera_focus(&v->cam, 1.1); break;
    case SDLK_DOWN: view_camera_focus(&v->cam, 1.0 / 1.1); break;
    case SDLK_RIGHT: view_camera_aperture(&v->cam, 1.25, v->aperture_first); break;
    case SDLK_LEFT: view_camera_aperture(&v->cam, 1.0 / 1.25, v->aperture_first); break;
    case SDLK_PLUS: case SDLK_EQUALS: case SDLK_KP_PLUS:
        v->exposure += 0.5;
        lut_fill(v);
        v->refresh = 1;
        return;
    case SDLK_MINUS: case SDLK_KP_MINUS:
        v->exposure -= 0.5;
        lut_fill(v);
        v->refresh = 1;
        return;
    case SDLK_v:
        v->view = v->view == VIEW_STANDARD ? VIEW_AGX : v->view == VIEW_AGX ? VIEW_FILMIC : VIEW_STANDARD;
        v->refresh = 1;
        return;
    case SDLK_n:
        v->denoise = !v->denoise;
        viewer_render_set_denoise(&v->vr, v->denoise);
        if (!v->cfg->quiet)
            fprintf(stderr, "clpt: viewer: denoised view %s\n", v->denoise ? "on (each finished pass)" : "off");
        v->refresh = 1;
        return;
    case SDLK_SPACE:
        v->paused = !v->paused;
        viewer_render_set_paused(&v->vr, v->paused);
        return;
    case SDLK_c: v->save_pending = 1; return;
    case SDLK_p:
        view_camera_print(stdout, &v->cam);
        fflush(stdout);
        return;
    case SDLK_h:
        v->help = !v->help;
        if (v->help) fputs(HELP_TEXT, stderr);
        return;
    case SDLK_F11:
        v->fullscreen = !v->fullscreen;
        SDL_SetWindowFullscreen(v->win, v->fullscreen ? SDL_WINDOW_FULLSCREEN_DESKTOP : 0);
        v->refresh = 1;
        return;
    case SDLK_ESCAPE: v->quit = 1; return;
    default: return;
    }
    camera_changed(v);
}

static void event_handle(Viewer *v, const SDL_Event *e)
{
    switch (e->type) {
    case SDL_QUIT: v->quit = 1; break;
    case SDL_KEYDOWN: key_down(v, &e->key); break;
    case SDL_MOUSEMOTION:
        if (e->motion.state & SDL_BUTTON_LMASK) {
            v->drag_x += e->motion.xrel;
            v->drag_y += e->motion.yrel;
        }
        break;
    case SDL_MOUSEWHEEL: {
        int dy = e->wheel.direction == SDL_MOUSEWHEEL_FLIPPED ? -e->wheel.y : e->wheel.y;
        if (dy) {
            view_camera_move(&v->cam, 0, 0, v->step * dy);
            camera_changed(v);
        }
        break;
    }
    case SDL_WINDOWEVENT: v->refresh = 1; break;
    default: break;
    }
}

/* A drag turns the camera by the angle the pointer moved over: the point under the
 * pointer stays under it, as far as a pinhole allows. */
static void drag_apply(Viewer *v)
{
    if (v->drag_x == 0.0 && v->drag_y == 0.0) return;
    int ww = 0, wh = 0;
    SDL_GetWindowSize(v->win, &ww, &wh);
    double per_pixel = (double)v->cam.vfov / (wh > 0 ? wh : (int)v->h);
    if (view_camera_turn(&v->cam, v->drag_x * per_pixel, -v->drag_y * per_pixel)) camera_changed(v);
    v->drag_x = v->drag_y = 0.0;
}

/* One round: waits briefly for input, handles everything queued, hands a changed
 * camera to the render thread, draws a new frame. */
static void loop_once(Viewer *v)
{
    SDL_Event e;
    v->moved = 0;
    if (SDL_WaitEventTimeout(&e, LOOP_MS)) {
        event_handle(v, &e);
        while (SDL_PollEvent(&e)) event_handle(v, &e);
    }
    drag_apply(v);
    if (v->moved) {
        v->gen++;
        viewer_render_set_camera(&v->vr, &v->cam);
        v->change_time = timer_now();
        v->waiting_frame = 1;
    }
    frame_take(v);
    double now = timer_now();
    if (v->loops && now - v->last_loop > v->longest_gap) v->longest_gap = now - v->last_loop;
    v->last_loop = now;
    v->loops++;
    if (now - v->title_time >= 0.25) {
        title_update(v);
        v->title_time = now;
    }
}

/* ------------------------------------------------------------------ setup */

/* Rendering keeps every core busy; the window's thread needs a few milliseconds at a
 * time and must get them at once. So every other thread of the process (the render
 * thread, the scalar device's workers, PoCL's) runs at a lower priority (nice + 5;
 * raising one's own nice value needs no privilege), and the threads they start later
 * inherit it. Linux only: elsewhere /proc/self/task is missing and nothing changes. */
static void threads_lower_priority(void)
{
    DIR *dir = opendir("/proc/self/task");
    if (!dir) return;
    long self = syscall(SYS_gettid);
    int base = getpriority(PRIO_PROCESS, 0);
    struct dirent *e;
    while ((e = readdir(dir)) != NULL) {
        long tid = strtol(e->d_name, NULL, 10);
        if (tid > 0 && tid != self) setpriority(PRIO_PROCESS, (id_t)tid, base + 5);
    }
    closedir(dir);
}

static void devices_describe(Viewer *v)
{
    size_t len = 0;
    v->devices[0] = '\0';
    for (size_t i = 0; i < v->cfg->n_devices && len + 2 < sizeof v->devices; i++)
        len += (size_t)snprintf(v->devices + len, sizeof v->devices - len, "%s%s", i ? ", " : "",
                                v->cfg->devices[i]->desc.name);
}

/* Steps scale with the scene: 2% of its bounding box's diagonal per key press (the eye's
 * distance to its target when the box is empty: planes only). */
static void steps_choose(Viewer *v)
{
    const RenderParams *p = &v->cfg->rs->ds.params;
    double dx = (double)p->bounds_hi.x - p->bounds_lo.x, dy = (double)p->bounds_hi.y - p->bounds_lo.y,
           dz = (double)p->bounds_hi.z - p->bounds_lo.z;
    double size = sqrt(dx * dx + dy * dy + dz * dz);
    if (!(size > 0.0) || !isfinite(size)) {
        double ex = (double)v->cam.at.x - v->cam.from.x, ey = (double)v->cam.at.y - v->cam.from.y,
               ez = (double)v->cam.at.z - v->cam.from.z;
        size = sqrt(ex * ex + ey * ey + ez * ez);
    }
    v->step = 0.02 * size;
    v->aperture_first = 0.005 * size;
}

static Status window_open(Viewer *v, Error *err)
{
    int ww = (int)v->w, wh = (int)v->h;
    SDL_Rect usable;
    if (SDL_GetDisplayUsableBounds(0, &usable) == 0 && usable.w > 0 && usable.h > 0) {
        double f = fmin(1.0, fmin((double)usable.w / ww, (double)usable.h / wh));
        ww = (int)(ww * f) > 0 ? (int)(ww * f) : 1;
        wh = (int)(wh * f) > 0 ? (int)(wh * f) : 1;
    }
    v->win = SDL_CreateWindow("clpt", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, ww, wh, SDL_WINDOW_RESIZABLE);
    if (!v->win) return error_set(err, ST_DEVICE, "cannot open the viewer's window: %s", SDL_GetError());
    /* The window shows one image a few times a second: SDL's software renderer (X shared
     * memory) costs well under a millisecond a frame, while its OpenGL renderer on a
     * machine without a GPU is Mesa's llvmpipe, whose threads take cores from the
     * render. SDL_RENDER_DRIVER (SDL's own variable) still chooses another. */
    v->ren = SDL_CreateRenderer(v->win, -1, env_set("SDL_RENDER_DRIVER") ? 0 : SDL_RENDERER_SOFTWARE);
    if (!v->ren) v->ren = SDL_CreateRenderer(v->win, -1, 0);
    if (!v->ren) return error_set(err, ST_DEVICE, "cannot draw in the viewer's window: %s", SDL_GetError());
    SDL_RenderSetLogicalSize(v->ren, (int)v->w, (int)v->h);
    v->tex = SDL_CreateTexture(v->ren, SDL_PIXELFORMAT_RGB24, SDL_TEXTUREACCESS_STREAMING, (int)v->w, (int)v->h);
    if (!v->tex) return error_set(err, ST_DEVICE, "cannot make the viewer's image: %s", SDL_GetError());
    return ST_OK;
}

static void window_close(Viewer *v)
{
    if (v->tex) SDL_DestroyTexture(v->tex);
    if (v->ren) SDL_DestroyRenderer(v->ren);
    if (v->win) SDL_DestroyWindow(v->win);
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* --stats: how responsive the window was, and the rendering speed of the last view. */
static void stats_print(Viewer *v)
{
    double secs = timer_now() - v->t_start;
    printf("viewer: %.1f s: %lu input rounds (%.1f per second, longest gap %.1f ms), %lu frames drawn (%.1f per second)\n",
           secs, v->loops, (double)v->loops / secs, 1e3 * v->longest_gap, v->draws, (double)v->draws / secs);
    if (v->n_latencies) {
        qsort(v->latencies, v->n_latencies, sizeof *v->latencies, compare_double);
        printf("viewer: camera change to its first frame drawn: %u changes, median %.1f ms, max %.1f ms\n",
               v->n_latencies, 1e3 * v->latencies[v->n_latencies / 2], 1e3 * v->latencies[v->n_latencies - 1]);
    }
    pthread_mutex_lock(&v->vr.lock);
    double msps = v->vr.view_seconds > 0.0 ? v->vr.view_samples / v->vr.view_seconds / 1e6 : 0.0;
    printf("viewer: last view: %llu spp, %.0f samples in %.2f s of passes: %.3f Msamples/s\n",
           (unsigned long long)v->shown_samples, v->vr.view_samples, v->vr.view_seconds, msps);
    if (v->vr.denoise_count)
        printf("viewer: %u frames denoised, %.3f s each on average\n", v->vr.denoise_count,
               v->vr.denoise_seconds / v->vr.denoise_count);
    if (v->vr.denoise_cancels) printf("viewer: %u denoises cancelled (the view changed, a pause, N off)\n", v->vr.denoise_cancels);
    pthread_mutex_unlock(&v->vr.lock);
}

Status viewer_run(const ViewerConfig *cfg, Error *err)
{
    Viewer *v = calloc(1, sizeof *v);
    if (!v) return error_set(err, ST_INTERNAL, "out of memory");
    v->cfg = cfg;
    v->w = cfg->rs->ds.params.width;
    v->h = cfg->rs->ds.params.height;
    v->cam = cfg->scene->camera;
    v->gen = 1;
    v->t_start = timer_now();
    v->exposure = cfg->style.look.exposure;
    v->view = cfg->style.look.view;
    v->denoise = cfg->denoiser != NULL;
    lut_fill(v);
    steps_choose(v);
    devices_describe(v);
    Status st = ST_OK;
    size_t n = (size_t)v->w * v->h * 3u;
    v->pixels = calloc(n, 1);
    v->save_rgb = malloc(n * sizeof *v->save_rgb);
    if (!v->pixels || !v->save_rgb) st = error_set(err, ST_INTERNAL, "out of memory for the viewer's images");
    if (st == ST_OK) st = window_open(v, err);
    if (st == ST_OK)
        st = viewer_render_start(&v->vr, cfg->devices, cfg->n_devices, &cfg->rs->ds, &cfg->device_config, &v->cam,
                                 cfg->scene->image.spp, cfg->fixed_batch, cfg->denoiser, err);
    if (st == ST_OK) {
        threads_lower_priority();
        if (!cfg->quiet)
            fprintf(stderr, "clpt: viewer: %ux%u, up to %u spp on %s; press H for the keys, Esc to quit\n", v->w,
                    v->h, cfg->scene->image.spp, v->devices);
        v->refresh = 1;
        while (!v->quit) loop_once(v);
        if (cfg->stats) stats_print(v);
        st = viewer_render_stop(&v->vr, err);
    }
    window_close(v);
    free(v->pixels);
    free(v->save_rgb);
    free(v);
    return st;
}
