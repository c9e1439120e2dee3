#include "device/ocl_program.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdint.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/bytes.h"
#include "base/sha256.h"
#include "base/timer.h"

/* Cache file layout (integers little-endian):
 *   0  8  magic "CLPTKBIN"
 *   8  4  format version (OCLP__VERSION)
 *  12  4  zero
 *  16  8  payload length in bytes
 *  24 32  SHA-256 key of the entry (also its file name), so a misplaced file is refused
 *  56 32  SHA-256 of the payload, so a torn or flipped file is refused
 *  88     payload: the device's CL_PROGRAM_BINARIES entry */
#define OCLP__MAGIC "CLPTKBIN"
#define OCLP__VERSION 1u
#define OCLP__HEADER 88
/* No device binary of this program comes near this; a larger length is corruption. */
#define OCLP__MAX_PAYLOAD ((uint64_t)1 << 30)

/* ---------------------------------------------------------------- source and options */

/* Reads a whole file into a NUL-terminated heap buffer. */
static Status oclp__read_file(const char *path, char **text, size_t *len, Error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return error_set(err, ST_IO, "%s: cannot open: %s", path, strerror(errno));
    char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n + 4096 + 1 > cap) {
            cap = (n + 4096 + 1) * 2;
            char *grown = realloc(buf, cap);
            if (!grown) {
                free(buf);
                fclose(f);
                return error_set(err, ST_INTERNAL, "%s: out of memory reading it", path);
            }
            buf = grown;
        }
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0) break;
    }
    int failed = ferror(f);
    fclose(f);
    if (failed) {
        free(buf);
        return error_set(err, ST_IO, "%s: read error", path);
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return ST_OK;
}

static Status oclp__options(const OclDeviceInfo *dev, const char *kernel_dir, const char *extra,
                            char *buf, size_t cap, Error *err)
{
    size_t n = (size_t)snprintf(buf, cap, "-cl-std=CL1.2");
    if (dev->correctly_rounded_divide_sqrt && n < cap)
        n += (size_t)snprintf(buf + n, cap - n, " -cl-fp32-correctly-rounded-divide-sqrt");
    if (kernel_dir && n < cap) {
        /* The option string is split at blanks by the drivers, and quoting is not
         * handled alike by all of them: refuse what cannot be passed reliably. */
        if (strpbrk(kernel_dir, " \t\n\"'\\"))
            return error_set(err, ST_USAGE, "kernel folder '%s': the path must not contain "
                             "blanks, quotes or backslashes (OpenCL build options cannot "
                             "carry them portably)", kernel_dir);
        n += (size_t)snprintf(buf + n, cap - n, " -I %s", kernel_dir);
    }
    if (extra && extra[0] && n < cap) n += (size_t)snprintf(buf + n, cap - n, " %s", extra);
    if (n >= cap) return error_set(err, ST_USAGE, "OpenCL build options too long (%zu bytes)", n);
    return ST_OK;
}

/* ---------------------------------------------------------------- the cache */

int ocl_program_cache_dir(char *buf, size_t cap)
{
    const char *v = getenv("CLPT_CACHE_DIR");
    int n;
    if (v && v[0]) {
        n = snprintf(buf, cap, "%s", v);
    } else if ((v = getenv("XDG_CACHE_HOME")) && v[0] == '/') {
        /* The XDG spec says a relative XDG_CACHE_HOME is invalid and must be ignored. */
        n = snprintf(buf, cap, "%s/clpt", v);
    } else if ((v = getenv("HOME")) && v[0]) {
        n = snprintf(buf, cap, "%s/.cache/clpt", v);
    } else {
        return 0;
    }
    return n > 0 && (size_t)n < cap;
}

/* mkdir -p; returns 0 when the folder is there and writable, 1 when it is there but
 * cannot be written (a read-only shared cache: read, never written), -1 otherwise. */
static int oclp__make_dirs(const char *path)
{
    char tmp[1024];
    size_t n = strlen(path);
    if (n == 0 || n >= sizeof tmp) return -1;
    memcpy(tmp, path, n + 1);
    for (char *p = tmp + 1; *p; p++) {
        if (*p != '/') continue;
        *p = '\0';
        if (mkdir(tmp, 0755) != 0 && errno != EEXIST) return -1;
        *p = '/';
    }
    if (mkdir(tmp, 0755) != 0 && errno != EEXIST) return -1;
    struct stat sb;
    if (stat(tmp, &sb) != 0 || !S_ISDIR(sb.st_mode)) return -1;
    return access(tmp, W_OK) == 0 ? 0 : 1;
}

