/*
 * exr_imf.h — an EXR image's colour channels as 32-bit floats through the OpenEXR C++
 * library's InputFile (exr_imf.cpp), for the images OpenEXRCore cannot decode: Debian
 * 12's OpenEXR 3.1 decompresses DWAA/DWAB only in the C++ library ("DWA/B decompression
 * not yet implemented in C"), and its C interface (ImfCRgbaFile.h) gives halves only.
 * The one C++ file of clpt; exr.c checks the header and the sizes first.
 */
#ifndef CLPT_EXR_IMF_H
#define CLPT_EXR_IMF_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Decodes the channels names[0..2] (NULL: not read) of the EXR file at `path`, whose
 * data window starts at (x0, y0) and is w x h pixels, into rgb (w x h x 3 floats, rows
 * top to bottom, zeroed by the caller) as 32-bit floats: float channels bit for bit,
 * halves exactly. A tiled image gives its level (0, 0), the full resolution. A name
 * given twice is decoded once, into the first component it names. Returns 1, or 0 with
 * the library's reason in why[why_size]; never throws. */
int exr_imf_read_float(const char *path, const char *const names[3], int x0, int y0, int w, int h, float *rgb,
                       char *why, size_t why_size);

#ifdef __cplusplus
}
#endif

#endif /* CLPT_EXR_IMF_H */
