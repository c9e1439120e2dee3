/*
 * test_ocl.c — OpenCL host basics: error names, device discovery, building the program,
 * the on-disk binary cache and build failures.
 *
 * Runs against PoCL, which `make test` installs. Before the first OpenCL call main()
 * points CLPT_CACHE_DIR and POCL_CACHE_DIR at fresh temporary folders, so the first
 * build is truly cold and the timings it prints are honest; everything is removed at
 * the end. Two helper modes re-execute this program with POCL_DEVICES or
 * OCL_ICD_VENDORS set, because those are read once, when the ICD loader first loads.
 */
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "harness.h"
#include "layout.h"
#include "device/ocl.h"
#include "device/ocl_args.h"
#include "device/ocl_program.h"
#include "base/sha256.h"
#include "types.h"

static char tmp_root[256];    /* everything this test writes lives below it */
static char cache_dir[300];   /* CLPT_CACHE_DIR for the in-process tests */
/* The options of the program the cache tests build (set first in main, for the child
 * runs too): the wave kernels and the Whitted integrator's, which k_layout (run_layout)
 * needs both of, and no other feature. What the cache does is the same for any program,
 * and the whole program (every feature, which test_kernels builds and runs) cost PoCL
 * half a minute or more per cold build, five of them here. */
static char cache_test_options[64];
static OclDeviceInfo *devices;
static size_t n_devices;
static cl_context ctx;
static const OclDeviceInfo *dev; /* the first device; every build test uses it */

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    int ok = fputs(text, f) >= 0;
    return (fclose(f) == 0 && ok) ? 0 : -1;
}

static long file_size(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 ? (long)sb.st_size : -1;
}

static int remove_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
    (void)sb; (void)flag; (void)ftw;
    return remove(path);
}

