/*
 * test_schedule.c — samples in batches across devices: the image is the same bits on any
 * device mix and batch size, a failing device's batches are redone elsewhere with the
 * same result, the time limit is honoured within a batch, and an interrupt leaves a
 * valid image. A cancelled batch is dropped whole by every device kind, and SIGINT or
 * SIGTERM stops even a render whose one batch would take minutes within about a second;
 * a second signal ends the program at once. Runs with two PoCL devices (POCL_DEVICES="pthread pthread") plus the
 * scalar device.
 */
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <time.h>

#include "cli_util.h"
#include "harness.h"
#include "render_util.h"
#include "base/timer.h"
#include "file_util.h"

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


/* --- cancelling a batch on the device itself */

static atomic_int cancel_flag;

static void *cancel_later(void *arg)
{
    (void)arg;
    struct timespec ts = { 0, 100000000L };
    nanosleep(&ts, NULL);
    atomic_store(&cancel_flag, 1);
    return NULL;
}

/* Renders batch [0, count) on d and takes its film into a fresh one. */
static Status render_batch(Device *d, uint count, Film *f, Error *err)
{
    Status st = d->ops->render(d, 0, count, err);
    if (st == ST_OK) st = d->ops->take_film(d, f->sum, err);
    return st;
}

static void check_cancel_on(const char *spec)
{
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    scene_load("scenes/cornell-box.scene", &s, &err);
    s.image.width = 160;
    s.image.height = 120;
    RenderScene rs;
    DeviceDesc *all = NULL;
    size_t n_all = 0, *chosen = NULL, n_chosen = 0;
    Device *d = NULL;
    char warning[1100];
    Film ref, after;
    memset(&ref, 0, sizeof ref);
    memset(&after, 0, sizeof after);
    CHECK(render_scene_prepare(&s, 0, &rs, &err) == ST_OK);
    CHECK(device_list(&all, &n_all, warning, sizeof warning, &err) == ST_OK);
    CHECK(device_select(spec, all, n_all, &chosen, &n_chosen, &err) == ST_OK && n_chosen == 1);
    CHECK(device_open(&all[chosen[0]], NULL, &d, &err) == ST_OK);
    CHECK(d && d->ops->load_scene(d, &rs.ds, &err) == ST_OK);
    film_init(&ref, 160, 120, &err);
    film_init(&after, 160, 120, &err);
    if (!d || !ref.sum || !after.sum) goto out;
    atomic_store(&cancel_flag, 0);
    d->cancel = &cancel_flag;
    CHECK_EQ_INT(render_batch(d, 2, &ref, &err), ST_OK);
    /* How long a small batch (38,400 paths) takes now: the bound below grows with the
     * machine's load rather than failing on a busy one. A cancel is seen between waves,
     * and a CPU wave (2^16 to 2^17 paths) is a few of these batches. */
    double t_small = timer_now();
    CHECK_EQ_INT(render_batch(d, 2, &after, &err), ST_OK);
    t_small = timer_now() - t_small;
    memset(after.sum, 0, (size_t)160 * 120 * 3 * sizeof *after.sum);

    /* a batch of about 5M paths (seconds), cancelled after 0.1 s; timed the second time
     * (PoCL compiles variants of the kernels for the wave sizes on first use) */
    for (int timed = 0; timed < 2; timed++) {
        atomic_store(&cancel_flag, 0);
        pthread_t t;
        pthread_create(&t, NULL, cancel_later, NULL);
        double t0 = timer_now();
        Status st = d->ops->render(d, 0, 256, &err);
        double secs = timer_now() - t0;
        pthread_join(t, NULL);
        CHECK_MSG(st == ST_INTERRUPTED, "%s: the cancelled batch returned %d (%s)", spec, (int)st, err.msg);
        if (timed)
            CHECK_MSG(secs < 1.0 + 8.0 * t_small, "%s: the cancelled batch returned after %.2f s (a 2-spp batch: "
                      "%.2f s)", spec, secs, t_small);
        error_clear(&err);
    }
    /* cancelled before it starts: nothing rendered */
    CHECK_EQ_INT(d->ops->render(d, 0, 2, &err), ST_INTERRUPTED);
    error_clear(&err);

    /* nothing of the dropped batches is left in the device's film */
    atomic_store(&cancel_flag, 0);
    CHECK_EQ_INT(render_batch(d, 2, &after, &err), ST_OK);
    CHECK_MSG(memcmp(ref.sum, after.sum, (size_t)160 * 120 * 3 * sizeof *ref.sum) == 0,
              "%s: the film after cancelled batches differs", spec);
out:
    if (d) d->cancel = NULL;
    device_close(d);
    film_free(&ref);
    film_free(&after);
    free(chosen);
    free(all);
    render_scene_free(&rs);
    scene_free(&s);
    error_clear(&err);
}

static void test_cancelled_batch_is_dropped_whole(void)
{
    check_cancel_on("scalar");
    check_cancel_on("0");
}

/* --- the program itself: PFM output identical across devices, time limit, SIGINT */

static CliResult r;
#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static int read_file(const char *path, char **data, size_t *len)
{
    *data = file_util_read(path, len);
    return *data != NULL;
}

