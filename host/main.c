/*
 * main.c — command line → outputs checked → scene → kd-tree → devices → render →
 * checkpoint and image → exit code.
 *
 * The whole life of a render reads top to bottom in run(), one named step a line.
 * Errors travel up as Status values with their message in one Error, printed once here;
 * the status is the exit code.
 */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dist/merge.h"
#include "dist/mpi_driver.h"
#include "dist/mpi_job.h"
#include "job_options.h"
#include "render/adaptive.h"
#include "render/display.h"
#include "device/device.h"
#include "device/ocl_program.h"
#include "render/film.h"
#include "io/image_write.h"
#include "options.h"
#include "outputs.h"
#include "render/passes.h"
#include "base/progress.h"
#include "render/render_job.h"
#include "scene/scene.h"
#include "scene_options.h"
#include "stop_signal.h"
#include "render/schedule.h"
#include "render/stats.h"
#include "io/scene_load.h"
#include "base/timer.h"
#include "version.h"
#include "viewer/viewer.h"

/* What the render's hooks need of the run: its output and the live display (the job,
 * render_job.h, holds the rest, and hands this to the hooks as its `user`). */
typedef struct {
    const char *output;
    int progressive_failed;
    ImageStyle style;
    double progressive_seconds;   /* 0: no progressive output */
    double last_progressive;      /* when the output was last rewritten */
    Display *display;             /* --display-server; NULL: none, or the connection was lost */
    uint width, height;           /* the image's */
} RenderContext;

/* On a terminal the progress bar may be on the line: the warning first clears it. In
 * a log (stderr not a terminal) there is no bar, and escape codes would be noise. */
static void print_warning(void *ctx, const char *msg)
{
    (void)ctx;
    fprintf(stderr, "%sclpt: warning: %s\n", isatty(STDERR_FILENO) ? "\r\033[K" : "", msg);
}

/* An error that is not the run's exit status (that one is printed by main). */
static void print_error(const Error *e)
{
    fprintf(stderr, "clpt: error: %s\n", e->msg);
}

/* The run's status stays the first failure: a later one (`next`, its message in
 * `next_err`) is printed on its own, or becomes the status when there was none. */
static Status keep_first(Status st, Error *err, Status next, Error *next_err)
{
    if (next == ST_OK) return st;
    if (st != ST_OK) {
        print_error(next_err);
        error_clear(next_err);
        return st;
    }
    error_clear(err);
    *err = *next_err;
    return next;
}

/* The live display (--display-server) gets rgb; a lost connection is said once, and
 * the display is dropped (the render goes on). */
static void display_send(RenderContext *ctx, const float *rgb)
{
    Error err = { 0 };
    if (ctx->display && display_update(ctx->display, rgb, &err) != ST_OK) {
        print_warning(NULL, err.msg);
        display_close(ctx->display);
        ctx->display = NULL;
    }
    error_clear(&err);
}

/* The film as it is now (or, without one, the job's image), to the live display. */
static void display_send_film(RenderContext *ctx, const Film *film, const RenderJob *job)
{
    if (!ctx->display) return;
    float *rgb = malloc((size_t)ctx->width * ctx->height * 3u * sizeof *rgb);
    if (!rgb) return;   /* the next tick tries again */
    if (film) film_resolve(film, rgb);
    else render_job_resolve(job, rgb);
    display_send(ctx, rgb);
    free(rgb);
}

/* The periodic tick: progressive output rewrites the image (atomically, so a viewer
 * never sees half a file) every progressive_seconds, a failure reported once and not
 * stopping the render; the live display gets the image every tick. */
static void on_progress_tick(void *vjob, const ScheduleSnapshot *snap)
{
    RenderContext *ctx = ((RenderJob *)vjob)->user;
    display_send_film(ctx, snap->film, NULL);
    double now = timer_now();
    /* ticks come at the progressive interval or sooner; the 0.1% slack keeps a tick that
     * arrives a hair early at the same interval from being skipped */
    if (ctx->progressive_seconds <= 0.0 || now - ctx->last_progressive < ctx->progressive_seconds * 0.999) return;
    ctx->last_progressive = now;
    Error err = { 0 };
    if (film_write(snap->film, ctx->output, &ctx->style, &err) != ST_OK && !ctx->progressive_failed) {
        ctx->progressive_failed = 1;
        print_warning(NULL, err.msg);
    }
    error_clear(&err);
}

static void on_denoised(void *vctx, const float *rgb)
{
    display_send(vctx, rgb);
}

