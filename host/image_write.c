/*
 * image_write.c — PNG/PPM/BMP/PFM encoding over an atomic temp-file-and-rename writer.
 *
 * PNG compression is stb_image_write's (Debian's libstb); it hands us the finished file
 * in memory through a callback, so every byte on disk goes through our own checked writes.
 */
#include "image_write.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stb_image_write.h>

#define SUPPORTED_EXTENSIONS ".png, .ppm, .pfm, .bmp"

Status image_format_from_path(const char *path, ImageFormat *fmt, Error *err)
{
    const char *slash = strrchr(path, '/');
    const char *name = slash ? slash + 1 : path;
    const char *dot = strrchr(name, '.');
    if (!dot || dot == name)
        return error_set(err, ST_USAGE,
                         "cannot tell the image format of '%s': it has no extension "
                         "(supported: " SUPPORTED_EXTENSIONS ")", path);
    if (strcasecmp(dot, ".png") == 0) *fmt = IMAGE_PNG;
    else if (strcasecmp(dot, ".ppm") == 0) *fmt = IMAGE_PPM;
    else if (strcasecmp(dot, ".pfm") == 0) *fmt = IMAGE_PFM;
    else if (strcasecmp(dot, ".bmp") == 0) *fmt = IMAGE_BMP;
    else
        return error_set(err, ST_USAGE,
                         "cannot tell the image format of '%s': unsupported extension '%s' "
                         "(supported: " SUPPORTED_EXTENSIONS ")", path, dot);
    return ST_OK;
}

/* ------------------------------------------------------------------ sRGB encoding */

float image_srgb_encode(float linear)
{
    double x = linear;
    if (!(x > 0.0)) return 0.0f; /* also catches NaN */
    if (x >= 1.0) return 1.0f;
    if (x <= 0.0031308) return (float)(12.92 * x);
    return (float)(1.055 * pow(x, 1.0 / 2.4) - 0.055);
}

unsigned char image_to_srgb8(float linear)
{
    return (unsigned char)floor((double)image_srgb_encode(linear) * 255.0 + 0.5);
}

unsigned char image_to_linear8(float linear)
{
    double x = linear;
    if (!(x > 0.0)) return 0;
    if (x >= 1.0) return 255;
    return (unsigned char)floor(x * 255.0 + 0.5);
}

/* ------------------------------------------------------------------ atomic file */

/* A file being written under a temporary name. The first failure is remembered (step and
 * errno) and later writes are skipped, so the encoders need not check each call. */
typedef struct {
    const char *path; /* the target */
    char *tmp;        /* "<path>.tmp.XXXXXX" once created, else NULL */
    FILE *f;
    const char *failed_step;
    int failed_errno;
} AtomicFile;

static void atomic_fail(AtomicFile *af, const char *step)
{
    if (af->failed_step) return;
    af->failed_step = step;
    af->failed_errno = errno ? errno : EIO;
}

static Status atomic_error(const AtomicFile *af, Error *err)
{
    return error_set(err, ST_IO, "cannot write '%s': %s: %s", af->path, af->failed_step,
                     strerror(af->failed_errno));
}

/* Drops the temporary file; the target is never touched before the final rename. */
static void atomic_abort(AtomicFile *af)
{
    if (af->f) fclose(af->f);
    af->f = NULL;
    if (af->tmp) unlink(af->tmp);
    free(af->tmp);
    af->tmp = NULL;
}

/* The temporary file lives in the target's folder so that the final rename stays within
 * one filesystem, where it is atomic. */
