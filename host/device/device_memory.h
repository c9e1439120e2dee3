/*
 * device_memory.h — whether a render's buffers fit a device, checked before any of them
 * is allocated: each buffer within the device's largest allocation
 * (CL_DEVICE_MAX_MEM_ALLOC_SIZE), all of them within its global memory
 * (CL_DEVICE_GLOBAL_MEM_SIZE). A scene too large for a GPU is then a clear message
 * naming the device and the sizes, not a failed allocation halfway through the upload
 * (or a driver that accepts the allocations and fails the first launch).
 */
#ifndef CLPT_DEVICE_MEMORY_H
#define CLPT_DEVICE_MEMORY_H

#include <stddef.h>
#include <stdint.h>

#include "base/status.h"

typedef struct {
    const char *what;     /* "triangles", "film", "path states" ... */
    uint64_t bytes;
} DeviceBuffer;

/* ST_DEVICE when a buffer exceeds max_alloc or all of them exceed global_mem:
 *   "device 'NAME': the triangles need 1200.0 MiB in one buffer, more than its largest
 *    allocation (1024.0 MiB)"
 *   "device 'NAME': the render needs 5000.0 MiB (triangles 3000.0 MiB, ...), more than
 *    its 4096.0 MiB of memory"
 * each followed by what can be done about it. */
Status device_memory_check(const char *device, uint64_t global_mem, uint64_t max_alloc,
                           const DeviceBuffer *bufs, size_t n, Error *err);

#endif /* CLPT_DEVICE_MEMORY_H */
