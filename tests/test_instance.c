/*
 * test_instance.c — instances of objects through the BVH's two levels
 * (docs/instancing.md): an instanced scene against the same scene flattened into copies
 * (bit for bit under identity transforms, within noise under others), hits and normals
 * through rotated, non-uniformly scaled and mirrored instances against a test of every
 * primitive of every instance, PoCL against the scalar device bit for bit, the
 * kd-tree's copies, and instanced emitters as lights (against their copies, each
 * sampling strategy alone, their noise before and after) and the scene radius that
 * delta lights are chosen by. Run from the project root.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh_top.h"
#include "harness.h"
#include "io/scene_load.h"
#include "render_util.h"
#include "scene/instance.h"
#include "scene/transform.h"
#include "geom/surface.h"
#include "accel/traverse.h"

/* A floor, a lamp, and an object of a sphere, a box and two triangles (a quad). */
#define HEAD                                                                             \
    "camera { from 0 3 9 at 0 0.6 0 fov 40 }\n"                                          \
    "image { width 48 height 36 spp 16 depth 4 seed 7 }\n"                               \
    "background { color 0.3 0.35 0.4 }\n"                                                \
    "material red { type diffuse albedo 0.8 0.25 0.2 }\n"                                \
    "material grey { type diffuse albedo 0.5 0.5 0.5 }\n"                                \
    "material gold { type conductor metal Au roughness 0.3 }\n"                          \
    "material lamp { type emissive radiance 6 6 6 }\n"                                   \
    "quad { v0 -1 4 -1 v1 1 4 -1 v2 1 4 1 v3 -1 4 1 material lamp }\n"                   \
    "box { min -6 -0.1 -6 max 6 0 6 material grey }\n"                                  \
    "object thing {\n"                                                                   \
    "  sphere { center 0 0.5 0 radius 0.5 material red }\n"                              \
    "  box { min 0.6 0 -0.3 max 1.2 0.6 0.3 material gold }\n"                           \
    "  quad { v0 -1.3 0 0 v1 -0.7 0 0 v2 -0.7 1 0.2 v3 -1.3 1 0.2 material red }\n"      \
    "}\n"

/* Identities only: the world's own primitives and an identity instance. */
static const char identity_scene[] = HEAD "instance thing { }\n"
                                          "instance thing { material grey }\n";
/* Translations, rotations, non-uniform scales and a mirror (no rotated box, which the
 * kd-tree's copies cannot hold). */
static const char moved_scene[] = HEAD "instance thing { translate 2.6 0 0 }\n"
                                       "instance thing { translate -2.6 0 0.5 scale 0.7 1.6 0.9 material gold }\n"
                                       "instance thing { translate 0 0 -2 scale -1 1 1 }\n"
                                       "instance thing { translate 0 0 1.8 scale 0.5 }\n";

/* A lamp object: a dark triangle, an emissive quad (two triangle lights, one
 * parallelogram) and a dimmer emissive triangle, facing down in object space; three
 * instances under rotations and non-uniform scales (one mirrored) above a diffuse floor,
 * and a fourth whose material replaces the lamp's, which makes it no light. Direct light
 * only (depth 1), so that the strategies are the two estimators and nothing else. */
#define LAMPS(spp, seed)                                                                       \
    "camera { from 0 4.5 7.5 at 0 0.4 0 fov 45 }\n"                                            \
    "image { width 48 height 36 spp " #spp " depth 1 seed " #seed " }\n"                       \
    "background { color 0 0 0 }\n"                                                             \
    "material floor { type diffuse albedo 0.7 0.7 0.7 }\n"                                     \
    "material glow { type emissive radiance 8 7 5.5 }\n"                                       \
    "material dim { type emissive radiance 2 3 4 }\n"                                          \
    "box { min -6 -0.1 -6 max 6 0 6 material floor }\n"                                       \
    "object lamp {\n"                                                                          \
    "  triangle { v0 -0.5 0.1 -0.3 v1 0.5 0.1 -0.3 v2 0 0.1 -0.6 material floor }\n"           \
    "  quad { v0 -0.5 0 -0.3 v1 0.5 0 -0.3 v2 0.5 0 0.3 v3 -0.5 0 0.3 material glow }\n"       \
    "  triangle { v0 -0.5 0 0.4 v1 0.5 0 0.4 v2 0 0 0.8 material dim }\n"                      \
    "}\n"                                                                                      \
    "instance lamp { rz 25 translate -1.8 2.2 0 }\n"                                           \
    "instance lamp { scale 1.6 0.5 0.8 ry 40 translate 1.6 1.8 -0.6 }\n"                       \
    "instance lamp { rx -30 scale -0.7 0.7 0.7 translate 0 2.6 1.6 }\n"                        \
    "instance lamp { translate 0 3 -2 material floor }\n"

static const char lamps_scene[] = LAMPS(64, 3);

/* Spheres of objects: two instances under similarities (one mirrored) are sphere lights
 * in the world, and render as world spheres at the places the transforms put them do
 * (their copies would be ellipsoids, which the world does not take as lights); under a
 * non-uniform scale (BULB_SQUASHED) an ellipsoid, whose light has no power: never
 * chosen, its emission found by BSDF sampling at full weight. */
#define BULB_HEAD(spp)                                                                         \
    "camera { from 0 4.5 7.5 at 0 0.4 0 fov 45 }\n"                                            \
    "image { width 48 height 36 spp " #spp " depth 1 seed 5 }\n"                               \
    "background { color 0 0 0 }\n"                                                             \
    "material floor { type diffuse albedo 0.7 0.7 0.7 }\n"                                     \
    "material glow { type emissive radiance 8 7 5.5 }\n"                                       \
    "box { min -6 -0.1 -6 max 6 0 6 material floor }\n"
#define BULBS(spp)                                                                             \
    BULB_HEAD(spp) "object bulb { sphere { center 0 0.2 0 radius 0.3 material glow } }\n"      \
    "instance bulb { scale 0.8 ry 30 translate -1 1.5 0 }\n"                                   \
    "instance bulb { scale -1.2 1.2 1.2 rx 20 translate 1.2 1.2 0.5 }\n"
#define BULB_SQUASHED "instance bulb { scale 1 0.5 1 translate 0 2.5 -1.5 }\n"


static Status load_text(const char *text, Scene *s, Error *err)
{
    scene_init(s);
    return scene_load_text("inst.scene", text, strlen(text), s, err);
}

/* Renders `text` on `devices` opened under cfg (NULL: the defaults), instanced or
 * flattened into copies first. */
static Status render_cfg(const char *text, const char *devices, const DeviceConfig *cfg, int flatten, uint accel,
                         Film *film, Error *err)
{
    Scene s;
    Status st = load_text(text, &s, err);
    s.accel = accel;
    if (!st && flatten) st = scene_flatten_instances(&s, err);
    if (!st) st = render_util_run_cfg(&s, RENDER_UTIL_SCENE_MIS, devices, cfg, 0, film, err);
    scene_free(&s);
    return st;
}

static Status render(const char *text, const char *devices, int flatten, uint accel, Film *film, Error *err)
{
    return render_cfg(text, devices, NULL, flatten, accel, film, err);
}