/* Hashes one field as length + bytes, so that no two different field lists can give the
 * same byte stream ("ab"+"c" versus "a"+"bc"). */
static void oclp__hash_field(Sha256 *h, const char *s, size_t n)
{
    unsigned char len[8];
    bytes_put_le(len, n, 8);
    sha256_update(h, len, sizeof len);
    sha256_update(h, s, n);
}

static void oclp__key(const OclDeviceInfo *dev, const char *src, size_t src_len,
                      const char *options, unsigned char key[SHA256_DIGEST_SIZE])
{
    Sha256 h;
    sha256_init(&h);
    static const char tag[] = "clpt kernel cache v1";
    oclp__hash_field(&h, tag, sizeof tag - 1);
    oclp__hash_field(&h, src, src_len);
    const char *fields[] = {dev->name, dev->vendor, dev->driver_version, dev->platform_name,
                            dev->platform_version, dev->device_version, options};
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++)
        oclp__hash_field(&h, fields[i], strlen(fields[i]));
    sha256_final(&h, key);
}

/* Reads and checks a cache entry. Returns 1 and a heap payload when the file is whole
 * and belongs to `key` (not checked when NULL), with the payload's SHA-256 in `digest`;
 * 0 when there is no file; -1 when it is damaged or not a regular file. Opened without
 * blocking: a FIFO in the entry's place hung clpt for ever. */
static int oclp__cache_read(const char *path, const unsigned char *key, unsigned char **payload, size_t *len,
                            unsigned char digest[SHA256_DIGEST_SIZE])
{
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return errno == ENOENT ? 0 : -1;
    struct stat sb;
    FILE *f = fstat(fd, &sb) == 0 && S_ISREG(sb.st_mode) ? fdopen(fd, "rb") : NULL;
    if (!f) {
        close(fd);
        return -1;
    }
    unsigned char head[OCLP__HEADER];
    int ok = fread(head, 1, sizeof head, f) == sizeof head &&
             memcmp(head, OCLP__MAGIC, 8) == 0 && bytes_get_le(head + 8, 4) == OCLP__VERSION &&
             (!key || memcmp(head + 24, key, SHA256_DIGEST_SIZE) == 0);
    uint64_t n = ok ? bytes_get_le(head + 16, 8) : 0;
    ok = ok && n > 0 && n <= OCLP__MAX_PAYLOAD;
    unsigned char *buf = ok ? malloc((size_t)n + 1) : NULL;
    ok = buf && fread(buf, 1, (size_t)n, f) == n && fgetc(f) == EOF;
    fclose(f);
    if (ok) {
        sha256(buf, (size_t)n, digest);
        ok = memcmp(digest, head + 56, SHA256_DIGEST_SIZE) == 0;
    }
    if (!ok) {
        free(buf);
        return -1;
    }
    *payload = buf;
    *len = (size_t)n;
    return 1;
}

/* Removes a damaged entry, whatever it is: a file, a FIFO, an empty folder (a folder
 * with files in it stays, and the cache is then only missed), and its proof. */
static void oclp__cache_remove(const char *path)
{
    char proof[1100];
    (void)remove(path);
    if (snprintf(proof, sizeof proof, "%s.ok", path) < (int)sizeof proof) (void)remove(proof);
}

/* Writes a cache entry atomically (a reader never sees half an entry). Failure is
 * silent by design: the caller has a working program either way. */
static void oclp__cache_write(const char *path, const unsigned char key[SHA256_DIGEST_SIZE],
                              const unsigned char *payload, size_t len)
{
    unsigned char head[OCLP__HEADER] = {0};
    memcpy(head, OCLP__MAGIC, 8);
    bytes_put_le(head + 8, OCLP__VERSION, 4);
    bytes_put_le(head + 16, len, 8);
    memcpy(head + 24, key, SHA256_DIGEST_SIZE);
    sha256(payload, len, head + 56);
    AtomicFile af;
    Error ignored = {0};
    if (atomic_open(&af, path, "kernel cache entry", &ignored) == ST_OK) {
        atomic_write(&af, head, sizeof head);
        atomic_write(&af, payload, len);
        (void)atomic_commit(&af, &ignored);
    }
    error_clear(&ignored);
}

/* The compiled binary of `prog` for dev; the program may span several devices of the
 * context, and CL_PROGRAM_BINARIES wants a buffer for each of them. */
