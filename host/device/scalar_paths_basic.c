/* scalar_paths_basic.c — the scalar device's build for scenes of the basic materials
 * alone (scalar_paths.h): diffuse, metal, dielectric and emissive, untextured and never
 * cut out, lit by area lights under a plain background; spheres, boxes, planes and
 * triangles under either tree; no media, no instances. one-weekend, the scenes of
 * spheres or boxes (triangles alone run on 'mesh', scalar_paths_mesh.c): without the
 * other materials' dispatch, the texture lookups and the other lights' code their paths
 * took 12-15% fewer instructions than on the 'lean' build (docs/design.md). */

/* Expanded where KF_HAS is used, after kernels/types.h has defined the names; the
 * material bits are scalar_paths_impl.h's. */
#define CLPT_FEATURES                                                                                        \
    (KF_PATH | KF_WHITTED | KF_PATH_MEGAKERNEL | KF_PATH_LANES | KF_KDTREE | KF_BVH | KF_SPHERES | KF_BOXES | \
     KF_PLANES | SCALAR_PATHS_MAT_DIFFUSE | SCALAR_PATHS_MAT_METAL | SCALAR_PATHS_MAT_DIELECTRIC |          \
     SCALAR_PATHS_MAT_EMISSIVE)
#define SCALAR_PATHS scalar_paths_basic
#define SCALAR_PATHS_LABEL "basic"
#include "device/scalar_paths_impl.h"
