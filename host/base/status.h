/*
 * status.h — status codes and the error record.
 *
 * A failing function fills an Error where the failure happens (with file:line:column,
 * the device and call, or whatever locates it) and returns its status; callers pass the
 * status up unchanged, and main() prints the message once and exits with the code.
 * The numeric values are the program's documented exit codes (docs/exit-codes.md).
 */
#ifndef CLPT_STATUS_H
#define CLPT_STATUS_H

#include <stddef.h>

typedef enum {
    ST_OK = 0,            /* success */
    ST_INTERNAL = 1,      /* a bug or an unexpected system failure (out of memory) */
    ST_USAGE = 2,         /* bad command line */
    ST_INPUT = 3,         /* a scene, mesh or other input file is malformed */
    ST_IO = 4,            /* a file could not be read or written */
    ST_DEVICE = 5,        /* no usable device, or a device failed */
    ST_INTERRUPTED = 6,   /* stopped by SIGINT/SIGTERM; the partial image was written */
    ST_NOTHING_RENDERED = 7 /* --time-limit ran out before a batch finished; no output written */
} Status;

typedef struct {
    Status status;
    char msg[1024];       /* one or a few lines, no trailing newline */
    char *detail;         /* optional long text (an OpenCL build log), heap-allocated */
} Error;

/* Formats the message into err (if err is non-NULL) and returns `status`. */
Status error_set(Error *err, Status status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Attaches a copy of a long detail text to err (no-op if err is NULL or copy fails). */
void error_set_detail(Error *err, const char *detail);
/* Prepends "prefix: " to the message already in err. */
void error_prefix(Error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Appends the formatted text to the message already in err, as much of it as fits. */
void error_append(Error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void error_clear(Error *err);
/* Prints "clpt: error: <msg>" (and the detail) to stderr. */
void error_print(const Error *err);
const char *status_name(Status s);

#endif /* CLPT_STATUS_H */
