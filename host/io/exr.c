/* exr.c — OpenEXR images through OpenEXRCore (see exr.h). */
#include "io/exr.h"
#include "io/exr_imf.h"

#include "base/bytes.h"
#include "base/strmap.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <ImfCRgbaFile.h>
#include <openexr.h>

/* The longest side clpt lets OpenEXR accept (beyond its pixel limit, which is checked
 * separately). */
#define EXR_MAX_SIDE 65536

/* The most bytes one chunk of an image may decode to (all its channels): a 16384-wide
 * RGBA half image in DWAB's 256-row chunks needs 32 MiB. */
#define EXR_MAX_CHUNK_BYTES (256u << 20)

/* The file name OpenEXRCore is given when it writes to memory: it names the file in its
 * messages and, on a failed write, is what the library's own file handling would
 * remove; a path that cannot exist keeps that from touching any real file. */
#define EXR_NO_FILE "/nonexistent/clpt-exr-in-memory"

int exr_is_exr(const unsigned char *head, size_t n)
{
    return n >= 4 && head[0] == 0x76 && head[1] == 0x2f && head[2] == 0x31 && head[3] == 0x01;
}

/* OpenEXRCore reports a failure through the context's error handler, with a message
 * more precise than its error code; the last one is kept here for our own message
 * (the library would otherwise print it to stderr). One per thread: textures may be
 * read from several. */
static _Thread_local char exr_last_error[256];

static void exr_error_handler(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    snprintf(exr_last_error, sizeof exr_last_error, "%s", msg ? msg : exr_get_error_code_as_string(code));
}

static Status exr_fail(const char *path, exr_result_t rv, Error *err)
{
    const char *why = exr_last_error[0] ? exr_last_error : exr_get_error_code_as_string(rv);
    if (rv == EXR_ERR_FILE_ACCESS)
        return error_set(err, ST_IO, "cannot open '%s': %s", path, why);
    return error_set(err, ST_INPUT, "'%s': not an EXR file OpenEXR can read (%s)", path, why);
}

/* The channel that fills component `k` (0 R, 1 G, 2 B) of the RGB output, or -1: R,
 * G, B by name, or Y for all three when none of R, G and B is there. */
static int exr_pick_channel(const exr_attr_chlist_t *ch, int k)
{
    static const char *const names[3] = { "R", "G", "B" };
    int any_rgb = 0, y = -1;
    for (int i = 0; i < ch->num_channels; i++) {
        const char *n = ch->entries[i].name.str;
        if (strcmp(n, names[k]) == 0) return i;
        if (!strcmp(n, "R") || !strcmp(n, "G") || !strcmp(n, "B")) any_rgb = 1;
        if (!strcmp(n, "Y")) y = i;
    }
    return any_rgb ? -1 : y;
}

/* A buffer the decoders take for one piece of the image (a tile, a row of tiles, a
 * chunk of scanlines), refused above EXR_MAX_CHUNK_BYTES: `piece` says what the piece
 * is and ends in its verb ("... need"), `each` follows the byte count. */
static Status chunk_fits(const char *path, const char *piece, uint64_t bytes, const char *each, Error *err)
{
    if (bytes <= EXR_MAX_CHUNK_BYTES) return ST_OK;
    return error_set(err, ST_INPUT, "'%s': %s %llu bytes%s, more than clpt decodes (%u)", path, piece,
                     (unsigned long long)bytes, each, EXR_MAX_CHUNK_BYTES);
}

/* Checks the first part's header (read by OpenEXRCore, which bounds what a header may
 * ask for) before any pixel memory exists. */
