/* adaptive.c — adaptive sampling for the path tracer (see adaptive.h). */
#include "render/adaptive.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/progress.h"
#include "base/timer.h"

Status adaptive_film_init(AdaptiveFilm *af, uint width, uint height, Error *err)
{
    memset(af, 0, sizeof *af);
    Status st = film_init(&af->film, width, height, err);
    if (st) return st;
    size_t n = (size_t)width * height;
    af->odd = calloc(n * 3u, sizeof *af->odd);
    af->spp = calloc(n, sizeof *af->spp);
    if (!af->odd || !af->spp) {
        adaptive_film_free(af);
        return error_set(err, ST_INTERNAL, "out of memory for a %ux%u adaptive film", width, height);
    }
    return ST_OK;
}

void adaptive_film_free(AdaptiveFilm *af)
{
    film_free(&af->film);
    free(af->odd);
    free(af->spp);
    memset(af, 0, sizeof *af);
}

void adaptive_film_resolve(const AdaptiveFilm *af, float *rgb)
{
    size_t n = (size_t)af->film.width * af->film.height;
    for (size_t i = 0; i < n; i++) {
        /* in double, as film_resolve: a sum can exceed float's mantissa by far */
        double scale = af->spp[i] ? 1.0 / ((double)(1u << FILM_FRAC_BITS) * (double)af->spp[i]) : 0.0;
        for (int c = 0; c < 3; c++) rgb[3 * i + c] = (float)((double)af->film.sum[3 * i + c] * scale);
    }
}

Status adaptive_film_write(const AdaptiveFilm *af, const char *path, const ImageStyle *style, Error *err)
{
    size_t n = (size_t)af->film.width * af->film.height * 3u;
    float *rgb = malloc(n * sizeof *rgb);
    if (!rgb) return error_set(err, ST_INTERNAL, "out of memory resolving the image");
    adaptive_film_resolve(af, rgb);
    Status st = image_write_styled(path, rgb, af->film.width, af->film.height, style, err);
    free(rgb);
    return st;
}

double adaptive_pixel_error(const AdaptiveFilm *af, size_t pixel)
{
    uint n = af->spp[pixel];
    if (n == 0) return 0.0;
    /* integer sums to double: exact below 2^53, and the same on every machine */
    double unit = 1.0 / ((double)(1u << FILM_FRAC_BITS) * (double)n);
    double diff = 0.0, sum = 0.0;
    for (int c = 0; c < 3; c++) {
        int64_t all = af->film.sum[3 * pixel + c], odd = af->odd[3 * pixel + c];
        int64_t even = all - odd;
        diff += (double)(even > odd ? even - odd : odd - even) * unit;
        sum += (double)all * unit;
    }
    return diff / (1e-4 + sqrt(sum));
}

/* The first decision: min_spp rounded up to even, so that the halves hold as many. */
static uint first_stop(const AdaptiveSettings *s)
{
    return s->min_spp + (s->min_spp & 1u);
}

/* The next decision count: the least even m 2^j above `stop` with m 4, 5 or 6 (4, 6,
 * 8, 10, 12, 16, 20, 24, 32, 40, 48, 64 ...), each a fifth to a third more than the
 * last. Counts with at most two bits set below a power of two are where the Sobol
 * sampler's points are best spread: uniform sampling's MSE x samples on the Cornell
 * box was 1.6-1.8e-3 at 512 and 768 spp, 2.0-2.2e-3 at 611 and 694 (bench/RESULTS.md),
 * and a pixel that stops ends at one of these counts. */
static uint stop_after(uint stop)
{
    for (uint j = 0; j < 30u; j++)
        for (uint m = 4; m <= 6u; m++) {
            uint n = m << j;
            if (n > stop && !(n & 1u)) return n;
        }
    return stop + 2u;   /* past 6 * 2^29: not reached (CLPT_MAX_SPP is far below) */
}

int adaptive_decides_at(const AdaptiveSettings *s, uint n)
{
    uint stop = first_stop(s);
    while (stop < n) stop = stop_after(stop);
    return stop == n;
}

uint adaptive_next_stop(const AdaptiveSettings *s, uint reached, uint spp)
{
    uint stop = first_stop(s);
    while (stop <= reached) stop = stop_after(stop);
    return stop < spp ? stop : spp;
}

/* The error a decision compares with the threshold: the mean of the errors of pixel
 * (x, y) and its 8 neighbours (those in the image, each at its own count), or half the
 * pixel's own error when that is larger.
 *
 * Why a mean: one pixel's estimate is the difference of two half means, whose spread is
 * as large as the error it estimates (|E - O| of a normal variable is below a quarter
 * of its deviation one time in five), and at 16 samples a rare bright path is in
 * neither half more often than not. Judged alone, pixels stopped on a lucky estimate
 * were half of McGuire's box at --noise-threshold 0.05, with 2.5 to 6 times the MSE
 * they have in a uniform render of the same cost. Neighbours see nearly the same light,
 * and the mean of nine estimates varies a third as much; so a decision judges a 3x3
 * block, as Dammertz et al. (2010) judge image blocks rather than pixels.
 * Why half the pixel's own: a mean also outvotes a pixel that holds a firefly among
 * quiet neighbours, which then stops with it (on tests/test_adaptive.c's scene ten such
 * pixels held 42% of the squared error); one whose own error is twice the threshold
 * goes on whatever its block says. */
