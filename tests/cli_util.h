/* cli_util.h — runs the clpt program as a user would and captures what it prints. */
#ifndef CLPT_CLI_UTIL_H
#define CLPT_CLI_UTIL_H

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "harness.h"

/* The Makefile passes its build folder (build, build-asan), so each build's tests run
 * that build's program. */
#ifndef CLPT_BUILD_DIR
#define CLPT_BUILD_DIR "build"
#endif
#define CLI_PROGRAM CLPT_BUILD_DIR "/clpt"
#define CLI_OUT_MAX 65536

typedef struct {
    int status;                 /* exit code, or 128 + signal */
    char out[CLI_OUT_MAX];      /* stdout */
    char err[CLI_OUT_MAX];      /* stderr */
} CliResult;

static inline void cli_slurp(int fd, char *buf)
{
    lseek(fd, 0, SEEK_SET);
    ssize_t n = read(fd, buf, CLI_OUT_MAX - 1);
    buf[n > 0 ? n : 0] = '\0';
}

/* argv without the program name, NULL-terminated. Runs from the repository root (where
 * make test runs). Returns the child's pid through *pid_out if non-NULL and does not
 * wait when `wait_for` is 0 (the caller then calls cli_finish). */
typedef struct {
    pid_t pid;
    int out_fd, err_fd;
} CliChild;

static inline CliChild cli_start(const char *const *args)
{
    CliChild c;
    char out_name[] = "/tmp/clpt-cli-out-XXXXXX", err_name[] = "/tmp/clpt-cli-err-XXXXXX";
    c.out_fd = mkstemp(out_name);
    c.err_fd = mkstemp(err_name);
    unlink(out_name);
    unlink(err_name);
    const char *argv[64];
    int n = 0;
    argv[n++] = CLI_PROGRAM;
    for (; args[n - 1] && n < 63; n++) argv[n] = args[n - 1];
    argv[n] = NULL;
    c.pid = fork();
    if (c.pid == 0) {
        dup2(c.out_fd, 1);
        dup2(c.err_fd, 2);
        execv(CLI_PROGRAM, (char *const *)argv);
        _exit(127);
    }
    return c;
}

static inline void cli_finish(CliChild c, CliResult *r)
{
    int wstatus = 0;
    waitpid(c.pid, &wstatus, 0);
    r->status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
    cli_slurp(c.out_fd, r->out);
    cli_slurp(c.err_fd, r->err);
    close(c.out_fd);
    close(c.err_fd);
}

/* Whether the child's LeakSanitizer crashed at exit (docs/hardening.md): its tracer
 * misread the dynamic thread-local storage, a fault of the sanitizer, not a leak (a leak
 * is reported as "detected memory leaks"). */
static inline int cli_tracer_fault(const CliResult *r)
{
    return r->status != 0 && strstr(r->err, "Tracer caught signal") &&
           strstr(r->err, "LeakSanitizer has encountered a fatal error");
}

/* Runs clpt to the end. Under the sanitizers, a run whose LeakSanitizer crashed as above
 * runs again once with thread-local storage left out of the leak scan (use_tls=0),
 * which is what the tracer misreads; the leak check itself stays on. */
static inline void cli_run(const char *const *args, CliResult *r)
{
    cli_finish(cli_start(args), r);
    if (!cli_tracer_fault(r)) return;
    const char *old = getenv("LSAN_OPTIONS");
    char *saved = old ? strdup(old) : NULL, opts[1024];
    snprintf(opts, sizeof opts, "%s%suse_tls=0", old ? old : "", old && old[0] ? ":" : "");
    fprintf(stderr, "  clpt's LeakSanitizer crashed at exit (%.60s...); running it again with use_tls=0\n",
            strstr(r->err, "Tracer caught signal"));
    setenv("LSAN_OPTIONS", opts, 1);
    cli_finish(cli_start(args), r);
    if (saved) setenv("LSAN_OPTIONS", saved, 1);
    else unsetenv("LSAN_OPTIONS");
    free(saved);
}

/* Whether two files hold the same bytes (and both exist): the bit-for-bit checks of
 * images and checkpoints. */
static inline int files_equal(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb;
    while (same) {
        int ca = fgetc(fa), cb = fgetc(fb);
        if (ca != cb) same = 0;
        if (ca == EOF || cb == EOF) break;
    }
    if (fa) fclose(fa);
    if (fb) fclose(fb);
    return same;
}

static inline int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Writes text to a new temporary file with the given suffix; returns its path (static
 * buffer per call site is the caller's: pass one in). */
static inline void write_temp(char *path, size_t size, const char *suffix, const char *text)
{
    snprintf(path, size, "/tmp/clpt-test-XXXXXX%s", suffix);
    int fd = mkstemps(path, (int)strlen(suffix));
    if (fd >= 0) {
        ssize_t w = write(fd, text, strlen(text));
        (void)w;
        close(fd);
    }
}

/* A command line clpt must refuse (argv without the program name; the unused tail of
 * args is NULL) and a part of what it must say on stderr (NULL: only the status is
 * checked). */
typedef struct {
    const char *args[16];
    const char *msg;
} CliRefusal;

/* Runs each case and checks clpt exits with `status` and says its message: the tables of
 * bad command lines. */
static inline void cli_check_refusals(const CliRefusal *cases, size_t n, int status)
{
    static CliResult r;
    for (size_t i = 0; i < n; i++) {
        cli_run(cases[i].args, &r);
        CHECK_MSG(r.status == status, "case %zu (%s ...): status %d, not %d", i, cases[i].args[0], r.status, status);
        if (cases[i].msg) CHECK_STR_CONTAINS(r.err, cases[i].msg);
    }
}

/* `scene` checkpointed at 4 samples (into ck) on the OpenCL devices the tests compare
 * (TEST_OPENCL) and resumed to 8 on those and the scalar device together (into out)
 * must be the straight 8-sample scalar render (ref) bit for bit: the resume check of
 * the media and motion tests. */
static inline void cli_check_resume_matches_straight(const char *scene, const char *ref, const char *out,
                                                     const char *ck)
{
    static CliResult r;
    char both[32];
    snprintf(both, sizeof both, "%s,scalar", TEST_OPENCL);
    unlink(ck);
    const char *straight[] = { scene, "--device", "scalar", "--spp", "8", "-q", "-o", ref, NULL };
    const char *first[] = { scene, "--device", TEST_OPENCL, "--spp", "4", "-q", "-o", out, "--checkpoint", ck, NULL };
    const char *resumed[] = { scene, "--device", both, "--spp", "8", "--batch", "1", "-q", "-o", out, "--resume", ck,
                              NULL };
    cli_run(straight, &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(first, &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(resumed, &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(files_equal(ref, out), "4 samples resumed to 8 differ from a straight 8-sample render");
    unlink(ref);
    unlink(out);
    unlink(ck);
}

#endif /* CLPT_CLI_UTIL_H */
