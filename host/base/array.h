/* array.h — growing a heap array by doubling, for every module that appends. */
#ifndef CLPT_ARRAY_H
#define CLPT_ARRAY_H

#include <stddef.h>

/* Grows *ptr (an array of `elem`-byte items with capacity *cap) to hold `need` items.
 * Returns 0 on success, -1 when out of memory or when the size would overflow (the
 * array is then unchanged). */
int array_reserve(void **ptr, size_t *cap, size_t need, size_t elem);

#endif /* CLPT_ARRAY_H */
