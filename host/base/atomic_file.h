/*
 * atomic_file.h — a file written whole or not at all: the bytes go to a temporary file
 * beside the target, which is synced and renamed over it only once everything is
 * written. A reader sees the old file or the complete new one, never a half-written
 * one, whatever kills the process. Used by the images, the checkpoints and the kernel
 * cache.
 *
 * The target is the file a plain fopen() would write: a symlink is followed (the link
 * stays and its target gets the new content; a dangling one's target is created), and
 * an existing file keeps its permission bits. Only a regular file is replaced: a
 * target that is a FIFO, a socket, a device node or a directory, named directly or
 * through links, is refused (ST_IO), since the rename would put a plain file in its
 * place (as root, `-o out.png` with out.png -> /dev/null would replace /dev/null). A file with several hard links is replaced under the name given,
 * so its other names keep the old content: writing into the shared inode in place
 * would give up the whole-or-nothing promise, which matters more for images that a
 * viewer or a later resume reads while clpt writes them (docs/exit-codes.md).
 *
 * The first failure is remembered (its step and errno) and later writes are skipped,
 * so writers need not check each call; atomic_commit reports it.
 */
#ifndef CLPT_ATOMIC_FILE_H
#define CLPT_ATOMIC_FILE_H

#include "base/status.h"

#include <stddef.h>
#include <stdio.h>

typedef struct {
    const char *path;        /* the target */
    const char *what;        /* for messages: "cannot write <what> '<path>'" ("" for none) */
    char *target;            /* path with its symlinks followed: what is replaced */
    char *tmp;               /* "<target>.tmp.XXXXXX" once created, else NULL */
    int keep_mode;           /* the target exists: give the new file its mode */
    unsigned mode;
    FILE *f;
    const char *failed_step; /* the first failure, or NULL */
    int failed_errno;
    int stream;              /* atomic_open_stream: f is the caller's, nothing renamed */
} AtomicFile;

/* Creates the temporary file beside `path`. `what` names the kind of file in messages
 * ("checkpoint"; "" for an image). On failure nothing is left behind. */
Status atomic_open(AtomicFile *af, const char *path, const char *what, Error *err);
/* The same writer over an open stream (standard output, `-o -`): the bytes go straight
 * to f, which is flushed by atomic_commit and never closed. Nothing about it is atomic
 * (a reader sees the bytes as they come, and a failure leaves what was written); the
 * failures are still remembered and reported as "cannot write <what> to <name>". */
void atomic_open_stream(AtomicFile *af, FILE *f, const char *name, const char *what);
/* Checks, before a long render, that `path` can be written: creates and removes the
 * temporary file atomic_open would. Fails as atomic_open would (ST_IO, the same
 * message: a missing or unwritable folder, a folder, FIFO or device in the file's
 * place). */
Status atomic_probe(const char *path, const char *what, Error *err);
/* Appends n bytes (skipped after a failure). */
void atomic_write(AtomicFile *af, const void *data, size_t n);
/* Records a failure of the writer's own (an encoder's), with errno or EIO. */
void atomic_fail(AtomicFile *af, const char *step);
/* Flushes, syncs, gives the file the mode of the file it replaces, or for a new file
 * the mode an ordinary fopen() would (0666 less the umask), renames it over the target and syncs the folder. On any failure, including
 * an earlier one, the temporary file is removed, the target left as it was, and the
 * error is "cannot write <what> '<path>': <step>: <errno text>". */
Status atomic_commit(AtomicFile *af, Error *err);
/* Gives up: removes the temporary file; the target is untouched. */
void atomic_abort(AtomicFile *af);

#endif
