/* test_pages.c — memory on huge pages (host/base/pages.c), which the trees' arrays and
 * the OpenCL CPU devices' large buffers use: aligned to 2 MiB, its rounded-up size all
 * writable (ASan and valgrind check the bounds), NULL for sizes that cannot be rounded;
 * small arrays 64-byte aligned and not rounded up. Whether the kernel
 * then backs it with huge pages is up to its settings; the test reports what it did
 * (bench/RESULTS.md measures what it is worth). The images the buffers give are checked
 * by every OpenCL-against-scalar test, whose waves and large scenes use them. */
#include "harness.h"

#include "base/pages.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void test_aligned_and_rounded(void)
{
    const size_t sizes[] = { 1, PAGES_HUGE_BYTES - 1u, PAGES_HUGE_BYTES, PAGES_HUGE_BYTES + 1u,
                             3u * PAGES_HUGE_BYTES + 12345u };
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        unsigned char *p = pages_alloc_huge(sizes[i]);
        CHECK(p != NULL);
        if (!p) continue;
        CHECK_EQ_INT((int)((uintptr_t)p % PAGES_HUGE_BYTES), 0);
        /* the whole of each huge page is the caller's */
        size_t rounded = (sizes[i] + PAGES_HUGE_BYTES - 1u) / PAGES_HUGE_BYTES * PAGES_HUGE_BYTES;
        memset(p, 0xa5, rounded);
        CHECK(p[0] == 0xa5 && p[sizes[i] - 1u] == 0xa5 && p[rounded - 1u] == 0xa5);
        free(p);
    }
}

/* Small arrays stay as small as their contents, 64-byte aligned; large ones go huge. */
static void test_large_only_when_large(void)
{
    const size_t sizes[] = { 0, 1, 63, 64, 65, 100000, PAGES_HUGE_BYTES - 1u, PAGES_HUGE_BYTES,
                             PAGES_HUGE_BYTES + 100u };
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        unsigned char *p = pages_alloc_large(sizes[i]);
        CHECK(p != NULL);
        if (!p) continue;
        CHECK_EQ_INT((int)((uintptr_t)p % 64u), 0);
        if (sizes[i] >= PAGES_HUGE_BYTES) CHECK_EQ_INT((int)((uintptr_t)p % PAGES_HUGE_BYTES), 0);
        if (sizes[i]) {
            memset(p, 0x5a, sizes[i]);
            CHECK(p[sizes[i] - 1u] == 0x5a);
        }
        free(p);
    }
    CHECK(pages_alloc_large(SIZE_MAX) == NULL);
}

/* pages_on_huge tells pages_alloc_huge's arrays (which an OpenCL CPU device then uses in
 * place) from everything else: malloc's large blocks, small arrays, NULL. */
static void test_on_huge(void)
{
    size_t big = 2u * PAGES_HUGE_BYTES;
    unsigned char *h = pages_alloc_huge(big), *l = pages_alloc_large(big), *m = malloc(big), *s = pages_alloc_large(4096);
    CHECK(h && l && m && s);
    if (h && l && m && s) {
        CHECK(pages_on_huge(h, big));
        CHECK(pages_on_huge(h, PAGES_HUGE_BYTES));
        CHECK(!pages_on_huge(h, PAGES_HUGE_BYTES - 1u));   /* too small to be worth it */
        CHECK(pages_on_huge(l, big));
        CHECK(!pages_on_huge(m, big));
        CHECK(!pages_on_huge(s, 4096));
        CHECK(!pages_on_huge(h + 64, big - 64));
    }
    CHECK(!pages_on_huge(NULL, big));
    free(h);
    free(l);
    free(m);
    free(s);
}

static void test_too_large(void)
{
    CHECK(pages_alloc_huge(SIZE_MAX) == NULL);
    CHECK(pages_alloc_huge(SIZE_MAX - PAGES_HUGE_BYTES + 2u) == NULL);
}

/* Reports how much of a written 8 MiB block the kernel put on huge pages. */
static void test_report_huge_pages(void)
{
    size_t bytes = 4u * PAGES_HUGE_BYTES;
    unsigned char *p = pages_alloc_huge(bytes);
    CHECK(p != NULL);
    if (!p) return;
    memset(p, 1, bytes);
    long huge_kb = -1;
    FILE *f = fopen("/proc/self/smaps", "r");
    char line[512];
    int in_block = 0;
    while (f && fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2 && strchr(line, '-') < strchr(line, ' '))
            in_block = (uintptr_t)p >= lo && (uintptr_t)p < hi;
        else if (in_block && sscanf(line, "AnonHugePages: %ld kB", &huge_kb) == 1)
            break;
    }
    if (f) fclose(f);
    printf("  %ld kB of the block's mapping on huge pages (transparent huge pages: ", huge_kb);
    f = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (f && fgets(line, sizeof line, f)) printf("%.*s)\n", (int)strcspn(line, "\n"), line);
    else printf("not available)\n");
    if (f) fclose(f);
    CHECK(p[bytes - 1u] == 1);
    free(p);
}

int main(void)
{
    RUN(test_aligned_and_rounded);
    RUN(test_large_only_when_large);
    RUN(test_on_huge);
    RUN(test_too_large);
    RUN(test_report_huge_pages);
    return harness_report();
}
