/*
 * test_scalar_paths.c — the scalar device's builds of its per-sample code
 * (host/device/scalar_paths.h): the leanest that covers a scene's kernel features is
 * picked, and every build renders a scene it covers with the same bits as the build of
 * everything (which the other tests compare with PoCL); on a processor with AVX2 or
 * AVX-512 the same for the builds compiled for it, which the scalar device then picks.
 */
#include <string.h>

#include "harness.h"
#include "device/kernel_features.h"
#include "device/scalar_paths.h"
#include "io/scene_load.h"
#include "render/render_scene.h"
#include "sample/sampling.h"

/* The rows of scalar_paths_builds this processor runs (the instruction sets up to the
 * best it has); the others are not rendered. */
static size_t n_rows;

/* Whether build b has every feature of `features`. */
static int covers(const ScalarPaths *b, unsigned features) { return (features & ~b->features) == 0u; }

/* The build for instruction set `isa` of the same features as build b (one of the
 * first row); NULL where there is none. */
static const ScalarPaths *isa_twin(const ScalarPaths *b, ScalarIsa isa)
{
    for (size_t k = 0; k < SCALAR_PATHS_BUILDS; k++)
        if (scalar_paths_builds[0][k] == b && (size_t)isa < SCALAR_PATHS_ISAS) return scalar_paths_builds[isa][k];
    return NULL;
}

/* The builds for any x86-64 processor alone. */
static const ScalarPaths *pick_sse2(unsigned features) { return scalar_paths_pick_isa(features, SCALAR_ISA_BASE); }

/* For any feature set: a build that has it, and no leaner one would do; for each
 * instruction set its twin, and on this processor the twin for the best it has. */
