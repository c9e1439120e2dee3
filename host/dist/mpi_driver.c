/* mpi_driver.c — see mpi_driver.h; the messages are listed in docs/distributed.md. */
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
#include "render/film.h"
#include "render/schedule.h"

/* Message tags. Every message goes between rank 0 and one worker. */
enum {
    TAG_BATCH = 1,     /* 0 -> w: uint32 {first, count, spp} */
    TAG_STOP,          /* 0 -> w: uint32 {0}: no more batches; answer with TAG_STATS */
    TAG_RESULT,        /* w -> 0: WireResult; TAG_FILM follows when its status is ST_OK */
    TAG_FILM,          /* w -> 0: int64 film sums, width * height * 3 */
    TAG_STATS,         /* w -> 0: WireStats: the worker's devices, at the end */
    TAG_ALIVE,         /* w -> 0: empty, every second: the worker is alive */
    TAG_START,         /* w -> 0: WireStart: what the worker's command line asks for */
    TAG_GO             /* 0 -> w: int32: 1 when every rank may go on with the render */
};

#define ALIVE_SECONDS 1.0
#define POLL_SECONDS 0.0005
#define MAX_WORKER_DEVICES 16

struct DistWire {
    pthread_mutex_t lock;      /* MPI_THREAD_SERIALIZED: one thread in MPI at a time */
    char **names;              /* rank 0: each rank's "host: devices", from dist_agree */
    unsigned char *gone;       /* rank 0: ranks given up during the render (silent, or MPI failed) */
};

typedef struct {
    int32_t status;
    uint32_t first, count;
    uint32_t pad;
    uint64_t samples, rays;
    char msg[1024];
} WireResult;

typedef struct {
    char name[256];
    uint32_t batches, failed;
    uint64_t samples, rays;
    double busy, idle;
} WireDevice;

typedef struct {
    uint32_t n;
    uint32_t pad;
    WireDevice dev[MAX_WORKER_DEVICES];
} WireStats;

typedef struct {
    int32_t plan;              /* DistPlan */
    int32_t status;            /* DIST_FAILED: the failure's Status */
    int32_t broadcast;         /* --mpi-broadcast */
    int32_t pad;
    char msg[1024];            /* DIST_FAILED: the failure's message */
} WireStart;

typedef struct {
    int32_t status;
    unsigned char key[CHECKPOINT_KEY_SIZE];
    char where[160];           /* "host: device, device" */
    char msg[1024];
} WireAgree;

/* ------------------------------------------------------------------ MPI calls */

static void wire_lock(Dist *d)
{
    pthread_mutex_lock(&d->wire->lock);
}

static void wire_unlock(Dist *d)
{
    pthread_mutex_unlock(&d->wire->lock);
}

static void mpi_message(int rc, char *buf, size_t size)
{
    char s[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(rc, s, &len) != MPI_SUCCESS) len = 0;
    s[len] = '\0';
    snprintf(buf, size, "%s", len ? s : "MPI error");
}

static Status mpi_failed(Error *err, int rc, int rank, const char *what)
{
    char m[MPI_MAX_ERROR_STRING + 1];
    mpi_message(rc, m, sizeof m);
    return error_set(err, ST_DEVICE, "MPI rank %d: %s: %s", rank, what, m);
}

static int wire_send(Dist *d, const void *buf, int count, MPI_Datatype type, int to, int tag)
{
    wire_lock(d);
    int rc = MPI_Send(buf, count, type, to, tag, MPI_COMM_WORLD);
    wire_unlock(d);
    return rc;
}

static void sleep_seconds(double s)
{
    struct timespec ts = { (time_t)s, (long)((s - (double)(time_t)s) * 1e9) };
    nanosleep(&ts, NULL);
}

/* Receives a message that MPI_Iprobe has matched. A large message (over the transport's
 * eager limit) is announced before its data moves, and a rank that dies in between
 * never completes it: a blocking MPI_Recv would then wait for ever under
 * --enable-recovery, holding the MPI lock that every other rank's device needs. So the
 * receive is posted and polled, the lock held only for each call, and given up after
 * d->timeout seconds without completing, like a rank that says nothing. */
