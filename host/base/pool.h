/* pool.h — a bump allocator in chunks, with marks to roll back to: allocation is a
 * pointer increment, and everything allocated after a mark is given back at once (the
 * kd-tree build retracts a subtree that did not pay off this way). Not thread-safe: one
 * pool per thread. */
#ifndef CLPT_POOL_H
#define CLPT_POOL_H

#include <stddef.h>

typedef struct PoolChunk {
    struct PoolChunk *next;
    size_t cap, used;
    max_align_t data[];
} PoolChunk;

typedef struct { PoolChunk *first, *cur; } Pool;
typedef struct { PoolChunk *chunk; size_t used; } PoolMark;

/* size bytes aligned to 16; NULL when out of memory. */
void *pool_alloc(Pool *p, size_t size);
/* Where the pool is now, to roll back to. */
PoolMark pool_mark(const Pool *p);
/* Gives back everything allocated since mark m; (PoolMark){ NULL, 0 } frees it all. */
void pool_release(Pool *p, PoolMark m);

#endif /* CLPT_POOL_H */
