/* scalar_paths.c — the choice between the scalar device's builds of its per-sample code
 * (scalar_paths.h). */
#include "device/scalar_paths.h"

ScalarIsa scalar_paths_isa_usable(void)
{
#if SCALAR_PATHS_HAVE_AVX2
    /* gcc's and clang's checks also ask the operating system whether it saves the
     * 256-bit registers (XGETBV), and for AVX-512 the 512-bit and mask registers, which
     * the instructions need as much as the processor. x86-64-v4 is v3 (AVX2, FMA, BMI1
     * and 2, LZCNT, MOVBE) and AVX-512 F, VL, BW, DQ and CD; asked are the five, AVX2,
     * FMA and BMI2: every processor with those has the rest of v3. */
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("avx2")) return SCALAR_ISA_BASE;
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
        __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
        __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2"))
        return SCALAR_ISA_AVX512;
    return SCALAR_ISA_AVX2;
#else
    return SCALAR_ISA_BASE;
#endif
}

const char *scalar_paths_isa_name(ScalarIsa isa)
{
    if (!SCALAR_PATHS_HAVE_AVX2) return "";
    return isa == SCALAR_ISA_AVX512 ? "AVX-512" : isa == SCALAR_ISA_AVX2 ? "AVX2" : "SSE2";
}

const ScalarPaths *const scalar_paths_builds[SCALAR_PATHS_ISAS][SCALAR_PATHS_BUILDS] = {
    { &scalar_paths_mesh, &scalar_paths_basic, &scalar_paths_lean, &scalar_paths_all },
#if SCALAR_PATHS_HAVE_AVX2
    { &scalar_paths_mesh_avx2, &scalar_paths_basic_avx2, &scalar_paths_lean_avx2, &scalar_paths_all_avx2 },
    { &scalar_paths_mesh_avx512, &scalar_paths_basic_avx512, &scalar_paths_lean_avx512, &scalar_paths_all_avx512 },
#endif
};

const ScalarPaths *scalar_paths_pick_isa(unsigned features, ScalarIsa isa)
{
    const ScalarPaths *const *row = scalar_paths_builds[(size_t)isa < SCALAR_PATHS_ISAS ? (size_t)isa : 0u];
    for (size_t i = 0; i + 1u < SCALAR_PATHS_BUILDS; i++)
        if ((features & ~row[i]->features) == 0u) return row[i];
    return row[SCALAR_PATHS_BUILDS - 1u];
}

const ScalarPaths *scalar_paths_pick(unsigned features)
{
    return scalar_paths_pick_isa(features, scalar_paths_isa_usable());
}
