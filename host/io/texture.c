/* texture.c — image and checkerboard textures (see texture.h). */
#include "io/texture.h"

#include "base/bytes.h"
#include "base/limit.h"
#include "io/exr.h"
#include "io/lexer.h"
#include "util/kmath.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <stb_image.h>

static Texture texture_base(uint type)
{
    Texture t;
    memset(&t, 0, sizeof t);
    t.type = type;
    t.m[0] = 1.0f;
    t.m[5] = 1.0f;
    t.m[10] = 1.0f;
    return t;
}

Texture texture_make_checker(vec3 c0, vec3 c1, float scale, int solid)
{
    Texture t = texture_base(TEX_CHECKER);
    t.flags = solid ? TEX_SOLID : 0u;
    t.color0 = c0;
    t.color1 = c1;
    texture_set_scale_offset(&t, scale, scale, 0.0f, 0.0f);
    return t;
}

void texture_set_scale_offset(Texture *t, float su, float sv, float ou, float ov)
{
    memset(t->m, 0, sizeof t->m);
    t->m[0] = su;
    t->m[3] = ou;
    t->m[5] = sv;
    t->m[7] = ov;
    t->m[10] = (t->flags & TEX_SOLID) ? su : 1.0f;
}

void texture_set_matrix(Texture *t, const float m[12])
{
    memcpy(t->m, m, sizeof t->m);
}

Status texture_check_map(const Texture *t, Error *err)
{
    for (int i = 0; i < 12; i++) {
        float e = t->m[i];
        if (e >= -TEXTURE_MAX_MAP_ENTRY && e <= TEXTURE_MAX_MAP_ENTRY) continue;
        return error_set(err, ST_INPUT, "the texture's map has %s %g (row %d, column %d); clpt takes finite entries "
                         "of at most %.0f in size", isfinite(e) ? "the entry" : "an entry that is not finite as a "
                         "float:", (double)e, i / 4 + 1, i % 4 + 1, (double)TEXTURE_MAX_MAP_ENTRY);
    }
    return ST_OK;
}

/* Packs 8-bit RGBA into the uint texel layout of kernels/material/texture.h. */
static uint pack_rgba(const unsigned char *p)
{
    return bytes_get_le32(p);
}

/* A binary PNM (P5, P6) must hold the pixels its header declares. stb_image 2.27
 * (Debian 12's libstb) reads past its buffer when a 16-bit one (maxval > 255) is short,
 * and fills a short 8-bit one with black; both are truncated files, so both are errors,
 * found before stb_image sees them. Its header numbers must fit an int: stb_image reads
 * them into one without a check, so a height of 46 digits wrapped to 198 and a short
 * 16-bit file got past the size check below (found by fuzz_texture). Anything that is
 * not a binary PNM header passes. */
static Status pnm_check(const char *path, Error *err)
{
    static const char *const field[3] = { "width", "height", "maxval" };
    FILE *f = fopen(path, "rb");
    if (!f) return ST_OK;   /* stb_image reports it */
    unsigned char head[4096];
    size_t n = fread(head, 1, sizeof head, f);
    long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    fclose(f);
    if (n < 2 || size < 0 || head[0] != 'P' || (head[1] != '5' && head[1] != '6')) return ST_OK;
    uint64_t v[3];
    size_t p = 2;
    for (int i = 0; i < 3; i++) {
        /* blanks and # comments, as stb_image skips them */
        for (;;) {
            while (p < n && isspace(head[p])) p++;
            if (p >= n || head[p] != '#') break;
            while (p < n && head[p] != '\n' && head[p] != '\r') p++;
        }
        if (p >= n || !isdigit(head[p])) return ST_OK;   /* malformed: stb_image rejects it */
        size_t first = p;
        v[i] = 0;
        while (p < n && isdigit(head[p])) {
            if (v[i] <= INT32_MAX) v[i] = v[i] * 10 + (uint64_t)(head[p] - '0');
            p++;
        }
        if (v[i] > INT32_MAX)
            return error_set(err, ST_INPUT, "%s: the header's %s, a number of %zu digits, is larger than %d: the "
                             "file is corrupt", path, field[i], p - first, INT32_MAX);
    }
    p++;   /* the one blank after maxval */
    uint64_t channels = head[1] == '6' ? 3 : 1, bytes = v[2] > 255 ? 2 : 1;
    return limit_count(path, "pixels", v[0] * v[1], channels * bytes,
                       (uint64_t)size > p ? (uint64_t)size - p : 0, err);
}

