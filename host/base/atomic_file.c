/* atomic_file.c — temporary file, sync, rename (see atomic_file.h). */
#include "base/atomic_file.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

void atomic_fail(AtomicFile *af, const char *step)
{
    if (af->failed_step) return;
    af->failed_step = step;
    af->failed_errno = errno ? errno : EIO;
}

static Status atomic_error(const AtomicFile *af, Error *err)
{
    if (af->stream)
        return error_set(err, ST_IO, "cannot write %s%sto %s: %s: %s", af->what, af->what[0] ? " " : "", af->path,
                         af->failed_step, strerror(af->failed_errno));
    return error_set(err, ST_IO, "cannot write %s%s'%s': %s: %s", af->what, af->what[0] ? " " : "", af->path,
                     af->failed_step, strerror(af->failed_errno));
}

void atomic_open_stream(AtomicFile *af, FILE *f, const char *name, const char *what)
{
    memset(af, 0, sizeof *af);
    af->path = name;
    af->what = what;
    af->f = f;
    af->stream = 1;
}

/* A stream's end: what is buffered is flushed, the stream stays open for its owner. */
static Status atomic_commit_stream(AtomicFile *af, Error *err)
{
    errno = 0;
    if (!af->failed_step && (fflush(af->f) != 0 || ferror(af->f))) atomic_fail(af, "write");
    af->f = NULL;
    return af->failed_step ? atomic_error(af, err) : ST_OK;
}

void atomic_abort(AtomicFile *af)
{
    if (af->stream) {
        if (af->f) fflush(af->f);
        af->f = NULL;
        return;
    }
    if (af->f) fclose(af->f);
    af->f = NULL;
    if (af->tmp) unlink(af->tmp);
    free(af->tmp);
    af->tmp = NULL;
    free(af->target);
    af->target = NULL;
}

/* `link`'s folder joined with a relative symlink text `rel` (an absolute one stands
 * alone). */
static char *join_beside(const char *link, const char *rel)
{
    const char *slash = strrchr(link, '/');
    size_t dir = rel[0] == '/' || !slash ? 0 : (size_t)(slash - link) + 1;
    size_t n = strlen(rel);
    char *out = malloc(dir + n + 1);
    if (!out) return NULL;
    memcpy(out, link, dir);
    memcpy(out + dir, rel, n + 1);
    return out;
}

/* The file a write to `path` should replace: symlinks are followed (also dangling ones,
 * whose target is then created), as editors do, so that the link keeps pointing at the
 * new content and the temporary file lands in the target's folder, where the rename is
 * atomic. NULL when out of memory; a loop stops after 40 links, as the kernel does. */
static char *resolve_target(const char *path)
{
    char *cur = strdup(path);
    for (int depth = 0; cur && depth < 40; depth++) {
        struct stat sb;
        if (lstat(cur, &sb) != 0 || !S_ISLNK(sb.st_mode)) return cur;
        char text[PATH_MAX];
        ssize_t n = readlink(cur, text, sizeof text - 1);
        if (n <= 0) return cur;
        text[n] = '\0';
        char *next = join_beside(cur, text);
        free(cur);
        cur = next;
    }
    return cur;
}

/* What a file that is not a regular file is, for messages; NULL for a regular file. */
static const char *not_regular_kind(mode_t mode)
{
    if (S_ISREG(mode)) return NULL;
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISSOCK(mode)) return "a socket";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISLNK(mode)) return "a symlink";
    return "not a regular file";
}

/* Refuses a target that exists and is not a regular file: the rename would replace a
 * FIFO, a socket or a device node (as root, `-o` through a link to /dev/null would
 * replace /dev/null) with a plain file. Names the link's target when they differ. */
static Status refuse_not_regular(AtomicFile *af, const char *kind, Error *err)
{
    Status st;
    if (strcmp(af->path, af->target) == 0)
        st = error_set(err, ST_IO, "cannot write %s%s'%s': it is %s, not a regular file (clpt replaces only regular "
                       "files)", af->what, af->what[0] ? " " : "", af->path, kind);
    else
        st = error_set(err, ST_IO, "cannot write %s%s'%s': it leads to '%s', which is %s, not a regular file (clpt "
                       "replaces only regular files)", af->what, af->what[0] ? " " : "", af->path, af->target, kind);
    free(af->tmp);
    af->tmp = NULL;
    atomic_abort(af);
    return st;
}

/* The temporary file lives in the target's folder so that the final rename stays within
 * one filesystem, where it is atomic. */
