/* scalar_paths_diffuse.c — the scalar device's build for scenes of diffuse and emissive
 * materials alone (scalar_paths.h): untextured and never cut out, lit by area lights
 * under a plain background, spheres, boxes, planes and triangles under either tree; no
 * media, no instances. The Cornell box and most meshes; without the other materials'
 * dispatch and the texture lookups their paths took a tenth fewer instructions. */

/* Expanded where KF_HAS is used, after kernels/types.h has defined the names. The
 * material bits are numbers because KF_MAT_* are enum constants, which #if reads as 0
 * (checked below). */
#define SCALAR_PATHS_MAT_DIFFUSE 0x800u
#define SCALAR_PATHS_MAT_EMISSIVE 0x4000u
#define CLPT_FEATURES (KF_PATH | KF_WHITTED | KF_PATH_MEGAKERNEL | KF_PATH_LANES | KF_KDTREE | KF_BVH | \
                       KF_SPHERES | KF_BOXES | KF_PLANES | SCALAR_PATHS_MAT_DIFFUSE | SCALAR_PATHS_MAT_EMISSIVE)
#define SCALAR_PATHS scalar_paths_diffuse
#define SCALAR_PATHS_LABEL "diffuse"
#include "device/scalar_paths_impl.h"

_Static_assert(SCALAR_PATHS_MAT_DIFFUSE == KF_MAT_DIFFUSE && SCALAR_PATHS_MAT_EMISSIVE == KF_MAT_EMISSIVE,
               "scalar_paths_diffuse: the material bits of kernels/types.h");