/* Every PNG chunk must fit in the file. stb_image 2.27 reserves an IDAT chunk's declared
 * length before reading it, so a corrupt length of a few gigabytes in a small file is a
 * huge allocation (found by fuzz_texture); the walk over the chunk headers finds it
 * first. Anything that is not a PNG passes. */
static Status png_check(const char *path, Error *err)
{
    static const unsigned char signature[8] = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n' };
    FILE *f = fopen(path, "rb");
    if (!f) return ST_OK;   /* stb_image reports it */
    unsigned char head[8];
    long size = -1;
    Status st = ST_OK;
    if (fread(head, 1, 8, f) != 8 || memcmp(head, signature, 8) != 0 || fseek(f, 0, SEEK_END) != 0 ||
        (size = ftell(f)) < 0 || fseek(f, 8, SEEK_SET) != 0) {
        fclose(f);
        return ST_OK;
    }
    uint64_t at = 8;
    while (at + 8 <= (uint64_t)size) {
        unsigned char c[8];
        if (fread(c, 1, 8, f) != 8) break;
        uint64_t length = bytes_get_be32(c);
        /* the chunk's data and its 4-byte CRC */
        if (length > (uint64_t)size - at - 8) {
            char type[5];
            for (int i = 0; i < 4; i++) type[i] = isprint(c[4 + i]) ? (char)c[4 + i] : '?';
            type[4] = '\0';
            st = error_set(err, ST_INPUT, "'%s': the PNG chunk '%s' at byte offset %llu declares %llu bytes, more "
                           "than the %llu left in the file (a truncated or corrupt file)", path, type,
                           (unsigned long long)at, (unsigned long long)length,
                           (unsigned long long)((uint64_t)size - at - 8));
            break;
        }
        if (memcmp(c + 4, "IEND", 4) == 0) break;
        at += 12 + length;
        if (fseek(f, (long)at, SEEK_SET) != 0) break;
    }
    fclose(f);
    return st;
}

/* ------------------------------------------------------------------ the data that
 * TGA, BMP, PSD and HDR headers promise. stb_image 2.27 decodes a short file without
 * complaint: an uncompressed TGA's missing rows stay uninitialised (valgrind sees them
 * read in texture_eval), BMP and PSD pixels and run-length packets read past the end as
 * zeros, and an HDR allocates for its claimed size before reading a byte of it (1.5 GB
 * from a 51-byte file). So before stb_image decodes, the bytes the header promises are
 * checked against the file: a fixed size for uncompressed data, and for run-length
 * data a walk over the packets exactly as stb_image reads them, which costs one pass
 * over the file and allocates nothing. A structure stb_image rejects itself (a bad
 * packet, an unknown depth) passes here and is reported by stb_image. */

/* A cursor over the file; reads past its end set `short_read`. */
typedef struct {
    FILE *f;
    uint64_t pos, size;
    int short_read;
} Walk;

static int walk_byte(Walk *w)
{
    int c = w->pos < w->size ? getc(w->f) : EOF;
    if (c == EOF) {
        w->short_read = 1;
        return 0;
    }
    w->pos++;
    return c;
}

static void walk_skip(Walk *w, uint64_t n)
{
    if (n > w->size - w->pos) {
        w->short_read = 1;
        w->pos = w->size;
    } else if (n <= 64) {
        for (uint64_t i = 0; i < n; i++) walk_byte(w);
    } else {
        w->pos += n;
        if (fseeko(w->f, (off_t)w->pos, SEEK_SET) != 0) w->short_read = 1;
    }
}


