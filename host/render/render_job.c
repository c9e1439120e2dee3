/*
 * render_job.c — one render run, for the program and the library alike (render_job.h).
 */
#include "render/render_job.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/timer.h"
#include "scene/camera.h"

void render_job_init(RenderJob *job, const RenderJobSettings *set, DeviceWarn warn, void *warn_ctx, void *user)
{
    memset(job, 0, sizeof *job);
    job->set = *set;
    job->warn = warn;
    job->warn_ctx = warn_ctx;
    job->user = user;
    job->adaptive = set->adaptive.threshold > 0.0;
}

void render_job_free(RenderJob *job)
{
    schedule_stats_free(&job->stats);
    for (size_t i = 0; i < job->n_devs; i++) device_close(job->devs[i]);
    free(job->devs);
    job->devs = NULL;
    job->n_devs = 0;
    denoiser_close(job->denoiser);
    job->denoiser = NULL;
    film_free(&job->film);
    adaptive_film_free(&job->af);
    checkpoint_free(&job->resume);
    render_scene_free(&job->rs);
}

/* A warning said once per kind: *said remembers that it was. */
static void warn_once(RenderJob *job, int *said, const char *msg)
{
    if (*said) return;
    *said = 1;
    if (job->warn) job->warn(job->warn_ctx, msg);
}

Status render_job_open_denoiser(RenderJob *job, Error *err)
{
    return job->set.denoise && !job->denoiser ? denoiser_open(&job->denoiser, err) : ST_OK;
}

Status render_job_prepare_scene(RenderJob *job, Scene *scene, Error *err)
{
    job->scene = scene;
    return render_scene_prepare(scene, 0, &job->rs, err);
}

void render_job_take_scene(RenderJob *job, RenderScene *rs)
{
    *rs = job->rs;
    memset(&job->rs, 0, sizeof job->rs);
}

Status render_job_adopt_scene(RenderJob *job, Scene *scene, RenderScene *rs, Error *err)
{
    job->scene = scene;
    job->rs = *rs;
    memset(rs, 0, sizeof *rs);
    RenderParams *p = &job->rs.ds.params;
    /* split auto is chosen again for each frame (render_job_run), as a frame rendered
     * alone chooses */
    p->split = scene->image.split;
    Status st = camera_setup(&scene->camera, scene->image.width, scene->image.height, &p->camera, err);
    return st ? st : scene_check_precision(scene, err);
}

Status render_job_update_devices(RenderJob *job, Device **devs, size_t n_devs, Error *err)
{
    job->devs = devs;
    job->n_devs = job->n_local_devs = n_devs;
    return device_update_all(devs, n_devs, &job->rs.ds, err);
}

/* ------------------------------------------------------------------ resuming */

/* How the whitted integrator places a pixel's samples at `spp` (render_scene_strata). */
static void grid_words(uint spp, char *buf, size_t size)
{
    uint m = render_scene_strata(spp);
    if (m >= 2u) snprintf(buf, size, "a %ux%u grid", m, m);
    else snprintf(buf, size, "%s", m ? "uniform jitter" : "the pixel centre");
}

/* A whitted render places its samples in an m x m grid when its samples per pixel are
 * m^2 (render_scene_strata): grown to a count with another grid, its first samples
 * would be other samples than the checkpoint's. (The render key differs then too; this
 * says why.) */
static Status resume_check_grid(const RenderJob *job, const Checkpoint *ck, Error *err)
{
    uint had = ck->id.spp, want = job->scene->image.spp;
    if (job->scene->integrator != INTEGRATOR_WHITTED || had >= want ||
        render_scene_strata(had) == render_scene_strata(want))
        return ST_OK;
    char a[32], b[32];
    grid_words(had, a, sizeof a);
    grid_words(want, b, sizeof b);
    return error_set(err, ST_INPUT, "checkpoint '%s' is a whitted render of %u samples per pixel, placed in %s; %u "
                     "would be placed in %s, so it cannot grow to %u (resume with --spp %u, or a count placed "
                     "alike)", job->set.resume_path, had, a, want, b, want, had);
}