static int oclp__binary(cl_program prog, const OclDeviceInfo *dev, unsigned char **out,
                        size_t *len)
{
    cl_uint n = 0;
    if (clGetProgramInfo(prog, CL_PROGRAM_NUM_DEVICES, sizeof n, &n, NULL) != CL_SUCCESS || !n)
        return 0;
    int found = 0;
    cl_device_id *devs = calloc(n, sizeof *devs);
    size_t *sizes = calloc(n, sizeof *sizes);
    unsigned char **bins = calloc(n, sizeof *bins);
    if (!devs || !sizes || !bins) goto cleanup;
    if (clGetProgramInfo(prog, CL_PROGRAM_DEVICES, n * sizeof *devs, devs, NULL) != CL_SUCCESS ||
        clGetProgramInfo(prog, CL_PROGRAM_BINARY_SIZES, n * sizeof *sizes, sizes, NULL) !=
            CL_SUCCESS)
        goto cleanup;
    cl_uint me = n;
    for (cl_uint i = 0; i < n; i++) {
        if (devs[i] == dev->id) me = i;
        bins[i] = malloc(sizes[i] ? sizes[i] : 1);
        if (!bins[i]) goto cleanup;
    }
    if (me == n || sizes[me] == 0) goto cleanup;
    if (clGetProgramInfo(prog, CL_PROGRAM_BINARIES, n * sizeof *bins, bins, NULL) != CL_SUCCESS)
        goto cleanup;
    *out = bins[me];
    *len = sizes[me];
    bins[me] = NULL;
    found = 1;
cleanup:
    if (bins)
        for (cl_uint i = 0; i < n; i++) free(bins[i]);
    free(bins);
    free(sizes);
    free(devs);
    return found;
}

/* Whether a program built from a cached binary is usable: built for the device
 * (clBuildProgram can succeed while the device's status says otherwise) and holding
 * kernels (every program clpt builds has some; a binary the driver half-read may not). */
static int oclp__usable(cl_program prog, const OclDeviceInfo *dev)
{
    cl_build_status bs = CL_BUILD_NONE;
    if (clGetProgramBuildInfo(prog, dev->id, CL_PROGRAM_BUILD_STATUS, sizeof bs, &bs, NULL) != CL_SUCCESS ||
        bs != CL_BUILD_SUCCESS)
        return 0;
    size_t n_kernels = 0;
    return clGetProgramInfo(prog, CL_PROGRAM_NUM_KERNELS, sizeof n_kernels, &n_kernels, NULL) == CL_SUCCESS &&
           n_kernels > 0;
}

/* Creates and builds a program from a cached binary; 0 (and nothing to release) when
 * the driver refuses it or the result is not usable. */
static int oclp__from_binary(cl_context ctx, const OclDeviceInfo *dev, const unsigned char *bin,
                             size_t len, const char *options, cl_program *out)
{
    cl_int rc, bin_status = CL_INVALID_BINARY;
    cl_program prog = clCreateProgramWithBinary(ctx, 1, &dev->id, &len, &bin, &bin_status, &rc);
    if (rc != CL_SUCCESS || bin_status != CL_SUCCESS) {
        if (prog) clReleaseProgram(prog);
        return 0;
    }
    if (clBuildProgram(prog, 1, &dev->id, options, NULL, NULL) != CL_SUCCESS || !oclp__usable(prog, dev)) {
        clReleaseProgram(prog);
        return 0;
    }
    *out = prog;
    return 1;
}

/* ---------------------------------------------------------------- the trial load */

static atomic_int oclp__announce_builds;   /* see ocl_program_announce_builds */

/* A payload whose checksum is right can still crash the driver that reads it (a
 * flipped byte in a PoCL binary is a SIGSEGV in clCreateProgramWithBinary; a torn one
 * an assertion), and a crash cannot be caught in the process it happens in. So an entry
 * is first loaded in a child process (a trial): only a payload that a trial, or an
 * earlier run, loaded without harm is loaded here. The proof is PATH.ok, holding the
 * SHA-256 of the payload proven, so a payload put in the entry's place afterwards is
 * tried again. The trial costs a process start and the driver's start-up, once per new
 * entry. The child is this same program (/proc/self/exe, whatever binary links clpt's
 * library: clpt, a test, a benchmark), told by the environment what to try; it runs
 * the trial from a constructor (oclp__trial_main), before main, and exits. */
#define OCLP__TRIAL_DEVICE "CLPT_KERNEL_CACHE_TRIAL"          /* "PLATFORM.DEVICE" indices */
#define OCLP__TRIAL_ENTRY "CLPT_KERNEL_CACHE_TRIAL_ENTRY"     /* the entry's path */
#define OCLP__TRIAL_DIGEST "CLPT_KERNEL_CACHE_TRIAL_DIGEST"   /* the payload's SHA-256, hex */
#define OCLP__TRIAL_OPTIONS "CLPT_KERNEL_CACHE_TRIAL_OPTIONS" /* the build options */
#define OCLP__TRIAL_SECONDS 120.0   /* a trial that takes longer is a driver hanging on it */