static void remove_tree(const char *path)
{
    nftw(path, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

/* Runs k_layout of `prog` on dev and reads back its values; 0 on success. */
static int run_layout(cl_program prog, cl_uint values[LAYOUT_VALUES])
{
    Error err = {0};
    cl_kernel k = NULL;
    cl_mem buf = NULL;
    cl_command_queue q = NULL;
    int result = -1;
    cl_int rc;
    if (ocl_program_kernel(prog, dev, "k_layout", &k, &err) != ST_OK) goto cleanup;
    q = clCreateCommandQueue(ctx, dev->id, 0, &rc);
    if (rc != CL_SUCCESS) goto cleanup;
    buf = clCreateBuffer(ctx, CL_MEM_WRITE_ONLY, LAYOUT_VALUES * sizeof(cl_uint), NULL, &rc);
    if (rc != CL_SUCCESS) goto cleanup;
    size_t global = 1;
    if (clSetKernelArg(k, 0, sizeof buf, &buf) != CL_SUCCESS ||
        clEnqueueNDRangeKernel(q, k, 1, NULL, &global, NULL, 0, NULL, NULL) != CL_SUCCESS ||
        clEnqueueReadBuffer(q, buf, CL_TRUE, 0, LAYOUT_VALUES * sizeof(cl_uint), values, 0,
                            NULL, NULL) != CL_SUCCESS)
        goto cleanup;
    result = 0;
cleanup:
    if (buf) clReleaseMemObject(buf);
    if (q) clReleaseCommandQueue(q);
    if (k) clReleaseKernel(k);
    error_clear(&err);
    return result;
}

/* ---------------------------------------------------------------- helper modes */

/* Child mode: lists the PoCL devices, builds for each through one two-device context
 * (so CL_PROGRAM_BINARIES spans two devices) and prints what happened. */
static int child_two_devices(void)
{
    OclDeviceInfo *list = NULL;
    size_t n = 0;
    Error err = {0};
    if (ocl_enumerate(&list, &n, &err) != ST_OK) {
        printf("error %s\n", err.msg);
        return 1;
    }
    cl_device_id ids[2];
    size_t pocl = 0;
    for (size_t i = 0; i < n; i++)
        if (strstr(list[i].platform_name, "Portable Computing Language")) {
            if (pocl < 2) ids[pocl] = list[i].id;
            pocl++;
        }
    printf("pocl_devices %zu\n", pocl);
    for (size_t i = 0; i < n && i < 2; i++)
        printf("index %u.%u\n", list[i].platform_index, list[i].device_index);
    if (pocl == 2 && list[0].id == ids[0] && list[1].id == ids[1]) {
        cl_int rc;
        cl_context c = clCreateContext(NULL, 2, ids, NULL, NULL, &rc);
        for (int d = 0; rc == CL_SUCCESS && d < 2; d++) {
            cl_program prog = NULL;
            OclProgramStats stats;
            Status st = ocl_program_build(c, &list[d], NULL, cache_test_options, &prog, &stats, &err);
            printf("build %d status %d from_cache %d\n", d, (int)st, stats.from_cache);
            if (prog) clReleaseProgram(prog);
        }
        if (rc == CL_SUCCESS) clReleaseContext(c);
    }
    free(list);
    return 0;
}

/* Child mode: builds the embedded program for the first device, as a run of clpt does,
 * and prints what happened. */
static int child_build(int variant, int show_path)
{
    OclDeviceInfo *list = NULL;
    size_t n = 0;
    Error err = {0};
    if (ocl_enumerate(&list, &n, &err) != ST_OK || n == 0) {
        printf("no device %s\n", err.msg);
        free(list);
        return 1;
    }
    cl_int rc;
    cl_context c = clCreateContext(NULL, 1, &list[0].id, NULL, NULL, &rc);
    Status st = ST_DEVICE;
    OclProgramStats stats;
    memset(&stats, 0, sizeof stats);
    if (rc == CL_SUCCESS) {
        cl_program prog = NULL;
        char options[96];
        snprintf(options, sizeof options, "%s%s", cache_test_options, variant ? " -DCLPT_TEST_VARIANT=1" : "");
        st = ocl_program_build(c, &list[0], NULL, options, &prog, &stats, &err);
        if (prog) clReleaseProgram(prog);
        clReleaseContext(c);
    }
    printf("build status %d from_cache %d%s\n", (int)st, stats.from_cache,
           !show_path ? "" : stats.cache_path[0] ? " cache_path 1" : " cache_path 0");
    free(list);
    error_clear(&err);
    return st == ST_OK ? 0 : 1;
}

/* Child mode: prints what enumeration returns. */
static int child_enumerate(void)
{
    OclDeviceInfo *list = NULL;
    size_t n = 0;
    Error err = {0};
    Status st = ocl_enumerate(&list, &n, &err);
    printf("status %d devices %zu\n", (int)st, n);
    free(list);
    return 0;
}

/* ---------------------------------------------------------------- tests */

static void test_error_names(void)
{
    CHECK(strcmp(ocl_error_name(CL_SUCCESS), "CL_SUCCESS") == 0);
    CHECK(strcmp(ocl_error_name(-5), "CL_OUT_OF_RESOURCES") == 0);
    CHECK(strcmp(ocl_error_name(CL_BUILD_PROGRAM_FAILURE), "CL_BUILD_PROGRAM_FAILURE") == 0);
    CHECK(strcmp(ocl_error_name(CL_INVALID_KERNEL_NAME), "CL_INVALID_KERNEL_NAME") == 0);
    CHECK(strcmp(ocl_error_name(-68), "CL_INVALID_DEVICE_PARTITION_COUNT") == 0);
    CHECK(strcmp(ocl_error_name(-69), "CL_INVALID_PIPE_SIZE") == 0);
    CHECK(strcmp(ocl_error_name(-1001), "CL_PLATFORM_NOT_FOUND_KHR") == 0);
    CHECK(strcmp(ocl_error_name(-9999), "unknown OpenCL error") == 0);
    CHECK(strcmp(ocl_error_name(7), "unknown OpenCL error") == 0);
    /* Every code the 1.2 headers define has a name. */
    for (cl_int c = -1; c >= -68; c--) {
        if (c == -20) c = -30;
        CHECK_MSG(strncmp(ocl_error_name(c), "CL_", 3) == 0, "code %d", (int)c);
    }

    CHECK(strcmp(ocl_device_type_name(CL_DEVICE_TYPE_GPU), "GPU") == 0);
    CHECK(strcmp(ocl_device_type_name(CL_DEVICE_TYPE_CPU | CL_DEVICE_TYPE_DEFAULT), "CPU") == 0);
    CHECK(strcmp(ocl_device_type_name(CL_DEVICE_TYPE_ACCELERATOR), "accelerator") == 0);

    OclDeviceInfo d;
    memset(&d, 0, sizeof d);
    snprintf(d.name, sizeof d.name, "Some GPU");
    Error err = {0};
    CHECK_EQ_INT(ocl_fail(&err, &d, "clFinish", CL_OUT_OF_RESOURCES), ST_DEVICE);
    CHECK(strcmp(err.msg, "device 'Some GPU': clFinish failed: CL_OUT_OF_RESOURCES") == 0);
    CHECK_EQ_INT(err.status, ST_DEVICE);
    ocl_failf(&err, &d, "clCreateBuffer", -4, "%d bytes", 64);
    CHECK(strcmp(err.msg, "device 'Some GPU': clCreateBuffer failed: "
                          "CL_MEM_OBJECT_ALLOCATION_FAILURE: 64 bytes") == 0);
    ocl_fail(&err, NULL, "clGetPlatformIDs", -9999);
    CHECK(strcmp(err.msg, "clGetPlatformIDs failed: unknown OpenCL error -9999") == 0);
    d.name[0] = '\0';
    d.platform_index = 1;
    d.device_index = 2;
    ocl_fail(&err, &d, "clGetDeviceInfo", CL_INVALID_VALUE);
    CHECK(strcmp(err.msg, "device #1.2: clGetDeviceInfo failed: CL_INVALID_VALUE") == 0);
}

static void test_sha256(void)
{
    char hex[65];
    unsigned char d[SHA256_DIGEST_SIZE];
    sha256("", 0, d);
    sha256_hex(d, hex);
    CHECK(strcmp(hex, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855") == 0);
    sha256("abc", 3, d);
    sha256_hex(d, hex);
    CHECK(strcmp(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad") == 0);
    const char *two = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
    sha256(two, strlen(two), d);
    sha256_hex(d, hex);
    CHECK(strcmp(hex, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1") == 0);

    /* One million 'a', fed in uneven pieces so that every partial-block path runs. */
    static char a[1000000];
    memset(a, 'a', sizeof a);
    Sha256 h;
    sha256_init(&h);
    size_t off = 0, step = 1;
    while (off < sizeof a) {
        size_t take = step < sizeof a - off ? step : sizeof a - off;
        sha256_update(&h, a + off, take);
        off += take;
        step = step * 7 % 131 + 1;
    }
    sha256_final(&h, d);
    sha256_hex(d, hex);
    CHECK(strcmp(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0") == 0);
}

static void test_enumerate(void)
{
    CHECK_MSG(n_devices >= 1, "no OpenCL device found (PoCL should be installed)");
    for (size_t i = 0; i < n_devices; i++) {
        const OclDeviceInfo *d = &devices[i];
        fprintf(stderr, "  device %u.%u: '%s' (%s, %s) on '%s' [%s], driver %s, %s, %u CUs, "
                "%llu MiB, correctly rounded div/sqrt %d\n", d->platform_index,
                d->device_index, d->name, ocl_device_type_name(d->type), d->vendor,
                d->platform_name, d->platform_version, d->driver_version, d->opencl_c_version,
                d->compute_units, (unsigned long long)(d->global_mem >> 20),
                d->correctly_rounded_divide_sqrt);
        CHECK(d->id != NULL && d->platform != NULL);
        CHECK(d->name[0] && d->vendor[0] && d->platform_name[0] && d->driver_version[0]);
        CHECK(strncmp(d->platform_version, "OpenCL ", 7) == 0);
        CHECK(strncmp(d->device_version, "OpenCL ", 7) == 0);
        CHECK(strncmp(d->opencl_c_version, "OpenCL C ", 9) == 0);
        CHECK(d->name[strlen(d->name) - 1] != ' ');
        CHECK(d->compute_units >= 1);
        CHECK(d->global_mem > 0 && d->max_alloc > 0 && d->max_alloc <= d->global_mem);
        CHECK(d->local_mem > 0 && d->max_work_group >= 1);
        CHECK(d->available && d->compiler_available);
        if (i > 0) {
            const OclDeviceInfo *p = &devices[i - 1];
            CHECK(d->platform_index > p->platform_index ||
                  (d->platform_index == p->platform_index &&
                   d->device_index == p->device_index + 1));
        }
    }
}

static void test_context(void)
{
    CHECK_MSG(ctx != NULL, "no OpenCL context for the first device: no build test can run");
}

/* Runs this program in `mode` with env_name=env_value (plus the caches given) and
 * returns its exit status, its stdout in out. */
static int run_child(const char *mode, const char *env_name, const char *env_value,
                     const char *clpt_cache, const char *pocl_cache, char *out, size_t cap)
{
    int fds[2];
    out[0] = '\0';
    if (pipe(fds) != 0) return -1;
    pid_t pid = fork();
    if (pid == 0) {
        dup2(fds[1], 1);
        close(fds[0]);
        close(fds[1]);
        setenv(env_name, env_value, 1);
        setenv("CLPT_CACHE_DIR", clpt_cache, 1);
        setenv("POCL_CACHE_DIR", pocl_cache, 1);
        execl("/proc/self/exe", "test_ocl", mode, (char *)NULL);
        _exit(127);
    }
    close(fds[1]);
    size_t n = 0;
    ssize_t got;
    while (n < cap - 1 && (got = read(fds[0], out + n, cap - 1 - n)) > 0) n += (size_t)got;
    out[n] = '\0';
    close(fds[0]);
    int wstatus = 0;
    if (pid < 0 || waitpid(pid, &wstatus, 0) != pid) return -1;
    return WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
}

/* POCL_DEVICES="pthread pthread" makes PoCL offer two devices, and a program built for
 * the first is loaded from the cache for the second (same name, driver and options: the
 * same key). Each child gets its own PoCL cache, so the parent's stays cold. */
static void test_two_devices(void)
{
    char two_cache[400], two_pocl[400], out[2048];
    snprintf(two_cache, sizeof two_cache, "%s/two", tmp_root);
    snprintf(two_pocl, sizeof two_pocl, "%s/two-pocl", tmp_root);
    CHECK_EQ_INT(run_child("--two-devices", "POCL_DEVICES", "pthread pthread", two_cache,
                           two_pocl, out, sizeof out), 0);
    CHECK_STR_CONTAINS(out, "pocl_devices 2\n");
    CHECK_STR_CONTAINS(out, "index 0.0\nindex 0.1\n");
    CHECK_STR_CONTAINS(out, "build 0 status 0 from_cache 0\n");
    CHECK_STR_CONTAINS(out, "build 1 status 0 from_cache 1\n");
    CHECK_EQ_INT(count_dir_entries(two_cache, ".bin"), 1);
    CHECK_EQ_INT(count_dir_entries(two_cache, ".bin.ok"), 1);   /* proven by build 1's trial */
    CHECK_EQ_INT(count_dir_entries(two_cache, ""), 2);
}

/* With no OpenCL driver at all (the ICD loader pointed at an empty vendor folder)
 * enumeration succeeds with no devices. */
static void test_no_platform(void)
{
    char empty[400], out[256];
    snprintf(empty, sizeof empty, "%s/no-icd", tmp_root);
    CHECK(mkdir(empty, 0755) == 0);
    CHECK_EQ_INT(run_child("--enumerate", "OCL_ICD_VENDORS", empty, empty, empty, out,
                           sizeof out), 0);
    CHECK(strcmp(out, "status 0 devices 0\n") == 0);
}

static void test_build_and_cache(void)
{
    Error err = {0};
    cl_program cold = NULL, warm = NULL;
    OclProgramStats s1, s2;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &cold, &s1, &err), ST_OK);
    CHECK_MSG(cold != NULL, "%s", err.msg);
    if (!cold) return;
    CHECK_EQ_INT(s1.from_cache, 0);
    CHECK_STR_CONTAINS(s1.options, "-cl-std=CL1.2");
    CHECK(strstr(s1.options, "fast-relaxed") == NULL && strstr(s1.options, "mad-enable") == NULL);
    CHECK_EQ_INT(strstr(s1.options, "-cl-fp32-correctly-rounded-divide-sqrt") != NULL,
                 dev->correctly_rounded_divide_sqrt);
    CHECK(strncmp(s1.cache_path, cache_dir, strlen(cache_dir)) == 0);
    CHECK(file_size(s1.cache_path) > 88);
    CHECK_EQ_INT(count_dir_entries(cache_dir, ""), 1); /* no temporary file left behind */

    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &warm, &s2, &err), ST_OK);
    CHECK(warm != NULL);
    CHECK_EQ_INT(s2.from_cache, 1);
    CHECK(strcmp(s1.cache_path, s2.cache_path) == 0);
    CHECK(strcmp(s1.options, s2.options) == 0);
    CHECK_MSG(s2.seconds < s1.seconds, "cache load %.3f s, cold build %.3f s", s2.seconds,
              s1.seconds);
    fprintf(stderr, "  embedded source (%zu bytes), %s: cold build %.3f s, cache load %.3f s, "
            "cache entry %ld bytes\n", clpt_kernel_source_len, cache_test_options, s1.seconds, s2.seconds,
            file_size(s1.cache_path));

    /* The cached binary must run and agree with the freshly built one and the host. */
    cl_uint a[LAYOUT_VALUES], b[LAYOUT_VALUES];
    CHECK(run_layout(cold, a) == 0);
    if (warm) CHECK(run_layout(warm, b) == 0);
    CHECK(memcmp(a, b, sizeof a) == 0);
    CHECK_EQ_INT(a[1], sizeof(Ray));
    CHECK_EQ_INT(a[12], sizeof(RenderParams));

    /* Other options are another entry. */
    cl_program other = NULL;
    OclProgramStats s3;
    char variant[96];
    snprintf(variant, sizeof variant, "%s -DCLPT_TEST_VARIANT=1", cache_test_options);
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, variant, &other, &s3, &err), ST_OK);
    CHECK_EQ_INT(s3.from_cache, 0);
    CHECK_STR_CONTAINS(s3.options, " -DCLPT_TEST_VARIANT=1");
    CHECK(strcmp(s3.cache_path, s1.cache_path) != 0);
    CHECK_EQ_INT(count_dir_entries(cache_dir, ".bin"), 2);
    CHECK_EQ_INT(count_dir_entries(cache_dir, ""), 2 + count_dir_entries(cache_dir, ".bin.ok"));

    if (other) clReleaseProgram(other);
    if (warm) clReleaseProgram(warm);
    clReleaseProgram(cold);
    error_clear(&err);
}

/* Reads a whole file into a heap buffer (NULL if it cannot). */
static unsigned char *slurp(const char *path, long *size)
{
    *size = file_size(path);
    FILE *f = fopen(path, "rb");
    unsigned char *buf = *size >= 0 ? malloc((size_t)*size + 1) : NULL;
    if (!f || !buf || fread(buf, 1, (size_t)*size, f) != (size_t)*size) {
        free(buf);
        buf = NULL;
    }
    if (f) fclose(f);
    return buf;
}

/* Damages the cache entry with `damage`, then expects a rebuild from source, a new
 * entry in its place, and a cache hit on the build after. (The new entry need not equal
 * the first: PoCL's binary also carries the kernels it has compiled meanwhile.) */
static void expect_recovery(const char *what, void (*damage)(const char *path))
{
    Error err = {0};
    cl_program prog = NULL;
    OclProgramStats s;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
    if (prog) clReleaseProgram(prog);
    damage(s.cache_path);
    long bad_size, new_size;
    unsigned char *bad = slurp(s.cache_path, &bad_size);

    prog = NULL;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
    CHECK_MSG(s.from_cache == 0, "%s: damaged entry was used", what);
    unsigned char *fresh = slurp(s.cache_path, &new_size);
    CHECK_MSG(bad && fresh && (bad_size != new_size || memcmp(bad, fresh, (size_t)bad_size)),
              "%s: entry not replaced", what);
    free(bad);
    free(fresh);
    cl_uint v[LAYOUT_VALUES];
    CHECK(prog && run_layout(prog, v) == 0);
    if (prog) clReleaseProgram(prog);

    prog = NULL;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
    CHECK_MSG(s.from_cache == 1, "%s: replaced entry not used", what);
    CHECK(prog && run_layout(prog, v) == 0);
    if (prog) clReleaseProgram(prog);
    CHECK_EQ_INT(count_dir_entries(cache_dir, ".bin"), 2);
    CHECK_EQ_INT(count_dir_entries(cache_dir, ""), 2 + count_dir_entries(cache_dir, ".bin.ok"));
    error_clear(&err);
}

static void flip_payload_byte(const char *path)
{
    int fd = open(path, O_RDWR);
    unsigned char c;
    off_t at = 88 + 100;
    if (fd < 0 || pread(fd, &c, 1, at) != 1) return;
    c ^= 0x10;
    if (pwrite(fd, &c, 1, at) != 1) fprintf(stderr, "  cannot damage %s\n", path);
    close(fd);
}

static void truncate_half(const char *path)
{
    if (truncate(path, file_size(path) / 2) != 0) fprintf(stderr, "  cannot truncate\n");
}

/* A whole, correctly checksummed entry whose payload the driver must refuse. */
static void replace_payload_with_garbage(const char *path)
{
    long size = file_size(path);
    unsigned char *buf = malloc((size_t)size);
    FILE *f = fopen(path, "rb");
    if (!buf || !f || fread(buf, 1, (size_t)size, f) != (size_t)size) {
        if (f) fclose(f);
        free(buf);
        return;
    }
    fclose(f);
    for (long i = 88; i < size; i++) buf[i] = (unsigned char)(i * 131 + 7);
    sha256(buf + 88, (size_t)(size - 88), buf + 56);
    f = fopen(path, "wb");
    if (f) {
        fwrite(buf, 1, (size_t)size, f);
        fclose(f);
    }
    free(buf);
}

static void test_corrupt_cache(void)
{
    expect_recovery("flipped byte", flip_payload_byte);
    expect_recovery("truncated", truncate_half);
    expect_recovery("valid checksum, garbage binary", replace_payload_with_garbage);
}

/* Damages 64 payload bytes a third of the way in and gives the entry the checksum of
 * its new payload: a whole entry that PoCL accepts and then aborts on (an assertion
 * in pocl_llvm_read_program_llvm_irs), leaving what it read in its own cache. */
static void damage_with_valid_checksum(const char *path)
{
    long size = 0;
    unsigned char *buf = slurp(path, &size);
    if (!buf || size < 88 + 3 * 64) {
        free(buf);
        return;
    }
    long from = 88 + (size - 88) / 3;
    for (long i = from; i < from + 64; i++) buf[i] ^= 0xffu;
    sha256(buf + 88, (size_t)(size - 88), buf + 56);
    FILE *f = fopen(path, "wb");
    if (f) {
        fwrite(buf, 1, (size_t)size, f);
        fclose(f);
    }
    free(buf);
}

/* An entry with a valid checksum and a payload the driver crashes on (in child runs
 * with a cold PoCL cache, as after clearing ~/.cache/pocl): the driver crashes in the
 * trial process, and the run that meets the entry builds afresh past what PoCL kept of
 * it and stores a good entry, which the runs after load. Before, the first run died
 * (SIGSEGV, no message), and before that every later run too. */
static void test_crashing_cache_entry(void)
{
    Error err = {0};
    cl_program prog = NULL;
    OclProgramStats s;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
    if (prog) clReleaseProgram(prog);
    char dir[400], pocl[400], entry[600], out[512];
    snprintf(dir, sizeof dir, "%s/crash-cache", tmp_root);
    snprintf(pocl, sizeof pocl, "%s/crash-pocl", tmp_root);
    CHECK(mkdir(dir, 0755) == 0);
    const char *name = strrchr(s.cache_path, '/');
    snprintf(entry, sizeof entry, "%s%s", dir, name ? name : "/missing");
    long size = 0;
    unsigned char *good = slurp(s.cache_path, &size);
    FILE *f = good ? fopen(entry, "wb") : NULL;
    CHECK(f != NULL);
    if (!f) {
        free(good);
        return;
    }
    fwrite(good, 1, (size_t)size, f);
    fclose(f);
    free(good);
    damage_with_valid_checksum(entry);

    int first = run_child("--build", "CLPT_TEST_UNUSED", "1", dir, pocl, out, sizeof out);
    fprintf(stderr, "  run meeting the damaged entry: exit %d, %s", first, out[0] ? out : "(no output)\n");
    /* the driver crashes in the trial process, not in the run: it builds from source */
    CHECK_EQ_INT(first, 0);
    CHECK_STR_CONTAINS(out, "build status 0 from_cache 0\n");
    CHECK_EQ_INT(run_child("--build", "CLPT_TEST_UNUSED", "1", dir, pocl, out, sizeof out), 0);
    CHECK_STR_CONTAINS(out, "build status 0 from_cache 1\n");
    CHECK_EQ_INT(run_child("--build", "CLPT_TEST_UNUSED", "1", dir, pocl, out, sizeof out), 0);
    CHECK_STR_CONTAINS(out, "build status 0 from_cache 1\n");
    error_clear(&err);
}

/* Runs that start together, as MPI's ranks or a farm's tasks over one shared cache do,
 * all load the entry (proven by a trial before): none finds the entry gone while another
 * reads it. Before, a run moved the entry aside while its driver read it, and about half
 * of six runs started at once compiled from source. */
static void test_runs_together(void)
{
    char dir[400], pocl[400];
    snprintf(dir, sizeof dir, "%s/together", tmp_root);
    snprintf(pocl, sizeof pocl, "%s/together-pocl", tmp_root);
    char out[512];
    /* the entry, then a run that proves it in its trial */
    CHECK_EQ_INT(run_child("--build", "CLPT_TEST_UNUSED", "1", dir, pocl, out, sizeof out), 0);
    CHECK_STR_CONTAINS(out, "from_cache 0\n");
    CHECK_EQ_INT(run_child("--build", "CLPT_TEST_UNUSED", "1", dir, pocl, out, sizeof out), 0);
    CHECK_STR_CONTAINS(out, "from_cache 1\n");
    enum { RUNS = 8 };
    int fds[RUNS][2];
    pid_t pids[RUNS];
    for (int i = 0; i < RUNS; i++) {
        pids[i] = -1;
        if (pipe(fds[i]) != 0) continue;
        pids[i] = fork();
        if (pids[i] == 0) {
            dup2(fds[i][1], 1);
            close(fds[i][0]);
            close(fds[i][1]);
            setenv("CLPT_CACHE_DIR", dir, 1);
            setenv("POCL_CACHE_DIR", pocl, 1);
            execl("/proc/self/exe", "test_ocl", "--build", (char *)NULL);
            _exit(127);
        }
        close(fds[i][1]);
    }
    int loaded = 0;
    for (int i = 0; i < RUNS; i++) {
        CHECK(pids[i] > 0);
        if (pids[i] <= 0) continue;
        size_t n = 0;
        ssize_t got;
        while (n < sizeof out - 1 && (got = read(fds[i][0], out + n, sizeof out - 1 - n)) > 0) n += (size_t)got;
        out[n] = '\0';
        close(fds[i][0]);
        int wstatus = 0;
        CHECK(waitpid(pids[i], &wstatus, 0) == pids[i] && WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0);
        loaded += strstr(out, "build status 0 from_cache 1\n") != NULL;
    }
    CHECK_MSG(loaded == RUNS, "%d of %d runs started together loaded the entry", loaded, RUNS);
    CHECK_EQ_INT(count_dir_entries(dir, ".trying"), 0);   /* every mark taken away */
}

/* The mark of a run that died while its driver read the entry (a process of this
 * machine that is gone): the next run does not load the entry but builds afresh,
 * compiling past the driver's own cache (the .crashed mark), and stores an entry that
 * the run after loads. A mark of another machine, whose processes this one cannot ask
 * after, is left alone and the entry loaded. */
static void test_died_reading_entry(void)
{
    Error err = {0};
    cl_program prog = NULL;
    OclProgramStats s;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
    if (prog) clReleaseProgram(prog);
    char host[256], mark[1400], crashed[1100];
    CHECK(gethostname(host, sizeof host) == 0);
    host[sizeof host - 1] = '\0';

    /* another machine's mark, of a process number nothing here runs under */
    snprintf(mark, sizeof mark, "%s.%s-elsewhere.999999999.trying", s.cache_path, host);
    CHECK(write_text(mark, "") == 0);
    prog = NULL;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
    CHECK_MSG(s.from_cache == 1, "another machine's mark made the run build");
    CHECK(access(mark, F_OK) == 0);
    unlink(mark);
    if (prog) clReleaseProgram(prog);

    /* this machine's mark of a process that is gone */
    pid_t gone = fork();
    if (gone == 0) _exit(0);
    CHECK(gone > 0 && waitpid(gone, NULL, 0) == gone);
    snprintf(mark, sizeof mark, "%s.%s.%ld.trying", s.cache_path, host, (long)gone);
    snprintf(crashed, sizeof crashed, "%s.crashed", s.cache_path);
    unlink(crashed);
    CHECK(write_text(mark, "") == 0);
    prog = NULL;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
    CHECK_MSG(s.from_cache == 0, "an entry a run died reading was loaded again");
    CHECK_MSG(access(mark, F_OK) != 0, "the dead run's mark was left");
    CHECK_MSG(access(crashed, F_OK) == 0, "no .crashed mark");
    CHECK(access(s.cache_path, F_OK) == 0);   /* a new entry in its place */
    if (prog) clReleaseProgram(prog);
    prog = NULL;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
    CHECK_EQ_INT(s.from_cache, 1);
    if (prog) clReleaseProgram(prog);
    error_clear(&err);
}

/* A cache folder that cannot be written, as a farm may share a filled one read-only:
 * a run loads its entry (it used to compile whenever the folder was not writable) and
 * builds what is not there without claiming to store it. Read-only through a bind
 * mount in a mount namespace of its own (root writes through file modes); skipped
 * where unshare cannot make one. */
static void test_read_only_cache(void)
{
    char dir[400], pocl[400], out[512], cmd[4096];
    snprintf(dir, sizeof dir, "%s/read-only", tmp_root);
    snprintf(pocl, sizeof pocl, "%s/read-only-pocl", tmp_root);
    CHECK_EQ_INT(run_child("--build", "CLPT_TEST_UNUSED", "1", dir, pocl, out, sizeof out), 0);
    CHECK_STR_CONTAINS(out, "from_cache 0\n");
    const char *tries[] = { "--build-path", "--build-variant-path" };
    for (int k = 0; k < 2; k++) {
        snprintf(cmd, sizeof cmd, "unshare -m sh -c 'mount --bind -o ro \"%s\" \"%s\" && touch \"%s/x\" 2>/dev/null; "
                 "test ! -e \"%s/x\" && CLPT_CACHE_DIR=\"%s\" POCL_CACHE_DIR=\"%s\" /proc/%ld/exe %s' 2>/dev/null",
                 dir, dir, dir, dir, dir, pocl, (long)getpid(), tries[k]);
        FILE *p = popen(cmd, "r");
        size_t n = p ? fread(out, 1, sizeof out - 1, p) : 0;
        out[n] = '\0';
        int rc = p ? pclose(p) : -1;
        if (k == 0 && n == 0) {
            fprintf(stderr, "  (skipped: no read-only mount here: %d)\n", rc);
            return;
        }
        CHECK_EQ_INT(rc, 0);
        /* the entry there is loaded; the variant, not there, is built and not stored */
        CHECK_STR_CONTAINS(out, k == 0 ? "build status 0 from_cache 1 cache_path 1\n"
                                       : "build status 0 from_cache 0 cache_path 0\n");
    }
    CHECK_EQ_INT(count_dir_entries(dir, ".bin"), 1);
}

/* A FIFO or a folder in the entry's place: a cache miss, at once (a FIFO hung the
 * build for ever, waiting for a writer), and a regular entry stored in its place. */
static void test_special_cache_entries(void)
{
    for (int kind = 0; kind < 2; kind++) {
        Error err = {0};
        cl_program prog = NULL;
        OclProgramStats s;
        CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
        if (prog) clReleaseProgram(prog);
        CHECK(remove(s.cache_path) == 0);
        CHECK(kind ? mkdir(s.cache_path, 0755) == 0 : mkfifo(s.cache_path, 0644) == 0);
        alarm(120);   /* a hang fails the test instead of stopping the suite */
        prog = NULL;
        CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
        alarm(0);
        CHECK_MSG(s.from_cache == 0, "%s: used as an entry", kind ? "a folder" : "a FIFO");
        struct stat sb;
        CHECK_MSG(stat(s.cache_path, &sb) == 0 && S_ISREG(sb.st_mode), "%s: not replaced by an entry",
                  kind ? "a folder" : "a FIFO");
        if (prog) clReleaseProgram(prog);
        error_clear(&err);
    }
}

/* Every argument position device_ocl.c sets by name (ocl_args.h) is the kernel's
 * argument of that name, and the scene buffers are the first arguments of every scene
 * kernel in the order of kernels/scene_buffers.h. */
static void check_arg_name(cl_program prog, const char *kernel, cl_uint arg, const char *name)
{
    cl_int rc;
    cl_kernel k = clCreateKernel(prog, kernel, &rc);
    char got[64] = "";
    if (rc == CL_SUCCESS) {
        rc = clGetKernelArgInfo(k, arg, CL_KERNEL_ARG_NAME, sizeof got, got, NULL);
        clReleaseKernel(k);
    }
    CHECK_MSG(rc == CL_SUCCESS && strcmp(got, name) == 0, "%s argument %u is '%s' (%s), ocl_args.h says '%s'",
              kernel, arg, got, ocl_error_name(rc), name);
}

static void test_kernel_argument_names(void)
{
    Error err = {0};
    cl_program prog = NULL;
    /* argument names are kept only when asked for (PoCL drops them from a binary); the
     * program of every kernel named below and no other feature */
    char options[96];
    snprintf(options, sizeof options, "-D CLPT_FEATURES=0x%xu -cl-kernel-arg-info",
             KF_PATH | KF_WHITTED | KF_PATH_MEGAKERNEL);
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, options, &prog, NULL, &err), ST_OK);
    CHECK_MSG(prog != NULL, "%s", err.msg);
    if (!prog) return;
#define BUFFER_NAME_(kind, Type, name, count, what) #name,
    static const char *const buffers[SCENE_BUF_COUNT] = { SCENE_BUFFERS(BUFFER_NAME_) };
#undef BUFFER_NAME_
    static const char *const scene_kernels[] = { "k_raygen", "k_intersect", "k_shade", "k_shadow", "k_whitted" };
    for (size_t k = 0; k < sizeof scene_kernels / sizeof scene_kernels[0]; k++)
        for (cl_uint i = 0; i < SCENE_BUF_COUNT; i++) check_arg_name(prog, scene_kernels[k], i, buffers[i]);
    static const struct { const char *kernel; cl_uint arg; const char *name; } named[] = {
        { "k_raygen", ARG_RAYGEN_FIRST_PIXEL, "first_pixel" },
        { "k_raygen", ARG_RAYGEN_FIRST_SAMPLE, "first_sample" }, { "k_raygen", ARG_RAYGEN_N_PIXELS, "n_pixels" },
        { "k_raygen", ARG_RAYGEN_N_PATHS, "n_paths" }, { "k_raygen", ARG_RAYGEN_PATHS, "paths" },
        { "k_raygen", ARG_RAYGEN_RAYS, "rays" }, { "k_raygen", ARG_RAYGEN_QUEUE, "queue" },
        { "k_intersect", ARG_INTERSECT_QUEUE, "queue" }, { "k_intersect", ARG_INTERSECT_N, "n" },
        { "k_intersect", ARG_INTERSECT_RAYS, "rays" }, { "k_intersect", ARG_INTERSECT_HITS, "hits" },
        { "k_intersect", ARG_INTERSECT_COUNTS, "counts" }, { "k_intersect", ARG_INTERSECT_LIVE_SLOT, "live_slot" },
        { "k_intersect", ARG_INTERSECT_PATHS, "paths" },
        { "k_shade", ARG_SHADE_QUEUE, "queue" }, { "k_shade", ARG_SHADE_N, "n" },
        { "k_shade", ARG_SHADE_RAYS, "rays" }, { "k_shade", ARG_SHADE_HITS, "hits" },
        { "k_shade", ARG_SHADE_PATHS, "paths" }, { "k_shade", ARG_SHADE_SHADOW_RAYS, "shadow_rays" },
        { "k_shade", ARG_SHADE_NEXT_QUEUE, "next_queue" }, { "k_shade", ARG_SHADE_SHADOW_QUEUE, "shadow_queue" },
        { "k_shade", ARG_SHADE_COUNTS, "counts" }, { "k_shade", ARG_SHADE_SLOT, "slot" },
        { "k_shadow", ARG_SHADOW_QUEUE, "shadow_queue" }, { "k_shadow", ARG_SHADOW_N, "n" },
        { "k_shadow", ARG_SHADOW_RAYS, "shadow_rays" }, { "k_shadow", ARG_SHADOW_PATHS, "paths" },
        { "k_shadow", ARG_SHADOW_COUNTS, "counts" }, { "k_shadow", ARG_SHADOW_LIVE_SLOT, "live_slot" },
        { "k_film", ARG_FILM_PATHS, "paths" },
        { "k_film", ARG_FILM_N_PIXELS, "n_pixels" }, { "k_film", ARG_FILM_N_PATHS, "n_paths" },
        { "k_film", ARG_FILM_FILM, "film" },
        { "k_path", ARG_PATH_FIRST_PIXEL, "first_pixel" }, { "k_path", ARG_PATH_FIRST_SAMPLE, "first_sample" },
        { "k_path", ARG_PATH_N_PIXELS, "n_pixels" }, { "k_path", ARG_PATH_N_PATHS, "n_paths" },
        { "k_path", ARG_PATH_PATHS, "paths" }, { "k_path", ARG_PATH_RAYS, "rays" },
        { "k_path", ARG_PATH_SHADOW_RAYS, "shadow_rays" }, { "k_path", ARG_PATH_COUNTERS, "counters" },
        { "k_whitted", ARG_WHITTED_FIRST_PIXEL, "first_pixel" }, { "k_whitted", ARG_WHITTED_FIRST_SAMPLE, "first_sample" },
        { "k_whitted", ARG_WHITTED_N_PIXELS, "n_pixels" }, { "k_whitted", ARG_WHITTED_N_PATHS, "n_paths" },
        { "k_whitted", ARG_WHITTED_PATHS, "paths" }, { "k_whitted", ARG_WHITTED_COUNTERS, "counters" },
    };
    for (size_t i = 0; i < sizeof named / sizeof named[0]; i++)
        check_arg_name(prog, named[i].kernel, named[i].arg, named[i].name);
    clReleaseProgram(prog);
    error_clear(&err);
}

/* The renderer's program for `features` (CLPT_FEATURES) with `extra` options, built as
 * the device builds it (in the kernel cache, so the suite's second run loads it); its
 * options into `options`. NULL, having failed the test, if it does not build. */
static cl_program build_program(unsigned features, const char *extra, char *options, size_t cap)
{
    snprintf(options, cap, "-D CLPT_FEATURES=0x%xu%s", features, extra);
    Error err = {0};
    cl_program prog = NULL;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, options, &prog, NULL, &err), ST_OK);
    CHECK_MSG(prog != NULL, "%s: %s", options, err.msg);
    error_clear(&err);
    return prog;
}

