/*
 * adaptive.h — adaptive sampling for the path tracer (--noise-threshold), as Cycles'
 * noise threshold: every pixel renders min_spp samples, then pixels whose estimated
 * error is below the threshold stop while the others go on, up to the render's spp.
 *
 * The error of a pixel comes from two half-films, the sums of its even and of its odd
 * sample indices: two independent estimates of the same pixel, whose difference says
 * how far either is from the mean. The film is integer, so each half is exact whatever
 * device, batch or process added it.
 *
 * Decisions are taken only at fixed sample counts (adaptive_decides_at: min_spp, then
 * each a fifth to a third more), from the integer sums alone, in double arithmetic on the
 * host; between two of them every pixel still rendering gets the same sample indices.
 * So which pixels stop, and the image, are the same bits on any device mix, batch size,
 * or resume: the state after a round is the film, the odd half, each pixel's count and
 * the count reached, all of which a checkpoint holds.
 *
 * A round renders the even and the odd samples of [reached, next stop) as two batches
 * of "half" samples (RenderParams.sample_step 2, sample_offset 0 or 1; raygen.h) over
 * the list of the pixels still rendering (RenderParams.pixel_list_size: the waves hold
 * only theirs, so a converged pixel costs nothing), each through the scheduler, so
 * every selected device works on it.
 * A round interrupted or cut by the time limit is dropped whole: the film keeps whole
 * rounds only, and a resume renders that round again.
 */
#ifndef CLPT_ADAPTIVE_H
#define CLPT_ADAPTIVE_H

#include <stdint.h>

#include "render/film.h"
#include "render/render_scene.h"
#include "render/schedule.h"

/* --min-spp when not given: enough samples that the two halves' difference says
 * something about a pixel (Cycles' default minimum is of the same order). */
#define ADAPTIVE_DEFAULT_MIN_SPP 16u

typedef struct {
    double threshold;      /* > 0: a pixel stops once its error is below it */
    uint min_spp;          /* >= 2: samples of every pixel before the first decision */
} AdaptiveSettings;

/* The accumulation state of an adaptive render. */
typedef struct {
    Film film;             /* every sample's sums; film.samples: the count the pixels still
                            * rendering hold (the most any pixel holds) */
    int64_t *odd;          /* the sums of the odd sample indices (width * height * 3) */
    uint *spp;             /* each pixel's samples: film.samples, or the stop it ended at */
} AdaptiveFilm;

Status adaptive_film_init(AdaptiveFilm *af, uint width, uint height, Error *err);
void adaptive_film_free(AdaptiveFilm *af);
/* Each pixel's sums over its own sample count, into rgb (width * height * 3). */
void adaptive_film_resolve(const AdaptiveFilm *af, float *rgb);
/* The resolved image written to path (atomically): as film_write, per-pixel counts. */
Status adaptive_film_write(const AdaptiveFilm *af, const char *path, const ImageStyle *style, Error *err);

/* A pixel's error estimate: with S its sums over all n samples, O over the odd ones and
 * E = S - O over the even ones (film units),
 *     err = sum_c |E_c - O_c| / n  /  (1e-4 + sqrt(sum_c S_c / n)),
 * radiance units: the two half means' difference relative to the square root of the
 * pixel's brightness, as the eye sees noise more in the dark (Cycles' measure, after
 * Dammertz et al. 2010). 0 for a pixel without samples. */
double adaptive_pixel_error(const AdaptiveFilm *af, size_t pixel);

/* Whether the render decides which pixels stop when they hold n samples: at min_spp
 * (rounded up to even), then at each count 4, 5 or 6 times a power of two above it
 * (16, 20, 24, 32, 40, 48, 64, ...), a fifth to a third more, so that a pixel
 * overshoots its stop by a third at most, and stops where Sobol points are well spread.
 * Every such count is even: the halves then hold as many samples each. */
int adaptive_decides_at(const AdaptiveSettings *s, uint n);
/* The next count after `reached` at which the render decides, capped at spp. */
uint adaptive_next_stop(const AdaptiveSettings *s, uint reached, uint spp);

/* The pixels that render the next round, into mask (width * height, 1 = renders): those
 * at af->film.samples and, where that count is a decision, whose decision error or a
 * neighbour's (the 3x3 around it, among pixels still at that count) is at or above the
 * threshold: an edge's converged side goes on with its noisy side, as in Cycles. A
 * pixel's decision error is the mean of adaptive_pixel_error over its 3x3 block (each
 * pixel at its own count), or half its own error when that is larger: one estimate
 * alone is too noisy to stop on (adaptive.c, decision_error). *active: how many. */
Status adaptive_mask(const AdaptiveSettings *s, const AdaptiveFilm *af, uint *mask, size_t *active, Error *err);

/* Called after each round, with the state: progressive output and checkpoints. */
typedef void (*AdaptiveRoundFn)(void *ctx, const AdaptiveFilm *af);

typedef struct {
    Device **devices;
    size_t n_devices;
    RenderScene *rs;               /* its params and pixel list change during the render, restored after */
    const ScheduleConfig *cfg;     /* stop flag, time limit, warnings, batch size; spp the most a pixel gets */
    AdaptiveRoundFn on_round;      /* NULL: none */
    void *round_ctx;
} AdaptiveRun;

/* Renders rounds into af (fresh: all zero; resumed: a checkpoint's state) until every
 * pixel has stopped or holds cfg->spp samples, the stop flag or the time limit ends it,
 * or every device failed (ST_DEVICE). stats sums the rounds' runs (free with
 * schedule_stats_free); stats->samples counts the pixel samples of pixels that rendered. */
Status adaptive_run(const AdaptiveRun *run, const AdaptiveSettings *s, AdaptiveFilm *af, ScheduleStats *stats,
                    Error *err);

#endif /* CLPT_ADAPTIVE_H */
