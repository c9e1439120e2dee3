/* api_context.c — contexts, their errors and warnings, and the device listing
 * (include/clpt/clpt.h). */
#include "api/api.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CLPT_STR2(x) #x
#define CLPT_STR(x) CLPT_STR2(x)

const char *clpt_version(void)
{
    return CLPT_STR(CLPT_VERSION_MAJOR) "." CLPT_STR(CLPT_VERSION_MINOR) "." CLPT_STR(CLPT_VERSION_PATCH);
}

/* The default warning callback: what the program prints. */
static void warn_stderr(void *user, const char *msg)
{
    (void)user;
    fprintf(stderr, "clpt: warning: %s\n", msg);
}

clpt_context *clpt_context_create(void)
{
    clpt_context *ctx = calloc(1, sizeof *ctx);
    if (ctx) ctx->warn = warn_stderr;
    return ctx;
}

void clpt_context_free(clpt_context *ctx)
{
    if (!ctx) return;
    error_clear(&ctx->err);
    free(ctx->device_spec);
    free(ctx->devices);
    free(ctx);
}

const char *clpt_last_error(const clpt_context *ctx)
{
    return ctx ? ctx->err.msg : "no context (clpt_context_create returned NULL: out of memory)";
}

clpt_status api_fail(clpt_context *ctx, Status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    error_clear(&ctx->err);
    vsnprintf(ctx->err.msg, sizeof ctx->err.msg, fmt, ap);
    ctx->err.status = st;
    va_end(ap);
    return (clpt_status)st;
}

void api_warn(void *vctx, const char *msg)
{
    clpt_context *ctx = vctx;
    if (ctx->warn) ctx->warn(ctx->warn_user, msg);
}

void clpt_context_set_warning_callback(clpt_context *ctx, clpt_warning_fn fn, void *user)
{
    if (!ctx) return;
    ctx->warn = fn;
    ctx->warn_user = user;
}

Status api_devices(clpt_context *ctx, Error *err)
{
    if (ctx->listed) return ST_OK;
    char warning[1100];
    Status st = device_list(&ctx->devices, &ctx->n_devices, warning, sizeof warning, err);
    if (st) return st;
    /* a broken OpenCL installation leaves the scalar device: said once, as the program does */
    if (warning[0]) api_warn(ctx, warning);
    ctx->listed = 1;
    return ST_OK;
}

clpt_status clpt_context_set_devices(clpt_context *ctx, const char *spec)
{
    if (!ctx) return CLPT_ERROR_USAGE;
    error_clear(&ctx->err);
    char *copy = spec && spec[0] ? strdup(spec) : NULL;
    if (spec && spec[0] && !copy) return api_fail(ctx, ST_INTERNAL, "out of memory");
    size_t *chosen = NULL, n_chosen = 0;
    Status st = api_devices(ctx, &ctx->err);
    /* checked now, so that a spec naming nothing fails here and not at the render */
    if (st == ST_OK) st = device_select(copy, ctx->devices, ctx->n_devices, &chosen, &n_chosen, &ctx->err);
    free(chosen);
    if (st != ST_OK) {
        free(copy);
        return (clpt_status)st;
    }
    free(ctx->device_spec);
    ctx->device_spec = copy;
    return CLPT_OK;
}

/* Device i of the listing, NULL past its end or when the listing failed (the error is
 * then the context's). */
static const DeviceDesc *device_at(clpt_context *ctx, size_t i)
{
    if (!ctx || api_devices(ctx, &ctx->err) != ST_OK || i >= ctx->n_devices) return NULL;
    return &ctx->devices[i];
}

size_t clpt_device_count(clpt_context *ctx)
{
    return ctx && api_devices(ctx, &ctx->err) == ST_OK ? ctx->n_devices : 0;
}

const char *clpt_device_name(clpt_context *ctx, size_t i)
{
    const DeviceDesc *d = device_at(ctx, i);
    if (!d) return NULL;
    return d->kind == DEVICE_SCALAR ? "scalar C device" : d->name;
}

const char *clpt_device_kind(clpt_context *ctx, size_t i)
{
    const DeviceDesc *d = device_at(ctx, i);
    return !d ? NULL : d->kind == DEVICE_SCALAR ? "scalar" : "opencl";
}

const char *clpt_device_type(clpt_context *ctx, size_t i)
{
    const DeviceDesc *d = device_at(ctx, i);
    return d ? d->type_name : NULL;
}

const char *clpt_device_platform(clpt_context *ctx, size_t i)
{
    const DeviceDesc *d = device_at(ctx, i);
    return !d ? NULL : d->kind == DEVICE_SCALAR ? "" : d->platform_name;
}

int clpt_device_index(clpt_context *ctx, size_t i)
{
    const DeviceDesc *d = device_at(ctx, i);
    return d && d->kind == DEVICE_OPENCL ? (int)d->index : -1;
}
