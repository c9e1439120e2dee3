/*
 * test_exr.c — the float outputs: EXR written by clpt (host/io/image_write.c through
 * OpenEXRCore) read back with the OpenEXR library's other reader, channel by channel:
 * the same floats (32-bit: bit for bit; half: within half precision, NaN and infinities
 * kept); the auxiliary channels of `clpt --aov` in one file; Radiance HDR read back with
 * stb_image within RGBE's precision. Run from the project root.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <ImfCRgbaFile.h>
#include <openexr.h>
#include <stb_image.h>

#include "cli_util.h"
#include "harness.h"
#include "io/exr.h"
#include "io/image_write.h"

enum { W = 37, H = 21 };   /* odd sizes: a partial last chunk, rows of odd length */

/* Reads channel `name` of the EXR at path as floats (w x h), through OpenEXRCore's
 * decoder, or returns NULL when the file or the channel is not there. */
static float *read_channel(const char *path, const char *name, int *w, int *h)
{
    exr_context_t ctxt = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    if (exr_start_read(&ctxt, path, &init) != EXR_ERR_SUCCESS) return NULL;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *ch = NULL;
    int lines = 0, found = -1;
    float *out = NULL;
    if (exr_get_data_window(ctxt, 0, &dw) || exr_get_channels(ctxt, 0, &ch) ||
        exr_get_scanlines_per_chunk(ctxt, 0, &lines))
        goto done;
    for (int i = 0; i < ch->num_channels; i++)
        if (strcmp(ch->entries[i].name.str, name) == 0) found = i;
    if (found < 0) goto done;
    *w = dw.max.x - dw.min.x + 1;
    *h = dw.max.y - dw.min.y + 1;
    out = malloc((size_t)*w * (size_t)*h * sizeof *out);
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    int started = 0, ok = 1;
    for (int y = dw.min.y; y <= dw.max.y && ok; y += lines) {
        exr_chunk_info_t ci;
        ok = exr_read_scanline_chunk_info(ctxt, 0, y, &ci) == EXR_ERR_SUCCESS &&
             (started ? exr_decoding_update(ctxt, 0, &ci, &dec) : exr_decoding_initialize(ctxt, 0, &ci, &dec)) ==
                 EXR_ERR_SUCCESS;
        if (!ok) break;
        started = 1;
        for (int c = 0; c < dec.channel_count; c++) dec.channels[c].decode_to_ptr = NULL;
        exr_coding_channel_info_t *cc = &dec.channels[found];
        cc->decode_to_ptr = (uint8_t *)(out + (size_t)(ci.start_y - dw.min.y) * (size_t)*w);
        cc->user_pixel_stride = sizeof(float);
        cc->user_line_stride = *w * (int32_t)sizeof(float);
        cc->user_data_type = EXR_PIXEL_FLOAT;
        cc->user_bytes_per_element = sizeof(float);
        ok = exr_decoding_choose_default_routines(ctxt, 0, &dec) == EXR_ERR_SUCCESS &&
             exr_decoding_run(ctxt, 0, &dec) == EXR_ERR_SUCCESS;
    }
    if (started) exr_decoding_destroy(ctxt, &dec);
    if (!ok) {
        free(out);
        out = NULL;
    }
done:
    exr_finish(&ctxt);
    return out;
}

/* The pixel type of channel `name` (EXR_PIXEL_HALF ...), or -1. */
static int channel_type(const char *path, const char *name)
{
    exr_context_t ctxt = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    if (exr_start_read(&ctxt, path, &init) != EXR_ERR_SUCCESS) return -1;
    const exr_attr_chlist_t *ch = NULL;
    int type = -1;
    if (exr_get_channels(ctxt, 0, &ch) == EXR_ERR_SUCCESS)
        for (int i = 0; i < ch->num_channels; i++)
            if (strcmp(ch->entries[i].name.str, name) == 0) type = (int)ch->entries[i].pixel_type;
    exr_finish(&ctxt);
    return type;
}

/* Values over the range an image holds: ordinary radiance, tiny and huge values,
 * negatives, zero; NaN and infinities at a few pixels. */
static float *test_values(int special)
{
    float *rgb = malloc(W * H * 3 * sizeof *rgb);
    for (int i = 0; i < W * H * 3; i++) rgb[i] = (float)((i * 7919) % 1000) / 37.0f - 3.0f;
    rgb[5] = 1e-5f;
    rgb[6] = 60000.0f;
    rgb[7] = 0.0f;
    if (special) {
        rgb[9] = NAN;
        rgb[10] = INFINITY;
        rgb[11] = -INFINITY;
    }
    return rgb;
}

static float half_round(float f)
{
    ImfHalf h;
    ImfFloatToHalf(f, &h);
    return ImfHalfToFloat(h);
}

