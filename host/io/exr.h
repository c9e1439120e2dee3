/*
 * exr.h — OpenEXR images (libopenexr-dev): reading an image's colour as linear RGB
 * floats (environment maps, textures), scanline or tiled, whatever the compression
 * (DWAA/DWAB included). OpenEXRCore's C API reads and checks the header and decodes
 * float colour; DWA-compressed float colour comes through the C++ library
 * (exr_imf.h), colour in halves through its C interface to RgbaInputFile.
 */
#ifndef CLPT_EXR_H
#define CLPT_EXR_H

#include <stddef.h>
#include <stdint.h>

#include "base/status.h"

/* Whether the first bytes of a file (n of them) are the OpenEXR magic number. */
int exr_is_exr(const unsigned char *head, size_t n);

/* The size of the EXR file's data window, from its header alone (OpenEXRCore); 0 when
 * the header cannot be read. */
int exr_size(const char *path, int *width, int *height);

/* Reads the EXR file at `path` as width x height RGB floats (its data window), rows top
 * to bottom (*rgb, freed with free): 32-bit float channels at full precision, halves
 * exactly, scanline or tiled (a mipmapped or ripmapped image: level (0, 0), the full
 * resolution); luminance/chroma images as halves. DWAA/DWAB code R, G, B and Y as
 * halves whatever the channel type (OpenEXR's DWA rules): such floats come back as
 * OpenEXR decodes them. The colour is the channels R, G and B (a missing one is 0), or
 * Y (grey) when the image has none of them (luminance/chroma images are converted to
 * RGB); other channels are ignored. The data window's size, and a chunk's or a tile's
 * decoded size, are checked before anything is allocated for the pixels. Errors
 * (ST_INPUT, naming the file): "not an EXR file OpenEXR can read (REASON)", a deep
 * image, no colour channel, an image larger than max_pixels, chunks or tiles larger
 * than clpt decodes, a header attribute larger than the rest of the file (or a preview
 * image larger than its attribute), a pixel that is not a finite number; ST_IO "cannot
 * open 'PATH': REASON". */
Status exr_read_rgb(const char *path, uint64_t max_pixels, float **rgb, int *width, int *height, Error *err);

/* One channel of an image to write: its EXR name and its values, `stride` floats apart,
 * rows top to bottom. `linear` marks data channels (normals, depth); colour channels
 * are marked perceptually logarithmic, which lossy compressors look at. `float32`
 * writes this channel as 32-bit floats whatever exr_encode's own choice. */
typedef struct {
    const char *name;
    const float *data;
    unsigned stride;
    int linear;
    int float32;
} ExrChannel;

/* Encodes a width x height image of n channels as a single-part scanline OpenEXR file
 * in memory (OpenEXRCore; ZIP compression, lossless), each channel 16-bit half or, with
 * `float32` (or the channel's own), 32-bit float: *bytes (freed with free) of *size bytes. The library sorts the
 * channels by name, as the format asks. ST_INTERNAL, with OpenEXR's reason, on failure
 * (out of memory). */
Status exr_encode(const ExrChannel *ch, size_t n, unsigned width, unsigned height, int float32, unsigned char **bytes,
                  size_t *size, Error *err);

#endif /* CLPT_EXR_H */