static Status wire_receive(Dist *d, int from, int tag, void *buf, int count, Error *err)
{
    MPI_Request req;
    wire_lock(d);
    int rc = MPI_Irecv(buf, count, MPI_BYTE, from, tag, MPI_COMM_WORLD, &req);
    wire_unlock(d);
    if (rc != MPI_SUCCESS) return mpi_failed(err, rc, from, "receiving");
    double start = timer_now();
    for (;;) {
        int done = 0;
        wire_lock(d);
        rc = MPI_Test(&req, &done, MPI_STATUS_IGNORE);
        wire_unlock(d);
        if (rc != MPI_SUCCESS) return mpi_failed(err, rc, from, "receiving");
        if (done) return ST_OK;
        if (timer_now() - start > d->timeout) {
            /* the sender is gone, so nothing more is written into buf; cancelling the
             * matched request is best effort (the job ends with MPI_Abort) */
            wire_lock(d);
            MPI_Cancel(&req);
            wire_unlock(d);
            return error_set(err, ST_DEVICE, "MPI rank %d stopped in the middle of a message: nothing more of it "
                             "for %g s (its process or node died, or it hangs; see --mpi-timeout)", from, d->timeout);
        }
        sleep_seconds(POLL_SECONDS);
    }
}

/* Waits for the next message from `from` (other than a TAG_ALIVE, which only says it is
 * alive) and receives it if its tag is `want` and it fits in `bytes`: polling, so that
 * the waiting thread neither holds the MPI lock nor spins on a core a device needs.
 * ST_INTERRUPTED when *cancel is set meanwhile; ST_DEVICE when the rank says nothing
 * for d->timeout seconds, an MPI call fails or a message of another kind comes. */