/* After each round of an adaptive render: progressive output, at most as often as its
 * interval (a round's film is whole; the scheduler's snapshots in the middle of one
 * are not the render's state). The job writes the checkpoints. */
static void on_adaptive_round(void *vjob, const AdaptiveFilm *af)
{
    RenderContext *ctx = ((RenderJob *)vjob)->user;
    Error err = { 0 };
    double now = timer_now();
    if (ctx->progressive_seconds <= 0.0 || now - ctx->last_progressive < ctx->progressive_seconds) return;
    ctx->last_progressive = now;
    if (adaptive_film_write(af, ctx->output, &ctx->style, &err) != ST_OK && !ctx->progressive_failed) {
        ctx->progressive_failed = 1;
        print_warning(NULL, err.msg);
    }
    error_clear(&err);
}

/* Everything one render holds, freed by run_free whatever step failed. */
typedef struct {
    Options o;
    const char *output;
    char *default_out;
    ImageStyle style;
    int bare_mesh;
    Scene scene;
    RenderJob job;                /* the render itself (render/render_job.h) */
    RenderContext ctx;
    double t_start;
    int frames;                   /* --frames: this render is one frame of an animation */
    FILE *report;                 /* --stats and --profile: stdout, stderr when the image goes there */
} Run;

static void run_free(Run *r)
{
    render_job_free(&r->job);
    display_close(r->ctx.display);
    scene_free(&r->scene);
    free(r->default_out);
}

/* The chosen devices, each given the scene; "compiling kernels..." said unless quiet. */
static Status open_devices(Run *r, Error *err)
{
    ocl_program_announce_builds(!r->o.quiet);
    return render_job_open_devices(&r->job, err);
}

/* --help, --version and --list-devices: print and exit. *done tells whether one ran. */
static Status run_info_command(const Options *o, int *done, Error *err)
{
    *done = o->help || o->version || o->list_devices;
    if (o->help) {
        options_print_help(stdout);
    } else if (o->version) {
        printf("clpt %s (commit %s)\n", clpt_version_text, clpt_commit);
    } else if (o->list_devices) {
        DeviceDesc *all = NULL;
        size_t n = 0;
        char warning[1100];
        Status st = device_list(&all, &n, warning, sizeof warning, err);
        if (st) return st;
        if (warning[0]) print_warning(NULL, warning);
        device_list_print(stdout, all, n);
        free(all);
    }
    return ST_OK;
}

/* The render job from the command line; the program's warnings, and its hooks' state. */
static void job_init(Run *r)
{
    RenderJobSettings set = job_options_settings(&r->o);
    render_job_init(&r->job, &set, print_warning, NULL, &r->ctx);
}

/* --display-server: connected once the image's size is known, before the render. A
 * server that cannot be reached is a warning: the render is what was asked for. */
static void display_prepare(Run *r)
{
    if (!r->o.display_server) return;
    const char *base = strrchr(r->output, '/');
    Error err = { 0 };
    if (display_open(r->o.display_server, base ? base + 1 : r->output, r->job.film.width, r->job.film.height,
                     &r->ctx.display, &err) != ST_OK)
        print_warning(NULL, err.msg);
    error_clear(&err);
}

/* ------------------------------------------------------------------ scene */

/* The input file as a scene: a mesh file given in place of a scene is shown in a scene
 * made around it. */
static Status load_scene_input(const Options *o, Scene *scene, int *bare_mesh, Error *err)
{
    SceneKind kind = SCENE_KIND_CLPT;
    Status st = scene_options_before_load(o, scene, err);
    if (st == ST_OK) st = scene_load_file(o->scene_path, (SceneFormat)o->format, scene, &kind, err);
    *bare_mesh = st == ST_OK && kind == SCENE_KIND_MESH;
    if (st == ST_OK)
        for (size_t i = 0; i < scene->n_warnings; i++) print_warning(NULL, scene->warnings[i]);
    return st;
}

/* The command line's overrides, checked against the scene they apply to. */
/* --time T: the scene posed at T seconds of its animation, as frame T*FPS of --frames
 * would be (the same pose, then the camera flags again: frame_render's order), so a
 * time on a frame gives that frame's bits. A time after the animation's end is refused
 * as a frame after it is (the same microsecond's slack), not clamped: a still of the
 * last pose is --time at the end. */
