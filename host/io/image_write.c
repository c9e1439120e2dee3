/*
 * image_write.c — PNG/PPM/BMP/PFM/EXR/HDR encoding, written through atomic_file.h (temp file,
 * rename).
 *
 * 8-bit PNG and JPEG compression is stb_image_write's (Debian's libstb), 16-bit PNG
 * libpng's (stb writes 8 bits only); both hand us the file through a callback, so every
 * byte on disk goes through our own checked writes.
 */
#include "io/image_write.h"

#include "base/atomic_file.h"
#include "base/bytes.h"
#include "io/exr.h"

#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include <png.h>
#include <setjmp.h>
#include <stb_image_write.h>

#define SUPPORTED_EXTENSIONS ".png, .jpg, .jpeg, .ppm, .pfm, .bmp, .exr, .hdr"

/* The formats by their extension, without the dot: also the FORMAT of "FORMAT:-". */
static int format_from_word(const char *word, size_t len, ImageFormat *fmt)
{
    static const struct { const char *name; ImageFormat fmt; } formats[] = {
        { "png", IMAGE_PNG }, { "ppm", IMAGE_PPM }, { "pfm", IMAGE_PFM },
        { "bmp", IMAGE_BMP }, { "exr", IMAGE_EXR }, { "hdr", IMAGE_HDR },
        { "jpg", IMAGE_JPEG }, { "jpeg", IMAGE_JPEG },
    };
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (strlen(formats[i].name) == len && strncasecmp(word, formats[i].name, len) == 0) {
            *fmt = formats[i].fmt;
            return 1;
        }
    return 0;
}

int image_path_is_stdout(const char *path)
{
    size_t n = strlen(path);
    return strcmp(path, "-") == 0 || (n > 2 && strcmp(path + n - 2, ":-") == 0 && !strchr(path, '/'));
}

Status image_stdout_check(Error *err)
{
    if (isatty(STDOUT_FILENO))
        return error_set(err, ST_USAGE, "-o - writes the image to standard output, which is a terminal: "
                         "redirect it (clpt SCENE -o - > image.png, or into a pipe)");
    return ST_OK;
}

/* "-" is PNG; "exr:-" names its format before the colon. */
static Status stdout_format(const char *path, ImageFormat *fmt, Error *err)
{
    if (strcmp(path, "-") == 0) {
        *fmt = IMAGE_PNG;
        return ST_OK;
    }
    if (!format_from_word(path, strlen(path) - 2, fmt))
        return error_set(err, ST_USAGE, "cannot write the image to standard output as '%.*s': -o - writes PNG, "
                         "and FORMAT:- one of png, jpg, ppm, pfm, bmp, exr, hdr", (int)(strlen(path) - 2), path);
    return ST_OK;
}

