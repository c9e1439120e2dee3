/* schedule.c — see schedule.h. */
#include "render/schedule.h"

#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/timer.h"

#define DEFAULT_BATCH_SECONDS 0.25
#define MAX_BATCH_SAMPLES 65536u
/* Most batches one device may have in flight (device.h: max_in_flight). */
#define MAX_PIPELINE 4u

typedef struct Shared Shared;

typedef struct {
    Shared *shared;
    Device *dev;
    size_t index;               /* position in the selection */
    int64_t *scratch;           /* one batch's film, added into the shared film */
    DeviceRunStats stats;
    double seconds_per_sample;  /* measured; 0 until the first batch */
    long fail_at_batch;         /* test hook: fail when starting this batch (-1: never) */
    unsigned started;           /* batches handed to the device */
} Worker;

struct Shared {
    const ScheduleConfig *cfg;
    BatchQueue queue;
    Film *film;
    BatchSet done;              /* sample ranges in the film; under film_lock */
    int done_lost;              /* out of memory recording `done`: no more checkpoints */
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
 * batch (counting from 0), as a real fault would: its batches go back to the queue. */
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

static int time_is_up(const Shared *sh)
{
    return sh->cfg->time_limit > 0.0 && timer_now() - sh->start >= sh->cfg->time_limit;
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

/* Adds a finished batch's film into the shared film, in one step with the record of
 * which samples the film holds, so that a snapshot always sees the two agree. */
static void merge_batch(Worker *w, Batch b)
{
    Shared *sh = w->shared;
    size_t len = (size_t)sh->film->width * sh->film->height * 3u;
    int lost = 0;
    pthread_mutex_lock(&sh->film_lock);
    for (size_t i = 0; i < len; i++) sh->film->sum[i] += w->scratch[i];
    sh->film->samples += b.count;
    if (!sh->done_lost && batch_set_add(&sh->done, b) != 0) lost = sh->done_lost = 1;
    pthread_mutex_unlock(&sh->film_lock);
    if (lost) warn(sh, "out of memory recording the finished batches; no more checkpoints will be written");
    memset(w->scratch, 0, len * sizeof *w->scratch);
}

static void *worker_main(void *arg)
{
    Worker *w = arg;
    Shared *sh = w->shared;
    const ScheduleConfig *cfg = sh->cfg;
    size_t film_len = (size_t)sh->film->width * sh->film->height * 3u;
    uint depth = w->dev->max_in_flight ? w->dev->max_in_flight : 1u;
    if (depth > MAX_PIPELINE) depth = MAX_PIPELINE;
    Batch flight[MAX_PIPELINE];   /* rendered, film not yet taken; oldest first */
    uint n_flight = 0;
    double thread_start = timer_now();
    uint64_t samples_before = w->dev->counters.samples, rays_before = w->dev->counters.rays;
    Error err = { 0 };
    Status st = ST_OK;
    for (;;) {
        int stopping = cfg->stop && *cfg->stop;
        if (!stopping && time_is_up(sh)) {
            batch_queue_close(&sh->queue);
            stopping = 1;
        }
        /* Keep the device's pipeline full: the next batch is handed over before the
         * last one's film is taken. Only a worker with nothing in flight may wait for
         * a batch, or it could wait for its own. */
        if (!stopping && n_flight < depth) {
            pthread_mutex_lock(&sh->state_lock);
            size_t n_active = sh->active;
            pthread_mutex_unlock(&sh->state_lock);
            Batch b;
            uint want = choose_batch(w, n_active);
            int got = n_flight ? batch_queue_try_take(&sh->queue, want, &b) : batch_queue_take(&sh->queue, want, &b);
            if (got) {
                flight[n_flight++] = b;
                double t0 = timer_now();
                if (w->fail_at_batch >= 0 && (long)w->started == w->fail_at_batch)
                    st = error_set(&err, ST_DEVICE, "failure injected by CLPT_TEST_FAIL");
                else
                    st = w->dev->ops->render(w->dev, b.first, b.count, &err);
                w->started++;
                double t1 = timer_now();
                if (st != ST_OK) {
                    /* The batches before this one may be complete on the device: keep
                     * what can still be taken. */
                    Batch failed = flight[--n_flight];
                    if (batch_queue_give_back(&sh->queue, failed) != 0)
                        warn(sh, "out of memory returning a batch; the image will have fewer samples");
                    Error take_err = { 0 };
                    while (n_flight > 0 && w->dev->ops->take_film(w->dev, w->scratch, &take_err) == ST_OK) {
                        Batch done = flight[0];
                        memmove(&flight[0], &flight[1], --n_flight * sizeof *flight);
                        merge_batch(w, done);
                        batch_queue_done(&sh->queue, done);
                        w->stats.batches++;
                    }
                    memset(w->scratch, 0, film_len * sizeof *w->scratch);
                    error_clear(&take_err);
                    break;
                }
                w->stats.busy_seconds += t1 - t0;
                /* render returns when the device has worked through the batch (for a
                 * pipelined device, all but the film's read-back) */
                w->seconds_per_sample = (t1 - t0) / (double)b.count;
                w->stats.batch_last = b.count;
                if (!w->stats.batch_min || b.count < w->stats.batch_min) w->stats.batch_min = b.count;
                if (b.count > w->stats.batch_max) w->stats.batch_max = b.count;
                continue;
            }
        }
        if (n_flight == 0) break;

        double t0 = timer_now();
        st = w->dev->ops->take_film(w->dev, w->scratch, &err);
        w->stats.busy_seconds += timer_now() - t0;
        if (st != ST_OK) {
            memset(w->scratch, 0, film_len * sizeof *w->scratch);
            break;
        }
        Batch b = flight[0];
        memmove(&flight[0], &flight[1], --n_flight * sizeof *flight);
        merge_batch(w, b);
        batch_queue_done(&sh->queue, b);
        w->stats.batches++;
    }
    if (st != ST_OK) {
        /* Whatever this device had in flight goes to the others. */
        w->stats.failed = 1;
        snprintf(w->stats.failure, sizeof w->stats.failure, "%s", err.msg);
        for (uint i = 0; i < n_flight; i++)
            if (batch_queue_give_back(&sh->queue, flight[i]) != 0)
                warn(sh, "out of memory returning a batch; the image will have fewer samples");
        warn(sh, "device '%s' failed and was dropped; its samples go to the other devices: %s", w->stats.name,
             err.msg);
        error_clear(&err);
    }
    w->stats.idle_seconds = (timer_now() - thread_start) - w->stats.busy_seconds;
    w->stats.samples = w->dev->counters.samples - samples_before;
    w->stats.rays = w->dev->counters.rays - rays_before;
    pthread_mutex_lock(&sh->state_lock);
    sh->active--;
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

/* Copies the film and the record of its samples under the lock, so the callbacks can
 * take their time (PNG encoding, disk writes) while the devices go on merging. Returns
 * 0, or -1 when the record is incomplete (out of memory) and must not be used. */
static int take_snapshot(Shared *sh, Film *copy, BatchSet *done)
{
    size_t len = (size_t)sh->film->width * sh->film->height * 3u;
    pthread_mutex_lock(&sh->film_lock);
    memcpy(copy->sum, sh->film->sum, len * sizeof *copy->sum);
    copy->samples = sh->film->samples;
    int rc = sh->done_lost || batch_set_copy(done, &sh->done) != 0 ? -1 : 0;
    pthread_mutex_unlock(&sh->film_lock);
    return rc;
}

void schedule_stats_free(ScheduleStats *s)
{
    free(s->devices);
    s->devices = NULL;
    batch_set_free(&s->done);
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
    Film snap;
    memset(&snap, 0, sizeof snap);
    BatchSet snap_done;
    memset(&snap_done, 0, sizeof snap_done);
    pthread_t *threads = NULL;
    if (batch_queue_init(&sh.queue, cfg->spp) != 0) return error_set(err, ST_INTERNAL, "cannot create a mutex");
    pthread_mutex_init(&sh.film_lock, NULL);
    pthread_mutex_init(&sh.state_lock, NULL);
    pthread_cond_init(&sh.state_cond, NULL);
    for (size_t i = 0; i < cfg->n_done; i++)
        if (batch_set_add(&sh.done, cfg->done[i]) != 0) {
            st = error_set(err, ST_INTERNAL, "out of memory starting the render");
            goto cleanup;
        }
    int rc = batch_queue_skip_done(&sh.queue, cfg->done, cfg->n_done);
    if (rc != 0) {
        st = rc == -2 ? error_set(err, ST_INTERNAL, "out of memory starting the render")
                      : error_set(err, ST_INTERNAL, "the finished sample ranges overlap or exceed %u samples", cfg->spp);
        goto cleanup;
    }
    uint done_before = batch_queue_completed(&sh.queue);
    sh.workers = calloc(n, sizeof *sh.workers);
    threads = calloc(n, sizeof *threads);
    if (!sh.workers || !threads) {
        st = error_set(err, ST_INTERNAL, "out of memory starting the render");
        goto cleanup;
    }
    if ((cfg->on_tick || cfg->on_checkpoint) && film_init(&snap, film->width, film->height, err) != ST_OK) {
        st = ST_INTERNAL;
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
        pthread_mutex_lock(&sh.state_lock);
        sh.active++;
        pthread_mutex_unlock(&sh.state_lock);
        if (pthread_create(&threads[i], NULL, worker_main, &sh.workers[i]) != 0) {
            pthread_mutex_lock(&sh.state_lock);
            sh.active--;
            pthread_mutex_unlock(&sh.state_lock);
            threads[i] = 0;
            sh.workers[i].stats.failed = 1;
            snprintf(sh.workers[i].stats.failure, sizeof sh.workers[i].stats.failure,
                     "cannot start a host thread: %s", strerror(errno));
        }
    }

    Progress progress;
    double pixels = (double)film->width * (double)film->height;
    progress_begin(&progress, "render", (double)(cfg->spp - done_before) * pixels, "samples", cfg->show_progress);
    double last_tick = sh.start, last_checkpoint = sh.start;
    for (;;) {
        wait_tick(&sh, 0.1);
        pthread_mutex_lock(&sh.state_lock);
        size_t active = sh.active;
        pthread_mutex_unlock(&sh.state_lock);
        if (cfg->stop && *cfg->stop) {
            batch_queue_close(&sh.queue);
            stats->interrupted = 1;
        }
        double done = (double)(batch_queue_completed(&sh.queue) - done_before) * pixels;
        progress_update(&progress, done);
        double now = timer_now();
        int tick = cfg->on_tick && cfg->tick_seconds > 0.0 && now - last_tick >= cfg->tick_seconds;
        int checkpoint = cfg->on_checkpoint && cfg->checkpoint_seconds > 0.0 &&
                         now - last_checkpoint >= cfg->checkpoint_seconds;
        if (active > 0 && (tick || checkpoint) && take_snapshot(&sh, &snap, &snap_done) == 0) {
            ScheduleSnapshot s = { &snap, snap_done.ranges, snap_done.n };
            double t_snap = timer_now();
            stats->snapshot_seconds += t_snap - now;
            if (tick) {
                last_tick = now;
                if (snap.samples > 0) cfg->on_tick(cfg->ctx, &s);
            }
            if (checkpoint) {
                double t0 = timer_now();
                last_checkpoint = now;
                cfg->on_checkpoint(cfg->ctx, &s);
                stats->checkpoints++;
                stats->checkpoint_seconds += timer_now() - t0;
            }
        }
        if (active == 0) break;
    }
    progress_end(&progress);
    for (size_t i = 0; i < n; i++)
        if (threads[i]) pthread_join(threads[i], NULL);

    uint completed = batch_queue_completed(&sh.queue);
    stats->seconds = timer_now() - sh.start;
    stats->spp_done = (uint)film->samples;
    stats->time_up = cfg->time_limit > 0.0 && completed < cfg->spp && !stats->interrupted;
    stats->n_devices = n;
    stats->devices = calloc(n, sizeof *stats->devices);
    stats->done = sh.done;
    memset(&sh.done, 0, sizeof sh.done);
    if (sh.done_lost) batch_set_free(&stats->done);
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
    else if (!stats->interrupted && !stats->time_up && completed < cfg->spp)
        st = error_set(err, ST_INTERNAL, "the render ended with %u of %u samples per pixel done", completed, cfg->spp);

cleanup:
    if (sh.workers)
        for (size_t i = 0; i < n; i++) free(sh.workers[i].scratch);
    free(sh.workers);
    free(threads);
    film_free(&snap);
    batch_set_free(&snap_done);
    batch_set_free(&sh.done);
    pthread_cond_destroy(&sh.state_cond);
    pthread_mutex_destroy(&sh.state_lock);
    pthread_mutex_destroy(&sh.film_lock);
    batch_queue_free(&sh.queue);
    return st;
}
