/*
 * test_device_errors.c — OpenCL failures as the user meets them, by running the
 * program: a kernel that does not build (exit 5 with the device, the call, the options
 * and the whole build log), a device too small for the render (checked before any
 * upload), either failure on one of two devices (that device is dropped with a
 * warning and the other renders), and the default choice falling back to the scalar
 * device when no OpenCL device can build its kernels. Two PoCL devices are made with
 * POCL_DEVICES; the failures with the test-only variables of host/base/fault.h.
 */

#include "cli_util.h"
#include "device/device_memory.h"
#include "harness.h"

static CliResult r;   /* large: static */

/* The --list-devices indices of the two PoCL devices ("0" and "1" where PoCL is the
 * only OpenCL platform), as --device and the fault variables take them. */
static char pocl_a[8] = "0", pocl_b[8] = "1", pocl_ab[20] = "0,1";
static char cap_a[40], cap_b[40], cap_ab[80], fail_b[8];

static void find_pocl_devices(void)
{
    cli_run((const char *const[]){ "--list-devices", NULL }, &r);
    unsigned idx[2];
    int n = 0;
    char *save = NULL;
    for (char *line = strtok_r(r.out, "\n", &save); line && n < 2; line = strtok_r(NULL, "\n", &save)) {
        unsigned i;
        char kind[16];
        if (sscanf(line, "%u %15s", &i, kind) == 2 && strcmp(kind, "opencl") == 0 && strstr(line, "pthread"))
            idx[n++] = i;
    }
    if (n == 2) {
        snprintf(pocl_a, sizeof pocl_a, "%u", idx[0]);
        snprintf(pocl_b, sizeof pocl_b, "%u", idx[1]);
        snprintf(pocl_ab, sizeof pocl_ab, "%u,%u", idx[0], idx[1]);
    }
    CHECK_MSG(n == 2, "expected two PoCL devices in --list-devices, found %d", n);
    snprintf(cap_a, sizeof cap_a, "%s:1048576", pocl_a);
    snprintf(cap_b, sizeof cap_b, "%s:1048576", pocl_b);
    snprintf(cap_ab, sizeof cap_ab, "%s,%s", cap_a, cap_b);
    snprintf(fail_b, sizeof fail_b, "%s", pocl_b);
}

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })
#define SMALL "--width", "16", "--height", "12", "--spp", "2"
/* in this process's scratch folder (harness.h): other test runs on the machine use /tmp too */
static char out_path[512];
#define OUT out_path

static void test_broken_kernel_dir(void)
{
    char dir[] = "/tmp/clpt-test-kdir-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[300];
    snprintf(path, sizeof path, "%s/entry.cl", dir);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f) return;
    fputs("__kernel void k_raygen(__global float *out)\n{\n    out[0] = clpt_undefined_on_purpose;\n}\n", f);
    fclose(f);
    unlink(OUT);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", pocl_a, "--kernel-dir", dir, SMALL, "-o", OUT), &r);
    CHECK_EQ_INT(r.status, 5);
    CHECK_STR_CONTAINS(r.err, "clpt: error: device 'pthread");                   /* the device */
    CHECK_STR_CONTAINS(r.err, "clBuildProgram failed: CL_BUILD_PROGRAM_FAILURE"); /* call, error name */
    CHECK_STR_CONTAINS(r.err, "options \"-cl-std=CL1.2");                         /* the options */
    char inc[320];
    snprintf(inc, sizeof inc, "-I %s -D CLPT_FEATURES=0x", dir);   /* then the scene's kernel features */
    CHECK_STR_CONTAINS(r.err, inc);
    CHECK_STR_CONTAINS(r.err, "(build log follows)");
    CHECK_STR_CONTAINS(r.err, "entry.cl:3:");                                     /* the log itself */
    CHECK_STR_CONTAINS(r.err, "clpt_undefined_on_purpose");
    CHECK(!file_exists(OUT));
    unlink(path);
    rmdir(dir);
}

static void test_build_failure_on_one_device(void)
{
    setenv("CLPT_TEST_BUILD_FAIL", fail_b, 1);
    unlink(OUT);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", pocl_ab, SMALL, "-o", OUT), &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
    CHECK_STR_CONTAINS(r.err, "clBuildProgram failed: CL_BUILD_PROGRAM_FAILURE");
    CHECK_STR_CONTAINS(r.err, "unknown type name 'clpt_test_build_failure_forced_by_CLPT_TEST_BUILD_FAIL'");
    char dropped[64];
    snprintf(dropped, sizeof dropped, "clpt: warning: device %s 'pthread", pocl_b);
    CHECK_STR_CONTAINS(r.err, dropped);
    CHECK_STR_CONTAINS(r.err, "dropped; rendering with the others");
    CHECK_STR_CONTAINS(r.err, "rendered 16x12, 2 spp");
    CHECK(file_exists(OUT));
    /* alone, the same device is an error */
    unlink(OUT);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", pocl_b, SMALL, "-o", OUT), &r);
    CHECK_EQ_INT(r.status, 5);
    CHECK_STR_CONTAINS(r.err, "clpt: error: device 'pthread");
    CHECK_STR_CONTAINS(r.err, "-D__kernel=clpt_test_build_failure_forced_by_CLPT_TEST_BUILD_FAIL");
    CHECK(!file_exists(OUT));
    unsetenv("CLPT_TEST_BUILD_FAIL");
}

/* The default choice (no --device) is every OpenCL CPU here; when none of them can
 * build its kernels, the next group of the default order renders, with a warning: the
 * scalar device. A device named with --device gets no such fallback. */
