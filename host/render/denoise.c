/* denoise.c — Open Image Denoise through dlopen (see denoise.h). */
#include "render/denoise.h"

#include <dlfcn.h>
#include <float.h>
#include <limits.h>
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ------------------------------------------------------------------ OIDN's C API
 *
 * The part of OIDN 2's public C API (oidn.h, as its documentation describes it) that
 * clpt calls, declared here so that neither the header nor the library is needed to
 * build. Handles are opaque pointers; the enums are ints of the documented values. */
typedef void *OidnDevice;
typedef void *OidnFilter;
typedef void *OidnBuffer;
enum {
    OIDN_DEVICE_TYPE_DEFAULT = 0,   /* the fastest device OIDN supports here */
    OIDN_ERROR_NONE = 0,
    OIDN_ERROR_CANCELLED = 6,       /* a progress monitor returned false */
    OIDN_FORMAT_FLOAT3 = 3
};

/* OIDN_FUNCTIONS(X) calls X(return type, name, parameters) once per function: the
 * table's members and the dlsym loop both come from it. */
#define OIDN_FUNCTIONS(X) \
    X(OidnDevice, oidnNewDevice, (int type)) \
    X(void, oidnCommitDevice, (OidnDevice device)) \
    X(void, oidnReleaseDevice, (OidnDevice device)) \
    X(int, oidnGetDeviceInt, (OidnDevice device, const char *name)) \
    X(int, oidnGetDeviceError, (OidnDevice device, const char **message)) \
    X(OidnBuffer, oidnNewBuffer, (OidnDevice device, size_t bytes)) \
    X(void, oidnWriteBuffer, (OidnBuffer buffer, size_t offset, size_t bytes, const void *src)) \
    X(void, oidnReadBuffer, (OidnBuffer buffer, size_t offset, size_t bytes, void *dst)) \
    X(void, oidnReleaseBuffer, (OidnBuffer buffer)) \
    X(OidnFilter, oidnNewFilter, (OidnDevice device, const char *type)) \
    X(void, oidnSetFilterImage, (OidnFilter filter, const char *name, OidnBuffer buffer, int format, size_t width, \
                                 size_t height, size_t offset, size_t pixel_stride, size_t row_stride)) \
    X(void, oidnSetFilterBool, (OidnFilter filter, const char *name, bool value)) \
    X(void, oidnCommitFilter, (OidnFilter filter)) \
    X(void, oidnExecuteFilter, (OidnFilter filter)) \
    X(void, oidnSetFilterProgressMonitorFunction, (OidnFilter filter, bool (*func)(void *user, double n), \
                                                   void *user)) \
    X(void, oidnReleaseFilter, (OidnFilter filter))

struct Denoiser {
    void *lib;
    char path[PATH_MAX];          /* the file it was loaded from */
#define X(ret, name, params) ret(*name) params;
    OIDN_FUNCTIONS(X)
#undef X
    OidnDevice device;
    const volatile sig_atomic_t *cancel;   /* denoiser_set_cancel's flag, or NULL */
};

#define OIDN_SONAME "libOpenImageDenoise.so.2"
#define OIDN_FETCH_HINT "fetch it with: sh tools/deps.sh oidn (./run.sh does too)"

/* ------------------------------------------------------------------ finding the library */

/* The folder of the running program (/proc/self/exe), into dir; 0 when unknown. */
static int program_dir(char *dir, size_t size)
{
    ssize_t n = readlink("/proc/self/exe", dir, size - 1);
    if (n <= 0) return 0;
    dir[n] = '\0';
    char *slash = strrchr(dir, '/');
    if (!slash) return 0;
    *slash = '\0';
    return 1;
}

/* dlopen of DIR/OIDN_SONAME. A file that is there but does not load is an error (its
 * reason matters more than a system copy's); a missing file is not. */
static void *open_in(const char *dir, char *path, size_t size, Error *err, Status *st)
{
    snprintf(path, size, "%s/%s", dir, OIDN_SONAME);
    if (access(path, F_OK) != 0) return NULL;
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) *st = error_set(err, ST_DEVICE, "cannot load Open Image Denoise from '%s': %s", path, dlerror());
    return lib;
}