Status atomic_open(AtomicFile *af, const char *path, const char *what, Error *err)
{
    static const char suffix[] = ".tmp.XXXXXX";
    memset(af, 0, sizeof *af);
    af->path = path;
    af->what = what ? what : "";
    af->target = resolve_target(path);
    af->tmp = af->target ? malloc(strlen(af->target) + sizeof suffix) : NULL;
    if (!af->tmp) {
        af->failed_step = "out of memory";
        af->failed_errno = ENOMEM;
        Status st = atomic_error(af, err);
        atomic_abort(af);
        return st;
    }
    struct stat sb;
    if (stat(af->target, &sb) == 0) {
        if (S_ISDIR(sb.st_mode)) {
            errno = EISDIR;
            atomic_fail(af, "not a file");
            free(af->tmp);
            af->tmp = NULL;
            Status st = atomic_error(af, err);
            atomic_abort(af);
            return st;
        }
        const char *kind = not_regular_kind(sb.st_mode);
        if (kind) return refuse_not_regular(af, kind, err);
        af->keep_mode = 1;
        af->mode = sb.st_mode & 07777;
    }
    size_t n = strlen(af->target);
    memcpy(af->tmp, af->target, n);
    memcpy(af->tmp + n, suffix, sizeof suffix);
    errno = 0;
    int fd = mkostemp(af->tmp, O_CLOEXEC);
    if (fd < 0) {
        atomic_fail(af, "cannot create a temporary file beside it");
        free(af->tmp);
        af->tmp = NULL; /* nothing was created, so nothing to remove */
        Status st = atomic_error(af, err);
        atomic_abort(af);
        return st;
    }
    af->f = fdopen(fd, "wb");
    if (!af->f) {
        atomic_fail(af, "fdopen");
        close(fd);
        Status st = atomic_error(af, err);
        atomic_abort(af);
        return st;
    }
    return ST_OK;
}

Status atomic_probe(const char *path, const char *what, Error *err)
{
    AtomicFile af;
    Status st = atomic_open(&af, path, what, err);
    if (st == ST_OK) atomic_abort(&af);
    return st;
}

void atomic_write(AtomicFile *af, const void *data, size_t n)
{
    if (af->failed_step || n == 0) return;
    errno = 0;
    if (fwrite(data, 1, n, af->f) != n) atomic_fail(af, "write");
}

/* mkstemp creates files 0600; give the file the mode an ordinary fopen() would have,
 * 0666 less the umask. umask() can only be read by changing it, which would race with
 * other threads creating files, so read it from /proc (022 when that is unavailable). */
static mode_t ordinary_file_mode(void)
{
    unsigned mask = 022;
    FILE *f = fopen("/proc/self/status", "re");
    if (f) {
        char line[256];
        while (fgets(line, sizeof line, f))
            if (sscanf(line, "Umask: %o", &mask) == 1) break;
        fclose(f);
    }
    return (mode_t)(0666u & ~mask);
}

/* Syncs the folder so that the rename itself survives a power loss. Best effort: by now
 * the file is complete and in place, so a failure here is not worth failing the write. */
static void sync_parent_folder(const char *path)
{
    const char *slash = strrchr(path, '/');
    char *dir = NULL;
    if (!slash) dir = strdup(".");
    else if (slash == path) dir = strdup("/");
    else dir = strndup(path, (size_t)(slash - path));
    if (!dir) return;
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        (void)fsync(fd);
        close(fd);
    }
    free(dir);
}

/* Write errors such as a full disk often surface only at the flush or the sync. */
Status atomic_commit(AtomicFile *af, Error *err)
{
    if (af->stream) return atomic_commit_stream(af, err);
    if (!af->failed_step) {
        errno = 0;
        if (fflush(af->f) != 0) atomic_fail(af, "write");
    }
    if (!af->failed_step && fsync(fileno(af->f)) != 0) atomic_fail(af, "fsync");
    if (!af->failed_step && fchmod(fileno(af->f), af->keep_mode ? af->mode : ordinary_file_mode()) != 0)
        atomic_fail(af, "chmod");
    if (!af->failed_step) {
        errno = 0;
        int rc = fclose(af->f);
        af->f = NULL;
        if (rc != 0) atomic_fail(af, "close");
    }
    /* Checked again: hours may have passed since atomic_open, and what sits at the target
     * now is what the rename would replace. */
    struct stat sb;
    if (!af->failed_step && lstat(af->target, &sb) == 0 && !S_ISREG(sb.st_mode)) {
        errno = S_ISDIR(sb.st_mode) ? EISDIR : EEXIST;
        atomic_fail(af, "something that is not a regular file took its place");
    }
    if (!af->failed_step && rename(af->tmp, af->target) != 0)
        atomic_fail(af, "cannot rename the temporary file over it");
    if (af->failed_step) {
        Status st = atomic_error(af, err);
        atomic_abort(af);
        return st;
    }
    free(af->tmp);
    af->tmp = NULL;
    sync_parent_folder(af->target);
    free(af->target);
    af->target = NULL;
    return ST_OK;
}
