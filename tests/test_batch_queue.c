/* test_batch_queue.c — every sample index is completed exactly once, whatever the batch
 * sizes, the number of devices, their speeds and their failures. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>

#include "render/batch_queue.h"
#include "harness.h"

static void test_sequential_take(void)
{
    BatchQueue q;
    CHECK(batch_queue_init(&q, 10) == 0);
    Batch b;
    CHECK(batch_queue_take(&q, 4, &b) == 1);
    CHECK_EQ_INT(b.first, 0);
    CHECK_EQ_INT(b.count, 4);
    CHECK_EQ_INT(batch_queue_remaining(&q), 6);
    batch_queue_done(&q, b);
    CHECK(batch_queue_take(&q, 100, &b) == 1);
    CHECK_EQ_INT(b.first, 4);
    CHECK_EQ_INT(b.count, 6);
    batch_queue_done(&q, b);
    CHECK(batch_queue_take(&q, 1, &b) == 0);
    CHECK_EQ_INT(batch_queue_completed(&q), 10);
    batch_queue_free(&q);
}

static void test_give_back_is_split_and_served_first(void)
{
    BatchQueue q;
    CHECK(batch_queue_init(&q, 100) == 0);
    Batch a, b;
    CHECK(batch_queue_take(&q, 10, &a) == 1);
    CHECK(batch_queue_give_back(&q, a) == 0);
    CHECK(batch_queue_take(&q, 4, &b) == 1);
    CHECK_EQ_INT(b.first, 0);
    CHECK_EQ_INT(b.count, 4);
    batch_queue_done(&q, b);
    CHECK(batch_queue_take(&q, 100, &b) == 1);
    CHECK_EQ_INT(b.first, 4);
    CHECK_EQ_INT(b.count, 6);
    batch_queue_done(&q, b);
    CHECK(batch_queue_take(&q, 100, &b) == 1);
    CHECK_EQ_INT(b.first, 10);
    CHECK_EQ_INT(b.count, 90);
    batch_queue_done(&q, b);
    CHECK_EQ_INT(batch_queue_completed(&q), 100);
    batch_queue_free(&q);
}

static void test_close_stops_handing_out(void)
{
    BatchQueue q;
    CHECK(batch_queue_init(&q, 100) == 0);
    Batch b;
    CHECK(batch_queue_take(&q, 10, &b) == 1);
    batch_queue_close(&q);
    Batch c;
    CHECK(batch_queue_take(&q, 10, &c) == 0);
    batch_queue_done(&q, b);
    CHECK_EQ_INT(batch_queue_completed(&q), 10);
    batch_queue_free(&q);
}

/* ---- many simulated devices with random speeds, batch sizes and failures */

#define N_SAMPLES 5000u

typedef struct {
    BatchQueue *q;
    atomic_int *done_count;      /* per sample index: how many times completed */
    unsigned seed;
    int fail_after;              /* fail on this batch (-1: never) */
} SimDevice;

static unsigned lcg(unsigned *s) { return *s = *s * 1664525u + 1013904223u; }

static void *sim_device(void *arg)
{
    SimDevice *d = arg;
    int batches = 0;
    Batch b;
    while (batch_queue_take(d->q, 1 + lcg(&d->seed) % 37u, &b)) {
        struct timespec ts = { 0, (long)(lcg(&d->seed) % 200000u) };
        nanosleep(&ts, NULL);
        if (batches++ == d->fail_after) {
            CHECK(batch_queue_give_back(d->q, b) == 0);
            return NULL;
        }
        for (uint s = b.first; s < b.first + b.count; s++) atomic_fetch_add(&d->done_count[s], 1);
        batch_queue_done(d->q, b);
    }
    return NULL;
}

static void test_random_devices_and_failures(void)
{
    for (unsigned round = 0; round < 20; round++) {
        BatchQueue q;
        CHECK(batch_queue_init(&q, N_SAMPLES) == 0);
        atomic_int *count = calloc(N_SAMPLES, sizeof *count);
        enum { N_DEV = 6 };
        SimDevice devs[N_DEV];
        pthread_t th[N_DEV];
        unsigned s = 12345u + round * 7919u;
        for (int i = 0; i < N_DEV; i++) {
            devs[i].q = &q;
            devs[i].done_count = count;
            devs[i].seed = lcg(&s);
            /* up to all but one device fail at some point */
            devs[i].fail_after = (i < N_DEV - 1 && lcg(&s) % 2u) ? (int)(lcg(&s) % 30u) : -1;
            pthread_create(&th[i], NULL, sim_device, &devs[i]);
        }
        for (int i = 0; i < N_DEV; i++) pthread_join(th[i], NULL);
        int wrong = 0;
        for (uint i = 0; i < N_SAMPLES; i++) wrong += atomic_load(&count[i]) != 1;
        CHECK_MSG(wrong == 0, "round %u: %d sample indices not completed exactly once", round, wrong);
        CHECK_EQ_INT(batch_queue_completed(&q), N_SAMPLES);
        free(count);
        batch_queue_free(&q);
    }
}

