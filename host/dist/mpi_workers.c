/* mpi_workers.c — see mpi_driver.h: on rank 0 every worker rank as a remote device of
 * the scheduler; on the workers, the loop that renders the batches rank 0 sends; and
 * the end, when rank 0 stops the workers and collects their statistics. */
#include "dist/mpi_driver.h"

#include <errno.h>
#include <mpi.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/timer.h"
#include "dist/mpi_wire.h"
#include "render/film.h"
#include "render/schedule.h"

/* ------------------------------------------------------------------ rank 0: remote devices */

typedef struct {
    Dist *d;
    int rank;
    int64_t *film;             /* the last batch's film, until taken */
    size_t n_values;
} Remote;

/* Sends the batch and waits for its film: a rank is one device to the scheduler, whose
 * render takes as long as the rank's round trip (so its batch sizes adapt to it). */
static Status remote_render(Device *dev, uint first, uint count, Error *err)
{
    Remote *rm = dev->impl;
    uint32_t batch[3] = { first, count, rm->d->spp };
    int rc = wire_send(rm->d, batch, 3, MPI_UINT32_T, rm->rank, TAG_BATCH);
    if (rc != MPI_SUCCESS) return mpi_failed(err, rc, rm->rank, "sending a batch");
    WireResult res;
    Status st = wire_wait(rm->d, rm->rank, TAG_RESULT, &res, sizeof res, dev->cancel, err);
    if (st == ST_OK && res.status == ST_OK)
        st = wire_wait(rm->d, rm->rank, TAG_FILM, rm->film, rm->n_values * sizeof *rm->film, NULL, err);
    if (st != ST_OK) {
        /* an interrupted wait leaves the rank working: its answer is drained at the end
         * (dist_stop_workers); a silent or broken rank is not waited for again */
        if (st != ST_INTERRUPTED && rm->d->wire->gone) rm->d->wire->gone[rm->rank] = 1;
        return st;
    }
    if (res.status != ST_OK) {
        res.msg[sizeof res.msg - 1] = '\0';
        return error_set(err, (Status)res.status, "MPI rank %d: %s", rm->rank, res.msg);
    }
    dev->counters.samples += res.samples;
    dev->counters.rays += res.rays;
    return ST_OK;
}

static Status remote_take_film(Device *dev, int64_t *film, Error *err)
{
    (void)err;
    Remote *rm = dev->impl;
    for (size_t i = 0; i < rm->n_values; i++) film[i] += rm->film[i];
    return ST_OK;
}

static Status remote_not_here(Device *dev, const char *what, Error *err)
{
    Remote *rm = dev->impl;
    return error_set(err, ST_USAGE, "MPI rank %d: %s is not available under MPI", rm->rank, what);
}

static Status remote_load_scene(Device *dev, const DeviceScene *scene, Error *err)
{
    (void)scene;
    return remote_not_here(dev, "loading another scene", err);
}

/* Sends the rank the params block and pixel list its devices render the next batches
 * with (the rounds of --noise-threshold, render/adaptive.c: rank 0 decides which pixels
 * go on from the merged film, so every rank renders the samples one process would).
 * Messages from one rank to another arrive in order, so the batches sent after this
 * are rendered with it; a worker that cannot apply it answers its next batch with the
 * failure. */
static Status remote_update_params(Device *dev, const RenderParams *params, const uint *pixel_list, Error *err)
{
    Remote *rm = dev->impl;
    /* a rank given up renders nothing more (its batches fail): nothing to tell it */
    if (rm->d->wire->gone && rm->d->wire->gone[rm->rank]) return ST_OK;
    size_t listed = pixel_list ? params->pixel_list_size : 0u;
    size_t bytes = sizeof *params + listed * sizeof *pixel_list;
    if (bytes > (size_t)INT32_MAX) return error_set(err, ST_INTERNAL, "MPI rank %d: a pixel list too long to send",
                                                     rm->rank);
    unsigned char *msg = malloc(bytes);
    if (!msg) return error_set(err, ST_INTERNAL, "out of memory sending the render parameters to the MPI ranks");
    memcpy(msg, params, sizeof *params);
    if (listed) memcpy(msg + sizeof *params, pixel_list, listed * sizeof *pixel_list);
    int rc = wire_send(rm->d, msg, (int)bytes, MPI_BYTE, rm->rank, TAG_PARAMS);
    free(msg);
    if (rc != MPI_SUCCESS) {
        if (rm->d->wire->gone) rm->d->wire->gone[rm->rank] = 1;
        return mpi_failed(err, rc, rm->rank, "sending the render parameters");
    }
    return ST_OK;
}