/* The trial child's exit statuses. Not 1: a process that dies of a fault caught by a
 * runtime (a sanitizer reports a driver's SIGSEGV and exits 1) or that the driver ends
 * with exit(1) gave no verdict, and counts as a crash, as a fatal signal does. */
#define OCLP__EXIT_LOADED 0
#define OCLP__EXIT_REFUSED 64
#define OCLP__EXIT_NO_TRIAL 65

typedef enum {
    OCLP__TRIAL_LOADED,    /* the driver built it and the program is usable */
    OCLP__TRIAL_REFUSED,   /* the driver refused it, or hung on it */
    OCLP__TRIAL_CRASHED,   /* the driver crashed on it */
    OCLP__TRIAL_UNKNOWN,   /* no answer: no trial could run, or it was interrupted */
} OclpTrial;

/* Whether PATH.ok proves the payload with this digest. */
static int oclp__proven(const char *path, const unsigned char digest[SHA256_DIGEST_SIZE])
{
    char proof[1100];
    if (snprintf(proof, sizeof proof, "%s.ok", path) >= (int)sizeof proof) return 0;
    int fd = open(proof, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return 0;
    unsigned char got[SHA256_DIGEST_SIZE + 1];
    struct stat sb;
    int ok = fstat(fd, &sb) == 0 && S_ISREG(sb.st_mode) && read(fd, got, sizeof got) == SHA256_DIGEST_SIZE &&
             memcmp(got, digest, SHA256_DIGEST_SIZE) == 0;
    close(fd);
    return ok;
}

static void oclp__prove(const char *path, const unsigned char digest[SHA256_DIGEST_SIZE])
{
    char proof[1100];
    if (snprintf(proof, sizeof proof, "%s.ok", path) >= (int)sizeof proof) return;
    AtomicFile af;
    Error ignored = {0};
    if (atomic_open(&af, proof, "kernel cache proof", &ignored) == ST_OK) {
        atomic_write(&af, digest, SHA256_DIGEST_SIZE);
        (void)atomic_commit(&af, &ignored);
    }
    error_clear(&ignored);
}

/* The child's side: loads the entry for the device named by the environment. Exit
 * status OCLP__EXIT_LOADED: loaded and usable; OCLP__EXIT_REFUSED: refused;
 * OCLP__EXIT_NO_TRIAL: the trial itself could not run. */
static int oclp__trial(const char *which, const char *path, const char *digest_hex, const char *options)
{
    unsigned p = 0, d = 0;
    if (!path || !digest_hex || !options || sscanf(which, "%u.%u", &p, &d) != 2) return OCLP__EXIT_NO_TRIAL;
    cl_uint n_platforms = 0, n_devices = 0;
    cl_platform_id platforms[64];
    cl_device_id devices[64];
    if (clGetPlatformIDs(64, platforms, &n_platforms) != CL_SUCCESS || p >= n_platforms || p >= 64)
        return OCLP__EXIT_NO_TRIAL;
    if (clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, 64, devices, &n_devices) != CL_SUCCESS ||
        d >= n_devices || d >= 64)
        return OCLP__EXIT_NO_TRIAL;
    unsigned char *bin = NULL, digest[SHA256_DIGEST_SIZE];
    size_t len = 0;
    char hex[65];
    if (oclp__cache_read(path, NULL, &bin, &len, digest) != 1) return OCLP__EXIT_NO_TRIAL;
    sha256_hex(digest, hex);
    if (strcmp(hex, digest_hex) != 0) return OCLP__EXIT_NO_TRIAL;   /* replaced meanwhile: not what was asked */
    cl_context_properties props[] = { CL_CONTEXT_PLATFORM, (cl_context_properties)platforms[p], 0 };
    cl_int rc;
    cl_context ctx = clCreateContext(props, 1, &devices[d], NULL, NULL, &rc);
    if (rc != CL_SUCCESS) return OCLP__EXIT_NO_TRIAL;
    OclDeviceInfo dev;
    memset(&dev, 0, sizeof dev);
    dev.id = devices[d];
    cl_program prog;
    int ok = oclp__from_binary(ctx, &dev, bin, len, options, &prog);
    if (ok) clReleaseProgram(prog);
    clReleaseContext(ctx);
    free(bin);
    return ok ? OCLP__EXIT_LOADED : OCLP__EXIT_REFUSED;
}

