/*
 * mpi_driver.h — one image rendered by the processes of an MPI job (docs/distributed.md).
 *
 * Rank 0 runs the ordinary scheduler (render/schedule.h) over its own devices plus one
 * "remote device" per other rank: the remote device's render() sends the batch (sample
 * range) to its rank and waits for that rank's film of the batch, which take_film adds
 * into the film like any device's. So the batch queue spans the ranks, a rank asks for
 * its next batch as soon as it has returned the last (fast ranks do more), batch sizes
 * adapt per rank, a rank that fails or stops answering gives its batch back to the
 * others, and progress, --time-limit, --progressive-output, checkpoints and --stats are
 * the scheduler's own. The film is integer, so the image is the same bits as one
 * process's, for any number of ranks and any devices.
 *
 * Every other rank (a worker) renders each batch it receives with its own devices (the
 * scheduler again, over that range only) and sends back the batch's film, until rank 0
 * says stop. Workers write nothing; rank 0 prints every message.
 *
 * MPI is initialised only when an MPI launcher started the process (mpirun, or srun
 * through PMI/PMIx, seen in the environment) and the job has more than one rank: a
 * plain `clpt` run never starts MPI (and so never pays for its start-up or shows its
 * allocations to valgrind and LeakSanitizer).
 */
#ifndef CLPT_MPI_DRIVER_H
#define CLPT_MPI_DRIVER_H

#include <signal.h>
#include <stddef.h>

#include "base/status.h"
#include "device/device.h"
#include "render/checkpoint.h"

typedef struct DistWire DistWire;

typedef struct {
    int active;                   /* in an MPI job of more than one rank */
    int rank, size;
    int broadcast;                /* --mpi-broadcast: the scene comes from rank 0 */
    unsigned spp;                 /* the render's samples per pixel */
    unsigned fixed_batch;         /* --batch: a worker's batches within a batch */
    double timeout;               /* seconds without a word from a rank before it is given up */
    int lost;                     /* a worker did not answer the end: abort, not finalise */
    DistWire *wire;               /* the lock that serialises MPI calls; owned */
    void *scene_bufs[SCENE_BUF_COUNT];   /* a broadcast scene, on the workers; owned */
} Dist;

/* Whether an MPI launcher started this process in a job of more than one rank. */
int dist_launched(void);

/* Joins the MPI job when launched by an MPI launcher (else leaves *d inactive, at no
 * cost). Called after the command line is read, also when reading it failed, so that
 * every rank joins and the others hear of the failure (dist_start). A job that has not
 * started within `timeout` seconds (0: 30) ends this process with a message and status
 * ST_DEVICE (a process of the job never joined). ST_INTERNAL when MPI cannot start. */
Status dist_init(Dist *d, double timeout, Error *err);

/* What a rank's command line asks for. */
typedef enum { DIST_RENDER, DIST_HELP, DIST_VERSION, DIST_LIST_DEVICES, DIST_FAILED } DistPlan;

/* Right after dist_init: every rank tells rank 0 its plan (or its failure, st with the
 * message in err), and whether it has --mpi-broadcast; rank 0 answers each whether to
 * go on. Rank 0 fails with its own failure, else with the first worker's failure or
 * the first worker whose plan differs from its own (named); a worker then returns
 * ST_INTERRUPTED, quietly. Every wait is bounded by d->timeout; a rank that does not
 * answer sets d->lost (the job must be aborted, not finalised). */
Status dist_start(Dist *d, DistPlan plan, int broadcast, Status st, Error *err);

/* Leaves the job (MPI_Finalize), or ends it for every rank (MPI_Abort) when `abort`:
 * after a rank stopped answering, a finalize could wait for it for ever. */
void dist_finish(Dist *d, int exit_status, int abort);

/* --mpi-broadcast: rank 0 sends the prepared scene (every scene buffer, and the samples
 * per pixel), or the news that it has none (rank0_status, not ST_OK); a worker receives
 * it into *ds. A worker returns ST_INTERRUPTED, quietly, when rank 0 had none. */
Status dist_share_scene(Dist *d, Status rank0_status, DeviceScene *ds, unsigned *spp, Error *err);

/* Every rank tells rank 0 how its start went (status, message), which render it is
 * about to take part in (the render key) and with which devices: rank 0 fails with the
 * first worker's failure, or when a worker read another scene or settings; a worker
 * fails quietly (ST_INTERRUPTED, nothing to print) when any rank failed. */
Status dist_agree(Dist *d, Status st, const Error *st_err, const CheckpointId *id, Device **devs, size_t n,
                  Error *err);

/* Rank 0: one remote device per worker rank, appended to *devs (grown). */
Status dist_add_remote_devices(Dist *d, unsigned n_pixels, Device ***devs, size_t *n, Error *err);

/* A worker: renders the batches rank 0 sends with `devs` until rank 0 says stop. */
Status dist_worker_run(Dist *d, Device **devs, size_t n, unsigned width, unsigned height,
                       volatile sig_atomic_t *stop, Error *err);

/* Rank 0, after the render: tells every worker to stop and gathers their devices'
 * statistics, printed with --stats (to `out` when non-NULL). Sets d->lost when a worker
 * did not answer (the job must then be aborted, not finalised). */
void dist_stop_workers(Dist *d, FILE *out);

#endif /* CLPT_MPI_DRIVER_H */
