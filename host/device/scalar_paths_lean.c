/* scalar_paths_lean.c — the scalar device's build of every kernel feature but participating
 * media and instancing (scalar_paths.h): the two whose code every path of every scene
 * ran through, the media checks at each bounce and the BVH walk's second level. */
#define CLPT_FEATURES (0xffffffffu & ~(KF_MEDIA | KF_INSTANCES))
#define SCALAR_PATHS scalar_paths_lean
#define SCALAR_PATHS_LABEL "lean"
#include "device/scalar_paths_impl.h"