/* Runs the trial when this process is a trial child; every other process returns at
 * once. _exit: the child has nothing of the parent's to flush, and a sanitizer's leak
 * check at exit has nothing to say about a process that ran no main. */
__attribute__((constructor)) static void oclp__trial_main(void)
{
    const char *which = getenv(OCLP__TRIAL_DEVICE);
    if (!which) return;
    _exit(oclp__trial(which, getenv(OCLP__TRIAL_ENTRY), getenv(OCLP__TRIAL_DIGEST), getenv(OCLP__TRIAL_OPTIONS)));
}

/* The parent's side: starts the child with the environment plus the trial's variables,
 * its output thrown away (a driver's assertion message is not clpt's to show), and
 * waits for its verdict. */
static OclpTrial oclp__try_entry(const OclDeviceInfo *dev, const char *path,
                                 const unsigned char digest[SHA256_DIGEST_SIZE], const char *options)
{
    extern char **environ;
    char hex[65], v_device[64], v_entry[1200], v_digest[128], v_options[700];
    sha256_hex(digest, hex);
    snprintf(v_device, sizeof v_device, "%s=%u.%u", OCLP__TRIAL_DEVICE, dev->platform_index, dev->device_index);
    snprintf(v_digest, sizeof v_digest, "%s=%s", OCLP__TRIAL_DIGEST, hex);
    if (snprintf(v_entry, sizeof v_entry, "%s=%s", OCLP__TRIAL_ENTRY, path) >= (int)sizeof v_entry ||
        snprintf(v_options, sizeof v_options, "%s=%s", OCLP__TRIAL_OPTIONS, options) >= (int)sizeof v_options)
        return OCLP__TRIAL_UNKNOWN;
    size_t n_env = 0;
    while (environ[n_env]) n_env++;
    char **envp = calloc(n_env + 5, sizeof *envp);
    if (!envp) return OCLP__TRIAL_UNKNOWN;
    size_t k = 0;
    for (size_t i = 0; i < n_env; i++)
        if (strncmp(environ[i], "CLPT_KERNEL_CACHE_TRIAL", 23) != 0) envp[k++] = environ[i];
    envp[k++] = v_device;
    envp[k++] = v_entry;
    envp[k++] = v_digest;
    envp[k++] = v_options;
    char *argv[] = { (char *)"clpt-kernel-cache-trial", NULL };
    posix_spawn_file_actions_t fa;
    pid_t pid = -1;
    int spawned = -1;
    if (posix_spawn_file_actions_init(&fa) == 0) {
        if (posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0) == 0 &&
            posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0) == 0 &&
            posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0) == 0)
            spawned = posix_spawn(&pid, "/proc/self/exe", &fa, NULL, argv, envp);
        posix_spawn_file_actions_destroy(&fa);
    }
    free(envp);
    if (spawned != 0) return OCLP__TRIAL_UNKNOWN;
    int wstatus = 0;
    double deadline = timer_now() + OCLP__TRIAL_SECONDS;
    for (;;) {
        pid_t got = waitpid(pid, &wstatus, WNOHANG);
        if (got == pid) break;
        if (got < 0 && errno != EINTR) return OCLP__TRIAL_UNKNOWN;
        if (timer_now() > deadline) {
            kill(pid, SIGKILL);
            while (waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {}
            return OCLP__TRIAL_REFUSED;
        }
        nanosleep(&(struct timespec){ 0, 5000000 }, NULL);
    }
    if (WIFEXITED(wstatus))
        return WEXITSTATUS(wstatus) == OCLP__EXIT_LOADED    ? OCLP__TRIAL_LOADED
             : WEXITSTATUS(wstatus) == OCLP__EXIT_REFUSED   ? OCLP__TRIAL_REFUSED
             : WEXITSTATUS(wstatus) == OCLP__EXIT_NO_TRIAL  ? OCLP__TRIAL_UNKNOWN
                                                            : OCLP__TRIAL_CRASHED;   /* no verdict */
    switch (WTERMSIG(wstatus)) {
    case SIGSEGV: case SIGBUS: case SIGABRT: case SIGILL: case SIGFPE: case SIGSYS: return OCLP__TRIAL_CRASHED;
    default: return OCLP__TRIAL_UNKNOWN;   /* interrupted with the parent (Ctrl-C), or killed */
    }
}

/* Creates the empty file `path`, a mark (best effort). */
static void oclp__mark(const char *path)
{
    FILE *mark = fopen(path, "w");
    if (mark) fclose(mark);
}