static void check_exr(int float32)
{
    char path[] = "/tmp/clpt-test-exr-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    CHECK(fd >= 0);
    close(fd);
    float *rgb = test_values(1);
    float albedo[W * H * 3];
    for (int i = 0; i < W * H * 3; i++) albedo[i] = (float)i / (W * H * 3);
    ImageLayer layer = { { "albedo.R", "albedo.G", NULL }, albedo };
    Error err = { 0 };
    CHECK_MSG(image_write_exr(path, rgb, &layer, 1, W, H, float32, &err) == ST_OK, "%s", err.msg);
    const char *names[5] = { "R", "G", "B", "albedo.R", "albedo.G" };
    uint exact = 0, close_enough = 0;
    for (int c = 0; c < 5; c++) {
        int w = 0, h = 0;
        float *got = read_channel(path, names[c], &w, &h);
        CHECK_MSG(got != NULL, "channel %s missing", names[c]);
        if (!got) continue;
        CHECK_EQ_INT(w, W);
        CHECK_EQ_INT(h, H);
        CHECK_EQ_INT(channel_type(path, names[c]), float32 ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF);
        const float *src = c < 3 ? rgb + c : albedo + (c - 3);
        for (int i = 0; i < W * H; i++) {
            float want = float32 ? src[3 * i] : half_round(src[3 * i]);
            int same = memcmp(&want, &got[i], sizeof want) == 0 || (isnan(want) && isnan(got[i]));
            exact += same;
            close_enough += same || fabsf(got[i] - src[3 * i]) <= fabsf(src[3 * i]) * (1.0f / 1024.0f);
        }
        free(got);
    }
    CHECK(read_channel(path, "albedo.B", &(int){ 0 }, &(int){ 0 }) == NULL);
    fprintf(stderr, "  %s EXR: %u of %u values read back as written (%s), %u within half precision\n",
            float32 ? "32-bit float" : "half", exact, 5u * W * H, float32 ? "bit for bit" : "as rounded to half",
            close_enough);
    CHECK_EQ_INT(exact, 5 * W * H);
    unlink(path);
    free(rgb);
    error_clear(&err);
}

static void test_exr_half(void) { check_exr(0); }
static void test_exr_float(void) { check_exr(1); }

/* -o x.exr through image_write_encoded: R, G, B only, half unless IMAGE_EXR_FLOAT. */
static void test_exr_encoded(void)
{
    char path[] = "/tmp/clpt-test-exr-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    close(fd);
    float *rgb = test_values(0);
    Error err = { 0 };
    CHECK(image_write_encoded(path, rgb, W, H, (ImageEncoding)(IMAGE_SRGB | IMAGE_EXR_FLOAT), &err) == ST_OK);
    int w, h;
    float *g = read_channel(path, "G", &w, &h);
    CHECK(g != NULL);
    for (int i = 0; g && i < W * H; i++) CHECK(g[i] == rgb[3 * i + 1]);
    free(g);
    CHECK_EQ_INT(channel_type(path, "A"), -1);
    CHECK(image_write_encoded(path, rgb, W, H, IMAGE_SRGB, &err) == ST_OK);
    CHECK_EQ_INT(channel_type(path, "R"), EXR_PIXEL_HALF);
    unlink(path);
    free(rgb);
}

/* A half holds at most 65504: the default half EXR wrote +inf for every brighter pixel,
 * and the reader, which read halves, refused a float file with such a pixel (a 70000
 * sun), clpt's own --exr-float output included (issue 39). Now a half image with a
 * value past 65504 is written as floats, depth (Z) always is, and float channels are
 * read as floats, bit for bit. */
