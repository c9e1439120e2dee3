/*
 * test_scalar_paths.c — the scalar device's builds of its per-sample code
 * (host/device/scalar_paths.h): the leanest that covers a scene's kernel features is
 * picked, and every build renders a scene it covers with the same bits as the build of
 * everything (which the other tests compare with PoCL).
 */
#include <string.h>

#include "harness.h"
#include "device/kernel_features.h"
#include "device/scalar_paths.h"
#include "io/scene_load.h"
#include "render/render_scene.h"

static const ScalarPaths *const builds[] = { &scalar_paths_basic, &scalar_paths_lean, &scalar_paths_all };
#define N_BUILDS (sizeof builds / sizeof builds[0])

/* Whether build b has every feature of `features`. */
static int covers(const ScalarPaths *b, unsigned features) { return (features & ~b->features) == 0u; }

/* For any feature set: a build that has it, and no leaner one would do. */
static void test_pick_leanest(void)
{
    CHECK(scalar_paths_pick(KF_BVH | KF_MAT_DIFFUSE | KF_MAT_EMISSIVE) == &scalar_paths_basic);
    CHECK(scalar_paths_pick(KF_KDTREE | KF_SPHERES | KF_BOXES | KF_PLANES | KF_MAT_DIFFUSE) == &scalar_paths_basic);
    CHECK(scalar_paths_pick(KF_BVH | KF_MAT_DIFFUSE | KF_TEXTURES) == &scalar_paths_lean);
    CHECK(scalar_paths_pick(KF_BVH | KF_SPHERES | KF_MAT_METAL | KF_MAT_DIELECTRIC) == &scalar_paths_basic);
    CHECK(scalar_paths_pick(KF_BVH | KF_MAT_PRINCIPLED) == &scalar_paths_lean);
    CHECK(scalar_paths_pick(KF_BVH | KF_MAT_DIFFUSE | KF_ENV_MAP) == &scalar_paths_lean);
    CHECK(scalar_paths_pick(KF_BVH | KF_MAT_DIFFUSE | KF_DELTA_LIGHTS) == &scalar_paths_lean);
    CHECK(scalar_paths_pick(KF_BVH | KF_MAT_DIFFUSE | KF_MEDIA) == &scalar_paths_all);
    CHECK(scalar_paths_pick(KF_BVH | KF_MAT_DIFFUSE | KF_INSTANCES) == &scalar_paths_all);
    CHECK(scalar_paths_pick(0xffffffffu) == &scalar_paths_all);
    CHECK(scalar_paths_all.features == 0xffffffffu);
    /* each bit alone and with a few others */
    unsigned state = 1u;
    for (int i = 0; i < 2000; i++) {
        unsigned f = 1u << (i % 32);
        if (i >= 32) {
            state = state * 1664525u + 1013904223u;   /* Numerical Recipes' LCG */
            f |= state & (state >> 7) & (state >> 13);
        }
        const ScalarPaths *p = scalar_paths_pick(f);
        CHECK_MSG(covers(p, f), "features 0x%x: picked '%s' (0x%x)", f, p->name, p->features);
        for (size_t k = 0; k < N_BUILDS && builds[k] != p; k++)
            CHECK_MSG(!covers(builds[k], f), "features 0x%x: picked '%s', but '%s' has them", f, p->name,
                      builds[k]->name);
    }
}

static int same_bits(vec3 a, vec3 b) { return memcmp(&a, &b, sizeof a) == 0; }

/* Renders `path` (at 20 x 15 pixels, 3 samples each, path tracer and whitted; through the
 * kd-tree if `kdtree`, else the BVH) with every build that covers its features and
 * compares each sample with the build of everything; `expect`: the build the scalar
 * device picks. */
static void check_scene(const char *path, int kdtree, const ScalarPaths *expect)
{
    Scene s;
    SceneKind kind;
    Error err = { 0 };
    scene_init(&s);
    Status st = scene_load_file(path, SCENE_FORMAT_AUTO, &s, &kind, &err);
    CHECK_MSG(st == ST_OK, "%s: %s", path, err.msg);
    if (st) {
        scene_free(&s);
        error_clear(&err);
        return;
    }
    s.image.width = 20;
    s.image.height = 15;
    if (kdtree) s.accel = ACCEL_KDTREE;
    RenderScene rs;
    CHECK_MSG((st = render_scene_prepare(&s, 1, &rs, &err)) == ST_OK, "%s: %s", path, err.msg);
    if (st == ST_OK) {
        unsigned f = kernel_scene_features(&rs.ds);
        const ScalarPaths *p = scalar_paths_pick(f);
        CHECK_MSG(p == expect, "%s (features 0x%x): picked '%s', expected '%s'", path, f, p->name, expect->name);
        SceneView sv;
        device_scene_view(&rs.ds, &sv);
        uint n_pixels = rs.ds.params.width * rs.ds.params.height;
        for (size_t k = 0; k + 1 < N_BUILDS; k++) {
            const ScalarPaths *b = builds[k];
            if (!covers(b, f)) continue;
            size_t samples = 0, same = 0;
            for (uint pixel = 0; pixel < n_pixels; pixel++) {
                for (uint sample = 0; sample < 3u; sample++) {
                    vec3 la, lb;
                    uint64_t ra = scalar_paths_all.path(&sv, pixel, sample, &la);
                    uint64_t rb = b->path(&sv, pixel, sample, &lb);
                    uint wa = 0, wb = 0;
                    vec3 wla = scalar_paths_all.whitted(&sv, pixel, sample, &wa);
                    vec3 wlb = b->whitted(&sv, pixel, sample, &wb);
                    samples += 2;
                    same += (ra == rb && same_bits(la, lb)) + (wa == wb && same_bits(wla, wlb));
                }
            }
            fprintf(stderr, "  %s: build '%s': %zu of %zu samples bit-identical to build 'all'\n", path, b->name,
                    same, samples);
            CHECK(same == samples);
        }
    }
    render_scene_free(&rs);
    scene_free(&s);
    error_clear(&err);
}

static void test_cornell_box(void)
{
    check_scene("scenes/cornell-box.scene", 0, &scalar_paths_basic);
    check_scene("scenes/cornell-box.scene", 1, &scalar_paths_basic);
}
static void test_one_weekend(void) { check_scene("scenes/one-weekend.scene", 0, &scalar_paths_basic); }
static void test_materials(void)
{
    /* the scene is lit by the shared courtyard map alone */
    if (!shared_model_present("../shared/envmaps/courtyard.hdr", "the 'lean' build's scene is not rendered")) return;
    check_scene("scenes/materials.scene", 0, &scalar_paths_lean);
}
static void test_fog(void) { check_scene("scenes/fog.scene", 0, &scalar_paths_all); }

int main(void)
{
    RUN(test_pick_leanest);
    RUN(test_cornell_box);
    RUN(test_one_weekend);
    RUN(test_materials);
    RUN(test_fog);
    return harness_report();
}