/* The name of the mark a run of this machine leaves beside entry `path` while its
 * driver reads the entry: PATH.HOST.PID.trying for process pid (prefix only, "PATH.HOST.",
 * with pid < 0). The host is in the name because a cache folder may be shared between
 * machines (a farm's), and only a process of this machine can be asked whether it still
 * runs. 0 when the name does not fit. */
static int oclp__trying_name(char *buf, size_t cap, const char *path, long pid)
{
    char host[256];
    if (gethostname(host, sizeof host) != 0) host[0] = '\0';
    host[sizeof host - 1] = '\0';
    for (char *c = host; *c; c++)
        if (*c == '/') *c = '_';
    int n = pid < 0 ? snprintf(buf, cap, "%s.%s.", path, host[0] ? host : "localhost")
                    : snprintf(buf, cap, "%s.%s.%ld.trying", path, host[0] ? host : "localhost", pid);
    return n > 0 && (size_t)n < cap;
}

/* Whether a run of this machine died while its driver read the entry at `path`: it
 * left its mark behind (oclp__cache_load) and its process is gone. Removes such marks.
 * A run still reading the entry, and the marks of other machines, are left alone. */
static int oclp__crashed_before(const char *path)
{
    char prefix[1400];   /* an entry's path (at most 1024) and a host name (at most 255) */
    if (!oclp__trying_name(prefix, sizeof prefix, path, -1)) return 0;
    const char *slash = strrchr(prefix, '/');
    if (!slash) return 0;
    char dir[1400];
    memcpy(dir, prefix, (size_t)(slash - prefix));
    dir[slash - prefix] = '\0';
    const char *base = slash + 1;   /* ENTRY.HOST. */
    size_t base_len = strlen(base);
    DIR *d = opendir(dir);
    if (!d) return 0;
    int crashed = 0;
    for (struct dirent *e; (e = readdir(d));) {
        const char *name = e->d_name;
        size_t len = strlen(name);
        if (len <= base_len + 7 || strncmp(name, base, base_len) != 0 || strcmp(name + len - 7, ".trying") != 0)
            continue;
        char *end = NULL;
        long pid = strtol(name + base_len, &end, 10);
        if (pid <= 0 || end != name + len - 7) continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;   /* still running */
        /* gone, and its mark still there: a run that ends well takes its mark away
         * before it exits, so one that ended between readdir and kill is not counted */
        char stale[2700];
        if (snprintf(stale, sizeof stale, "%s/%s", dir, name) < (int)sizeof stale && unlink(stale) == 0) crashed = 1;
    }
    closedir(d);
    return crashed;
}

/* Loads the program from the cache entry at `path`; 1 on success. A payload no trial
 * has proven is loaded in a child process first (oclp__try_entry), and removed when the
 * driver refuses it or crashes on it there (PoCL 3 aborts or faults on some damaged
 * binaries whose checksum is right, in clCreateProgramWithBinary or clBuildProgram).
 * Should the driver still crash here (no trial could run, or a proven entry), this
 * run's mark stays beside the entry (oclp__trying_name), and the next run of this
 * machine that meets the entry finds the mark of a process that is gone and builds
 * afresh: the entry costs at most the runs that read it together. The entry itself
 * stays where it is while it is read, so runs started at the same moment (MPI's ranks,
 * a farm's tasks over a shared cache) all load it; moving it aside, as clpt did before,
 * made them find no entry and compile. A refused entry is deleted. A cache folder that
 * cannot be written (a read-only shared one) is read without the mark.
 *
 * The driver may have kept what it read in a cache of its own (PoCL does, under the
 * program's hash, and then crashes on it when the same source is built again): when a
 * trial crashed or a run died reading the entry, `path`.crashed is left as a mark, and
 * while it exists the source is built with a line that changes the driver's key
 * (oclp__from_source). */
