/* batch_queue.c — see batch_queue.h. */
#include "render/batch_queue.h"

#include <stdlib.h>
#include <string.h>

#include "base/array.h"

int batch_queue_init(BatchQueue *q, uint end)
{
    memset(q, 0, sizeof *q);
    q->end = end;
    if (pthread_mutex_init(&q->lock, NULL)) return -1;
    if (pthread_cond_init(&q->changed, NULL)) {
        pthread_mutex_destroy(&q->lock);
        return -1;
    }
    return 0;
}

void batch_queue_free(BatchQueue *q)
{
    pthread_cond_destroy(&q->changed);
    pthread_mutex_destroy(&q->lock);
    free(q->returned);
    q->returned = NULL;
}

static int cmp_batch(const void *a, const void *b)
{
    uint x = ((const Batch *)a)->first, y = ((const Batch *)b)->first;
    return (x > y) - (x < y);
}

int batch_queue_skip_done(BatchQueue *q, const Batch *done, size_t n)
{
    Batch *sorted = n ? malloc(n * sizeof *sorted) : NULL;
    if (n && !sorted) return -2;
    if (n) memcpy(sorted, done, n * sizeof *sorted);
    if (n) qsort(sorted, n, sizeof *sorted, cmp_batch);   /* qsort(NULL, 0) is undefined */
    int rc = 0;
    uint at = 0, skipped = 0;
    size_t n_todo = 0;
    Batch *todo = malloc((n + 1) * sizeof *todo);
    if (!todo) rc = -2;
    for (size_t i = 0; rc == 0 && i < n; i++) {
        if (sorted[i].first < at || sorted[i].first > q->end || sorted[i].count > q->end - sorted[i].first) {
            rc = -1;
            break;
        }
        if (sorted[i].first > at) todo[n_todo++] = (Batch){ at, sorted[i].first - at };
        at = sorted[i].first + sorted[i].count;
        skipped += sorted[i].count;
    }
    if (rc == 0 && at < q->end) todo[n_todo++] = (Batch){ at, q->end - at };
    if (rc == 0) {
        pthread_mutex_lock(&q->lock);
        /* The gaps are handed out through the given-back list, which is served from
         * its end: stored in reverse, the lowest sample indices go first. */
        free(q->returned);
        q->returned = todo;
        q->cap_returned = n + 1;
        q->n_returned = n_todo;
        for (size_t i = 0; i < n_todo / 2; i++) {
            Batch t = todo[i];
            todo[i] = todo[n_todo - 1 - i];
            todo[n_todo - 1 - i] = t;
        }
        q->next = q->end;
        q->completed = skipped;
        pthread_mutex_unlock(&q->lock);
        todo = NULL;
    }
    free(todo);
    free(sorted);
    return rc;
}

/* Hands out up to `want` samples from what is free; the caller holds the lock. */
static int take_locked(BatchQueue *q, uint want, Batch *out)
{
    if (q->closed) return 0;
    if (q->n_returned > 0) {
        Batch *b = &q->returned[q->n_returned - 1];
        out->first = b->first;
        out->count = b->count < want ? b->count : want;
        b->first += out->count;
        b->count -= out->count;
        if (b->count == 0) q->n_returned--;
    } else if (q->next < q->end) {
        out->first = q->next;
        out->count = q->end - q->next < want ? q->end - q->next : want;
        q->next += out->count;
    } else {
        return 0;
    }
    q->outstanding += out->count;
    return 1;
}

int batch_queue_take(BatchQueue *q, uint want, Batch *out)
{
    pthread_mutex_lock(&q->lock);
    while (!q->closed && q->n_returned == 0 && q->next >= q->end && q->outstanding > 0)
        pthread_cond_wait(&q->changed, &q->lock);
    int got = take_locked(q, want ? want : 1, out);
    pthread_mutex_unlock(&q->lock);
    return got;
}

int batch_queue_try_take(BatchQueue *q, uint want, Batch *out)
{
    pthread_mutex_lock(&q->lock);
    int got = take_locked(q, want ? want : 1, out);
    pthread_mutex_unlock(&q->lock);
    return got;
}

void batch_queue_done(BatchQueue *q, Batch b)
{
    pthread_mutex_lock(&q->lock);
    q->outstanding -= b.count;
    q->completed += b.count;
    pthread_cond_broadcast(&q->changed);
    pthread_mutex_unlock(&q->lock);
}

int batch_queue_give_back(BatchQueue *q, Batch b)
{
    int rc = 0;
    pthread_mutex_lock(&q->lock);
    q->outstanding -= b.count;
    if (array_reserve((void **)&q->returned, &q->cap_returned, q->n_returned + 1, sizeof b) == 0)
        q->returned[q->n_returned++] = b;
    else {
        q->closed = 1;
        rc = -1;
    }
    pthread_cond_broadcast(&q->changed);
    pthread_mutex_unlock(&q->lock);
    return rc;
}

void batch_queue_close(BatchQueue *q)
{
    pthread_mutex_lock(&q->lock);
    q->closed = 1;
    pthread_cond_broadcast(&q->changed);
    pthread_mutex_unlock(&q->lock);
}

uint batch_queue_remaining(BatchQueue *q)
{
    pthread_mutex_lock(&q->lock);
    uint r = q->end - q->next;
    for (size_t i = 0; i < q->n_returned; i++) r += q->returned[i].count;
    pthread_mutex_unlock(&q->lock);
    return r;
}

uint batch_queue_completed(BatchQueue *q)
{
    pthread_mutex_lock(&q->lock);
    uint c = q->completed;
    pthread_mutex_unlock(&q->lock);
    return c;
}

int batch_set_add(BatchSet *s, Batch b)
{
    if (b.count == 0) return 0;
    /* the first range that starts after b */
    size_t i = 0;
    while (i < s->n && s->ranges[i].first < b.first) i++;
    int join_prev = i > 0 && s->ranges[i - 1].first + s->ranges[i - 1].count == b.first;
    int join_next = i < s->n && b.first + b.count == s->ranges[i].first;
    if (join_prev && join_next) {
        s->ranges[i - 1].count += b.count + s->ranges[i].count;
        memmove(&s->ranges[i], &s->ranges[i + 1], (s->n - i - 1) * sizeof *s->ranges);
        s->n--;
    } else if (join_prev) {
        s->ranges[i - 1].count += b.count;
    } else if (join_next) {
        s->ranges[i].first = b.first;
        s->ranges[i].count += b.count;
    } else {
        if (array_reserve((void **)&s->ranges, &s->cap, s->n + 1, sizeof b)) return -1;
        memmove(&s->ranges[i + 1], &s->ranges[i], (s->n - i) * sizeof *s->ranges);
        s->ranges[i] = b;
        s->n++;
    }
    return 0;
}

int batch_set_copy(BatchSet *dst, const BatchSet *src)
{
    if (array_reserve((void **)&dst->ranges, &dst->cap, src->n ? src->n : 1, sizeof *src->ranges)) return -1;
    if (src->n) memcpy(dst->ranges, src->ranges, src->n * sizeof *src->ranges);
    dst->n = src->n;
    return 0;
}

uint batch_set_total(const BatchSet *s)
{
    uint t = 0;
    for (size_t i = 0; i < s->n; i++) t += s->ranges[i].count;
    return t;
}

void batch_set_free(BatchSet *s)
{
    free(s->ranges);
    memset(s, 0, sizeof *s);
}
