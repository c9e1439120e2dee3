/* stats.h — what --stats and --profile print (to stdout, or to stderr when the image
 * goes to stdout: the caller's `out`): the scene and its tree, each device's share of
 * the render, and where each device's time went. The line formats are what scripts read
 * (bench/, tests/test_cli.c): change them with care. --stats=json prints one JSON
 * object instead (docs/cli.md): add keys, never rename them. */
#ifndef CLPT_RENDER_STATS_H
#define CLPT_RENDER_STATS_H

#include <stddef.h>
#include <stdio.h>

#include "device/device.h"
#include "render/render_job.h"
#include "render/render_scene.h"
#include "render/schedule.h"
#include "scene/scene.h"

/* The scene's contents, its textures, and the tree built over it. */
void render_stats_print_scene(FILE *out, const Scene *s, const RenderScene *rs);
/* Per device: its kernels and waves (OpenCL), then batches, samples, busy and idle time,
 * throughput and share; the total; the film's sample ranges; the checkpoints. */
void render_stats_print_run(FILE *out, const ScheduleStats *st, uint spp, Device **devs, size_t n);
/* --profile: each device's time per phase (enum DevicePhase), in seconds and as a share
 * of its busy time; the scalar device's thread time is divided by its threads. */
void render_stats_print_profile(FILE *out, const ScheduleStats *st, Device **devs, size_t n);

/* What --stats=json says beside the render's statistics: names from the command line. */
typedef struct {
    const char *version;          /* clpt's */
    const char *scene_path, *output;
    const char *result;           /* "rendered", "interrupted" or "time limit reached" */
    unsigned width, height, spp;  /* the image, and the samples per pixel asked for */
    double total_seconds;         /* from the start of the program */
    const SplitPilot *split;      /* the split rendered, and --split auto's pilot */
} RenderStatsRun;

/* The split rendered and, for --split auto, what its pilot measured: "split: 2, chosen
 * by a pilot of 1024 pixels x 16 spp in 0.12 s (error x rays against split 1: 2 0.69, 4
 * 0.72)". */
void render_stats_print_split(FILE *out, const SplitPilot *sp, uint scene_split);

/* --stats=json: the render as one JSON object on one line. */
void render_stats_print_json(FILE *out, const RenderStatsRun *run, const Scene *s, const ScheduleStats *st);

/* The run's result in words: "rendered", "interrupted" or "time limit reached". */
const char *render_stats_result(const ScheduleStats *st);

/* The run's line: "clpt: rendered 64x48, 16 spp in 0.52 s (0.80 s total): 1.2
 * Msamples/s, 4.5 Mrays/s -> OUTPUT"; an adaptive render's samples per pixel as
 * "adaptive 16..256 spp (mean 41.2)". */
void render_stats_print_summary(FILE *out, const RenderJob *job, double total_seconds, const char *output);

#endif /* CLPT_RENDER_STATS_H */
