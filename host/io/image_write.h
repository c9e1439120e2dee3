/*
 * image_write.h — writing the final image: PNG (8-bit, or 16-bit through libpng), JPEG
 * (stb_image_write, a quality from 1 to 100), PPM and BMP (sRGB, or linear when asked), or
 * linear float: PFM, OpenEXR (half or 32-bit float channels, ZIP
 * compressed; with the auxiliary images as extra channels: image_write_exr) and
 * Radiance HDR (RGBE, through stb_image_write).
 *
 * The format follows the output path's extension. Every write is atomic: the data goes to
 * a temporary file in the target's folder, which is synced and then renamed over the
 * target, so a reader (or a crash, a full disk, a Ctrl-C) never sees a half-written image
 * and a failed write leaves any earlier file at that path untouched.
 *
 * PNG, JPEG, PPM and BMP store sRGB-encoded values: NaN becomes 0, values are clamped to
 * [0,1], the exact sRGB transfer function is applied and the result scaled to 255 (or
 * 65535 for a 16-bit PNG) and rounded to nearest. With
 * IMAGE_LINEAR the transfer function is left out (value * 255, rounded), which is how
 * the classic ray tracers of computer-graphics courses write their images.
 * PFM stores the linear radiance unchanged, bit for bit — NaN, infinities and negative
 * values included — because it is the format for exact data: determinism tests compare
 * PFM files bitwise, and clamping there would hide the very values they look for.
 * EXR stores the radiance as R, G, B (as halves, NaN and infinities included, unless
 * IMAGE_EXR_FLOAT asks for floats: then bit for bit). HDR stores RGBE, which holds no
 * negative or non-finite value: NaN and negative values become 0, infinities the
 * largest float.
 */
#ifndef CLPT_IMAGE_WRITE_H
#define CLPT_IMAGE_WRITE_H

#include "base/status.h"
#include "io/view_transform.h"

#include <stddef.h>

typedef enum { IMAGE_PNG, IMAGE_PPM, IMAGE_PFM, IMAGE_BMP, IMAGE_EXR, IMAGE_HDR, IMAGE_JPEG } ImageFormat;

/* How display formats encode linear values: IMAGE_SRGB or IMAGE_LINEAR, either with
 * IMAGE_EXR_FLOAT or-ed in for 32-bit float EXR channels (else half) and IMAGE_PNG16
 * for 16 bits a channel in a PNG (else 8). */
typedef enum { IMAGE_SRGB = 0, IMAGE_LINEAR = 1, IMAGE_EXR_FLOAT = 2, IMAGE_PNG16 = 4 } ImageEncoding;

/* JPEG quality when none is asked for (ImageStyle.jpeg_quality 0). */
#define IMAGE_JPEG_QUALITY 90

/* Everything that decides how linear radiance becomes the bytes of a file: the
 * encoding, and the look (exposure and view) of the formats meant for a display (PNG,
 * PPM, BMP). Float formats ignore the look. */
typedef struct {
    ImageEncoding encoding;
    ViewLook look;
    unsigned jpeg_quality;     /* 1..100; 0: IMAGE_JPEG_QUALITY */
} ImageStyle;

/* One named group of channels of a float image (an auxiliary image): `names` for up
 * to three interleaved floats a pixel (NULL: that channel is left out). */
typedef struct {
    const char *names[3];
    const float *rgb;          /* width * height * 3 floats, top row first */
} ImageLayer;

/* The format named by path's extension (.png .jpg .jpeg .ppm .pfm .bmp .exr .hdr, any case). An unknown or
 * missing extension is ST_USAGE, with a message that lists the supported ones. The
 * path "-" is standard output as PNG, and "FORMAT:-" (exr:-, pfm:-, any of the six)
 * standard output in that format; an unknown FORMAT is ST_USAGE too. */
Status image_format_from_path(const char *path, ImageFormat *fmt, Error *err);
/* Whether path names standard output ("-" or "FORMAT:-") rather than a file. Such an
 * image is written straight to stdout, not atomically (see atomic_open_stream). */
int image_path_is_stdout(const char *path);
/* Standard output can take an image: not a terminal (binary bytes on a screen help
 * nobody), else ST_USAGE saying how to redirect it. */
Status image_stdout_check(Error *err);

/* Writes rgb (linear radiance, width*height*3 floats, top row first) to path, atomically,
 * in the format of its extension. ST_USAGE for an unknown extension, ST_IO when the file
 * cannot be written (the message names the path and the step that failed), ST_INTERNAL for
 * an empty or impossibly large image or when memory runs out. */
Status image_write(const char *path, const float *rgb, unsigned width, unsigned height,
                   Error *err);
/* The same with a choice of 8-bit encoding (PFM is always linear float). */
Status image_write_encoded(const char *path, const float *rgb, unsigned width, unsigned height,
                           ImageEncoding encoding, Error *err);

/* The same with a look: display formats get rgb through view_apply (view_transform.h)
 * first, unless the look changes nothing (then the bytes are image_write_encoded's). */
Status image_write_styled(const char *path, const float *rgb, unsigned width, unsigned height,
                          const ImageStyle *style, Error *err);
/* Whether the format is one a view transform applies to (8-bit display formats). */
int image_format_is_display(ImageFormat fmt);
/* ST_USAGE when `look` would change an image at `path` whose format keeps linear
 * radiance (PFM, EXR, HDR), where it would be silently ignored; else ST_OK (also for
 * a path of no known format: image_format_from_path reports that). */
Status image_check_look(const char *path, const ViewLook *look, Error *err);

/* Writes an OpenEXR file (path must end in .exr): rgb as R, G, B, then each layer's
 * named channels (as "normal.X", "Z", "albedo.R"), as halves or with float32 as
 * 32-bit floats; atomically. Errors as image_write. */
Status image_write_exr(const char *path, const float *rgb, const ImageLayer *layers, size_t n_layers, unsigned width,
                       unsigned height, int float32, Error *err);

/* The sRGB transfer function (IEC 61966-2-1) applied to a linear value: NaN and values
 * <= 0 give 0, values >= 1 give 1. */
float image_srgb_encode(float linear);
/* image_srgb_encode scaled to 0..255 and rounded to nearest: the byte PNG and PPM store. */
unsigned char image_to_srgb8(float linear);
/* The same scaled to 0..65535: a 16-bit PNG's value. */
unsigned image_to_srgb16(float linear);
/* A linear value clamped to [0,1] (NaN: 0), scaled to 0..65535 and rounded to nearest. */
unsigned image_to_linear16(float linear);
/* A linear value clamped to [0,1] (NaN: 0), scaled to 0..255 and rounded to nearest. */
unsigned char image_to_linear8(float linear);

#endif /* CLPT_IMAGE_WRITE_H */
