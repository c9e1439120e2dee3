/*
 * bench_schedule.c — how rendering scales over devices, and what the scheduler costs.
 *
 *   build/bench/bench_schedule [--reps N] [--retry-seconds S] [--json FILE] [SCENE:WIDTHxHEIGHT:SPP]
 *
 * Scaling: renders the scene through the scheduler with each device configuration —
 * one PoCL device with 1 thread, one with 2 threads, two PoCL devices with 1 thread
 * each, PoCL (1 thread) plus the scalar device (1 thread), and the parts alone — and
 * reports samples/s and the efficiency against the sum of the parts' separate rates
 * (the goal: 95% for two devices). PoCL reads its device
 * configuration (POCL_DEVICES, POCL_MAX_PTHREAD_COUNT) from the environment when the ICD
 * loads, so each configuration runs in a child process: this program re-executes itself
 * with the environment set. Repetitions go round the configurations (rep 1 of each, then
 * rep 2 ...) so that a slow spell of a shared machine hits them alike; medians are
 * reported. Before timing anything it checks that every configuration produced the same
 * image bits (SHA-256 of the film).
 *
 * Scheduler overhead: one device rendering the same samples through schedule_run
 * (adaptive batches, film merges, a host thread) and alone (one direct render call),
 * alternated in one process, for the PoCL device and the scalar device, with four times
 * the samples of the scaling runs so that most batches have their steady size. (The
 * scalar device renders all samples of a pixel in a row, and more of them in a row run
 * a little faster, so part of its overhead is the batch size itself.)
 *
 * On a shared machine other processes steal cores and scaling numbers mean nothing, so
 * every timed run is checked: the machine's busy time (/proc/stat) minus this program's
 * own CPU time is what others used meanwhile, and a run during which they used more
 * than 10% of the machine is thrown away and repeated, for at most --retry-seconds in
 * all (default 180); the table says how many runs were repeated and marks a result it
 * had to keep anyway.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "device/device.h"
#include "render/film.h"
#include "render/render_scene.h"
#include "render/schedule.h"
#include "base/sha256.h"
#include "base/timer.h"

#define MAX_REPS 15
#define MAX_FOREIGN 0.10

/* Seconds left for repeating runs spoilt by other processes (shared by parent and
 * child: the child gets what is left on its command line). */
static double retry_budget = 180.0;

/* ------------------------------------------------------------------ other processes */

/* Busy and total CPU time of the whole machine, and the CPU time of this process or of
 * its finished children, at one moment. */
typedef struct {
    double busy, wall, own;
} Meter;

static double cpu_seconds(int who)
{
    struct rusage ru;
    getrusage(who, &ru);
    return (double)ru.ru_utime.tv_sec + (double)ru.ru_stime.tv_sec +
           1e-6 * ((double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_usec);
}

static Meter meter_read(int who)
{
    Meter m = { 0.0, timer_now(), cpu_seconds(who) };
    FILE *f = fopen("/proc/stat", "r");
    unsigned long long v[8] = { 0 };
    if (f) {
        if (fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5],
                   &v[6], &v[7]) == 8) {
            double ticks = (double)sysconf(_SC_CLK_TCK);
            m.busy = (double)(v[0] + v[1] + v[2] + v[5] + v[6] + v[7]) / ticks;   /* not idle, not iowait */
        }
        fclose(f);
    }
    return m;
}

/* The share of the machine that other processes used since `a`. */
static double meter_foreign(Meter a, int who)
{
    Meter b = meter_read(who);
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    double capacity = (b.wall - a.wall) * (double)(cores > 0 ? cores : 1);
    double foreign = (b.busy - a.busy) - (b.own - a.own);
    return capacity > 0.0 && foreign > 0.0 ? foreign / capacity : 0.0;
}

typedef struct {
    const char *name;          /* row label */
    const char *pocl_devices;  /* POCL_DEVICES */
    const char *pocl_threads;  /* POCL_MAX_PTHREAD_COUNT, NULL: PoCL's default (every core) */
    const char *devices;       /* --device spec */
    int scalar_threads;
    int part_a, part_b;        /* rows whose rates sum to this one's ideal; -1: none */
} Config;

/* PoCL 3.1 runs every pthread device of a process on one shared pool of worker threads
 * (sized by the first device), so two pthread devices cannot have a thread each; a
 * `basic` device runs its kernels on the host thread that drives it. Two devices with
 * one thread each are therefore a basic plus a 1-thread pthread device. (Two basic
 * devices in one process trip an assertion in PoCL 3.1's kernel handle cache.) */
