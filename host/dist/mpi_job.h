/*
 * mpi_job.h — one rank's part in an MPI job, step by step (docs/distributed.md): join
 * the job with what the command line asks for (dist_join), then prepare, agree and
 * render (dist_run_rank). Every step runs on every rank, also after a failure, so that
 * no rank waits for ever in a collective call; rank 0 alone reports.
 *
 * The program's own steps (its outputs, its scene, its devices, its render and what it
 * writes) are the program's, given as DistRankSteps; this file holds their order under
 * MPI and the MPI side of each (mpi_driver.h). The command line reaches it as a
 * DistRequest, filled by the program, so dist/ never reads Options.
 */
#ifndef CLPT_MPI_JOB_H
#define CLPT_MPI_JOB_H

#include <signal.h>
#include <stddef.h>
#include <stdio.h>

#include "base/status.h"
#include "device/device.h"
#include "dist/mpi_driver.h"
#include "render/checkpoint.h"

/* What an MPI job needs of the command line. */
typedef struct {
    DistPlan plan;          /* what the command line asks for (DIST_RENDER, --help, ...) */
    int broadcast;          /* --mpi-broadcast: the scene comes from rank 0 */
    double timeout;         /* --mpi-timeout in seconds; 0: the default */
    unsigned fixed_batch;   /* --batch */
    int passes;             /* --adaptive or --aov: not available under MPI */
    int interactive;        /* --interactive: not available under MPI */
} DistRequest;

/* Under an MPI launcher: joins the job also after a failed command line (st, its
 * message in err), and all ranks agree on what to do (dist_start), so that a rank that
 * cannot start, or that was given another command (an MPMD job), ends the job with
 * rank 0's message instead of leaving the others waiting. */
Status dist_join(Dist *d, const DistRequest *q, Status st, Error *err);

/* The program's steps of one rank, each given `ctx`, and where the state they fill
 * lies. */
typedef struct {
    void *ctx;
    /* The outputs (rank 0 only: not `worker`) and the prepared scene (not when
     * `receive`: it comes from rank 0). */
    Status (*prepare)(void *ctx, int worker, int receive, Error *err);
    /* Opens this rank's devices into *devs, *n_devs. */
    Status (*open_devices)(void *ctx, Error *err);
    /* A worker, just before it renders rank 0's batches (its signal handlers). */
    void (*worker_starts)(void *ctx);
    /* Rank 0: the render, with the others as devices (dist_add_remote_devices), and
     * what it writes; its status is the run's. */
    Status (*render)(void *ctx, Dist *d, Error *err);
    DeviceScene *ds;              /* the prepared (or received) scene */
    unsigned *spp;                /* its samples per pixel (a received one is stored here) */
    CheckpointId *id;             /* the render's identity (set for a received scene) */
    Device ***devs;
    size_t *n_devs;
    volatile sig_atomic_t *stop;  /* a worker stops rendering when it is set */
    FILE *stats_out;              /* --stats: where the workers' statistics go; NULL: not printed */
} DistRankSteps;

/* One rank of the job that dist_join started: every rank prepares the scene (or
 * receives it, --mpi-broadcast) and its devices, and all agree to start; then rank 0
 * renders with the others as devices and writes the outputs, while the others render
 * the batches it sends. */
Status dist_run_rank(Dist *d, const DistRankSteps *s, Error *err);

#endif /* CLPT_MPI_JOB_H */
