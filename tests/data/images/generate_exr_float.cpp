/*
 * generate_exr_float.cpp — writes the float EXR files of the tests that OpenEXRCore 3.1
 * (Debian 12) cannot write: DWA compression (not in its C encoder), ripmaps (it numbers
 * their chunks wrongly) and tiles that ZIP does not shrink (it stores them garbled). The
 * OpenEXR C++ library writes them; tests/test_exr.c reads them and they seed
 * fuzz_texture. Every file is float R, G, B of the test image of test_exr.c
 * (layout_value: level l of a tiled file adds 1000 l; pixel (1, 0)'s G is 70000, past
 * a half's range). Run from this folder; the output is committed:
 *     g++ -I/usr/include/OpenEXR -I/usr/include/Imath -o /tmp/generate_exr_float \
 *         generate_exr_float.cpp -lOpenEXR && /tmp/generate_exr_float
 */
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <vector>

using namespace Imf;

static float layout_value(int x, int y, int k, int level)
{
    if (x == 1 && y == 0 && k == 1) return 70000.0f;
    return (float)((x * 131 + y * 71 + k * 37) % 997) / 7.0f - 20.0f + 1000.0f * (float)level;
}

static std::vector<float> pixels(int w, int h, int level)
{
    std::vector<float> px((size_t)w * h * 3);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = 0; k < 3; k++) px[3 * ((size_t)y * w + x) + k] = layout_value(x, y, k, level);
    return px;
}

static Header header(int w, int h, Compression comp)
{
    Header hd(w, h);
    hd.compression() = comp;
    for (const char *n : { "R", "G", "B" }) hd.channels().insert(n, Channel(FLOAT));
    return hd;
}

static FrameBuffer frame(std::vector<float> &px, int w)
{
    FrameBuffer fb;
    const char *names[3] = { "R", "G", "B" };
    for (int k = 0; k < 3; k++) fb.insert(names[k], Slice(FLOAT, (char *)(px.data() + k), 12, 12 * (size_t)w));
    return fb;
}

static void write_scanline(const char *name, int w, int h, Compression comp)
{
    OutputFile f(name, header(w, h, comp));
    std::vector<float> px = pixels(w, h, 0);
    f.setFrameBuffer(frame(px, w));
    f.writePixels(h);
}

static void write_tiled(const char *name, int w, int h, int tile, LevelMode mode, Compression comp)
{
    Header hd = header(w, h, comp);
    hd.setTileDescription(TileDescription(tile, tile, mode, ROUND_DOWN));
    TiledOutputFile f(name, hd);
    for (int ly = 0; ly < f.numYLevels(); ly++)
        for (int lx = 0; lx < f.numXLevels(); lx++) {
            if (mode != RIPMAP_LEVELS && lx != ly) continue;
            int lw = f.levelWidth(lx), lh = f.levelHeight(ly);
            std::vector<float> px = pixels(lw, lh, lx + ly);
            f.setFrameBuffer(frame(px, lw));   /* a level's pixels start at its (0, 0) */
            f.writeTiles(0, f.numXTiles(lx) - 1, 0, f.numYTiles(ly) - 1, lx, ly);
        }
}

int main()
{
    write_scanline("float-dwab.exr", 40, 24, DWAB_COMPRESSION);
    write_tiled("float-tiled-dwaa.exr", 37, 21, 16, MIPMAP_LEVELS, DWAA_COMPRESSION);
    write_tiled("float-ripmap.exr", 19, 11, 4, RIPMAP_LEVELS, PIZ_COMPRESSION);
    write_tiled("float-tiled-zip.exr", 19, 11, 5, ONE_LEVEL, ZIP_COMPRESSION);
    return 0;
}