static int oclp__cache_load(cl_context ctx, const OclDeviceInfo *dev, const char *path,
                            const unsigned char key[SHA256_DIGEST_SIZE], const char *options,
                            cl_program *out)
{
    char trying[1400], crashed[1100];
    if (!oclp__trying_name(trying, sizeof trying, path, (long)getpid()) ||
        snprintf(crashed, sizeof crashed, "%s.crashed", path) >= (int)sizeof crashed)
        return 0;
    unsigned char *bin = NULL, digest[SHA256_DIGEST_SIZE];
    size_t bin_len = 0;
    int got = oclp__cache_read(path, key, &bin, &bin_len, digest);
    if (got == 0) {
        if (oclp__crashed_before(path)) oclp__mark(crashed);
        return 0;
    }
    if (oclp__crashed_before(path)) {
        /* a run of this machine died reading this entry: not read again */
        oclp__mark(crashed);
        if (atomic_load(&oclp__announce_builds))
            fprintf(stderr, "clpt: warning: a run died while the OpenCL driver loaded the kernel cache entry '%s'; "
                    "removed it\n", path);
        oclp__cache_remove(path);
        free(bin);
        return 0;
    }
    OclpTrial trial = got < 0 || oclp__proven(path, digest) ? OCLP__TRIAL_LOADED
                                                            : oclp__try_entry(dev, path, digest, options);
    if (trial == OCLP__TRIAL_CRASHED) {
        oclp__mark(crashed);   /* the driver may have kept what it read: compile past it */
        if (atomic_load(&oclp__announce_builds))
            fprintf(stderr, "clpt: warning: the OpenCL driver crashed loading the kernel cache entry '%s' (in a "
                    "trial process); removed it\n", path);
    }
    if (trial == OCLP__TRIAL_LOADED && got > 0) oclp__prove(path, digest);
    if (got < 0 || trial == OCLP__TRIAL_REFUSED || trial == OCLP__TRIAL_CRASHED) {
        oclp__cache_remove(path);     /* damaged: rebuilt and replaced by the caller */
        free(bin);
        return 0;
    }
    oclp__mark(trying);
    int ok = oclp__from_binary(ctx, dev, bin, bin_len, options, out);
    unlink(trying);
    if (!ok) oclp__cache_remove(path);
    free(bin);
    return ok;
}

/* ---------------------------------------------------------------- building */

static char *oclp__build_log(cl_program prog, const OclDeviceInfo *dev)
{
    size_t n = 0;
    if (clGetProgramBuildInfo(prog, dev->id, CL_PROGRAM_BUILD_LOG, 0, NULL, &n) != CL_SUCCESS)
        return NULL;
    char *log = malloc(n + 1);
    if (!log) return NULL;
    if (clGetProgramBuildInfo(prog, dev->id, CL_PROGRAM_BUILD_LOG, n, log, NULL) != CL_SUCCESS) {
        free(log);
        return NULL;
    }
    log[n] = '\0';
    return log;
}

/* Appended to the source while a cache entry's mark says a run crashed loading it
 * (oclp__cache_load): a different source is a different key in the driver's own cache,
 * so the driver compiles afresh instead of reading what the bad binary left there. A
 * declaration, not a comment: PoCL keys its cache on the preprocessed source. */
static const char oclp__fresh_line[] = "\ntypedef int clpt_built_afresh_after_a_crash;\n";

static Status oclp__from_source(cl_context ctx, const OclDeviceInfo *dev, const char *src,
                                size_t len, const char *options, int fresh, cl_program *out, Error *err)
{
    cl_int rc;
    const char *parts[2] = { src, oclp__fresh_line };
    size_t lens[2] = { len, sizeof oclp__fresh_line - 1 };
    cl_program prog = clCreateProgramWithSource(ctx, fresh ? 2 : 1, parts, lens, &rc);
    if (rc != CL_SUCCESS) return ocl_fail(err, dev, "clCreateProgramWithSource", rc);
    rc = clBuildProgram(prog, 1, &dev->id, options, NULL, NULL);
    if (rc != CL_SUCCESS) {
        char *log = oclp__build_log(prog, dev);
        Status st = ocl_failf(err, dev, "clBuildProgram", rc, "options \"%s\"%s", options,
                              log && log[0] ? " (build log follows)" : " (no build log)");
        error_set_detail(err, log);
        free(log);
        clReleaseProgram(prog);
        return st;
    }
    *out = prog;
    return ST_OK;
}

/* ---------------------------------------------------------------- the notice */

void ocl_program_announce_builds(int on)
{
    atomic_store(&oclp__announce_builds, on);
}

/* A build from source takes seconds to a minute with nothing else to show: say why. */
static void oclp__announce(const OclDeviceInfo *dev, int cached_afterwards)
{
    if (!atomic_load(&oclp__announce_builds)) return;
    fprintf(stderr, "clpt: compiling kernels for %s%s...\n", dev->name,
            cached_afterwards ? ", cached for next time" : "");
    fflush(stderr);
}