static void remote_destroy(Device *dev)
{
    Remote *rm = dev->impl;
    if (rm) free(rm->film);
    free(rm);
    free(dev);
}

static const DeviceOps remote_ops = { remote_load_scene, remote_update_params, remote_render, remote_take_film,
                                      remote_destroy };

Status dist_add_remote_devices(Dist *d, unsigned n_pixels, Device ***devs, size_t *n, Error *err)
{
    size_t want = *n + (size_t)d->size - 1;
    Device **grown = realloc(*devs, want * sizeof *grown);
    if (!grown) return error_set(err, ST_INTERNAL, "out of memory");
    *devs = grown;
    for (int r = 1; r < d->size; r++) {
        Device *dev = calloc(1, sizeof *dev);
        Remote *rm = calloc(1, sizeof *rm);
        int64_t *film = calloc((size_t)n_pixels * 3u, sizeof *film);
        if (!dev || !rm || !film) {
            free(dev);
            free(rm);
            free(film);
            return error_set(err, ST_INTERNAL, "out of memory for the films of the MPI ranks");
        }
        *rm = (Remote){ d, r, film, (size_t)n_pixels * 3u };
        dev->ops = &remote_ops;
        dev->impl = rm;
        dev->n_pixels = n_pixels;
        dev->max_in_flight = 1;
        const char *where = d->wire->names && d->wire->names[r] ? d->wire->names[r] : "?";
        snprintf(dev->desc.name, sizeof dev->desc.name, "rank %d (%s)", r, where);
        dev->desc.type_name = "MPI rank";
        dev->desc.kind = DEVICE_SCALAR;   /* not OpenCL: no kernel build of its own to report */
        (*devs)[(*n)++] = dev;
    }
    return ST_OK;
}

/* ------------------------------------------------------------------ workers */

typedef struct {
    Dist *d;
    atomic_int quit;
    pthread_t thread;
    int running;
} Heartbeat;

/* A worker's second thread: tells rank 0 every second that this process is alive, so
 * that rank 0 can tell a long batch from a dead rank. */
static void *heartbeat_main(void *arg)
{
    Heartbeat *hb = arg;
    while (!atomic_load(&hb->quit)) {
        for (int i = 0; i < 20 && !atomic_load(&hb->quit); i++) sleep_seconds(ALIVE_SECONDS / 20.0);
        if (!atomic_load(&hb->quit)) wire_send(hb->d, NULL, 0, MPI_BYTE, 0, TAG_ALIVE);
    }
    return NULL;
}

/* Adds one batch's device statistics into the worker's totals. */
static void stats_add(WireStats *tot, const ScheduleStats *s)
{
    for (size_t i = 0; i < s->n_devices && i < MAX_WORKER_DEVICES && s->devices; i++) {
        WireDevice *w = &tot->dev[i];
        const DeviceRunStats *x = &s->devices[i];
        snprintf(w->name, sizeof w->name, "%s", x->name);
        w->batches += x->batches;
        w->failed |= (uint32_t)x->failed;
        w->samples += x->samples;
        w->rays += x->rays;
        w->busy += x->busy_seconds;
        w->idle += x->idle_seconds;
        if (tot->n < i + 1) tot->n = (uint32_t)(i + 1);
    }
}

/* What rank 0 last set with TAG_PARAMS (remote_update_params): the devices keep
 * pointing at the pixel list, so it lives until the next one. A failure to apply it is
 * the answer to every batch after it. */
typedef struct {
    RenderParams params;
    uint *pixel_list;
    Status st;
    char msg[1024];
} WorkerParams;

/* Receives a TAG_PARAMS message of `bytes` bytes and gives its params block and pixel
 * list to every device of this worker. Only an MPI failure is returned; a bad message
 * or a device that fails is kept in wp for the next batch's answer. */