/* Where clpt looks, in order: only $CLPT_OIDN_DIR when it is set; else oidn/lib beside
 * the program (build/clpt) or one folder up (build/tests/..., build/bench/...), where
 * tools/oidn_fetch.sh puts it, or ../lib/clpt/oidn/lib (PREFIX/bin/clpt finds
 * PREFIX/lib/clpt/oidn/lib, where `make install` copies it: a private folder, so that
 * its TBB is not put on the system's library path); else the system's library path. */
static void *denoiser_load(char *path, size_t size, Error *err, Status *st)
{
    const char *env = getenv(DENOISE_DIR_ENV);
    void *lib = NULL;
    if (env && *env) {
        if (!(lib = open_in(env, path, size, err, st)) && *st == ST_OK)
            *st = error_set(err, ST_DEVICE, "--denoise needs Intel Open Image Denoise 2 (%s), which is not in '%s' "
                            "(named by %s); %s", OIDN_SONAME, env, DENOISE_DIR_ENV, OIDN_FETCH_HINT);
        return lib;
    }
    char exe[PATH_MAX], dir[PATH_MAX + 16];
    if (program_dir(exe, sizeof exe)) {
        static const char *const below[] = { "oidn/lib", "../oidn/lib", "../lib/clpt/oidn/lib" };
        for (size_t i = 0; i < sizeof below / sizeof *below && !lib && *st == ST_OK; i++) {
            snprintf(dir, sizeof dir, "%s/%s", exe, below[i]);
            lib = open_in(dir, path, size, err, st);
        }
    }
    if (lib || *st != ST_OK) return lib;
    snprintf(path, size, "%s", OIDN_SONAME);
    if (!(lib = dlopen(OIDN_SONAME, RTLD_NOW | RTLD_LOCAL)))
        *st = error_set(err, ST_DEVICE, "--denoise needs Intel Open Image Denoise 2 (%s), found neither beside "
                        "the program (oidn/lib, ../lib/clpt/oidn/lib) nor on the system's library path; %s", OIDN_SONAME, OIDN_FETCH_HINT);
    return lib;
}