Status image_format_from_path(const char *path, ImageFormat *fmt, Error *err)
{
    if (image_path_is_stdout(path)) return stdout_format(path, fmt, err);
    const char *slash = strrchr(path, '/');
    const char *name = slash ? slash + 1 : path;
    const char *dot = strrchr(name, '.');
    if (!dot || dot == name)
        return error_set(err, ST_USAGE,
                         "cannot tell the image format of '%s': it has no extension "
                         "(supported: " SUPPORTED_EXTENSIONS ")", path);
    if (!format_from_word(dot + 1, strlen(dot + 1), fmt))
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

unsigned image_to_srgb16(float linear)
{
    return (unsigned)floor((double)image_srgb_encode(linear) * 65535.0 + 0.5);
}

unsigned image_to_linear16(float linear)
{
    double x = linear;
    if (!(x > 0.0)) return 0;
    if (x >= 1.0) return 65535;
    return (unsigned)floor(x * 65535.0 + 0.5);
}

unsigned char image_to_linear8(float linear)
{
    double x = linear;
    if (!(x > 0.0)) return 0;
    if (x >= 1.0) return 255;
    return (unsigned char)floor(x * 255.0 + 0.5);
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

static void write_jpeg(AtomicFile *af, const unsigned char *srgb, unsigned w, unsigned h, unsigned quality)
{
    errno = 0;
    if (!stbi_write_jpg_to_func(png_sink, af, (int)w, (int)h, 3, srgb, (int)quality)) {
        /* as write_png: only an allocation fails */
        if (!errno) errno = ENOMEM;
        atomic_fail(af, "JPEG encoding");
    }
}

static void png16_write(png_structp png, png_bytep data, size_t n)
{
    atomic_write(png_get_io_ptr(png), data, n);
}

static void png16_flush(png_structp png)
{
    (void)png;
}

/* libpng reports an error by longjmp to the setjmp in write_png16; nothing it owns
 * outlives that function, and it prints nothing. */
static void png16_error(png_structp png, png_const_charp msg)
{
    (void)msg;
    png_longjmp(png, 1);
}

static void png16_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

/* A 16-bit RGB PNG of `be16`: the big-endian samples PNG stores, rows top first. */
static void write_png16(AtomicFile *af, const unsigned char *be16, unsigned w, unsigned h)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, png16_error, png16_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_destroy_write_struct(&png, NULL);
        errno = ENOMEM;
        atomic_fail(af, "PNG encoding");
        return;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        if (!af->failed_step) {
            errno = ENOMEM;   /* libpng fails on its allocations; our writes record their own */
            atomic_fail(af, "PNG encoding");
        }
        return;
    }
    png_set_write_fn(png, af, png16_write, png16_flush);
    png_set_IHDR(png, info, w, h, 16, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (unsigned y = 0; y < h; y++) png_write_row(png, be16 + (size_t)y * w * 6u);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
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
    bytes_put_le(header + 2, (uint32_t)(sizeof header + row * h), 4);
    bytes_put_le(header + 10, sizeof header, 4);
    bytes_put_le(header + 14, 40, 4);
    bytes_put_le(header + 18, w, 4);
    bytes_put_le(header + 22, h, 4);
    bytes_put_le(header + 26, 1, 2);       /* planes */
    bytes_put_le(header + 28, 24, 2);      /* bits per pixel; compression 0 (none) */
    bytes_put_le(header + 34, (uint32_t)(row * h), 4);
    bytes_put_le(header + 38, 2835, 4);    /* 72 dpi */
    bytes_put_le(header + 42, 2835, 4);
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
            bytes_put_le32(row + 4 * i, bits);
        }
        atomic_write(af, row, row_floats * 4);
    }
    free(row);
    return ST_OK;
}

/* Radiance HDR through stb_image_write (RLE RGBE), after making every value one RGBE
 * can hold (see image_write.h). */
static Status write_hdr(AtomicFile *af, const float *rgb, unsigned w, unsigned h, Error *err)
{
    size_t n = (size_t)w * h * 3u;
    float *safe = malloc(n * sizeof *safe);
    if (!safe) return error_set(err, ST_INTERNAL, "cannot write '%s': out of memory", af->path);
    for (size_t i = 0; i < n; i++) safe[i] = rgb[i] > 0.0f ? (rgb[i] <= FLT_MAX ? rgb[i] : FLT_MAX) : 0.0f;
    errno = 0;
    if (!stbi_write_hdr_to_func(png_sink, af, (int)w, (int)h, 3, safe)) {
        if (!errno) errno = ENOMEM;
        atomic_fail(af, "HDR encoding");
    }
    free(safe);
    return ST_OK;
}

/* Whether any of the n values is a finite number beyond what a half holds (65504, its
 * largest finite value; what rounds past it becomes infinite). Infinities and NaN a
 * half holds as they are. */
static int exr_beyond_half(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (isfinite(v[i]) && (v[i] > 65504.0f || v[i] < -65504.0f)) return 1;
    return 0;
}

