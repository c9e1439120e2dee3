#include "device/ocl.h"

#include "base/pages.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- error names */

#define OCL__NAME(code) {code, #code}

/* Codes newer than the OpenCL 1.2 headers we compile against, and extension codes, are
 * written as numbers: a 2.x or 3.0 driver may still return them to a 1.2 program. */
static const struct { cl_int code; const char *name; } ocl__errors[] = {
    OCL__NAME(CL_SUCCESS),
    OCL__NAME(CL_DEVICE_NOT_FOUND),
    OCL__NAME(CL_DEVICE_NOT_AVAILABLE),
    OCL__NAME(CL_COMPILER_NOT_AVAILABLE),
    OCL__NAME(CL_MEM_OBJECT_ALLOCATION_FAILURE),
    OCL__NAME(CL_OUT_OF_RESOURCES),
    OCL__NAME(CL_OUT_OF_HOST_MEMORY),
    OCL__NAME(CL_PROFILING_INFO_NOT_AVAILABLE),
    OCL__NAME(CL_MEM_COPY_OVERLAP),
    OCL__NAME(CL_IMAGE_FORMAT_MISMATCH),
    OCL__NAME(CL_IMAGE_FORMAT_NOT_SUPPORTED),
    OCL__NAME(CL_BUILD_PROGRAM_FAILURE),
    OCL__NAME(CL_MAP_FAILURE),
    OCL__NAME(CL_MISALIGNED_SUB_BUFFER_OFFSET),
    OCL__NAME(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST),
    OCL__NAME(CL_COMPILE_PROGRAM_FAILURE),
    OCL__NAME(CL_LINKER_NOT_AVAILABLE),
    OCL__NAME(CL_LINK_PROGRAM_FAILURE),
    OCL__NAME(CL_DEVICE_PARTITION_FAILED),
    OCL__NAME(CL_KERNEL_ARG_INFO_NOT_AVAILABLE),
    OCL__NAME(CL_INVALID_VALUE),
    OCL__NAME(CL_INVALID_DEVICE_TYPE),
    OCL__NAME(CL_INVALID_PLATFORM),
    OCL__NAME(CL_INVALID_DEVICE),
    OCL__NAME(CL_INVALID_CONTEXT),
    OCL__NAME(CL_INVALID_QUEUE_PROPERTIES),
    OCL__NAME(CL_INVALID_COMMAND_QUEUE),
    OCL__NAME(CL_INVALID_HOST_PTR),
    OCL__NAME(CL_INVALID_MEM_OBJECT),
    OCL__NAME(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR),
    OCL__NAME(CL_INVALID_IMAGE_SIZE),
    OCL__NAME(CL_INVALID_SAMPLER),
    OCL__NAME(CL_INVALID_BINARY),
    OCL__NAME(CL_INVALID_BUILD_OPTIONS),
    OCL__NAME(CL_INVALID_PROGRAM),
    OCL__NAME(CL_INVALID_PROGRAM_EXECUTABLE),
    OCL__NAME(CL_INVALID_KERNEL_NAME),
    OCL__NAME(CL_INVALID_KERNEL_DEFINITION),
    OCL__NAME(CL_INVALID_KERNEL),
    OCL__NAME(CL_INVALID_ARG_INDEX),
    OCL__NAME(CL_INVALID_ARG_VALUE),
    OCL__NAME(CL_INVALID_ARG_SIZE),
    OCL__NAME(CL_INVALID_KERNEL_ARGS),
    OCL__NAME(CL_INVALID_WORK_DIMENSION),
    OCL__NAME(CL_INVALID_WORK_GROUP_SIZE),
    OCL__NAME(CL_INVALID_WORK_ITEM_SIZE),
    OCL__NAME(CL_INVALID_GLOBAL_OFFSET),
    OCL__NAME(CL_INVALID_EVENT_WAIT_LIST),
    OCL__NAME(CL_INVALID_EVENT),
    OCL__NAME(CL_INVALID_OPERATION),
    OCL__NAME(CL_INVALID_GL_OBJECT),
    OCL__NAME(CL_INVALID_BUFFER_SIZE),
    OCL__NAME(CL_INVALID_MIP_LEVEL),
    OCL__NAME(CL_INVALID_GLOBAL_WORK_SIZE),
    OCL__NAME(CL_INVALID_PROPERTY),
    OCL__NAME(CL_INVALID_IMAGE_DESCRIPTOR),
    OCL__NAME(CL_INVALID_COMPILER_OPTIONS),
    OCL__NAME(CL_INVALID_LINKER_OPTIONS),
    OCL__NAME(CL_INVALID_DEVICE_PARTITION_COUNT),
    {-69, "CL_INVALID_PIPE_SIZE"},
    {-70, "CL_INVALID_DEVICE_QUEUE"},
    {-71, "CL_INVALID_SPEC_ID"},
    {-72, "CL_MAX_SIZE_RESTRICTION_EXCEEDED"},
    {-1000, "CL_INVALID_GL_SHAREGROUP_REFERENCE_KHR"},
    {-1001, "CL_PLATFORM_NOT_FOUND_KHR"},
    {-1057, "CL_DEVICE_PARTITION_FAILED_EXT"},
    {-1058, "CL_INVALID_PARTITION_COUNT_EXT"},
    {-1059, "CL_INVALID_PARTITION_NAME_EXT"},
    {-1121, "CL_CONTEXT_TERMINATED_KHR"},
};

