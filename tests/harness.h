/*
 * harness.h — a minimal test harness. Each tests/test_*.c is a program:
 *
 *     static void test_something(void) { CHECK(x == 1); CHECK_NEAR(a, b, 1e-6); }
 *     int main(void) { RUN(test_something); return harness_report(); }
 *
 * A test passes when none of its checks fail. A failed check prints file:line and the
 * expression (and values) and the test goes on, so one run shows every failure.
 * harness_report() prints "N passed, M failed" and returns the exit status.
 */
#ifndef CLPT_HARNESS_H
#define CLPT_HARNESS_H

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static int harness_passed, harness_failed, harness_current_failed;
static const char *harness_current = "";

/* The OpenCL devices that the tests compare with the scalar device, as a --device spec:
 * PoCL's CPU devices ("cpu"), or CLPT_TEST_OPENCL=gpu, so that the same bit-for-bit
 * checks run on a GPU (tools/gpu-check.sh). The kernel tests, which open one device
 * themselves, take the first OpenCL device of that type. */
static inline const char *test_opencl_spec(void)
{
    const char *s = getenv("CLPT_TEST_OPENCL");
    return s && strcmp(s, "gpu") == 0 ? "gpu" : "cpu";
}
#define TEST_OPENCL test_opencl_spec()
#define TEST_OPENCL_IS_GPU (strcmp(test_opencl_spec(), "gpu") == 0)

#define CHECK(cond)                                                                    \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "  FAIL %s:%d [%s]: %s\n", __FILE__, __LINE__,             \
                    harness_current, #cond);                                           \
            harness_current_failed++;                                                  \
        }                                                                              \
    } while (0)

#define CHECK_MSG(cond, ...)                                                           \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "  FAIL %s:%d [%s]: %s: ", __FILE__, __LINE__,             \
                    harness_current, #cond);                                           \
            fprintf(stderr, __VA_ARGS__);                                              \
            fputc('\n', stderr);                                                       \
            harness_current_failed++;                                                  \
        }                                                                              \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                          \
    do {                                                                               \
        double ha_ = (double)(a), hb_ = (double)(b);                                   \
        if (!(fabs(ha_ - hb_) <= (double)(tol))) {                                     \
            fprintf(stderr, "  FAIL %s:%d [%s]: %s = %.9g, %s = %.9g, tolerance %g\n", \
                    __FILE__, __LINE__, harness_current, #a, ha_, #b, hb_,             \
                    (double)(tol));                                                    \
            harness_current_failed++;                                                  \
        }                                                                              \
    } while (0)

#define CHECK_EQ_INT(a, b)                                                             \
    do {                                                                               \
        long long ha_ = (long long)(a), hb_ = (long long)(b);                          \
        if (ha_ != hb_) {                                                              \
            fprintf(stderr, "  FAIL %s:%d [%s]: %s = %lld, expected %s = %lld\n",      \
                    __FILE__, __LINE__, harness_current, #a, ha_, #b, hb_);            \
            harness_current_failed++;                                                  \
        }                                                                              \
    } while (0)

#define CHECK_STR_CONTAINS(hay, needle)                                                \
    do {                                                                               \
        const char *hh_ = (hay), *hn_ = (needle);                                      \
        if (!hh_ || !strstr(hh_, hn_)) {                                               \
            fprintf(stderr, "  FAIL %s:%d [%s]: \"%s\" does not contain \"%s\"\n",     \
                    __FILE__, __LINE__, harness_current, hh_ ? hh_ : "(null)", hn_);   \
            harness_current_failed++;                                                  \
        }                                                                              \
    } while (0)

#define RUN(fn)                                                                        \
    do {                                                                               \
        harness_current = #fn;                                                         \
        harness_current_failed = 0;                                                    \
        fn();                                                                          \
        if (harness_current_failed) {                                                  \
            harness_failed++;                                                          \
            fprintf(stderr, "FAIL %s\n", #fn);                                         \
        } else {                                                                       \
            harness_passed++;                                                          \
            fprintf(stderr, "ok   %s\n", #fn);                                         \
        }                                                                              \
    } while (0)

/* Readers must be linear in their input. A test of that times one parse of n items
 * and one of GROWTH_FACTOR * n, in CPU seconds of this process (other jobs on a
 * shared machine don't count), and checks the ratio: about 8 when linear, 64 when
 * quadratic. A ratio rather than a bound in seconds, because sanitizers, valgrind and
 * slow machines stretch both parses alike. The small parse's time is floored at
 * 5 ms so that clock noise on a tiny input cannot make a linear reader fail. */
#define GROWTH_FACTOR 8
#define GROWTH_RATIO_MAX 24.0

static inline double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#define CHECK_LINEAR(what, secs_n, secs_8n)                                            \
    do {                                                                               \
        double hs_ = (secs_n), hb_ = (secs_8n);                                        \
        double hr_ = hb_ / (hs_ > 0.005 ? hs_ : 0.005);                                \
        CHECK_MSG(hr_ < GROWTH_RATIO_MAX,                                              \
                  "%s: %.3f s of CPU time for %d times the input of %.3f s (ratio %.1f, " \
                  "linear is about %d)", what, hb_, GROWTH_FACTOR, hs_, hr_, GROWTH_FACTOR); \
    } while (0)

/* The team's standard meshes live in ../shared/models, beside the checkout (and in CI).
 * A test that reads one calls this first: in a checkout without them it says what it
 * skips, on stderr, and the rest of the test still runs. */
static inline int shared_model_present(const char *path, const char *skipped)
{
    FILE *f = fopen(path, "rb");
    if (f) {
        fclose(f);
        return 1;
    }
    fprintf(stderr, "  %s not found: %s\n", path, skipped);
    return 0;
}

/* The entries of folder `dir` whose names end in `suffix` ("" for all, "." and ".."
 * left out); -1 when the folder cannot be read. For the kernel-cache tests. */
static inline int count_dir_entries(const char *dir, const char *suffix)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    int n = 0;
    size_t ls = strlen(suffix);
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t l = strlen(e->d_name);
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        if (l >= ls && strcmp(e->d_name + l - ls, suffix) == 0) n++;
    }
    closedir(d);
    return n;
}

/* Scratch files private to this test process. Two test runs at once (two checkouts,
 * a developer and CI) once shared fixed names under /tmp, so one run rewrote the image
 * the other was about to compare. Every file a test writes now goes into one folder
 * made with mkdtemp ($TMPDIR or /tmp) at its first use and removed, with what is in it,
 * when the process exits.
 *
 *     const char *out = TEST_TMP("render.pfm");    the same pointer for the same name
 *     test_tmp_path(buf, sizeof buf, "a.pfm");      into a caller's buffer
 *
 * A process that cannot make the folder stops at once: running on with a shared name
 * would bring back the very collisions this avoids. */
#define TEST_TMP_NAMES_MAX 256

static inline void test_tmp_remove_tree(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0) return;
    if (S_ISDIR(st.st_mode)) {
        chmod(path, 0700);   /* a test may leave a read-only folder to check a write error */
        DIR *d = opendir(path);
        if (d) {
            struct dirent *e;
            char child[4096];
            while ((e = readdir(d)))
                if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") &&
                    snprintf(child, sizeof child, "%s/%s", path, e->d_name) < (int)sizeof child)
                    test_tmp_remove_tree(child);
            closedir(d);
        }
        rmdir(path);
    } else {
        unlink(path);
    }
}