static Status atomic_open(AtomicFile *af, const char *path, Error *err)
{
    static const char suffix[] = ".tmp.XXXXXX";
    memset(af, 0, sizeof *af);
    af->path = path;
    size_t n = strlen(path);
    af->tmp = malloc(n + sizeof suffix);
    if (!af->tmp)
        return error_set(err, ST_INTERNAL, "cannot write '%s': out of memory", path);
    memcpy(af->tmp, path, n);
    memcpy(af->tmp + n, suffix, sizeof suffix);
    errno = 0;
    int fd = mkostemp(af->tmp, O_CLOEXEC);
    if (fd < 0) {
        atomic_fail(af, "cannot create a temporary file beside it");
        free(af->tmp);
        af->tmp = NULL; /* nothing was created, so nothing to remove */
        return atomic_error(af, err);
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

static void atomic_write(AtomicFile *af, const void *data, size_t n)
{
    if (af->failed_step || n == 0) return;
    errno = 0;
    if (fwrite(data, 1, n, af->f) != n) atomic_fail(af, "write");
}

/* mkstemp creates files 0600; give the image the mode an ordinary fopen() would have,
 * 0666 less the umask. umask() can only be read by changing it, which would race with
 * other threads creating files, so read it from /proc (022 when that is unavailable). */
static mode_t image_file_mode(void)
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
 * the image is complete and in place, so a failure here is not worth failing the write. */
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

/* Flushes and syncs the data (write errors such as a full disk often surface only here),
 * sets the mode, then renames the finished file over the target. */
static Status atomic_commit(AtomicFile *af, Error *err)
{
    if (!af->failed_step) {
        errno = 0;
        if (fflush(af->f) != 0) atomic_fail(af, "write");
    }
    if (!af->failed_step && fsync(fileno(af->f)) != 0) atomic_fail(af, "fsync");
    if (!af->failed_step && fchmod(fileno(af->f), image_file_mode()) != 0)
        atomic_fail(af, "chmod");
    if (!af->failed_step) {
        errno = 0;
        int rc = fclose(af->f);
        af->f = NULL;
        if (rc != 0) atomic_fail(af, "close");
    }
    if (!af->failed_step && rename(af->tmp, af->path) != 0)
        atomic_fail(af, "cannot rename the temporary file over it");
    if (af->failed_step) {
        Status st = atomic_error(af, err);
        atomic_abort(af);
        return st;
    }
    free(af->tmp);
    af->tmp = NULL;
    sync_parent_folder(af->path);
    return ST_OK;
}

/* ------------------------------------------------------------------ encoders */

static void write_ppm(AtomicFile *af, const unsigned char *srgb, unsigned w, unsigned h)
{
    char header[64];
    int n = snprintf(header, sizeof header, "P6\n%u %u\n255\n", w, h);
    atomic_write(af, header, (size_t)n);
    atomic_write(af, srgb, (size_t)w * h * 3);
}

static void png_sink(void *context, void *data, int size)
{
    atomic_write(context, data, (size_t)size);
}

static void write_png(AtomicFile *af, const unsigned char *srgb, unsigned w, unsigned h)
{
    errno = 0;
    if (!stbi_write_png_to_func(png_sink, af, (int)w, (int)h, 3, srgb, (int)(w * 3))) {
        /* stb fails only when its allocations do */
        if (!errno) errno = ENOMEM;
        atomic_fail(af, "PNG encoding");
    }
}

static void put_le(unsigned char *p, uint32_t v, int bytes)
{
    for (int i = 0; i < bytes; i++) p[i] = (unsigned char)(v >> (8 * i));
}

/* BMP: the 14-byte file header and the 40-byte BITMAPINFOHEADER, then 24-bit BGR rows
 * bottom to top, each padded to a multiple of 4 bytes. */
static void write_bmp(AtomicFile *af, const unsigned char *rgb8, unsigned w, unsigned h)
{
    size_t row = ((size_t)w * 3 + 3) & ~(size_t)3;
    unsigned char header[54];
    memset(header, 0, sizeof header);
    header[0] = 'B';
    header[1] = 'M';
    put_le(header + 2, (uint32_t)(sizeof header + row * h), 4);
    put_le(header + 10, sizeof header, 4);
    put_le(header + 14, 40, 4);
    put_le(header + 18, w, 4);
    put_le(header + 22, h, 4);
    put_le(header + 26, 1, 2);       /* planes */
    put_le(header + 28, 24, 2);      /* bits per pixel; compression 0 (none) */
    put_le(header + 34, (uint32_t)(row * h), 4);
    put_le(header + 38, 2835, 4);    /* 72 dpi */
    put_le(header + 42, 2835, 4);
    atomic_write(af, header, sizeof header);
    unsigned char *line = calloc(row, 1);
    if (!line) {
        errno = ENOMEM;
        atomic_fail(af, "BMP encoding");
        return;
    }
    for (unsigned y = h; y-- > 0;) {
        const unsigned char *src = rgb8 + (size_t)y * w * 3;
        for (size_t x = 0; x < w; x++) {
            line[3 * x + 0] = src[3 * x + 2];
            line[3 * x + 1] = src[3 * x + 1];
            line[3 * x + 2] = src[3 * x + 0];
        }
        atomic_write(af, line, row);
    }
    free(line);
}

/* PFM: a text header, scale -1 meaning little-endian floats, then the rows bottom to top.
 * Bytes are assembled explicitly so the file is the same on a big-endian host. */
static Status write_pfm(AtomicFile *af, const float *rgb, unsigned w, unsigned h, Error *err)
{
    char header[64];
    int n = snprintf(header, sizeof header, "PF\n%u %u\n-1.0\n", w, h);
    atomic_write(af, header, (size_t)n);
    size_t row_floats = (size_t)w * 3;
    unsigned char *row = malloc(row_floats * 4);
    if (!row) return error_set(err, ST_INTERNAL, "cannot write '%s': out of memory", af->path);
    for (unsigned y = h; y-- > 0;) {
        const float *src = rgb + (size_t)y * row_floats;
        for (size_t i = 0; i < row_floats; i++) {
            uint32_t bits;
            memcpy(&bits, &src[i], 4);
            row[4 * i + 0] = (unsigned char)(bits & 0xffu);
            row[4 * i + 1] = (unsigned char)((bits >> 8) & 0xffu);
            row[4 * i + 2] = (unsigned char)((bits >> 16) & 0xffu);
            row[4 * i + 3] = (unsigned char)(bits >> 24);
        }
        atomic_write(af, row, row_floats * 4);
    }
    free(row);
    return ST_OK;
}

Status image_write(const char *path, const float *rgb, unsigned width, unsigned height,
                   Error *err)
{
    return image_write_encoded(path, rgb, width, height, IMAGE_SRGB, err);
}

Status image_write_encoded(const char *path, const float *rgb, unsigned width, unsigned height,
                           ImageEncoding encoding, Error *err)
{
    ImageFormat fmt;
    Status st = image_format_from_path(path, &fmt, err);
    if (st != ST_OK) return st;
    if (width == 0 || height == 0 || !rgb)
        return error_set(err, ST_INTERNAL, "cannot write '%s': empty image (%ux%u)", path,
                         width, height);
    /* stb takes int sizes and an int row stride; PFM rows need w*12 bytes. */
    if (width > (unsigned)(INT_MAX / 3) || height > (unsigned)INT_MAX ||
        (size_t)width * height > SIZE_MAX / 12)
        return error_set(err, ST_INTERNAL, "cannot write '%s': image too large (%ux%u)", path,
                         width, height);

    /* Encode before creating the temporary file: running out of memory then leaves no
     * trace on disk. */
    unsigned char *srgb = NULL;
    size_t count = (size_t)width * height * 3;
    if (fmt != IMAGE_PFM) {
        srgb = malloc(count);
        if (!srgb) return error_set(err, ST_INTERNAL, "cannot write '%s': out of memory", path);
        for (size_t i = 0; i < count; i++)
            srgb[i] = encoding == IMAGE_LINEAR ? image_to_linear8(rgb[i]) : image_to_srgb8(rgb[i]);
    }

    AtomicFile af;
    st = atomic_open(&af, path, err);
    if (st != ST_OK) {
        free(srgb);
        return st;
    }
    switch (fmt) {
    case IMAGE_PNG: write_png(&af, srgb, width, height); break;
    case IMAGE_PPM: write_ppm(&af, srgb, width, height); break;
    case IMAGE_BMP: write_bmp(&af, srgb, width, height); break;
    case IMAGE_PFM: st = write_pfm(&af, rgb, width, height, err); break;
    }
    free(srgb);
    if (st != ST_OK) {
        atomic_abort(&af);
        return st;
    }
    return atomic_commit(&af, err);
}