static Status exr_check_part(exr_context_t ctxt, const char *path, uint64_t max_pixels, const int pick[3], int w,
                             int h, Error *err)
{
    exr_storage_t storage;
    exr_result_t rv = exr_get_storage(ctxt, 0, &storage);
    if (rv != EXR_ERR_SUCCESS) return exr_fail(path, rv, err);
    if (storage == EXR_STORAGE_DEEP_SCANLINE || storage == EXR_STORAGE_DEEP_TILED)
        return error_set(err, ST_INPUT, "'%s': a deep EXR image (samples at several depths per pixel); clpt "
                         "reads flat images only", path);
    if (pick[0] < 0 && pick[1] < 0 && pick[2] < 0)
        return error_set(err, ST_INPUT, "'%s': the EXR image has no colour channel (R, G, B or Y)", path);
    if (w <= 0 || h <= 0 || (uint64_t)w * (uint64_t)h > max_pixels)
        return error_set(err, ST_INPUT, "'%s': a %dx%d EXR image is larger than the images clpt reads (at most "
                         "%llu pixels)", path, w, h, (unsigned long long)max_pixels);
    /* the libraries' decompressors buffer one chunk of every channel: for a scanline
     * image, rows per chunk (up to 256 for DWAB) x width x the bytes of all channels,
     * which a wide image with many channels makes gigabytes (found by fuzz_texture); for
     * a tiled one, a whole tile as the header sizes it, which may be far larger than the
     * image (the C++ library allocates the full tile, even for a tile the image clips) */
    const exr_attr_chlist_t *ch = NULL;
    uint64_t pixel_bytes = 0;
    if (exr_get_channels(ctxt, 0, &ch) == EXR_ERR_SUCCESS)
        for (int i = 0; i < ch->num_channels; i++) pixel_bytes += ch->entries[i].pixel_type == EXR_PIXEL_HALF ? 2u : 4u;
    int channels = ch ? ch->num_channels : 0;
    if (storage == EXR_STORAGE_TILED) {
        uint32_t tw = 0, th = 0;
        exr_tile_level_mode_t levels;
        exr_tile_round_mode_t round;
        rv = exr_get_tile_descriptor(ctxt, 0, &tw, &th, &levels, &round);
        if (rv != EXR_ERR_SUCCESS) return exr_fail(path, rv, err);
        char piece[160];
        snprintf(piece, sizeof piece, "the EXR image's tiles of %ux%u pixels x %d channels need", tw, th, channels);
        Status st = chunk_fits(path, piece, (uint64_t)tw * (uint64_t)th * pixel_bytes, " each", err);
        /* the C++ library's InputFile reads a tiled image a row of tiles at a time,
         * into a buffer of the image's width x the tiles' height */
        snprintf(piece, sizeof piece, "a row of the EXR image's tiles (%d pixels wide, %u high, %d channels) needs", w,
                 th, channels);
        return st ? st : chunk_fits(path, piece, (uint64_t)w * (uint64_t)th * pixel_bytes, "", err);
    }
    int lines = 0;
    if (exr_get_scanlines_per_chunk(ctxt, 0, &lines) != EXR_ERR_SUCCESS || lines <= 0) lines = 1;
    char piece[160];
    snprintf(piece, sizeof piece, "the EXR image's chunks of %d rows of %d pixels x %d channels need", lines, w,
             channels);
    return chunk_fits(path, piece, (uint64_t)lines * (uint64_t)w * pixel_bytes, " each", err);
}

/* A NUL-terminated string of at most 255 characters from f into buf[256]; 0 when the
 * file ends first or the string is longer (then the libraries judge the file). */
static int exr_read_name(FILE *f, char buf[256])
{
    for (int i = 0; i < 256; i++) {
        int c = getc(f);
        if (c == EOF) return 0;
        buf[i] = (char)c;
        if (c == 0) return 1;
    }
    return 0;
}

/* The size of a value of the OpenEXR library's attribute type `type` when it is fixed
 * (the library reads that many bytes whatever the attribute declares), else 0. */
static uint64_t exr_fixed_size(const char *type)
{
    static const struct { const char *type; uint64_t size; } fixed[] = {
        { "box2i", 16 }, { "box2f", 16 }, { "chromaticities", 32 }, { "compression", 1 }, { "double", 8 },
        { "envmap", 1 }, { "float", 4 }, { "int", 4 }, { "keycode", 28 }, { "lineOrder", 1 }, { "m33f", 36 },
        { "m33d", 72 }, { "m44f", 64 }, { "m44d", 128 }, { "rational", 8 }, { "tiledesc", 9 }, { "timecode", 8 },
        { "v2i", 8 }, { "v2f", 8 }, { "v2d", 16 }, { "v3i", 12 }, { "v3f", 12 }, { "v3d", 24 },
        { "deepImageState", 1 },
    };
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
        if (strcmp(type, fixed[i].type) == 0) return fixed[i].size;
    return 0;
}

