/*
 * generate_exr.c — writes the small EXR files of the tests (tiny.exr and tiny-dwab.exr
 * here, which seed fuzz_texture, and the source of tests/data/bad/nan.exr) through
 * OpenEXR's C interface. Run from this folder; the output is committed:
 *     cc -I/usr/include/OpenEXR -o /tmp/generate_exr generate_exr.c -lOpenEXR -lm && /tmp/generate_exr
 * tests/data/bad/truncated.exr is big.exr's first 3000 bytes; huge-claim.exr is tiny.exr
 * with its dataWindow rewritten to 0 0 8999 8999; magic-only.exr its first 4 bytes.
 * tiny-tiled-mipmap.exr is a tiled, mipmapped half image; the tests/data/bad/tiles-*.exr
 * are it, or float-tiled-zip.exr (generate_exr_float.cpp: run that first), with tile
 * sizes that lie, written here too. generate_exr_float.cpp writes the float files.
 */
#include <ImfCRgbaFile.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
static void write_exr(const char *name, int w, int h, int comp, float nan_at)
{
    ImfHeader *hd = ImfNewHeader();
    ImfHeaderSetDataWindow(hd, 0, 0, w - 1, h - 1);
    ImfHeaderSetDisplayWindow(hd, 0, 0, w - 1, h - 1);
    ImfHeaderSetCompression(hd, comp);
    ImfOutputFile *o = ImfOpenOutputFile(name, hd, IMF_WRITE_RGBA);
    ImfRgba *px = calloc(w * h, sizeof *px);
    for (int i = 0; i < w * h; i++) {
        ImfFloatToHalf(0.25f + (i % 7) * 0.125f, &px[i].r);
        ImfFloatToHalf(0.5f, &px[i].g);
        ImfFloatToHalf((float)(i % 5), &px[i].b);
        ImfFloatToHalf(1.0f, &px[i].a);
    }
    if (nan_at >= 0) ImfFloatToHalf(NAN, &px[(int)nan_at].g);
    ImfOutputSetFrameBuffer(o, px, 1, w);
    ImfOutputWritePixels(o, h);
    ImfCloseOutputFile(o);
    ImfDeleteHeader(hd);
    free(px);
}
/* A tiled half RGBA image, mipmapped (levels rounded down), tiles of t x t pixels:
 * level l holds the pattern of write_exr plus l. */
static void write_tiled_mipmap(const char *name, int w, int h, int t)
{
    ImfHeader *hd = ImfNewHeader();
    ImfHeaderSetDataWindow(hd, 0, 0, w - 1, h - 1);
    ImfHeaderSetDisplayWindow(hd, 0, 0, w - 1, h - 1);
    ImfHeaderSetCompression(hd, IMF_ZIP_COMPRESSION);
    ImfTiledOutputFile *o = ImfOpenTiledOutputFile(name, hd, IMF_WRITE_RGBA, t, t, IMF_MIPMAP_LEVELS, IMF_ROUND_DOWN);
    int top = w > h ? w : h, levels = 1;
    while (top >> levels) levels++;
    for (int l = 0; l < levels; l++) {
        int lw = w >> l > 0 ? w >> l : 1, lh = h >> l > 0 ? h >> l : 1;
        ImfRgba *px = calloc((size_t)lw * lh, sizeof *px);
        for (int i = 0; i < lw * lh; i++) {
            ImfFloatToHalf(0.25f + (i % 7) * 0.125f + l, &px[i].r);
            ImfFloatToHalf(0.5f + l, &px[i].g);
            ImfFloatToHalf((float)(i % 5) + l, &px[i].b);
            ImfFloatToHalf(1.0f, &px[i].a);
        }
        ImfTiledOutputSetFrameBuffer(o, px, 1, lw);
        ImfTiledOutputWriteTiles(o, 0, (lw + t - 1) / t - 1, 0, (lh + t - 1) / t - 1, l, l);
        free(px);
    }
    ImfCloseTiledOutputFile(o);
    ImfDeleteHeader(hd);
}

/* A copy of `from` whose tile description says x by y pixels. */
static void write_tiles_lie(const char *from, const char *to, unsigned x, unsigned y)
{
    static unsigned char b[1 << 16];
    FILE *f = fopen(from, "rb");
    size_t n = f ? fread(b, 1, sizeof b, f) : 0;
    if (f) fclose(f);
    static const char key[] = "tiles\0tiledesc\0";
    for (size_t i = 0; i + sizeof key + 12 < n; i++)
        if (memcmp(b + i, key, sizeof key - 1) == 0) {
            unsigned char *v = b + i + sizeof key - 1 + 4;   /* after the name, the type, the size */
            for (int k = 0; k < 4; k++) {
                v[k] = (unsigned char)(x >> 8 * k);
                v[4 + k] = (unsigned char)(y >> 8 * k);
            }
            f = fopen(to, "wb");
            fwrite(b, 1, n, f);
            fclose(f);
            return;
        }
}

int main(void)
{
    write_exr("../bad/nan.exr", 4, 2, IMF_NO_COMPRESSION, 1);
    write_exr("tiny.exr", 8, 4, IMF_ZIP_COMPRESSION, -1);
    write_exr("/tmp/big.exr", 64, 64, IMF_PIZ_COMPRESSION, -1);   /* for truncated.exr */
    write_exr("tiny-dwab.exr", 32, 32, IMF_DWAB_COMPRESSION, -1);
    write_tiled_mipmap("tiny-tiled-mipmap.exr", 19, 11, 4);
    write_tiles_lie("tiny-tiled-mipmap.exr", "../bad/tiles-huge.exr", 65536, 65536);
    write_tiles_lie("tiny-tiled-mipmap.exr", "../bad/tiles-smaller-half.exr", 2, 2);
    write_tiles_lie("float-tiled-zip.exr", "../bad/tiles-smaller.exr", 4, 4);
    write_tiles_lie("float-tiled-zip.exr", "../bad/tiles-larger.exr", 8, 8);
    write_tiles_lie("float-tiled-zip.exr", "../bad/tiles-zero.exr", 0, 5);
    write_tiles_lie("float-tiled-zip.exr", "../bad/tiles-tall.exr", 1, 1u << 22);
    return 0;
}
