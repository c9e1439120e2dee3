/* mpi_job.c — see mpi_job.h. */
#include "dist/mpi_job.h"

/* The options an MPI job takes, passed on to the driver. */
static Status dist_options(Dist *d, const DistRequest *q, Error *err)
{
    if (q->passes)
        return error_set(err, ST_USAGE, "--adaptive and --aov are not available under MPI (run them in one process)");
    if (q->interactive)
        return error_set(err, ST_USAGE, "--interactive is not available under MPI (the window belongs to one process)");
    d->broadcast = q->broadcast;
    if (q->timeout > 0.0) d->timeout = q->timeout;
    d->fixed_batch = q->fixed_batch;
    return ST_OK;
}

Status dist_join(Dist *d, const DistRequest *q, Status st, Error *err)
{
    Error init_err = { 0 };
    Status joined = dist_init(d, st == ST_OK ? q->timeout : 0.0, &init_err);
    if (joined != ST_OK) {
        error_clear(err);
        *err = init_err;
        return joined;
    }
    if (st == ST_OK && d->active) st = dist_options(d, q, err);
    return dist_start(d, q->plan, st == ST_OK && q->broadcast, st, err);
}

/* --mpi-broadcast: rank 0's prepared scene becomes every worker's. */
static Status share_scene(Dist *d, const DistRankSteps *s, Status st, Error *err)
{
    unsigned spp = *s->spp;
    Status shared = dist_share_scene(d, st, s->ds, &spp, err);
    if (shared != ST_OK || d->rank == 0) return shared;
    *s->spp = spp;
    checkpoint_id(s->ds, spp, s->id);
    return ST_OK;
}

Status dist_run_rank(Dist *d, const DistRankSteps *s, Error *err)
{
    int worker = d->rank > 0, receive = worker && d->broadcast;
    Status st = s->prepare(s->ctx, worker, receive, err);
    if (d->broadcast) st = share_scene(d, s, st, err);
    if (st == ST_OK) st = s->open_devices(s->ctx, err);
    st = dist_agree(d, st, err, s->id, *s->devs, *s->n_devs, err);
    if (st != ST_OK) return st;
    if (worker) {
        s->worker_starts(s->ctx);
        return dist_worker_run(d, *s->devs, *s->n_devs, s->ds->params.width, s->ds->params.height, s->stop, err);
    }
    st = s->render(s->ctx, d, err);
    dist_stop_workers(d, s->stats_out);
    return st;
}