/* The parts of an attribute's value the OpenEXR library sizes from inside the value:
 * a channel list (entries up to an empty name, read whatever the declared size says),
 * a preview (width x height x 4 bytes), a string vector (a length before each string).
 * Each must end exactly at the declared size n, as everything else the library reads
 * by n; `f` is at the value and is left after it. Returns 0 when it does not. */
static int exr_value_fits(FILE *f, const char *type, uint64_t n)
{
    uint64_t fixed = exr_fixed_size(type);
    if (fixed) return n == fixed && fseek(f, (long)n, SEEK_CUR) == 0;
    if (strcmp(type, "chlist") == 0) {
        uint64_t used = 0;
        char name[256];
        unsigned char rest[16];
        for (;;) {
            if (!exr_read_name(f, name)) return 0;
            used += strlen(name) + 1;
            if (name[0] == '\0') return used == n;
            if (fread(rest, 1, 16, f) != 16) return 0;
            used += 16;
            if (used > n) return 0;
        }
    }
    if (strcmp(type, "preview") == 0) {
        unsigned char wh[8];
        if (n < 8 || fread(wh, 1, 8, f) != 8) return 0;
        uint64_t w = bytes_get_le32(wh), h = bytes_get_le32(wh + 4);
        if ((w && h > (n - 8) / 4 / w) || w * h * 4 != n - 8) return 0;
        return fseek(f, (long)(n - 8), SEEK_CUR) == 0;
    }
    if (strcmp(type, "stringvector") == 0) {
        for (uint64_t used = 0; used < n;) {
            unsigned char len[4];
            if (n - used < 4 || fread(len, 1, 4, f) != 4) return 0;
            uint64_t l = bytes_get_le32(len);
            used += 4;
            if (l > n - used || fseek(f, (long)l, SEEK_CUR) != 0) return 0;
            used += l;
        }
        return 1;
    }
    if (strcmp(type, "idmanifest") == 0) return 0;   /* compressed, sized from inside: not read */
    return fseek(f, (long)n, SEEK_CUR) == 0;
}

/* Every header attribute must fit in the file and be the size the OpenEXR library will
 * read of it (exr_value_fits). The library (RgbaInputFile) reserves an attribute's
 * declared size before reading a byte of it, so a corrupt size in a small file was a
 * 1.8 GB allocation (found by fuzz_texture), and it reads a known type's fixed size
 * whatever the declared one, after which it reads the rest of the header out of step.
 * OpenEXRCore, which reads the header first, lets such attributes pass. A header must
 * name each attribute once: OpenEXRCore and the library keep different ones of a
 * repeated name (a second dataWindow slipped past the size checks). One pass over the
 * header(s); only the names are kept. */
static Status exr_header_check(const char *path, const exr_attr_box2i_t *core_dw, Error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return ST_OK;   /* the readers report it */
    unsigned char head[8];
    long size = -1;
    if (fread(head, 1, 8, f) != 8 || fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 8, SEEK_SET) != 0) {
        fclose(f);
        return ST_OK;
    }
    int multipart = (head[5] & 0x10) != 0;   /* version flags: bit 12 of the version word */
    Status st = ST_OK;
    char name[256], type[256];
    StrMap seen = { 0 };
    int part = 0, have_dw = 0;
    int32_t dw[4] = { 0, 0, 0, 0 };
    while (!st) {
        if (!exr_read_name(f, name)) break;
        int added = name[0] ? strmap_add(&seen, name, strlen(name), 0) : 0;
        if (added < 0) {
            st = error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
            break;
        }
        if (added > 0) {
            st = error_set(err, ST_INPUT, "'%s': the EXR header names the attribute '%s' twice (a corrupt file)", path,
                           name);
            break;
        }
        if (name[0] == '\0') {
            strmap_free(&seen);
            memset(&seen, 0, sizeof seen);
            part++;
            /* the end of a header: the only one, or in a multi-part file the next one's
             * start, unless that is empty too (the end of the list) */
            if (!multipart) break;
            int c = getc(f);
            if (c == 0 || c == EOF) break;
            ungetc(c, f);
            continue;
        }
        unsigned char sz[4];
        if (!exr_read_name(f, type) || fread(sz, 1, 4, f) != 4) break;
        uint64_t n = bytes_get_le32(sz);
        long at = ftell(f);
        if (at < 0) break;
        if (n > (uint64_t)(size - at)) {
            st = error_set(err, ST_INPUT, "'%s': the EXR header attribute '%s' declares %llu bytes, more than the %llu "
                           "left in the file (a truncated or corrupt file)", path, name, (unsigned long long)n,
                           (unsigned long long)(size - at));
            break;
        }
        if (part == 0 && strcmp(name, "dataWindow") == 0 && strcmp(type, "box2i") == 0 && n == 16) {
            unsigned char b[16];
            if (fread(b, 1, 16, f) != 16 || fseek(f, -16, SEEK_CUR) != 0) break;
            for (int k = 0; k < 4; k++) dw[k] = (int32_t)bytes_get_le32(b + 4 * k);
            have_dw = 1;
        }
        if (!exr_value_fits(f, type, n))
            st = error_set(err, ST_INPUT, "'%s': the EXR header attribute '%s' of type '%s' does not hold the %llu "
                           "bytes it declares (a corrupt file)", path, name, type, (unsigned long long)n);
    }
    strmap_free(&seen);
    fclose(f);
    /* The library sizes its line buffers from the first header's dataWindow as it reads
     * it in order; OpenEXRCore may have taken another one from a garbled header (a
     * 1 GB line buffer for a 455-byte file, found by fuzz_texture). Both must agree. */
    if (!st && (!have_dw || dw[0] != core_dw->min.x || dw[1] != core_dw->min.y || dw[2] != core_dw->max.x ||
                dw[3] != core_dw->max.y))
        st = error_set(err, ST_INPUT, "'%s': the EXR header's dataWindow is missing or read two ways (a corrupt file)",
                       path);
    return st;
}