/* A resumed render: only the gaps between the ranges already done are handed out, the
 * lowest first, and the done count starts at what was done. */
static void test_skip_done_hands_out_only_the_gaps(void)
{
    BatchQueue q;
    CHECK(batch_queue_init(&q, 100) == 0);
    const Batch done[] = { { 40, 10 }, { 0, 5 }, { 90, 10 } };   /* unsorted on purpose */
    CHECK(batch_queue_skip_done(&q, done, 3) == 0);
    CHECK_EQ_INT(batch_queue_completed(&q), 25);
    CHECK_EQ_INT(batch_queue_remaining(&q), 75);
    const Batch expect[] = { { 5, 35 }, { 50, 40 } };
    Batch b;
    for (int i = 0; i < 2; i++) {
        CHECK(batch_queue_take(&q, 1000, &b) == 1);
        CHECK_EQ_INT(b.first, expect[i].first);
        CHECK_EQ_INT(b.count, expect[i].count);
        batch_queue_done(&q, b);
    }
    CHECK(batch_queue_take(&q, 1000, &b) == 0);
    CHECK_EQ_INT(batch_queue_completed(&q), 100);
    batch_queue_free(&q);

    /* overlapping or out-of-range ranges are refused */
    CHECK(batch_queue_init(&q, 100) == 0);
    const Batch overlap[] = { { 0, 10 }, { 5, 10 } };
    CHECK_EQ_INT(batch_queue_skip_done(&q, overlap, 2), -1);
    const Batch beyond[] = { { 95, 10 } };
    CHECK_EQ_INT(batch_queue_skip_done(&q, beyond, 1), -1);
    const Batch past_end[] = { { 101, 0 } };
    CHECK_EQ_INT(batch_queue_skip_done(&q, past_end, 1), -1);
    batch_queue_free(&q);
}

/* try_take never waits, even while batches are in flight. */
static void test_try_take_does_not_wait(void)
{
    BatchQueue q;
    CHECK(batch_queue_init(&q, 10) == 0);
    Batch a, b;
    CHECK(batch_queue_try_take(&q, 10, &a) == 1);
    CHECK(batch_queue_try_take(&q, 10, &b) == 0);
    batch_queue_done(&q, a);
    batch_queue_free(&q);
}

/* The record of done samples stays sorted and merged, whatever the order batches finish. */
static void test_batch_set_merges(void)
{
    BatchSet s;
    memset(&s, 0, sizeof s);
    unsigned seed = 99u;
    /* 200 batches of 5 samples, added in a shuffled order */
    uint order[200];
    for (uint i = 0; i < 200; i++) order[i] = i;
    for (uint i = 199; i > 0; i--) {
        uint j = lcg(&seed) % (i + 1), t = order[i];
        order[i] = order[j];
        order[j] = t;
    }
    for (uint i = 0; i < 200; i++) {
        CHECK(batch_set_add(&s, (Batch){ order[i] * 5u, 5u }) == 0);
        for (size_t k = 1; k < s.n; k++)
            CHECK(s.ranges[k - 1].first + s.ranges[k - 1].count < s.ranges[k].first);
    }
    CHECK_EQ_INT(s.n, 1);
    CHECK_EQ_INT(s.ranges[0].first, 0);
    CHECK_EQ_INT(batch_set_total(&s), 1000);
    BatchSet c;
    memset(&c, 0, sizeof c);
    CHECK(batch_set_copy(&c, &s) == 0);
    CHECK(c.n == 1 && c.ranges[0].count == 1000);
    batch_set_free(&c);
    batch_set_free(&s);
}

int main(void)
{
    RUN(test_sequential_take);
    RUN(test_give_back_is_split_and_served_first);
    RUN(test_close_stops_handing_out);
    RUN(test_random_devices_and_failures);
    RUN(test_skip_done_hands_out_only_the_gaps);
    RUN(test_try_take_does_not_wait);
    RUN(test_batch_set_merges);
    return harness_report();
}