/* Every function of OIDN_FUNCTIONS, and the real file behind a system copy. */
static Status denoiser_resolve(Denoiser *d, Error *err)
{
#define X(ret, name, params) \
    *(void **)&d->name = dlsym(d->lib, #name); \
    if (!d->name) \
        return error_set(err, ST_DEVICE, "'%s' has no %s: not Open Image Denoise 2 (%s)", d->path, #name, \
                         OIDN_FETCH_HINT);
    OIDN_FUNCTIONS(X)
#undef X
    Dl_info info;
    if (dladdr(*(void **)&d->oidnNewDevice, &info) && info.dli_fname) {
        char real[PATH_MAX];
        snprintf(d->path, sizeof d->path, "%s", realpath(info.dli_fname, real) ? real : info.dli_fname);
    }
    return ST_OK;
}

/* OIDN records the first error of a device until it is asked: ST_DEVICE with its
 * message, or ST_OK. */
static Status denoiser_check(const Denoiser *d, const char *step, Error *err)
{
    const char *msg = NULL;
    int code = d->oidnGetDeviceError(d->device, &msg);
    if (code == OIDN_ERROR_NONE) return ST_OK;
    if (code == OIDN_ERROR_CANCELLED) return error_set(err, ST_INTERRUPTED, "denoising was cancelled");
    return error_set(err, ST_DEVICE, "Open Image Denoise (%s) failed %s: %s (error %d)", d->path, step,
                     msg && *msg ? msg : "no message", code);
}

Status denoiser_open(Denoiser **out, Error *err)
{
    *out = NULL;
    Denoiser *d = calloc(1, sizeof *d);
    if (!d) return error_set(err, ST_INTERNAL, "out of memory");
    Status st = ST_OK;
    d->lib = denoiser_load(d->path, sizeof d->path, err, &st);
    if (st == ST_OK) st = denoiser_resolve(d, err);
    if (st == ST_OK && !(d->device = d->oidnNewDevice(OIDN_DEVICE_TYPE_DEFAULT)))
        st = error_set(err, ST_DEVICE, "Open Image Denoise (%s) has no device it can run on here", d->path);
    if (st == ST_OK) {
        d->oidnCommitDevice(d->device);
        st = denoiser_check(d, "to start its device", err);
    }
    if (st != ST_OK) {
        denoiser_close(d);
        return st;
    }
    *out = d;
    return ST_OK;
}

const char *denoiser_library(const Denoiser *d) { return d->path; }

void denoiser_set_cancel(Denoiser *d, const volatile sig_atomic_t *cancel) { d->cancel = cancel; }

const char *denoiser_device_kind(const Denoiser *d)
{
    static const char *const kinds[] = { "default", "CPU", "SYCL", "CUDA", "HIP", "Metal" };
    int t = d->oidnGetDeviceInt(d->device, "type");
    return t >= 0 && t < 6 ? kinds[t] : "unknown";
}

void denoiser_close(Denoiser *d)
{
    if (!d) return;
    if (d->device) d->oidnReleaseDevice(d->device);
    if (d->lib) dlclose(d->lib);
    free(d);
}

/* ------------------------------------------------------------------ denoising */

/* One image in a buffer of OIDN's device. */
typedef enum { IMG_COLOR, IMG_ALBEDO, IMG_NORMAL, IMG_OUTPUT, IMG_COUNT } ImageSlot;

static float clampf(float x, float lo, float hi) { return x > lo ? (x < hi ? x : hi) : lo; }

/* What OIDN is given: finite values in the ranges its documentation asks for (colour
 * non-negative, albedo 0..1, normal -1..1). NaN fails every comparison and becomes lo. */
static void clean_input(const float *in, float *tmp, size_t n, ImageSlot slot)
{
    float lo = slot == IMG_NORMAL ? -1.0f : 0.0f, hi = slot == IMG_COLOR ? FLT_MAX : 1.0f;
    for (size_t i = 0; i < n; i++) tmp[i] = clampf(in[i], lo, hi);
}

/* OIDN's progress monitor: called from its threads between pieces of the filter's
 * work; false stops the filter (oidnExecuteFilter returns, the device's error is
 * OIDN_ERROR_CANCELLED). The flag is only read. */
static bool keep_going(void *user, double progress)
{
    (void)progress;
    const volatile sig_atomic_t *cancel = user;
    return !*cancel;
}

/* Whether the caller's flag asks to stop: checked before each filter too, so that a
 * raised flag costs no upload or filter at all. */
static Status cancelled(const Denoiser *d, Error *err)
{
    return d->cancel && *d->cancel ? error_set(err, ST_INTERRUPTED, "denoising was cancelled") : ST_OK;
}

/* One RT filter over the buffers in buf (NULL: not an input), with `set` naming the
 * slot each is given as. The features are prefiltered by passing them alone, as
 * "albedo" or "normal", with the output in place. */
static Status run_filter(Denoiser *d, OidnBuffer const *buf, const char *const *set, OidnBuffer output, unsigned w,
                         unsigned h, int hdr, int clean_aux, const char *step, Error *err)
{
    Status st = cancelled(d, err);
    if (st != ST_OK) return st;
    OidnFilter f = d->oidnNewFilter(d->device, "RT");
    st = denoiser_check(d, step, err);
    if (st != ST_OK || !f) return st ? st : error_set(err, ST_DEVICE, "Open Image Denoise has no RT filter");
    if (d->cancel) d->oidnSetFilterProgressMonitorFunction(f, keep_going, (void *)(uintptr_t)d->cancel);
    for (int s = 0; s < IMG_OUTPUT; s++)
        if (buf[s]) d->oidnSetFilterImage(f, set[s], buf[s], OIDN_FORMAT_FLOAT3, w, h, 0, 0, 0);
    d->oidnSetFilterImage(f, "output", output, OIDN_FORMAT_FLOAT3, w, h, 0, 0, 0);
    if (hdr) d->oidnSetFilterBool(f, "hdr", true);
    if (clean_aux) d->oidnSetFilterBool(f, "cleanAux", true);
    d->oidnCommitFilter(f);
    d->oidnExecuteFilter(f);
    st = denoiser_check(d, step, err);
    d->oidnReleaseFilter(f);
    return st;
}

static const char *const slot_names[IMG_OUTPUT] = { "color", "albedo", "normal" };

/* Prefilters the features in buf (those present), each alone, in place. */
static Status prefilter(Denoiser *d, OidnBuffer *buf, unsigned w, unsigned h, Error *err)
{
    const char *const *names = slot_names;
    Status st = ST_OK;
    for (int s = IMG_ALBEDO; s <= IMG_NORMAL && st == ST_OK; s++) {
        if (!buf[s]) continue;
        OidnBuffer alone[IMG_OUTPUT] = { NULL, NULL, NULL };
        alone[s] = buf[s];
        st = run_filter(d, alone, names, buf[s], w, h, 0, 0, s == IMG_ALBEDO ? "denoising the albedo"
                                                                              : "denoising the normals", err);
    }
    return st;
}

/* The colour through the RT filter with the (clean) features as they are in buf. */
static Status run_color(Denoiser *d, OidnBuffer *buf, unsigned w, unsigned h, Error *err)
{
    return run_filter(d, buf, slot_names, buf[IMG_OUTPUT], w, h, 1, buf[IMG_ALBEDO] || buf[IMG_NORMAL],
                      "denoising the image", err);
}

/* The inputs, cleaned, into device buffers; NULL inputs get none. */
static Status upload(Denoiser *d, const float *const *in, OidnBuffer *buf, size_t n, Error *err)
{
    float *tmp = malloc(n * sizeof *tmp);
    if (!tmp) return error_set(err, ST_INTERNAL, "out of memory for the denoiser");
    Status st = ST_OK;
    for (int s = 0; s < IMG_COUNT && st == ST_OK; s++) {
        if (s != IMG_OUTPUT && !in[s]) continue;
        buf[s] = d->oidnNewBuffer(d->device, n * sizeof *tmp);
        if ((st = denoiser_check(d, "to allocate its images", err))) break;
        if (!buf[s]) {
            st = error_set(err, ST_DEVICE, "Open Image Denoise could not allocate its images");
            break;
        }
        if (s == IMG_OUTPUT) continue;
        clean_input(in[s], tmp, n, (ImageSlot)s);
        d->oidnWriteBuffer(buf[s], 0, n * sizeof *tmp, tmp);
    }
    free(tmp);
    return st;
}

/* denoiser_run, with the features prefiltered here or not (already clean). */
static Status denoise_image(Denoiser *d, const float *color, const float *albedo, const float *normal,
                            unsigned width, unsigned height, float *out, int features_raw, Error *err)
{
    size_t n = (size_t)width * height * 3u;
    const float *in[IMG_COUNT] = { color, albedo, normal, NULL };
    OidnBuffer buf[IMG_COUNT] = { NULL, NULL, NULL, NULL };
    Status st = upload(d, in, buf, n, err);
    if (st == ST_OK && features_raw) st = prefilter(d, buf, width, height, err);
    if (st == ST_OK) st = run_color(d, buf, width, height, err);
    if (st == ST_OK) {
        d->oidnReadBuffer(buf[IMG_OUTPUT], 0, n * sizeof *out, out);
        st = denoiser_check(d, "reading the image back", err);
    }
    /* the network's output is finite for finite input; kept so whatever comes back */
    if (st == ST_OK)
        for (size_t i = 0; i < n; i++) out[i] = clampf(out[i], 0.0f, FLT_MAX);
    for (int s = 0; s < IMG_COUNT; s++)
        if (buf[s]) d->oidnReleaseBuffer(buf[s]);
    return st;
}

Status denoiser_run(Denoiser *d, const float *color, const float *albedo, const float *normal, unsigned width,
                    unsigned height, float *out, Error *err)
{
    return denoise_image(d, color, albedo, normal, width, height, out, 1, err);
}

Status denoiser_run_clean(Denoiser *d, const float *color, const float *albedo, const float *normal, unsigned width,
                          unsigned height, float *out, Error *err)
{
    return denoise_image(d, color, albedo, normal, width, height, out, 0, err);
}

Status denoiser_clean_features(Denoiser *d, float *albedo, float *normal, unsigned width, unsigned height,
                               Error *err)
{
    size_t n = (size_t)width * height * 3u;
    const float *in[IMG_COUNT] = { NULL, albedo, normal, NULL };
    OidnBuffer buf[IMG_COUNT] = { NULL, NULL, NULL, NULL };
    Status st = upload(d, in, buf, n, err);
    if (st == ST_OK) st = prefilter(d, buf, width, height, err);
    for (int s = IMG_ALBEDO; s <= IMG_NORMAL && st == ST_OK; s++)
        if (buf[s]) {
            d->oidnReadBuffer(buf[s], 0, n * sizeof(float), s == IMG_ALBEDO ? albedo : normal);
            st = denoiser_check(d, "reading the features back", err);
        }
    for (int s = 0; s < IMG_COUNT; s++)
        if (buf[s]) d->oidnReleaseBuffer(buf[s]);
    return st;
}