static Status wire_wait(Dist *d, int from, int want, void *buf, size_t bytes, const atomic_int *cancel, Error *err)
{
    double last = timer_now();
    for (;;) {
        int flag = 0;
        MPI_Status ms;
        wire_lock(d);
        int rc = MPI_Iprobe(from, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
        if (rc == MPI_SUCCESS && flag && ms.MPI_TAG == TAG_ALIVE)
            rc = MPI_Recv(NULL, 0, MPI_BYTE, from, TAG_ALIVE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        else if (rc == MPI_SUCCESS && flag) {
            int count = 0;
            MPI_Get_count(&ms, MPI_BYTE, &count);
            if (ms.MPI_TAG != want || (size_t)count != bytes) {
                wire_unlock(d);
                return error_set(err, ST_DEVICE, "MPI rank %d sent a message of kind %d and %d bytes where kind %d "
                                 "and %zu bytes were due (ranks running different clpt builds?)", from, ms.MPI_TAG,
                                 count, want, bytes);
            }
            wire_unlock(d);
            return wire_receive(d, from, want, buf, count, err);
        }
        wire_unlock(d);
        if (rc != MPI_SUCCESS) return mpi_failed(err, rc, from, "waiting for a message");
        if (flag) last = timer_now();
        else if (cancel && atomic_load(cancel))
            return error_set(err, ST_INTERRUPTED, "interrupted");
        else if (timer_now() - last > d->timeout)
            return error_set(err, ST_DEVICE, "MPI rank %d stopped answering: no word from it for %g s (its process "
                             "or node died, or it hangs; see --mpi-timeout)", from, d->timeout);
        else
            sleep_seconds(POLL_SECONDS);
    }
}

/* ------------------------------------------------------------------ joining */

/* An MPI launcher starts each process with these in its environment: Open MPI's
 * mpirun with OMPI_COMM_WORLD_SIZE, srun and other PMI launchers with PMIX_RANK or
 * PMI_RANK. */
int dist_launched(void)
{
    const char *size = getenv("OMPI_COMM_WORLD_SIZE");
    if (size) return strcmp(size, "1") != 0;
    return getenv("PMIX_RANK") || getenv("PMI_RANK");
}

/* This process's rank as the launcher gave it, for a message written before MPI knows. */
static const char *launcher_rank(void)
{
    const char *names[] = { "OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (getenv(names[i])) return getenv(names[i]);
    return "?";
}

typedef struct {
    pthread_mutex_t lock;
    pthread_cond_t wake;
    int started;               /* MPI_Init_thread returned */
    double timeout;
} InitWatch;

/* MPI_Init_thread waits for every process of the job to join it, and a process that
 * ended without joining (in an MPMD job, a program that is not a clpt render, or
 * `clpt merge`, ending with status 0) leaves it waiting for ever. So a second thread
 * ends this process after the timeout, with a message and a non-zero status, which
 * makes the launcher end the whole job. */
static void *init_watch_main(void *arg)
{
    InitWatch *w = arg;
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    double whole = (double)(time_t)w->timeout;
    until.tv_sec += (time_t)whole;
    until.tv_nsec += (long)((w->timeout - whole) * 1e9);
    if (until.tv_nsec >= 1000000000L) {
        until.tv_sec++;
        until.tv_nsec -= 1000000000L;
    }
    pthread_mutex_lock(&w->lock);
    int rc = 0;
    while (!w->started && rc != ETIMEDOUT) rc = pthread_cond_timedwait(&w->wake, &w->lock, &until);
    if (!w->started) {
        fprintf(stderr, "clpt: MPI rank %s: error: the MPI job did not start within %g s: a process of the job never "
                "joined it (in an MPMD job, one that is not a clpt render, or that ended first), or the launcher "
                "hangs; see --mpi-timeout\n", launcher_rank(), w->timeout);
        _exit(ST_DEVICE);
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

/* MPI_Init_thread, given up after `timeout` seconds (init_watch_main). */
static int init_watched(double timeout, int *provided)
{
    InitWatch w = { PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, 0, timeout };
    pthread_t watcher;
    int watching = pthread_create(&watcher, NULL, init_watch_main, &w) == 0;
    int rc = MPI_Init_thread(NULL, NULL, MPI_THREAD_SERIALIZED, provided);
    pthread_mutex_lock(&w.lock);
    w.started = 1;
    pthread_cond_signal(&w.wake);
    pthread_mutex_unlock(&w.lock);
    if (watching) pthread_join(watcher, NULL);
    return rc;
}

Status dist_init(Dist *d, double timeout, Error *err)
{
    memset(d, 0, sizeof *d);
    d->timeout = timeout > 0.0 ? timeout : 30.0;
    if (!dist_launched()) return ST_OK;
    int provided = 0;
    if (init_watched(d->timeout, &provided) != MPI_SUCCESS)
        return error_set(err, ST_INTERNAL, "cannot start MPI (MPI_Init_thread failed)");
    /* MPI's default handler, MPI_ERRORS_ARE_FATAL, would end every process at the first
     * failed call without a word from clpt: errors are returned and handled instead. */
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &d->size);
    if (provided < MPI_THREAD_SERIALIZED) {
        MPI_Finalize();
        return error_set(err, ST_INTERNAL, "this MPI library does not allow calls from several threads "
                         "(MPI_THREAD_SERIALIZED), which clpt needs");
    }
    if (!(d->wire = calloc(1, sizeof *d->wire)) || pthread_mutex_init(&d->wire->lock, NULL) != 0) {
        free(d->wire);
        d->wire = NULL;
        MPI_Finalize();
        return error_set(err, ST_INTERNAL, "out of memory starting MPI");
    }
    d->active = 1;
    if (d->size == 1) dist_finish(d, 0, 0);
    return ST_OK;
}

void dist_finish(Dist *d, int exit_status, int abort)
{
    if (!d->active) return;
    /* errorcode 0 is allowed: a render that went on without a dead rank succeeded */
    if (abort) MPI_Abort(MPI_COMM_WORLD, exit_status);
    MPI_Finalize();
    if (d->wire) {
        if (d->wire->names)
            for (int i = 0; i < d->size; i++) free(d->wire->names[i]);
        free(d->wire->names);
        free(d->wire->gone);
        pthread_mutex_destroy(&d->wire->lock);
        free(d->wire);
    }
    for (int i = 0; i < SCENE_BUF_COUNT; i++) free(d->scene_bufs[i]);
    memset(d, 0, sizeof *d);
}

/* ------------------------------------------------------------------ agreeing on the command */

/* What a rank's plan is, in words, for the message that two ranks differ. */
static const char *plan_name(int32_t plan, int32_t broadcast)
{
    switch (plan) {
    case DIST_RENDER: return broadcast ? "a render with --mpi-broadcast" : "a render without --mpi-broadcast";
    case DIST_HELP: return "--help";
    case DIST_VERSION: return "--version";
    case DIST_LIST_DEVICES: return "--list-devices";
    default: return "a failed start";
    }
}

/* Rank 0: waits for each worker's WireStart and judges them against its own; returns
 * ST_OK when every rank may go on. Its own failure comes first (err already holds it). */
static Status start_judge(Dist *d, const WireStart *mine, Status st, Error *err)
{
    Status out = st;
    for (int r = 1; r < d->size; r++) {
        WireStart w;
        Error e = { 0 };
        Status got = wire_wait(d, r, TAG_START, &w, sizeof w, NULL, &e);
        if (got != ST_OK) {
            /* a rank that says nothing will not leave MPI_Finalize either */
            d->lost = 1;
            if (out == ST_OK) out = error_set(err, got, "starting the MPI job: %s", e.msg);
            error_clear(&e);
            continue;
        }
        w.msg[sizeof w.msg - 1] = '\0';
        if (out != ST_OK) continue;
        if (w.plan == DIST_FAILED)
            out = error_set(err, w.status != ST_OK ? (Status)w.status : ST_INTERNAL, "MPI rank %d could not start: %s",
                            r, w.msg);
        else if (w.plan != mine->plan || (w.plan == DIST_RENDER && !w.broadcast != !mine->broadcast))
            out = error_set(err, ST_USAGE, "MPI ranks 0 and %d were given different commands (rank 0: %s; rank %d: "
                            "%s): every rank of a job must run the same command, only the device flags may differ",
                            r, plan_name(mine->plan, mine->broadcast), r, plan_name(w.plan, w.broadcast));
    }
    return out;
}

Status dist_start(Dist *d, DistPlan plan, int broadcast, Status st, Error *err)
{
    if (!d->active) return st;
    WireStart mine;
    memset(&mine, 0, sizeof mine);
    mine.plan = st == ST_OK ? plan : DIST_FAILED;
    mine.status = st;
    mine.broadcast = broadcast;
    if (st != ST_OK) snprintf(mine.msg, sizeof mine.msg, "%s", err->msg);
    if (d->rank == 0) {
        Status out = start_judge(d, &mine, st, err);
        int32_t go = out == ST_OK;
        for (int r = 1; r < d->size; r++) {
            int rc = wire_send(d, &go, 1, MPI_INT32_T, r, TAG_GO);
            if (rc != MPI_SUCCESS && out == ST_OK) out = mpi_failed(err, rc, r, "starting the MPI job");
        }
        return out;
    }
    int rc = wire_send(d, &mine, (int)sizeof mine, MPI_BYTE, 0, TAG_START);
    if (rc != MPI_SUCCESS) {
        d->lost = 1;
        return mpi_failed(err, rc, 0, "starting the MPI job");
    }
    /* rank 0 may wait d->timeout for another rank before it answers */
    int32_t go = 0;
    Error e = { 0 };
    double timeout = d->timeout;
    d->timeout = 2.0 * timeout + 1.0;
    Status got = wire_wait(d, 0, TAG_GO, &go, sizeof go, NULL, &e);
    d->timeout = timeout;
    if (got != ST_OK) {
        d->lost = 1;
        if (st == ST_OK) st = error_set(err, got, "starting the MPI job: %s", e.msg);
        error_clear(&e);
        return st;
    }
    /* rank 0 reports every failure, this rank's own too */
    return go ? ST_OK : ST_INTERRUPTED;
}

/* ------------------------------------------------------------------ the scene */

typedef struct {
    int32_t status;
    uint32_t spp, n_materials, n_shading, n_tri_extra_of, n_tri_extras;
    uint64_t n_texels, n_rev_points, n_env_cdf, n_bvh_leaves;
    uint64_t bytes[SCENE_BUF_COUNT];
} WireScene;

/* MPI counts are ints: big buffers go in pieces of 1 GiB. */
static int bcast_bytes(void *data, size_t bytes)
{
    const size_t piece = (size_t)1 << 30;
    for (size_t at = 0; at < bytes; at += piece) {
        size_t n = bytes - at < piece ? bytes - at : piece;
        int rc = MPI_Bcast((char *)data + at, (int)n, MPI_BYTE, 0, MPI_COMM_WORLD);
        if (rc != MPI_SUCCESS) return rc;
    }
    return MPI_SUCCESS;
}

/* A worker: points the buffer fields of ds at the received buffers. */
static void scene_set_buffer(DeviceScene *ds, unsigned i, void *buf)
{
    switch (i) {
#define SET_ONE_(Type, name) memcpy(&ds->name, buf, sizeof ds->name)
#define SET_MANY_(Type, name) ds->name = (const Type *)buf
#define SET_CASE_(kind, Type, name, count, what) \
    case SCENE_BUF_##name:                       \
        SET_##kind##_(Type, name);               \
        break;
        SCENE_BUFFERS(SET_CASE_)
#undef SET_CASE_
#undef SET_MANY_
#undef SET_ONE_
    default:
        break;
    }
}

static Status scene_receive(Dist *d, const WireScene *h, DeviceScene *ds, Error *err)
{
    memset(ds, 0, sizeof *ds);
    ds->n_materials = h->n_materials;
    ds->n_shading = h->n_shading;
    ds->n_tri_extra_of = h->n_tri_extra_of;
    ds->n_tri_extras = h->n_tri_extras;
    ds->n_texels = (size_t)h->n_texels;
    ds->n_rev_points = (size_t)h->n_rev_points;
    ds->n_env_cdf = (size_t)h->n_env_cdf;
    ds->n_bvh_leaves = (size_t)h->n_bvh_leaves;
    for (unsigned i = 0; i < SCENE_BUF_COUNT; i++) {
        if (h->bytes[i] == 0) continue;
        if (h->bytes[i] > SIZE_MAX || !(d->scene_bufs[i] = malloc((size_t)h->bytes[i])))
            return error_set(err, ST_INTERNAL, "out of memory for the broadcast scene");
        int rc = bcast_bytes(d->scene_bufs[i], (size_t)h->bytes[i]);
        if (rc != MPI_SUCCESS) return mpi_failed(err, rc, 0, "receiving the scene");
        if (i == SCENE_BUF_params && h->bytes[i] != sizeof(RenderParams))
            return error_set(err, ST_INTERNAL, "the broadcast scene comes from another clpt build");
        scene_set_buffer(ds, i, d->scene_bufs[i]);
    }
    /* the counts in the params block must give the sizes received */
    for (unsigned i = 0; i < SCENE_BUF_COUNT; i++)
        if (device_scene_buffer(ds, i).bytes != h->bytes[i])
            return error_set(err, ST_INTERNAL, "the broadcast scene's %s do not match its counts",
                             device_scene_buffer(ds, i).what);
    return ST_OK;
}

Status dist_share_scene(Dist *d, Status rank0_status, DeviceScene *ds, unsigned *spp, Error *err)
{
    WireScene h;
    memset(&h, 0, sizeof h);
    if (d->rank == 0) {
        h.status = rank0_status;
        h.spp = *spp;
        h.n_materials = ds->n_materials;
        h.n_shading = ds->n_shading;
        h.n_tri_extra_of = ds->n_tri_extra_of;
        h.n_tri_extras = ds->n_tri_extras;
        h.n_texels = ds->n_texels;
        h.n_rev_points = ds->n_rev_points;
        h.n_env_cdf = ds->n_env_cdf;
        h.n_bvh_leaves = ds->n_bvh_leaves;
        for (unsigned i = 0; rank0_status == ST_OK && i < SCENE_BUF_COUNT; i++)
            h.bytes[i] = device_scene_buffer(ds, i).bytes;
    }
    int rc = MPI_Bcast(&h, (int)sizeof h, MPI_BYTE, 0, MPI_COMM_WORLD);
    if (rc != MPI_SUCCESS) return mpi_failed(err, rc, d->rank, "broadcasting the scene");
    if (h.status != ST_OK) return d->rank == 0 ? rank0_status : ST_INTERRUPTED;
    if (d->rank != 0) {
        *spp = h.spp;
        return scene_receive(d, &h, ds, err);
    }
    for (unsigned i = 0; i < SCENE_BUF_COUNT; i++) {
        SceneBufferBytes b = device_scene_buffer(ds, i);
        if (b.bytes && (rc = bcast_bytes((void *)b.data, b.bytes)) != MPI_SUCCESS)
            return mpi_failed(err, rc, 0, "broadcasting the scene");
    }
    return ST_OK;
}

/* ------------------------------------------------------------------ agreeing to start */

static void describe_rank(Device **devs, size_t n, char *where, size_t size)
{
    char host[MPI_MAX_PROCESSOR_NAME + 1];
    int len = 0;
    if (MPI_Get_processor_name(host, &len) != MPI_SUCCESS) len = 0;
    host[len] = '\0';
    size_t at = (size_t)snprintf(where, size, "%s:", len ? host : "?");
    for (size_t i = 0; i < n && at < size; i++)
        at += (size_t)snprintf(where + at, size - at, "%s %s", i ? "," : "", devs[i]->desc.name);
}

Status dist_agree(Dist *d, Status st, const Error *st_err, const CheckpointId *id, Device **devs, size_t n,
                  Error *err)
{
    WireAgree mine;
    memset(&mine, 0, sizeof mine);
    mine.status = st;
    if (st == ST_OK) memcpy(mine.key, id->key, sizeof mine.key);
    else snprintf(mine.msg, sizeof mine.msg, "%s", st_err->msg);
    describe_rank(devs, n, mine.where, sizeof mine.where);
    WireAgree *all = d->rank == 0 ? calloc((size_t)d->size, sizeof *all) : NULL;
    int32_t verdict = ST_OK;
    if (d->rank == 0 && !all) verdict = ST_INTERNAL;
    int rc = MPI_Gather(&mine, (int)sizeof mine, MPI_BYTE, all, (int)sizeof mine, MPI_BYTE, 0, MPI_COMM_WORLD);
    Status out = rc == MPI_SUCCESS ? ST_OK : mpi_failed(err, rc, d->rank, "starting the render");
    if (d->rank == 0 && all && rc == MPI_SUCCESS) {
        d->wire->names = calloc((size_t)d->size, sizeof *d->wire->names);
        d->wire->gone = calloc((size_t)d->size, 1);
        for (int r = 1; r < d->size && verdict == ST_OK && st == ST_OK; r++) {
            if (all[r].status != ST_OK) {
                verdict = all[r].status;
                out = error_set(err, (Status)all[r].status, "MPI rank %d (%s) could not start: %s", r, all[r].where,
                                all[r].msg);
            } else if (memcmp(all[r].key, id->key, sizeof id->key) != 0) {
                verdict = ST_INPUT;
                out = error_set(err, ST_INPUT, "MPI rank %d (%s) read another scene or settings than rank 0 (its "
                                "render key differs): give every rank the same files, or use --mpi-broadcast", r,
                                all[r].where);
            } else if (d->wire->names) {
                d->wire->names[r] = strdup(all[r].where);
            }
        }
        if (st != ST_OK) verdict = st;
    }
    free(all);
    rc = MPI_Bcast(&verdict, 1, MPI_INT32_T, 0, MPI_COMM_WORLD);
    if (out == ST_OK && rc != MPI_SUCCESS) out = mpi_failed(err, rc, d->rank, "starting the render");
    if (out == ST_OK && verdict != ST_OK) out = d->rank == 0 ? (Status)verdict : ST_INTERRUPTED;
    if (d->rank != 0 && st != ST_OK) out = ST_INTERRUPTED;   /* rank 0 says it */
    if (d->rank == 0 && st != ST_OK) out = st;               /* err already holds it */
    return out;
}

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

static Status remote_update_params(Device *dev, const RenderParams *params, const uint *mask, Error *err)
{
    (void)params;
    (void)mask;
    return remote_not_here(dev, "a second pass (--adaptive, --aov)", err);
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

/* Renders one batch with the worker's devices and sends rank 0 its result and film. */
static Status worker_batch(Dist *d, Device **devs, size_t n, Film *film, const uint32_t *batch,
                           volatile sig_atomic_t *stop, WireStats *tot, Error *err)
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

/* Waits for rank 0's next word: a batch (1) or stop (0). */
static int worker_next(Dist *d, uint32_t *batch, Status *st, Error *err)
{
    for (;;) {
        int flag = 0;
        MPI_Status ms;
        wire_lock(d);
        int rc = MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
        if (rc == MPI_SUCCESS && flag)
            rc = MPI_Recv(batch, 3, MPI_UINT32_T, 0, ms.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        wire_unlock(d);
        if (rc != MPI_SUCCESS) {
            *st = mpi_failed(err, rc, d->rank, "waiting for a batch");
            return 0;
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
    uint32_t batch[3];
    while (st == ST_OK && tot && worker_next(d, batch, &st, err))
        st = worker_batch(d, devs, n, &film, batch, stop, tot, err);
    atomic_store(&hb.quit, 1);
    if (hb.running) pthread_join(hb.thread, NULL);
    if (st == ST_OK && tot) {
        int rc = wire_send(d, tot, (int)sizeof *tot, MPI_BYTE, 0, TAG_STATS);
        if (rc != MPI_SUCCESS) st = mpi_failed(err, rc, d->rank, "sending its statistics");
    }
    if (!tot && st == ST_OK) st = error_set(err, ST_INTERNAL, "out of memory");
    free(tot);
    film_free(&film);
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
