/* mpi_driver.c — see mpi_driver.h: joining the ranks, agreeing on the command and the
 * render, sharing the scene. The remote devices and the workers are mpi_workers.c, the
 * messages mpi_wire.h (listed in docs/distributed.md). */
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

#define WIRE_COUNT_ONE_(Type, name) +1
enum { WIRE_COUNTS = 0 DEVICE_SCENE_COUNTS(WIRE_COUNT_ONE_) };
#undef WIRE_COUNT_ONE_

/* The scene's header: rank 0's status, the spp, every count of DEVICE_SCENE_COUNTS in its
 * order, and each buffer's size. */
typedef struct {
    int32_t status;
    uint32_t spp;
    uint64_t counts[WIRE_COUNTS];
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
    unsigned k = 0;
#define GET_COUNT_(Type, name) ds->name = (Type)h->counts[k++];
    DEVICE_SCENE_COUNTS(GET_COUNT_)
#undef GET_COUNT_
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
        unsigned k = 0;
#define PUT_COUNT_(Type, name) h.counts[k++] = (uint64_t)ds->name;
        DEVICE_SCENE_COUNTS(PUT_COUNT_)
#undef PUT_COUNT_
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
