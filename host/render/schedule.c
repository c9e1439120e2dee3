/* schedule.c — see schedule.h. */
#include "render/schedule.h"

#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/fault.h"
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
    atomic_int cancel;          /* interrupted: the devices drop the batches they render */
    int queue_ready;            /* queue and locks made (shared_free frees them) */
    double start;
    Worker *workers;
    size_t n_workers;
};

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

/* The batches a worker has handed to its device and not yet taken, oldest first. */
typedef struct {
    Batch b[MAX_PIPELINE];
    uint n;
} Flight;

static Batch flight_pop_oldest(Flight *fl)
{
    Batch b = fl->b[0];
    memmove(&fl->b[0], &fl->b[1], --fl->n * sizeof *fl->b);
    return b;
}

static size_t active_workers(Shared *sh)
{
    pthread_mutex_lock(&sh->state_lock);
    size_t n = sh->active;
    pthread_mutex_unlock(&sh->state_lock);
    return n;
}

/* No more batches for this worker: the render was interrupted (the calling thread has
 * closed the queue and raised the cancel) or its time is up (closed here). */
static int worker_stopping(Worker *w)
{
    Shared *sh = w->shared;
    if (atomic_load(&sh->cancel)) return 1;
    if (!time_is_up(sh)) return 0;
    batch_queue_close(&sh->queue);
    return 1;
}

static void give_back(Worker *w, Batch b)
{
    if (batch_queue_give_back(&w->shared->queue, b) != 0)
        warn(w->shared, "out of memory returning a batch; the image will have fewer samples");
}

/* Takes the film of the oldest batch in flight and adds it into the shared film. */
static Status worker_take_oldest(Worker *w, Flight *fl, Error *err)
{
    double t0 = timer_now();
    Status st = w->dev->ops->take_film(w->dev, w->scratch, err);
    w->stats.busy_seconds += timer_now() - t0;
    if (st != ST_OK) {
        size_t film_len = (size_t)w->shared->film->width * w->shared->film->height * 3u;
        memset(w->scratch, 0, film_len * sizeof *w->scratch);
        return st;
    }
    Batch b = flight_pop_oldest(fl);
    merge_batch(w, b);
    batch_queue_done(&w->shared->queue, b);
    w->stats.batches++;
    return ST_OK;
}

/* After a batch failed or was cancelled, the batches rendered before it may be whole on
 * the device: keeps those whose films can still be taken. */
static void worker_keep_finished(Worker *w, Flight *fl)
{
    Error err = { 0 };
    while (fl->n > 0 && worker_take_oldest(w, fl, &err) == ST_OK) {}
    error_clear(&err);
}

/* render returns when the device has worked through the batch (for a pipelined device,
 * all but the film's read-back): its time gives the device's speed. */
static void worker_record_batch(Worker *w, Batch b, double seconds)
{
    w->stats.busy_seconds += seconds;
    w->seconds_per_sample = seconds / (double)b.count;
    w->stats.batch_last = b.count;
    if (!w->stats.batch_min || b.count < w->stats.batch_min) w->stats.batch_min = b.count;
    if (b.count > w->stats.batch_max) w->stats.batch_max = b.count;
}

/* Hands the device its next batch. Returns 1 when one was rendered, 0 when none could
 * be taken or the render did not succeed (*st says which: a failure, or ST_INTERRUPTED
 * for a cancelled batch, which is dropped whole). Only a worker with nothing in flight
 * may wait for a batch, or it could wait for its own. */
static int worker_render_next(Worker *w, Flight *fl, Status *st, Error *err)
{
    Shared *sh = w->shared;
    Batch b;
    uint want = choose_batch(w, active_workers(sh));
    if (!(fl->n ? batch_queue_try_take(&sh->queue, want, &b) : batch_queue_take(&sh->queue, want, &b))) return 0;
    double t0 = timer_now();
    if (w->fail_at_batch >= 0 && (long)w->started == w->fail_at_batch)
        *st = error_set(err, ST_DEVICE, "failure injected by CLPT_TEST_FAIL");
    else
        *st = w->dev->ops->render(w->dev, b.first, b.count, err);
    w->started++;
    if (*st != ST_OK) {
        give_back(w, b);
        worker_keep_finished(w, fl);
        return 0;
    }
    fl->b[fl->n++] = b;
    worker_record_batch(w, b, timer_now() - t0);
    return 1;
}