/* Whether prog has a kernel named `name`. */
static int has_kernel(cl_program prog, const char *name)
{
    cl_int rc;
    cl_kernel k = clCreateKernel(prog, name, &rc);
    if (rc != CL_SUCCESS) return 0;
    clReleaseKernel(k);
    return 1;
}

/* The device's two programs (kernels/entry.cl, CLPT_FEATURES): the path tracer's has
 * no k_whitted and the whitted one none of the path tracer's kernels; both have k_film
 * (what a cached program is checked for), neither k_layout (the tests' whole program
 * has it). Built in the cache like the device builds them, so the second run of the
 * suite loads them. */
static void test_program_per_integrator(void)
{
    static const struct { unsigned features; const char *has[3], *lacks[3]; } programs[] = {
        { KF_PATH, { "k_raygen", "k_shade", "k_film" }, { "k_whitted", "k_layout", "k_path" } },
        { KF_WHITTED, { "k_whitted", "k_film", "k_film" }, { "k_shade", "k_raygen", "k_path" } },
        { KF_PATH_MEGAKERNEL, { "k_path", "k_film", "k_film" }, { "k_shade", "k_raygen", "k_path_lanes" } },
        { KF_PATH_LANES, { "k_path_lanes", "k_film", "k_film" }, { "k_path", "k_shade", "k_whitted" } },
    };
    for (size_t i = 0; i < sizeof programs / sizeof programs[0]; i++) {
        char options[96];
        cl_program prog = build_program(programs[i].features, "", options, sizeof options);
        if (!prog) continue;
        for (int k = 0; k < 3; k++)
            CHECK_MSG(has_kernel(prog, programs[i].has[k]), "%s: no %s", options, programs[i].has[k]);
        for (int k = 0; k < 3 && programs[i].lacks[k]; k++)
            CHECK_MSG(!has_kernel(prog, programs[i].lacks[k]), "%s: has %s", options, programs[i].lacks[k]);
        clReleaseProgram(prog);
    }
}

