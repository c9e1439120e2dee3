/* device_memory.c — see device_memory.h. */
#include "device/device_memory.h"

#include <stdio.h>

static double mib(uint64_t bytes) { return (double)bytes / 1048576.0; }

#define ADVICE "render a smaller image or scene, lower --wave-paths, or choose another device"

Status device_memory_check(const char *device, uint64_t global_mem, uint64_t max_alloc,
                           const DeviceBuffer *bufs, size_t n, Error *err)
{
    uint64_t total = 0;
    for (size_t i = 0; i < n; i++) {
        if (bufs[i].bytes > max_alloc)
            return error_set(err, ST_DEVICE,
                             "device '%s': the %s need %.1f MiB in one buffer, more than its largest "
                             "allocation (%.1f MiB); " ADVICE,
                             device, bufs[i].what, mib(bufs[i].bytes), mib(max_alloc));
        total += bufs[i].bytes;
    }
    if (total <= global_mem) return ST_OK;
    /* name the buffers that take the most, largest first, as far as the message goes */
    char parts[600];
    size_t o = 0;
    int used[64] = { 0 };
    for (size_t k = 0; k < 4 && k < n && k < 64; k++) {
        size_t best = n;
        for (size_t i = 0; i < n && i < 64; i++)
            if (!used[i] && (best == n || bufs[i].bytes > bufs[best].bytes)) best = i;
        if (best == n || bufs[best].bytes == 0) break;
        used[best] = 1;
        int w = snprintf(parts + o, sizeof parts - o, "%s%s %.1f MiB", o ? ", " : "", bufs[best].what,
                         mib(bufs[best].bytes));
        if (w < 0 || (size_t)w >= sizeof parts - o) break;
        o += (size_t)w;
    }
    parts[o < sizeof parts ? o : sizeof parts - 1] = '\0';
    return error_set(err, ST_DEVICE,
                     "device '%s': the render needs %.1f MiB (%s%s), more than its %.1f MiB of "
                     "memory; " ADVICE,
                     device, mib(total), parts, n > 4 ? ", ..." : "", mib(global_mem));
}