static const Config configs[] = {
    { "PoCL pthread, 1 thread", "pthread", "1", "0", 1, -1, -1 },
    { "PoCL basic (1 thread)", "basic", "1", "0", 1, -1, -1 },
    { "scalar, 1 thread", "pthread", "1", "scalar", 1, -1, -1 },
    { "PoCL pthread, 2 threads", "pthread", "2", "0", 1, 0, 0 },
    { "2 PoCL devices, 1 thread each", "basic pthread", "1", "0,1", 1, 1, 0 },
    { "2 PoCL devices on a 2-thread pool", "pthread pthread", "2", "0,1", 1, 0, 0 },
    { "PoCL 1 thread + scalar 1 thread", "pthread", "1", "0,scalar", 1, 0, 2 },
};
enum { N_CONFIGS = sizeof configs / sizeof configs[0] };

typedef struct {
    char path[512];
    uint width, height, spp;
} BenchScene;

typedef struct {
    double sps;                        /* samples per second */
    char hash[65];                     /* the film's SHA-256 */
    char devices[1024];                /* per device: name, share, batch sizes */
    int ok;
} ChildResult;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(const double *v, int n)
{
    double s[MAX_REPS];
    memcpy(s, v, (size_t)n * sizeof *s);
    qsort(s, (size_t)n, sizeof *s, cmp_double);
    return n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
}

/* ------------------------------------------------------------------ in the child */

typedef struct {
    RenderScene rs;
    Scene scene;
    Device **devs;
    size_t n;
} Setup;

static int setup_open(const BenchScene *bs, const char *spec, int scalar_threads, Setup *s)
{
    Error err = { 0 };
    memset(s, 0, sizeof *s);
    scene_init(&s->scene);
    DeviceDesc *all = NULL;
    size_t n_all = 0, *chosen = NULL, n_chosen = 0;
    char warning[1100];
    int ok = 0;
    if (scene_load(bs->path, &s->scene, &err)) goto out;
    s->scene.image.width = bs->width;
    s->scene.image.height = bs->height;
    if (render_scene_prepare(&s->scene, 0, &s->rs, &err)) goto out;
    if (device_list(&all, &n_all, warning, sizeof warning, &err)) goto out;
    if (device_select(spec, all, n_all, &chosen, &n_chosen, &err)) goto out;
    s->devs = calloc(n_chosen, sizeof *s->devs);
    DeviceConfig cfg = { .threads = scalar_threads };
    for (size_t i = 0; i < n_chosen; i++) {
        if (device_open(&all[chosen[i]], &cfg, &s->devs[s->n], &err)) goto out;
        s->n++;
        if (s->devs[s->n - 1]->ops->load_scene(s->devs[s->n - 1], &s->rs.ds, &err)) goto out;
    }
    ok = 1;
out:
    if (!ok) fprintf(stderr, "bench_schedule: %s: %s\n", spec, err.msg);
    error_clear(&err);
    free(all);
    free(chosen);
    return ok;
}

static void setup_close(Setup *s)
{
    for (size_t i = 0; i < s->n; i++) device_close(s->devs[i]);
    free(s->devs);
    render_scene_free(&s->rs);
    scene_free(&s->scene);
}

/* Renders spp samples through the scheduler; returns samples/s (0 on failure). */
static double scheduled(Setup *s, uint spp, Film *film, ScheduleStats *st)
{
    Error err = { 0 };
    ScheduleConfig cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = spp;
    if (film_init(film, s->rs.ds.params.width, s->rs.ds.params.height, &err)) return 0.0;
    double t0 = timer_now();
    Status rc = schedule_run(s->devs, s->n, &cfg, film, st, &err);
    double secs = timer_now() - t0;
    if (rc) fprintf(stderr, "bench_schedule: %s\n", err.msg);
    error_clear(&err);
    return rc ? 0.0 : (double)film->width * film->height * spp / secs;
}

