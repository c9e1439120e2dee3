/*
 * batch_queue.h — the samples still to render, handed out as batches.
 *
 * A batch is a range of sample indices [first, first + count) over the whole image. Any
 * device takes the next batch when it finishes its last one, of the size it asks for;
 * a device that fails gives its batch back, and the batch is handed out again before any
 * fresh samples. Every sample index below `end` is completed exactly once.
 * Thread-safe.
 */
#ifndef CLPT_BATCH_QUEUE_H
#define CLPT_BATCH_QUEUE_H

#include <pthread.h>
#include <stddef.h>

#include "types.h"

typedef struct {
    uint first, count;
} Batch;

typedef struct {
    pthread_mutex_t lock;
    pthread_cond_t changed;  /* signalled when batches are done, given back or closed */
    uint next;              /* first sample index never handed out */
    uint end;               /* one past the last sample index to render */
    Batch *returned;        /* batches given back, handed out again first */
    size_t n_returned, cap_returned;
    uint outstanding;       /* samples handed out and neither done nor returned */
    uint completed;         /* samples done */
    int closed;             /* no more batches will be handed out (time up, interrupt) */
} BatchQueue;

/* Samples [0, end). Returns 0, or -1 if the mutex cannot be created. */
int batch_queue_init(BatchQueue *q, uint end);
void batch_queue_free(BatchQueue *q);

/* Resuming a render: marks `n` ranges of sample indices as already done (sorted or not,
 * but disjoint and below `end`), so that only the rest is handed out. Call before any
 * take. Returns 0, -1 if the ranges overlap or lie beyond the end, -2 if out of memory. */
int batch_queue_skip_done(BatchQueue *q, const Batch *done, size_t n);

/* Takes up to `want` (>= 1) samples. Returns 1 with *out filled, or 0 when nothing is
 * left to do (every sample done, or the queue closed). While nothing is free but other
 * batches are in flight it waits, since a failing device may give its batch back.
 * A given-back batch larger than `want` is split. */
int batch_queue_take(BatchQueue *q, uint want, Batch *out);
/* The same without waiting: 0 also when nothing is free right now. For a caller that
 * holds batches in flight itself (waiting could wait for its own batches). */
int batch_queue_try_take(BatchQueue *q, uint want, Batch *out);
/* Reports a taken batch as finished. */
void batch_queue_done(BatchQueue *q, Batch b);
/* Gives a taken batch back unfinished (its device failed); returns -1 if out of memory,
 * in which case the batch is lost to this run and the queue is closed. */
int batch_queue_give_back(BatchQueue *q, Batch b);
/* Stops handing out batches; batches in flight may still be reported. */
void batch_queue_close(BatchQueue *q);

/* Samples not yet handed out (fresh or given back), and those done. */
uint batch_queue_remaining(BatchQueue *q);
uint batch_queue_completed(BatchQueue *q);

/* A set of sample indices as sorted, disjoint, non-adjacent ranges: the samples a film
 * holds, as recorded in a checkpoint. Not thread-safe (the scheduler guards it with the
 * film's lock). */
typedef struct {
    Batch *ranges;
    size_t n, cap;
} BatchSet;

/* Adds a range that does not overlap the set; returns 0, or -1 if out of memory (the
 * set is then unchanged). */
int batch_set_add(BatchSet *s, Batch b);
/* A copy of `src` in `dst` (whose old contents are freed); -1 if out of memory. */
int batch_set_copy(BatchSet *dst, const BatchSet *src);
/* The number of sample indices in the set. */
uint batch_set_total(const BatchSet *s);
void batch_set_free(BatchSet *s);

#endif /* CLPT_BATCH_QUEUE_H */