/* Encodes the EXR in memory first (OpenEXR writes at offsets), then writes it whole. */
static Status write_exr(AtomicFile *af, const float *rgb, const ImageLayer *layers, size_t n_layers, unsigned w,
                        unsigned h, int float32, Error *err)
{
    ExrChannel ch[3 + 3 * 8];
    size_t n = 0;
    static const char *const rgb_names[3] = { "R", "G", "B" };
    /* the colour is written as floats where a half would not hold it: a half's largest
     * value is 65504, and a brighter pixel became +inf (issue 39) */
    int wide = exr_beyond_half(rgb, (size_t)w * h * 3u);
    for (int k = 0; k < 3; k++) ch[n++] = (ExrChannel){ rgb_names[k], rgb + k, 3u, 0, wide };
    /* depth (Z) is always float: distances pass 65504 and want more than a half's 11
     * bits; other layers as their values need */
    for (size_t l = 0; l < n_layers && l < 8; l++) {
        int layer_wide = exr_beyond_half(layers[l].rgb, (size_t)w * h * 3u);
        for (int k = 0; k < 3; k++)
            if (layers[l].names[k])
                ch[n++] = (ExrChannel){ layers[l].names[k], layers[l].rgb + k, 3u, 1,
                                        layer_wide || strcmp(layers[l].names[k], "Z") == 0 };
    }
    unsigned char *bytes;
    size_t size;
    Status st = exr_encode(ch, n, w, h, float32, &bytes, &size, err);
    if (st) {
        error_prefix(err, "cannot write '%s'", af->path);
        return st;
    }
    atomic_write(af, bytes, size);
    free(bytes);
    return ST_OK;
}

/* The writer for path: a temporary file renamed over it, or standard output. */
static Status image_open(AtomicFile *af, const char *path, Error *err)
{
    if (!image_path_is_stdout(path)) return atomic_open(af, path, "", err);
    Status st = image_stdout_check(err);
    if (st == ST_OK) atomic_open_stream(af, stdout, "standard output", "the image");
    return st;
}

/* Checks the size every format can take. */
static Status image_check_size(const char *path, const float *rgb, unsigned width, unsigned height, Error *err)
{
    if (width == 0 || height == 0 || !rgb)
        return error_set(err, ST_INTERNAL, "cannot write '%s': empty image (%ux%u)", path,
                         width, height);
    /* stb takes int sizes and an int row stride; PFM rows need w*12 bytes. */
    if (width > (unsigned)(INT_MAX / 3) || height > (unsigned)INT_MAX ||
        (size_t)width * height > SIZE_MAX / 12)
        return error_set(err, ST_INTERNAL, "cannot write '%s': image too large (%ux%u)", path,
                         width, height);
    return ST_OK;
}

Status image_write_exr(const char *path, const float *rgb, const ImageLayer *layers, size_t n_layers, unsigned width,
                       unsigned height, int float32, Error *err)
{
    Status st = image_check_size(path, rgb, width, height, err);
    if (st != ST_OK) return st;
    AtomicFile af;
    if ((st = image_open(&af, path, err)) != ST_OK) return st;
    if ((st = write_exr(&af, rgb, layers, n_layers, width, height, float32, err)) != ST_OK) {
        atomic_abort(&af);
        return st;
    }
    return atomic_commit(&af, err);
}

Status image_write(const char *path, const float *rgb, unsigned width, unsigned height,
                   Error *err)
{
    return image_write_encoded(path, rgb, width, height, IMAGE_SRGB, err);
}

int image_format_is_display(ImageFormat fmt)
{
    return fmt == IMAGE_PNG || fmt == IMAGE_PPM || fmt == IMAGE_BMP || fmt == IMAGE_JPEG;
}

Status image_check_look(const char *path, const ViewLook *look, Error *err)
{
    ImageFormat fmt;
    Error ignored = { 0 };
    int known = image_format_from_path(path, &fmt, &ignored) == ST_OK;
    error_clear(&ignored);
    if (!known || image_format_is_display(fmt) || view_look_is_identity(look)) return ST_OK;
    return error_set(err, ST_USAGE, "--view and --exposure form the picture of 8-bit images; '%s' keeps the linear "
                     "radiance (write a .png, .jpg, .ppm or .bmp, or leave them out)", path);
}

