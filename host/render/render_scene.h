/*
 * render_scene.h — a loaded scene made ready for the devices: lights listed, camera
 * prepared, the tree built (the BVH or the kd-tree), and everything gathered into the DeviceScene every device
 * uploads. Used by main and by the tests, so both render the same way.
 */
#ifndef CLPT_RENDER_SCENE_H
#define CLPT_RENDER_SCENE_H

#include "device/device.h"
#include "accel/bvh.h"
#include "accel/bvh_inst.h"
#include "accel/kd_inst.h"
#include "accel/kdtree.h"
#include "scene/scene.h"

typedef struct {
    KdTree kd;            /* the scene's tree (Scene.accel): one of these two, */
    Bvh bvh;              /* the other one empty; with objects under --accel kdtree the
                           * top level in bvh, the prototypes' kd-trees in kd */
    DeviceScene ds;       /* points into the Scene and the tree: keep both alive */
    /* a scene with objects (docs/instancing.md): the BVH's two levels and the device's
     * instance records (the scene's, their roots filled, then the world's own) */
    Instance *instances;  size_t n_instances;
    BvhLevels levels;
    int instanced;        /* the tree has two levels */
    /* --accel kdtree with objects: each prototype's kd-tree's record (n_objects + 1 of
     * them, the world's last) and the trees' sizes */
    KdProto *kd_protos;   size_t n_kd_protos;
    KdProtoStats kd_levels;
    /* motion blur (docs/motion.md): the keys of the moving instances, then the moving
     * camera's, or NULL; per device instance its first key or NO_INDEX, or NULL */
    MotionKey *motion_keys;
    uint *instance_motion;
} RenderScene;

/* The scene's image settings (size, depth, seed) and its tree are taken as they are
 * now, so apply command-line overrides first. tree_threads (the build's): 0 = every
 * core. On failure nothing is left to free. */
Status render_scene_prepare(Scene *s, int tree_threads, RenderScene *out, Error *err);
void render_scene_free(RenderScene *r);

/* Points ds at a built tree: its buffers, counts and root box. A DeviceScene may hold
 * both (the benchmark and tests that compare the walks); the kd-tree's box then stays,
 * since its walk clips rays to it. */
void render_scene_use_kdtree(DeviceScene *ds, const KdTree *kd);
void render_scene_use_bvh(DeviceScene *ds, const Bvh *bvh);

/* How the whitted integrator places spp samples in a pixel (RenderParams.strata): 1 is
 * the pixel centre (0), a square number an m x m jittered grid (m), any other number
 * uniform jitter (1). */
uint render_scene_strata(uint spp);

/* The pixels a mask of n entries sets, in increasing order, written to list (room for
 * n): a DeviceScene's pixel_list (RenderParams.pixel_list_size, the count returned), so
 * that a pass or round over some pixels costs only theirs. */
uint render_scene_list_pixels(const uint *mask, size_t n, uint *list);

#endif /* CLPT_RENDER_SCENE_H */