/* A part (--sample-range) resumed from a checkpoint must not carry samples outside
 * its range: the part's film would then hold samples another part renders too. */
static Status resume_check_range(const RenderJob *job, const Checkpoint *ck, Error *err)
{
    const RenderJobSettings *s = &job->set;
    if (s->range_end < 0) return ST_OK;
    for (size_t i = 0; i < ck->n_done; i++) {
        Batch b = ck->done[i];
        if ((long)b.first < s->range_first || (long)b.first + (long)b.count > s->range_end)
            return error_set(err, ST_INPUT, "checkpoint '%s' holds samples [%u,%u), outside --sample-range %ld:%ld; "
                             "resume it with the range it was made with", s->resume_path, b.first, b.first + b.count,
                             s->range_first, s->range_end);
    }
    return ST_OK;
}

/* The checkpoint's state copied into the film (and an adaptive render's halves and
 * counts), said unless quiet. */
static void resume_into_film(RenderJob *job, const Checkpoint *ck)
{
    Film *film = &job->film;
    size_t n = (size_t)film->width * film->height;
    memcpy(film->sum, ck->film.sum, n * 3u * sizeof *film->sum);
    film->samples = ck->film.samples;
    if (job->adaptive) {
        memcpy(job->af.film.sum, ck->film.sum, n * 3u * sizeof *film->sum);
        memcpy(job->af.odd, ck->odd, n * 3u * sizeof *job->af.odd);
        memcpy(job->af.spp, ck->pixel_spp, n * sizeof *job->af.spp);
        job->af.film.samples = ck->film.samples;
    }
    if (job->set.quiet) return;
    const char *path = job->set.resume_path;
    if (ck->id.spp < job->checkpoint_id.spp)
        fprintf(stderr, "clpt: resuming from '%s': %llu samples per pixel already done, growing the render from %u "
                "to %u\n", path, (unsigned long long)film->samples, ck->id.spp, job->checkpoint_id.spp);
    else
        fprintf(stderr, "clpt: resuming from '%s': %llu of %u samples per pixel already done\n", path,
                (unsigned long long)film->samples, job->checkpoint_id.spp);
}

/* --resume: the checkpoint, checked against this render, becomes the film's start. */
static Status resume_film(RenderJob *job, Error *err)
{
    const char *path = job->set.resume_path;
    Checkpoint *ck = &job->resume;
    Status st = checkpoint_read(path, ck, err);
    if (st == ST_OK) st = resume_check_grid(job, ck, err);
    if (st == ST_OK) st = checkpoint_check(ck, path, &job->checkpoint_id, err);
    if (st == ST_OK) st = checkpoint_check_adaptive(ck, path, job->adaptive ? &job->set.adaptive : NULL, err);
    if (st == ST_OK) st = resume_check_range(job, ck, err);
    if (st == ST_OK) resume_into_film(job, ck);
    return st;
}

Status render_job_prepare_film(RenderJob *job, int keyed, int skip_resume, Error *err)
{
    const DeviceScene *ds = &job->rs.ds;
    const RenderJobSettings *s = &job->set;
    if (keyed || s->checkpoint_path || s->resume_path) checkpoint_id(ds, job->scene->image.spp, &job->checkpoint_id);
    Status st = film_init(&job->film, ds->params.width, ds->params.height, err);
    if (st == ST_OK && job->adaptive) st = adaptive_film_init(&job->af, ds->params.width, ds->params.height, err);
    if (st != ST_OK || !s->resume_path || skip_resume) return st;
    return resume_film(job, err);
}

Status render_job_open_devices(RenderJob *job, Error *err)
{
    Status st = device_open_all(job->set.device_spec, &job->set.device, &job->rs.ds, job->warn, job->warn_ctx,
                                &job->devs, &job->n_devs, err);
    job->n_local_devs = job->n_devs;
    return st;
}

void render_job_take_devices(RenderJob *job, Device ***devs, size_t *n_devs)
{
    *devs = job->devs;
    *n_devs = job->n_devs;
    job->devs = NULL;
    job->n_devs = job->n_local_devs = 0;
}

