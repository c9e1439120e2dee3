/*
 * bytes.h — fixed-width integers in a byte buffer, in a stated byte order, whatever the
 * host's: the file formats clpt reads and writes (checkpoints, the kernel cache, EXR,
 * GLB, image headers) store little-endian words, a few image headers big-endian ones.
 *
 * `p` needs only byte alignment; reads never look past the `n` bytes they are asked for.
 */
#ifndef CLPT_BYTES_H
#define CLPT_BYTES_H

#include <stdint.h>

/* The `n`-byte (1..8) little-endian unsigned integer at p. */
static inline uint64_t bytes_get_le(const unsigned char *p, int n)
{
    uint64_t v = 0;
    for (int i = 0; i < n; i++) v |= (uint64_t)p[i] << (8 * i);
    return v;
}

/* Stores the low `n` bytes (1..8) of v at p, least significant first. */
static inline void bytes_put_le(unsigned char *p, uint64_t v, int n)
{
    for (int i = 0; i < n; i++) p[i] = (unsigned char)(v >> (8 * i));
}

static inline uint16_t bytes_get_le16(const unsigned char *p) { return (uint16_t)bytes_get_le(p, 2); }
static inline uint32_t bytes_get_le32(const unsigned char *p) { return (uint32_t)bytes_get_le(p, 4); }
static inline uint64_t bytes_get_le64(const unsigned char *p) { return bytes_get_le(p, 8); }
static inline void bytes_put_le32(unsigned char *p, uint32_t v) { bytes_put_le(p, v, 4); }
static inline void bytes_put_le64(unsigned char *p, uint64_t v) { bytes_put_le(p, v, 8); }

/* The 2- and 4-byte big-endian unsigned integers at p, and a 4-byte store. */
static inline uint16_t bytes_get_be16(const unsigned char *p) { return (uint16_t)(p[0] << 8 | p[1]); }
static inline uint32_t bytes_get_be32(const unsigned char *p)
{
    return (uint32_t)bytes_get_be16(p) << 16 | bytes_get_be16(p + 2);
}
static inline void bytes_put_be32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (24 - 8 * i));
}

#endif /* CLPT_BYTES_H */