static Status pose_at_time(Run *r, Error *err)
{
    SceneAnimation *anim = r->scene.animation;
    double t = r->o.anim_time;
    if (!anim)
        return error_set(err, ST_USAGE, "--time poses the animation of a glTF file given as the scene, or a clpt "
                         "scene's camera_path; '%s' has neither", r->o.scene_path);
    if (t > anim->end + 1e-6)
        return error_set(err, ST_USAGE, "--time %g is after the end of the animation of '%s' at %g s", t,
                         r->o.scene_path, anim->end);
    Status st = anim->pose(anim, &r->scene, t, err);
    return st == ST_OK ? scene_options_apply_camera(&r->o, &r->scene, err) : st;
}

/* --shutter A:B: the scene's animation sampled over the shutter (motion blur,
 * docs/motion.md); a close after the end is refused as --time's is. */
static Status pose_over_shutter(Run *r, Error *err)
{
    SceneAnimation *anim = r->scene.animation;
    double open = r->o.shutter_open, close = r->o.shutter_close;
    if (!anim || !anim->pose_shutter)
        return error_set(err, ST_USAGE, "--shutter blurs the animation of a glTF file given as the scene; '%s' is "
                         "not one", r->o.scene_path);
    if (anim->end > 0.0 && close > anim->end + 1e-6)
        return error_set(err, ST_USAGE, "--shutter %g:%g closes after the end of the animation of '%s' at %g s", open,
                         close, r->o.scene_path, anim->end);
    Status st = anim->pose_shutter(anim, &r->scene, open, close, err);
    return st == ST_OK ? scene_options_apply_camera(&r->o, &r->scene, err) : st;
}

static Status scene_apply_options(Run *r, Error *err)
{
    Status st = scene_options_apply(&r->o, &r->scene, r->bare_mesh, err);
    if (st == ST_OK && r->o.anim_time >= 0.0) st = pose_at_time(r, err);
    if (st == ST_OK && r->o.shutter_close > r->o.shutter_open) st = pose_over_shutter(r, err);
    r->style.encoding = (ImageEncoding)((r->scene.linear_output ? IMAGE_LINEAR : IMAGE_SRGB) |
                                        (r->o.exr_float ? IMAGE_EXR_FLOAT : 0) | (r->o.png_depth == 16 ? IMAGE_PNG16 : 0));
    r->style.look = (ViewLook){ (ViewTransform)r->o.view, r->o.exposure };
    r->style.jpeg_quality = r->o.jpeg_quality;
    return st;
}

/* kd-tree and device buffers, the film (from --resume), and the render's identity where
 * something compares or records it (render_job_prepare_film). --stats describes the
 * scene as the devices get it. */
static Status render_prepare(Run *r, int worker, int keyed, Error *err)
{
    Status st = render_job_prepare_scene(&r->job, &r->scene, err);
    if (st == ST_OK && r->o.stats == STATS_TEXT && !worker) render_stats_print_scene(r->report, &r->scene, &r->job.rs);
    return st == ST_OK ? render_job_prepare_film(&r->job, keyed, worker, err) : st;
}

/* ------------------------------------------------------------------ render */

/* The job's scheduler settings, and the program's hooks: the progress bar, the stop
 * signal, progressive output and the live display. */
static void render_configure(Run *r)
{
    const Options *o = &r->o;
    RenderJob *job = &r->job;
    ScheduleConfig *cfg = &job->cfg;
    render_job_configure(job);
    r->ctx.output = r->output;
    r->ctx.style = r->style;
    r->ctx.width = job->film.width;
    r->ctx.height = job->film.height;
    cfg->show_progress = progress_should_enable(o->quiet);
    cfg->stop = &stop_requested;
    /* one tick serves both: the display's every second (or sooner, for progressive
     * output more often), progressive output at its own interval */
    r->ctx.progressive_seconds = o->progressive_seconds;
    r->ctx.last_progressive = timer_now();
    cfg->on_tick = o->progressive_seconds > 0.0 || r->ctx.display ? on_progress_tick : NULL;
    cfg->tick_seconds = !r->ctx.display ? o->progressive_seconds
                      : o->progressive_seconds > 0.0 && o->progressive_seconds < 1.0 ? o->progressive_seconds : 1.0;
    job->on_round = on_adaptive_round;
}

/* The render itself, this process's devices joined by the other ranks' under MPI. Its
 * status is kept apart (job.render_st): after a failure or an interrupt, what was
 * finished is still saved. */