Status render_job_adopt_devices(RenderJob *job, Device **devs, size_t n_devs, Error *err)
{
    job->devs = devs;
    job->n_devs = job->n_local_devs = n_devs;
    for (size_t i = 0; i < n_devs; i++) {
        Status st = devs[i]->ops->load_scene(devs[i], &job->rs.ds, err);
        if (st) return st;
    }
    return ST_OK;
}

/* ------------------------------------------------------------------ the render */

static void job_warning(void *vjob, const char *msg)
{
    RenderJob *job = vjob;
    if (job->warn) job->warn(job->warn_ctx, msg);
}

/* Periodic checkpoints; a failure is said once (the next one may succeed) and does not
 * stop the render. */
static void job_checkpoint(void *vjob, const ScheduleSnapshot *snap)
{
    RenderJob *job = vjob;
    Error err = { 0 };
    if (checkpoint_write(job->set.checkpoint_path, &job->checkpoint_id, snap->film, snap->done, snap->n_done, &err) !=
        ST_OK)
        warn_once(job, &job->checkpoint_failed, err.msg);
    error_clear(&err);
}

/* After each round of an adaptive render: a checkpoint at most as often as its
 * interval (a round's film is whole; the scheduler's snapshots in the middle of one
 * are not the render's state), then the caller's hook. */
static void job_round(void *vjob, const AdaptiveFilm *af)
{
    RenderJob *job = vjob;
    double now = timer_now();
    if (job->set.checkpoint_path && now - job->last_checkpoint >= job->set.checkpoint_seconds) {
        Error err = { 0 };
        job->last_checkpoint = now;
        if (checkpoint_write_adaptive(job->set.checkpoint_path, &job->checkpoint_id, af, &job->set.adaptive, &err) !=
            ST_OK)
            warn_once(job, &job->checkpoint_failed, err.msg);
        error_clear(&err);
    }
    if (job->on_round) job->on_round(job, af);
}

void render_job_configure(RenderJob *job)
{
    const RenderJobSettings *s = &job->set;
    ScheduleConfig *cfg = &job->cfg;
    memset(cfg, 0, sizeof *cfg);
    cfg->spp = job->scene->image.spp;
    cfg->done = job->resume.done;
    cfg->n_done = job->resume.n_done;
    if (s->range_end >= 0) {
        cfg->range_first = (uint)s->range_first;
        cfg->range_end = (uint)s->range_end;
    }
    cfg->on_checkpoint = s->checkpoint_path ? job_checkpoint : NULL;
    cfg->checkpoint_seconds = s->checkpoint_seconds;
    cfg->time_limit = s->time_limit;
    cfg->fixed_batch = s->batch;
    cfg->on_warning = job_warning;
    cfg->ctx = job;
    job->last_checkpoint = timer_now();
}

Status render_job_run(RenderJob *job, Error *err)
{
    /* --split auto: the pilot chooses, and the devices get the choice (split_pilot.h) */
    AdaptiveRun pilot = { job->devs, job->n_devs, &job->rs, &job->cfg, NULL, NULL };
    job->render_st = split_pilot_run(&pilot, &job->split_pilot, err);
    if (job->render_st != ST_OK) return job->render_st;
    if (job->adaptive) {
        AdaptiveRun run = { job->devs, job->n_devs, &job->rs, &job->cfg, job_round, job };
        job->render_st = adaptive_run(&run, &job->set.adaptive, &job->af, &job->stats, err);
        /* what the results ask of the film: its count (the image is af's) */
        job->film.samples = job->af.film.samples;
    } else {
        job->render_st = schedule_run(job->devs, job->n_devs, &job->cfg, &job->film, &job->stats, err);
    }
    /* the pilot is part of the render's time (its rates and the peers' benchmark) */
    job->stats.seconds += job->split_pilot.seconds;
    return job->render_st;
}

int render_job_complete(const RenderJob *job)
{
    return job->render_st == ST_OK && !job->stats.interrupted && !job->stats.time_up;
}

/* ------------------------------------------------------------------ results */