const char *ocl_error_name(cl_int code)
{
    for (size_t i = 0; i < sizeof ocl__errors / sizeof ocl__errors[0]; i++)
        if (ocl__errors[i].code == code) return ocl__errors[i].name;
    return "unknown OpenCL error";
}

const char *ocl_device_type_name(cl_device_type type)
{
    if (type & CL_DEVICE_TYPE_GPU) return "GPU";
    if (type & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
    if (type & CL_DEVICE_TYPE_CPU) return "CPU";
    if (type & CL_DEVICE_TYPE_CUSTOM) return "custom";
    return "unknown";
}

/* ---------------------------------------------------------------- failures */

/* Writes the "device 'NAME': CALL failed: CL_NAME" head of a message. */
static void ocl__head(char *buf, size_t cap, const OclDeviceInfo *dev, const char *call,
                      cl_int rc)
{
    const char *name = ocl_error_name(rc);
    /* An unknown code keeps its number, which is then the only clue. */
    char num[48] = "";
    if (strcmp(name, "unknown OpenCL error") == 0) snprintf(num, sizeof num, " %d", (int)rc);
    if (!dev)
        snprintf(buf, cap, "%s failed: %s%s", call, name, num);
    else if (dev->name[0])
        snprintf(buf, cap, "device '%s': %s failed: %s%s", dev->name, call, name, num);
    else
        snprintf(buf, cap, "device #%u.%u: %s failed: %s%s", dev->platform_index,
                 dev->device_index, call, name, num);
}

Status ocl_fail(Error *err, const OclDeviceInfo *dev, const char *call, cl_int rc)
{
    char head[sizeof err->msg];
    ocl__head(head, sizeof head, dev, call, rc);
    return error_set(err, ST_DEVICE, "%s", head);
}

Status ocl_failf(Error *err, const OclDeviceInfo *dev, const char *call, cl_int rc,
                 const char *fmt, ...)
{
    char head[sizeof err->msg], ctx[sizeof err->msg];
    ocl__head(head, sizeof head, dev, call, rc);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ctx, sizeof ctx, fmt, ap);
    va_end(ap);
    return error_set(err, ST_DEVICE, "%s: %s", head, ctx);
}

/* ---------------------------------------------------------------- enumeration */

/* Copies `s` (n bytes, maybe unterminated) into buf without surrounding blanks: some
 * drivers pad device names with spaces, which would spoil messages and device lists. */