/* Where pixel (0, 0) of a data window starting at (x0, y0), w pixels wide, would be if
 * px held the window: the base the library's frame buffer wants (exr_decode). */
static ImfRgba *exr_frame_base(ImfRgba *px, int x0, int y0, int w)
{
    uintptr_t offset = ((uintptr_t)(intptr_t)x0 + (uintptr_t)(intptr_t)y0 * (uintptr_t)w) * sizeof *px;
    return (ImfRgba *)((uintptr_t)px - offset);
}

/* Decodes the pixels through the OpenEXR library's C interface to RgbaInputFile
 * (EXR_VIA_RGBA): it reads every layout and compression (DWAA/DWAB, which real tools
 * write environment maps with, included), converts luminance/chroma images to RGB and
 * gives halves, exact for colour stored in halves (the precision of almost every EXR
 * environment map). */
static Status exr_decode(const char *path, int w, int h, float *rgb, Error *err)
{
    ImfInputFile *in = ImfOpenInputFile(path);
    if (!in) return error_set(err, ST_INPUT, "'%s': not an EXR file OpenEXR can read (%s)", path, ImfErrorMessage());
    int x0, y0, x1, y1;
    ImfHeaderDataWindow(ImfInputHeader(in), &x0, &y0, &x1, &y1);
    Status st = ST_OK;
    ImfRgba *px = NULL;
    if (x1 - x0 + 1 != w || y1 - y0 + 1 != h)
        st = error_set(err, ST_INPUT, "'%s': the EXR image changed while it was read", path);
    else if (!(px = malloc((size_t)w * (size_t)h * sizeof *px)))
        st = error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
    /* the frame buffer is addressed by absolute pixel coordinates: its base is where
     * pixel (0, 0) would be (the library's documented use). A data window far from the
     * origin puts that address outside px, even outside the address space (found by
     * fuzz_texture), which pointer arithmetic may not reach: it is computed as an
     * integer, modulo 2^64 as the library's own offsets are. */
    else if (!ImfInputSetFrameBuffer(in, exr_frame_base(px, x0, y0, w), 1, (size_t)w) ||
             !ImfInputReadPixels(in, y0, y1))
        st = error_set(err, ST_INPUT, "'%s': not an EXR file OpenEXR can read (%s)", path, ImfErrorMessage());
    if (!st)
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
            rgb[3 * i] = ImfHalfToFloat(px[i].r);
            rgb[3 * i + 1] = ImfHalfToFloat(px[i].g);
            rgb[3 * i + 2] = ImfHalfToFloat(px[i].b);
        }
    free(px);
    ImfCloseInputFile(in);
    return st;
}

/* How the colour is decoded. A half holds at most 65504: a float sky's 70000-valued sun
 * was infinite as a half, and the image refused (issue 39); so a colour channel of 32
 * bits (float or uint) is read as float, whatever the layout. */
