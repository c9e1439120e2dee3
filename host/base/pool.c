/* pool.c — see pool.h. */
#include "base/pool.h"

#include <stdlib.h>

/* Bytes of a chunk (a larger allocation gets a chunk of its own size). */
#define POOL_CHUNK_BYTES (1u << 20)

void *pool_alloc(Pool *p, size_t size)
{
    size = (size + 15u) & ~(size_t)15u;
    PoolChunk *c = p->cur;
    if (!c || c->used + size > c->cap) {
        size_t cap = size > POOL_CHUNK_BYTES ? size : POOL_CHUNK_BYTES;
        PoolChunk *fresh = malloc(sizeof *fresh + cap);
        if (!fresh) return NULL;
        fresh->next = NULL;
        fresh->cap = cap;
        fresh->used = 0;
        if (c) c->next = fresh;
        else p->first = fresh;
        p->cur = c = fresh;
    }
    void *r = (char *)c->data + c->used;
    c->used += size;
    return r;
}

PoolMark pool_mark(const Pool *p)
{
    PoolMark m = { p->cur, p->cur ? p->cur->used : 0 };
    return m;
}

static void pool_free_from(PoolChunk *c)
{
    while (c) {
        PoolChunk *next = c->next;
        free(c);
        c = next;
    }
}

void pool_release(Pool *p, PoolMark m)
{
    if (!m.chunk) {
        pool_free_from(p->first);
        p->first = p->cur = NULL;
        return;
    }
    pool_free_from(m.chunk->next);
    m.chunk->next = NULL;
    m.chunk->used = m.used;
    p->cur = m.chunk;
}

