/* array.c — see array.h. */
#include "base/array.h"

#include <stdint.h>
#include <stdlib.h>

int array_reserve(void **ptr, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap) return 0;
    size_t new_cap = *cap ? *cap : 16;
    while (new_cap < need) {
        if (new_cap > SIZE_MAX / 2) return -1;
        new_cap *= 2;
    }
    if (new_cap > SIZE_MAX / elem) return -1;
    void *p = realloc(*ptr, new_cap * elem);
    if (!p) return -1;
    *ptr = p;
    *cap = new_cap;
    return 0;
}