typedef enum {
    EXR_VIA_RGBA,    /* halves through RgbaInputFile (exr_decode): colour in halves only
                      * (read exactly), and luminance/chroma images, which need the
                      * library's conversion to RGB */
    EXR_VIA_CORE,    /* floats through OpenEXRCore (exr_decode_float): scanline and tiled
                      * images of every compression OpenEXRCore decompresses */
    EXR_VIA_IMF,     /* floats through the C++ library (exr_imf.h): DWAA and DWAB, which
                      * Debian 12's OpenEXRCore 3.1 cannot decompress ("DWA/B decompression
                      * not yet implemented in C") */
} ExrDecoder;

static ExrDecoder exr_pick_decoder(exr_context_t ctxt, const exr_attr_chlist_t *ch, const int pick[3])
{
    for (int i = 0; i < ch->num_channels; i++) {
        const char *n = ch->entries[i].name.str;
        if (!strcmp(n, "RY") || !strcmp(n, "BY")) return EXR_VIA_RGBA;
    }
    int wide = 0;
    for (int k = 0; k < 3; k++) {
        if (pick[k] < 0) continue;
        const exr_attr_chlist_entry_t *e = &ch->entries[pick[k]];
        if (e->x_sampling != 1 || e->y_sampling != 1) return EXR_VIA_RGBA;
        if (e->pixel_type != EXR_PIXEL_HALF) wide = 1;
    }
    exr_compression_t comp;
    if (!wide || exr_get_compression(ctxt, 0, &comp) != EXR_ERR_SUCCESS) return EXR_VIA_RGBA;
    return comp == EXR_COMPRESSION_DWAA || comp == EXR_COMPRESSION_DWAB ? EXR_VIA_IMF : EXR_VIA_CORE;
}

/* One chunk of the image: a block of scanlines or a tile of level (0, 0), at (x, y)
 * from the data window's corner, w x h pixels. */
typedef struct {
    exr_chunk_info_t info;
    int64_t x, y, w, h;
} ExrChunk;

/* The number of chunks of level (0, 0) (the full resolution; a mipmapped or ripmapped
 * image's smaller levels follow and are not read) and the blocks' size: tiles of tw x
 * th pixels, or rows of th scanlines (tw = 0). */
static exr_result_t exr_chunk_grid(exr_context_t ctxt, int w, int h, int *cols, int *rows, int *tw, int *th)
{
    exr_storage_t storage;
    exr_result_t rv = exr_get_storage(ctxt, 0, &storage);
    if (rv) return rv;
    if (storage == EXR_STORAGE_TILED) {
        uint32_t x = 0, y = 0;
        exr_tile_level_mode_t levels;
        exr_tile_round_mode_t round;
        rv = exr_get_tile_descriptor(ctxt, 0, &x, &y, &levels, &round);
        if (rv) return rv;
        if (x == 0 || y == 0 || x > INT32_MAX || y > INT32_MAX) return EXR_ERR_INVALID_ATTR;
        *tw = (int)x;
        *th = (int)y;
        *cols = (int)(((int64_t)w + x - 1) / x);
        *rows = (int)(((int64_t)h + y - 1) / y);
        return EXR_ERR_SUCCESS;
    }
    int lines = 0;
    rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines);
    if (rv) return rv;
    if (lines <= 0) return EXR_ERR_INVALID_ATTR;
    *tw = 0;
    *th = lines;
    *cols = 1;
    *rows = (int)(((int64_t)h + lines - 1) / lines);
    return EXR_ERR_SUCCESS;
}

/* Reads the header of chunk (col, row) and where its pixels go. OpenEXRCore 3.1 gives a
 * tile's start_x/start_y as tile indices (later versions as pixels), so a tile's place
 * is computed here from the grid; the chunk's own size must be the one the grid gives
 * it (the image clips the last column and row). */
