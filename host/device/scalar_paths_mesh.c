/* scalar_paths_mesh.c — the scalar device's build for triangle meshes of the basic
 * materials (scalar_paths.h): the 'basic' build (scalar_paths_basic.c) without spheres
 * and boxes, whose intersection tests, inlined into the walks' leaf code though a mesh
 * never runs them, made the BVH walk 5-15% slower on Sponza's rays (bench_traverse) and
 * the McGuire Cornell box 5% slower to render (bench/RESULTS.md). Triangles and
 * infinite planes under either tree: the Cornell boxes, the dragon, most OBJ and PLY
 * files. */

/* As in scalar_paths_basic.c, less KF_SPHERES and KF_BOXES. */
#define CLPT_FEATURES                                                                                     \
    (KF_PATH | KF_WHITTED | KF_PATH_MEGAKERNEL | KF_PATH_LANES | KF_KDTREE | KF_BVH | KF_PLANES |         \
     SCALAR_PATHS_MAT_DIFFUSE | SCALAR_PATHS_MAT_METAL | SCALAR_PATHS_MAT_DIELECTRIC | SCALAR_PATHS_MAT_EMISSIVE)
#define SCALAR_PATHS scalar_paths_mesh
#define SCALAR_PATHS_LABEL "mesh"
#include "device/scalar_paths_impl.h"