static double decision_error(const double *pixel_error, uint w, uint h, uint x, uint y)
{
    double sum = 0.0;
    uint k = 0;
    for (uint yy = y ? y - 1u : 0u; yy <= y + 1u && yy < h; yy++)
        for (uint xx = x ? x - 1u : 0u; xx <= x + 1u && xx < w; xx++, k++) sum += pixel_error[(size_t)yy * w + xx];
    double block = sum / (double)k, own = 0.5 * pixel_error[(size_t)y * w + x];
    return block > own ? block : own;
}

/* 1 where pixel (x, y) or one of its 8 neighbours is set in `noisy`. */
static uint near_noisy(const uint *noisy, uint w, uint h, uint x, uint y)
{
    for (uint yy = y ? y - 1u : 0u; yy <= y + 1u && yy < h; yy++)
        for (uint xx = x ? x - 1u : 0u; xx <= x + 1u && xx < w; xx++)
            if (noisy[(size_t)yy * w + xx]) return 1u;
    return 0u;
}

Status adaptive_mask(const AdaptiveSettings *s, const AdaptiveFilm *af, uint *mask, size_t *active, Error *err)
{
    uint w = af->film.width, h = af->film.height;
    size_t n = (size_t)w * h;
    uint reached = (uint)af->film.samples;
    int decide = reached > 0 && adaptive_decides_at(s, reached);
    *active = 0;
    /* between decisions every pixel at the count goes on */
    if (!decide) {
        for (size_t i = 0; i < n; i++) *active += (mask[i] = af->spp[i] == reached);
        return ST_OK;
    }
    uint *noisy = malloc(n * sizeof *noisy);
    double *pixel_error = malloc(n * sizeof *pixel_error);
    if (!noisy || !pixel_error) {
        free(noisy);
        free(pixel_error);
        return error_set(err, ST_INTERNAL, "out of memory for the adaptive sampling mask");
    }
    for (size_t i = 0; i < n; i++) pixel_error[i] = adaptive_pixel_error(af, i);
    for (uint y = 0; y < h; y++)
        for (uint x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            noisy[i] = af->spp[i] == reached && !(decision_error(pixel_error, w, h, x, y) < s->threshold);
        }
    free(pixel_error);
    for (uint y = 0; y < h; y++)
        for (uint x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            mask[i] = af->spp[i] == reached && near_noisy(noisy, w, h, x, y);
            *active += mask[i];
        }
    free(noisy);
    return ST_OK;
}

/* ------------------------------------------------------------------ the rounds */

/* Gives every device the params block and pixel list of the run's scene. */
/* Adds one scheduler run's statistics into the render's. */
static Status stats_add(ScheduleStats *sum, const ScheduleStats *one, Error *err)
{
    if (!sum->devices && one->n_devices) {
        sum->devices = calloc(one->n_devices, sizeof *sum->devices);
        if (!sum->devices) return error_set(err, ST_INTERNAL, "out of memory");
        sum->n_devices = one->n_devices;
        for (size_t i = 0; i < one->n_devices; i++) {
            memcpy(sum->devices[i].name, one->devices[i].name, sizeof sum->devices[i].name);
            sum->devices[i].batch_min = one->devices[i].batch_min;
        }
    }
    sum->seconds += one->seconds;
    sum->rays += one->rays;
    sum->interrupted |= one->interrupted;
    sum->time_up |= one->time_up;
    sum->snapshot_seconds += one->snapshot_seconds;
    for (size_t i = 0; i < sum->n_devices && i < one->n_devices; i++) {
        DeviceRunStats *a = &sum->devices[i];
        const DeviceRunStats *b = &one->devices[i];
        a->batches += b->batches;
        a->samples += b->samples;
        a->rays += b->rays;
        a->busy_seconds += b->busy_seconds;
        a->idle_seconds += b->idle_seconds;
        if (b->batches && (b->batch_min < a->batch_min || !a->batch_min)) a->batch_min = b->batch_min;
        if (b->batch_max > a->batch_max) a->batch_max = b->batch_max;
        if (b->batches) a->batch_last = b->batch_last;
        if (b->failed && !a->failed) {
            a->failed = 1;
            memcpy(a->failure, b->failure, sizeof a->failure);
        }
    }
    return ST_OK;
}

/* The half-samples [first, end) of parity `half` (sample_step 2, sample_offset half)
 * of the listed pixels into `film`, a fresh film. *whole: every one of them was
 * rendered (no interrupt, time limit or lost samples). */