/* Uncompressed data of `need` bytes from byte `start`. */
static Status check_fixed(const char *path, const char *format, int w, int h, uint64_t start, uint64_t need,
                          uint64_t size, Error *err)
{
    if (start <= size && need <= size - start) return ST_OK;
    return error_set(err, ST_INPUT, "'%s': a truncated %s file: its %dx%d pixels need %llu bytes after byte "
                     "%llu, and the file has %llu bytes", path, format, w, h, (unsigned long long)need,
                     (unsigned long long)start, (unsigned long long)size);
}

static Status check_walked(const Walk *wk, const char *path, const char *format, int w, int h, Error *err)
{
    if (!wk->short_read) return ST_OK;
    return error_set(err, ST_INPUT, "'%s': a truncated %s file: its run-length data ends (at byte %llu) "
                     "before the %dx%d pixels its header declares", path, format,
                     (unsigned long long)wk->size, w, h);
}

/* stb_image's TGA reader: an 18-byte header, the image ID, the palette (after
 * `palette_start` bytes stb_image skips), then pixels of 1 to 4 bytes, raw or in
 * packets of up to 128 (a header byte, then one pixel repeated or that many pixels). */
static Status tga_check(Walk *wk, const unsigned char *hd, const char *path, int w, int h, Error *err)
{
    int indexed = hd[1], type = hd[2], bpp = hd[16], rle = type >= 8;
    uint64_t pixel = indexed ? (bpp == 8 ? 1u : 2u) : (uint64_t)(bpp + 7) / 8;
    uint64_t start = 18 + (uint64_t)hd[0];
    if (indexed) start += bytes_get_le16(hd + 3) + bytes_get_le16(hd + 5) * (uint64_t)((hd[7] + 7) / 8);
    uint64_t n = (uint64_t)w * (uint64_t)h;
    if (!rle) return check_fixed(path, "TGA", w, h, start, n * pixel, wk->size, err);
    walk_skip(wk, start - wk->pos);
    for (uint64_t i = 0; i < n && !wk->short_read;) {
        int cmd = walk_byte(wk);
        uint64_t count = 1 + (uint64_t)(cmd & 127);
        if (count > n - i) count = n - i;
        walk_skip(wk, (cmd & 128 ? 1 : count) * pixel);
        i += count;
    }
    return check_walked(wk, path, "TGA", w, h, err);
}

/* stb_image's BMP reader: uncompressed rows of w pixels of `bpp` bits, each padded to
 * 4 bytes, from the header's data offset (run-length BMPs it refuses). */
static Status bmp_check(Walk *wk, const unsigned char *hd, const char *path, int w, int h, Error *err)
{
    uint64_t hsz = bytes_get_le32(hd + 14), bpp = hsz == 12 ? bytes_get_le16(hd + 24) : bytes_get_le16(hd + 28);
    if (bpp != 1 && bpp != 4 && bpp != 8 && bpp != 16 && bpp != 24 && bpp != 32) return ST_OK;
    uint64_t row = ((uint64_t)w * bpp + 7) / 8, stride = ((uint64_t)w * bpp + 31) / 32 * 4;
    return check_fixed(path, "BMP", w, h, bytes_get_le32(hd + 10), stride * (uint64_t)(h - 1) + row, wk->size, err);
}

/* stb_image's PSD reader: a 26-byte header, three sections with a 4-byte length each,
 * the compression, then the first four channels one after the other: raw, or after a
 * table of 2-byte row lengths it skips, PackBits packets (a header byte n: n + 1 bytes
 * copied, 257 - n copies of one byte, or 128, nothing) over the whole channel. */
