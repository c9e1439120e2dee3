/* scalar_paths_all.c — the scalar device's build of every kernel feature (scalar_paths.h):
 * for the scenes no leaner build covers. */
#define CLPT_FEATURES 0xffffffffu
#define SCALAR_PATHS scalar_paths_all
#define SCALAR_PATHS_LABEL "all"
#include "device/scalar_paths_impl.h"