static void render_run(Run *r, Dist *dist, Error *err)
{
    install_signal_handlers(dist->active ? STOP_SAY_MPI : STOP_SAY);
    render_configure(r);
    if (dist->active) {
        /* the other ranks join the render as devices of this one */
        dist->spp = r->scene.image.spp;
        r->job.render_st = dist_add_remote_devices(dist, r->job.film.width * r->job.film.height, &r->job.devs,
                                                   &r->job.n_devs, err);
        if (r->job.render_st != ST_OK) return;
    }
    render_job_run(&r->job, err);
}

/* ------------------------------------------------------------------ results */

/* No batch finished: the outputs are left as they were (a black image over a good one
 * helps nobody), and the exit status says so. */
static Status results_nothing_rendered(const Run *r, Error *err)
{
    if (r->job.render_st != ST_OK) return r->job.render_st;
    if (r->job.stats.interrupted) {
        fprintf(stderr, "clpt: interrupted before the first batch finished: nothing was rendered, and '%s' was "
                        "left as it was\n", r->output);
        return ST_INTERRUPTED;
    }
    return error_set(err, ST_NOTHING_RENDERED,
                     "the time limit of %g s was reached before the first batch finished: nothing was rendered, "
                     "and '%s' was left as it was (allow more time, or a smaller --batch)",
                     r->o.time_limit, r->output);
}

/* The output as the summary names it. */
static const char *output_name(const char *output)
{
    return image_path_is_stdout(output) ? "standard output" : output;
}

/* --stats=json: the run as one object (stats.h). */
static void results_print_json(const Run *r, const char *result)
{
    RenderStatsRun run = { clpt_version_text, r->o.scene_path, output_name(r->output), result, r->job.film.width,
                           r->job.film.height, r->scene.image.spp, timer_now() - r->t_start, &r->job.split_pilot };
    render_stats_print_json(r->report, &run, &r->scene, &r->job.stats);
}

static void results_print_summary(const Run *r)
{
    const RenderJob *job = &r->job;
    const ScheduleStats *s = &job->stats;
    if (r->o.stats == STATS_JSON) results_print_json(r, render_stats_result(s));
    else if (r->o.stats || r->o.profile) {
        if (r->scene.integrator == INTEGRATOR_PATH)
            render_stats_print_split(r->report, &job->split_pilot, r->scene.image.split);
        render_stats_print_run(r->report, s, r->scene.image.spp, job->devs, job->n_devs);
    }
    if (r->o.profile) {
        render_stats_print_profile(r->report, s, job->devs, job->n_devs);
        if (job->rs.ds.params.split > 1 && r->scene.integrator == INTEGRATOR_PATH)
            fprintf(r->report, "profile: with --split, OpenCL devices run each path as one kernel (k_path), whose "
                    "time is all under shade\n");
    }
    if (r->o.quiet && job->render_st == ST_OK && !s->interrupted) return;
    render_stats_print_summary(stderr, job, timer_now() - r->t_start, output_name(r->output));
}

/* The adaptive pass, the denoiser and the auxiliary images, after a complete main
 * image (passes.h). */
static Status results_run_passes(Run *r, Error *err)
{
    RenderJob *job = &r->job;
    float *rgb = malloc((size_t)job->film.width * job->film.height * 3u * sizeof *rgb);
    if (!rgb) return error_set(err, ST_INTERNAL, "out of memory");
    render_job_resolve(job, rgb);
    ScheduleConfig pcfg;
    PassContext pc;
    render_job_pass_context(job, &pcfg, &pc);
    pc.on_denoised = on_denoised;
    pc.on_denoised_ctx = &r->ctx;
    PassRequest q = outputs_pass_request(&r->o);
    Status st = passes_after_image(&q, &pc, r->output, &r->style, rgb, (uint)job->film.samples, err);
    free(rgb);
    if (st == ST_OK && stop_requested) st = ST_INTERRUPTED;
    return st;
}

/* Whatever was finished is saved, also after an interrupt or device failures: the
 * checkpoint, then the image. The status is the first failure: the render's, else the
 * interrupt, else a write's. */