static void ocl__copy_trimmed(char *buf, size_t cap, const char *s, size_t n)
{
    while (n && (s[n - 1] == '\0' || s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\n'))
        n--;
    while (n && (*s == ' ' || *s == '\t')) s++, n--;
    if (n >= cap) n = cap - 1;
    memcpy(buf, s, n);
    buf[n] = '\0';
}

/* Reads a string property of a platform or device of any length; a longer one than
 * `cap` is truncated rather than refused (a driver's long version string is no error). */
static cl_int ocl__string(cl_platform_id platform, cl_device_id device, cl_uint what,
                          char *buf, size_t cap)
{
    size_t need = 0;
    cl_int rc = device ? clGetDeviceInfo(device, what, 0, NULL, &need)
                       : clGetPlatformInfo(platform, what, 0, NULL, &need);
    if (rc != CL_SUCCESS) return rc;
    char *tmp = malloc(need + 1);
    if (!tmp) return CL_OUT_OF_HOST_MEMORY;
    rc = device ? clGetDeviceInfo(device, what, need, tmp, NULL)
                : clGetPlatformInfo(platform, what, need, tmp, NULL);
    if (rc == CL_SUCCESS) ocl__copy_trimmed(buf, cap, tmp, need);
    free(tmp);
    return rc;
}

/* Fills everything but the platform fields and indices. */
static Status ocl__describe(OclDeviceInfo *d, Error *err)
{
    const struct { cl_device_info what; const char *label; char *dst; size_t cap; } strs[] = {
        {CL_DEVICE_NAME, "CL_DEVICE_NAME", d->name, sizeof d->name},
        {CL_DEVICE_VENDOR, "CL_DEVICE_VENDOR", d->vendor, sizeof d->vendor},
        {CL_DRIVER_VERSION, "CL_DRIVER_VERSION", d->driver_version, sizeof d->driver_version},
        {CL_DEVICE_VERSION, "CL_DEVICE_VERSION", d->device_version, sizeof d->device_version},
        {CL_DEVICE_OPENCL_C_VERSION, "CL_DEVICE_OPENCL_C_VERSION", d->opencl_c_version,
         sizeof d->opencl_c_version},
    };
    for (size_t i = 0; i < sizeof strs / sizeof strs[0]; i++) {
        cl_int rc = ocl__string(NULL, d->id, strs[i].what, strs[i].dst, strs[i].cap);
        if (rc != CL_SUCCESS) return ocl_failf(err, d, "clGetDeviceInfo", rc, "%s", strs[i].label);
    }

    cl_bool available = CL_FALSE, compiler = CL_FALSE;
    cl_device_fp_config fp = 0;
    const struct { cl_device_info what; const char *label; void *dst; size_t size; } nums[] = {
        {CL_DEVICE_TYPE, "CL_DEVICE_TYPE", &d->type, sizeof d->type},
        {CL_DEVICE_MAX_COMPUTE_UNITS, "CL_DEVICE_MAX_COMPUTE_UNITS", &d->compute_units,
         sizeof d->compute_units},
        {CL_DEVICE_GLOBAL_MEM_SIZE, "CL_DEVICE_GLOBAL_MEM_SIZE", &d->global_mem,
         sizeof d->global_mem},
        {CL_DEVICE_MAX_MEM_ALLOC_SIZE, "CL_DEVICE_MAX_MEM_ALLOC_SIZE", &d->max_alloc,
         sizeof d->max_alloc},
        {CL_DEVICE_LOCAL_MEM_SIZE, "CL_DEVICE_LOCAL_MEM_SIZE", &d->local_mem,
         sizeof d->local_mem},
        {CL_DEVICE_MAX_WORK_GROUP_SIZE, "CL_DEVICE_MAX_WORK_GROUP_SIZE", &d->max_work_group,
         sizeof d->max_work_group},
        {CL_DEVICE_SINGLE_FP_CONFIG, "CL_DEVICE_SINGLE_FP_CONFIG", &fp, sizeof fp},
        {CL_DEVICE_AVAILABLE, "CL_DEVICE_AVAILABLE", &available, sizeof available},
        {CL_DEVICE_COMPILER_AVAILABLE, "CL_DEVICE_COMPILER_AVAILABLE", &compiler,
         sizeof compiler},
    };
    for (size_t i = 0; i < sizeof nums / sizeof nums[0]; i++) {
        cl_int rc = clGetDeviceInfo(d->id, nums[i].what, nums[i].size, nums[i].dst, NULL);
        if (rc != CL_SUCCESS) return ocl_failf(err, d, "clGetDeviceInfo", rc, "%s", nums[i].label);
    }
    d->correctly_rounded_divide_sqrt = (fp & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT) != 0;
    d->available = available == CL_TRUE;
    d->compiler_available = compiler == CL_TRUE;
    return ST_OK;
}

Status ocl_enumerate(OclDeviceInfo **out, size_t *n, Error *err)
{
    *out = NULL;
    *n = 0;
    cl_uint n_platforms = 0;
    /* PoCL compiles a work-group function per kernel when clpt reads the program binary
     * back for its cache, and by default compiles a second one, specialised for the
     * launch's sizes, at each kernel's first launch: 1.2 s of a 3.3 s cold start on the
     * Cornell box, for no measurable speed (Cornell box and dragon, interleaved:
     * 2.36 and 2.58 Msamples/s without, 2.36 and 2.51 with; bench/RESULTS.md). The
     * kernels declare the one work-group size the renderer launches them with
     * (CLPT_LOCAL_SIZE in entry.cl), so the function in the binary fits every launch.
     * Read by PoCL when it starts, i.e. before the first call below; a value the user
     * set is kept. */
    setenv("POCL_WORK_GROUP_SPECIALIZATION", "0", 0);
    cl_int rc = clGetPlatformIDs(0, NULL, &n_platforms);
    /* -1001 is CL_PLATFORM_NOT_FOUND_KHR: the ICD loader found no driver at all. */
    if (rc == -1001 || (rc == CL_SUCCESS && n_platforms == 0)) return ST_OK;
    if (rc != CL_SUCCESS) return ocl_fail(err, NULL, "clGetPlatformIDs", rc);

    Status st = ST_OK;
    OclDeviceInfo *list = NULL;
    size_t count = 0;
    cl_device_id *ids = NULL;
    cl_platform_id *platforms = calloc(n_platforms, sizeof *platforms);
    if (!platforms) return error_set(err, ST_INTERNAL, "out of memory listing OpenCL platforms");
    rc = clGetPlatformIDs(n_platforms, platforms, NULL);
    if (rc != CL_SUCCESS) {
        st = ocl_fail(err, NULL, "clGetPlatformIDs", rc);
        goto cleanup;
    }

    for (cl_uint p = 0; p < n_platforms; p++) {
        char pname[256], pversion[256];
        rc = ocl__string(platforms[p], NULL, CL_PLATFORM_NAME, pname, sizeof pname);
        if (rc != CL_SUCCESS) {
            st = ocl_failf(err, NULL, "clGetPlatformInfo", rc, "CL_PLATFORM_NAME of platform #%u",
                           p);
            goto cleanup;
        }
        rc = ocl__string(platforms[p], NULL, CL_PLATFORM_VERSION, pversion, sizeof pversion);
        if (rc != CL_SUCCESS) {
            st = error_set(err, ST_DEVICE, "platform '%s': clGetPlatformInfo failed: %s: "
                           "CL_PLATFORM_VERSION", pname, ocl_error_name(rc));
            goto cleanup;
        }

        cl_uint n_devices = 0;
        rc = clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, 0, NULL, &n_devices);
        if (rc == CL_DEVICE_NOT_FOUND || (rc == CL_SUCCESS && n_devices == 0)) continue;
        if (rc != CL_SUCCESS) {
            st = error_set(err, ST_DEVICE, "platform '%s': clGetDeviceIDs failed: %s", pname,
                           ocl_error_name(rc));
            goto cleanup;
        }
        free(ids);
        ids = calloc(n_devices, sizeof *ids);
        OclDeviceInfo *grown = realloc(list, (count + n_devices) * sizeof *list);
        if (!ids || !grown) {
            if (grown) list = grown;
            st = error_set(err, ST_INTERNAL, "out of memory listing OpenCL devices");
            goto cleanup;
        }
        list = grown;
        rc = clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, n_devices, ids, NULL);
        if (rc != CL_SUCCESS) {
            st = error_set(err, ST_DEVICE, "platform '%s': clGetDeviceIDs failed: %s", pname,
                           ocl_error_name(rc));
            goto cleanup;
        }
        for (cl_uint i = 0; i < n_devices; i++) {
            OclDeviceInfo *d = &list[count];
            memset(d, 0, sizeof *d);
            d->platform = platforms[p];
            d->id = ids[i];
            d->platform_index = p;
            d->device_index = i;
            snprintf(d->platform_name, sizeof d->platform_name, "%s", pname);
            snprintf(d->platform_version, sizeof d->platform_version, "%s", pversion);
            st = ocl__describe(d, err);
            if (st != ST_OK) {
                error_prefix(err, "platform '%s'", pname);
                goto cleanup;
            }
            count++;
        }
    }

cleanup:
    free(ids);
    free(platforms);
    if (st != ST_OK) {
        free(list);
        return st;
    }
    *out = list;
    *n = count;
    return ST_OK;
}