static Status psd_check(Walk *wk, const unsigned char *hd, const char *path, int w, int h, Error *err)
{
    uint64_t channels = bytes_get_be16(hd + 12), depth = bytes_get_be16(hd + 22), n = (uint64_t)w * (uint64_t)h;
    walk_skip(wk, 26);
    for (int section = 0; section < 3 && !wk->short_read; section++) {
        unsigned char len[4];
        for (int i = 0; i < 4; i++) len[i] = (unsigned char)walk_byte(wk);
        walk_skip(wk, bytes_get_be32(len));
    }
    unsigned char comp[2];
    comp[0] = (unsigned char)walk_byte(wk);
    comp[1] = (unsigned char)walk_byte(wk);
    if (wk->short_read) return check_walked(wk, path, "PSD", w, h, err);
    uint64_t read = channels < 4 ? channels : 4;
    if (bytes_get_be16(comp) == 0) return check_fixed(path, "PSD", w, h, wk->pos, read * n * (depth / 8), wk->size, err);
    if (bytes_get_be16(comp) != 1) return ST_OK;
    walk_skip(wk, (uint64_t)h * channels * 2);
    for (uint64_t c = 0; c < read && !wk->short_read; c++)
        for (uint64_t done = 0; done < n && !wk->short_read;) {
            int len = walk_byte(wk);
            if (len == 128) continue;
            uint64_t count = len < 128 ? (uint64_t)len + 1 : 257 - (uint64_t)len;
            if (count > n - done) return ST_OK;   /* stb_image: "bad RLE data" */
            walk_skip(wk, len < 128 ? count : 1);
            done += count;
        }
    return check_walked(wk, path, "PSD", w, h, err);
}

/* stb_image's Radiance HDR reader: text lines up to an empty one, the size line, then
 * 4 bytes a pixel, flat when the width is below 8 or above 32767 or a scanline does not
 * start with the marker 2 2 (from there stb_image reads the whole image flat), else per
 * scanline the marker, the width, and each of the 4 components in packets (n > 128: one
 * byte repeated n - 128 times; else n bytes). */
static Status hdr_check(Walk *wk, const char *path, int w, int h, Error *err)
{
    /* the identifier line, the header lines, the empty line, the size line; stb_image
     * reads a line as a C string, so a line that starts with a NUL ends the header too
     * (missing that let a file through whose RLE data stb_image then read past its end,
     * where it loops for ever on zero-length packets) */
    int lines_after_empty = -1;
    for (int prev = '\n'; lines_after_empty < 1;) {
        int c = walk_byte(wk);
        if (wk->short_read) break;
        if (prev == '\n' && c == '\0' && lines_after_empty < 0) {
            while (walk_byte(wk) != '\n' && !wk->short_read) {}
            c = '\n';
            lines_after_empty = 0;
        } else if (c == '\n') {
            if (prev == '\n' && lines_after_empty < 0) lines_after_empty = 0;
            else if (lines_after_empty >= 0) lines_after_empty++;
        }
        prev = c;
    }
    /* a header cut short is rejected by stb_image; a size line cut short leaves no data,
     * which the checks below report */
    if (wk->short_read && lines_after_empty < 0) return ST_OK;
    uint64_t n = (uint64_t)w * (uint64_t)h;
    if (w < 8 || w >= 32768) return check_fixed(path, "HDR", w, h, wk->pos, n * 4, wk->size, err);
    for (int j = 0; j < h && !wk->short_read; j++) {
        uint64_t line_start = wk->pos;
        int c1 = walk_byte(wk), c2 = walk_byte(wk), hi = walk_byte(wk);
        if (c1 != 2 || c2 != 2 || (hi & 0x80))
            return check_fixed(path, "HDR", w, h, line_start, n * 4, wk->size, err);
        if ((hi << 8 | walk_byte(wk)) != w) return ST_OK;   /* stb_image: "invalid decoded scanline length" */
        for (int k = 0; k < 4 && !wk->short_read; k++)
            for (int i = 0; i < w && !wk->short_read;) {
                int count = walk_byte(wk);
                int run = count > 128;
                if (run) count -= 128;
                if (count > w - i) return ST_OK;   /* stb_image: "bad RLE data in HDR" */
                walk_skip(wk, run ? 1u : (uint64_t)count);
                i += count;
            }
    }
    return check_walked(wk, path, "HDR", w, h, err);
}

/* Dispatches on the format by its signature; TGA, which has none, is what stb_image
 * recognised that has a colour-map type of 0 or 1 in its second byte (no other
 * format's signature has). */
