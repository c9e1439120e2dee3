/*
 * sha256.h — SHA-256 (FIPS 180-4), for content addressing.
 *
 * The kernel cache (ocl_program.c) names each compiled binary by the SHA-256 of
 * everything that determines it, and checks each stored payload against its SHA-256.
 * A cryptographic hash is used rather than FNV or a CRC because a collision between two
 * keys would silently run the wrong kernel binary; at a few hundred MB/s it costs
 * nothing next to a kernel build.
 *
 *     Sha256 h; sha256_init(&h); sha256_update(&h, data, n); sha256_final(&h, digest);
 */
#ifndef CLPT_SHA256_H
#define CLPT_SHA256_H

#include <stddef.h>
#include <stdint.h>

#define SHA256_DIGEST_SIZE 32

typedef struct {
    uint32_t state[8];
    uint64_t total;          /* bytes hashed so far */
    unsigned char block[64]; /* partial block, `total % 64` bytes used */
} Sha256;

void sha256_init(Sha256 *h);
void sha256_update(Sha256 *h, const void *data, size_t n);
/* Writes the 32-byte digest; `h` must be re-initialised before further use. */
void sha256_final(Sha256 *h, unsigned char digest[SHA256_DIGEST_SIZE]);
/* Hashes one buffer in one call. */
void sha256(const void *data, size_t n, unsigned char digest[SHA256_DIGEST_SIZE]);
/* Writes the digest as 64 lowercase hex digits and a NUL (65 bytes). */
void sha256_hex(const unsigned char digest[SHA256_DIGEST_SIZE], char hex[65]);

#endif /* CLPT_SHA256_H */
