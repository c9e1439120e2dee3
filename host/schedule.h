/*
 * schedule.h — renders an image with every selected device at once.
 *
 * One host thread drives each device: it takes the next batch of samples from the shared
 * BatchQueue, renders it, takes the device's film and adds it into the host film. Batch
 * sizes adapt per device so that one batch takes about `target_batch_seconds`, and shrink
 * toward the end so that all devices finish together. A device that fails gives its batch
 * back and stops; the others finish the image. The calling thread shows progress.
 */
#ifndef CLPT_SCHEDULE_H
#define CLPT_SCHEDULE_H

#include <signal.h>
#include <stdint.h>

#include "device.h"
#include "film.h"
#include "progress.h"

typedef struct {
    uint spp;                        /* samples per pixel to render */
    double time_limit;               /* seconds; 0 = none. Whole batches only. */
    double target_batch_seconds;     /* 0 = 0.25 */
    uint fixed_batch;                /* > 0: every batch has this many samples (tests) */
    int show_progress;
    volatile sig_atomic_t *stop;     /* set asynchronously (a signal) to stop early */
    /* Called from the calling thread about every `tick_seconds` with the film locked
     * consistent (e.g. progressive output); NULL for none. */
    void (*on_tick)(void *ctx, const Film *film);
    double tick_seconds;
    void (*on_warning)(void *ctx, const char *message);
    void *ctx;
} ScheduleConfig;

typedef struct {
    char name[256];
    unsigned batches;
    uint64_t samples;                /* pixel samples */
    uint64_t rays;
    double busy_seconds, idle_seconds;
    uint batch_min, batch_max, batch_last;   /* sizes chosen, in samples per pixel */
    int failed;
    char failure[1024];
} DeviceRunStats;

typedef struct {
    double seconds;
    uint64_t samples, rays;
    uint spp_done;                   /* samples per pixel in the film */
    int interrupted, time_up;
    size_t n_devices;
    DeviceRunStats *devices;         /* n_devices, owned; free with schedule_stats_free */
} ScheduleStats;

/* Renders into `film` (already initialised to the scene's size, possibly holding samples
 * from earlier). Fails (ST_DEVICE) only when every device failed; the film then keeps
 * what was finished. */
Status schedule_run(Device **devices, size_t n, const ScheduleConfig *cfg, Film *film,
                    ScheduleStats *stats, Error *err);
void schedule_stats_free(ScheduleStats *s);

#endif /* CLPT_SCHEDULE_H */