static Status data_check(const char *path, int w, int h, Error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return ST_OK;   /* stb_image reports it */
    unsigned char hd[32] = { 0 };
    size_t got = fread(hd, 1, sizeof hd, f);
    off_t size = fseeko(f, 0, SEEK_END) == 0 ? ftello(f) : -1;
    Status st = ST_OK;
    if (size >= 0 && fseeko(f, 0, SEEK_SET) == 0 && w > 0 && h > 0) {
        Walk wk = { f, 0, (uint64_t)size, 0 };
        /* a header shorter than its format's is read as stb_image reads it: the
         * missing bytes are zeros */
        if (got >= 2 && memcmp(hd, "BM", 2) == 0) st = bmp_check(&wk, hd, path, w, h, err);
        else if (got >= 4 && memcmp(hd, "8BPS", 4) == 0) st = psd_check(&wk, hd, path, w, h, err);
        else if (got >= 2 && memcmp(hd, "#?", 2) == 0) st = hdr_check(&wk, path, w, h, err);
        else if (got >= 2 && hd[1] <= 1) st = tga_check(&wk, hd, path, w, h, err);
    }
    fclose(f);
    return st;
}

/* Whether the file at `path` starts with the OpenEXR magic number. */
static Status texture_add_read(Scene *s, const char *name, const char *path, Texture t, uint *texels, size_t n,
                               int w, int h, int clamp, uint *index, Error *err);

static int file_is_exr(const char *path)
{
    unsigned char head[4];
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    size_t n = fread(head, 1, sizeof head, f);
    fclose(f);
    return exr_is_exr(head, n);
}

/* An EXR image as float texels (3 floats a texel, as uint bits). */
static Status texture_read_exr(const char *path, uint **texels, size_t *n, int *w, int *h, Error *err)
{
    float *rgb = NULL;
    Status st = exr_read_rgb(path, CLPT_MAX_TEXTURE_PIXELS, &rgb, w, h, err);
    if (st) return st;
    *n = (size_t)*w * (size_t)*h * 3u;
    *texels = malloc(*n * sizeof **texels);
    if (*texels) memcpy(*texels, rgb, *n * sizeof **texels);   /* float bits as uint */
    free(rgb);
    return *texels ? ST_OK : error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
}

/* Reads the image file at `path` into new texels: 3 floats (as uint bits) a texel and
 * TEX_FLOAT in *flags for EXR and Radiance HDR, else packed RGBA8 and TEX_SRGB unless
 * `linear`. */
static Status texture_read(const char *path, int linear, uint **out, size_t *n_out, int *w_out, int *h_out,
                           uint *flags, Error *err)
{
    /* stb_image opens files by name: a FIFO would block it, a directory read as empty */
    Status fst = lex_check_file(path, err);
    if (fst) return fst;
    int w = 0, h = 0, channels = 0;
    uint *texels = NULL;
    size_t n = 0;
    if (file_is_exr(path)) {
        *flags = TEX_FLOAT;
        return texture_read_exr(path, out, n_out, w_out, h_out, err);
    }
    Status pst = pnm_check(path, err);
    if (!pst) pst = png_check(path, err);
    if (pst) return pst;
    /* the size from the header, and the data it promises, before stb_image allocates
     * for it */
    int known = stbi_info(path, &w, &h, &channels);
    if (known && (uint64_t)(unsigned)w * (uint64_t)(unsigned)h > CLPT_MAX_TEXTURE_PIXELS)
        return error_set(err, ST_INPUT, "'%s': a %dx%d image is larger than the textures clpt "
                         "reads (at most %u pixels, as in 8192x8192)", path, w, h, CLPT_MAX_TEXTURE_PIXELS);
    if (known && (pst = data_check(path, w, h, err))) return pst;
    if (stbi_is_hdr(path)) {
        float *data = stbi_loadf(path, &w, &h, &channels, 3);
        if (!data)
            return error_set(err, ST_INPUT, "'%s': not an image stb_image can read (%s)", path,
                             stbi_failure_reason());
        n = (size_t)w * (size_t)h * 3u;
        texels = malloc(n * sizeof *texels);
        if (texels) memcpy(texels, data, n * sizeof *texels);   /* float bits as uint */
        stbi_image_free(data);
        *flags = TEX_FLOAT;
    } else {
        unsigned char *data = stbi_load(path, &w, &h, &channels, 4);
        if (!data)
            return error_set(err, ST_INPUT, "'%s': not an image stb_image can read (%s)", path,
                             stbi_failure_reason());
        n = (size_t)w * (size_t)h;
        texels = malloc(n * sizeof *texels);
        if (texels)
            for (size_t i = 0; i < n; i++) texels[i] = pack_rgba(data + 4 * i);
        stbi_image_free(data);
        *flags = linear ? 0u : TEX_SRGB;
    }
    if (!texels) return error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
    *out = texels;
    *n_out = n;
    *w_out = w;
    *h_out = h;
    return ST_OK;
}