static exr_result_t exr_locate_chunk(exr_context_t ctxt, const exr_attr_box2i_t *dw, int w, int h, int col, int row,
                                     int tw, int th, ExrChunk *c)
{
    exr_result_t rv;
    if (tw > 0) {
        rv = exr_read_tile_chunk_info(ctxt, 0, col, row, 0, 0, &c->info);
        c->x = (int64_t)col * tw;
    } else {
        rv = exr_read_scanline_chunk_info(ctxt, 0, (int)(dw->min.y + (int64_t)row * th), &c->info);
        c->x = 0;
    }
    if (rv) return rv;
    c->y = (int64_t)row * th;
    c->w = tw > 0 ? (w - c->x < tw ? w - c->x : tw) : w;
    c->h = h - c->y < th ? h - c->y : th;
    if (c->info.width != c->w || c->info.height != c->h || (tw == 0 && c->info.start_y != dw->min.y + c->y))
        return EXR_ERR_CORRUPT_CHUNK;
    return EXR_ERR_SUCCESS;
}

/* Decodes the colour channels pick[] of a scanline or tiled image (EXR_VIA_CORE)
 * through OpenEXRCore as 32-bit floats into rgb (w x h x 3, zeroed): halves convert
 * exactly, floats keep every bit. One channel (Y) picked for all three is decoded once
 * and copied. */
static Status exr_decode_float(exr_context_t ctxt, const char *path, const exr_attr_chlist_t *ch, const int pick[3],
                               const exr_attr_box2i_t *dw, int w, int h, float *rgb, Error *err)
{
    int cols = 0, rows = 0, tw = 0, th = 0;
    exr_result_t rv = exr_chunk_grid(ctxt, w, h, &cols, &rows, &tw, &th);
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    int started = 0;
    for (int row = 0; rv == EXR_ERR_SUCCESS && row < rows; row++)
        for (int col = 0; rv == EXR_ERR_SUCCESS && col < cols; col++) {
            ExrChunk c;
            rv = exr_locate_chunk(ctxt, dw, w, h, col, row, tw, th, &c);
            if (rv) break;
            rv = started ? exr_decoding_update(ctxt, 0, &c.info, &dec) : exr_decoding_initialize(ctxt, 0, &c.info, &dec);
            if (rv) break;
            started = 1;
            for (int i = 0; i < dec.channel_count; i++) {
                exr_coding_channel_info_t *cc = &dec.channels[i];
                cc->decode_to_ptr = NULL;
                for (int k = 0; k < 3; k++) {
                    if (pick[k] < 0 || (k > 0 && pick[k] == pick[k - 1])) continue;
                    if (strcmp(cc->channel_name, ch->entries[pick[k]].name.str) != 0) continue;
                    cc->decode_to_ptr = (uint8_t *)(rgb + 3u * ((size_t)c.y * (size_t)w + (size_t)c.x) + k);
                    cc->user_pixel_stride = (int32_t)(3 * sizeof(float));
                    cc->user_line_stride = (int32_t)((size_t)w * 3 * sizeof(float));
                    cc->user_data_type = EXR_PIXEL_FLOAT;
                    cc->user_bytes_per_element = (int16_t)sizeof(float);
                }
            }
            rv = exr_decoding_choose_default_routines(ctxt, 0, &dec);
            if (!rv) rv = exr_decoding_run(ctxt, 0, &dec);
        }
    if (started) exr_decoding_destroy(ctxt, &dec);
    if (rv) return exr_fail(path, rv, err);
    return ST_OK;
}

/* Y alone, picked for all three components, was decoded into the first: copy it. */
static void exr_spread_grey(const int pick[3], float *rgb, int w, int h)
{
    for (int k = 1; k < 3; k++)
        if (pick[k] >= 0 && pick[k] == pick[0])
            for (size_t i = 0; i < (size_t)w * (size_t)h; i++) rgb[3 * i + (size_t)k] = rgb[3 * i];
}

/* Decodes through the C++ library (EXR_VIA_IMF), after the same checks. */
static Status exr_decode_imf(const char *path, const exr_attr_chlist_t *ch, const int pick[3],
                             const exr_attr_box2i_t *dw, int w, int h, float *rgb, Error *err)
{
    const char *names[3];
    for (int k = 0; k < 3; k++) names[k] = pick[k] < 0 ? NULL : ch->entries[pick[k]].name.str;
    char why[256];
    if (!exr_imf_read_float(path, names, dw->min.x, dw->min.y, w, h, rgb, why, sizeof why))
        return error_set(err, ST_INPUT, "'%s': not an EXR file OpenEXR can read (%s)", path, why);
    return ST_OK;
}

/* Checks every value: the renderer's sums need finite numbers (a half can be inf or
 * NaN). */