/* With CLPT_LOCAL_SIZE, as the device builds them, the launched kernels of both programs
 * declare that work-group size, so that PoCL compiles each kernel once (the size the
 * binary is made for is the launches' size; ocl.c turns PoCL's re-specialisation off). */
static void test_kernels_declare_the_launch_size(void)
{
    static const struct { unsigned features; const char *kernels[5]; } programs[] = {
        { KF_PATH, { "k_raygen", "k_intersect", "k_shade", "k_shadow", "k_film" } },
        { KF_WHITTED, { "k_whitted", "k_film", NULL, NULL, NULL } },
        { KF_PATH_MEGAKERNEL, { "k_path", "k_film", NULL, NULL, NULL } },
        { KF_PATH_LANES, { "k_path_lanes", "k_film", NULL, NULL, NULL } },
    };
    for (size_t i = 0; i < sizeof programs / sizeof programs[0]; i++) {
        char options[96];
        cl_program prog = build_program(programs[i].features, " -D CLPT_LOCAL_SIZE=64", options, sizeof options);
        if (!prog) continue;
        for (int k = 0; k < 5 && programs[i].kernels[k]; k++) {
            cl_int rc;
            cl_kernel kn = clCreateKernel(prog, programs[i].kernels[k], &rc);
            size_t size[3] = { 0, 0, 0 };
            CHECK(rc == CL_SUCCESS);
            if (rc != CL_SUCCESS) continue;
            CHECK(clGetKernelWorkGroupInfo(kn, dev->id, CL_KERNEL_COMPILE_WORK_GROUP_SIZE, sizeof size, size, NULL) ==
                  CL_SUCCESS);
            /* k_path_lanes: eight paths per work-item, as many paths per group */
            size_t want = strcmp(programs[i].kernels[k], "k_path_lanes") == 0 ? 64u / PATH_LANES : 64u;
            CHECK_MSG(size[0] == want && size[1] == 1 && size[2] == 1, "%s: declared size %zu x %zu x %zu",
                      programs[i].kernels[k], size[0], size[1], size[2]);
            clReleaseKernel(kn);
        }
        clReleaseProgram(prog);
    }
    const char *spec = getenv("POCL_WORK_GROUP_SPECIALIZATION");
    CHECK_MSG(spec && strcmp(spec, "0") == 0, "POCL_WORK_GROUP_SPECIALIZATION is %s", spec ? spec : "unset");
}

