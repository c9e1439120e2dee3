/* texture.c — image and checkerboard textures (see texture.h). */
#include "io/texture.h"

#include "base/limit.h"
#include "io/lexer.h"

#include <ctype.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* Packs 8-bit RGBA into the uint texel layout of kernels/texture.h. */
static uint pack_rgba(const unsigned char *p)
{
    return (uint)p[0] | (uint)p[1] << 8 | (uint)p[2] << 16 | (uint)p[3] << 24;
}

/* A binary PNM (P5, P6) must hold the pixels its header declares. stb_image 2.27
 * (Debian 12's libstb) reads past its buffer when a 16-bit one (maxval > 255) is short,
 * and fills a short 8-bit one with black; both are truncated files, so both are errors,
 * found before stb_image sees them. Anything that is not a binary PNM header passes. */
static Status pnm_check(const char *path, Error *err)
{
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
        v[i] = 0;
        while (p < n && isdigit(head[p]))
            if ((v[i] = v[i] * 10 + (uint64_t)(head[p++] - '0')) > UINT32_MAX) return ST_OK;
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
        uint64_t length = (uint64_t)c[0] << 24 | (uint64_t)c[1] << 16 | (uint64_t)c[2] << 8 | c[3];
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

Status texture_load_image(Scene *s, const char *name, const char *path, int linear, int clamp,
                          uint *index, Error *err)
{
    Texture t = texture_base(TEX_IMAGE);
    uint encoding = linear ? 0u : TEX_SRGB;
    /* the same file read before with the same encoding: share its texels */
    for (size_t i = 0; i < s->n_textures; i++) {
        const Texture *o = &s->textures[i];
        if (!s->texture_sources[i] || strcmp(s->texture_sources[i], path) != 0) continue;
        if ((o->flags & TEX_FLOAT) == 0 && (o->flags & TEX_SRGB) != encoding) continue;
        t.offset = o->offset;
        t.width = o->width;
        t.height = o->height;
        t.flags = (o->flags & (TEX_FLOAT | TEX_SRGB)) | (clamp ? TEX_CLAMP : 0u);
        return scene_add_texture(s, name, path, t, index, err);
    }

    /* stb_image opens files by name: a FIFO would block it, a directory read as empty */
    Status fst = lex_check_file(path, err);
    if (fst) return fst;
    int w = 0, h = 0, channels = 0;
    Status pst = pnm_check(path, err);
    if (!pst) pst = png_check(path, err);
    if (pst) return pst;
    /* the size from the header, before stb_image allocates for it */
    if (stbi_info(path, &w, &h, &channels) &&
        (uint64_t)(unsigned)w * (uint64_t)(unsigned)h > CLPT_MAX_TEXTURE_PIXELS)
        return error_set(err, ST_INPUT, "'%s': a %dx%d image is larger than the textures clpt "
                         "reads (at most %u pixels, as in 8192x8192)", path, w, h, CLPT_MAX_TEXTURE_PIXELS);
    uint *texels = NULL;
    size_t n = 0;
    if (stbi_is_hdr(path)) {
        float *data = stbi_loadf(path, &w, &h, &channels, 3);
        if (!data)
            return error_set(err, ST_INPUT, "'%s': not an image stb_image can read (%s)", path,
                             stbi_failure_reason());
        n = (size_t)w * (size_t)h * 3u;
        texels = malloc(n * sizeof *texels);
        if (texels) memcpy(texels, data, n * sizeof *texels);   /* float bits as uint */
        stbi_image_free(data);
        t.flags = TEX_FLOAT;
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
        t.flags = encoding;
    }
    if (!texels) return error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
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