static Status results_write(Run *r, Error *err)
{
    RenderJob *job = &r->job;
    if (job->film.samples == 0) return results_nothing_rendered(r, err);
    Status st = job->render_st != ST_OK ? job->render_st : (job->stats.interrupted ? ST_INTERRUPTED : ST_OK);
    Error next = { 0 };
    st = keep_first(st, err, render_job_final_checkpoint(job, &next), &next);
    /* an animation's frame is written whole or not at all: a rerun skips the frames
     * whose images are there (run_frames) and resumes this one from its checkpoint */
    if (r->frames && !render_job_complete(job)) {
        if (!r->o.quiet)
            fprintf(stderr, "clpt: the frame is unfinished: '%s' is not written%s\n", r->output,
                    r->job.set.checkpoint_path ? "; --resume goes on from its checkpoint" : "");
        return st != ST_OK ? st : error_set(err, ST_NOTHING_RENDERED, "the time limit of %g s was reached before "
                                            "the frame was finished: '%s' is not written", r->o.time_limit,
                                            r->output);
    }
    Status image_st = render_job_write_image(job, r->output, &r->style, &next);
    st = keep_first(st, err, image_st, &next);
    if (image_st != ST_OK) return st;   /* the summary's "-> OUTPUT" would be untrue */
    /* an adaptive render's image is not its film's: the job resolves it */
    display_send_film(&r->ctx, NULL, job);
    results_print_summary(r);
    /* a --denoise part keeps the denoiser's inputs for merge instead of denoising its
     * share (render_job_part_features) */
    int part = r->o.range_end >= 0;
    if (st == ST_OK && part && r->o.denoise) st = render_job_part_features(job, err);
    if (st == ST_OK && (r->o.adaptive > 0.0 || r->o.aovs || (r->o.denoise && !part))) st = results_run_passes(r, err);
    return st;
}

/* ------------------------------------------------------------------ frames */

/* The last frame of the scene's animation at --fps: the last whose time is at or before
 * the last key (a microsecond's slack for key times stored as floats). */
static long frames_last_of(const Run *r)
{
    return (long)floor(r->scene.animation->end * r->o.fps + 1e-6);
}

/* --frames A:B against the scene: it has an animation, and B is within it. */
static Status frames_check(const Run *r, Error *err)
{
    if (!r->scene.animation)
        return error_set(err, ST_USAGE, "--frames renders the animation of a glTF file given as the scene, or a "
                         "clpt scene's camera_path; '%s' has neither", r->o.scene_path);
    if (r->o.shutter_fraction > 0.0 && !r->scene.animation->pose_shutter)
        return error_set(err, ST_USAGE, "--shutter blurs the animation of a glTF file given as the scene; '%s' is "
                         "not one", r->o.scene_path);
    long last = frames_last_of(r);
    if (r->o.frames_last > last)
        return error_set(err, ST_USAGE, "--frames %ld:%ld: frame %ld (at %g s) is after the end of the animation of "
                         "'%s' at %g s; at %g frames per second its frames are 0 to %ld", r->o.frames_first,
                         r->o.frames_last, r->o.frames_last, (double)r->o.frames_last / r->o.fps, r->o.scene_path,
                         r->scene.animation->end, r->o.fps, last);
    return ST_OK;
}

/* Frame k's names: the image, and the checkpoint and the one to resume (NULL when
 * none: a frame resumes from its own checkpoint only when it is there). */
typedef struct {
    char *output, *checkpoint, *resume;
} FramePaths;

static void frame_paths_free(FramePaths *p)
{
    free(p->output);
    free(p->checkpoint);
    free(p->resume);
}

static Status frame_paths(const Run *r, const char *base_output, long k, FramePaths *p, Error *err)
{
    memset(p, 0, sizeof *p);
    int failed = !(p->output = outputs_frame_path(base_output, k));
    if (r->o.checkpoint_path) failed |= !(p->checkpoint = outputs_frame_path(r->o.checkpoint_path, k));
    if (r->o.resume_path) {
        failed |= !(p->resume = outputs_frame_path(r->o.resume_path, k));
        if (p->resume && access(p->resume, F_OK) != 0) {
            free(p->resume);
            p->resume = NULL;
        }
    }
    return failed ? error_set(err, ST_INTERNAL, "out of memory") : ST_OK;
}

/* What one frame hands the next: the devices (opened by the first frame: nothing is
 * compiled again), the run's denoiser, and for an animation of the camera alone the
 * prepared scene with its parameters as prepared (before any pass changed them). */
typedef struct {
    Device **devs;
    size_t n_devs;
    Denoiser *denoiser;
    RenderScene rs;
    RenderParams params;
    int have_rs;
} FrameCarry;

/* The frame's scene prepared: in full, or (the camera alone moving, and a scene
 * prepared before) the kept one with the new camera; then the film. */
static Status frame_prepare(Run *r, FrameCarry *c, Error *err)
{
    if (!c->have_rs) {
        Status st = render_prepare(r, 0, 0, err);
        c->params = r->job.rs.ds.params;
        return st;
    }
    c->rs.ds.params = c->params;
    c->have_rs = 0;   /* the job holds it until render_job_take_scene */
    Status st = render_job_adopt_scene(&r->job, &r->scene, &c->rs, err);
    return st == ST_OK ? render_job_prepare_film(&r->job, 0, 0, err) : st;
}

