/* stats.h — what --stats and --profile print to stdout: the scene and its tree, each
 * device's share of the render, and where each device's time went. The line formats are
 * what scripts read (bench/, tests/test_cli.c): change them with care. */
#ifndef CLPT_RENDER_STATS_H
#define CLPT_RENDER_STATS_H

#include <stddef.h>

#include "device/device.h"
#include "render/render_scene.h"
#include "render/schedule.h"
#include "scene/scene.h"

/* The scene's contents, its textures, and the tree built over it. */
void render_stats_print_scene(const Scene *s, const RenderScene *rs);
/* Per device: its kernels and waves (OpenCL), then batches, samples, busy and idle time,
 * throughput and share; the total; the film's sample ranges; the checkpoints. */
void render_stats_print_run(const ScheduleStats *st, uint spp, Device **devs, size_t n);
/* --profile: each device's time per phase (enum DevicePhase), in seconds and as a share
 * of its busy time; the scalar device's thread time is divided by its threads. */
void render_stats_print_profile(const ScheduleStats *st, Device **devs, size_t n);

#endif /* CLPT_RENDER_STATS_H */
