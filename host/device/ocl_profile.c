/*
 * ocl_profile.c — --profile on an OpenCL device: the device time of each command,
 * read from its event once it is complete, added to the phase it belongs to (enum
 * DevicePhase, device.h).
 */
#include <stdlib.h>
#include <string.h>

#include "device/ocl_device.h"

/* --profile: adds the device time of the complete command `e` to its phase. */
void ocld_profile_add(OclDevice *od, cl_event e, int phase)
{
    cl_ulong t0 = 0, t1 = 0;
    if (clGetEventProfilingInfo(e, CL_PROFILING_COMMAND_START, sizeof t0, &t0, NULL) == CL_SUCCESS &&
        clGetEventProfilingInfo(e, CL_PROFILING_COMMAND_END, sizeof t1, &t1, NULL) == CL_SUCCESS && t1 > t0)
        od->phases[phase] += (double)(t1 - t0) * 1e-9;
}

/* --profile: keeps the event of a command just enqueued, to be read when complete
 * (reading it at once would wait, and serialise host and device). */
void ocld_profile_track(OclDevice *od, cl_event e, int phase)
{
    if (od->n_profiled == od->cap_profiled) {
        size_t cap = od->cap_profiled ? 2 * od->cap_profiled : 256;
        ProfiledCommand *p = realloc(od->profiled, cap * sizeof *p);
        if (!p) {
            /* no room to keep it: wait for it now rather than lose its time */
            if (clWaitForEvents(1, &e) == CL_SUCCESS) ocld_profile_add(od, e, phase);
            clReleaseEvent(e);
            return;
        }
        od->profiled = p;
        od->cap_profiled = cap;
    }
    od->profiled[od->n_profiled].event = e;
    od->profiled[od->n_profiled++].phase = phase;
}

/* --profile: reads and forgets the tracked commands that are complete (failed ones are
 * forgotten unread). */
void ocld_profile_collect(OclDevice *od)
{
    size_t keep = 0;
    for (size_t i = 0; i < od->n_profiled; i++) {
        ProfiledCommand c = od->profiled[i];
        cl_int status = CL_QUEUED;
        clGetEventInfo(c.event, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status, &status, NULL);
        if (status > CL_COMPLETE) {
            od->profiled[keep++] = c;
            continue;
        }
        if (status == CL_COMPLETE) ocld_profile_add(od, c.event, c.phase);
        clReleaseEvent(c.event);
    }
    od->n_profiled = keep;
}

/* The phase of each kernel's time (the classic ray tracer's samples count as shading). */
int ocld_profile_phase_of(const char *kernel)
{
    static const struct { const char *name; int phase; } map[] = {
        { "k_raygen", PHASE_RAYGEN }, { "k_intersect", PHASE_TRAVERSE }, { "k_shade", PHASE_SHADE },
        { "k_shadow", PHASE_SHADOW }, { "k_film", PHASE_FILM },
    };
    /* k_path (a megakernel asked for with --profile) does all of a path's stages at
     * once: its time counts as shading, as the classic ray tracer's does */
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (strcmp(kernel, map[i].name) == 0) return map[i].phase;
    return PHASE_SHADE;
}

/* Forgets every tracked command (the queue is finished: each is complete). */
void ocld_profile_free(OclDevice *od)
{
    ocld_profile_collect(od);
    for (size_t i = 0; i < od->n_profiled; i++) clReleaseEvent(od->profiled[i].event);
    free(od->profiled);
    od->profiled = NULL;
    od->n_profiled = od->cap_profiled = 0;
}
