/* fault.c — the test-only fault injection of fault.h. */
#include "base/fault.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Whether the comma-separated `list` holds `item` exactly. */
static int list_has(const char *list, const char *item)
{
    size_t n = strlen(item);
    for (const char *p = list; p && *p;) {
        size_t k = strcspn(p, ",");
        if (k == n && strncmp(p, item, n) == 0) return 1;
        p += k + (p[k] == ',');
    }
    return 0;
}

int fault_alloc_fails(const char *site)
{
    return list_has(getenv("CLPT_TEST_FAIL_ALLOC"), site);
}

void fault_device_memory(unsigned index, uint64_t *global_mem, uint64_t *max_alloc)
{
    const char *p = getenv("CLPT_TEST_DEVICE_MEMORY");
    while (p && *p) {
        char *end;
        unsigned long i = strtoul(p, &end, 10);
        if (end != p && *end == ':') {
            unsigned long long cap = strtoull(end + 1, &end, 10);
            if (i == index) {
                if (*global_mem > cap) *global_mem = cap;
                if (*max_alloc > cap) *max_alloc = cap;
            }
        }
        p = strchr(p, ',');
        if (p) p++;
    }
}

const char *fault_build_options(unsigned index)
{
    char item[24];
    snprintf(item, sizeof item, "%u", index);
    /* every `__kernel` becomes an unknown type name: the compiler stops with errors in
     * the build log, as for any broken kernel source */
    return list_has(getenv("CLPT_TEST_BUILD_FAIL"), item)
               ? "-D__kernel=clpt_test_build_failure_forced_by_CLPT_TEST_BUILD_FAIL"
               : NULL;
}

long fault_device_batch(size_t device_index)
{
    const char *spec = getenv("CLPT_TEST_FAIL");
    while (spec && *spec) {
        char *end;
        unsigned long dev = strtoul(spec, &end, 10);
        if (*end != ':') break;
        long batch = strtol(end + 1, &end, 10);
        if (dev == device_index) return batch;
        if (*end != ',') break;
        spec = end + 1;
    }
    return -1;
}