static void test_default_device_falls_back(void)
{
    setenv("CLPT_TEST_BUILD_FAIL", pocl_ab, 1);
    unlink(OUT);
    cli_run(ARGS("scenes/cornell-box.scene", SMALL, "-o", OUT), &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
    CHECK_STR_CONTAINS(r.err, "clBuildProgram failed: CL_BUILD_PROGRAM_FAILURE");
    CHECK_STR_CONTAINS(r.err, "clpt: warning: the default devices cannot be used; falling back to device ");
    CHECK_STR_CONTAINS(r.err, " 'scalar'");
    CHECK_STR_CONTAINS(r.err, "rendered 16x12, 2 spp");
    CHECK(file_exists(OUT));
    unlink(OUT);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", pocl_ab, SMALL, "-o", OUT), &r);
    CHECK_EQ_INT(r.status, 5);
    CHECK(strstr(r.err, "falling back") == NULL);
    CHECK(!file_exists(OUT));
    unsetenv("CLPT_TEST_BUILD_FAIL");
}

static void test_device_too_small(void)
{
    /* 1 MiB: the path-state buffer alone is larger */
    setenv("CLPT_TEST_DEVICE_MEMORY", cap_a, 1);
    cli_run(ARGS("--list-devices"), &r);
    CHECK_STR_CONTAINS(r.out, "1 MiB");
    unlink(OUT);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", pocl_a, SMALL, "-o", OUT), &r);
    CHECK_EQ_INT(r.status, 5);
    CHECK_STR_CONTAINS(r.err, "clpt: error: device 'pthread");
    CHECK_STR_CONTAINS(r.err, "the wave 1 path states need 5.0 MiB in one buffer, more than its largest allocation (1.0 MiB)");
    CHECK(!file_exists(OUT));
    /* 8 MB: every buffer fits alone, not all together */
    char cap[40];
    snprintf(cap, sizeof cap, "%s:8000000", pocl_a);
    setenv("CLPT_TEST_DEVICE_MEMORY", cap, 1);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", pocl_a, SMALL, "-o", OUT), &r);
    CHECK_EQ_INT(r.status, 5);
    /* 23.5: path states of 80 bytes (a medium per path) and hits of 32 (an instance) */
    CHECK_STR_CONTAINS(r.err, "the render needs 23.5 MiB (wave 1 path states 5.0 MiB, wave 2 path states 5.0 MiB");
    CHECK_STR_CONTAINS(r.err, "more than its 7.6 MiB of memory");
    /* fewer paths per wave fit */
    cli_run(ARGS("scenes/cornell-box.scene", "--device", pocl_a, "--wave-paths", "4096", SMALL, "-o", OUT), &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
    CHECK(file_exists(OUT));
    unsetenv("CLPT_TEST_DEVICE_MEMORY");
}

static void test_small_device_dropped(void)
{
    setenv("CLPT_TEST_DEVICE_MEMORY", cap_b, 1);
    unlink(OUT);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", pocl_ab, SMALL, "-o", OUT), &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
    CHECK_STR_CONTAINS(r.err, "more than its largest allocation (1.0 MiB)");
    char dropped[64];
    snprintf(dropped, sizeof dropped, "clpt: warning: device %s 'pthread", pocl_b);
    CHECK_STR_CONTAINS(r.err, dropped);
    CHECK(file_exists(OUT));
    /* both too small: nothing can render */
    setenv("CLPT_TEST_DEVICE_MEMORY", cap_ab, 1);
    unlink(OUT);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", pocl_ab, SMALL, "-o", OUT), &r);
    CHECK_EQ_INT(r.status, 5);
    CHECK_STR_CONTAINS(r.err, "clpt: error: none of the 2 chosen devices could be used");
    CHECK(!file_exists(OUT));
    unsetenv("CLPT_TEST_DEVICE_MEMORY");
    unlink(OUT);
}

static void test_memory_check(void)
{
    DeviceBuffer b[3] = { { "triangles", 600 << 20 }, { "film", 100 << 20 }, { "hits", 300 << 20 } };
    Error err = { 0 };
    CHECK_EQ_INT(device_memory_check("gpu", 1000u << 20, 600u << 20, b, 3, &err), ST_OK);
    CHECK_EQ_INT(device_memory_check("gpu", 1000u << 20, 599u << 20, b, 3, &err), ST_DEVICE);
    CHECK_STR_CONTAINS(err.msg, "device 'gpu': the triangles need 600.0 MiB in one buffer, more than its "
                                "largest allocation (599.0 MiB)");
    CHECK_EQ_INT(device_memory_check("gpu", 999u << 20, 600u << 20, b, 3, &err), ST_DEVICE);
    CHECK_STR_CONTAINS(err.msg, "device 'gpu': the render needs 1000.0 MiB (triangles 600.0 MiB, hits 300.0 MiB, "
                                "film 100.0 MiB), more than its 999.0 MiB of memory");
    CHECK_STR_CONTAINS(err.msg, "lower --wave-paths");
    error_clear(&err);
}

int main(void)
{
    /* before anything loads the ICD in a child: two PoCL CPU devices, 0 and 1 */
    setenv("POCL_DEVICES", "pthread pthread", 1);
    test_tmp_path(out_path, sizeof out_path, "clpt-test-device-errors.png");
    RUN(find_pocl_devices);
    RUN(test_memory_check);
    RUN(test_broken_kernel_dir);
    RUN(test_build_failure_on_one_device);
    RUN(test_default_device_falls_back);
    RUN(test_device_too_small);
    RUN(test_small_device_dropped);
    unlink(OUT);
    return harness_report();
}