/* Every feature switch of types.h, alone with either integrator, compiles without a
 * warning: PoCL prints a build's warnings on stderr ("1 warning generated."), so a
 * switch that leaves, say, a constant operand of || behind would show in every run of
 * a scene without that feature. Checked with the system's clang as OpenCL C (fast: no
 * code generation); skipped where there is none. */
static void test_feature_switches_compile_cleanly(void)
{
    if (system("clang --version >/dev/null 2>&1") != 0) {
        fprintf(stderr, "  (no clang: the feature switches were not compiled)\n");
        return;
    }
    static const unsigned programs[] = { KF_PATH, KF_WHITTED, KF_PATH_MEGAKERNEL, KF_PATH_LANES };
    /* each switch alone, each material type's, and each of the two trees */
#define MATERIAL_SWITCH_(name, value, bit, traits, lobes) bit,
    static const unsigned switches[] = { 1u << 0, 1u << 1, 1u << 2, 1u << 3, 1u << 4, 1u << 5, 1u << 6, 1u << 7,
                                         1u << 8, 1u << 9, 1u << 10, KF_KDTREE, KF_BVH,
                                         KF_SPHERES | KF_SPHERE_XFORM, KF_MEDIA, KF_BVH | KF_INSTANCES, KF_MOTION,
                                         MATERIAL_TYPES(MATERIAL_SWITCH_) };
#undef MATERIAL_SWITCH_
    for (size_t bit = 0; bit < sizeof switches / sizeof switches[0]; bit++) {
        if (switches[bit] == 0u) continue;   /* a material type that is always compiled */
        for (size_t k = 0; k < sizeof programs / sizeof programs[0]; k++) {
            unsigned features = programs[k] | switches[bit];
            char cmd[300], out[2048];
            snprintf(cmd, sizeof cmd, "clang -x cl -cl-std=CL1.2 -Xclang -finclude-default-header -fsyntax-only "
                     "-Wall -Wextra -Ikernels -DCLPT_FEATURES=0x%xu kernels/entry.cl 2>&1", features);
            FILE *p = popen(cmd, "r");
            if (!p) continue;
            size_t n = fread(out, 1, sizeof out - 1, p);
            out[n] = '\0';
            int rc = pclose(p);
            CHECK_MSG(rc == 0 && n == 0, "CLPT_FEATURES=0x%x: %s", features, out);
        }
    }
    /* the material types' bits are single bits that no other switch and no other type has */
    unsigned others = KF_PATH | KF_WHITTED | KF_TEXTURES | KF_ALPHA | KF_ENV_MAP | KF_CUBEMAP | KF_REVSURFACE |
                      KF_SPHERES | KF_BOXES | KF_PLANES | KF_DELTA_LIGHTS | KF_PATH_MEGAKERNEL | KF_KDTREE | KF_BVH |
                      KF_PATH_LANES | KF_SPHERE_XFORM | KF_MEDIA | KF_INSTANCES | KF_MOTION;
    unsigned seen = others;
#define MATERIAL_BIT_(name, value, bit, traits, lobes) \
    CHECK_MSG(((bit) & ((bit) - 1u)) == 0u && ((bit) & seen) == 0u, "%s: feature bit 0x%x", #name, (bit)); \
    seen |= (bit);
    MATERIAL_TYPES(MATERIAL_BIT_)
#undef MATERIAL_BIT_
    CHECK_EQ_INT(KF_ALL, seen);
}

static void test_cache_location(void)
{
    char saved_clpt[400], buf[1024];
    snprintf(saved_clpt, sizeof saved_clpt, "%s", getenv("CLPT_CACHE_DIR"));
    const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    char saved_xdg[512] = "", saved_home[512] = "";
    if (xdg) snprintf(saved_xdg, sizeof saved_xdg, "%s", xdg);
    if (home) snprintf(saved_home, sizeof saved_home, "%s", home);

    setenv("XDG_CACHE_HOME", "/x/cache", 1);
    setenv("HOME", "/h", 1);
    CHECK(ocl_program_cache_dir(buf, sizeof buf) && strcmp(buf, saved_clpt) == 0);
    unsetenv("CLPT_CACHE_DIR");
    CHECK(ocl_program_cache_dir(buf, sizeof buf) && strcmp(buf, "/x/cache/clpt") == 0);
    setenv("XDG_CACHE_HOME", "relative/cache", 1);
    CHECK(ocl_program_cache_dir(buf, sizeof buf) && strcmp(buf, "/h/.cache/clpt") == 0);
    unsetenv("XDG_CACHE_HOME");
    unsetenv("HOME");
    CHECK(ocl_program_cache_dir(buf, sizeof buf) == 0);

    /* An unusable cache folder (below a regular file) costs the cache, not the build. */
    char blocker[400], bad[450];
    snprintf(blocker, sizeof blocker, "%s/not-a-folder", tmp_root);
    snprintf(bad, sizeof bad, "%s/cache", blocker);
    CHECK(write_text(blocker, "x") == 0);
    setenv("CLPT_CACHE_DIR", bad, 1);
    Error err = {0};
    cl_program prog = NULL;
    OclProgramStats s;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, NULL, cache_test_options, &prog, &s, &err), ST_OK);
    CHECK(prog != NULL);
    CHECK_EQ_INT(s.from_cache, 0);
    CHECK(s.cache_path[0] == '\0');
    if (prog) clReleaseProgram(prog);

    setenv("CLPT_CACHE_DIR", saved_clpt, 1);
    if (saved_xdg[0]) setenv("XDG_CACHE_HOME", saved_xdg, 1);
    if (saved_home[0]) setenv("HOME", saved_home, 1);
    error_clear(&err);
}