static Status exr_finish_pixels(const char *path, float *rgb, int w, int h, Error *err)
{
        size_t n = (size_t)w * (size_t)h;
    for (size_t i = 0; i < n; i++) {
        float *p = rgb + 3u * i;
        for (int k = 0; k < 3; k++) {
            if (!isfinite(p[k]))
                return error_set(err, ST_INPUT, "'%s': pixel (%zu, %zu) of the EXR image is not a finite number",
                                 path, i % (size_t)w, i / (size_t)w);
        }
    }
    return ST_OK;
}

int exr_size(const char *path, int *width, int *height)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_error_handler;
    init.max_image_width = EXR_MAX_SIDE;
    init.max_image_height = EXR_MAX_SIDE;
    exr_context_t ctxt = NULL;
    exr_attr_box2i_t dw;
    int ok = exr_start_read(&ctxt, path, &init) == EXR_ERR_SUCCESS &&
             exr_get_data_window(ctxt, 0, &dw) == EXR_ERR_SUCCESS;
    exr_finish(&ctxt);
    if (!ok) return 0;
    *width = (int)((int64_t)dw.max.x - dw.min.x + 1);
    *height = (int)((int64_t)dw.max.y - dw.min.y + 1);
    return 1;
}

Status exr_read_rgb(const char *path, uint64_t max_pixels, float **rgb, int *width, int *height, Error *err)
{
    *rgb = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_error_handler;
    /* the library sizes its chunk table from the header: a bound on the sides keeps a
     * corrupt header from asking for gigabytes before our own size check runs */
    init.max_image_width = EXR_MAX_SIDE;
    init.max_image_height = EXR_MAX_SIDE;
    exr_last_error[0] = '\0';
    exr_context_t ctxt = NULL;
    exr_result_t rv = exr_start_read(&ctxt, path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        Status st = exr_fail(path, rv, err);
        exr_finish(&ctxt);
        return st;
    }
    const exr_attr_chlist_t *ch = NULL;
    exr_attr_box2i_t dw;
    Status st = ST_OK;
    if ((rv = exr_get_channels(ctxt, 0, &ch)) != EXR_ERR_SUCCESS || (rv = exr_get_data_window(ctxt, 0, &dw)))
        st = exr_fail(path, rv, err);
    int pick[3] = { -1, -1, -1 };
    int64_t w = 0, h = 0;
    if (!st) {
        for (int k = 0; k < 3; k++) pick[k] = exr_pick_channel(ch, k);
        w = (int64_t)dw.max.x - dw.min.x + 1;
        h = (int64_t)dw.max.y - dw.min.y + 1;
        if (w > INT32_MAX || h > INT32_MAX) w = h = 0;
        st = exr_check_part(ctxt, path, max_pixels, pick, (int)w, (int)h, err);
    }
    if (!st) st = exr_header_check(path, &dw, err);
    float *px = NULL;
    if (!st && !(px = calloc((size_t)w * (size_t)h * 3u, sizeof *px)))
        st = error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
    ExrDecoder via = st ? EXR_VIA_RGBA : exr_pick_decoder(ctxt, ch, pick);
    if (!st && via == EXR_VIA_CORE) st = exr_decode_float(ctxt, path, ch, pick, &dw, (int)w, (int)h, px, err);
    if (!st && via == EXR_VIA_IMF) st = exr_decode_imf(path, ch, pick, &dw, (int)w, (int)h, px, err);
    if (!st && via != EXR_VIA_RGBA) exr_spread_grey(pick, px, (int)w, (int)h);
    exr_finish(&ctxt);
    if (!st && via == EXR_VIA_RGBA) st = exr_decode(path, (int)w, (int)h, px, err);
    if (!st) st = exr_finish_pixels(path, px, (int)w, (int)h, err);
    if (st) {
        free(px);
        return st;
    }
    *rgb = px;
    *width = (int)w;
    *height = (int)h;
    return ST_OK;
}

/* ------------------------------------------------------------------ writing */

/* The file being encoded, in memory: OpenEXRCore writes at offsets (the chunk table is
 * written last, after the chunks), so it is a growing buffer, not a stream. */
typedef struct {
    unsigned char *data;
    size_t size, cap;
    int failed;
} ExrMemory;