/* The same samples as one direct render call on device 0, no scheduler. */
static double direct(Setup *s, uint spp)
{
    Error err = { 0 };
    Device *d = s->devs[0];
    int64_t *film = calloc((size_t)d->n_pixels * 3u, sizeof *film);
    double t0 = timer_now();
    Status rc = film ? d->ops->render(d, 0, spp, &err) : ST_INTERNAL;
    if (!rc) rc = d->ops->take_film(d, film, &err);
    double secs = timer_now() - t0;
    free(film);
    error_clear(&err);
    return rc ? 0.0 : (double)d->n_pixels * spp / secs;
}

/* One scheduled render; prints "sps=... hash=... devices=..." for the parent. */
static int child_scaling(const BenchScene *bs, const char *spec, int scalar_threads)
{
    Setup s;
    if (!setup_open(bs, spec, scalar_threads, &s)) return 1;
    Film film;
    ScheduleStats st;
    double sps = scheduled(&s, 1, &film, &st);   /* warm-up: caches, PoCL specialisation */
    film_free(&film);
    schedule_stats_free(&st);
    sps = scheduled(&s, bs->spp, &film, &st);
    unsigned char digest[SHA256_DIGEST_SIZE];
    char hex[65];
    sha256(film.sum, (size_t)film.width * film.height * 3u * sizeof *film.sum, digest);
    sha256_hex(digest, hex);
    printf("sps=%.1f hash=%s devices=", sps, hex);
    for (size_t i = 0; i < st.n_devices; i++) {
        const DeviceRunStats *d = &st.devices[i];
        printf("%s%s: %.0f%% of the samples, batches %u-%u spp (last %u)", i ? "; " : "", d->name,
               st.samples ? 100.0 * (double)d->samples / (double)st.samples : 0.0, d->batch_min, d->batch_max,
               d->batch_last);
    }
    printf("\n");
    film_free(&film);
    schedule_stats_free(&st);
    setup_close(&s);
    return sps > 0.0 ? 0 : 1;
}

/* Alternates direct and scheduled renders of one device; prints both medians. */
static int child_overhead(const BenchScene *bs, const char *spec, int reps)
{
    Setup s;
    if (!setup_open(bs, spec, 0, &s)) return 1;
    double d[MAX_REPS], sc[MAX_REPS];
    Film film;
    ScheduleStats st;
    direct(&s, 1);
    uint spp = 4u * bs->spp;
    int repeated = 0, tainted = 0;
    double t_start = timer_now();
    for (int r = 0; r < reps; r++) {
        for (;;) {
            Meter m = meter_read(RUSAGE_SELF);
            d[r] = direct(&s, spp);
            sc[r] = scheduled(&s, spp, &film, &st);
            film_free(&film);
            schedule_stats_free(&st);
            if (meter_foreign(m, RUSAGE_SELF) <= MAX_FOREIGN) break;
            if (timer_now() - t_start > retry_budget) {
                tainted++;
                break;
            }
            repeated++;
        }
    }
    printf("direct=%.1f scheduled=%.1f repeated=%d tainted=%d\n", median(d, reps), median(sc, reps), repeated,
           tainted);
    setup_close(&s);
    return 0;
}

/* ------------------------------------------------------------------ in the parent */

