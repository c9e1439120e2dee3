/*
 * pages.h — memory for large arrays that are read at random, on 2 MiB pages.
 *
 * A render reads a big scene's arrays at random: the dragon's 871k triangles have
 * 3.3 MB of BVH nodes, which every ray walks, and 37 MB of leaves and 42 MB of
 * triangles. On 4 KiB pages those accesses also miss the TLB (on a VM, a two-level page
 * walk). Linux backs memory with transparent huge pages everywhere or, when it is set
 * to `madvise` (as the kernels clpt was measured on are), only where asked; Embree asks
 * for its trees. bench/RESULTS.md has what it gave. Where the kernel has no huge pages
 * the advice changes nothing, and nothing depends on it.
 */
#ifndef CLPT_PAGES_H
#define CLPT_PAGES_H

#include <stddef.h>

/* The huge page size, and the smallest array worth a huge page of its own. */
#define PAGES_HUGE_BYTES ((size_t)2 << 20)

/* At least `bytes` of uninitialised memory aligned to PAGES_HUGE_BYTES, its size rounded
 * up to a whole number of huge pages that are asked to be huge; NULL when out of memory.
 * Write it before anything else does: pages are made when first touched. Free with free(). */
void *pages_alloc_huge(size_t bytes);

/* At least `bytes` of uninitialised memory aligned to 64 bytes: pages_alloc_huge's when
 * bytes >= PAGES_HUGE_BYTES, so that an array only as large as its contents is not
 * rounded up to a huge page; NULL when out of memory. Free with free(). */
void *pages_alloc_large(size_t bytes);

/* Whether the array p of `bytes` is pages_alloc_huge's memory: PAGES_HUGE_BYTES or more
 * at a PAGES_HUGE_BYTES boundary. Nothing else in clpt asks for that alignment, and
 * glibc's own large blocks start 16 bytes into a page. */
int pages_on_huge(const void *p, size_t bytes);

#endif /* CLPT_PAGES_H */
