/* scalar_paths_lean.c — the scalar device's build of every kernel feature but participating
 * media, instancing and motion blur (scalar_paths.h): the three whose code every path of
 * every scene ran through, the media checks at each bounce, the BVH walk's second level
 * and the path's time. */
#define CLPT_FEATURES (0xffffffffu & ~(KF_MEDIA | KF_INSTANCES | KF_MOTION))
#define SCALAR_PATHS scalar_paths_lean
#define SCALAR_PATHS_LABEL "lean"
#include "device/scalar_paths_impl.h"