/* A failed device drops out: whatever it had in flight goes to the others. */
static void worker_drop_device(Worker *w, Flight *fl, Error *err)
{
    w->stats.failed = 1;
    snprintf(w->stats.failure, sizeof w->stats.failure, "%s", err->msg);
    for (uint i = 0; i < fl->n; i++) give_back(w, fl->b[i]);
    fl->n = 0;
    warn(w->shared, "device '%s' failed and was dropped; its samples go to the other devices: %s", w->stats.name,
         err->msg);
}

/* One host thread per device: keeps the device's pipeline full (the next batch is
 * handed over before the last one's film is taken) until the queue is empty, the
 * render is interrupted or the device fails. */
static void *worker_main(void *arg)
{
    Worker *w = arg;
    Shared *sh = w->shared;
    uint depth = w->dev->max_in_flight ? w->dev->max_in_flight : 1u;
    if (depth > MAX_PIPELINE) depth = MAX_PIPELINE;
    Flight fl = { .n = 0 };
    double thread_start = timer_now();
    uint64_t samples_before = w->dev->counters.samples, rays_before = w->dev->counters.rays;
    Error err = { 0 };
    Status st = ST_OK;
    for (;;) {
        if (!worker_stopping(w) && fl.n < depth) {
            if (worker_render_next(w, &fl, &st, &err)) continue;
            if (st != ST_OK) break;
        }
        if (fl.n == 0) break;
        if ((st = worker_take_oldest(w, &fl, &err)) != ST_OK) break;
    }
    if (st == ST_INTERRUPTED) {
        for (uint i = 0; i < fl.n; i++) give_back(w, fl.b[i]);   /* films that could not be taken */
    } else if (st != ST_OK) {
        worker_drop_device(w, &fl, &err);
    }
    error_clear(&err);
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

/* The queue skips what the film holds and, for a render of a sample range, what lies
 * outside it (those samples are not in the film: the record `done` leaves them out). */
static int skip_outside_range(Shared *sh, const ScheduleConfig *cfg)
{
    if (cfg->range_end == 0) return batch_queue_skip_done(&sh->queue, cfg->done, cfg->n_done);
    if (cfg->range_first >= cfg->range_end || cfg->range_end > cfg->spp) return -1;
    Batch *skip = malloc((cfg->n_done + 2) * sizeof *skip);
    if (!skip) return -2;
    size_t n = 0;
    if (cfg->n_done) memcpy(skip, cfg->done, cfg->n_done * sizeof *skip);
    n = cfg->n_done;
    if (cfg->range_first > 0) skip[n++] = (Batch){ 0, cfg->range_first };
    if (cfg->range_end < cfg->spp) skip[n++] = (Batch){ cfg->range_end, cfg->spp - cfg->range_end };
    int rc = batch_queue_skip_done(&sh->queue, skip, n);
    free(skip);
    return rc;
}

/* The queue of batches, the locks, and the record of what a resumed film holds. */
static Status shared_init(Shared *sh, const ScheduleConfig *cfg, Film *film, Error *err)
{
    memset(sh, 0, sizeof *sh);
    sh->cfg = cfg;
    sh->film = film;
    atomic_init(&sh->cancel, 0);
    if (batch_queue_init(&sh->queue, cfg->spp) != 0) return error_set(err, ST_INTERNAL, "cannot create a mutex");
    pthread_mutex_init(&sh->film_lock, NULL);
    pthread_mutex_init(&sh->state_lock, NULL);
    pthread_cond_init(&sh->state_cond, NULL);
    sh->queue_ready = 1;
    for (size_t i = 0; i < cfg->n_done; i++)
        if (batch_set_add(&sh->done, cfg->done[i]) != 0) return error_set(err, ST_INTERNAL, "out of memory starting the render");
    int rc = skip_outside_range(sh, cfg);
    if (rc == -2) return error_set(err, ST_INTERNAL, "out of memory starting the render");
    if (rc != 0)
        return error_set(err, ST_INTERNAL, "the finished sample ranges overlap or exceed %u samples", cfg->spp);
    return ST_OK;
}

/* Frees what shared_init and workers_create made (after a failure of either, too). */
static void shared_free(Shared *sh)
{
    if (sh->workers)
        for (size_t i = 0; i < sh->n_workers; i++) free(sh->workers[i].scratch);
    free(sh->workers);
    batch_set_free(&sh->done);
    if (!sh->queue_ready) return;
    pthread_cond_destroy(&sh->state_cond);
    pthread_mutex_destroy(&sh->state_lock);
    pthread_mutex_destroy(&sh->film_lock);
    batch_queue_free(&sh->queue);
}

/* One Worker per device, each with a film of its own for the batch being merged; the
 * devices see the shared cancel flag. */
static Status workers_create(Shared *sh, Device **devices, size_t n, Error *err)
{
    size_t film_len = (size_t)sh->film->width * sh->film->height * 3u;
    sh->workers = calloc(n, sizeof *sh->workers);
    if (!sh->workers) return error_set(err, ST_INTERNAL, "out of memory starting the render");
    sh->n_workers = n;
    for (size_t i = 0; i < n; i++) {
        Worker *w = &sh->workers[i];
        w->shared = sh;
        w->dev = devices[i];
        w->index = i;
        w->fail_at_batch = fault_device_batch(i);
        snprintf(w->stats.name, sizeof w->stats.name, "%s", devices[i]->desc.name);
        w->scratch = calloc(film_len, sizeof *w->scratch);
        if (!w->scratch) return error_set(err, ST_INTERNAL, "out of memory for device films");
    }
    return ST_OK;
}

/* Starts a thread per worker. A thread that cannot start counts as a failed device. */
static void workers_start(Shared *sh, pthread_t *threads)
{
    sh->start = timer_now();
    for (size_t i = 0; i < sh->n_workers; i++) {
        Worker *w = &sh->workers[i];
        w->dev->cancel = &sh->cancel;
        pthread_mutex_lock(&sh->state_lock);
        sh->active++;
        pthread_mutex_unlock(&sh->state_lock);
        if (pthread_create(&threads[i], NULL, worker_main, w) != 0) {
            pthread_mutex_lock(&sh->state_lock);
            sh->active--;
            pthread_mutex_unlock(&sh->state_lock);
            threads[i] = 0;
            w->stats.failed = 1;
            snprintf(w->stats.failure, sizeof w->stats.failure, "cannot start a host thread: %s", strerror(errno));
        }
    }
}

static void workers_join(Shared *sh, pthread_t *threads)
{
    for (size_t i = 0; i < sh->n_workers; i++) {
        if (threads[i]) pthread_join(threads[i], NULL);
        sh->workers[i].dev->cancel = NULL;
    }
}

/* A stop request (a signal) closes the queue and cancels the batches being rendered:
 * they are dropped whole, so the film keeps whole batches only. */
static int check_interrupt(Shared *sh)
{
    const ScheduleConfig *cfg = sh->cfg;
    if (!cfg->stop || !*cfg->stop) return 0;
    if (!atomic_load(&sh->cancel)) {
        batch_queue_close(&sh->queue);
        atomic_store(&sh->cancel, 1);
    }
    return 1;
}

/* The calling thread's part while the workers render. */
typedef struct {
    Film snap;                  /* copies for the callbacks */
    BatchSet snap_done;
    double last_tick, last_checkpoint;
} Monitor;

/* Calls on_tick and on_checkpoint when they are due, with a snapshot. */
static void monitor_callbacks(Shared *sh, Monitor *m, ScheduleStats *stats)
{
    const ScheduleConfig *cfg = sh->cfg;
    double now = timer_now();
    int tick = cfg->on_tick && cfg->tick_seconds > 0.0 && now - m->last_tick >= cfg->tick_seconds;
    int checkpoint = cfg->on_checkpoint && cfg->checkpoint_seconds > 0.0 &&
                     now - m->last_checkpoint >= cfg->checkpoint_seconds;
    if (!(tick || checkpoint) || take_snapshot(sh, &m->snap, &m->snap_done) != 0) return;
    ScheduleSnapshot s = { &m->snap, m->snap_done.ranges, m->snap_done.n };
    stats->snapshot_seconds += timer_now() - now;
    if (tick) {
        m->last_tick = now;
        if (m->snap.samples > 0) cfg->on_tick(cfg->ctx, &s);
    }
    if (checkpoint) {
        double t0 = timer_now();
        m->last_checkpoint = now;
        cfg->on_checkpoint(cfg->ctx, &s);
        stats->checkpoints++;
        stats->checkpoint_seconds += timer_now() - t0;
    }
}

/* Shows progress, passes on interrupts and calls the callbacks until every worker is
 * done. */
static void monitor_run(Shared *sh, Monitor *m, uint done_before, ScheduleStats *stats)
{
    const ScheduleConfig *cfg = sh->cfg;
    Progress progress;
    double pixels = (double)sh->film->width * (double)sh->film->height;
    progress_begin(&progress, "render", (double)(cfg->spp - done_before) * pixels, "samples", cfg->show_progress);
    progress_set_step(&progress, pixels, "spp");
    m->last_tick = m->last_checkpoint = sh->start;
    double poll = cfg->poll_seconds > 0.0 ? cfg->poll_seconds : 0.1;
    for (;;) {
        wait_tick(sh, poll);
        size_t active = active_workers(sh);
        if (check_interrupt(sh)) stats->interrupted = 1;
        uint completed = batch_queue_completed(&sh->queue);
        progress_update(&progress, (double)(completed - done_before) * pixels);
        if (cfg->on_poll) cfg->on_poll(cfg->ctx, completed);
        if (active == 0) break;
        monitor_callbacks(sh, m, stats);
    }
    progress_end(&progress);
}

/* Gathers the devices' statistics and the record of the film's samples; the status
 * says whether the render ended as it should have. */
static Status collect_stats(Shared *sh, const Film *film, ScheduleStats *stats, Error *err)
{
    const ScheduleConfig *cfg = sh->cfg;
    size_t n = sh->n_workers;
    uint completed = batch_queue_completed(&sh->queue);
    stats->seconds = timer_now() - sh->start;
    stats->spp_done = (uint)film->samples;
    stats->time_up = cfg->time_limit > 0.0 && completed < cfg->spp && !stats->interrupted;
    stats->n_devices = n;
    stats->devices = calloc(n, sizeof *stats->devices);
    stats->done = sh->done;
    memset(&sh->done, 0, sizeof sh->done);
    if (sh->done_lost) batch_set_free(&stats->done);
    size_t failed = 0;
    for (size_t i = 0; i < n; i++) {
        if (stats->devices) stats->devices[i] = sh->workers[i].stats;
        stats->samples += sh->workers[i].stats.samples;
        stats->rays += sh->workers[i].stats.rays;
        failed += (size_t)sh->workers[i].stats.failed;
    }
    if (failed == n)
        return error_set(err, ST_DEVICE, "every device failed (last: %s: %s); %u of %u samples per pixel were finished",
                         sh->workers[n - 1].stats.name, sh->workers[n - 1].stats.failure, (unsigned)film->samples,
                         cfg->spp);
    if (!stats->interrupted && !stats->time_up && completed < cfg->spp)
        return error_set(err, ST_INTERNAL, "the render ended with %u of %u samples per pixel done", completed, cfg->spp);
    return ST_OK;
}

ScheduleConfig schedule_config_part(const ScheduleConfig *cfg, uint first, uint end, double time_limit)
{
    ScheduleConfig part = *cfg;
    part.spp = end;
    part.range_first = first;
    part.range_end = end;
    part.done = NULL;
    part.n_done = 0;
    part.time_limit = time_limit;
    part.show_progress = PROGRESS_OFF;
    part.on_tick = NULL;
    part.on_checkpoint = NULL;
    part.on_poll = NULL;
    return part;
}

Status schedule_run(Device **devices, size_t n, const ScheduleConfig *cfg, Film *film,
                    ScheduleStats *stats, Error *err)
{
    memset(stats, 0, sizeof *stats);
    if (n == 0) return error_set(err, ST_DEVICE, "no device to render with");
    Shared sh;
    Monitor m;
    memset(&m, 0, sizeof m);
    pthread_t *threads = NULL;
    Status st = shared_init(&sh, cfg, film, err);
    uint done_before = sh.queue_ready ? batch_queue_completed(&sh.queue) : 0;
    if (st == ST_OK) st = workers_create(&sh, devices, n, err);
    if (st == ST_OK && !(threads = calloc(n, sizeof *threads)))
        st = error_set(err, ST_INTERNAL, "out of memory starting the render");
    if (st == ST_OK && (cfg->on_tick || cfg->on_checkpoint))
        st = film_init(&m.snap, film->width, film->height, err);
    if (st == ST_OK) {
        workers_start(&sh, threads);
        monitor_run(&sh, &m, done_before, stats);
        workers_join(&sh, threads);
        st = collect_stats(&sh, film, stats, err);
    }
    free(threads);
    film_free(&m.snap);
    batch_set_free(&m.snap_done);
    shared_free(&sh);
    return st;
}
