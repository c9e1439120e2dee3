/*
 * generate_exr.c — writes the small EXR files of the tests (tiny.exr and tiny-dwab.exr
 * here, which seed fuzz_texture, and the source of tests/data/bad/nan.exr) through
 * OpenEXR's C interface. Run from this folder; the output is committed:
 *     cc -I/usr/include/OpenEXR -o /tmp/generate_exr generate_exr.c -lOpenEXR -lm && /tmp/generate_exr
 * tests/data/bad/truncated.exr is big.exr's first 3000 bytes; huge-claim.exr is tiny.exr
 * with its dataWindow rewritten to 0 0 8999 8999; magic-only.exr its first 4 bytes.
 */
#include <ImfCRgbaFile.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
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
int main(void)
{
    write_exr("../bad/nan.exr", 4, 2, IMF_NO_COMPRESSION, 1);
    write_exr("tiny.exr", 8, 4, IMF_ZIP_COMPRESSION, -1);
    write_exr("/tmp/big.exr", 64, 64, IMF_PIZ_COMPRESSION, -1);   /* for truncated.exr */
    write_exr("tiny-dwab.exr", 32, 32, IMF_DWAB_COMPRESSION, -1);
    return 0;
}
