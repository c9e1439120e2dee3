/* schedule.c — see schedule.h. */
#include "schedule.h"

#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "batch_queue.h"
#include "timer.h"

#define DEFAULT_BATCH_SECONDS 0.25
#define MAX_BATCH_SAMPLES 65536u

typedef struct Shared Shared;

typedef struct {
    Shared *shared;
    Device *dev;
    size_t index;               /* position in the selection */
    int64_t *scratch;           /* this device's batch film, added into the shared film */
    DeviceRunStats stats;
    double seconds_per_sample;  /* measured; 0 until the first batch */
    long fail_at_batch;         /* test hook: fail when starting this batch (-1: never) */
    int running;
} Worker;

struct Shared {
    const ScheduleConfig *cfg;
    BatchQueue queue;
    Film *film;
    pthread_mutex_t film_lock;
    pthread_mutex_t state_lock;
    pthread_cond_t state_cond;
    size_t active;              /* workers still running */
    double start;
    Worker *workers;
    size_t n_workers;
};

/* Tests make a device fail on purpose: CLPT_TEST_FAIL="DEVICE:BATCH[,DEVICE:BATCH...]"
 * makes the device at position DEVICE of the selection fail when it starts its BATCH-th
 * batch (counting from 0), as a real fault would: its batch goes back to the queue. */
static long injected_failure(size_t device_index)
{
    const char *spec = getenv("CLPT_TEST_FAIL");
    while (spec && *spec) {
        char *end;
        unsigned long dev = strtoul(spec, &end, 10);
        if (*end != ':') break;
        long batch = strtol(end + 1, &end, 10);
        if (dev == device_index) return batch;
        if (*end != ',') break;
        spec = end + 1;
    }
    return -1;
}