static int64_t exr_memory_write(exr_const_context_t ctxt, void *user, const void *buffer, uint64_t sz, uint64_t offset,
                                exr_stream_error_func_ptr_t error_cb)
{
    ExrMemory *m = user;
    if (offset > SIZE_MAX - sz) m->failed = 1;
    size_t end = m->failed ? 0 : (size_t)(offset + sz);
    if (!m->failed && end > m->cap) {
        size_t cap = m->cap ? m->cap : 4096;
        while (cap < end) cap = cap > SIZE_MAX / 2 ? end : 2 * cap;
        unsigned char *grown = realloc(m->data, cap);
        if (!grown) m->failed = 1;
        else {
            memset(grown + m->cap, 0, cap - m->cap);
            m->data = grown;
            m->cap = cap;
        }
    }
    if (m->failed) {
        error_cb(ctxt, EXR_ERR_OUT_OF_MEMORY, "out of memory encoding the EXR image");
        return -1;
    }
    memcpy(m->data + offset, buffer, (size_t)sz);
    if (end > m->size) m->size = end;
    return (int64_t)sz;
}

/* Points each channel of the encoder at its source rows for the chunk starting at
 * row y (the encoder lists the channels sorted by name). */
static void exr_encode_sources(exr_encode_pipeline_t *enc, const ExrChannel *ch, size_t n, unsigned width, int y)
{
    for (int c = 0; c < enc->channel_count; c++) {
        exr_coding_channel_info_t *cc = &enc->channels[c];
        for (size_t i = 0; i < n; i++) {
            if (strcmp(cc->channel_name, ch[i].name) != 0) continue;
            cc->encode_from_ptr = (const uint8_t *)(ch[i].data + (size_t)y * width * ch[i].stride);
            cc->user_pixel_stride = (int32_t)(ch[i].stride * sizeof(float));
            cc->user_line_stride = (int32_t)((size_t)width * ch[i].stride * sizeof(float));
            cc->user_data_type = EXR_PIXEL_FLOAT;
            cc->user_bytes_per_element = (int16_t)sizeof(float);
        }
    }
}

Status exr_encode(const ExrChannel *ch, size_t n, unsigned width, unsigned height, int float32, unsigned char **bytes,
                  size_t *size, Error *err)
{
    *bytes = NULL;
    *size = 0;
    ExrMemory mem = { NULL, 0, 0, 0 };
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_error_handler;
    init.user_data = &mem;
    init.write_fn = exr_memory_write;
    exr_last_error[0] = '\0';
    exr_context_t ctxt = NULL;
    int part = 0, lines = 0, started = 0;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    exr_result_t rv = exr_start_write(&ctxt, EXR_NO_FILE, EXR_WRITE_FILE_DIRECTLY, &init);
    if (!rv) rv = exr_add_part(ctxt, "image", EXR_STORAGE_SCANLINE, &part);
    if (!rv) rv = exr_initialize_required_attr_simple(ctxt, part, (int32_t)width, (int32_t)height, EXR_COMPRESSION_ZIP);
    for (size_t i = 0; i < n && !rv; i++)
        rv = exr_add_channel(ctxt, part, ch[i].name, float32 || ch[i].float32 ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF,
                             ch[i].linear ? EXR_PERCEPTUALLY_LINEAR : EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (!rv) rv = exr_write_header(ctxt);
    if (!rv) rv = exr_get_scanlines_per_chunk(ctxt, part, &lines);
    for (int y = 0; !rv && y < (int)height; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_write_scanline_chunk_info(ctxt, part, y, &ci);
        if (!rv) rv = started ? exr_encoding_update(ctxt, part, &ci, &enc) : exr_encoding_initialize(ctxt, part, &ci, &enc);
        if (rv) break;
        started = 1;
        exr_encode_sources(&enc, ch, n, width, y);
        rv = exr_encoding_choose_default_routines(ctxt, part, &enc);
        if (!rv) rv = exr_encoding_run(ctxt, part, &enc);
    }
    if (started) exr_encoding_destroy(ctxt, &enc);
    exr_result_t fin = exr_finish(&ctxt);
    if (!rv) rv = fin;
    if (rv || mem.failed) {
        free(mem.data);
        return error_set(err, ST_INTERNAL, "cannot encode the EXR image: %s",
                         exr_last_error[0] ? exr_last_error : exr_get_error_code_as_string(rv));
    }
    *bytes = mem.data;
    *size = mem.size;
    return ST_OK;
}