/* Developer mode: a kernel folder whose entry.cl includes a header. */
static void test_kernel_dir(void)
{
    char dir[400], path[500];
    snprintf(dir, sizeof dir, "%s/kernels", tmp_root);
    CHECK(mkdir(dir, 0755) == 0);
    snprintf(path, sizeof path, "%s/entry.cl", dir);
    CHECK(write_text(path, "#include \"value.h\"\n"
                           "__kernel void k_value(__global uint *out) { out[0] = VALUE; }\n") == 0);
    snprintf(path, sizeof path, "%s/value.h", dir);
    CHECK(write_text(path, "#define VALUE 7u\n") == 0);

    int cached_before = count_dir_entries(cache_dir, "");
    Error err = {0};
    cl_program prog = NULL;
    cl_kernel k = NULL;
    OclProgramStats s;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, dir, NULL, &prog, &s, &err), ST_OK);
    CHECK_MSG(prog != NULL, "%s\n%s", err.msg, err.detail ? err.detail : "");
    CHECK_STR_CONTAINS(s.options, " -I ");
    CHECK_STR_CONTAINS(s.options, dir);
    CHECK(s.cache_path[0] == '\0' && s.from_cache == 0);
    CHECK_EQ_INT(count_dir_entries(cache_dir, ""), cached_before);
    if (prog) {
        CHECK_EQ_INT(ocl_program_kernel(prog, dev, "k_value", &k, &err), ST_OK);
        if (k) clReleaseKernel(k);
        k = NULL;
        CHECK_EQ_INT(ocl_program_kernel(prog, dev, "k_missing", &k, &err), ST_DEVICE);
        CHECK(k == NULL);
        CHECK_STR_CONTAINS(err.msg, dev->name);
        CHECK_STR_CONTAINS(err.msg, "clCreateKernel failed: CL_INVALID_KERNEL_NAME");
        CHECK_STR_CONTAINS(err.msg, "'k_missing'");
        clReleaseProgram(prog);
    }

    /* Breaking only the included header must break the next build: no cache on either
     * side (ours or the driver's) may serve the old program. */
    CHECK(write_text(path, "#define VALUE clpt_undeclared_name\n") == 0);
    prog = NULL;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, dir, NULL, &prog, &s, &err), ST_DEVICE);
    CHECK(prog == NULL);
    CHECK_STR_CONTAINS(err.detail, "clpt_undeclared_name");

    /* Missing entry.cl, and a path the build options cannot carry. */
    snprintf(path, sizeof path, "%s/nothing-here", tmp_root);
    CHECK_EQ_INT(ocl_program_build(ctx, dev, path, NULL, &prog, &s, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "nothing-here/entry.cl");
    CHECK_EQ_INT(ocl_program_build(ctx, dev, "/tmp/with space", NULL, &prog, &s, &err),
                 ST_USAGE);
    error_clear(&err);
}

