/*
 * texel_pack.h — float textures stored as one RGBE word a texel wherever that keeps every
 * value (TEX_RGBE, kernels/types.h).
 *
 * A Radiance .hdr image is 8-bit mantissas sharing a power of two per pixel, and
 * stb_image hands it over as three floats a texel: 12 bytes holding 4 bytes' worth. An
 * environment map is read at random directions from every path vertex, so its bytes are
 * cache misses: a 1024 x 512 map is 6 MB of floats and 2 MB of RGBE words. The packing
 * is exact (each word decodes, in rgbe_decode, to the very floats it replaced), so images
 * do not change; a texture with any value RGBE cannot hold (an EXR's halves, a negative
 * or non-finite value, a resampled cube map) stays as floats.
 */
#ifndef CLPT_TEXEL_PACK_H
#define CLPT_TEXEL_PACK_H

#include "scene/scene.h"

/* The RGBE word whose rgbe_decode is exactly (c[0], c[1], c[2]) in *word and 1, or 0
 * when there is none: the shared exponent is that of the largest component, with the
 * largest mantissa in [128, 255] (as Radiance writes), and every component must then be
 * an integer mantissa. Zero is written with exponent 10, as every word is (see
 * rgbe_decode). */
int rgbe_encode_exact(const float c[3], uint *word);

/* Repacks the scene's texels: every float image texture whose texels all have an exact
 * RGBE word gets TEX_RGBE and a third of the words; the others are copied as they were.
 * Textures that share texels keep sharing them. Run once the scene is loaded (the host
 * reads float texels while loading, e.g. to build the environment map's distribution);
 * render_scene_prepare does. Textures already packed are left as they are. */
Status scene_pack_texels(Scene *s, Error *err);

#endif /* CLPT_TEXEL_PACK_H */
