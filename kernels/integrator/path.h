/*
 * path.h -- one path of the path tracer from its birth at the camera to its end:
 * trace, shade, answer the shadow ray, again, and with first-hit splitting once more
 * from the first hit for each continuation (shade_path.h). The megakernel k_path (entry.cl)
 * runs it per work-item and the scalar C device per sample, so both take the same
 * steps; k_path_lanes runs eight at a time in the same order (entry.cl), and the
 * wavefront kernels split the same steps over launches.
 */
#ifndef CLPT_PATH_H
#define CLPT_PATH_H

#include "accel/alpha.h"
#include "integrator/raygen.h"
#include "integrator/shade_path.h"
#include "accel/traverse.h"
#include "medium/transmit.h"

/* Points sc at a copy of the view seen at path ps's time where the scene moves
 * (SceneView.time, docs/motion.md); without KF_MOTION, nothing. */
#if KF_HAS(KF_MOTION)
#define PATH_AT_TIME(sc, ps)                                                             \
    SceneView at_time_;                                                                  \
    if ((sc)->params->camera.moving) {                                                   \
        at_time_ = *(sc);                                                                \
        at_time_.time = (ps)->time;                                                      \
        sc = &at_time_;                                                                  \
    }
#else
#define PATH_AT_TIME(sc, ps)
#endif

/* path_run's loop, written once: STAGE(phase) follows each of its stages (enum
 * DevicePhase, host/device/device.h). path_run passes an empty one; the scalar device's
 * --profile (render_path_timed, host/device/scalar_paths_impl.h) reads its clock there.
 * Uses sc, pixel, sample, ps, ray and shadow_ray, and declares n_rays, the rays traced.
 * First-hit splitting (shade_path.h) keeps the camera ray and first hit, the continuations
 * still to go (known once the first hit is shaded) and whether the path restarts from
 * the first hit. One call of the walk: inlined twice, it made k_path 5-9% slower on the
 * envmap, one-weekend and mesh scenes. */
#define PATH_RUN_BODY(STAGE)                                                             \
    uint n_rays = 0u;                                                                    \
    raygen_path(sc->params, sc->motion_keys, pixel, sample, ps, ray);                    \
    PATH_AT_TIME(sc, ps);                                                                \
    STAGE(PHASE_RAYGEN);                                                                 \
    Ray first_ray = *ray;                                                                \
    Hit first_hit, beyond_hit;                                                           \
    uint split = 0u;                                                                     \
    int restart = 0, beyond = 0, beyond_kept = 0;                                        \
    for (int first = 1;; first = 0) {                                                    \
        Hit hit;                                                                         \
        if (restart) {                                                                   \
            hit = first_hit;                                                             \
        } else if (beyond && beyond_kept) {                                              \
            hit = beyond_hit;                                                            \
        } else {                                                                         \
            /* the hit beyond a boundary is kept for every continuation: the whole   \
             * walk's; any other stops looking where a flight in fog will stop */   \
            hit = beyond ? trace_closest_visible(sc, *ray) : trace_flight(sc, *ray, ps); \
            n_rays++;                                                                    \
            if (beyond) {                                                                \
                beyond_hit = hit;                                                        \
                beyond_kept = 1;                                                         \
            }                                                                            \
        }                                                                                \
        if (first) {                                                                     \
            first_hit = hit;                                                             \
            first_hit.flight_drawn = 0u;   /* each branch draws its own flight */       \
        }                                                                                \
        int at_first = first || restart;                                                 \
        STAGE(PHASE_TRAVERSE);                                                           \
        uint r = shade_path(sc, ray, hit, ps, shadow_ray);                               \
        STAGE(PHASE_SHADE);                                                              \
        if (first && (r & SHADE_SCATTERED)) split = params_split(sc->params) - 1u;       \
        /* a first hit that is a medium's boundary: every continuation crosses it on the \
         * camera ray's line, so the hit beyond it is the same for all, traced once */   \
        beyond = KF_HAS(KF_MEDIA) && at_first && (r & SHADE_CONTINUE) && params_split(sc->params) > 1u && \
                 ps->bounce == 0u && ps->crossings == 1u;                                \
        if (r & SHADE_SHADOW) {                                                          \
            n_rays += shadow_trace(sc, ps, *shadow_ray);                                 \
            STAGE(PHASE_SHADOW);                                                         \
        }                                                                                \
        restart = 0;                                                                     \
        if (!(r & SHADE_CONTINUE)) {                                                     \
            if (split == 0u) break;                                                      \
            split--;                                                                     \
            path_branch_next(ps);                                                        \
            *ray = first_ray;                                                            \
            restart = 1;                                                                 \
        }                                                                                \
    }

#define PATH_STAGE_NONE(phase)

/* One path from birth to end; returns the rays it traced. A call on CPUs, for two
 * reasons measured on PoCL (bench/RESULTS.md). PoCL keeps a kernel's body three times
 * over (the kernel and two work-group functions); this function, with shade_path inlined
 * into it (shade_path.h), is most of k_path's code, and as a call it is compiled once. And
 * the same code ran 6-15% faster as a call than in the kernel's body, whose variables
 * PoCL's work-group function handles around the kernel's barriers (add_group_rays). */
KFN_CALL_CL uint path_run(const SceneView *sc, uint pixel, uint sample, GLOBAL PathState *ps, GLOBAL Ray *ray,
                          GLOBAL Ray *shadow_ray)
{
    PATH_RUN_BODY(PATH_STAGE_NONE)
    return n_rays;
}

#endif /* CLPT_PATH_H */