static void test_build_failure(void)
{
    char dir[400], path[500];
    snprintf(dir, sizeof dir, "%s/bad_kernels", tmp_root);
    CHECK(mkdir(dir, 0755) == 0);
    snprintf(path, sizeof path, "%s/entry.cl", dir);
    CHECK(write_text(path, "__kernel void k_bad(__global float *out)\n"
                           "{\n"
                           "    out[0] = clpt_no_such_identifier * 2.0f;\n"
                           "    out[1] = 1.0f\n"
                           "}\n") == 0);
    Error err = {0};
    cl_program prog = NULL;
    OclProgramStats s;
    CHECK_EQ_INT(ocl_program_build(ctx, dev, dir, "-DCLPT_EXTRA=1", &prog, &s, &err), ST_DEVICE);
    CHECK(prog == NULL);
    CHECK_EQ_INT(err.status, ST_DEVICE);
    CHECK_STR_CONTAINS(err.msg, dev->name);
    CHECK_STR_CONTAINS(err.msg, "clBuildProgram failed: CL_BUILD_PROGRAM_FAILURE");
    CHECK_STR_CONTAINS(err.msg, "-cl-std=CL1.2");
    CHECK_STR_CONTAINS(err.msg, "-DCLPT_EXTRA=1");
    CHECK_STR_CONTAINS(err.msg, dir);
    CHECK_STR_CONTAINS(err.detail, "clpt_no_such_identifier");
    CHECK_STR_CONTAINS(err.detail, "entry.cl:3");
    fprintf(stderr, "  build failure message: %s\n", err.msg);
    error_clear(&err);
}

