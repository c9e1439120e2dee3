/*
 * mpi_wire.h — the messages between rank 0 and the workers (tags and layouts, listed
 * in docs/distributed.md) and the MPI calls that carry them, shared by mpi_driver.c
 * (joining, agreeing, the scene), mpi_workers.c (remote devices, the workers, the end)
 * and mpi_wire.c. Not included outside host/dist/.
 */
#ifndef CLPT_MPI_WIRE_H
#define CLPT_MPI_WIRE_H

#include <mpi.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

#include "dist/mpi_driver.h"

/* Message tags. Every message goes between rank 0 and one worker. */
enum {
    TAG_BATCH = 1,     /* 0 -> w: uint32 {first, count, spp} */
    TAG_STOP,          /* 0 -> w: uint32 {0}: no more batches; answer with TAG_STATS */
    TAG_RESULT,        /* w -> 0: WireResult; TAG_FILM follows when its status is ST_OK */
    TAG_FILM,          /* w -> 0: int64 film sums, width * height * 3 */
    TAG_STATS,         /* w -> 0: WireStats: the worker's devices, at the end */
    TAG_ALIVE,         /* w -> 0: empty, every second: the worker is alive */
    TAG_START,         /* w -> 0: WireStart: what the worker's command line asks for */
    TAG_GO,            /* 0 -> w: int32: 1 when every rank may go on with the render */
    TAG_PARAMS         /* 0 -> w: bytes: a RenderParams, then its pixel_list_size uint32
                        * pixel indices: the devices' new params block and pixel list
                        * (an adaptive round, --noise-threshold); the batches after it
                        * render with them */
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

/* One thread in MPI at a time (MPI_THREAD_SERIALIZED). */
void wire_lock(Dist *d);
void wire_unlock(Dist *d);
/* ST_DEVICE naming the MPI error rc, the rank and what was being done. */
Status mpi_failed(Error *err, int rc, int rank, const char *what);
/* MPI_Send under the lock; the MPI return code. */
int wire_send(Dist *d, const void *buf, int count, MPI_Datatype type, int to, int tag);
void sleep_seconds(double s);
/* Receives a message that MPI_Iprobe has matched (see mpi_wire.c). */
Status wire_receive(Dist *d, int from, int tag, void *buf, int count, Error *err);
/* Waits for the next message from `from` of tag `want` (TAG_ALIVE aside), polling so
 * that a cancel or a silent rank is seen (see mpi_wire.c). */
Status wire_wait(Dist *d, int from, int want, void *buf, size_t bytes, const atomic_int *cancel, Error *err);

#endif /* CLPT_MPI_WIRE_H */
