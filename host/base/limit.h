/*
 * limit.h — the largest inputs clpt accepts, checked before anything is allocated for
 * them, so that a corrupt header or an absurd setting gives a clear message instead of
 * an out-of-memory kill, an overflowed size or hours of work. Every parser and option
 * uses these constants and helpers; docs/hardening.md lists them with their reasons.
 */
#ifndef CLPT_LIMIT_H
#define CLPT_LIMIT_H

#include <stddef.h>
#include <stdint.h>

#include "base/status.h"

/* Image width and height, each. */
#define CLPT_MAX_IMAGE_SIDE 16384
/* Width or height an `image` block may ask for. The size rendered is checked against
 * CLPT_MAX_IMAGE_SIDE and CLPT_MAX_PIXELS after --width/--height, which may make a large
 * scene image small; this bound only keeps absurd numbers out of the parse (nothing is
 * allocated from the scene's size before the final check). */
#define CLPT_MAX_SCENE_IMAGE_SIDE 1048576
/* Pixels in an image (16384 x 8192): the host film alone is 24 bytes a pixel, and every
 * device and scheduling worker holds another film of the same size. */
#define CLPT_MAX_PIXELS (16384u * 8192u)
/* Samples per pixel. The film adds samples in 64-bit fixed point with 24 fractional
 * bits, each clamped to 65536 (2^16): 2^20 samples stay below 2^60, far from overflow. */
#define CLPT_MAX_SPP 1000000
/* Longest path, in bounces after the camera ray. */
#define CLPT_MAX_DEPTH 1024
/* Continuations per camera sample from its first hit (first-hit splitting): a path's
 * sample index is sample x split + branch (kernels/sample/rng.h), below 2^32 with CLPT_MAX_SPP
 * and the adaptive passes' samples. */
#define CLPT_MAX_SPLIT 64
/* Nesting of scene `include`s (a file including itself stops here). */
#define CLPT_MAX_INCLUDE_DEPTH 16
/* Nesting of the classic format's Group and Transform blocks, which are read
 * recursively: each level takes a few hundred bytes of stack, and 40,000 levels
 * overflowed it. Course scenes nest a handful deep. */
#define CLPT_MAX_NESTING 256
/* Texels of one texture image (8192 x 8192): decoded to 4 bytes a texel (12 for HDR)
 * and copied once more into the scene. Compressed images (PNG, JPEG) can claim this
 * from a few bytes, so the size is read from the header before decoding. */
#define CLPT_MAX_TEXTURE_PIXELS (8192u * 8192u)
/* Triangles one scene may make from a few numbers in its file: the classic format's
 * surfaces of revolution whose axis a transform tilts (3,072 triangles a profile
 * segment; its squashed spheres, once 9,024 triangles each, so that a 65 KB file of
 * 1,000 took 4.6 GB, are exact ellipsoids now); pbrt's loopsubdiv levels (a 4 KB file
 * asked for 33 million) and emitting ellipsoids. */
#define CLPT_MAX_TESSELLATED_TRIANGLES (1u << 20)
/* pbrt scenes may tessellate this many more triangles per byte of input they read: a
 * real mesh written as text takes 20 or more bytes a triangle, so its loopsubdiv to
 * level 3 (64 triangles of one, pbrt's default) fits whatever its size, where a 4 KB
 * file stays near CLPT_MAX_TESSELLATED_TRIANGLES. */
#define CLPT_TESSELLATED_PER_INPUT_BYTE 64u
/* World instances a scene may make through nested objects (docs/instancing.md): each
 * level multiplies, so a 3 KB file of eight nested objects asked for ten million
 * instances, 1.2 GB of records (fuzz_scene, 2026-11-28). A world instance written out
 * takes 20 or more bytes of text, so a flat scene is bounded by its size already;
 * what nesting places may reach 2^20 instances (about 130 MB on the devices) and 64
 * more a byte of the load's text, up to SCENE_MAX_INSTANCES (scene/instance.h). */
#define CLPT_MAX_NESTED_INSTANCES (1u << 20)
#define CLPT_NESTED_INSTANCES_PER_INPUT_BYTE 64u
/* Any one input file: it is read whole into memory. */
#define CLPT_MAX_FILE_BYTES ((uint64_t)4 << 30)
/* The text one scene load reads, all its files together (includes, meshes, MTL files,
 * glTF buffers; a .gz file counted inflated): a 510 KB .pbrt.gz inflates to 536 MB, and
 * a file that includes it many times (or files that include each other, nested) made
 * that hundreds of times over. pbrt-v4's largest scenes are a few GB of text; the
 * environment variable CLPT_MAX_LOAD_BYTES (io/lexer.h) sets another budget. */
#define CLPT_MAX_LOAD_BYTES ((uint64_t)16 << 30)

/* Stringified, for messages built at compile time ("an integer in 1.." CLPT_STR(...)). */
#define CLPT_STR_(x) #x
#define CLPT_STR(x) CLPT_STR_(x)

/* For readers of formats that announce counts before the data (PLY's `element vertex
 * N`, a binary header's triangle count): fails with ST_INPUT unless `count` items of at
 * least `min_bytes` each fit in the `bytes_left` bytes that remain of the file, so that
 * no array is sized from a count the file cannot hold. `where` locates the count
 * ("file.ply:3:16"), `what` names the items ("vertices"). The message reads
 *   "<where>: the header declares <count> <what>, but the <bytes_left> bytes after it
 *    hold at most <max> (at least <min_bytes> bytes each): the file is truncated or
 *    the count is wrong" */
Status limit_count(const char *where, const char *what, uint64_t count, uint64_t min_bytes,
                   uint64_t bytes_left, Error *err);

/* `count` elements of `size` bytes each, as a byte count: 0 and *bytes set when the
 * product fits in size_t, -1 when it overflows. */
int limit_bytes(uint64_t count, uint64_t size, size_t *bytes);

/* Fails with `status` when width x height exceeds CLPT_MAX_PIXELS (each side is
 * checked where it is read); `where` starts the message ("scene.scene:3:9", or the
 * flags that set the size). */
Status limit_pixels(uint64_t width, uint64_t height, Status status, const char *where, Error *err);

/* Whether a file of `bytes` may be read; ST_INPUT naming `path` and the limit if not. */
Status limit_file_size(const char *path, uint64_t bytes, Error *err);

#endif /* CLPT_LIMIT_H */
