/*
 * schedule.h — renders an image with every selected device at once.
 *
 * One host thread drives each device: it takes the next batch of samples from the shared
 * BatchQueue, renders it, takes the device's film and adds it into the host film. A device
 * that can pipeline (device.h) gets its next batch before the film of the last one is
 * back, so it never waits for the host between batches. Batch sizes adapt per device so
 * that one batch takes about `target_batch_seconds`, and shrink toward the end so that
 * all devices finish together. A device that fails gives its batches back and stops; the
 * others finish the image. The calling thread shows progress, passes a stop request on
 * to the devices as a cancel, and calls the periodic callbacks (progressive output,
 * checkpoints) with a consistent copy of the film.
 *
 * Batches are whole-image sample ranges, so every pixel of the film always holds the
 * same number of samples (Film.samples); which sample indices those are is the set
 * `done` (for checkpoints: a render resumed from it renders exactly the others).
 */
#ifndef CLPT_SCHEDULE_H
#define CLPT_SCHEDULE_H

#include <signal.h>
#include <stdint.h>

#include "render/batch_queue.h"
#include "device/device.h"
#include "render/film.h"
#include "base/progress.h"

/* A consistent copy of the accumulation state, handed to the periodic callbacks: the
 * film (its samples count included) and the sample indices it holds. */
typedef struct {
    const Film *film;
    const Batch *done;
    size_t n_done;
} ScheduleSnapshot;

typedef struct {
    uint spp;                        /* samples per pixel to render: indices [0, spp) */
    /* Sample ranges the film already holds (a resumed render); only the others are
     * rendered. NULL/0 for a fresh film. */
    const Batch *done;
    size_t n_done;
    /* Only sample indices [range_first, range_end) are rendered (--sample-range, and the
     * batches an MPI rank is given); range_end 0 = all of [0, spp). `done` must lie
     * inside the range. */
    uint range_first, range_end;
    double time_limit;               /* seconds; 0 = none. Whole batches only. */
    double target_batch_seconds;     /* 0 = 0.25 */
    uint fixed_batch;                /* > 0: every batch has this many samples (tests) */
    int show_progress;               /* progress.h: PROGRESS_OFF, _TERMINAL or _LOG */
    /* Set asynchronously (a signal) to stop early: within about 0.1 s no batch is handed
     * out any more and the batches being rendered are cancelled (device.h) and dropped
     * whole; the film keeps the batches finished before. */
    volatile sig_atomic_t *stop;
    /* How often the calling thread looks at `stop` (and progress): 0 = every 0.1 s. The
     * viewer polls faster, so that a camera move cancels the batches of the old view
     * within milliseconds. */
    double poll_seconds;
    /* Called from the calling thread about every `tick_seconds` (progressive output) and
     * every `checkpoint_seconds`, with a snapshot taken under the film's lock; the devices
     * keep rendering meanwhile. NULL for none. */
    void (*on_tick)(void *ctx, const ScheduleSnapshot *snap);
    double tick_seconds;
    void (*on_checkpoint)(void *ctx, const ScheduleSnapshot *snap);
    double checkpoint_seconds;
    void (*on_warning)(void *ctx, const char *message);
    /* Called from the calling thread at every poll (about every poll_seconds) and once
     * at the end, with the samples per pixel finished so far: the library's progress
     * callback, which may set *stop. NULL for none. */
    void (*on_poll)(void *ctx, uint spp_done);
    void *ctx;
} ScheduleConfig;

typedef struct {
    char name[256];
    unsigned batches;                /* finished (film taken) */
    uint64_t samples;                /* pixel samples */
    uint64_t rays;
    double busy_seconds, idle_seconds;
    uint batch_min, batch_max, batch_last;   /* sizes chosen, in samples per pixel */
    int failed;
    char failure[1024];
} DeviceRunStats;

typedef struct {
    double seconds;
    uint64_t samples, rays;          /* rendered in this run */
    uint spp_done;                   /* samples per pixel in the film (every pixel) */
    int adaptive;                    /* adaptive.c's: spp_done is the most a pixel holds */
    int interrupted, time_up;
    unsigned checkpoints;            /* on_checkpoint calls */
    double snapshot_seconds;         /* copying the film under its lock, in total */
    double checkpoint_seconds;       /* in on_checkpoint (encoding, writing), in total */
    size_t n_devices;
    DeviceRunStats *devices;         /* n_devices, owned */
    BatchSet done;                   /* the sample indices in the film, owned */
} ScheduleStats;

/* Renders into `film` (initialised to the scene's size; for a resumed render holding the
 * samples of cfg->done). Fails (ST_DEVICE) only when every device failed; the film then
 * keeps what was finished, and stats->done says which samples those are. Free the stats
 * with schedule_stats_free in every case. */
/* A render's config narrowed to the sample indices [first, end) of a fresh film, for a
 * part of it run on its own (an adaptive round's half, the split pilot): no samples
 * done, no progress bar, tick, checkpoint or poll hooks; the stop flag, batch size and
 * warnings kept; time_limit 0 for none. */
ScheduleConfig schedule_config_part(const ScheduleConfig *cfg, uint first, uint end, double time_limit);

Status schedule_run(Device **devices, size_t n, const ScheduleConfig *cfg, Film *film,
                    ScheduleStats *stats, Error *err);
void schedule_stats_free(ScheduleStats *s);

#endif /* CLPT_SCHEDULE_H */