/* One frame: the scene posed at its time, prepared, given to the devices, rendered and
 * written. */
static Status frame_render(Run *r, Dist *dist, long k, const FramePaths *p, FrameCarry *c, Error *err)
{
    RenderJobSettings set = job_options_settings(&r->o);
    set.checkpoint_path = p->checkpoint;
    set.resume_path = p->resume;
    render_job_init(&r->job, &set, print_warning, NULL, &r->ctx);
    r->job.denoiser = c->denoiser;   /* the run's, lent to each frame */
    r->output = p->output;
    if (!r->o.quiet) fprintf(stderr, "clpt: frame %ld (%g s) -> %s\n", k, (double)k / r->o.fps, p->output);
    SceneAnimation *anim = r->scene.animation;
    int kept = c->have_rs;
    /* --shutter F: open from the frame's time for F of a frame's time; a last frame's
     * shutter may run past the animation's end, where the last pose holds */
    double t = (double)k / r->o.fps;
    Status st = r->o.shutter_fraction > 0.0
              ? anim->pose_shutter(anim, &r->scene, t, t + r->o.shutter_fraction / r->o.fps, err)
              : anim->pose(anim, &r->scene, t, err);
    if (st == ST_OK) st = scene_options_apply_camera(&r->o, &r->scene, err);
    if (st == ST_OK) st = frame_prepare(r, c, err);
    if (st == ST_OK && c->devs && kept) st = render_job_update_devices(&r->job, c->devs, c->n_devs, err);
    else if (st == ST_OK && c->devs) st = render_job_adopt_devices(&r->job, c->devs, c->n_devs, err);
    else if (st == ST_OK) st = open_devices(r, err);
    if (st == ST_OK) {
        render_run(r, dist, err);
        st = results_write(r, err);
    }
    render_job_take_devices(&r->job, &c->devs, &c->n_devs);
    if (anim->camera_only && st == ST_OK) {
        render_job_take_scene(&r->job, &c->rs);
        c->have_rs = 1;
    }
    r->job.denoiser = NULL;
    render_job_free(&r->job);
    memset(&r->job, 0, sizeof r->job);
    return st;
}

/* --frames A:B: each frame to its numbered image (outputs_frame_path); a frame whose
 * image is there already is skipped, so a rerun of an interrupted animation goes on
 * where it stopped. */
static Status run_frames(Run *r, Dist *dist, Error *err)
{
    Status st = frames_check(r, err);
    const char *base_output = r->output;
    FrameCarry c;
    memset(&c, 0, sizeof c);
    r->frames = 1;
    /* a blurred frame places the whole scene (camera keys are no camera-only change) */
    if (st == ST_OK && r->o.shutter_fraction > 0.0) r->scene.animation->camera_only = 0;
    /* each frame is a job of its own; the run's denoiser (--denoise) serves them all */
    c.denoiser = r->job.denoiser;
    r->job.denoiser = NULL;
    render_job_free(&r->job);
    memset(&r->job, 0, sizeof r->job);
    for (long k = r->o.frames_first; k <= r->o.frames_last && st == ST_OK; k++) {
        FramePaths p;
        st = frame_paths(r, base_output, k, &p, err);
        if (st == ST_OK && access(p.output, F_OK) == 0) {
            if (!r->o.quiet) fprintf(stderr, "clpt: frame %ld: '%s' is there already; skipped\n", k, p.output);
        } else if (st == ST_OK) {
            st = frame_render(r, dist, k, &p, &c, err);
        }
        frame_paths_free(&p);
        if (st == ST_OK && stop_requested) st = ST_INTERRUPTED;
    }
    r->output = base_output;
    for (size_t i = 0; i < c.n_devs; i++) device_close(c.devs[i]);
    free(c.devs);
    render_scene_free(&c.rs);
    r->job.denoiser = c.denoiser;   /* freed with the run's job */
    return st;
}

/* ------------------------------------------------------------------ under MPI */

/* What an MPI job needs of the command line (dist/mpi_job.h). */
static DistRequest dist_request(const Options *o)
{
    DistRequest q = { o->help ? DIST_HELP : o->version ? DIST_VERSION : o->list_devices ? DIST_LIST_DEVICES : DIST_RENDER,
                      o->mpi_broadcast, o->mpi_timeout, o->batch, o->adaptive > 0.0 || o->aovs != 0, o->interactive };
    return q;
}

