#include "base/status.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

Status error_set(Error *err, Status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->status = status;
    }
    return status;
}

void error_set_detail(Error *err, const char *detail)
{
    if (!err || !detail) return;
    free(err->detail);
    size_t n = strlen(detail);
    err->detail = malloc(n + 1);
    if (err->detail) memcpy(err->detail, detail, n + 1);
}

void error_prefix(Error *err, const char *fmt, ...)
{
    if (!err) return;
    char prefix[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    char old[sizeof err->msg];
    memcpy(old, err->msg, sizeof old);
    /* prefix, ": ", then as much of the old message as fits */
    size_t cap = sizeof err->msg - 1, n = strlen(prefix);
    if (n > cap) n = cap;
    memcpy(err->msg, prefix, n);
    for (const char *s = ": "; *s && n < cap; s++) err->msg[n++] = *s;
    size_t m = strlen(old);
    if (m > cap - n) m = cap - n;
    memcpy(err->msg + n, old, m);
    err->msg[n + m] = '\0';
}

void error_append(Error *err, const char *fmt, ...)
{
    if (!err) return;
    size_t n = strlen(err->msg);
    if (n + 1 >= sizeof err->msg) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg + n, sizeof err->msg - n, fmt, ap);
    va_end(ap);
}

void error_clear(Error *err)
{
    if (!err) return;
    free(err->detail);
    err->detail = NULL;
    err->msg[0] = '\0';
    err->status = ST_OK;
}

void error_print(const Error *err)
{
    fprintf(stderr, "clpt: error: %s\n", err->msg[0] ? err->msg : status_name(err->status));
    if (err->detail && err->detail[0]) {
        size_t n = strlen(err->detail);
        fprintf(stderr, "%s%s", err->detail, err->detail[n - 1] == '\n' ? "" : "\n");
    }
}

const char *status_name(Status s)
{
    switch (s) {
    case ST_OK: return "success";
    case ST_INTERNAL: return "internal error";
    case ST_USAGE: return "usage error";
    case ST_INPUT: return "input error";
    case ST_IO: return "I/O error";
    case ST_DEVICE: return "device error";
    case ST_INTERRUPTED: return "interrupted";
    case ST_NOTHING_RENDERED: return "nothing rendered";
    }
    return "unknown status";
}