static void warn(Shared *sh, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void warn(Shared *sh, const char *fmt, ...)
{
    char msg[1400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (sh->cfg->on_warning) sh->cfg->on_warning(sh->cfg->ctx, msg);
}

/* How many samples to ask for next: about the target time's worth, at most doubling from
 * the last batch (speed estimates from tiny batches are noisy), and no more than a fair
 * share of what is left, so devices finish together. */
static uint choose_batch(Worker *w, size_t n_active)
{
    const ScheduleConfig *cfg = w->shared->cfg;
    if (cfg->fixed_batch) return cfg->fixed_batch;
    double target = cfg->target_batch_seconds > 0.0 ? cfg->target_batch_seconds : DEFAULT_BATCH_SECONDS;
    uint want = 1;
    if (w->seconds_per_sample > 0.0) {
        double n = floor(target / w->seconds_per_sample);
        want = n < 1.0 ? 1u : (n > MAX_BATCH_SAMPLES ? MAX_BATCH_SAMPLES : (uint)n);
        if (w->stats.batch_last && want > 2u * w->stats.batch_last) want = 2u * w->stats.batch_last;
    }
    uint remaining = batch_queue_remaining(&w->shared->queue);
    uint share = (uint)((remaining + n_active - 1) / (n_active ? n_active : 1));
    if (share >= 1 && want > share) want = share;
    if (cfg->time_limit > 0.0 && w->seconds_per_sample > 0.0) {
        double left = cfg->time_limit - (timer_now() - w->shared->start);
        double n = floor(left / w->seconds_per_sample);
        if (n < (double)want) want = n < 1.0 ? 1u : (uint)n;
    }
    return want;
}

static void *worker_main(void *arg)
{
    Worker *w = arg;
    Shared *sh = w->shared;
    const ScheduleConfig *cfg = sh->cfg;
    size_t film_len = (size_t)sh->film->width * sh->film->height * 3u;
    double thread_start = timer_now();
    for (;;) {
        if (cfg->stop && *cfg->stop) break;
        if (cfg->time_limit > 0.0 && timer_now() - sh->start >= cfg->time_limit) {
            batch_queue_close(&sh->queue);
            break;
        }
        pthread_mutex_lock(&sh->state_lock);
        size_t n_active = sh->active;
        pthread_mutex_unlock(&sh->state_lock);
        Batch b;
        if (!batch_queue_take(&sh->queue, choose_batch(w, n_active), &b)) break;

        double t0 = timer_now();
        Error err = { 0 };
        Status st;
        if (w->fail_at_batch >= 0 && (long)w->stats.batches == w->fail_at_batch)
            st = error_set(&err, ST_DEVICE, "failure injected by CLPT_TEST_FAIL");
        else
            st = w->dev->ops->render(w->dev, b.first, b.count, &err);
        if (st == ST_OK) st = w->dev->ops->take_film(w->dev, w->scratch, &err);
        double t1 = timer_now();
        if (st != ST_OK) {
            w->stats.failed = 1;
            snprintf(w->stats.failure, sizeof w->stats.failure, "%s", err.msg);
            memset(w->scratch, 0, film_len * sizeof *w->scratch);
            if (batch_queue_give_back(&sh->queue, b) != 0)
                warn(sh, "out of memory returning a batch; the image will have fewer samples");
            warn(sh, "device '%s' failed and was dropped; its samples go to the other devices: %s",
                 w->stats.name, err.msg);
            error_clear(&err);
            break;
        }

        pthread_mutex_lock(&sh->film_lock);
        for (size_t i = 0; i < film_len; i++) sh->film->sum[i] += w->scratch[i];
        sh->film->samples += b.count;
        pthread_mutex_unlock(&sh->film_lock);
        memset(w->scratch, 0, film_len * sizeof *w->scratch);
        batch_queue_done(&sh->queue, b);

        w->stats.batches++;
        w->stats.busy_seconds += t1 - t0;
        w->stats.batch_last = b.count;
        if (!w->stats.batch_min || b.count < w->stats.batch_min) w->stats.batch_min = b.count;
        if (b.count > w->stats.batch_max) w->stats.batch_max = b.count;
        w->seconds_per_sample = (t1 - t0) / (double)b.count;
    }
    w->stats.idle_seconds = (timer_now() - thread_start) - w->stats.busy_seconds;
    w->stats.samples = w->dev->counters.samples;
    w->stats.rays = w->dev->counters.rays;
    pthread_mutex_lock(&sh->state_lock);
    sh->active--;
    w->running = 0;
    pthread_cond_broadcast(&sh->state_cond);
    pthread_mutex_unlock(&sh->state_lock);
    return NULL;
}

static void wait_tick(Shared *sh, double seconds)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    long ns = ts.tv_nsec + (long)(seconds * 1e9);
    ts.tv_sec += ns / 1000000000L;
    ts.tv_nsec = ns % 1000000000L;
    pthread_mutex_lock(&sh->state_lock);
    if (sh->active > 0) pthread_cond_timedwait(&sh->state_cond, &sh->state_lock, &ts);
    pthread_mutex_unlock(&sh->state_lock);
}

void schedule_stats_free(ScheduleStats *s)
{
    free(s->devices);
    s->devices = NULL;
}

Status schedule_run(Device **devices, size_t n, const ScheduleConfig *cfg, Film *film,
                    ScheduleStats *stats, Error *err)
{
    memset(stats, 0, sizeof *stats);
    if (n == 0) return error_set(err, ST_DEVICE, "no device to render with");
    Shared sh;
    memset(&sh, 0, sizeof sh);
    sh.cfg = cfg;
    sh.film = film;
    size_t film_len = (size_t)film->width * film->height * 3u;
    Status st = ST_OK;
    if (batch_queue_init(&sh.queue, cfg->spp) != 0) return error_set(err, ST_INTERNAL, "cannot create a mutex");
    pthread_mutex_init(&sh.film_lock, NULL);
    pthread_mutex_init(&sh.state_lock, NULL);
    pthread_cond_init(&sh.state_cond, NULL);
    sh.workers = calloc(n, sizeof *sh.workers);
    pthread_t *threads = calloc(n, sizeof *threads);
    if (!sh.workers || !threads) {
        st = error_set(err, ST_INTERNAL, "out of memory starting the render");
        goto cleanup;
    }
    for (size_t i = 0; i < n; i++) {
        Worker *w = &sh.workers[i];
        w->shared = &sh;
        w->dev = devices[i];
        w->index = i;
        w->fail_at_batch = injected_failure(i);
        snprintf(w->stats.name, sizeof w->stats.name, "%s", devices[i]->desc.name);
        w->scratch = calloc(film_len, sizeof *w->scratch);
        if (!w->scratch) {
            st = error_set(err, ST_INTERNAL, "out of memory for device films");
            goto cleanup;
        }
    }
    sh.n_workers = n;
    sh.start = timer_now();
    sh.active = 0;
    for (size_t i = 0; i < n; i++) {
        sh.workers[i].running = 1;
        pthread_mutex_lock(&sh.state_lock);
        sh.active++;
        pthread_mutex_unlock(&sh.state_lock);
        if (pthread_create(&threads[i], NULL, worker_main, &sh.workers[i]) != 0) {
            pthread_mutex_lock(&sh.state_lock);
            sh.active--;
            sh.workers[i].running = 0;
            pthread_mutex_unlock(&sh.state_lock);
            threads[i] = 0;
            sh.workers[i].stats.failed = 1;
            snprintf(sh.workers[i].stats.failure, sizeof sh.workers[i].stats.failure,
                     "cannot start a host thread: %s", strerror(errno));
        }
    }

    Progress progress;
    double total = (double)cfg->spp * (double)film->width * (double)film->height;
    progress_begin(&progress, "render", total, "samples", cfg->show_progress);
    double last_tick = sh.start;
    for (;;) {
        wait_tick(&sh, 0.1);
        pthread_mutex_lock(&sh.state_lock);
        size_t active = sh.active;
        pthread_mutex_unlock(&sh.state_lock);
        if (cfg->stop && *cfg->stop) {
            batch_queue_close(&sh.queue);
            stats->interrupted = 1;
        }
        double done = (double)batch_queue_completed(&sh.queue) * (double)film->width * (double)film->height;
        progress_update(&progress, done);
        if (cfg->on_tick && cfg->tick_seconds > 0.0 && timer_now() - last_tick >= cfg->tick_seconds && active > 0) {
            last_tick = timer_now();
            pthread_mutex_lock(&sh.film_lock);
            cfg->on_tick(cfg->ctx, film);
            pthread_mutex_unlock(&sh.film_lock);
        }
        if (active == 0) break;
    }
    progress_end(&progress);
    for (size_t i = 0; i < n; i++)
        if (threads[i]) pthread_join(threads[i], NULL);

    stats->seconds = timer_now() - sh.start;
    stats->spp_done = (uint)film->samples;
    stats->time_up = cfg->time_limit > 0.0 && batch_queue_completed(&sh.queue) < cfg->spp && !stats->interrupted;
    stats->n_devices = n;
    stats->devices = calloc(n, sizeof *stats->devices);
    size_t failed = 0;
    for (size_t i = 0; i < n; i++) {
        if (stats->devices) stats->devices[i] = sh.workers[i].stats;
        stats->samples += sh.workers[i].stats.samples;
        stats->rays += sh.workers[i].stats.rays;
        failed += (size_t)sh.workers[i].stats.failed;
    }
    if (failed == n)
        st = error_set(err, ST_DEVICE, "every device failed (last: %s: %s); %u of %u samples per pixel were finished",
                       sh.workers[n - 1].stats.name, sh.workers[n - 1].stats.failure,
                       (unsigned)film->samples, cfg->spp);
    else if (!stats->interrupted && !stats->time_up && batch_queue_completed(&sh.queue) < cfg->spp)
        st = error_set(err, ST_INTERNAL, "the render ended with %u of %u samples per pixel done",
                       batch_queue_completed(&sh.queue), cfg->spp);

cleanup:
    if (sh.workers)
        for (size_t i = 0; i < n; i++) free(sh.workers[i].scratch);
    free(sh.workers);
    free(threads);
    pthread_cond_destroy(&sh.state_cond);
    pthread_mutex_destroy(&sh.state_lock);
    pthread_mutex_destroy(&sh.film_lock);
    batch_queue_free(&sh.queue);
    return st;
}