static void test_pfm_identical_across_devices(void)
{
    const char *devs[] = { "0", "1,scalar", "0,1,scalar" };
    const char *batches[] = { "1", "0", "3" };
    char *ref = NULL;
    size_t ref_len = 0;
    for (int i = 0; i < 3; i++) {
        const char *out = TEST_TMP("clpt-test-mix.pfm");
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
    const char *out = TEST_TMP("clpt-test-time.png");
    unlink(out);
    double t0 = timer_now();
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "64", "--height", "64", "--spp",
                 "1000000", "--time-limit", "1.5", "-o", out), &r);
    double secs = timer_now() - t0;
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.err, "time limit reached");
    /* a batch is about 0.25 s; allow it, plus start-up and writing, which took up to
     * 1.3 s on a 2-core machine at load 12 (2.76 s in all, 2026-11-28); the render
     * itself would take hours */
    CHECK_MSG(secs < 1.5 + 0.25 + 2.0, "took %.2f s with a 1.5 s limit", secs);
    CHECK(file_exists(out));
    unlink(out);
}

static void test_sigint_writes_partial_image(void)
{
    const char *out = TEST_TMP("clpt-test-sigint.pfm");
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


/* Waits until the child's stderr (a file) holds `text`; pread leaves the child's
 * offset alone. Returns 0 when it did not come within `seconds`. */
static int wait_for_stderr(CliChild c, const char *text, double seconds)
{
    static char buf[CLI_OUT_MAX];
    double t0 = timer_now();
    for (;;) {
        ssize_t n = pread(c.err_fd, buf, sizeof buf - 1, 0);
        buf[n > 0 ? n : 0] = '\0';
        if (strstr(buf, text)) return 1;
        if (timer_now() - t0 > seconds) return 0;
        struct timespec ts = { 0, 1000000L };
        nanosleep(&ts, NULL);
    }
}

/* Whether the child has exited, without reaping it. */
static int child_exited(CliChild c)
{
    siginfo_t info;
    memset(&info, 0, sizeof info);
    return waitid(P_PID, (id_t)c.pid, &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == c.pid;
}

/* Waits for the child at most `seconds` (then kills it, so a test that fails does not
 * hang), collects its output and returns how long it took. */
static double finish_within(CliChild c, double seconds, CliResult *res)
{
    double t0 = timer_now();
    while (!child_exited(c) && timer_now() - t0 < seconds) {
        struct timespec ts = { 0, 5000000L };
        nanosleep(&ts, NULL);
    }
    double took = timer_now() - t0;
    if (!child_exited(c)) kill(c.pid, SIGKILL);
    cli_finish(c, res);
    return took;
}

/* One batch of 512 x 512 x 4096 paths: many minutes on the scalar device. */
static CliChild start_huge_batch(const char *out)
{
    unlink(out);
    CliChild c = cli_start(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "512", "--height", "512",
                                "--spp", "4096", "--batch", "4096", "-o", out));
    /* the first progress line says the render (and the signal handlers) are in place */
    CHECK(wait_for_stderr(c, "clpt: render", 30.0));
    struct timespec ts = { 0, 500000000L };
    nanosleep(&ts, NULL);
    return c;
}

static void check_signal_stops_huge_batch(int sig)
{
    const char *out = TEST_TMP("clpt-test-cancel.pfm");
    CliChild c = start_huge_batch(out);
    kill(c.pid, sig);
    double secs = finish_within(c, 10.0, &r);
    CHECK_MSG(secs < 3.0, "signal %d: the render took %.2f s to stop", sig, secs);
    CHECK_EQ_INT(r.status, 6);
    CHECK_STR_CONTAINS(r.err, "clpt: stopping: writing what is finished");
    /* no batch finished: nothing is written and the old output is left as it was */
    CHECK_STR_CONTAINS(r.err, "interrupted before the first batch finished: nothing was rendered");
    unlink(out);
}

static void test_sigint_stops_within_a_second(void)
{
    check_signal_stops_huge_batch(SIGINT);
}

static void test_sigterm_stops_within_a_second(void)
{
    check_signal_stops_huge_batch(SIGTERM);
}

/* The second signal must come while the first one's stop is still under way (the
 * render notices it within 0.1 s, then writes): a try where the program was quicker
 * is repeated. */
static void test_second_sigint_quits_at_once(void)
{
    const char *out = TEST_TMP("clpt-test-cancel2.pfm");
    int caught = 0;
    for (int attempt = 0; attempt < 5 && !caught; attempt++) {
        CliChild c = start_huge_batch(out);
        kill(c.pid, SIGINT);
        CHECK(wait_for_stderr(c, "clpt: stopping", 5.0));
        int raced = child_exited(c);
        if (!raced) kill(c.pid, SIGINT);
        double secs = finish_within(c, 10.0, &r);
        CHECK_MSG(secs < 3.0, "the render took %.2f s to end after the second SIGINT", secs);
        if (raced || r.status == 6) continue;
        caught = 1;
        CHECK_MSG(r.status == 128 + SIGINT, "status %d after two SIGINTs: %s", r.status, r.err);
        /* ended by the signal: no summary line */
        CHECK(strstr(r.err, "interrupted:") == NULL);
    }
    CHECK_MSG(caught, "the program always ended before the second SIGINT came");
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
    RUN(test_cancelled_batch_is_dropped_whole);
    RUN(test_sigint_stops_within_a_second);
    RUN(test_sigterm_stops_within_a_second);
    RUN(test_second_sigint_quits_at_once);
    scene_free(&base);
    return harness_report();
}