static void test_exr_beyond_half(void)
{
    char path[] = "/tmp/clpt-test-exr-bright-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    close(fd);
    float *rgb = test_values(0);
    rgb[4] = 70000.0f;
    rgb[8] = 1e30f;
    float depth[W * H * 3];
    for (int i = 0; i < W * H * 3; i++) depth[i] = 0.001f * (float)i + 0.1f;
    ImageLayer layer = { { "Z", NULL, NULL }, depth };
    Error err = { 0 };
    CHECK_MSG(image_write_exr(path, rgb, &layer, 1, W, H, 0, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(channel_type(path, "R"), EXR_PIXEL_FLOAT);
    CHECK_EQ_INT(channel_type(path, "Z"), EXR_PIXEL_FLOAT);
    int w, h;
    float *back = NULL;
    CHECK_MSG(exr_read_rgb(path, (uint64_t)W * H, &back, &w, &h, &err) == ST_OK, "%s", err.msg);
    if (back) CHECK(memcmp(back, rgb, sizeof(float) * W * H * 3) == 0);
    free(back);
    float *z = read_channel(path, "Z", &w, &h);
    CHECK(z != NULL);
    for (int i = 0; z && i < W * H; i++) CHECK(z[i] == depth[3 * i]);
    free(z);
    /* within half's range the colour stays half (and Z float) */
    rgb[4] = 65504.0f;
    rgb[8] = -65504.0f;
    CHECK(image_write_exr(path, rgb, &layer, 1, W, H, 0, &err) == ST_OK);
    CHECK_EQ_INT(channel_type(path, "G"), EXR_PIXEL_HALF);
    CHECK_EQ_INT(channel_type(path, "Z"), EXR_PIXEL_FLOAT);
    unlink(path);
    free(rgb);
    error_clear(&err);
}

/* An EXR whose data window does not start at the origin: the reader addresses the
 * library's frame buffer by absolute pixel coordinates, whose base lies outside the
 * pixels and, for a window far from the origin, outside the address space (a fuzz
 * finding: tests/data/fuzz/texture/exr-data-window-far-from-origin). The pixels must
 * come back in order either way. */
static void check_exr_window(int x0, int y0, int ww, int wh)
{
    char path[] = "/tmp/clpt-test-exr-window-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    close(fd);
    size_t n = (size_t)ww * (size_t)wh;
    ImfRgba *px = malloc(n * sizeof *px);
    CHECK(px != NULL);
    if (!px) return;
    for (size_t i = 0; i < n; i++) {
        float k = (float)(i % 1024u);   /* every value below is exact in half */
        ImfFloatToHalf(0.5f * k, &px[i].r);
        ImfFloatToHalf(1.0f + k, &px[i].g);
        ImfFloatToHalf(-0.25f * k, &px[i].b);
        ImfFloatToHalf(1.0f, &px[i].a);
    }
    ImfHeader *hdr = ImfNewHeader();
    ImfHeaderSetDataWindow(hdr, x0, y0, x0 + ww - 1, y0 + wh - 1);
    ImfOutputFile *out = ImfOpenOutputFile(path, hdr, IMF_WRITE_RGB);
    CHECK_MSG(out != NULL, "%s", ImfErrorMessage());
    /* the library's base, pixel (0, 0), computed modulo 2^64 as the reader does */
    uintptr_t off = ((uintptr_t)(intptr_t)x0 + (uintptr_t)(intptr_t)y0 * (uintptr_t)ww) * sizeof *px;
    CHECK(out && ImfOutputSetFrameBuffer(out, (const ImfRgba *)((uintptr_t)px - off), 1, (size_t)ww) &&
          ImfOutputWritePixels(out, wh));
    if (out) ImfCloseOutputFile(out);
    ImfDeleteHeader(hdr);
    float *rgb = NULL;
    int w = 0, h = 0;
    Error err = { 0 };
    CHECK_MSG(exr_read_rgb(path, 1u << 20, &rgb, &w, &h, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(w, ww);
    CHECK_EQ_INT(h, wh);
    uint bad = 0;
    for (size_t i = 0; rgb && i < n; i++) {
        float k = (float)(i % 1024u);
        bad += rgb[3 * i] != 0.5f * k || rgb[3 * i + 1] != 1.0f + k || rgb[3 * i + 2] != -0.25f * k;
    }
    CHECK_EQ_INT(bad, 0);
    free(rgb);
    free(px);
    unlink(path);
}

static void test_exr_data_window(void)
{
    check_exr_window(-3, 7, 5, 3);
    /* OpenEXR takes coordinates up to INT_MAX / 2 and rows up to 65,536 pixels: 10^9
     * such rows put pixel (0, 0) 5 * 10^14 bytes before the pixels, below address 0 */
    check_exr_window(1000000000, 1000000000, 65536, 2);
}

/* ------------------------------------------------------------ float layouts */

/* The value of component k of pixel (x, y) of level `level` of a test image: every bit
 * of the mantissa used, negatives, and a 70000-valued "sun" at pixel (1, 0), beyond a
 * half's 65504 (issue 39: such a float image was read as halves and refused). */
static float layout_value(int x, int y, int k, int level)
{
    if (x == 1 && y == 0 && k == 1) return 70000.0f;
    return (float)((x * 131 + y * 71 + k * 37) % 997) / 7.0f - 20.0f + 1000.0f * (float)level;
}

/* Level `level` of a test image (w x h) as interleaved RGB floats. */
static float *layout_pixels(int w, int h, int level)
{
    float *px = malloc((size_t)w * (size_t)h * 3 * sizeof *px);
    for (int y = 0; px && y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = 0; k < 3; k++) px[3 * ((size_t)y * w + x) + k] = layout_value(x, y, k, level);
    return px;
}

/* Points the encoder's channels (B, G, R, sorted by name) at the block of `px` (a
 * level `lw` pixels wide) whose corner is (x, y). */
static void layout_sources(exr_encode_pipeline_t *enc, const float *px, int lw, int x, int y)
{
    for (int c = 0; c < enc->channel_count; c++) {
        exr_coding_channel_info_t *cc = &enc->channels[c];
        int k = cc->channel_name[0] == 'R' ? 0 : cc->channel_name[0] == 'G' ? 1 : 2;
        cc->encode_from_ptr = (const uint8_t *)(px + 3 * ((size_t)y * lw + x) + k);
        cc->user_pixel_stride = 3 * sizeof(float);
        cc->user_line_stride = lw * 3 * (int32_t)sizeof(float);
        cc->user_data_type = EXR_PIXEL_FLOAT;
        cc->user_bytes_per_element = sizeof(float);
    }
}

/* Writes a tiled float RGB image (w x h, data window from (x0, y0), tw x th tiles)
 * through OpenEXRCore, every level of `mode` (one or mipmaps: OpenEXRCore 3.1 numbers
 * a ripmap's chunks wrongly): level l holds layout_value(..., l). OpenEXRCore 3.1
 * garbles a tile that its compressor does not shrink (both OpenEXR readers then read
 * noise), so small tiles are written uncompressed. Returns 1 when written. */
static int write_tiled(const char *path, int x0, int y0, int w, int h, int tw, int th, exr_tile_level_mode_t mode,
                       exr_compression_t comp)
{
    exr_context_t ctxt = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    int part = 0;
    exr_attr_box2i_t dw;
    dw.min.x = x0;
    dw.min.y = y0;
    dw.max.x = x0 + w - 1;
    dw.max.y = y0 + h - 1;
    exr_result_t rv = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (!rv) rv = exr_add_part(ctxt, "image", EXR_STORAGE_TILED, &part);
    if (!rv) rv = exr_initialize_required_attr_simple(ctxt, part, w, h, comp);
    if (!rv) rv = exr_set_data_window(ctxt, part, &dw);
    if (!rv) rv = exr_set_display_window(ctxt, part, &dw);
    for (int k = 0; k < 3 && !rv; k++)
        rv = exr_add_channel(ctxt, part, (const char *[]){ "R", "G", "B" }[k], EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (!rv) rv = exr_set_tile_descriptor(ctxt, part, (uint32_t)tw, (uint32_t)th, mode, EXR_TILE_ROUND_DOWN);
    if (!rv) rv = exr_write_header(ctxt);
    int nx = 0, ny = 0, started = 0;
    if (!rv) rv = exr_get_tile_levels(ctxt, part, &nx, &ny);
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    for (int ly = 0; ly < ny && !rv; ly++)
        for (int lx = 0; lx < nx && !rv; lx++) {
            if (mode == EXR_TILE_MIPMAP_LEVELS && lx != ly) continue;
            int lw = 0, lh = 0;
            rv = exr_get_level_sizes(ctxt, part, lx, ly, &lw, &lh);
            float *px = rv ? NULL : layout_pixels(lw, lh, lx + ly);
            for (int ty = 0; px && !rv && ty * th < lh; ty++)
                for (int tx = 0; !rv && tx * tw < lw; tx++) {
                    exr_chunk_info_t ci;
                    rv = exr_write_tile_chunk_info(ctxt, part, tx, ty, lx, ly, &ci);
                    if (!rv) rv = started ? exr_encoding_update(ctxt, part, &ci, &enc)
                                          : exr_encoding_initialize(ctxt, part, &ci, &enc);
                    if (rv) break;
                    started = 1;
                    layout_sources(&enc, px, lw, tx * tw, ty * th);
                    rv = exr_encoding_choose_default_routines(ctxt, part, &enc);
                    if (!rv) rv = exr_encoding_run(ctxt, part, &enc);
                }
            free(px);
        }
    if (started) exr_encoding_destroy(ctxt, &enc);
    exr_result_t fin = exr_finish(&ctxt);
    CHECK_MSG(!rv && !fin, "writing %s: %s", path, exr_get_error_code_as_string(rv ? rv : fin));
    return !rv && !fin;
}

/* Reads `path` with clpt's reader and compares with level 0 of the test image, bit for
 * bit; returns the pixels that differ. */
static uint read_layout(const char *path, int w, int h)
{
    float *rgb = NULL, *want = layout_pixels(w, h, 0);
    int gw = 0, gh = 0;
    Error err = { 0 };
    Status st = exr_read_rgb(path, 1u << 20, &rgb, &gw, &gh, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    uint bad = st ? (uint)(w * h) : 0;
    if (!st) {
        CHECK_EQ_INT(gw, w);
        CHECK_EQ_INT(gh, h);
        for (int i = 0; gw == w && gh == h && i < w * h; i++) bad += memcmp(rgb + 3 * i, want + 3 * i, 12) != 0;
    }
    free(rgb);
    free(want);
    error_clear(&err);
    return bad;
}

/* Tiled float images (read as halves before: the 70000 sun was infinite, the image
 * refused): through OpenEXRCore, every value bit for bit, with the last column and row
 * of tiles cut by the image, tiles larger than the image, a data window off the
 * origin; and the OpenEXR library's own ZIP-compressed tiles (generate_exr_float.cpp). */
static void test_exr_tiled_float(void)
{
    char path[] = "/tmp/clpt-test-exr-tiled-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    close(fd);
    static const int cases[][7] = { { 0, 0, 37, 21, 16, 8, EXR_COMPRESSION_ZIP },
                                    { -3, 7, 37, 21, 5, 3, EXR_COMPRESSION_NONE },
                                    { 0, 0, 7, 5, 64, 64, EXR_COMPRESSION_RLE },
                                    { 2, -9, 1, 1, 1, 1, EXR_COMPRESSION_NONE } };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const int *c = cases[i];
        if (!write_tiled(path, c[0], c[1], c[2], c[3], c[4], c[5], EXR_TILE_ONE_LEVEL, (exr_compression_t)c[6]))
            continue;
        uint bad = read_layout(path, c[2], c[3]);
        CHECK_MSG(bad == 0, "%dx%d from (%d, %d) in %dx%d tiles: %u pixels differ", c[2], c[3], c[0], c[1], c[4], c[5],
                  bad);
    }
    unlink(path);
    CHECK_EQ_INT(read_layout("tests/data/images/float-tiled-zip.exr", 19, 11), 0);
}

/* Mipmapped and ripmapped images: level (0, 0), the full resolution, is the image (the
 * smaller levels hold other values, 1000 x level more, and must not leak in). The
 * ripmap comes from the OpenEXR library (generate_exr_float.cpp). */
static void test_exr_tiled_levels(void)
{
    char path[] = "/tmp/clpt-test-exr-levels-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    close(fd);
    if (write_tiled(path, 0, 0, 37, 21, 8, 8, EXR_TILE_MIPMAP_LEVELS, EXR_COMPRESSION_ZIP))
        CHECK_EQ_INT(read_layout(path, 37, 21), 0);
    unlink(path);
    CHECK_EQ_INT(read_layout("tests/data/images/float-ripmap.exr", 19, 11), 0);
}

/* The uncompressed bytes of a scanline chunk of the test image: per row, the channels
 * in name order (B, G, R), each w little-endian floats (the hosts clpt runs on are
 * little-endian, as EXR is). */
static unsigned char *scanline_bytes(const float *px, int w, int y0, int rows, size_t *size)
{
    *size = (size_t)rows * 3 * (size_t)w * sizeof(float);
    unsigned char *b = malloc(*size), *o = b;
    for (int y = y0; b && y < y0 + rows; y++)
        for (int c = 2; c >= 0; c--)
            for (int x = 0; x < w; x++, o += sizeof(float)) memcpy(o, px + 3 * ((size_t)y * w + x) + c, sizeof(float));
    return b;
}

/* DWAB with float channels. OpenEXR 3.1's DWA coder classifies the channels by name
 * (ImfDwaCompressor.cpp's default rules): R, G, B, Y, BY and RY, half or float, go
 * through its lossy DCT, which codes halves (a float 70000 comes back below 65504); other
 * channels are stored losslessly, and so is any chunk that DWA would not make smaller:
 * the library then stores it as it is, which a reader knows from its size. Such a
 * chunk, written here with OpenEXRCore (which cannot compress DWA), holds every float
 * bit, the sun included; the reader decodes it through the C++ library (OpenEXRCore 3.1
 * cannot decompress DWA at all) and keeps every bit: it was read as halves before, and
 * refused. */
static void test_exr_dwab_float_stored(void)
{
    char path[] = "/tmp/clpt-test-exr-dwab-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    close(fd);
    const int w = 37, h = 21;
    float *px = layout_pixels(w, h, 0);
    size_t size = 0;
    unsigned char *raw = scanline_bytes(px, w, 0, h, &size);
    exr_context_t ctxt = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    int part = 0;
    exr_result_t rv = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (!rv) rv = exr_add_part(ctxt, "image", EXR_STORAGE_SCANLINE, &part);
    if (!rv) rv = exr_initialize_required_attr_simple(ctxt, part, w, h, EXR_COMPRESSION_DWAB);
    for (int k = 0; k < 3 && !rv; k++)
        rv = exr_add_channel(ctxt, part, (const char *[]){ "R", "G", "B" }[k], EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (!rv) rv = exr_write_header(ctxt);
    if (!rv) rv = exr_write_scanline_chunk(ctxt, part, 0, raw, size);   /* one chunk: DWAB's is 256 rows */
    exr_result_t fin = exr_finish(&ctxt);
    CHECK_MSG(!rv && !fin, "writing %s: %s", path, exr_get_error_code_as_string(rv ? rv : fin));
    CHECK_EQ_INT(read_layout(path, w, h), 0);
    free(raw);
    free(px);
    unlink(path);
}

/* Reads `path` with clpt's reader and with the OpenEXR library's half interface
 * (RgbaInputFile), and counts the pixels of the float reading that are the test image's
 * exact values (*exact) and those that equal the half reading (*as_half). */
static void read_dwa(const char *path, int w, int h, uint *exact, uint *as_half, float *sun)
{
    *exact = *as_half = 0;
    float *rgb = NULL, *want = layout_pixels(w, h, 0);
    int gw = 0, gh = 0;
    Error err = { 0 };
    CHECK_MSG(exr_read_rgb(path, 1u << 20, &rgb, &gw, &gh, &err) == ST_OK, "%s", err.msg);
    CHECK(gw == w && gh == h);
    ImfInputFile *in = ImfOpenInputFile(path);
    CHECK_MSG(in != NULL, "%s", ImfErrorMessage());
    ImfRgba *px = rgb && in && gw == w && gh == h ? malloc((size_t)w * (size_t)h * sizeof *px) : NULL;
    if (px && ImfInputSetFrameBuffer(in, px, 1, (size_t)w) && ImfInputReadPixels(in, 0, h - 1)) {
        for (int i = 0; i < w * h; i++) {
            *exact += memcmp(rgb + 3 * i, want + 3 * i, 12) == 0;
            *as_half += rgb[3 * i] == ImfHalfToFloat(px[i].r) && rgb[3 * i + 1] == ImfHalfToFloat(px[i].g) &&
                        rgb[3 * i + 2] == ImfHalfToFloat(px[i].b);
        }
        *sun = rgb[4];
    } else
        CHECK_MSG(0, "the library could not read %s: %s", path, ImfErrorMessage());
    free(px);
    if (in) ImfCloseInputFile(in);
    free(rgb);
    free(want);
    error_clear(&err);
}

/* Float images the OpenEXR library compressed with DWAB and DWAA (tiled, mipmapped:
 * level 0), generate_exr_float.cpp. What holds: every pixel is either the exact float
 * (a chunk DWA did not shrink, stored as it is) or what the library's half reading
 * gives (its DCT codes R, G and B as halves, float channels or not); the 70000 sun
 * comes back below 65504 from a DCT-coded chunk (DWA clamps; 64704 here, its
 * neighbours' doing), not +inf, so the image is read, not refused. */
static void test_exr_dwa_float_library(void)
{
    uint exact = 0, as_half = 0;
    float sun = 0.0f;
    read_dwa("tests/data/images/float-dwab.exr", 40, 24, &exact, &as_half, &sun);
    fprintf(stderr, "  float DWAB 40x24: %u of %u pixels as the library's half reading, %u exact; the sun reads %g\n",
            as_half, 40u * 24u, exact, (double)sun);
    CHECK_EQ_INT(as_half, 40 * 24);
    CHECK(sun > 60000.0f && sun <= 65504.0f);
    read_dwa("tests/data/images/float-tiled-dwaa.exr", 37, 21, &exact, &as_half, &sun);
    fprintf(stderr, "  float DWAA 37x21 in 16x16 tiles, mipmapped: %u of %u pixels exact (tiles stored as they "
            "are), %u as the half reading; the sun reads %g\n", exact, 37u * 21u, as_half, (double)sun);
    CHECK(exact > 0 && as_half > 0);
    CHECK_EQ_INT(exact + as_half, 37 * 21);
    CHECK(sun > 60000.0f && sun <= 65504.0f);
}

/* Radiance HDR: read back by stb_image within RGBE's precision (8 bits of mantissa
 * shared: 1/128 of the largest component); negative and NaN values come back 0. */
static void test_hdr(void)
{
    char path[] = "/tmp/clpt-test-hdr-XXXXXX.hdr";
    int fd = mkstemps(path, 4);
    close(fd);
    float *rgb = test_values(0);
    rgb[12] = NAN;
    Error err = { 0 };
    CHECK_MSG(image_write(path, rgb, W, H, &err) == ST_OK, "%s", err.msg);
    int w = 0, h = 0, c = 0;
    float *got = stbi_loadf(path, &w, &h, &c, 3);
    CHECK(got != NULL);
    CHECK_EQ_INT(w, W);
    CHECK_EQ_INT(h, H);
    uint bad = 0;
    for (int i = 0; got && i < W * H; i++) {
        float m = 0.0f;
        for (int k = 0; k < 3; k++) m = fmaxf(m, rgb[3 * i + k] > 0.0f ? rgb[3 * i + k] : 0.0f);
        for (int k = 0; k < 3; k++) {
            float want = rgb[3 * i + k] > 0.0f ? rgb[3 * i + k] : 0.0f;
            if (fabsf(got[3 * i + k] - want) > m / 128.0f + 1e-30f) bad++;
        }
    }
    CHECK_EQ_INT(bad, 0);
    stbi_image_free(got);
    unlink(path);
    free(rgb);
}

/* clpt -o x.exr --aov normal,depth,albedo: one file with R G B, normal.X/Y/Z (unit
 * where the sphere covers a pixel, 0 where nothing does), Z (the distance, +inf where
 * nothing is hit) and
 * albedo.R/G/B; no separate auxiliary files. */
static void test_cli_aov_channels(void)
{
    char dir[] = "/tmp/clpt-test-exr-cli-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char scene[256], out[256], cmd[1024];
    snprintf(scene, sizeof scene, "%s/s.scene", dir);
    snprintf(out, sizeof out, "%s/out.exr", dir);
    FILE *f = fopen(scene, "w");
    fputs("image { width 16 height 12 spp 4 }\n"
          "camera { from 0 0 5 at 0 0 0 fov 30 }\n"
          "background { color 0.5 0.6 0.7 }\n"
          "sphere { center 0 0 0 radius 1 material { type diffuse albedo 0.25 0.5 0.75 } }\n", f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "%s %s -q --device scalar -o %s --aov normal,depth,albedo --exr-float", CLI_PROGRAM, scene,
             out);
    CHECK_EQ_INT(system(cmd), 0);
    int w = 0, h = 0;
    float *nx = read_channel(out, "normal.X", &w, &h), *ny = read_channel(out, "normal.Y", &w, &h),
          *nz = read_channel(out, "normal.Z", &w, &h), *z = read_channel(out, "Z", &w, &h),
          *ar = read_channel(out, "albedo.R", &w, &h), *ab = read_channel(out, "albedo.B", &w, &h),
          *r = read_channel(out, "R", &w, &h);
    CHECK(nx && ny && nz && z && ar && ab && r);
    if (nx && ny && nz && z && ar && ab && r) {
        int c = (h / 2) * w + w / 2;   /* the centre: the sphere's front, facing the camera */
        fprintf(stderr, "  centre pixel: normal %.3f %.3f %.3f, Z %.4f, albedo %.3f .. %.3f; corner normal %g, Z %g\n",
                (double)nx[c], (double)ny[c], (double)nz[c], (double)z[c], (double)ar[c], (double)ab[c],
                (double)nx[0], (double)z[0]);
        CHECK(nz[c] > 0.95f && fabsf(nx[c]) < 0.2f && fabsf(ny[c]) < 0.2f);
        CHECK_NEAR(z[c], 4.0, 0.02);
        CHECK_NEAR(ar[c], 0.25, 1e-6);
        CHECK_NEAR(ab[c], 0.75, 1e-6);
        CHECK(nx[0] == 0.0f && ny[0] == 0.0f && nz[0] == 0.0f);
        CHECK(isinf(z[0]) && z[0] > 0.0f);   /* the background: infinitely far */
        CHECK(r[0] > 0.49f && r[0] < 0.51f);
    }
    free(nx); free(ny); free(nz); free(z); free(ar); free(ab); free(r);
    char other[300];
    snprintf(other, sizeof other, "%s/out-normal.exr", dir);
    CHECK(access(other, F_OK) != 0);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK_EQ_INT(system(cmd), 0);
}

/* --aov depth into a PFM: the distance where the sphere is hit, +inf where nothing is
 * (it was 0, which reads as "at the camera"). */
static void test_cli_depth_pfm_background_is_infinite(void)
{
    char dir[] = "/tmp/clpt-test-depth-pfm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char scene[256], out[256], depth[256], cmd[1024];
    snprintf(scene, sizeof scene, "%s/s.scene", dir);
    snprintf(out, sizeof out, "%s/out.pfm", dir);
    snprintf(depth, sizeof depth, "%s/out-depth.pfm", dir);
    FILE *f = fopen(scene, "w");
    fputs("image { width 16 height 12 spp 4 }\n"
          "camera { from 0 0 5 at 0 0 0 fov 30 }\n"
          "sphere { center 0 0 0 radius 1 material { type diffuse albedo 0.5 0.5 0.5 } }\n", f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "%s %s -q --device scalar -o %s --aov depth", CLI_PROGRAM, scene, out);
    CHECK_EQ_INT(system(cmd), 0);
    f = fopen(depth, "rb");
    int w = 0, h = 0;
    float scale = 0.0f, px[16 * 12 * 3];
    CHECK(f && fscanf(f, "PF %d %d %f", &w, &h, &scale) == 3 && fgetc(f) == '\n');
    CHECK(w == 16 && h == 12 && scale < 0.0f);
    CHECK(f && fread(px, sizeof px[0], 16 * 12 * 3, f) == 16 * 12 * 3);
    if (f) fclose(f);
    if (w == 16 && h == 12) {
        int c = (h / 2) * w + w / 2;
        CHECK_NEAR(px[3 * c], 4.0, 0.05);
        CHECK(isinf(px[0]) && px[0] > 0.0f);
    }
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK_EQ_INT(system(cmd), 0);
}

/* --aov normal into a PFM: the signed normal, misses 0, exactly the EXR output's
 * normal.X/Y/Z channels (it was (n + 1) / 2, the 8-bit image's colours). */
static void test_cli_normal_pfm_is_signed(void)
{
    char dir[] = "/tmp/clpt-test-normal-pfm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char scene[64], pfm_out[64], exr_out[64], normal[64], cmd[1024];
    snprintf(scene, sizeof scene, "%s/s.scene", dir);
    snprintf(pfm_out, sizeof pfm_out, "%s/out.pfm", dir);
    snprintf(exr_out, sizeof exr_out, "%s/out.exr", dir);
    snprintf(normal, sizeof normal, "%s/out-normal.pfm", dir);
    FILE *f = fopen(scene, "w");
    fputs("image { width 16 height 12 spp 4 }\n"
          "camera { from 0 0 5 at 0 0 0 fov 30 }\n"
          "sphere { center 0 0 0 radius 1 material { type diffuse albedo 0.5 0.5 0.5 } }\n", f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "%s %s -q --device scalar -o %s --aov normal && %s %s -q --device scalar -o %s --aov "
             "normal --exr-float", CLI_PROGRAM, scene, pfm_out, CLI_PROGRAM, scene, exr_out);
    CHECK_EQ_INT(system(cmd), 0);
    f = fopen(normal, "rb");
    int w = 0, h = 0;
    float scale = 0.0f, px[16 * 12 * 3];
    CHECK(f && fscanf(f, "PF %d %d %f", &w, &h, &scale) == 3 && fgetc(f) == '\n');
    CHECK(f && fread(px, sizeof px[0], 16 * 12 * 3, f) == 16 * 12 * 3);
    if (f) fclose(f);
    int ew = 0, eh = 0;
    float *ch[3] = { read_channel(exr_out, "normal.X", &ew, &eh), read_channel(exr_out, "normal.Y", &ew, &eh),
                     read_channel(exr_out, "normal.Z", &ew, &eh) };
    CHECK(w == 16 && h == 12 && ew == 16 && eh == 12 && ch[0] && ch[1] && ch[2]);
    if (w == 16 && h == 12 && ew == 16 && eh == 12 && ch[0] && ch[1] && ch[2]) {
        int same = 1, negative = 0;
        for (int y = 0; y < h; y++)   /* PFM rows run bottom to top */
            for (int x = 0; x < w; x++)
                for (int k = 0; k < 3; k++) {
                    float v = px[3 * ((h - 1 - y) * w + x) + k];
                    same &= v == ch[k][y * w + x];
                    negative |= v < -0.5f;
                }
        CHECK_MSG(same, "the PFM's normals differ from the EXR's normal channels");
        CHECK(negative);   /* signed: the sphere's left half points to -x */
        CHECK(px[0] == 0.0f && px[1] == 0.0f && px[2] == 0.0f);   /* a miss */
    }
    for (int k = 0; k < 3; k++) free(ch[k]);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK_EQ_INT(system(cmd), 0);
}

int main(void)
{
    RUN(test_exr_half);
    RUN(test_exr_float);
    RUN(test_exr_encoded);
    RUN(test_exr_beyond_half);
    RUN(test_exr_data_window);
    RUN(test_exr_tiled_float);
    RUN(test_exr_tiled_levels);
    RUN(test_exr_dwab_float_stored);
    RUN(test_exr_dwa_float_library);
    RUN(test_hdr);
    RUN(test_cli_aov_channels);
    RUN(test_cli_depth_pfm_background_is_infinite);
    RUN(test_cli_normal_pfm_is_signed);
    return harness_report();
}
