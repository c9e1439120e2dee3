/* exr_imf.cpp — float pixels through the OpenEXR C++ library (see exr_imf.h). */
#include "io/exr_imf.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

int exr_imf_read_float(const char *path, const char *const names[3], int x0, int y0, int w, int h, float *rgb,
                       char *why, size_t why_size)
{
    try {
        Imf::InputFile in(path);
        const Imath::Box2i &dw = in.header().dataWindow();
        if (dw.min.x != x0 || dw.min.y != y0 || (int64_t)dw.max.x - dw.min.x + 1 != w ||
            (int64_t)dw.max.y - dw.min.y + 1 != h) {
            std::snprintf(why, why_size, "the image changed while it was read");
            return 0;
        }
        /* The library addresses a slice by absolute pixel coordinates: its base is where
         * pixel (0, 0) would be, outside rgb for a window off the origin (and, far from
         * it, outside the address space), so it is computed as an integer, modulo 2^64
         * as the library's own offsets are (exr.c's exr_frame_base, for the same
         * reason). */
        const size_t pixel = 3 * sizeof(float), line = (size_t)w * pixel;
        uintptr_t origin = (uintptr_t)(intptr_t)x0 * pixel + (uintptr_t)(intptr_t)y0 * line;
        Imf::FrameBuffer fb;
        for (int k = 0; k < 3; k++) {
            if (!names[k] || fb.findSlice(names[k])) continue;
            char *base = reinterpret_cast<char *>(reinterpret_cast<uintptr_t>(rgb + k) - origin);
            fb.insert(names[k], Imf::Slice(Imf::FLOAT, base, pixel, line));
        }
        in.setFrameBuffer(fb);
        in.readPixels(dw.min.y, dw.max.y);
        return 1;
    } catch (const std::exception &e) {
        std::snprintf(why, why_size, "%s", e.what());
    } catch (...) {
        std::snprintf(why, why_size, "an unknown error in the OpenEXR library");
    }
    return 0;
}
