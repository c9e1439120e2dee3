/*
 * strmap.h — a map from byte strings to 32-bit values (an index into the caller's
 * array), so that the readers find a material, texture or element by name in constant
 * time: a linear search per lookup made 80,000 MTL materials take 23 s and 200,000
 * named scene materials 78 s.
 *
 * Open addressing with linear probing, a power-of-two table kept at most half full, and
 * keys copied into the map (the caller's strings may move or be freed). glib's
 * GHashTable or hsearch_r would do the job, but glib is a large dependency for one
 * table, and hsearch_r has a fixed size and no lookup by (pointer, length). The hash is
 * FNV-1a from a per-map seed taken from the clock and the table's address, so that a
 * file cannot be crafted to make every name collide.
 *
 * A zeroed StrMap is empty and ready; strmap_free releases it.
 */
#ifndef CLPT_STRMAP_H
#define CLPT_STRMAP_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    char *key;           /* NULL: an empty slot */
    size_t len;
    uint64_t hash;
    uint32_t value;
} StrMapSlot;

typedef struct {
    StrMapSlot *slots;
    size_t cap;          /* 0 or a power of two */
    size_t n;
    uint64_t seed;
} StrMap;

/* Whether key[0, len) is in the map; if so and value is non-NULL, *value is set. */
int strmap_find(const StrMap *m, const char *key, size_t len, uint32_t *value);
/* Adds key[0, len) -> value unless the key is present already, in which case its value
 * stays (the first definition wins) and 1 is returned. 0: added; -1: out of memory
 * (the map is unchanged). */
int strmap_add(StrMap *m, const char *key, size_t len, uint32_t value);
/* Sets key[0, len) -> value, adding the key or replacing its value. 0, or -1 when out
 * of memory (the map is unchanged). */
int strmap_set(StrMap *m, const char *key, size_t len, uint32_t value);
void strmap_free(StrMap *m);

#endif /* CLPT_STRMAP_H */