/* Builds src for dev, through the cache unless src came from a kernel folder. */
static Status oclp__build(cl_context ctx, const OclDeviceInfo *dev, const char *src, size_t src_len,
                          int from_folder, const char *options, cl_program *out,
                          OclProgramStats *stats, Error *err)
{
    /* Developer mode is never cached: the included files are not part of the key. */
    char dir[900], path[sizeof stats->cache_path] = "";
    unsigned char key[SHA256_DIGEST_SIZE];
    int folder = from_folder || !ocl_program_cache_dir(dir, sizeof dir) ? -1 : oclp__make_dirs(dir);
    int writable = folder == 0;
    if (folder >= 0) {
        char hex[65];
        oclp__key(dev, src, src_len, options, key);
        sha256_hex(key, hex);
        snprintf(path, sizeof path, "%s/%s.bin", dir, hex);
    }

    if (path[0] && oclp__cache_load(ctx, dev, path, key, options, out)) stats->from_cache = 1;

    Status st = ST_OK;
    if (!stats->from_cache) {
        oclp__announce(dev, path[0] != '\0' && writable);
        char crashed[sizeof path + 16];
        snprintf(crashed, sizeof crashed, "%s.crashed", path);
        int fresh = path[0] && access(crashed, F_OK) == 0;
        st = oclp__from_source(ctx, dev, src, src_len, options, fresh, out, err);
        if (st == ST_OK && path[0] && writable) {
            unsigned char *bin = NULL;
            size_t bin_len = 0;
            if (oclp__binary(*out, dev, &bin, &bin_len))
                oclp__cache_write(path, key, bin, bin_len);
            free(bin);
        }
    }
    if (st == ST_OK && (stats->from_cache || writable)) memcpy(stats->cache_path, path, sizeof path);
    return st;
}

/* <kernel_dir>/entry.cl, with a #line marker in front: drivers compile a copy in a
 * temporary file (PoCL does), so without it the build log would name that copy. The
 * path holds no quote or backslash (checked with the options). */
static Status oclp__read_entry(const char *kernel_dir, char **src, size_t *src_len, Error *err)
{
    char path[1024];
    if (snprintf(path, sizeof path, "%s/entry.cl", kernel_dir) >= (int)sizeof path)
        return error_set(err, ST_USAGE, "kernel folder path too long: %s", kernel_dir);
    char *text = NULL;
    size_t text_len = 0;
    Status st = oclp__read_file(path, &text, &text_len, err);
    if (st != ST_OK) return st;
    size_t head = strlen(path) + 16;
    char *file_src = malloc(head + text_len + 1);
    if (!file_src) {
        free(text);
        return error_set(err, ST_INTERNAL, "%s: out of memory", path);
    }
    size_t n = (size_t)snprintf(file_src, head, "#line 1 \"%s\"\n", path);
    memcpy(file_src + n, text, text_len + 1);
    free(text);
    *src = file_src;
    *src_len = n + text_len;
    return ST_OK;
}

Status ocl_program_build(cl_context ctx, const OclDeviceInfo *dev, const char *kernel_dir,
                         const char *extra_options, cl_program *out, OclProgramStats *stats,
                         Error *err)
{
    double t0 = timer_now();
    OclProgramStats local;
    if (!stats) stats = &local;
    memset(stats, 0, sizeof *stats);
    *out = NULL;

    /* The options are composed in the stats record itself, so what it reports is
     * exactly what was used. */
    Status st = oclp__options(dev, kernel_dir, extra_options, stats->options,
                              sizeof stats->options, err);
    if (st != ST_OK) return st;

    char *file_src = NULL;
    const char *src = clpt_kernel_source;
    size_t src_len = clpt_kernel_source_len;
    if (kernel_dir) {
        st = oclp__read_entry(kernel_dir, &file_src, &src_len, err);
        if (st != ST_OK) return st;
        src = file_src;
    }
    st = oclp__build(ctx, dev, src, src_len, kernel_dir != NULL, stats->options, out, stats, err);
    free(file_src);
    stats->seconds = timer_now() - t0;
    return st;
}

Status ocl_program_build_source(cl_context ctx, const OclDeviceInfo *dev, const char *src,
                                size_t src_len, const char *extra_options, cl_program *out,
                                OclProgramStats *stats, Error *err)
{
    double t0 = timer_now();
    OclProgramStats local;
    if (!stats) stats = &local;
    memset(stats, 0, sizeof *stats);
    *out = NULL;
    Status st = oclp__options(dev, NULL, extra_options, stats->options, sizeof stats->options, err);
    if (st == ST_OK) st = oclp__build(ctx, dev, src, src_len, 0, stats->options, out, stats, err);
    stats->seconds = timer_now() - t0;
    return st;
}

Status ocl_program_kernel(cl_program prog, const OclDeviceInfo *dev, const char *name,
                          cl_kernel *out, Error *err)
{
    cl_int rc;
    *out = clCreateKernel(prog, name, &rc);
    if (rc != CL_SUCCESS) {
        *out = NULL;
        return ocl_failf(err, dev, "clCreateKernel", rc, "kernel '%s'", name);
    }
    return ST_OK;
}
