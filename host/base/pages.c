/* pages.c — see pages.h. */
#include "base/pages.h"

#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>

void *pages_alloc_huge(size_t bytes)
{
    if (bytes > SIZE_MAX - PAGES_HUGE_BYTES) return NULL;
    size_t rounded = (bytes + PAGES_HUGE_BYTES - 1u) & ~(PAGES_HUGE_BYTES - 1u);
    void *p = aligned_alloc(PAGES_HUGE_BYTES, rounded ? rounded : PAGES_HUGE_BYTES);
#ifdef MADV_HUGEPAGE
    /* advice: a kernel without transparent huge pages refuses it, which changes nothing */
    if (p) (void)madvise(p, rounded, MADV_HUGEPAGE);
#endif
    return p;
}

int pages_on_huge(const void *p, size_t bytes)
{
    return p && bytes >= PAGES_HUGE_BYTES && ((uintptr_t)p & (PAGES_HUGE_BYTES - 1u)) == 0u;
}

void *pages_alloc_large(size_t bytes)
{
    if (bytes >= PAGES_HUGE_BYTES) return pages_alloc_huge(bytes);
    return aligned_alloc(64, (bytes + 63u) / 64u * 64u + 64u * (bytes == 0));
}
