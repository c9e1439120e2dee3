/* scalar_paths.c — the choice between the scalar device's builds of its per-sample code
 * (scalar_paths.h). */
#include "device/scalar_paths.h"

int scalar_paths_avx2_usable(void)
{
#if SCALAR_PATHS_HAVE_AVX2
    /* gcc's and clang's check also asks the operating system whether it saves the
     * 256-bit registers (XGETBV), which AVX needs as much as the processor */
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
#else
    return 0;
#endif
}

const ScalarPaths *scalar_paths_pick_isa(unsigned features, int avx2)
{
    /* leanest first; the last has every feature */
    static const ScalarPaths *const builds[] = { &scalar_paths_basic, &scalar_paths_lean, &scalar_paths_all };
#if SCALAR_PATHS_HAVE_AVX2
    static const ScalarPaths *const builds_avx2[] = { &scalar_paths_basic_avx2, &scalar_paths_lean_avx2,
                                                      &scalar_paths_all_avx2 };
    const ScalarPaths *const *list = avx2 ? builds_avx2 : builds;
#else
    (void)avx2;
    const ScalarPaths *const *list = builds;
#endif
    size_t n = sizeof builds / sizeof builds[0];
    for (size_t i = 0; i + 1 < n; i++)
        if ((features & ~list[i]->features) == 0u) return list[i];
    return list[n - 1];
}

const ScalarPaths *scalar_paths_pick(unsigned features)
{
    return scalar_paths_pick_isa(features, scalar_paths_avx2_usable());
}
