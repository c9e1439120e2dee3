/*
 * fuzz_texture.c — image textures (host/io/texture.c, decoding through stb_image, and
 * OpenEXR for EXR files: host/io/exr.c) on arbitrary bytes. The loader reads files, so
 * each input is written to a temporary file first. A file that decodes must give a texture whose texels all lie in the
 * scene's texel array; the size limit must hold before stb_image allocates (a header
 * claiming a huge image in a few bytes is an input error, not an out-of-memory).
 */
#include "fuzz.h"
#include "base/limit.h"
#include "io/exr.h"
#include "io/texture.h"

#include <stdio.h>
#include <unistd.h>

#include <stb_image.h>

FUZZ_SEEDS("png bmp tga hdr psd ppm pgm jpg exr");

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char path[64];
    if (!path[0]) snprintf(path, sizeof path, "/tmp/clpt-fuzz-texture-%d.img", (int)getpid());
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    int written = fwrite(data, 1, size, f) == size;
    if (fclose(f) != 0 || !written) return 0;
    /* one input's work stays small: images above a million pixels but within the limit
     * are legal and only slow (a 54-byte BMP header can ask for 8192x8192); those above
     * the limit still go through, to be refused */
    int w, h, c;
    uint64_t pixels = stbi_info(path, &w, &h, &c) ? (uint64_t)(unsigned)w * (unsigned)h : 0;
    if (exr_size(path, &w, &h) && w > 0 && h > 0) pixels = (uint64_t)(unsigned)w * (unsigned)h;
    if (pixels > (1u << 20) && pixels <= CLPT_MAX_TEXTURE_PIXELS) {
        unlink(path);
        return 0;
    }
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    uint index = NO_INDEX;
    Status st = texture_load_image(&s, NULL, path, (int)(size & 1), 0, &index, &err);
    if (st) {
        FUZZ_ASSERT(st == ST_INPUT && err.msg[0]);
    } else {
        FUZZ_ASSERT(index < s.n_textures);
        const Texture *t = &s.textures[index];
        uint per_texel = (t->flags & TEX_FLOAT) ? 3u : 1u;
        FUZZ_ASSERT(t->width > 0 && t->height > 0);
        FUZZ_ASSERT((uint64_t)t->width * t->height <= CLPT_MAX_TEXTURE_PIXELS);
        FUZZ_ASSERT((uint64_t)t->offset + (uint64_t)t->width * t->height * per_texel <= s.n_texels);
    }
    scene_free(&s);
    error_clear(&err);
    unlink(path);
    return 0;
}
