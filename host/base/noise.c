/*
 * noise.c — Perlin's gradient noise (noise.h).
 */
#include "base/noise.h"

#include <math.h>

/* Perlin's permutation of 0..255 (his 2002 reference implementation), repeated once so
 * that perm[perm[x] + y] needs no wrap. */
static const unsigned char perm[512] = {
#define PERLIN_PERM                                                                                              \
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69, 142, 8, 99, 37,  \
    240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177,   \
    33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146,   \
    158, 231, 83, 111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25,  \
    63, 161, 1, 216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, \
    109, 198, 173, 186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206, \
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153,   \
    101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, \
    97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49,    \
    192, 214, 31, 181, 199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93,    \
    222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180
    PERLIN_PERM, PERLIN_PERM
#undef PERLIN_PERM
};

/* The dot product of the offset (dx, dy, dz) with one of 12 edge directions of a cube
 * (4 repeated), picked by hashing the lattice point; pbrt-v4's choice of the two
 * components for h = 12, 13. */
static float grad(int x, int y, int z, float dx, float dy, float dz)
{
    int h = perm[perm[perm[x] + y] + z] & 15;
    float u = (h < 8 || h == 12 || h == 13) ? dx : dy;
    float v = (h < 4 || h == 12 || h == 13) ? dy : dz;
    return ((h & 1) ? -u : u) + ((h & 2) ? -v : v);
}

static float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
static float lerp(float t, float a, float b) { return (1.0f - t) * a + t * b; }

float noise3(float x, float y, float z)
{
    /* large coordinates would overflow the lattice's int (below 2^30 fmodf changes
     * nothing, and costs more than the rest of the lookup) */
    const float wrap = (float)(1 << 30);
    if (!(fabsf(x) < wrap)) x = fmodf(x, wrap);
    if (!(fabsf(y) < wrap)) y = fmodf(y, wrap);
    if (!(fabsf(z) < wrap)) z = fmodf(z, wrap);
    float fx = floorf(x), fy = floorf(y), fz = floorf(z);
    float dx = x - fx, dy = y - fy, dz = z - fz;
    int ix = (int)fx & 255, iy = (int)fy & 255, iz = (int)fz & 255;
    float w000 = grad(ix, iy, iz, dx, dy, dz), w100 = grad(ix + 1, iy, iz, dx - 1, dy, dz);
    float w010 = grad(ix, iy + 1, iz, dx, dy - 1, dz), w110 = grad(ix + 1, iy + 1, iz, dx - 1, dy - 1, dz);
    float w001 = grad(ix, iy, iz + 1, dx, dy, dz - 1), w101 = grad(ix + 1, iy, iz + 1, dx - 1, dy, dz - 1);
    float w011 = grad(ix, iy + 1, iz + 1, dx, dy - 1, dz - 1);
    float w111 = grad(ix + 1, iy + 1, iz + 1, dx - 1, dy - 1, dz - 1);
    float wx = fade(dx), wy = fade(dy), wz = fade(dz);
    float y0 = lerp(wy, lerp(wx, w000, w100), lerp(wx, w010, w110));
    float y1 = lerp(wy, lerp(wx, w001, w101), lerp(wx, w011, w111));
    return lerp(wz, y0, y1);
}

void noise3_gradient(float x, float y, float z, float out[3])
{
    const float h = 0.01f;
    float n = noise3(x, y, z);
    out[0] = (noise3(x + h, y, z) - n) / h;
    out[1] = (noise3(x, y + h, z) - n) / h;
    out[2] = (noise3(x, y, z + h) - n) / h;
}