static void test_pick_leanest(void)
{
    CHECK(pick_sse2(KF_BVH | KF_MAT_DIFFUSE | KF_MAT_EMISSIVE) == &scalar_paths_mesh);
    CHECK(pick_sse2(KF_KDTREE | KF_PLANES | KF_MAT_DIFFUSE | KF_MAT_DIELECTRIC) == &scalar_paths_mesh);
    CHECK(pick_sse2(KF_BVH | KF_SPHERES | KF_MAT_DIFFUSE) == &scalar_paths_basic);
    CHECK(pick_sse2(KF_BVH | KF_BOXES | KF_MAT_DIFFUSE) == &scalar_paths_basic);
    CHECK(pick_sse2(KF_KDTREE | KF_SPHERES | KF_BOXES | KF_PLANES | KF_MAT_DIFFUSE) == &scalar_paths_basic);
    CHECK(pick_sse2(KF_BVH | KF_MAT_DIFFUSE | KF_TEXTURES) == &scalar_paths_lean);
    CHECK(pick_sse2(KF_BVH | KF_SPHERES | KF_MAT_METAL | KF_MAT_DIELECTRIC) == &scalar_paths_basic);
    CHECK(pick_sse2(KF_BVH | KF_MAT_PRINCIPLED) == &scalar_paths_lean);
    CHECK(pick_sse2(KF_BVH | KF_MAT_DIFFUSE | KF_ENV_MAP) == &scalar_paths_lean);
    CHECK(pick_sse2(KF_BVH | KF_MAT_DIFFUSE | KF_DELTA_LIGHTS) == &scalar_paths_lean);
    CHECK(pick_sse2(KF_BVH | KF_MAT_DIFFUSE | KF_MEDIA) == &scalar_paths_all);
    CHECK(pick_sse2(KF_BVH | KF_MAT_DIFFUSE | KF_INSTANCES) == &scalar_paths_all);
    CHECK(pick_sse2(0xffffffffu) == &scalar_paths_all);
    CHECK(scalar_paths_all.features == 0xffffffffu);
    /* each bit alone and with a few others */
    unsigned state = 1u;
    for (int i = 0; i < 2000; i++) {
        unsigned f = 1u << (i % 32);
        if (i >= 32) {
            state = state * 1664525u + 1013904223u;   /* Numerical Recipes' LCG */
            f |= state & (state >> 7) & (state >> 13);
        }
        const ScalarPaths *p = pick_sse2(f);
        CHECK_MSG(covers(p, f), "features 0x%x: picked '%s' (0x%x)", f, p->name, p->features);
        for (size_t k = 0; k < SCALAR_PATHS_BUILDS && scalar_paths_builds[0][k] != p; k++)
            CHECK_MSG(!covers(scalar_paths_builds[0][k], f), "features 0x%x: picked '%s', but '%s' has them", f,
                      p->name, scalar_paths_builds[0][k]->name);
        CHECK(p->isa == SCALAR_ISA_BASE);
        for (ScalarIsa isa = SCALAR_ISA_AVX2; isa <= SCALAR_ISA_AVX512; isa++) {
            const ScalarPaths *q = scalar_paths_pick_isa(f, isa), *twin = isa_twin(p, isa);
            CHECK_MSG(q == (twin ? twin : p), "features 0x%x: for %s picked '%s'", f, scalar_paths_isa_name(isa),
                      q->name);
            CHECK(q->features == p->features && q->isa == (twin ? isa : SCALAR_ISA_BASE));
        }
        const ScalarPaths *here = isa_twin(p, scalar_paths_isa_usable());
        CHECK(scalar_paths_pick(f) == (here ? here : p));
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
        const ScalarPaths *p = scalar_paths_pick_isa(f, 0);
        CHECK_MSG(p == expect, "%s (features 0x%x): picked '%s', expected '%s'", path, f, p->name, expect->name);
        SceneView sv;
        device_scene_view(&rs.ds, &sv);
        uint n_pixels = rs.ds.params.width * rs.ds.params.height;
        for (size_t k = 0; k < n_rows * SCALAR_PATHS_BUILDS; k++) {
            const ScalarPaths *b = scalar_paths_builds[k / SCALAR_PATHS_BUILDS][k % SCALAR_PATHS_BUILDS];
            if (b == &scalar_paths_all || !covers(b, f)) continue;
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
            /* the queries alone (bench_traverse times them): rays in a spread of
             * directions from the middle of the camera's focus plane, inside the
             * scene, every other one stopped short */
            const Camera *cam = &rs.ds.params.camera;
            vec3 mid = v3_add(cam->corner, v3_scale(v3_sub(cam->horizontal, cam->vertical), 0.5f));
            size_t rays = 0, same_rays = 0, hits = 0;
            for (uint i = 0; i < 512u; i++) {
                float u1 = ((float)i + 0.5f) / 512.0f, u2 = (float)((i * 317u) % 512u) / 512.0f;
                Ray ray = { .o = mid, .tmin = 0.0f, .d = sample_sphere_dir(u1, u2), .tmax = (i & 1u) ? 2.0f : 1e30f };
                Hit ha, hb;
                scalar_paths_all.closest(&sv, &ray, &ha);
                b->closest(&sv, &ray, &hb);
                rays++;
                hits += ha.prim != NO_INDEX;
                same_rays += memcmp(&ha, &hb, sizeof ha) == 0 &&
                             scalar_paths_all.any(&sv, &ray) == b->any(&sv, &ray);
            }
            fprintf(stderr, "  %s: build '%s': %zu of %zu samples and %zu of %zu rays (%zu hits) bit-identical to "
                    "build 'all'\n", path, b->name, same, samples, same_rays, rays, hits);
            CHECK(same == samples && same_rays == rays && hits > 0);
        }
    }
    render_scene_free(&rs);
    scene_free(&s);
    error_clear(&err);
}

static void test_cornell_box(void)
{
    check_scene("scenes/cornell-box.scene", 0, &scalar_paths_mesh);
    check_scene("scenes/cornell-box.scene", 1, &scalar_paths_mesh);
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
    /* the sets up to the best this processor runs */
    ScalarIsa isa = scalar_paths_isa_usable();
    n_rows = (size_t)isa + 1u < SCALAR_PATHS_ISAS ? (size_t)isa + 1u : SCALAR_PATHS_ISAS;
    if (n_rows < SCALAR_PATHS_ISAS)
        fprintf(stderr, "  this processor runs the builds up to %s: the others are not rendered\n",
                scalar_paths_isa_name(isa));
    RUN(test_pick_leanest);
    RUN(test_cornell_box);
    RUN(test_one_weekend);
    RUN(test_materials);
    RUN(test_fog);
    return harness_report();
}