int main(int argc, char **argv)
{
    snprintf(cache_test_options, sizeof cache_test_options, "-D CLPT_FEATURES=0x%xu", KF_PATH | KF_WHITTED);
    if (argc == 2 && strcmp(argv[1], "--two-devices") == 0) return child_two_devices();
    if (argc == 2 && strcmp(argv[1], "--enumerate") == 0) return child_enumerate();
    if (argc == 2 && strcmp(argv[1], "--build") == 0) return child_build(0, 0);
    if (argc == 2 && strcmp(argv[1], "--build-path") == 0) return child_build(0, 1);
    if (argc == 2 && strcmp(argv[1], "--build-variant-path") == 0) return child_build(1, 1);

    snprintf(tmp_root, sizeof tmp_root, "%s/clpt-test-ocl-XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(tmp_root)) {
        fprintf(stderr, "mkdtemp: %s\n", strerror(errno));
        return 1;
    }
    char pocl_cache[400];
    snprintf(cache_dir, sizeof cache_dir, "%s/cache", tmp_root);
    snprintf(pocl_cache, sizeof pocl_cache, "%s/pocl-cache", tmp_root);
    mkdir(pocl_cache, 0755);
    setenv("CLPT_CACHE_DIR", cache_dir, 1);
    setenv("POCL_CACHE_DIR", pocl_cache, 1);

    RUN(test_error_names);
    RUN(test_sha256);
    RUN(test_feature_switches_compile_cleanly);

    Error err = {0};
    if (ocl_enumerate(&devices, &n_devices, &err) != ST_OK)
        fprintf(stderr, "ocl_enumerate: %s\n", err.msg);
    RUN(test_enumerate);
    RUN(test_two_devices);
    RUN(test_no_platform);
    if (n_devices > 0) {
        dev = &devices[0];
        cl_int rc;
        ctx = clCreateContext(NULL, 1, &dev->id, NULL, NULL, &rc);
        if (rc != CL_SUCCESS) fprintf(stderr, "clCreateContext: %s\n", ocl_error_name(rc));
    }
    RUN(test_context);
    if (ctx) {
        RUN(test_build_and_cache);
        RUN(test_corrupt_cache);
        RUN(test_crashing_cache_entry);
        RUN(test_special_cache_entries);
        RUN(test_runs_together);
        RUN(test_died_reading_entry);
        RUN(test_read_only_cache);
        RUN(test_kernel_argument_names);
        RUN(test_program_per_integrator);
        RUN(test_kernels_declare_the_launch_size);
        RUN(test_cache_location);
        RUN(test_kernel_dir);
        RUN(test_build_failure);
        clReleaseContext(ctx);
    }
    free(devices);
    remove_tree(tmp_root);
    return harness_report();
}
