/* strmap.c — the string map (strmap.h). */
#include "base/strmap.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

static uint64_t hash_bytes(uint64_t seed, const char *key, size_t len)
{
    uint64_t h = 14695981039346656037ull ^ seed;
    for (size_t i = 0; i < len; i++) {
        h ^= (unsigned char)key[i];
        h *= 1099511628211ull;
    }
    /* FNV's low bits mix poorly, and the table index is the low bits: finish with
     * the MurmurHash3 avalanche */
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    return h;
}

/* The slot holding the key, or the empty slot where it would go. */
static StrMapSlot *slot_for(const StrMapSlot *slots, size_t cap, const char *key, size_t len, uint64_t h)
{
    size_t mask = cap - 1;
    for (size_t i = (size_t)h & mask;; i = (i + 1) & mask) {
        const StrMapSlot *s = &slots[i];
        if (!s->key || (s->hash == h && s->len == len && memcmp(s->key, key, len) == 0))
            return (StrMapSlot *)s;
    }
}

int strmap_find(const StrMap *m, const char *key, size_t len, uint32_t *value)
{
    if (m->n == 0) return 0;
    const StrMapSlot *s = slot_for(m->slots, m->cap, key, len, hash_bytes(m->seed, key, len));
    if (!s->key) return 0;
    if (value) *value = s->value;
    return 1;
}

/* Doubles the table (or makes the first one); the slots keep their keys. */
static int grow(StrMap *m)
{
    size_t cap = m->cap ? m->cap * 2 : 16;
    if (cap > SIZE_MAX / 2 / sizeof(StrMapSlot)) return -1;
    StrMapSlot *slots = calloc(cap, sizeof *slots);
    if (!slots) return -1;
    if (!m->slots) {
        struct timespec ts;
        timespec_get(&ts, TIME_UTC);
        m->seed = (uint64_t)ts.tv_nsec * 0x9e3779b97f4a7c15ull ^ (uint64_t)(uintptr_t)slots;
    }
    for (size_t i = 0; i < m->cap; i++) {
        const StrMapSlot *o = &m->slots[i];
        if (o->key) *slot_for(slots, cap, o->key, o->len, o->hash) = *o;
    }
    free(m->slots);
    m->slots = slots;
    m->cap = cap;
    return 0;
}

/* The key's slot, added (with `value`) when absent; NULL when out of memory. *added
 * says which. */
static StrMapSlot *insert(StrMap *m, const char *key, size_t len, uint32_t value, int *added)
{
    *added = 0;
    if (m->n > 0) {
        StrMapSlot *s = slot_for(m->slots, m->cap, key, len, hash_bytes(m->seed, key, len));
        if (s->key) return s;
    }
    /* at most half full, so that probe runs stay short */
    if ((m->n + 1) * 2 > m->cap && grow(m)) return NULL;
    char *copy = malloc(len + 1);
    if (!copy) return NULL;
    memcpy(copy, key, len);
    copy[len] = '\0';
    uint64_t h = hash_bytes(m->seed, key, len);
    StrMapSlot *s = slot_for(m->slots, m->cap, key, len, h);
    s->key = copy;
    s->len = len;
    s->hash = h;
    s->value = value;
    m->n++;
    *added = 1;
    return s;
}

int strmap_add(StrMap *m, const char *key, size_t len, uint32_t value)
{
    int added;
    if (!insert(m, key, len, value, &added)) return -1;
    return added ? 0 : 1;
}

int strmap_set(StrMap *m, const char *key, size_t len, uint32_t value)
{
    int added;
    StrMapSlot *s = insert(m, key, len, value, &added);
    if (!s) return -1;
    s->value = value;
    return 0;
}

void strmap_free(StrMap *m)
{
    for (size_t i = 0; i < m->cap; i++) free(m->slots[i].key);
    free(m->slots);
    memset(m, 0, sizeof *m);
}
