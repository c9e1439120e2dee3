/*
 * srgb_table.c — writes kernels/material/srgb_table.h: the linear value of each 8-bit
 * sRGB code, k_srgb_to_linear(i / 255) as the kernels compute it (kernels/util/kmath.h),
 * printed exactly (hex floats), so that texel_fetch reads the very bits it computed
 * before, with no pow per channel. Run from the repository root:
 *   cc -std=c11 -Ikernels -o build/srgb_table tools/srgb_table.c -lm && build/srgb_table > kernels/material/srgb_table.h
 * tests/test_texture.c checks the table against the function, bit for bit.
 */
#include <stdio.h>

#include "util/kmath.h"

int main(void)
{
    printf("/* srgb_table.h — written by tools/srgb_table.c; do not edit. The linear value of\n"
           " * each 8-bit sRGB code i: k_srgb_to_linear(i / 255.0f), bit for bit (texel_fetch). */\n"
           "#ifndef CLPT_SRGB_TABLE_H\n#define CLPT_SRGB_TABLE_H\n\n"
           "static CONSTANT float srgb_to_linear_table[256] = {\n");
    for (unsigned i = 0; i < 256; i++) {
        float v = k_srgb_to_linear((float)i / 255.0f);
        printf("%s%af%s", i % 4 == 0 ? "    " : "", (double)v, i == 255 ? "\n" : (i % 4 == 3 ? ",\n" : ", "));
    }
    printf("};\n\n#endif /* CLPT_SRGB_TABLE_H */\n");
    return 0;
}