/* The memory of a buffer made with CL_MEM_USE_HOST_PTR, freed once OpenCL has deleted
 * the buffer (which may be after clReleaseMemObject returns). */
static void CL_CALLBACK free_host_memory(cl_mem mem, void *host)
{
    (void)mem;
    free(host);
}

cl_mem ocl_buffer_in_place(cl_context ctx, size_t bytes, const void *src, const char **call, cl_int *rc)
{
    *call = "clCreateBuffer";
    /* CL_MEM_READ_ONLY: the kernels never write it, and the host never writes or maps
     * it, so the const of src holds */
    return clCreateBuffer(ctx, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, bytes, (void *)(uintptr_t)src, rc);
}

cl_mem ocl_buffer(cl_context ctx, cl_device_type type, cl_mem_flags flags, OclReads reads, size_t bytes,
                  const void *src, const char **call, cl_int *rc)
{
    size_t size = bytes < OCL_BUFFER_MIN ? OCL_BUFFER_MIN : bytes;
    /* CL_MEM_COPY_HOST_PTR copies `size` bytes: a source shorter than the minimum (a
     * leaf list of one index) goes through a zero-padded copy, not read past its end */
    unsigned char padded[OCL_BUFFER_MIN] = { 0 };
    if (src && bytes < size) {
        memcpy(padded, src, bytes);
        src = padded;
    }
    void *host = NULL;
    if ((type & CL_DEVICE_TYPE_CPU) && reads == OCL_READ_AT_RANDOM && size >= PAGES_HUGE_BYTES &&
        (host = pages_alloc_huge(size))) {
        if (src) memcpy(host, src, size);
        flags |= CL_MEM_USE_HOST_PTR;
    } else if (src) {
        flags |= CL_MEM_COPY_HOST_PTR;
        host = (void *)(uintptr_t)src;
    }
    *call = "clCreateBuffer";
    cl_mem m = clCreateBuffer(ctx, flags, size, host, rc);
    if (*rc == CL_SUCCESS && (flags & CL_MEM_USE_HOST_PTR)) {
        *call = "clSetMemObjectDestructorCallback";
        *rc = clSetMemObjectDestructorCallback(m, free_host_memory, host);
        if (*rc != CL_SUCCESS) clReleaseMemObject(m);
    }
    if (*rc == CL_SUCCESS) return m;
    if (flags & CL_MEM_USE_HOST_PTR) free(host);
    return NULL;
}
