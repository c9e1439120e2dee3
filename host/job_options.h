/* job_options.h — the command line's options as a render job's settings, shared by the
 * program (main.c) and the library (api/), so that both render a run from the same
 * flags (render/render_job.h). */
#ifndef CLPT_JOB_OPTIONS_H
#define CLPT_JOB_OPTIONS_H

#include "option_values.h"
#include "render/render_job.h"

/* The settings of the render that `o` asks (o finished: options_finish). */
RenderJobSettings job_options_settings(const Options *o);

#endif /* CLPT_JOB_OPTIONS_H */