/* A rank's outputs (rank 0 only) and its prepared scene (unless rank 0 sends it). */
static Status rank_prepare(void *vr, int worker, int receive, Error *err)
{
    Run *r = vr;
    Status st = ST_OK;
    if (!worker) st = outputs_choose(&r->o, &r->output, &r->default_out, err);
    if (st == ST_OK && !worker) st = outputs_check(&r->o, r->output, err);
    if (st == ST_OK && !worker) st = render_job_open_denoiser(&r->job, err);
    if (st == ST_OK && !receive) st = load_scene_input(&r->o, &r->scene, &r->bare_mesh, err);
    if (st == ST_OK && !worker) st = outputs_from_scene(&r->o, &r->scene, &r->output, err);
    if (st == ST_OK && !receive) st = scene_apply_options(r, err);
    if (st == ST_OK && !receive) st = render_prepare(r, worker, 1, err);
    if (st == ST_OK && !worker) display_prepare(r);
    return st;
}

static Status rank_open_devices(void *vr, Error *err)
{
    Run *r = vr;
    return open_devices(r, err);
}

static void rank_worker_starts(void *vr)
{
    (void)vr;
    install_signal_handlers(STOP_QUIET);
}

static Status rank_render(void *vr, Dist *dist, Error *err)
{
    Run *r = vr;
    render_run(r, dist, err);
    return results_write(r, err);
}

/* One rank of an MPI job: its steps, in the order dist_run_rank runs them. */
static Status run_rank(Run *r, Dist *dist, Error *err)
{
    if (dist->rank > 0) r->o.quiet = 1;
    job_init(r);
    DistRankSteps s = { r, rank_prepare, rank_open_devices, rank_worker_starts, rank_render,
                        &r->job.rs.ds, &r->scene.image.spp, &r->job.checkpoint_id, &r->job.devs, &r->job.n_devs,
                        &stop_requested, r->o.stats == STATS_TEXT ? r->report : NULL };
    return dist_run_rank(dist, &s, err);
}

/* --interactive: the display first (without one, nothing slow is done), then the scene
 * and the devices as for a render, then the window (viewer.h) instead of the render. */
static Status run_interactive(Run *r, Error *err)
{
    Status st = viewer_open_display(err);
    if (st != ST_OK) {
        run_free(r);
        return st;
    }
    if (!r->o.wave_paths) r->o.wave_paths = VIEWER_WAVE_PATHS;
    job_init(r);
    st = render_job_open_denoiser(&r->job, err);   /* --denoise: the denoised view starts on */
    if (st == ST_OK) st = load_scene_input(&r->o, &r->scene, &r->bare_mesh, err);
    if (st == ST_OK) st = scene_apply_options(r, err);
    /* the viewer shows the whole image: a scene's crop window (pbrt's) is for renders
     * to a file, and --crop is refused with --interactive */
    r->scene.crop.kind = CROP_NONE;
    if (st == ST_OK) st = render_prepare(r, 0, 0, err);
    if (st == ST_OK) st = open_devices(r, err);
    if (st == ST_OK) {
        ViewerConfig vc = { r->o.scene_path, &r->scene, &r->job.rs, r->job.devs, r->job.n_devs,
                            { r->o.threads, r->o.kernel_dir, r->o.wave_paths, 0, r->o.wave_launch }, r->style,
                            r->o.batch, r->job.denoiser, r->o.stats, r->o.quiet };
        st = viewer_run(&vc, err);
    }
    run_free(r);
    return st;
}