Status render_job_final_checkpoint(RenderJob *job, Error *err)
{
    const char *path = job->set.checkpoint_path;
    if (!path) return ST_OK;
    Status st = job->adaptive ? checkpoint_write_adaptive(path, &job->checkpoint_id, &job->af, &job->set.adaptive, err)
              : batch_set_total(&job->stats.done) == job->film.samples
                  ? checkpoint_write(path, &job->checkpoint_id, &job->film, job->stats.done.ranges, job->stats.done.n,
                                     err)
                  : error_set(err, ST_INTERNAL, "the record of finished samples is incomplete; no final checkpoint "
                                                "written");
    if (st != ST_OK && render_job_complete(job)) {
        job_warning(job, err->msg);
        error_clear(err);
        return ST_OK;
    }
    return st;
}

void render_job_resolve(const RenderJob *job, float *rgb)
{
    if (job->adaptive) adaptive_film_resolve(&job->af, rgb);
    else film_resolve(&job->film, rgb);
}

Status render_job_write_image(const RenderJob *job, const char *path, const ImageStyle *style, Error *err)
{
    return job->adaptive ? adaptive_film_write(&job->af, path, style, err) : film_write(&job->film, path, style, err);
}

void render_job_pass_context(RenderJob *job, ScheduleConfig *pcfg, PassContext *pc)
{
    *pcfg = job->cfg;
    pcfg->show_progress = 0;
    /* a pass's film is not the render's: a checkpoint of it would replace the render's */
    pcfg->on_checkpoint = NULL;
    /* a pass renders all its samples: those a resumed checkpoint held were the main
     * image's, not the pass's (without this, --aov after --resume got only the rest) */
    pcfg->done = NULL;
    pcfg->n_done = 0;
    PassContext c = { job->devs, job->n_local_devs, &job->rs, pcfg, job->denoiser, NULL, NULL };
    *pc = c;
}

/* ------------------------------------------------------------------ passes into memory */

/* Whether the stop flag is up (the library's cancel, the program's signal). */
static int job_stopped(const RenderJob *job)
{
    return job->cfg.stop && *job->cfg.stop;
}

/* Auxiliary image `aov` into `out` (3 floats a pixel; depth: 1), as data. */
static Status job_aov(RenderJob *job, const PassContext *pc, unsigned aov, float *data, float *out, Error *err)
{
    size_t n = (size_t)job->film.width * job->film.height;
    double secs = 0.0;
    Status st = passes_aov_data(pc, aov, (uint)job->film.samples, data, &secs, err);
    /* an interrupted pass is incomplete: not handed out */
    if (st != ST_OK || job_stopped(job)) return st;
    if (aov == INTEGRATOR_AOV_DEPTH)
        for (size_t i = 0; i < n; i++) out[i] = data[3 * i];
    else
        memcpy(out, data, n * 3 * sizeof *data);
    job->passes_spp += (uint)job->film.samples;
    return ST_OK;
}

/* The denoiser on rgb, with the features rendered above (as the program's --denoise:
 * passes.c renders them with the same settings, so the same bits). */
static Status job_denoise(RenderJob *job, const PassContext *pc, float *rgb, const float *albedo, const float *normal,
                          Error *err)
{
    size_t n = (size_t)job->film.width * job->film.height * 3u;
    float *noisy = malloc(n * sizeof *noisy);
    if (!noisy) return error_set(err, ST_INTERNAL, "out of memory");
    memcpy(noisy, rgb, n * sizeof *rgb);
    Status st = passes_denoise(pc, (uint)job->film.samples, !(job->set.adaptive.threshold > 0.0), noisy, albedo,
                               normal, rgb, NULL, NULL, 1, err);
    free(noisy);
    return st;
}