Status texture_load_image(Scene *s, const char *name, const char *path, int linear, int clamp,
                          uint *index, Error *err)
{
    Texture t = texture_base(TEX_IMAGE);
    /* the same file read before with the same encoding: share its texels */
    uint same = scene_find_texture_source(s, path, linear);
    if (same != NO_INDEX) {
        const Texture *o = &s->textures[same];
        t.offset = o->offset;
        t.width = o->width;
        t.height = o->height;
        t.flags = (o->flags & (TEX_FLOAT | TEX_SRGB)) | (clamp ? TEX_CLAMP : 0u);
        return scene_add_texture(s, name, path, t, index, err);
    }
    int w = 0, h = 0;
    uint *texels = NULL;
    size_t n = 0;
    Status st = texture_read(path, linear, &texels, &n, &w, &h, &t.flags, err);
    if (st) return st;
    return texture_add_read(s, name, path, t, texels, n, w, h, clamp, index, err);
}

Status texture_read_rgb(const char *path, int linear, float **rgb, int *width, int *height, Error *err)
{
    uint *texels = NULL, flags = 0;
    size_t n = 0;
    int w = 0, h = 0;
    Status st = texture_read(path, linear, &texels, &n, &w, &h, &flags, err);
    if (st) return st;
    if (w <= 0 || h <= 0) {
        free(texels);
        return error_set(err, ST_INPUT, "'%s': the image is empty", path);
    }
    size_t px = (size_t)w * (size_t)h;
    float *out = malloc(px * 3u * sizeof *out);
    if (!out) {
        free(texels);
        return error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
    }
    if (flags & TEX_FLOAT) {
        memcpy(out, texels, px * 3u * sizeof *out);
    } else {
        for (size_t i = 0; i < px; i++)
            for (int c = 0; c < 3; c++) {
                float v = (float)((texels[i] >> (8 * c)) & 0xffu) / 255.0f;
                out[3 * i + (size_t)c] = flags & TEX_SRGB ? k_srgb_to_linear(v) : v;
            }
    }
    free(texels);
    *rgb = out;
    *width = w;
    *height = h;
    return ST_OK;
}

/* Adds the texels just read (taking them: freed here) and the texture over them. */
static Status texture_add_read(Scene *s, const char *name, const char *path, Texture t, uint *texels, size_t n,
                               int w, int h, int clamp, uint *index, Error *err)
{
    if (w <= 0 || h <= 0) {
        free(texels);
        return error_set(err, ST_INPUT, "'%s': the image is empty", path);
    }
    uint offset;
    Status st = scene_add_texels(s, texels, n, &offset, err);
    free(texels);
    if (st) return st;
    t.offset = offset;
    t.width = (uint)w;
    t.height = (uint)h;
    if (clamp) t.flags |= TEX_CLAMP;
    return scene_add_texture(s, name, path, t, index, err);
}

/* PNG chunk lengths of an image in memory checked as png_check does for a file. */
static Status png_check_memory(const char *name, const unsigned char *data, size_t len, Error *err)
{
    size_t at = 8;
    while (len >= 8 && at <= len - 8) {
        const unsigned char *c = data + at;
        uint64_t length = bytes_get_be32(c);
        if (length > (uint64_t)(len - at - 8))
            return error_set(err, ST_INPUT, "%s: a PNG chunk at byte offset %llu declares %llu bytes, more than "
                             "the %llu left in the image (a truncated or corrupt image)", name,
                             (unsigned long long)at, (unsigned long long)length,
                             (unsigned long long)(len - at - 8));
        if (memcmp(c + 4, "IEND", 4) == 0) break;
        at += 12 + (size_t)length;
    }
    return ST_OK;
}