static void test_identity_bit_identical(void)
{
    Film a, b;
    Error err = { 0 };
    CHECK_MSG(render(identity_scene, "scalar", 0, ACCEL_BVH, &a, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render(identity_scene, "scalar", 1, ACCEL_BVH, &b, &err) == ST_OK, "%s", err.msg);
    size_t n = (size_t)a.width * a.height * 3u, same = film_sums_same(&a, &b);
    fprintf(stderr, "  identity instances: %zu of %zu channel sums identical to the copies\n", same, n);
    CHECK(same == n);
    film_free(&a);
    film_free(&b);
}

static void test_moved_matches_flattened(void)
{
    Film a, b;
    Error err = { 0 };
    CHECK_MSG(render(moved_scene, "scalar", 0, ACCEL_BVH, &a, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render(moved_scene, "scalar", 1, ACCEL_BVH, &b, &err) == ST_OK, "%s", err.msg);
    if (!a.sum || !b.sum) return;
    double ma = film_mean(&a), mb = film_mean(&b);
    size_t n = (size_t)a.width * a.height * 3u, same = film_sums_same(&a, &b);
    fprintf(stderr, "  moved instances: mean %.6f, copies %.6f; %zu of %zu channel sums identical\n", ma, mb, same, n);
    /* the lamp's light and 16 samples: the means of two renders of one scene whose
     * rays differ by roundings agree far closer than this */
    CHECK(fabs(ma - mb) < 0.01 * mb);
    film_free(&a);
    film_free(&b);
}

/* --accel kdtree: the BVH's top level over a kd-tree per prototype (docs/instancing.md).
 * A prototype's kd walk finds the hit its BVH walk finds (the same leaf test on the
 * same object-space ray, and the tie rule), so the images are the BVH's bit for bit,
 * under any transform: rotated boxes too, which the copies made before could not hold.
 * With identity transforms they are the one-level kd-tree's over the copies too; under
 * others the copies' within noise (the copies are rounded into the world). */
static void test_kdtree_prototypes(void)
{
    static const char rotated_scene[] = HEAD "instance thing { ry 30 }\n"
                                             "instance thing { rotate 1 1 0 25 scale 0.6 1.7 0.9 translate 2.4 0 0 }\n"
                                             "instance thing { matrix 1 0.4 0 0.5  0 1 0.3 0  0.2 0 1 1.5  0 0 0 1 }\n";
    static const char *const scenes[] = { identity_scene, moved_scene, rotated_scene, lamps_scene };
    static const char *const names[] = { "identity", "moved", "rotated", "lamps" };
    for (size_t k = 0; k < 4; k++) {
        Film kd, bvh;
        Error err = { 0 };
        CHECK_MSG(render(scenes[k], "scalar", 0, ACCEL_KDTREE, &kd, &err) == ST_OK, "%s", err.msg);
        CHECK_MSG(render(scenes[k], "scalar", 0, ACCEL_BVH, &bvh, &err) == ST_OK, "%s", err.msg);
        size_t n = (size_t)kd.width * kd.height * 3u, same = film_sums_same(&kd, &bvh);
        fprintf(stderr, "  %s: %zu of %zu channel sums identical through kd-tree and BVH prototypes\n", names[k], same,
                n);
        CHECK(same == n);
        if (k < 2) {
            /* against the copies through the one-level kd-tree */
            Film copies;
            CHECK_MSG(render(scenes[k], "scalar", 1, ACCEL_KDTREE, &copies, &err) == ST_OK, "%s", err.msg);
            double mk = film_mean(&kd), mc = film_mean(&copies);
            size_t same_copies = film_sums_same(&kd, &copies);
            fprintf(stderr, "  %s: mean %.6f, kd-tree over the copies %.6f; %zu of %zu channel sums identical\n",
                    names[k], mk, mc, same_copies, n);
            if (k == 0) CHECK(same_copies == n);
            else CHECK(fabs(mk - mc) < 0.01 * mc);
            film_free(&copies);
        }
        film_free(&kd);
        film_free(&bvh);
    }
}

/* scenes/instances.scene (3,600 bunnies, 250 million instanced triangles, which the
 * copies could not hold) renders under --accel kdtree, small, as under the BVH. */
static void test_kdtree_bunnies(void)
{
    if (!shared_model_present("../shared/models/bunny/bun_zipper.ply", "scenes/instances.scene is not rendered"))
        return;
    Scene s;
    Error err = { 0 };
    Film kd, bvh;
    for (int k = 0; k < 2; k++) {
        scene_init(&s);
        Status st = scene_load_file("scenes/instances.scene", SCENE_FORMAT_AUTO, &s, NULL, &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        if (st) return;
        s.accel = k ? ACCEL_BVH : ACCEL_KDTREE;
        s.image.width = 64;
        s.image.height = 36;
        s.image.spp = 2;
        st = render_util_run(&s, "scalar", 0, k ? &bvh : &kd, &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        scene_free(&s);
        if (st) return;
    }
    size_t n = (size_t)kd.width * kd.height * 3u, same = film_sums_same(&kd, &bvh);
    fprintf(stderr, "  instances.scene at 64x36: %zu of %zu channel sums identical through kd-tree and BVH\n", same, n);
    CHECK(same == n);
    CHECK(film_mean(&kd) > 0.05);
    film_free(&kd);
    film_free(&bvh);
}

/* PoCL (or the GPU) gives the scalar device's bits, through both trees' prototypes; the
 * kd-tree's under each way a wave is launched (--wave-launch: counted, bounded,
 * megakernel; the default one, the CPUs' megakernel, in the first pass). */
static void test_opencl_matches_scalar(void)
{
    static const char *const scenes[] = { identity_scene, moved_scene, lamps_scene, BULBS(16) BULB_SQUASHED };
    static const int launches[] = { WAVE_LAUNCH_COUNTED, WAVE_LAUNCH_BOUNDED, WAVE_LAUNCH_MEGAKERNEL };
    for (size_t k = 0; k < 4 + 4 + 3; k++) {
        Film a, b;
        Error err = { 0 };
        uint accel = k < 4 ? ACCEL_BVH : ACCEL_KDTREE;
        const char *text = k < 8 ? scenes[k % 4] : moved_scene;
        DeviceConfig cfg;
        memset(&cfg, 0, sizeof cfg);
        cfg.wave_paths = k < 8 ? 0u : 1000u;
        cfg.wave_launch = k < 8 ? WAVE_LAUNCH_AUTO : launches[k - 8];
        Status sa = render_cfg(text, TEST_OPENCL, &cfg, 0, accel, &a, &err);
        CHECK_MSG(sa == ST_OK, "%s", err.msg);
        Status sb = render(text, "scalar", 0, accel, &b, &err);
        CHECK_MSG(sb == ST_OK, "%s", err.msg);
        if (sa == ST_OK && sb == ST_OK) {
            size_t n = (size_t)a.width * a.height * 3u, same = film_sums_same(&a, &b);
            static const char *const launch_names[] = { "", ", counted", ", bounded", ", megakernel" };
            fprintf(stderr, "  scene %zu (%s%s): %zu of %zu channel sums identical on OpenCL and scalar\n",
                    k < 8 ? k % 4 : 1u, accel == ACCEL_BVH ? "BVH" : "kd-tree", launch_names[cfg.wave_launch], same,
                    n);
            CHECK(same == n);
        }
        film_free(&a);
        film_free(&b);
    }
}

/* ------------------------------------------------------------------ nesting */

/* `thing` nested in objects under shears, mirrors and non-uniform scales (dyadic
 * entries, so every product is exact in double), with materials given at two levels and
 * an object of its own shape among them; NESTED_FLAT is the same scene written with one
 * level: the products written out, the materials resolved (the outermost wins). */
#define NESTED_PAIR                                                                              \
    "object pair {\n"                                                                            \
    "  instance thing { matrix 1 0.5 0 0.25  0 1 0 0  0 0 1 -1  0 0 0 1 }\n"                      \
    "  instance thing { matrix -0.5 0 0 1.5  0 0.75 0 0  0 0 1 0.5  0 0 0 1 material gold }\n"    \
    "}\n"
static const char nested_scene[] = HEAD NESTED_PAIR
    "object group {\n"
    "  box { min -0.2 0 -0.2 max 0.2 0.4 0.2 material grey }\n"
    "  instance pair { matrix 1 0 0 -1  0 1 0 0  0 0.25 1 0  0 0 0 1 }\n"
    "  instance pair { matrix 0.5 0 0 1  0 0.5 0 0  0 0 -1 0  0 0 0 1 material red }\n"
    "}\n"
    "instance group { matrix 1 0 0 0  0 1 0 0.125  0.5 0 1 0  0 0 0 1 }\n";
static const char nested_flat_scene[] = HEAD
    "object group { box { min -0.2 0 -0.2 max 0.2 0.4 0.2 material grey } }\n"
    "instance group { matrix 1 0 0 0  0 1 0 0.125  0.5 0 1 0  0 0 0 1 }\n"
    "instance thing { matrix 1 0.5 0 -0.75  0 1 0 0.125  0.5 0.5 1 -1.375  0 0 0 1 }\n"
    "instance thing { matrix -0.5 0 0 0.5  0 0.75 0 0.125  -0.25 0.1875 1 0.75  0 0 0 1 material gold }\n"
    "instance thing { matrix 0.5 0.25 0 1.125  0 0.5 0 0.125  0.25 0.125 -1 1.5625  0 0 0 1 material red }\n"
    "instance thing { matrix -0.25 0 0 1.75  0 0.375 0 0.125  -0.125 0 -1 0.375  0 0 0 1 material red }\n";

/* Nested instances resolve to the flat-written ones: the same world instance records
 * (transforms, inverses, materials, flags; the object by name), in the same order, and
 * the same image bit for bit, on the scalar device and on OpenCL. */
static void test_nested_equals_flat(void)
{
    Scene a, b;
    Error err = { 0 };
    CHECK_MSG(load_text(nested_scene, &a, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(load_text(nested_flat_scene, &b, &err) == ST_OK, "%s", err.msg);
    CHECK(a.n_instances == 5 && b.n_instances == 5);
    size_t same = 0;
    for (size_t i = 0; i < a.n_instances && i < b.n_instances; i++) {
        Instance x = a.instances[i], y = b.instances[i];
        int named = strcmp(a.objects[a.instance_objects[i]].name, b.objects[b.instance_objects[i]].name) == 0;
        same += named && memcmp(&x, &y, sizeof x) == 0;
    }
    fprintf(stderr, "  nested: %zu instances, %zu the same records as the flat-written ones\n", a.n_instances, same);
    CHECK(same == 5);
    scene_free(&a);
    scene_free(&b);
    const char *devices[] = { "scalar", TEST_OPENCL };
    for (int d = 0; d < 2; d++) {
        Film fa, fb;
        CHECK_MSG(render(nested_scene, devices[d], 0, ACCEL_BVH, &fa, &err) == ST_OK, "%s", err.msg);
        CHECK_MSG(render(nested_flat_scene, devices[d], 0, ACCEL_BVH, &fb, &err) == ST_OK, "%s", err.msg);
        size_t n = (size_t)fa.width * fa.height * 3u, eq = film_sums_same(&fa, &fb);
        fprintf(stderr, "  %s: %zu of %zu channel sums identical, nested and flat\n", devices[d], eq, n);
        CHECK(eq == n);
        film_free(&fa);
        film_free(&fb);
    }
}

/* A white furnace of white diffuse spheres (albedo 1 under a white background: every
 * pixel's exact value is 1) placed through three levels of objects under shears, a
 * mirror and non-uniform scales: ellipsoids whose normals, if carried by M rather than
 * M^-T or flipped by the mirror, would darken or brighten the image. */
static void test_nested_furnace(void)
{
    static const char text[] = "camera { from 0 0 9 at 0 0 0 fov 40 }\n"
                               "image { width 32 height 24 spp 32 depth 64 seed 3 }\n"
                               "background { color 1 1 1 }\n"
                               "material white { type diffuse albedo 1 1 1 }\n"
                               "object ball { sphere { center 0 0 0 radius 0.6 material white } }\n"
                               "object pair {\n"
                               "  instance ball { matrix 1 0.8 0 -0.7  0 1 0 0  0 0.3 1 0  0 0 0 1 }\n"
                               "  instance ball { scale 1.5 0.5 1 rz 30 translate 0.8 0.6 0 }\n"
                               "}\n"
                               "object cluster {\n"
                               "  instance pair { }\n"
                               "  instance pair { matrix -1 0 0 0  0.4 1 0 -1.2  0 0 1 0.5  0 0 0 1 }\n"
                               "}\n"
                               "instance cluster { matrix 1 0 0.6 0  0 1 0 0  0 0.2 1 0  0 0 0 1 }\n"
                               "instance cluster { scale 0.6 0.9 0.6 ry 40 translate 2 1.6 -1 }\n";
    Film f;
    Error err = { 0 };
    CHECK_MSG(render(text, "scalar", 0, ACCEL_BVH, &f, &err) == ST_OK, "%s", err.msg);
    if (!f.sum) return;
    double mean = film_mean(&f), worst = 0.0;
    size_t n = (size_t)f.width * f.height * 3u;
    float *rgb = malloc(n * sizeof *rgb);
    film_resolve(&f, rgb);
    for (size_t i = 0; i < n; i++) worst = fmax(worst, fabs((double)rgb[i] - 1.0));
    free(rgb);
    fprintf(stderr, "  nested furnace: mean %.6f, worst pixel off 1 by %.3g\n", mean, worst);
    CHECK(fabs(mean - 1.0) < 1e-3);
    /* not exactly 1 in every pixel: Russian roulette's weights; a flipped normal
     * (a path sent into its own ellipsoid and killed) would blacken whole pixels */
    CHECK(worst < 0.1);
    film_free(&f);
}

/* ------------------------------------------------------------------ instanced emitters */


/* The instances' lights are the flattened copies' lights, in the same order: the same
 * kinds of record, world areas, normals, parallelograms and choice probabilities. */
static void test_lamps_are_lights(void)
{
    Scene a, b;
    Error err = { 0 };
    RenderScene ra, rb;
    CHECK(load_text(lamps_scene, &a, &err) == ST_OK);
    CHECK(load_text(lamps_scene, &b, &err) == ST_OK);
    CHECK(scene_flatten_instances(&b, &err) == ST_OK);
    CHECK_MSG(render_scene_prepare(&a, 1, &ra, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_scene_prepare(&b, 1, &rb, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(a.n_lights, 9);
    CHECK_EQ_INT(b.n_lights, 9);
    CHECK(a.instance_lights != NULL && ra.ds.n_instance_lights == 4);
    if (a.n_lights == 9 && b.n_lights == 9 && a.instance_lights) {
        CHECK(a.instance_lights[0] == 0 && a.instance_lights[1] == 3 && a.instance_lights[2] == 6);
        CHECK(a.instance_lights[3] == NO_INDEX);
        double worst = 0.0;
        for (size_t i = 0; i < 9; i++) {
            const Light *x = &a.lights[i], *y = &b.lights[i];
            CHECK(x->type == LIGHT_INSTANCED && y->type == LIGHT_AREA);
            CHECK(x->quad == y->quad);
            double d = fabs(x->area - y->area) / y->area;
            d = fmax(d, fabs(x->pick_pdf - y->pick_pdf) / y->pick_pdf);
            d = fmax(d, 1.0 - v3_dot(x->normal, y->normal));
            if (x->quad != LIGHT_QUAD_NONE) {
                /* the copies' parallelogram: the same corner and edges (a mirror swaps
                 * the copies' corners, which turns the parallelogram's edges round) */
                vec3 ya = y->position, ye1 = y->direction, ye2 = y->intensity;
                int swapped = v3_len(v3_sub(x->direction, ye1)) > 1e-4f;
                d = fmax(d, v3_len(v3_sub(x->position, ya)));
                d = fmax(d, v3_len(v3_sub(x->direction, swapped ? ye2 : ye1)));
                d = fmax(d, v3_len(v3_sub(x->intensity, swapped ? ye1 : ye2)));
            }
            if (d > worst) worst = d;
        }
        fprintf(stderr, "  lamps: 9 lights, worst difference to the copies' %.2g\n", worst);
        CHECK(worst < 1e-5);
    }
    render_scene_free(&ra);
    render_scene_free(&rb);
    scene_free(&a);
    scene_free(&b);
    error_clear(&err);
}

/* The mean of each 8 x 6 block of a 48 x 36 film (36 blocks) and of the whole. */
static void lamp_blocks(const float *rgb, double blocks[36], double *mean)
{
    memset(blocks, 0, 36 * sizeof *blocks);
    *mean = 0.0;
    for (uint y = 0; y < 36; y++)
        for (uint x = 0; x < 48; x++) {
            const float *c = rgb + 3 * (y * 48 + x);
            double v = (c[0] + c[1] + c[2]) / 3.0;
            blocks[(y / 6) * 6 + x / 8] += v / 48.0;
            *mean += v / (48.0 * 36.0);
        }
}

/* The worst relative difference of two images' blocks (relative to at least 0.05). */
static double blocks_differ(const double a[36], const double b[36])
{
    double worst = 0.0;
    for (int i = 0; i < 36; i++) {
        double rel = fabs(a[i] - b[i]) / (b[i] > 0.05 ? b[i] : 0.05);
        if (rel > worst) worst = rel;
    }
    return worst;
}

/* MIS, light sampling alone and BSDF sampling alone agree on the instanced lamps, and
 * MIS on the instances agrees with MIS on their copies. */
static void test_lamps_strategies_agree(void)
{
    static const char *const names[4] = { "MIS", "light sampling", "BSDF sampling", "copies (MIS)" };
    static const char scene_text[] = LAMPS(1024, 3);
    float *img[4];
    double blocks[4][36], mean[4];
    Error err = { 0 };
    for (uint m = 0; m < 4; m++) {
        Scene s;
        img[m] = malloc(48 * 36 * 3 * sizeof *img[m]);
        CHECK(load_text(scene_text, &s, &err) == ST_OK);
        if (m == 3) CHECK(scene_flatten_instances(&s, &err) == ST_OK);
        Status st = render_util_rgb_mis(&s, m == 3 ? MIS_BOTH : m, "scalar", img[m], &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        lamp_blocks(img[m], blocks[m], &mean[m]);
        scene_free(&s);
    }
    fprintf(stderr, "  lamps, 1024 spp: mean %s %.4f, %s %.4f, %s %.4f, %s %.4f; worst block difference to MIS: "
            "light %.1f%%, BSDF %.1f%%, copies %.1f%%\n", names[0], mean[0], names[1], mean[1], names[2], mean[2],
            names[3], mean[3], 100.0 * blocks_differ(blocks[1], blocks[0]), 100.0 * blocks_differ(blocks[2], blocks[0]),
            100.0 * blocks_differ(blocks[3], blocks[0]));
    CHECK(mean[0] > 0.05);
    for (uint m = 1; m < 4; m++) CHECK(fabs(mean[m] - mean[0]) < 0.01 * mean[0]);
    CHECK(blocks_differ(blocks[1], blocks[0]) < 0.05);
    CHECK(blocks_differ(blocks[2], blocks[0]) < 0.08);
    CHECK(blocks_differ(blocks[3], blocks[0]) < 0.03);
    for (uint m = 0; m < 4; m++) free(img[m]);
    error_clear(&err);
}

/* The noise of the lamps' light with MIS and with BSDF sampling alone, which is how the
 * instanced lamps were found before they were lights: the mean over pixels of each
 * pixel's variance over 8 renders of 4 samples with different seeds. */
static void test_lamps_less_noise(void)
{
    enum { RUNS = 8, N = 48 * 36 * 3 };
    static const char *const texts[RUNS] = { LAMPS(4, 1), LAMPS(4, 2), LAMPS(4, 3), LAMPS(4, 4),
                                             LAMPS(4, 5), LAMPS(4, 6), LAMPS(4, 7), LAMPS(4, 8) };
    double var[2];
    Error err = { 0 };
    float *img = malloc(N * sizeof *img);
    double *sum = calloc(N, sizeof *sum), *sum2 = calloc(N, sizeof *sum2);
    for (uint m = 0; m < 2; m++) {
        memset(sum, 0, N * sizeof *sum);
        memset(sum2, 0, N * sizeof *sum2);
        for (int r = 0; r < RUNS; r++) {
            Scene s;
            CHECK(load_text(texts[r], &s, &err) == ST_OK);
            CHECK(render_util_rgb_mis(&s, m == 0 ? MIS_BOTH : MIS_BSDF_ONLY, "scalar", img, &err) == ST_OK);
            for (int i = 0; i < N; i++) sum[i] += img[i], sum2[i] += (double)img[i] * img[i];
            scene_free(&s);
        }
        var[m] = 0.0;
        for (int i = 0; i < N; i++) var[m] += (sum2[i] - sum[i] * sum[i] / RUNS) / (RUNS - 1) / N;
    }
    fprintf(stderr, "  lamps, 4 spp: mean pixel variance MIS %.4g, BSDF sampling alone %.4g (%.1fx)\n", var[0],
            var[1], var[1] / var[0]);
    CHECK(var[0] * 10.0 < var[1]);
    free(img);
    free(sum);
    free(sum2);
    error_clear(&err);
}

/* Spheres of objects as sphere lights, and a squashed one as no light (BULBS). */
static void test_bulbs_are_sphere_lights(void)
{
    static const char instanced[] = BULBS(1024);
    /* the same spheres in the world: centre M (0 0.2 0), radius 0.3 times the scale */
    char world[2048];
    double a = 20.0 * M_PI / 180.0;
    snprintf(world, sizeof world, BULB_HEAD(1024) "sphere { center -1 1.66 0 radius 0.24 material glow }\n"
             "sphere { center 1.2 %.9f %.9f radius 0.36 material glow }\n", 1.2 + 0.24 * cos(a), 0.5 + 0.24 * sin(a));
    Error err = { 0 };
    Scene s;
    RenderScene rs;
    CHECK(load_text(instanced, &s, &err) == ST_OK);
    CHECK_MSG(render_scene_prepare(&s, 1, &rs, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_lights, 2);
    if (s.n_lights == 2) {
        CHECK(fabsf(s.lights[0].atten0 - 0.24f) < 1e-6f && fabsf(s.lights[1].atten0 - 0.36f) < 1e-6f);
        CHECK(fabsf(s.lights[0].position.y - 1.66f) < 1e-6f);
    }
    render_scene_free(&rs);
    scene_free(&s);
    const char *texts[4] = { instanced, instanced, instanced, world };
    double blocks[4][36], mean[4];
    float *img = malloc(48 * 36 * 3 * sizeof *img);
    for (uint m = 0; m < 4; m++) {
        CHECK(load_text(texts[m], &s, &err) == ST_OK);
        CHECK_MSG(render_util_rgb_mis(&s, m == 3 ? MIS_BOTH : m, "scalar", img, &err) == ST_OK, "%s", err.msg);
        lamp_blocks(img, blocks[m], &mean[m]);
        scene_free(&s);
    }
    fprintf(stderr, "  bulbs, 1024 spp: mean MIS %.4f, light %.4f, BSDF %.4f, world spheres %.4f; worst block "
            "difference to MIS: light %.1f%%, BSDF %.1f%%, world %.1f%%\n", mean[0], mean[1], mean[2], mean[3],
            100.0 * blocks_differ(blocks[1], blocks[0]), 100.0 * blocks_differ(blocks[2], blocks[0]),
            100.0 * blocks_differ(blocks[3], blocks[0]));
    CHECK(mean[0] > 0.02);
    for (uint m = 1; m < 4; m++) CHECK(fabs(mean[m] - mean[0]) < 0.01 * mean[0]);
    CHECK(blocks_differ(blocks[1], blocks[0]) < 0.05);
    CHECK(blocks_differ(blocks[2], blocks[0]) < 0.08);
    CHECK(blocks_differ(blocks[3], blocks[0]) < 0.03);

    /* the squashed bulb: a light of no power, and MIS still agrees with BSDF sampling */
    static const char squashed[] = BULBS(1024) BULB_SQUASHED;
    CHECK(load_text(squashed, &s, &err) == ST_OK);
    CHECK_MSG(render_scene_prepare(&s, 1, &rs, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_lights, 3);
    if (s.n_lights == 3) CHECK(s.lights[2].pick_pdf == 0.0f && s.lights[0].pick_pdf > 0.0f);
    render_scene_free(&rs);
    scene_free(&s);
    for (uint m = 0; m < 2; m++) {
        CHECK(load_text(squashed, &s, &err) == ST_OK);
        CHECK(render_util_rgb_mis(&s, m == 0 ? MIS_BOTH : MIS_BSDF_ONLY, "scalar", img, &err) == ST_OK);
        lamp_blocks(img, blocks[m], &mean[m]);
        scene_free(&s);
    }
    fprintf(stderr, "  squashed bulb: mean MIS %.4f, BSDF %.4f\n", mean[0], mean[1]);
    CHECK(fabs(mean[1] - mean[0]) < 0.01 * mean[0]);
    free(img);
    error_clear(&err);
}

/* An emissive sphere of an object whose only instance replaces its material makes no
 * light, and then no instance has lights: the sphere names none either (surface_instanced
 * would read the empty instance_lights; this crashed). Its image is the dark replacing
 * material's, lit by nothing but the background. */
static void test_replaced_bulb_is_no_light(void)
{
    static const char text[] =
        "image { width 16 height 12 spp 2 }\n"
        "camera { from 0 3 6 at 0 0.6 0 fov 40 }\n"
        "background { color 0.5 0.5 0.5 }\n"
        "material grey { type diffuse albedo 0.5 0.5 0.5 }\n"
        "material hot { type emissive radiance 4 6 8 }\n"
        "plane { point 0 0 0 normal 0 1 0 material grey }\n"
        "object ball { sphere { center 0 0 0 radius 0.5 material hot } }\n"
        "instance ball { translate 0 1 0 material grey }\n";
    Scene s;
    Error err = { 0 };
    float img[16 * 12 * 3];
    CHECK(load_text(text, &s, &err) == ST_OK);
    CHECK_MSG(render_util_rgb_mis(&s, MIS_BOTH, "scalar", img, &err) == ST_OK, "%s", err.msg);
    CHECK(s.n_lights == 0 && s.instance_lights == NULL);
    for (uint i = 0; i < s.n_spheres; i++) CHECK(s.spheres[i].light == NO_INDEX);
    float top = 0.0f;
    for (int i = 0; i < 16 * 12 * 3; i++) top = img[i] > top ? img[i] : top;
    CHECK(top <= 0.5f);
    scene_free(&s);
    error_clear(&err);
}

/* The choice of a directional light reads the scene's radius, which counts the world
 * boxes of the instances: under axis-aligned scales and translations those are the
 * copies' bounds, so the light is chosen with the copies' probability, and the far
 * instance makes it far likelier than the world's own primitives alone would. */
static void test_radius_counts_instances(void)
{
    static const char text[] =
        "camera { from 0 4 9 at 0 0 0 fov 40 }\n"
        "image { width 8 height 8 spp 1 }\n"
        "material grey { type diffuse albedo 0.5 0.5 0.5 }\n"
        "material lamp { type emissive radiance 5 5 5 }\n"
        "quad { v0 -0.5 3 -0.5 v1 0.5 3 -0.5 v2 0.5 3 0.5 v3 -0.5 3 0.5 material lamp }\n"
        "light { type directional direction 0 -1 0 intensity 1 1 1 }\n"
        "object block { box { min -1 0 -1 max 1 1 1 material grey } }\n"
        "instance block { scale 2 1 3 translate 40 0 -10 }\n"
        "instance block { translate -5 0 0 }\n";
    Scene a, b, c;
    Error err = { 0 };
    CHECK(load_text(text, &a, &err) == ST_OK);
    CHECK(load_text(text, &b, &err) == ST_OK);
    CHECK(scene_flatten_instances(&b, &err) == ST_OK);
    CHECK(scene_prepare_lights(&a, &err) == ST_OK && scene_prepare_lights(&b, &err) == ST_OK);
    /* without the instances: the quad alone bounds the world */
    CHECK(load_text(text, &c, &err) == ST_OK);
    c.n_instances = 0;
    CHECK(scene_prepare_lights(&c, &err) == ST_OK);
    CHECK_EQ_INT(a.n_lights, 3);
    CHECK_EQ_INT(b.n_lights, 3);
    if (a.n_lights == 3 && b.n_lights == 3 && c.n_lights == 3) {
        float pa = a.lights[2].pick_pdf, pb = b.lights[2].pick_pdf, pc = c.lights[2].pick_pdf;
        fprintf(stderr, "  directional light chosen with %.6f (copies %.6f; without instances %.6f)\n", pa, pb, pc);
        CHECK(a.lights[2].type == LIGHT_DIRECTIONAL && fabsf(pa - pb) <= 1e-6f * pb);
        CHECK(pa > 10.0f * pc);
    }
    scene_free(&a);
    scene_free(&b);
    c.n_instances = 2;
    scene_free(&c);
    error_clear(&err);
}

/* ------------------------------------------------------------------ hits */

static uint32_t rng_state = 12345u;
static float frand(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) * (1.0f / 16777216.0f);
}

/* The closest hit of ray over every primitive of the world and of every instance, each
 * tested in its own space as the walk tests it, by the walk's tie rule. */
static Hit brute_force(const Scene *s, const SceneView *sv, const RenderScene *rs, Ray ray)
{
    Hit best = hit_none(ray);
    trace_planes(sv, ray, 0, &best);
    uint8_t *mask = NULL;
    Error err = { 0 };
    scene_object_mask(s, &mask, &err);
    for (size_t i = 0; i < rs->n_instances; i++) {
        const Instance *x = &rs->instances[i];
        Ray r = instance_ray(x, ray);
        RayPre rp;
        ray_prepare(r, &rp);
        uint inst = (x->flags & INST_WORLD) ? NO_INDEX : (uint)i;
        for (uint id = 0; id < scene_first_plane(s); id++) {
            int in_obj = mask && mask[id];
            if (inst == NO_INDEX ? in_obj : !in_obj) continue;
            if (inst != NO_INDEX) {
                uint lo[OBJ_KINDS], hi[OBJ_KINDS];
                size_t n = scene_object_ranges(s, s->instance_objects[i], lo, hi), k;
                for (k = 0; k < n && !(id >= lo[k] && id < hi[k]); k++) continue;
                if (k == n) continue;
            }
            Ray rr = r;
            rr.tmax = leaf_tmax(&best);
            Hit h;
            if (trace_prim(sv, id, &rp, rr, &h) && hit_wins(&best, h.t, id, inst)) hit_take(&best, h, id, inst);
        }
    }
    free(mask);
    return best;
}

/* The world normal of hit h computed from the instance's transform in double: the
 * triangle's transformed corners' winding normal, the ellipsoid's gradient. */
static vec3 normal_double(const Scene *s, const RenderScene *rs, Ray ray, Hit h)
{
    const Instance *x = h.inst == NO_INDEX ? NULL : &rs->instances[h.inst];
    Transform m = transform_identity();
    if (x)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) m.m[i][j] = x->to_world[4 * i + j];
    uint first_tri = scene_first_triangle(s), first_box = scene_first_box(s);
    double n[3];
    if (h.prim >= first_tri && h.prim < first_box) {
        const Triangle *t = &s->triangles[h.prim - first_tri];
        vec3 a = transform_point(&m, t->p0), b = transform_point(&m, t->p1), c = transform_point(&m, t->p2);
        double e1[3] = { (double)b.x - a.x, (double)b.y - a.y, (double)b.z - a.z };
        double e2[3] = { (double)c.x - a.x, (double)c.y - a.y, (double)c.z - a.z };
        /* a mirror keeps the outward side (the copy's corners swapped) */
        double sg = transform_det(&m) < 0.0 ? -1.0 : 1.0;
        n[0] = sg * (e1[1] * e2[2] - e1[2] * e2[1]);
        n[1] = sg * (e1[2] * e2[0] - e1[0] * e2[2]);
        n[2] = sg * (e1[0] * e2[1] - e1[1] * e2[0]);
    } else {
        /* sphere or box: the object normal by the normal matrix */
        double nm[3][3];
        transform_normal_matrix(&m, nm);
        Ray r = x ? instance_ray(x, ray) : ray;
        vec3 po = v3_madd(r.o, r.d, h.t), no;
        if (h.prim < first_tri) {
            no = v3_sub(po, s->spheres[h.prim].center);
        } else {
            int face = (int)h.u, axis = face >> 1;
            float sg = (face & 1) ? 1.0f : -1.0f;
            no = v3(axis == 0 ? sg : 0.0f, axis == 1 ? sg : 0.0f, axis == 2 ? sg : 0.0f);
        }
        for (int i = 0; i < 3; i++) n[i] = nm[i][0] * no.x + nm[i][1] * no.y + nm[i][2] * no.z;
    }
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return v3((float)(n[0] / len), (float)(n[1] / len), (float)(n[2] / len));
}

/* The walk against brute_force on 20,000 random rays through the instances of `text`,
 * and every hit's world normal against normal_double. */
static void hits_against_brute_force(const char *text, uint accel)
{
    Scene s;
    Error err = { 0 };
    RenderScene rs;
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    s.accel = accel;
    CHECK_MSG(render_scene_prepare(&s, 1, &rs, &err) == ST_OK, "%s", err.msg);
    rng_state = 12345u;   /* the same rays through either tree */
    SceneView sv;
    device_scene_view(&rs.ds, &sv);
    int rays = 20000, hits = 0, same = 0, any_ok = 0, normals_ok = 0, inst_hits = 0;
    double worst = 0.0;
    for (int i = 0; i < rays; i++) {
        Ray ray;
        ray.o = v3(frand() * 10.0f - 5.0f, frand() * 3.0f, frand() * 10.0f - 5.0f);
        ray.d = v3(frand() * 2.0f - 1.0f, frand() * 2.0f - 1.0f, frand() * 2.0f - 1.0f);
        ray.tmin = 0.0f;
        ray.tmax = 1e30f;
        Hit h = trace_closest(&sv, ray), b = brute_force(&s, &sv, &rs, ray);
        int eq = h.prim == b.prim && h.inst == b.inst && h.t == b.t && h.u == b.u && h.v == b.v;
        same += eq;
        if (!eq && i - same < 5)
            fprintf(stderr, "    ray %d: walk prim %u inst %u t %a, brute force prim %u inst %u t %a\n", i, h.prim,
                    h.inst, (double)h.t, b.prim, b.inst, (double)b.t);
        any_ok += trace_any(&sv, ray) == (b.prim != NO_INDEX);
        if (h.prim == NO_INDEX || h.prim >= scene_first_plane(&s)) continue;
        hits++;
        inst_hits += h.inst != NO_INDEX;
        Surface sf = surface_at(&sv, ray, h);
        vec3 nd = normal_double(&s, &rs, ray, h);
        double c = (double)sf.ng.x * nd.x + (double)sf.ng.y * nd.y + (double)sf.ng.z * nd.z;
        if (1.0 - c > worst) worst = 1.0 - c;
        normals_ok += c > 1.0 - 1e-5;
    }
    fprintf(stderr, "  %s: %d rays, %d hits (%d through instances): %d as brute force, %d any-hit right, %d normals "
            "within 1e-5 (worst 1 - cos %.2g)\n", accel == ACCEL_BVH ? "BVH" : "kd-tree", rays, hits, inst_hits, same,
            any_ok, normals_ok, worst);
    CHECK(inst_hits > 1000);
    CHECK(same == rays);
    CHECK(any_ok == rays);
    CHECK(normals_ok == hits);
    render_scene_free(&rs);
    scene_free(&s);
}

static void test_hits_against_brute_force(void)
{
    for (uint accel = 0; accel < 2; accel++)
        hits_against_brute_force(HEAD "instance thing { translate 2.6 0 0 ry 37 }\n"
                                  "instance thing { translate -2.6 0.2 0.5 rotate 1 1 0 25 scale 0.6 1.7 0.9 }\n"
                                  "instance thing { translate 0 0 -2 scale -1 1 1 rz 10 }\n"
                                  "instance thing { matrix 1 0.4 0 0.5  0 1 0.3 0  0.2 0 1 1.5  0 0 0 1 }\n",
                                 accel ? ACCEL_KDTREE : ACCEL_BVH);
}

/* Nested instances, three objects deep, under mirrors, non-uniform scales, shears and
 * rotations at every level: the world instances they resolve to hit and shade as any. */
static void test_nested_hits_against_brute_force(void)
{
    for (uint accel = 0; accel < 2; accel++)
        hits_against_brute_force(HEAD "object pair {\n"
                                  "  instance thing { matrix 1 0.4 0 0.5  0 1 0.3 0  0.2 0 1 0  0 0 0 1 }\n"
                                  "  instance thing { scale -0.6 1.3 0.8 ry 30 translate 1 0 0 }\n"
                                  "}\n"
                                  "object rack {\n"
                                  "  instance pair { rotate 1 1 0 25 scale 0.7 1.2 0.9 }\n"
                                  "  instance pair { scale 1 1 -1 translate 0 0 -2 }\n"
                                  "}\n"
                                  "instance rack { matrix 1 0 0.3 0  0 1 0 0.2  0 0.25 1 0.5  0 0 0 1 }\n"
                                  "instance rack { scale 0.5 0.8 0.5 rz 10 translate -2.5 0 1 }\n",
                                 accel ? ACCEL_KDTREE : ACCEL_BVH);
}

/* A top level of many instances (a 24 x 24 grid of the object, rotated and scaled, a
 * row mirrored) is cut into fuller nodes (bvh_collapse.c, pack_measure): 128 here, where the
 * greedy cut made 165 and at least (n - 1) / 7 = 83 are needed (the binary tree's
 * shape and the weight on area keep it from that); and it is walked as the brute force
 * walks it. */
static void test_top_level_packed(void)
{
    char *text = malloc(64 * 1024);
    size_t at = (size_t)snprintf(text, 64 * 1024, "%s", HEAD);
    for (int i = 0; i < 24 * 24; i++)
        at += (size_t)snprintf(text + at, 64 * 1024 - at, "instance thing { scale %s%.2f %.2f 0.3 ry %d translate %.1f 0 %.1f }\n",
                               i / 24 == 5 ? "-" : "", 0.3 + 0.01 * (i % 7), 0.2 + 0.02 * (i % 5), (i * 37) % 360,
                               -6.0 + 0.5 * (i % 24), -6.0 + 0.5 * (i / 24));
    Scene s;
    Error err = { 0 };
    RenderScene rs;
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_scene_prepare(&s, 1, &rs, &err) == ST_OK, "%s", err.msg);
    uint n = (uint)rs.n_instances, least = (n - 1u + 6u) / 7u;
    fprintf(stderr, "  %u instances: %u top-level nodes (at least %u), the walk's stack %u\n", n, rs.levels.top_nodes,
            least, rs.levels.top.max_stack);
    CHECK(rs.levels.top_nodes * 10u <= least * 16u);
    render_scene_free(&rs);
    scene_free(&s);
    hits_against_brute_force(text, ACCEL_BVH);
    hits_against_brute_force(text, ACCEL_KDTREE);   /* 577 prototype walks from one top level */
    free(text);
}

/* The compressed top level (BvhTopNode, host/accel/bvh_top.c): over 4,000 nodes of
 * random child boxes of every size and place (1e-30 to 1e30 from the origin, extents
 * from 0 to 1e30, a child much smaller than its siblings, planes one ulp apart), every
 * plane the kernels decode (bvh_top_plane, their very expression) holds its child's:
 * lower planes at or below, upper at or above. And they stay tight: a plane is within
 * two steps of its child's, the step at most twice the node's extent / 254 (the
 * exponent's choice), where the 2^-100 floor of the step allows. */
static void test_top_level_compressed(void)
{
    enum { NODES = 4096 };
    Bvh t;
    memset(&t, 0, sizeof t);
    t.nodes = calloc(NODES, sizeof *t.nodes);
    t.n_nodes = NODES;
    for (uint i = 0; i < NODES; i++) {
        BvhNode *nd = &t.nodes[i];
        uint n = 1u + (uint)(frand() * 8.0f) % 8u;
        float scale = powf(10.0f, -30.0f + 60.0f * frand()), at = scale * (frand() * 20.0f - 10.0f);
        for (uint l = 0; l < BVH_WIDTH; l++) {
            for (int k = 0; k < 3; k++) {
                float lo = at + scale * (frand() - 0.5f), ext = scale * frand();
                if (l == 1u) ext *= 1e-6f;                       /* a small sibling */
                if (l == 2u) ext = 0.0f;                         /* a flat one */
                if (l == 3u) ext = nextafterf(lo, INFINITY) - lo;   /* one ulp */
                nd->box[2 * k][l] = l < n ? lo : INFINITY;
                nd->box[2 * k + 1][l] = l < n ? lo + ext : -INFINITY;
            }
            nd->kind[l] = l < n ? (l % 2u ? BVH_CHILD_INSTANCE : BVH_CHILD_NODE) : BVH_CHILD_NONE;
            nd->ref[l] = l < n ? i * 8u + l : 0u;
        }
    }
    BvhTopNode *c = NULL;
    Error err = { 0 };
    CHECK_MSG(bvh_top_compress(&t, &c, &err) == ST_OK, "%s", err.msg);
    size_t held = 0, planes = 0, tight = 0;
    for (uint i = 0; c && i < NODES; i++) {
        const BvhNode *nd = &t.nodes[i];
        uint n = c[i].meta >> 24;
        CHECK(n == 0u || nd->kind[n - 1u] != BVH_CHILD_NONE);
        for (uint l = 0; l < n; l++) {
            uint want = nd->kind[l] == BVH_CHILD_INSTANCE ? nd->ref[l] | BVH_TOP_INSTANCE : nd->ref[l];
            CHECK(c[i].ref[l] == want);
            for (uint r = 0; r < 6u; r++) {
                uint k = r / 2u, e = (c[i].meta >> (8u * k)) & 0xffu;
                uint q = (c[i].q[r][l / 4u] >> (8u * (l % 4u))) & 0xffu;
                float v = bvh_top_plane(c[i].offset[k], e, q), want_v = nd->box[r][l];
                held += (r % 2u) ? v >= want_v : v <= want_v;
                planes++;
                float node_lo = INFINITY, node_hi = -INFINITY;
                for (uint m = 0; m < n; m++) {
                    node_lo = fminf(node_lo, nd->box[2u * k][m]);
                    node_hi = fmaxf(node_hi, nd->box[2u * k + 1u][m]);
                }
                double step = ldexp(1.0, (int)e - 150);
                /* 254: the planes lie on a grid of the step (the offset's float
                 * holds no finer), so the least lower plane may start up to a step
                 * below its child's, and 255 steps must span the extent and that */
                int step_ok = step <= fmax(2.0 * ((double)node_hi - (double)node_lo) / 254.0, 0x1p-100) * 1.0000001;
                tight += step_ok && fabs((double)v - (double)want_v) <= 2.0 * step;
            }
        }
    }
    fprintf(stderr, "  %d compressed nodes: %zu of %zu planes hold their child's, %zu tight\n", NODES, held, planes,
            tight);
    CHECK(held == planes && planes > 0);
    CHECK(tight == planes);
    free(c);
    free(t.nodes);
}

/* The compressed top level holds finite boxes within 2^110 (bvh_top.h): an instance
 * whose world box reaches beyond, or overflows floats, is refused when the tree is
 * built, naming the instance and its object, rather than decoded to infinite planes
 * (a child never entered) or given a box that does not hold it. */
static void test_top_level_refuses_far_boxes(void)
{
    static const struct {
        const char *text, *want;
    } cases[] = {
        { HEAD "instance thing { }\ninstance thing { scale 1e34 }\n",
          "instance 1 (of object 'thing'): its world box reaches 1.30002e+34, beyond the 1.29807e+33 (2^110) instanced "
          "scenes hold" },
        { HEAD "instance thing { translate 3.4028e38 0 0 }\n",
          "instance 0 (of object 'thing'): its world box does not fit in floats" },
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        Scene s;
        RenderScene rs;
        Error err = { 0 };
        CHECK_MSG(load_text(cases[c].text, &s, &err) == ST_OK, "%s", err.msg);
        Status st = render_scene_prepare(&s, 1, &rs, &err);
        CHECK_MSG(st == ST_INPUT, "case %zu: status %d", c, st);
        CHECK_MSG(strcmp(err.msg, cases[c].want) == 0, "case %zu:\n    got:      %s\n    expected: %s", c, err.msg,
                  cases[c].want);
        if (st == ST_OK) render_scene_free(&rs);
        scene_free(&s);
        error_clear(&err);
    }
    /* and 2^100 from the origin still renders: its boxes are held */
    Film f;
    Error err = { 0 };
    CHECK_MSG(render(HEAD "instance thing { }\ninstance thing { translate 1e30 0 0 }\n", "scalar", 0, ACCEL_BVH, &f,
                     &err) == ST_OK, "%s", err.msg);
    film_free(&f);
    error_clear(&err);
}

/* Surfaces through instances are in the world: a hit point lies on the ray, and a ray
 * leaving it by its error bound does not find the same surface again. */
static void test_spawn_leaves_surface(void)
{
    static const char text[] = HEAD "instance thing { translate 1000 0 0 rotate 0 1 1 33 scale 3 0.2 7 }\n"
                                    "instance thing { translate 0.001 0 0 scale 1e-3 2e-3 1e-3 }\n";
    Scene s;
    Error err = { 0 };
    RenderScene rs;
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_scene_prepare(&s, 1, &rs, &err) == ST_OK, "%s", err.msg);
    SceneView sv;
    device_scene_view(&rs.ds, &sv);
    int tried = 0, self = 0;
    for (int i = 0; i < 40000; i++) {
        int far = i & 1;
        vec3 c = far ? v3(1000.0f, 0.0f, 0.0f) : v3(0.001f, 0.0f, 0.0f);
        float size = far ? 10.0f : 4e-3f;
        Ray ray;
        ray.o = v3_add(c, v3(size * (frand() * 2.0f - 1.0f), size * (1.0f + frand()), size * (frand() * 2.0f - 1.0f)));
        ray.d = v3_sub(v3_add(c, v3(size * (frand() - 0.5f), size * frand() * 0.5f, size * (frand() - 0.5f))), ray.o);
        ray.tmin = 0.0f;
        ray.tmax = 1e30f;
        Hit h = trace_closest(&sv, ray);
        if (h.inst == NO_INDEX) continue;
        tried++;
        Surface sf = surface_at(&sv, ray, h);
        vec3 n = v3_dot(ray.d, sf.ng) < 0.0f ? sf.ng : v3_neg(sf.ng);
        Ray out;
        out.o = spawn_origin(sf, n);
        out.d = v3(n.x + 0.3f * (frand() - 0.5f), n.y + 0.3f * (frand() - 0.5f), n.z + 0.3f * (frand() - 0.5f));
        out.tmin = 0.0f;
        out.tmax = 1e30f;
        Hit back = trace_closest(&sv, out);
        /* (a ray may leave a sphere or box inward and meet its far side: triangles only) */
        int tri = h.prim >= scene_first_triangle(&s) && h.prim < scene_first_box(&s);
        self += tri && back.prim == h.prim && back.inst == h.inst;
    }
    fprintf(stderr, "  %d rays leaving surfaces of instances 1e-3 and 1e3 from the origin: %d found their own "
            "primitive again\n", tried, self);
    CHECK(tried > 5000);
    CHECK(self == 0);
    render_scene_free(&rs);
    scene_free(&s);
}

int main(void)
{
    RUN(test_hits_against_brute_force);
    RUN(test_nested_hits_against_brute_force);
    RUN(test_top_level_packed);
    RUN(test_top_level_compressed);
    RUN(test_top_level_refuses_far_boxes);
    RUN(test_spawn_leaves_surface);
    RUN(test_nested_equals_flat);
    RUN(test_nested_furnace);
    RUN(test_identity_bit_identical);
    RUN(test_moved_matches_flattened);
    RUN(test_kdtree_prototypes);
    RUN(test_kdtree_bunnies);
    RUN(test_lamps_are_lights);
    RUN(test_lamps_strategies_agree);
    RUN(test_lamps_less_noise);
    RUN(test_bulbs_are_sphere_lights);
    RUN(test_replaced_bulb_is_no_light);
    RUN(test_radius_counts_instances);
    RUN(test_opencl_matches_scalar);
    return harness_report();
}