Status render_job_passes_to_memory(RenderJob *job, float *rgb, const RenderJobAovs *aovs, Error *err)
{
    ScheduleConfig pcfg;
    PassContext pc;
    render_job_pass_context(job, &pcfg, &pc);
    size_t n = (size_t)job->film.width * job->film.height * 3u;
    Status st = ST_OK;
    if (job->set.edge_threshold > 0.0) {
        size_t marked = 0;
        double secs = 0.0;
        st = passes_adaptive(&pc, rgb, (uint)job->film.samples, (float)job->set.edge_threshold, job->set.edge_spp,
                             &marked, &secs, err);
        job->passes_spp += job->set.edge_spp;
    }
    /* the denoiser's features where the caller asks for no such image */
    float *data = malloc(n * sizeof *data), *feature[2] = { NULL, NULL };
    float *out[3] = { aovs->normal, aovs->depth, aovs->albedo };
    if (st == ST_OK && !data) st = error_set(err, ST_INTERNAL, "out of memory");
    for (int i = 0; i < 3 && st == ST_OK && job->set.denoise; i += 2)
        if (!out[i] && !(out[i] = feature[i / 2] = malloc(n * sizeof *data)))
            st = error_set(err, ST_INTERNAL, "out of memory");
    for (unsigned a = INTEGRATOR_AOV_NORMAL; a <= INTEGRATOR_AOV_ALBEDO && st == ST_OK && !job_stopped(job); a++)
        if (out[a - INTEGRATOR_AOV_NORMAL]) st = job_aov(job, &pc, a, data, out[a - INTEGRATOR_AOV_NORMAL], err);
    if (st == ST_OK && !job_stopped(job) && job->set.denoise) st = job_denoise(job, &pc, rgb, out[2], out[0], err);
    free(data);
    free(feature[0]);
    free(feature[1]);
    return st == ST_OK && job_stopped(job) ? ST_INTERRUPTED : st;
}

/* ------------------------------------------------------------------ a --denoise part */

Status render_job_part_features(RenderJob *job, Error *err)
{
    const RenderJobSettings *s = &job->set;
    if (!s->denoise || s->range_end < 0 || !s->checkpoint_path || !render_job_complete(job) || job->adaptive)
        return ST_OK;
    ScheduleConfig pcfg;
    PassContext pc;
    render_job_pass_context(job, &pcfg, &pc);
    uint spp = job->checkpoint_id.spp, first = (uint)s->range_first, end = (uint)s->range_end;
    uint more = passes_emission_more_spp(spp), factor = more / spp;
    /* a part cannot know whether another part's samples see an emitter: where the
     * emission can be left out, every part renders both emission films */
    int emission = passes_emission_splits(&job->rs.ds.params, 1);
    struct {
        unsigned mode;
        uint spp, first, end;
    } want[CKPT_FEATURES_MAX] = {
        [CKPT_FEATURE_ALBEDO] = { INTEGRATOR_FEATURE_ALBEDO, spp, first, end },
        [CKPT_FEATURE_NORMAL] = { INTEGRATOR_FEATURE_NORMAL, spp, first, end },
        [CKPT_FEATURE_EMISSION] = { INTEGRATOR_FEATURE_EMISSION, spp, first, end },
        [CKPT_FEATURE_EMISSION_MORE] = { INTEGRATOR_FEATURE_EMISSION, more, first * factor, end * factor },
    };
    uint n = emission ? CKPT_FEATURES_MAX : 2u;
    Film films[CKPT_FEATURES_MAX];
    memset(films, 0, sizeof films);
    double secs = 0.0;
    Status st = ST_OK;
    for (uint k = 0; k < n && st == ST_OK && !job_stopped(job); k++)
        st = passes_data_film(&pc, want[k].mode, want[k].spp, want[k].first, want[k].end, &films[k], &secs, err);
    if (st == ST_OK && job_stopped(job)) st = ST_INTERRUPTED;
    if (st == ST_OK)
        st = checkpoint_write_features(s->checkpoint_path, &job->checkpoint_id, &job->film, job->stats.done.ranges,
                                       job->stats.done.n, films, n, spp, err);
    if (st == ST_OK && !s->quiet)
        fprintf(stderr, "clpt: the denoiser's features of samples [%u,%u) in %.2f s -> %s (clpt merge --denoise "
                "denoises the parts)\n", first, end, secs, s->checkpoint_path);
    for (uint k = 0; k < CKPT_FEATURES_MAX; k++) film_free(&films[k]);
    return st;
}
