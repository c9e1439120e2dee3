/*
 * texture.h — textures for the scene (kernels/material/texture.h evaluates them): image files
 * read through Debian's stb_image (PNG, JPEG, BMP, TGA, GIF, PSD, PNM and Radiance HDR)
 * and OpenEXR (any compression; host/io/exr.h), and checkerboards.
 *
 * An image's texels are stored once per (file, colour encoding) however many textures
 * use it: each texture record only adds its own wrap mode and (u, v) transform.
 */
#ifndef CLPT_TEXTURE_H_HOST
#define CLPT_TEXTURE_H_HOST

#include "scene/scene.h"

/* A checkerboard of colours c0 and c1 with cells 1/scale wide: in 3D at the hit point
 * when `solid`, else on the surface's (u, v). */
Texture texture_make_checker(vec3 c0, vec3 c1, float scale, int solid);

/* Sets the map from (u, v) (or the 3D point of a solid texture) to texture space to
 * scale first, then offset: (s_u u + o_u, s_v v + o_v) (the z row, for solid
 * textures, scales by s_u). */
void texture_set_scale_offset(Texture *t, float su, float sv, float ou, float ov);

/* Sets the full 3x4 row-major map to texture space. */
void texture_set_matrix(Texture *t, const float m[12]);

/* The largest entry a texture's map may have: past 2^24 a coordinate has no fraction
 * left to choose a texel by (every point reads the same one), and a scale beyond
 * float's range is infinite, whose lookups are NaN. */
#define TEXTURE_MAX_MAP_ENTRY 16777216.0f

/* Fails with ST_INPUT unless every entry of t's map is finite and at most
 * TEXTURE_MAX_MAP_ENTRY in size: "the texture's map has WHAT ENTRY (row R, column C);
 * clpt takes finite entries of at most 16777216 in size", which the caller prefixes
 * with where the map was given. */
Status texture_check_map(const Texture *t, Error *err);

/* Reads the image file at `path` (or reuses the texels of an earlier read of it with
 * the same encoding) and adds an image texture for it to the scene, with the given name
 * (NULL: anonymous). 8-bit images are sRGB-encoded colours unless `linear`; HDR images
 * are linear floats. `clamp` clamps coordinates at the edges instead of repeating.
 * Errors: ST_IO "cannot open 'path': reason" when the file cannot be read, ST_INPUT
 * "'path': not an image stb_image can read (reason)" when it cannot be decoded. */
Status texture_load_image(Scene *s, const char *name, const char *path, int linear, int clamp,
                          uint *index, Error *err);

/* Reads the image file at `path` as linear RGB floats (*rgb: width x height x 3, top row
 * first, malloc'ed), 8-bit images decoded from sRGB unless `linear`; nothing is added to
 * a scene. The errors of texture_load_image. */
Status texture_read_rgb(const char *path, int linear, float **rgb, int *width, int *height, Error *err);

/* The same for an image already in memory (a glTF file's embedded PNG or JPEG; other
 * formats are refused), named `source` in messages; its texels are not shared. */
Status texture_load_image_memory(Scene *s, const char *name, const char *source, const unsigned char *data,
                                 size_t len, int linear, uint *index, Error *err);

/* Reads the six faces of a cube map from the folder `dir` (the MIT 6.837 course's
 * CubeMap: left, right, up, down, front and back, each NAME.png or else NAME.bmp) as
 * linear, clamped image textures with consecutive indices, the first (left) in *first,
 * in the order of enum CubeFace. Errors: ST_IO "cannot open 'DIR/NAME.png' (nor
 * 'DIR/NAME.bmp'): the cube map's NAME face" for a missing face, ST_IO "'DIR': not a
 * folder ..." when dir is not one, and texture_load_image's for a face that is there. */
Status texture_load_cubemap(Scene *s, const char *dir, uint *first, Error *err);

#endif /* CLPT_TEXTURE_H_HOST */
