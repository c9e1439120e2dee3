/* mpi_wire.c — the MPI calls under the messages (mpi_wire.h): one thread in MPI at a time,
 * errors named, and receives that poll so a cancel or a silent rank is seen. */
#include "dist/mpi_wire.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "base/timer.h"

void wire_lock(Dist *d)
{
    pthread_mutex_lock(&d->wire->lock);
}

void wire_unlock(Dist *d)
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

Status mpi_failed(Error *err, int rc, int rank, const char *what)
{
    char m[MPI_MAX_ERROR_STRING + 1];
    mpi_message(rc, m, sizeof m);
    return error_set(err, ST_DEVICE, "MPI rank %d: %s: %s", rank, what, m);
}

int wire_send(Dist *d, const void *buf, int count, MPI_Datatype type, int to, int tag)
{
    wire_lock(d);
    int rc = MPI_Send(buf, count, type, to, tag, MPI_COMM_WORLD);
    wire_unlock(d);
    return rc;
}

void sleep_seconds(double s)
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
Status wire_receive(Dist *d, int from, int tag, void *buf, int count, Error *err)
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
Status wire_wait(Dist *d, int from, int want, void *buf, size_t bytes, const atomic_int *cancel, Error *err)
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