Status texture_load_image_memory(Scene *s, const char *name, const char *source, const unsigned char *data,
                                 size_t len, int linear, uint *index, Error *err)
{
    static const unsigned char png[8] = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n' };
    int is_png = len >= 8 && memcmp(data, png, 8) == 0;
    int is_jpeg = len >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff;
    if (!is_png && !is_jpeg)
        return error_set(err, ST_INPUT, "%s: not a PNG or JPEG image (the image types glTF allows)", source);
    if (len > INT32_MAX) return error_set(err, ST_INPUT, "%s: an image of more than 2 GiB", source);
    Status st = is_png ? png_check_memory(source, data, len, err) : ST_OK;
    if (st) return st;
    int w = 0, h = 0, channels = 0;
    if (stbi_info_from_memory(data, (int)len, &w, &h, &channels) &&
        (uint64_t)(unsigned)w * (uint64_t)(unsigned)h > CLPT_MAX_TEXTURE_PIXELS)
        return error_set(err, ST_INPUT, "%s: a %dx%d image is larger than the textures clpt reads (at most %u "
                         "pixels, as in 8192x8192)", source, w, h, CLPT_MAX_TEXTURE_PIXELS);
    unsigned char *px = stbi_load_from_memory(data, (int)len, &w, &h, &channels, 4);
    if (!px)
        return error_set(err, ST_INPUT, "%s: not an image stb_image can read (%s)", source, stbi_failure_reason());
    size_t n = (size_t)w * (size_t)h;
    uint *texels = w > 0 && h > 0 ? malloc(n * sizeof *texels) : NULL;
    if (texels)
        for (size_t i = 0; i < n; i++) texels[i] = pack_rgba(px + 4 * i);
    stbi_image_free(px);
    if (!texels) return error_set(err, ST_INPUT, "%s: the image is empty or too large for memory", source);
    Texture t = texture_base(TEX_IMAGE);
    uint offset;
    st = scene_add_texels(s, texels, n, &offset, err);
    free(texels);
    if (st) return st;
    t.offset = offset;
    t.width = (uint)w;
    t.height = (uint)h;
    t.flags = linear ? 0u : TEX_SRGB;
    return scene_add_texture(s, name, NULL, t, index, err);
}

/* The course's face names, in the order of enum CubeFace, and the extensions its
 * versions used (Fall 2019: .png; the earlier starter code: .bmp). */
static const char *const cube_faces[6] = { "left", "right", "up", "down", "front", "back" };
static const char *const cube_exts[2] = { ".png", ".bmp" };

Status texture_load_cubemap(Scene *s, const char *dir, uint *first, Error *err)
{
    struct stat sb;
    if (stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode))
        return error_set(err, ST_IO, "'%s': not a folder (a cube map names a folder holding the images "
                         "left, right, up, down, front and back, .png or .bmp)", dir);
    size_t dl = strlen(dir);
    char *path = malloc(dl + 16);
    if (!path) return error_set(err, ST_INTERNAL, "out of memory");
    Status st = ST_OK;
    for (uint f = 0; f < 6 && !st; f++) {
        int found = -1;
        for (int e = 0; e < 2 && found < 0; e++) {
            snprintf(path, dl + 16, "%s/%s%s", dir, cube_faces[f], cube_exts[e]);
            if (stat(path, &sb) == 0) found = e;
        }
        if (found < 0) {
            st = error_set(err, ST_IO, "cannot open '%s/%s%s' (nor '%s/%s%s'): the cube map's %s face",
                           dir, cube_faces[f], cube_exts[0], dir, cube_faces[f], cube_exts[1], cube_faces[f]);
            break;
        }
        snprintf(path, dl + 16, "%s/%s%s", dir, cube_faces[f], cube_exts[found]);
        uint index;
        /* the file's bytes / 255, as the course reads them; clamped at the edges */
        st = texture_load_image(s, NULL, path, 1, 1, &index, err);
        if (!st && f == 0) *first = index;
    }
    free(path);
    return st;
}