static Status worker_params(Dist *d, Device **devs, size_t n, int bytes, WorkerParams *wp, Error *err)
{
    unsigned char *msg = malloc(bytes > 0 ? (size_t)bytes : 1u);
    if (!msg) return error_set(err, ST_INTERNAL, "out of memory for the render parameters");
    Status st = wire_receive(d, 0, TAG_PARAMS, msg, bytes, err);
    if (st != ST_OK) {
        free(msg);
        return st;
    }
    RenderParams p;
    size_t size = (size_t)bytes;
    if (size >= sizeof p) memcpy(&p, msg, sizeof p);
    if (size < sizeof p || (size - sizeof p) / sizeof(uint) != p.pixel_list_size || (size - sizeof p) % sizeof(uint)) {
        free(msg);
        wp->st = ST_INTERNAL;
        snprintf(wp->msg, sizeof wp->msg, "render parameters of %d bytes, which hold no whole pixel list", bytes);
        return ST_OK;
    }
    uint *list = NULL;
    if (p.pixel_list_size) {
        list = malloc((size_t)p.pixel_list_size * sizeof *list);
        if (list) memcpy(list, msg + sizeof p, (size_t)p.pixel_list_size * sizeof *list);
    }
    free(msg);
    if (p.pixel_list_size && !list) {
        wp->st = ST_INTERNAL;
        snprintf(wp->msg, sizeof wp->msg, "out of memory for the pixel list");
        return ST_OK;
    }
    Error e = { 0 };
    wp->st = ST_OK;
    for (size_t i = 0; i < n && wp->st == ST_OK; i++) wp->st = devs[i]->ops->update_params(devs[i], &p, list, &e);
    if (wp->st != ST_OK) snprintf(wp->msg, sizeof wp->msg, "%s", e.msg);
    error_clear(&e);
    /* the devices read the new list from now on; the old one is no longer theirs */
    free(wp->pixel_list);
    wp->pixel_list = list;
    wp->params = p;
    return ST_OK;
}

/* Renders one batch with the worker's devices and sends rank 0 its result and film. */
static Status worker_batch(Dist *d, Device **devs, size_t n, Film *film, const uint32_t *batch,
                           const WorkerParams *wp, volatile sig_atomic_t *stop, WireStats *tot, Error *err)
{
    ScheduleConfig cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = batch[2];
    cfg.range_first = batch[0];
    cfg.range_end = batch[0] + batch[1];
    cfg.fixed_batch = d->fixed_batch;
    cfg.stop = stop;
    ScheduleStats stats;
    memset(&stats, 0, sizeof stats);
    WireResult res;
    memset(&res, 0, sizeof res);
    res.first = batch[0];
    res.count = batch[1];
    Error e = { 0 };
    memset(film->sum, 0, (size_t)film->width * film->height * 3u * sizeof *film->sum);
    film->samples = 0;
    Status st;
    if (*stop)
        st = ST_INTERRUPTED;
    else if (wp->st != ST_OK)
        st = error_set(&e, wp->st, "%s", wp->msg);
    else if (batch[2] == 0 || batch[1] == 0 || batch[0] + batch[1] < batch[0] || batch[0] + batch[1] > batch[2])
        st = error_set(&e, ST_INTERNAL, "a batch outside the render's samples");
    else
        st = schedule_run(devs, n, &cfg, film, &stats, &e);
    /* a batch cut short by an interrupt is dropped whole, as in one process */
    if (st == ST_OK && (stats.interrupted || film->samples != batch[1])) st = ST_INTERRUPTED;
    stats_add(tot, &stats);
    res.status = st;
    res.samples = stats.samples;
    res.rays = stats.rays;
    snprintf(res.msg, sizeof res.msg, "%s", st == ST_INTERRUPTED ? "interrupted" : e.msg);
    error_clear(&e);
    schedule_stats_free(&stats);
    int rc = wire_send(d, &res, (int)sizeof res, MPI_BYTE, 0, TAG_RESULT);
    if (rc == MPI_SUCCESS && st == ST_OK)
        rc = wire_send(d, film->sum, (int)((size_t)film->width * film->height * 3u), MPI_INT64_T, 0, TAG_FILM);
    return rc == MPI_SUCCESS ? ST_OK : mpi_failed(err, rc, d->rank, "sending a batch's film");
}

/* Waits for rank 0's next word: a batch (1) or stop (0). New render parameters
 * (TAG_PARAMS) on the way are given to the devices. */
