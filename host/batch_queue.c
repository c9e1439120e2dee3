/* batch_queue.c — see batch_queue.h. */
#include "batch_queue.h"

#include <stdlib.h>
#include <string.h>

#include "scene.h"

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

int batch_queue_take(BatchQueue *q, uint want, Batch *out)
{
    if (want == 0) want = 1;
    int got = 0;
    pthread_mutex_lock(&q->lock);
    while (!q->closed && q->n_returned == 0 && q->next >= q->end && q->outstanding > 0)
        pthread_cond_wait(&q->changed, &q->lock);
    if (!q->closed) {
        if (q->n_returned > 0) {
            Batch *b = &q->returned[q->n_returned - 1];
            out->first = b->first;
            out->count = b->count < want ? b->count : want;
            b->first += out->count;
            b->count -= out->count;
            if (b->count == 0) q->n_returned--;
            got = 1;
        } else if (q->next < q->end) {
            out->first = q->next;
            out->count = q->end - q->next < want ? q->end - q->next : want;
            q->next += out->count;
            got = 1;
        }
        if (got) q->outstanding += out->count;
    }
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
