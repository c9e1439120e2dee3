/* job_options.c — the command line's options as a render job's settings. */
#include "job_options.h"

RenderJobSettings job_options_settings(const Options *o)
{
    RenderJobSettings s = {
        .device_spec = o->device_spec,
        .device = { o->threads, o->kernel_dir, o->wave_paths, o->profile, o->wave_launch },
        .checkpoint_path = o->checkpoint_path,
        .checkpoint_seconds = o->checkpoint_seconds,
        .resume_path = o->resume_path,
        .range_first = o->range_first,
        .range_end = o->range_end,
        .time_limit = o->time_limit,
        .batch = o->batch,
        .adaptive = { o->noise_threshold, o->min_spp },
        .edge_threshold = o->adaptive,
        .edge_spp = o->adaptive_spp,
        .denoise = o->denoise,
        .quiet = o->quiet,
    };
    return s;
}
