/*
 * test_schedule.c — samples in batches across devices: the image is the same bits on any
 * device mix and batch size, a failing device's batches are redone elsewhere with the
 * same result, the time limit is honoured within a batch, and an interrupt leaves a
 * valid image. Runs with two PoCL devices (POCL_DEVICES="pthread pthread") plus the
 * scalar device.
 */
#include <signal.h>
#include <stdlib.h>
#include <time.h>

#include "cli_util.h"
#include "harness.h"
#include "render_util.h"
#include "base/timer.h"

static Scene base;

static void load_base(void)
{
    Error err = { 0 };
    scene_init(&base);
    if (scene_load("scenes/cornell-box.scene", &base, &err)) fprintf(stderr, "%s\n", err.msg);
    base.image.width = 40;
    base.image.height = 30;
    base.image.spp = 12;
}

/* Renders a copy of the base scene; returns the film (caller frees). */
static Film render(const char *devices, uint batch, Status *st_out)
{
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    scene_load("scenes/cornell-box.scene", &s, &err);
    s.image = base.image;
    Film f;
    Status st = render_util_run(&s, devices, batch, &f, &err);
    if (st) fprintf(stderr, "  render on %s: %s\n", devices, err.msg);
    if (st_out) *st_out = st;
    scene_free(&s);
    error_clear(&err);
    return f;
}

static int films_identical(const Film *a, const Film *b)
{
    if (!a->sum || !b->sum || a->width != b->width || a->height != b->height || a->samples != b->samples) return 0;
    return memcmp(a->sum, b->sum, (size_t)a->width * a->height * 3u * sizeof *a->sum) == 0;
}

static void test_two_pocl_devices_listed(void)
{
    DeviceDesc *all = NULL;
    size_t n = 0;
    char w[1100];
    Error err = { 0 };
    CHECK(device_list(&all, &n, w, sizeof w, &err) == ST_OK);
    CHECK_MSG(n >= 3, "expected two PoCL devices and the scalar one, got %zu devices", n);
    free(all);
}

static void test_same_image_on_any_device_mix(void)
{
    Status st;
    Film ref = render("0", 1, &st);
    CHECK(st == ST_OK);
    const struct { const char *devices; uint batch; } mixes[] = {
        { "0", 0 }, { "0", 5 }, { "0,1", 0 }, { "0,1", 2 }, { "0,scalar", 0 }, { "scalar", 3 },
        { "0,1,scalar", 1 },
    };
    for (size_t i = 0; i < sizeof mixes / sizeof mixes[0]; i++) {
        Film f = render(mixes[i].devices, mixes[i].batch, &st);
        CHECK(st == ST_OK);
        CHECK_MSG(films_identical(&ref, &f), "devices '%s' batch %u: the film differs from one device's",
                  mixes[i].devices, mixes[i].batch);
        film_free(&f);
    }
    film_free(&ref);
}

static void test_failed_device_batches_are_redone(void)
{
    Status st;
    Film ref = render("scalar", 0, &st);
    /* device 0 of the selection fails on its second batch, device 1 on its first */
    setenv("CLPT_TEST_FAIL", "0:1,1:0", 1);
    Film f = render("0,1,scalar", 2, &st);
    unsetenv("CLPT_TEST_FAIL");
    CHECK(st == ST_OK);
    CHECK_MSG(films_identical(&ref, &f), "the image after two device failures differs");
    film_free(&f);
    /* every device failing: an error, and the film keeps what was finished */
    setenv("CLPT_TEST_FAIL", "0:2", 1);
    f = render("0", 1, &st);
    unsetenv("CLPT_TEST_FAIL");
    CHECK_EQ_INT(st, ST_DEVICE);
    CHECK_EQ_INT(f.samples, 2);
    film_free(&f);
    film_free(&ref);
}

/* --- the program itself: PFM output identical across devices, time limit, SIGINT */

static CliResult r;
#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static int read_file(const char *path, char **data, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    *data = malloc((size_t)n);
    *len = fread(*data, 1, (size_t)n, f);
    fclose(f);
    return *len == (size_t)n;
}

static void test_pfm_identical_across_devices(void)
{
    const char *devs[] = { "0", "1,scalar", "0,1,scalar" };
    const char *batches[] = { "1", "0", "3" };
    char *ref = NULL;
    size_t ref_len = 0;
    for (int i = 0; i < 3; i++) {
        const char *out = "/tmp/clpt-test-mix.pfm";
        if (batches[i][0] == '0')
            cli_run(ARGS("scenes/cornell-box.scene", "-q", "--device", devs[i], "--width", "32", "--height", "24",
                         "--spp", "8", "-o", out), &r);
        else
            cli_run(ARGS("scenes/cornell-box.scene", "-q", "--device", devs[i], "--batch", batches[i], "--width", "32",
                         "--height", "24", "--spp", "8", "-o", out), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        char *data = NULL;
        size_t len = 0;
        CHECK(read_file(out, &data, &len));
        if (i == 0) {
            ref = data;
            ref_len = len;
        } else {
            CHECK_MSG(len == ref_len && data && memcmp(data, ref, len) == 0, "PFM from devices '%s' differs", devs[i]);
            free(data);
        }
        unlink(out);
    }
    free(ref);
}

static void test_time_limit_within_one_batch(void)
{
    const char *out = "/tmp/clpt-test-time.png";
    unlink(out);
    double t0 = timer_now();
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "64", "--height", "64", "--spp",
                 "1000000", "--time-limit", "1.5", "-o", out), &r);
    double secs = timer_now() - t0;
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.err, "time limit reached");
    /* a batch is about 0.25 s; allow it, plus start-up and writing */
    CHECK_MSG(secs < 1.5 + 0.25 + 1.0, "took %.2f s with a 1.5 s limit", secs);
    CHECK(file_exists(out));
    unlink(out);
}

static void test_sigint_writes_partial_image(void)
{
    const char *out = "/tmp/clpt-test-sigint.pfm";
    unlink(out);
    CliChild c = cli_start(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "64", "--height", "64",
                                "--spp", "1000000", "-o", out));
    struct timespec ts = { 1, 500000000L };
    nanosleep(&ts, NULL);
    kill(c.pid, SIGINT);
    cli_finish(c, &r);
    CHECK_EQ_INT(r.status, 6);
    CHECK_STR_CONTAINS(r.err, "interrupted");
    char *data = NULL;
    size_t len = 0;
    CHECK(read_file(out, &data, &len));
    /* a complete PFM: header plus 64*64*3 floats */
    CHECK(data && len > 64u * 64u * 12u && memcmp(data, "PF\n64 64\n", 9) == 0);
    free(data);
    unlink(out);
}

int main(void)
{
    /* before anything loads the OpenCL ICD: two PoCL CPU devices */
    setenv("POCL_DEVICES", "pthread pthread", 1);
    load_base();
    RUN(test_two_pocl_devices_listed);
    RUN(test_same_image_on_any_device_mix);
    RUN(test_failed_device_batches_are_redone);
    RUN(test_pfm_identical_across_devices);
    RUN(test_time_limit_within_one_batch);
    RUN(test_sigint_writes_partial_image);
    scene_free(&base);
    return harness_report();
}
