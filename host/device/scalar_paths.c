/* scalar_paths.c — the choice between the scalar device's builds of its per-sample code
 * (scalar_paths.h). */
#include "device/scalar_paths.h"

const ScalarPaths *scalar_paths_pick(unsigned features)
{
    /* leanest first; the last has every feature */
    static const ScalarPaths *const builds[] = { &scalar_paths_basic, &scalar_paths_lean, &scalar_paths_all };
    for (size_t i = 0; i + 1 < sizeof builds / sizeof builds[0]; i++)
        if ((features & ~builds[i]->features) == 0u) return builds[i];
    return &scalar_paths_all;
}