static int worker_next(Dist *d, Device **devs, size_t n, WorkerParams *wp, uint32_t *batch, Status *st, Error *err)
{
    for (;;) {
        int flag = 0, params = 0, bytes = 0;
        MPI_Status ms;
        wire_lock(d);
        int rc = MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
        params = rc == MPI_SUCCESS && flag && ms.MPI_TAG == TAG_PARAMS;
        if (params)
            MPI_Get_count(&ms, MPI_BYTE, &bytes);
        else if (rc == MPI_SUCCESS && flag)
            rc = MPI_Recv(batch, 3, MPI_UINT32_T, 0, ms.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        wire_unlock(d);
        if (rc != MPI_SUCCESS) {
            *st = mpi_failed(err, rc, d->rank, "waiting for a batch");
            return 0;
        }
        if (params) {
            if ((*st = worker_params(d, devs, n, bytes, wp, err)) != ST_OK) return 0;
            continue;
        }
        if (flag) return ms.MPI_TAG == TAG_BATCH;
        sleep_seconds(POLL_SECONDS);
    }
}

Status dist_worker_run(Dist *d, Device **devs, size_t n, unsigned width, unsigned height,
                       volatile sig_atomic_t *stop, Error *err)
{
    Film film;
    Status st = film_init(&film, width, height, err);
    if (st != ST_OK) return st;
    Heartbeat hb = { .d = d };
    atomic_init(&hb.quit, 0);
    hb.running = pthread_create(&hb.thread, NULL, heartbeat_main, &hb) == 0;
    WireStats *tot = calloc(1, sizeof *tot);
    WorkerParams wp;
    memset(&wp, 0, sizeof wp);
    uint32_t batch[3];
    while (st == ST_OK && tot && worker_next(d, devs, n, &wp, batch, &st, err))
        st = worker_batch(d, devs, n, &film, batch, &wp, stop, tot, err);
    atomic_store(&hb.quit, 1);
    if (hb.running) pthread_join(hb.thread, NULL);
    if (st == ST_OK && tot) {
        int rc = wire_send(d, tot, (int)sizeof *tot, MPI_BYTE, 0, TAG_STATS);
        if (rc != MPI_SUCCESS) st = mpi_failed(err, rc, d->rank, "sending its statistics");
    }
    if (!tot && st == ST_OK) st = error_set(err, ST_INTERNAL, "out of memory");
    free(tot);
    film_free(&film);
    /* rank 0 ends every adaptive render by sending no list; after a failure the devices
     * may still hold this one, but they render nothing more (closed by the caller) */
    free(wp.pixel_list);
    return st;
}

/* ------------------------------------------------------------------ the end */

/* Rank 0: waits for a worker's statistics, throwing away what an abandoned batch still
 * sends. 0 when they came, -1 when the worker said nothing for d->timeout seconds. */
static int stop_collect(Dist *d, int r, WireStats *s)
{
    double last = timer_now();
    while (timer_now() - last <= d->timeout) {
        int flag = 0;
        MPI_Status ms;
        wire_lock(d);
        int rc = MPI_Iprobe(r, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
        wire_unlock(d);
        if (rc != MPI_SUCCESS) return -1;
        if (!flag) {
            sleep_seconds(POLL_SECONDS);
            continue;
        }
        int count = 0;
        MPI_Get_count(&ms, MPI_BYTE, &count);
        int stats = ms.MPI_TAG == TAG_STATS && count == (int)sizeof *s;
        void *buf = stats ? (void *)s : malloc(count ? (size_t)count : 1);
        if (!buf) return -1;
        Error e;
        Status st = wire_receive(d, r, ms.MPI_TAG, buf, count, &e);
        if (!stats) free(buf);
        if (st != ST_OK) return -1;
        if (stats) return 0;
        last = timer_now();
    }
    return -1;
}

static void stats_print(FILE *out, int r, const WireStats *s)
{
    for (uint32_t i = 0; i < s->n && i < MAX_WORKER_DEVICES; i++) {
        const WireDevice *w = &s->dev[i];
        double busy = w->busy > 0.0 ? w->busy : 1e-9;
        fprintf(out, "  rank %d device %u '%.60s': %u batches, %llu samples, busy %.2f s, idle %.2f s, "
                "%.3f Msamples/s, %.3f Mrays/s%s\n", r, i, w->name, w->batches, (unsigned long long)w->samples,
                w->busy, w->idle, (double)w->samples / busy / 1e6, (double)w->rays / busy / 1e6,
                w->failed ? "  FAILED" : "");
    }
}

void dist_stop_workers(Dist *d, FILE *out)
{
    if (!d->active) return;
    uint32_t stop[3] = { 0, 0, 0 };
    const unsigned char *gone = d->wire->gone;
    for (int r = 1; r < d->size; r++)
        if (!gone || !gone[r]) wire_send(d, stop, 3, MPI_UINT32_T, r, TAG_STOP);
    if (out) fprintf(out, "MPI ranks' devices (rank 0's are above):\n");
    for (int r = 1; r < d->size; r++) {
        WireStats s;
        if (gone && gone[r]) {
            /* MPI_Finalize would wait for it for ever */
            d->lost = 1;
            if (out) fprintf(out, "  rank %d: given up during the render\n", r);
        } else if (stop_collect(d, r, &s) != 0) {
            d->lost = 1;
            fprintf(stderr, "clpt: warning: MPI rank %d did not answer the end of the render within %g s\n", r,
                    d->timeout);
        } else if (out) {
            stats_print(out, r, &s);
        }
    }
}
