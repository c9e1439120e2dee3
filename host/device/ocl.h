/*
 * ocl.h — OpenCL basics shared by all OpenCL host code: error names, the one way a
 * failed call is reported, and device discovery.
 *
 * Every OpenCL call is checked, and a failure is recorded where it happens as
 *
 *     device 'NAME': clCallName failed: CL_ERROR_NAME[: context]
 *
 * (the Khronos OpenCL-SDK style: the call and the error's name, never a bare -5).
 * The one form used throughout:
 *
 *     cl_int rc = clFinish(queue);
 *     if (rc != CL_SUCCESS) return ocl_fail(err, dev, "clFinish", rc);
 *
 *     cl_mem buf = clCreateBuffer(ctx, flags, size, NULL, &rc);
 *     if (rc != CL_SUCCESS) {
 *         st = ocl_failf(err, dev, "clCreateBuffer", rc, "%zu bytes for triangles", size);
 *         goto cleanup;
 *     }
 *
 * A function holding OpenCL objects starts them as NULL, jumps to one `cleanup:` label
 * on failure, and releases what is non-NULL there.
 */
#ifndef CLPT_OCL_H
#define CLPT_OCL_H

#include <CL/cl.h>
#include <stddef.h>

#include "base/status.h"

/* One OpenCL device, with what clpt needs to know to choose, build for and report it. */
typedef struct {
    cl_platform_id platform;
    cl_device_id id;
    char name[256], vendor[256], platform_name[256], platform_version[256],
        driver_version[128], device_version[128], opencl_c_version[128];
    cl_device_type type;
    cl_uint compute_units;
    cl_ulong global_mem, max_alloc, local_mem; /* bytes */
    size_t max_work_group;
    int correctly_rounded_divide_sqrt; /* CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT for float */
    int available, compiler_available;
    unsigned platform_index, device_index; /* position in the enumeration order */
} OclDeviceInfo;

/* The name of an OpenCL error code ("CL_OUT_OF_RESOURCES"); every code of the OpenCL
 * 1.2 headers, the 2.x additions and the common KHR extension codes are known, anything
 * else is "unknown OpenCL error". The result is a static string (thread safe). */
const char *ocl_error_name(cl_int code);

/* "GPU", "CPU", "accelerator", "custom" or "unknown" (the most specific bit wins). */
const char *ocl_device_type_name(cl_device_type type);

/* Records a failed OpenCL call as ST_DEVICE:
 *   "device 'NAME': CALL failed: CL_NAME"  (dev NULL: "CALL failed: CL_NAME").
 * A device whose name is not known yet is named by its position ("device #0.1").
 * Returns ST_DEVICE so that it can end a `return` statement. */
Status ocl_fail(Error *err, const OclDeviceInfo *dev, const char *call, cl_int rc);
/* Same, with context appended after ": " (printf format). */
Status ocl_failf(Error *err, const OclDeviceInfo *dev, const char *call, cl_int rc,
                 const char *fmt, ...) __attribute__((format(printf, 5, 6)));

/* Lists every device of every platform (CL_DEVICE_TYPE_ALL), platforms then devices in
 * the order the ICD loader reports them. No OpenCL at all (no ICD, no platform) is not
 * an error: *out = NULL and *n = 0. A platform without devices contributes none. Other
 * failures are ST_DEVICE naming the platform or device and the call. On success the
 * caller frees *out with free(). */
Status ocl_enumerate(OclDeviceInfo **out, size_t *n, Error *err);

/* How a buffer's bytes are read: which decides whether a CPU device gets it on huge
 * pages. */
typedef enum {
    OCL_READ_IN_ORDER,  /* each work-item its own records (a wave's paths, rays and
                         * queues, a film, the pixel list): a 4 KiB page serves dozens
                         * of neighbouring work-items, so huge pages would only add
                         * their first touch, which on a VM that hands free memory back
                         * to its host costs 11-14 ms per MiB against 0.7 on small pages
                         * (bench/RESULTS.md, "A wave's buffers on small pages") */
    OCL_READ_AT_RANDOM, /* a scene's arrays, which every ray reads at random: on huge
                         * pages the TLB holds them (base/pages.h) */
} OclReads;

/* A buffer of `bytes` bytes, at least OCL_BUFFER_MIN (OpenCL has no empty buffers),
 * for devices of `type`, holding src's bytes when src is given (the rest zero). On a CPU
 * device, which computes in host memory, a buffer read OCL_READ_AT_RANDOM of
 * PAGES_HUGE_BYTES or more is memory clpt allocates on huge pages (base/pages.h) and
 * hands over with CL_MEM_USE_HOST_PTR, freed when OpenCL deletes the buffer; otherwise
 * the driver allocates it, CL_MEM_COPY_HOST_PTR copying src. On failure NULL, with the
 * failed call in *call and its code in *rc. */
#define OCL_BUFFER_MIN 16u
cl_mem ocl_buffer(cl_context ctx, cl_device_type type, cl_mem_flags flags, OclReads reads, size_t bytes,
                  const void *src, const char **call, cl_int *rc);

/* A read-only buffer of a CPU device over the host's own `bytes` at src, used in place
 * (CL_MEM_USE_HOST_PTR; nothing is copied, and nothing freed with the buffer): for an
 * array the host made on huge pages already (pages_on_huge), which a copy would only
 * touch a second time. The array must stay, unchanged, until the buffer is released,
 * as the scalar device's scene does (device.h). On failure NULL, as ocl_buffer. */
cl_mem ocl_buffer_in_place(cl_context ctx, size_t bytes, const void *src, const char **call, cl_int *rc);

#endif /* CLPT_OCL_H */
