/* split_pilot.c — `--split auto`: the pilot render that chooses first-hit splitting
 * (see split_pilot.h). */
#include "render/split_pilot.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/timer.h"
#include "render/render_scene.h"

const uint split_pilot_candidates[SPLIT_PILOT_CANDIDATES] = { 1u, 2u, 4u, 8u, 16u };
const uint split_pilot_measured_splits[SPLIT_PILOT_MEASURED] = { 1u, 2u, 4u, 16u };

uint split_pilot_plan(uint width, uint height, uint *stride, uint *pilot_spp)
{
    *stride = 0u;
    *pilot_spp = 0u;
    uint64_t n = (uint64_t)width * height;
    if (n < SPLIT_PILOT_MIN_IMAGE) return 0u;
    uint64_t want = n / 128u > SPLIT_PILOT_MIN_PIXELS ? n / 128u : SPLIT_PILOT_MIN_PIXELS;
    /* the grid's step: the largest whose grid still holds `want` pixels */
    uint k = (uint)floor(sqrt((double)n / (double)want));
    if (k == 0u) k = 1u;
    *stride = k;
    *pilot_spp = SPLIT_PILOT_SPP;
    return ((width + k - 1u - k / 2u) / k) * ((height + k - 1u - k / 2u) / k);
}

static double det3(double a[3][3])
{
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

int split_pilot_fit(const SplitPilot *sp, SplitModel *m)
{
    uint n = sp->measured;
    if (n < 3u) return 0;
    /* the normal equations of y ~ c0 + c1 x + c2 x^2 over the readings, x = log2 N,
     * y = log(error x rays): sums of x^0..x^4 and of y x^0..x^2 */
    double sx[5] = { 0.0 }, sy[3] = { 0.0 };
    for (uint i = 0; i < n; i++) {
        double e = sp->error[i] * (double)sp->rays[i];
        if (!(e > 0.0) || !isfinite(e) || sp->split[i] == 0u) return 0;
        double x = log2((double)sp->split[i]), y = log(e), xp = 1.0;
        for (uint k = 0; k < 5u; k++, xp *= x) {
            sx[k] += xp;
            if (k < 3u) sy[k] += xp * y;
        }
    }
    /* Cramer's rule on the 3 x 3 system (well conditioned for x in 0..4) */
    double a[3][3] = { { sx[0], sx[1], sx[2] }, { sx[1], sx[2], sx[3] }, { sx[2], sx[3], sx[4] } };
    double det = det3(a);
    if (!(fabs(det) > 1e-9)) return 0;
    double c[3];
    for (uint j = 0; j < 3u; j++) {
        double t[3][3];
        memcpy(t, a, sizeof t);
        for (uint r = 0; r < 3u; r++) t[r][j] = sy[r];
        c[j] = det3(t) / det;
    }
    m->c0 = c[0];
    m->c1 = c[1];
    m->c2 = c[2];
    return 1;
}

/* The fitted log(error x rays) at split n: log2 of a power of two is exact */
static double model_log_cost(const SplitModel *m, uint n)
{
    double x = log2((double)n);
    return m->c0 + m->c1 * x + m->c2 * x * x;
}

double split_model_cost(const SplitModel *m, uint n)
{
    return exp(model_log_cost(m, n));
}

uint split_pilot_choose(const SplitPilot *sp)
{
    if (!sp->fitted) return 1u;
    uint best = 0u;
    for (uint i = 1; i < SPLIT_PILOT_CANDIDATES; i++)
        if (model_log_cost(&sp->model, split_pilot_candidates[i]) < model_log_cost(&sp->model, split_pilot_candidates[best]))
            best = i;
    /* compared as logarithms: no exp between the fit and the choice */
    return model_log_cost(&sp->model, split_pilot_candidates[best]) - model_log_cost(&sp->model, 1u) < log(SPLIT_PILOT_GAIN)
               ? split_pilot_candidates[best] : 1u;
}

/* Samples [0, spp) of the listed pixels with `seed`, in a film of their own: each pixel's
 * channel values (radiance, the film's sums over spp) into v[3n], its rays added to
 * *rays. *whole: every sample was rendered. The params' seed is restored; the film of
 * the image's size lives only in here, so one is kept at a time. */
static Status render_pixels(const AdaptiveRun *run, const uint *list, uint n, uint seed, uint spp, double *v,
                            uint64_t *rays, int *whole, Error *err)
{
    RenderParams *p = &run->rs->ds.params;
    uint render_seed_was = p->seed;
    Film film;
    Status st = film_init(&film, p->width, p->height, err);
    if (st) return st;
    p->seed = seed;
    if ((st = device_update_all(run->devices, run->n_devices, &run->rs->ds, err)) == ST_OK) {
        ScheduleConfig cfg = schedule_config_part(run->cfg, 0u, spp, 0.0);
        /* The pilot's samples in a batch per device: grown from one sample, as a render's
         * batches are, they took four batches a film, each with its launch and its film
         * read back, a quarter of the dragon's pilot (bench/RESULTS.md). The film's
         * fixed-point sums do not depend on the batches, so neither does the choice. */
        cfg.fixed_batch = (spp + (uint)run->n_devices - 1u) / (uint)run->n_devices;
        ScheduleStats one;
        st = schedule_run(run->devices, run->n_devices, &cfg, &film, &one, err);
        *whole = st == ST_OK && !one.interrupted && !one.time_up && film.samples == spp;
        *rays += one.rays;
        schedule_stats_free(&one);
    }
    /* film units to radiance: the film holds spp samples of a pixel */
    double unit = 1.0 / ((double)(1u << FILM_FRAC_BITS) * (double)spp);
    for (uint i = 0; st == ST_OK && i < n; i++)
        for (uint c = 0; c < 3u; c++) v[3u * i + c] = (double)film.sum[3u * (size_t)list[i] + c] * unit;
    film_free(&film);
    p->seed = render_seed_was;
    return st;
}

/* The pilot's weights: 1 / (v^2 + SPLIT_PILOT_REL_EPS) for each listed pixel's channel
 * value v in a film of their own (split 1, SPLIT_PILOT_SEED_W), into w[3n]. Each split's
 * films are weighed by these, not by their own mean: a pixel where one film drew a rare
 * bright path (a highlight of the sun) then also had a large mean, which capped its
 * relative error near 4 whatever that path's size, so the pilot read envmat's split 16 at
 * 0.83 of split 1's error x rays where it is at 0.59 (bench/RESULTS.md). With one film's
 * weights for every split, the splits are compared on the same measure, and none of
 * them is weighed by its own samples. */
static Status weigh(const AdaptiveRun *run, const uint *list, uint n, uint spp, double *w, int *whole, Error *err)
{
    uint64_t rays = 0;
    Status st = render_pixels(run, list, n, SPLIT_PILOT_SEED_W, spp, w, &rays, whole, err);
    for (uint i = 0; st == ST_OK && i < 3u * n; i++) w[i] = 1.0 / (w[i] * w[i] + SPLIT_PILOT_REL_EPS);
    return st;
}

/* The pilot at the params' split: the listed pixels' samples [0, spp) with two seeds of
 * its own, two independent estimates of each pixel (the even and odd
 * samples of one Sobol sequence are not: they stratify each other, and their difference
 * put the Cornell box's split 2 at 0.72 of split 1 where it is at 1.24), their squared
 * difference weighed by w (weigh). */
static Status measure(const AdaptiveRun *run, const uint *list, uint n, uint spp, const double *w, double *error,
                      uint64_t *rays, int *whole, Error *err)
{
    double *a = malloc((size_t)n * 6u * sizeof *a);
    if (!a) return error_set(err, ST_INTERNAL, "out of memory for the split pilot");
    double *b = a + (size_t)n * 3u;
    *whole = 1;
    *rays = 0;
    Status st = render_pixels(run, list, n, SPLIT_PILOT_SEED_A, spp, a, rays, whole, err);
    if (st == ST_OK && *whole) st = render_pixels(run, list, n, SPLIT_PILOT_SEED_B, spp, b, rays, whole, err);
    double e = 0.0;
    for (uint i = 0; st == ST_OK && *whole && i < 3u * n; i++) e += (a[i] - b[i]) * (a[i] - b[i]) * w[i];
    *error = e;
    free(a);
    return st;
}

static Status set_split(const AdaptiveRun *run, uint split, Error *err)
{
    run->rs->ds.params.split = split;
    return device_update_all(run->devices, run->n_devices, &run->rs->ds, err);
}

Status split_pilot_run(const AdaptiveRun *run, SplitPilot *sp, Error *err)
{
    memset(sp, 0, sizeof *sp);
    sp->chosen = 1u;
    DeviceScene *ds = &run->rs->ds;
    RenderParams *p = &ds->params;
    if (p->split != 0u) {
        sp->chosen = p->split;
        return ST_OK;
    }
    uint stride, pilot_spp;
    uint n = p->integrator == INTEGRATOR_PATH && p->camera_medium == 0u
                 ? split_pilot_plan(p->width, p->height, &stride, &pilot_spp) : 0u;
    if (n == 0u) return set_split(run, 1u, err);
    uint *list = malloc((size_t)n * sizeof *list);
    double *w = malloc((size_t)n * 3u * sizeof *w);
    if (!list || !w) {
        free(list);
        free(w);
        return error_set(err, ST_INTERNAL, "out of memory for the split pilot");
    }
    uint k = 0;
    for (uint y = stride / 2u; y < p->height; y += stride)
        for (uint x = stride / 2u; x < p->width; x += stride) list[k++] = y * p->width + x;
    RenderParams saved = *p;
    const uint *saved_list = ds->pixel_list;
    ds->pixel_list = list;
    p->pixel_list_size = n;
    double t0 = timer_now();
    Status st = ST_OK;
    int whole = 1;
    if ((st = set_split(run, 1u, err)) == ST_OK) st = weigh(run, list, n, pilot_spp, w, &whole, err);
    for (uint c = 0; c < SPLIT_PILOT_MEASURED && st == ST_OK && whole; c++) {
        if ((st = set_split(run, split_pilot_measured_splits[c], err))) break;
        st = measure(run, list, n, pilot_spp, w, &sp->error[c], &sp->rays[c], &whole, err);
        if (st == ST_OK && whole) sp->split[sp->measured++] = split_pilot_measured_splits[c];
    }
    sp->seconds = timer_now() - t0;
    sp->pixels = n;
    sp->spp = pilot_spp;
    sp->ran = st == ST_OK && whole;
    sp->fitted = sp->ran && split_pilot_fit(sp, &sp->model);
    *p = saved;
    ds->pixel_list = saved_list;
    free(list);
    free(w);
    if (st) return st;
    sp->chosen = sp->ran ? split_pilot_choose(sp) : 1u;
    /* the devices get the params back, with the split chosen, and drop the list */
    return set_split(run, sp->chosen, err);
}