static Status render_half(const AdaptiveRun *run, uint half, uint first, uint end, double time_left, Film *film,
                          ScheduleStats *sum, int *whole, Error *err)
{
    RenderParams *p = &run->rs->ds.params;
    p->sample_step = 2u;
    p->sample_offset = half;
    Status st = device_update_all(run->devices, run->n_devices, &run->rs->ds, err);
    if (st) return st;
    ScheduleConfig cfg = schedule_config_part(run->cfg, first, end, time_left);
    ScheduleStats one;
    st = schedule_run(run->devices, run->n_devices, &cfg, film, &one, err);
    *whole = st == ST_OK && !one.interrupted && !one.time_up && film->samples == end - first;
    Status added = stats_add(sum, &one, st ? NULL : err);
    schedule_stats_free(&one);
    return st ? st : added;
}

/* The halves of [reached, next) are the even indices ceil(reached/2) .. ceil(next/2)
 * and the odd ones floor(reached/2) .. floor(next/2), in half-samples. */
static Status render_round(const AdaptiveRun *run, AdaptiveFilm *af, const uint *mask, uint next, double t0,
                           ScheduleStats *sum, int *whole, Error *err)
{
    uint reached = (uint)af->film.samples;
    size_t n = (size_t)af->film.width * af->film.height;
    Film half[2];
    memset(half, 0, sizeof half);
    Status st = ST_OK;
    *whole = 1;
    for (uint h = 0; h < 2u && st == ST_OK && *whole; h++) {
        uint first = (reached + 1u - h) / 2u, end = (next + 1u - h) / 2u;
        if ((st = film_init(&half[h], af->film.width, af->film.height, err)) || first == end) continue;
        double left = 0.0;
        if (run->cfg->time_limit > 0.0 && !((left = run->cfg->time_limit - (timer_now() - t0)) > 0.0)) {
            sum->time_up = 1;
            *whole = 0;
            break;
        }
        st = render_half(run, h, first, end, left, &half[h], sum, whole, err);
    }
    if (st == ST_OK && *whole) {
        for (size_t i = 0; i < n * 3u; i++) {
            af->film.sum[i] += half[0].sum[i] + half[1].sum[i];
            af->odd[i] += half[1].sum[i];
        }
        for (size_t i = 0; i < n; i++) af->spp[i] += mask[i] ? next - reached : 0u;
        af->film.samples = next;
    }
    film_free(&half[0]);
    film_free(&half[1]);
    return st;
}

/* Pixel samples in the film (those of converged pixels stop counting). */
static uint64_t pixel_samples(const AdaptiveFilm *af)
{
    size_t n = (size_t)af->film.width * af->film.height;
    uint64_t total = 0;
    for (size_t i = 0; i < n; i++) total += af->spp[i];
    return total;
}

Status adaptive_run(const AdaptiveRun *run, const AdaptiveSettings *s, AdaptiveFilm *af, ScheduleStats *stats,
                    Error *err)
{
    memset(stats, 0, sizeof *stats);
    DeviceScene *ds = &run->rs->ds;
    size_t n = (size_t)ds->params.width * ds->params.height;
    uint spp = run->cfg->spp;
    uint *mask = malloc(n * sizeof *mask), *list = malloc(n * sizeof *list);
    if (!mask || !list) {
        free(mask);
        free(list);
        return error_set(err, ST_INTERNAL, "out of memory for the adaptive sampling mask");
    }
    RenderParams saved = ds->params;
    ds->pixel_list = list;
    Progress prog;
    progress_begin(&prog, "render", (double)spp, "spp", run->cfg->show_progress);
    double t0 = timer_now();
    uint64_t before = pixel_samples(af);
    Status st = ST_OK;
    while (st == ST_OK && af->film.samples < spp && !(run->cfg->stop && *run->cfg->stop)) {
        size_t active = 0;
        if ((st = adaptive_mask(s, af, mask, &active, err)) || active == 0) break;
        /* the round's waves hold the pixels still rendering only */
        ds->params.pixel_list_size = render_scene_list_pixels(mask, n, list);
        int whole = 0;
        st = render_round(run, af, mask, adaptive_next_stop(s, (uint)af->film.samples, spp), t0, stats, &whole, err);
        if (st || !whole) break;
        progress_update(&prog, (double)af->film.samples);
        if (run->on_round) run->on_round(run->round_ctx, af);
    }
    progress_end(&prog);
    if (run->cfg->stop && *run->cfg->stop && af->film.samples < spp) stats->interrupted = 1;
    stats->seconds = timer_now() - t0;
    stats->samples = pixel_samples(af) - before;
    stats->spp_done = (uint)af->film.samples;
    stats->adaptive = 1;
    /* the pixels still rendering hold these indices, the others a start of them */
    if (af->film.samples && batch_set_add(&stats->done, (Batch){ 0, (uint)af->film.samples }) != 0 && st == ST_OK)
        st = error_set(err, ST_INTERNAL, "out of memory");
    ds->params = saved;
    ds->pixel_list = NULL;
    /* the devices too: none keeps the list freed below */
    Status restored = device_update_all(run->devices, run->n_devices, &run->rs->ds, st == ST_OK ? err : NULL);
    free(mask);
    free(list);
    return st ? st : restored;
}