Status image_write_encoded(const char *path, const float *rgb, unsigned width, unsigned height,
                           ImageEncoding encoding, Error *err)
{
    ImageStyle style = { encoding, { VIEW_STANDARD, 0.0 }, 0 };
    return image_write_styled(path, rgb, width, height, &style, err);
}

/* A display format's samples of `count` values: bytes, or with `wide` big-endian 16-bit
 * words (a 16-bit PNG's); NULL when out of memory. */
static unsigned char *encode_display(const float *src, size_t count, ImageEncoding encoding, int wide)
{
    unsigned char *out = malloc(count * (wide ? 2u : 1u));
    if (!out) return NULL;
    int linear = (encoding & IMAGE_LINEAR) != 0;
    for (size_t i = 0; i < count; i++) {
        if (!wide) {
            out[i] = linear ? image_to_linear8(src[i]) : image_to_srgb8(src[i]);
            continue;
        }
        unsigned v = linear ? image_to_linear16(src[i]) : image_to_srgb16(src[i]);
        out[2 * i] = (unsigned char)(v >> 8);
        out[2 * i + 1] = (unsigned char)(v & 0xffu);
    }
    return out;
}

/* The picture a display format stores: rgb through the look, in a new buffer (*out);
 * NULL in *out when the look changes nothing. */
static Status image_form_picture(const char *path, const float *rgb, size_t n_pixels, const ViewLook *look,
                                 float **out, Error *err)
{
    *out = NULL;
    if (view_look_is_identity(look)) return ST_OK;
    if (!(*out = malloc(n_pixels * 3 * sizeof **out)))
        return error_set(err, ST_INTERNAL, "cannot write '%s': out of memory", path);
    memcpy(*out, rgb, n_pixels * 3 * sizeof **out);
    view_apply(look, *out, n_pixels);
    return ST_OK;
}

Status image_write_styled(const char *path, const float *rgb, unsigned width, unsigned height,
                          const ImageStyle *style, Error *err)
{
    ImageFormat fmt;
    ImageEncoding encoding = style->encoding;
    Status st = image_format_from_path(path, &fmt, err);
    if (st != ST_OK) return st;
    if ((st = image_check_size(path, rgb, width, height, err)) != ST_OK) return st;
    float *picture = NULL;
    if (image_format_is_display(fmt) &&
        (st = image_form_picture(path, rgb, (size_t)width * height, &style->look, &picture, err)))
        return st;
    const float *src = picture ? picture : rgb;

    /* Encode before creating the temporary file: running out of memory then leaves no
     * trace on disk. */
    unsigned char *srgb = NULL;
    int png16 = fmt == IMAGE_PNG && (encoding & IMAGE_PNG16);
    if (image_format_is_display(fmt) && !(srgb = encode_display(src, (size_t)width * height * 3, encoding, png16))) {
        free(picture);
        return error_set(err, ST_INTERNAL, "cannot write '%s': out of memory", path);
    }
    free(picture);

    AtomicFile af;
    st = image_open(&af, path, err);
    if (st != ST_OK) {
        free(srgb);
        return st;
    }
    switch (fmt) {
    case IMAGE_PNG:
        if (png16) write_png16(&af, srgb, width, height);
        else write_png(&af, srgb, width, height);
        break;
    case IMAGE_JPEG: write_jpeg(&af, srgb, width, height, style->jpeg_quality ? style->jpeg_quality : IMAGE_JPEG_QUALITY); break;
    case IMAGE_PPM: write_ppm(&af, srgb, width, height); break;
    case IMAGE_BMP: write_bmp(&af, srgb, width, height); break;
    case IMAGE_PFM: st = write_pfm(&af, rgb, width, height, err); break;
    case IMAGE_HDR: st = write_hdr(&af, rgb, width, height, err); break;
    case IMAGE_EXR: st = write_exr(&af, rgb, NULL, 0, width, height, (encoding & IMAGE_EXR_FLOAT) != 0, err); break;
    }
    free(srgb);
    if (st != ST_OK) {
        atomic_abort(&af);
        return st;
    }
    return atomic_commit(&af, err);
}