static Status run(int argc, char **argv, Dist *dist, Error *err)
{
    Run r;
    memset(&r, 0, sizeof r);
    scene_init(&r.scene);
    r.t_start = timer_now();
    int done = 0;
    Status st = options_parse(argc, argv, &r.o, err);
    r.report = r.o.output && image_path_is_stdout(r.o.output) ? stderr : stdout;
    if (st == ST_OK && r.o.frames_first >= 0 && dist_launched())
        st = error_set(err, ST_USAGE, "--frames is not rendered under MPI (render the frames in separate runs, "
                       "each with its own --frames range)");
    if (dist_launched()) {
        DistRequest q = dist_request(&r.o);
        st = dist_join(dist, &q, st, err);
    }
    if (st != ST_OK) return st;
    if (dist->rank == 0) st = run_info_command(&r.o, &done, err);
    if (st != ST_OK || done || r.o.help || r.o.version || r.o.list_devices) return st;

    if (dist->active) {
        st = run_rank(&r, dist, err);
        run_free(&r);
        return st;
    }
    if (r.o.interactive) return run_interactive(&r, err);
    job_init(&r);
    st = outputs_choose(&r.o, &r.output, &r.default_out, err);
    if (st == ST_OK) st = outputs_check(&r.o, r.output, err);
    /* --denoise's library loaded before anything slow: a machine without it says so at once */
    if (st == ST_OK) st = render_job_open_denoiser(&r.job, err);
    if (st == ST_OK) st = load_scene_input(&r.o, &r.scene, &r.bare_mesh, err);
    if (st == ST_OK) st = outputs_from_scene(&r.o, &r.scene, &r.output, err);
    if (st == ST_OK) st = scene_apply_options(&r, err);
    if (st == ST_OK && r.o.frames_first >= 0) {
        st = run_frames(&r, dist, err);
        run_free(&r);
        return st;
    }
    if (st == ST_OK) st = render_prepare(&r, 0, 0, err);
    if (st == ST_OK) display_prepare(&r);
    if (st == ST_OK) st = open_devices(&r, err);
    if (st == ST_OK) {
        render_run(&r, dist, err);
        st = results_write(&r, err);
    }
    run_free(&r);
    return st;
}

/* What was printed to stdout (--help, --list-devices, --stats) reached it: a full disk
 * or a closed terminal is an I/O error, not a silent success. A reader that left early
 * (`clpt --stats scene | head -1`) got what it wanted: that is success (SIGPIPE is
 * ignored so that the image is still written). */
static Status stdout_close(Status st, Error *err)
{
    errno = 0;
    int failed = ferror(stdout);
    if (fflush(stdout) != 0) failed = 1;
    int e = errno;
    if (fclose(stdout) != 0 && !failed) {
        failed = 1;
        e = errno;
    }
    if (!failed) return st;
    if (e == 0) {
        /* the failure was in an earlier printf; a pipe without a reader shows POLLERR */
        struct pollfd p = { STDOUT_FILENO, POLLOUT, 0 };
        if (poll(&p, 1, 0) == 1 && (p.revents & POLLERR)) e = EPIPE;
    }
    if (e == EPIPE) return st;
    Error out = { 0 };
    error_set(&out, ST_IO, "cannot write to standard output: %s", e ? strerror(e) : "write error");
    return keep_first(st, err, ST_IO, &out);
}

/* Prints the run's error (once) and gives its exit status. */
static Status main_report(Status st, Error *err)
{
    st = stdout_close(st, err);
    if (st != ST_OK && st != ST_INTERRUPTED) {
        if (!err->msg[0]) err->status = st;   /* never "error: success" for a lost message */
        error_print(err);
        if (st == ST_USAGE) fprintf(stderr, "Try 'clpt --help' for more information.\n");
    }
    error_clear(err);
    return st;
}

int main(int argc, char **argv)
{
    Error err = { 0 };
    signal(SIGPIPE, SIG_IGN);
    /* Into a file or pipe, stdout is written at exit in one go (--help and --stats fit
     * in 64 KiB), so that stdout_close sees the failure and its errno. */
    static char stdout_buffer[1u << 16];   /* glibc ignores the size without a buffer */
    if (!isatty(STDOUT_FILENO)) setvbuf(stdout, stdout_buffer, _IOFBF, sizeof stdout_buffer);
    /* `clpt merge ...` adds the films of --sample-range parts (dist/merge.h) */
    if (argc > 1 && strcmp(argv[1], "merge") == 0) return (int)main_report(merge_command(argc - 1, argv + 1, &err), &err);
    /* under mpirun or srun, this process is one rank of a job (dist/mpi_driver.h) */
    Dist dist;
    memset(&dist, 0, sizeof dist);
    Status st = run(argc, argv, &dist, &err);
    if (dist.active && dist.rank > 0) {
        /* a worker's own failures only; ST_INTERRUPTED is a stop rank 0 reports */
        if (st != ST_OK && st != ST_INTERRUPTED) fprintf(stderr, "clpt: MPI rank %d: error: %s\n", dist.rank, err.msg);
        error_clear(&err);
        /* a worker that lost rank 0 at the start ends the job: nobody else would */
        dist_finish(&dist, (int)st, dist.lost);
        return 0;
    }
    st = main_report(st, &err);
    dist_finish(&dist, (int)st, dist.lost);
    return (int)st;
}