static char test_tmp_dir_buf[4096];
static pid_t test_tmp_owner;
static char *test_tmp_names[TEST_TMP_NAMES_MAX];
static int test_tmp_name_count;

static inline void test_tmp_cleanup(void)
{
    /* a forked child that exits through exit() runs this too; only the maker removes */
    if (getpid() != test_tmp_owner) return;
    test_tmp_remove_tree(test_tmp_dir_buf);
    for (int i = 0; i < test_tmp_name_count; i++) free(test_tmp_names[i]);
    test_tmp_name_count = 0;
}

/* This process's scratch folder, made at the first call. */
static inline const char *test_tmp_dir(void)
{
    if (test_tmp_dir_buf[0]) return test_tmp_dir_buf;
    const char *base = getenv("TMPDIR");
    if (!base || !*base) base = "/tmp";
    snprintf(test_tmp_dir_buf, sizeof test_tmp_dir_buf, "%s/clpt-test-XXXXXX", base);
    if (!mkdtemp(test_tmp_dir_buf)) {
        perror("test_tmp_dir: mkdtemp");
        exit(2);
    }
    test_tmp_owner = getpid();
    atexit(test_tmp_cleanup);
    return test_tmp_dir_buf;
}

/* DIR/name written into buf; returns buf. */
static inline char *test_tmp_path(char *buf, size_t size, const char *name)
{
    int n = snprintf(buf, size, "%s/%s", test_tmp_dir(), name);
    if (n < 0 || (size_t)n >= size) {
        fprintf(stderr, "test_tmp_path: '%s' does not fit in %zu bytes\n", name, size);
        exit(2);
    }
    return buf;
}

/* DIR/name in a buffer kept until exit, one per name, so that it can sit in an
 * initialiser or be compared with what the program printed. */
static inline const char *test_tmp(const char *name)
{
    const char *dir = test_tmp_dir();
    size_t dl = strlen(dir);
    for (int i = 0; i < test_tmp_name_count; i++)
        if (strcmp(test_tmp_names[i] + dl + 1, name) == 0) return test_tmp_names[i];
    size_t size = dl + 1 + strlen(name) + 1;
    char *p = malloc(size);
    if (!p || test_tmp_name_count == TEST_TMP_NAMES_MAX) {
        fprintf(stderr, "test_tmp: no room for '%s' (%d names at most)\n", name,
                TEST_TMP_NAMES_MAX);
        exit(2);
    }
    test_tmp_names[test_tmp_name_count++] = test_tmp_path(p, size, name);
    return p;
}
#define TEST_TMP(name) test_tmp(name)

static inline int harness_report(void)
{
    printf("%d passed, %d failed\n", harness_passed, harness_failed);
    return harness_failed ? 1 : 0;
}

#endif /* CLPT_HARNESS_H */
