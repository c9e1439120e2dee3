/* kd_events.c — the kd-tree build's sweep events: a primitive box's start, end or
 * planar event per axis (kd_build.h holds their 64-bit keys), and their sort. */
#include "accel/kd_build.h"

#include <stdlib.h>
#include <string.h>

/* Appends the events of one primitive's box on axis k. */
size_t kd_events_emit(Event *out, const Aabb *b, int k, uint prim)
{
    if (b->lo[k] == b->hi[k]) {
        out[0] = event_make(b->lo[k], EV_PLANAR, prim);
        return 1;
    }
    out[0] = event_make(b->lo[k], EV_START, prim);
    out[1] = event_make(b->hi[k], EV_END, prim);
    return 2;
}

/* LSD radix sort of bits [low, 64) of the keys, `bits` at a time (tmp holds n events;
 * count holds RADIX_BUCKETS counters), skipping digits that all keys share. It is
 * stable, so keys equal in those bits keep their order. */
static inline void radix_sort_from(Event *a, Event *tmp, size_t *count, size_t n, int low, int bits)
{
    size_t buckets = (size_t)1 << bits, mask = buckets - 1;
    Event *src = a, *dst = tmp;
    for (int shift = low; shift < 64; shift += bits) {
        memset(count, 0, buckets * sizeof *count);
        for (size_t i = 0; i < n; i++) count[(src[i] >> shift) & mask]++;
        if (count[(src[0] >> shift) & mask] == n) continue;
        size_t sum = 0;
        for (size_t d = 0; d < buckets; d++) {
            size_t c = count[d];
            count[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++) dst[count[(src[i] >> shift) & mask]++] = src[i];
        Event *swap = src;
        src = dst;
        dst = swap;
    }
    if (src != a) memcpy(a, src, n * sizeof *a);
}

/* Sorts any list of events: 16-bit digits for big lists, 8-bit ones for the straddling
 * primitives' few new events, insertion sort for tiny lists. */
void kd_events_sort(Event *a, Event *tmp, size_t *count, size_t n)
{
    if (n < 64) {
        for (size_t i = 1; i < n; i++) {
            Event e = a[i];
            size_t j = i;
            for (; j > 0 && a[j - 1] > e; j--) a[j] = a[j - 1];
            a[j] = e;
        }
        return;
    }
    /* constant digits, so that each call is specialised where it is inlined */
    if (n >= RADIX_BUCKETS) radix_sort_from(a, tmp, count, n, 0, RADIX_BIG_BITS);
    else radix_sort_from(a, tmp, count, n, 0, 8);
}

/* Sorts a list emitted in increasing primitive order, as the root's are. The sort is
 * stable, so only the bits above the primitive's need sorting: from bit 28, three
 * 12-bit digits (bits 28 and 29 of the primitive are then in order already). Three
 * passes over 4096 buckets instead of four over 65536: half the time on the dragon. */
void kd_events_sort_by_prim_order(Event *a, Event *tmp, size_t *count, size_t n)
{
    radix_sort_from(a, tmp, count, n, 28, 12);
}

static int uint_cmp(const void *a, const void *b)
{
    uint x = *(const uint *)a, y = *(const uint *)b;
    return (x > y) - (x < y);
}

void kd_ids_sort(uint *ids, uint n)
{
    if (n > 32) {
        qsort(ids, n, sizeof *ids, uint_cmp);
        return;
    }
    for (uint i = 1; i < n; i++) {
        uint x = ids[i], j = i;
        for (; j > 0 && ids[j - 1] > x; j--) ids[j] = ids[j - 1];
        ids[j] = x;
    }
}