/* Runs this program again with `args` and the PoCL environment; its stdout into out. */
static int run_child(const char *self, const Config *c, char *const *args, char *out, size_t cap)
{
    int fds[2];
    if (pipe(fds) != 0) return 0;
    pid_t pid = fork();
    if (pid < 0) return 0;
    if (pid == 0) {
        dup2(fds[1], 1);
        close(fds[0]);
        close(fds[1]);
        setenv("POCL_DEVICES", c->pocl_devices, 1);
        if (c->pocl_threads) setenv("POCL_MAX_PTHREAD_COUNT", c->pocl_threads, 1);
        else unsetenv("POCL_MAX_PTHREAD_COUNT");
        execv(self, args);
        _exit(127);
    }
    close(fds[1]);
    size_t n = 0;
    ssize_t k;
    while (n + 1 < cap && (k = read(fds[0], out + n, cap - 1 - n)) > 0) n += (size_t)k;
    out[n] = '\0';
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

static void scene_arg(const BenchScene *bs, char *buf, size_t size)
{
    snprintf(buf, size, "%s:%ux%u:%u", bs->path, bs->width, bs->height, bs->spp);
}

static int parse_scene(const char *arg, BenchScene *bs)
{
    return sscanf(arg, "%511[^:]:%ux%u:%u", bs->path, &bs->width, &bs->height, &bs->spp) == 4 && bs->width &&
           bs->height && bs->spp;
}

int main(int argc, char **argv)
{
    int reps = 3;
    const char *json_path = "build/bench/schedule.json";
    BenchScene bs = { "scenes/cornell-box.scene", 160, 120, 32 };
    const char *child = NULL, *spec = NULL;
    int scalar_threads = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--json") == 0 && i + 1 < argc) json_path = argv[++i];
        else if (strcmp(argv[i], "--retry-seconds") == 0 && i + 1 < argc) retry_budget = atof(argv[++i]);
        else if (strcmp(argv[i], "--child") == 0 && i + 3 < argc) {
            child = argv[++i];
            spec = argv[++i];
            scalar_threads = atoi(argv[++i]);
        } else if (!parse_scene(argv[i], &bs)) {
            fprintf(stderr, "usage: bench_schedule [--reps N] [--retry-seconds S] [--json FILE] "
                            "[SCENE:WIDTHxHEIGHT:SPP]\n");
            return 2;
        }
    }
    if (reps < 1) reps = 1;
    if (reps > MAX_REPS) reps = MAX_REPS;
    if (child && strcmp(child, "scaling") == 0) return child_scaling(&bs, spec, scalar_threads);
    if (child && strcmp(child, "overhead") == 0) return child_overhead(&bs, spec, reps);

    char self[4096];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len <= 0) {
        fprintf(stderr, "bench_schedule: cannot find its own executable: %s\n", strerror(errno));
        return 1;
    }
    self[len] = '\0';
    char scene_text[600], threads_text[16], reps_text[16], out[4096];
    scene_arg(&bs, scene_text, sizeof scene_text);
    snprintf(reps_text, sizeof reps_text, "%d", reps);

    printf("clpt scheduling benchmark: %s %ux%u, %u spp; median of %d runs per configuration\n\n", bs.path, bs.width,
           bs.height, bs.spp, reps);
    double t_start = timer_now();
    double rate[N_CONFIGS][MAX_REPS];
    char hash[N_CONFIGS][65], devices[N_CONFIGS][1024];
    int ok[N_CONFIGS], repeated = 0, tainted[N_CONFIGS];
    for (int c = 0; c < N_CONFIGS; c++) ok[c] = 1, tainted[c] = 0;
    for (int r = 0; r < reps; r++)
        for (int c = 0; c < N_CONFIGS; c++) {
            snprintf(threads_text, sizeof threads_text, "%d", configs[c].scalar_threads);
            char *args[] = { self, (char[]){ "--child" }, (char[]){ "scaling" }, (char *)configs[c].devices, threads_text,
                             scene_text, NULL };
            for (int attempt = 0;; attempt++) {
                rate[c][r] = 0.0;
                char h[65] = "";
                Meter m = meter_read(RUSAGE_CHILDREN);
                if (!run_child(self, &configs[c], args, out, sizeof out) ||
                    sscanf(out, "sps=%lf hash=%64s devices=%1023[^\n]", &rate[c][r], h, devices[c]) != 3) {
                    ok[c] = 0;
                    break;
                }
                if (r == 0 && attempt == 0) memcpy(hash[c], h, sizeof h);
                else if (strcmp(h, hash[c]) != 0) ok[c] = 0;
                if (meter_foreign(m, RUSAGE_CHILDREN) <= MAX_FOREIGN) break;
                if (timer_now() - t_start > retry_budget) {
                    tainted[c]++;
                    break;
                }
                repeated++;
            }
        }
    int identical = 1;
    for (int c = 0; c < N_CONFIGS; c++) identical &= ok[c] && strcmp(hash[c], hash[0]) == 0;
    printf("image check: %s\n", identical ? "every configuration rendered the same film bits"
                                          : "FAILED: the films differ between configurations (or a run failed)");
    printf("runs repeated because other processes used more than %.0f%% of the machine: %d\n\n",
           100.0 * MAX_FOREIGN, repeated);

    double med[N_CONFIGS];
    printf("%-36s %12s %14s %10s\n", "configuration", "Msamples/s", "sum of parts", "efficiency");
    for (int c = 0; c < N_CONFIGS; c++) {
        med[c] = ok[c] ? median(rate[c], reps) : 0.0;
        const Config *cf = &configs[c];
        const char *mark = tainted[c] ? "  (measured on a busy machine)" : "";
        if (cf->part_a < 0) {
            printf("%-36s %12.3f %14s %10s%s\n", cf->name, med[c] / 1e6, "-", "-", mark);
        } else {
            double parts = med[cf->part_a] + med[cf->part_b];
            printf("%-36s %12.3f %14.3f %9.1f%%%s\n", cf->name, med[c] / 1e6, parts / 1e6,
                   parts > 0.0 ? 100.0 * med[c] / parts : 0.0, mark);
        }
    }
    printf("\nbatch sizes chosen (last run of each):\n");
    for (int c = 0; c < N_CONFIGS; c++)
        if (ok[c]) printf("  %-34s %s\n", configs[c].name, devices[c]);

    /* scheduler overhead, each device with every core */
    static const Config over[] = {
        { "PoCL, 2 threads", "pthread", NULL, "0", 0, -1, -1 },
        { "scalar, 2 threads", "pthread", NULL, "scalar", 0, -1, -1 },
    };
    double o_direct[2] = { 0, 0 }, o_sched[2] = { 0, 0 };
    int o_repeated = 0, o_tainted = 0;
    printf("\nscheduler overhead, %u spp (the same device alone, one render call, vs through the scheduler):\n",
           4u * bs.spp);
    printf("%-34s %12s %12s %10s\n", "device", "alone", "scheduled", "overhead");
    for (int i = 0; i < 2; i++) {
        char budget_text[32];
        double left = retry_budget - (timer_now() - t_start);
        snprintf(budget_text, sizeof budget_text, "%.0f", left > 0.0 ? left / 2.0 : 0.0);
        char *args[] = { self, (char[]){ "--child" }, (char[]){ "overhead" }, (char *)over[i].devices,
                         (char[]){ "0" }, scene_text, (char[]){ "--reps" }, reps_text,
                         (char[]){ "--retry-seconds" }, budget_text, NULL };
        int rep_i = 0, taint_i = 0;
        if (!run_child(self, &over[i], args, out, sizeof out) ||
            sscanf(out, "direct=%lf scheduled=%lf repeated=%d tainted=%d", &o_direct[i], &o_sched[i], &rep_i,
                   &taint_i) != 4) {
            printf("%-34s failed\n", over[i].name);
            continue;
        }
        o_repeated += rep_i;
        o_tainted += taint_i;
        printf("%-34s %12.3f %12.3f %9.1f%%%s\n", over[i].name, o_direct[i] / 1e6, o_sched[i] / 1e6,
               o_direct[i] > 0.0 ? 100.0 * (1.0 - o_sched[i] / o_direct[i]) : 0.0,
               taint_i ? "  (measured on a busy machine)" : "");
    }
    printf("(pairs repeated because of other processes: %d)\n", o_repeated);

    FILE *json = fopen(json_path, "w");
    if (json) {
        fprintf(json, "{\n  \"scene\": \"%s\", \"width\": %u, \"height\": %u, \"spp\": %u, \"reps\": %d,\n"
                      "  \"images_identical\": %s, \"runs_repeated\": %d, \"overhead_pairs_repeated\": %d,\n"
                      "  \"scaling\": [\n",
                bs.path, bs.width, bs.height, bs.spp, reps, identical ? "true" : "false", repeated, o_repeated);
        for (int c = 0; c < N_CONFIGS; c++) {
            const Config *cf = &configs[c];
            double parts = cf->part_a < 0 ? 0.0 : med[cf->part_a] + med[cf->part_b];
            fprintf(json, "    {\"configuration\": \"%s\", \"samples_per_s\": %.1f, \"sum_of_parts\": %.1f, "
                          "\"efficiency\": %.4f, \"busy_machine_runs\": %d}%s\n",
                    cf->name, med[c], parts, parts > 0.0 ? med[c] / parts : 0.0, tainted[c],
                    c + 1 < N_CONFIGS ? "," : "");
        }
        fprintf(json, "  ],\n  \"scheduler_overhead\": [\n");
        for (int i = 0; i < 2; i++)
            fprintf(json, "    {\"device\": \"%s\", \"alone_samples_per_s\": %.1f, \"scheduled_samples_per_s\": %.1f}%s\n",
                    over[i].name, o_direct[i], o_sched[i], i ? "" : ",");
        fprintf(json, "  ],\n  \"overhead_busy_machine_pairs\": %d\n}\n", o_tainted);
        fclose(json);
        printf("\nJSON: %s\n", json_path);
    }
    return identical ? 0 : 1;
}
