/*
 * test_pbrt_motion.c — pbrt-v4's motion in clpt's reader (docs/pbrt.md#motion): the
 * two current transforms ActiveTransform picks between and TransformTimes dates; a
 * moving ObjectInstance, a moving Shape (made an object of its own) and a moving
 * camera against the average of still renders at fixed times; a turning instance at
 * one time at its own pose, not pbrt-v4's camera-pivoted one; a still scene with a
 * shutter and idle motion directives unchanged bit for bit; a scene like pbrt-v4's
 * killeroo-moving.pbrt (a spinning, sliding shape) read and rendered; a moving Shape
 * inside ObjectBegin/End moving within each of its instances, as pbrt-v4's does.
 * Bad input: tests/data/bad/pbrt-motion-* (test_bad_input.c). Run from the project root.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "render_util.h"
#include "io/scene_load.h"
#include "scene/motion.h"
#include "scene/transform.h"

static Status load_text(const char *text, Scene *s, Error *err)
{
    scene_init(s);
    return scene_load_bytes("tests/data/inline.pbrt", text, strlen(text), SCENE_FORMAT_AUTO, s, NULL, err);
}

static Status render_text(const char *text, Film *film, Error *err)
{
    return render_util_text_film("tests/data/inline.pbrt", text, SCENE_FORMAT_AUTO, "scalar", film, err);
}

enum { W = 40, H = 30, K = 8, SPP_STILL = 64 };

/* Each scene's head: %s the camera's transforms (before Camera), %s its parameters,
 * %u samples per pixel. */
#define HEAD                                                                             \
    "%s\n"                                                                               \
    "Camera \"perspective\" \"float fov\" 35 %s\n"                                       \
    "Film \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 30\n"               \
    "Sampler \"halton\" \"integer pixelsamples\" %u\n"                                   \
    "Integrator \"path\" \"integer maxdepth\" 3\n"                                       \
    "WorldBegin\n"                                                                       \
    "LightSource \"infinite\" \"rgb L\" [0.5 0.6 0.8]\n"                                 \
    "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"                           \
    "Shape \"trianglemesh\" \"point3 P\" [-10 0 -10 10 0 -10 10 0 10 -10 0 10]\n"         \
    "  \"integer indices\" [0 1 2 0 2 3]\n"                                              \
    "AttributeBegin\n"                                                                   \
    "  Material \"diffuse\" \"rgb reflectance\" [0.8 0.2 0.2]\n"                         \
    "  Translate 0 1 0\n"                                                                \
    "  Shape \"sphere\" \"float radius\" 1\n"                                            \
    "AttributeEnd\n"

#define LOOK "LookAt 0 1.4 -6  0 1 0  0 1 0"

/* An object whose turn shows: a yellow sphere and a blue slab beside it. */
#define THING                                                                            \
    "ObjectBegin \"thing\"\n"                                                            \
    "  Material \"diffuse\" \"rgb reflectance\" [0.9 0.9 0.2]\n"                         \
    "  Shape \"sphere\" \"float radius\" 0.5\n"                                          \
    "  Material \"diffuse\" \"rgb reflectance\" [0.2 0.2 0.9]\n"                         \
    "  Shape \"trianglemesh\" \"point3 P\" [0.3 -0.2 0 0.9 -0.2 0 0.9 0.2 0 0.3 0.2 0]\n" \
    "    \"integer indices\" [0 1 2 0 2 3]\n"                                            \
    "ObjectEnd\n"

/* Renders `moving` (K * SPP_STILL samples) and the K still scenes `still` writes for
 * the times u = (k + 1/2) / K; checks the moving image is their average within `tol`,
 * and far (> 0.1, relative to the middle one) from the middle still one, in 8 x 6
 * pixel blocks. */
static void check_average(const char *what, const char *moving, RenderUtilStillText still, double tol)
{
    Error err = { 0 };
    double worst, worst_mid;
    CHECK_MSG(render_util_motion_diffs(what, "tests/data/inline.pbrt", SCENE_FORMAT_AUTO, moving, still, K, 1, &worst,
                                       &worst_mid, &err) == ST_OK, "%s", err.msg);
    CHECK(worst < tol);
    CHECK(worst_mid > 0.1);
}

/* An ObjectInstance sliding, turning 120 degrees and growing by half between
 * TransformTimes 0 1: pbrt-v4 interpolates translation and scale linearly and the
 * rotation by slerp, so the still pose at u is Translate, Rotate 120u, Scale 1 + u/2. */
static void instance_still(double u, char *text, size_t size)
{
    snprintf(text, size, HEAD THING "Translate %.9g %.9g 0.5 Rotate %.9g 0 1 0 Scale %.9g %.9g %.9g\n"
             "ObjectInstance \"thing\"\n", LOOK, "", (unsigned)SPP_STILL, -1.2 + 2.4 * u, 2.0 + 0.2 * u, 120.0 * u,
             1.0 + 0.5 * u, 1.0 + 0.5 * u, 1.0 + 0.5 * u);
}

static void test_moving_instance_is_average_of_still(void)
{
    char text[8192];
    snprintf(text, sizeof text, HEAD THING "AttributeBegin\n"
             "  ActiveTransform StartTime\n  Translate -1.2 2 0.5\n"
             "  ActiveTransform EndTime\n  Translate 1.2 2.2 0.5\n  Rotate 120 0 1 0\n  Scale 1.5 1.5 1.5\n"
             "  ActiveTransform All\n"
             "  ObjectInstance \"thing\"\n"
             "AttributeEnd\n", LOOK, "", (unsigned)(K * SPP_STILL));
    Scene s;
    Error err = { 0 };
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_instances, 1);
    CHECK(s.n_instance_motion == 1 && s.instance_motion[0] == 0);
    CHECK_EQ_INT(s.n_motion_keys, 2);
    if (s.n_motion_keys == 2) {
        CHECK_NEAR(s.motion_keys[0].time, 0.0, 0.0);
        CHECK_NEAR(s.motion_keys[1].time, 1.0, 0.0);
    }
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    check_average("moving ObjectInstance", text, instance_still, 0.03);
}

/* A Shape outside any object under a moving transform (as pbrt-v4's killeroo-moving)
 * becomes an object of its own and a moving instance of it. TransformTimes 2 4 and the
 * shutter 2 4: the times are the file's. */
static void shape_still(double u, char *text, size_t size)
{
    snprintf(text, size, HEAD "Material \"diffuse\" \"rgb reflectance\" [0.9 0.9 0.2]\n"
             "Translate %.9g 2 0.5 Scale %.9g %.9g %.9g Shape \"sphere\" \"float radius\" 0.5\n", LOOK, "",
             (unsigned)SPP_STILL, -1.2 + 2.4 * u, 1.0 + u, 1.0 + u, 1.0 + u);
}

static void test_moving_shape_is_average_of_still(void)
{
    char text[8192];
    snprintf(text, sizeof text, "TransformTimes 2 4\n" HEAD "Material \"diffuse\" \"rgb reflectance\" [0.9 0.9 0.2]\n"
             "Translate -1.2 2 0.5\n"
             "ActiveTransform EndTime Translate 2.4 0 0 Scale 2 2 2 ActiveTransform All\n"
             "Shape \"sphere\" \"float radius\" 0.5\n",
             LOOK, "\"float shutteropen\" 2 \"float shutterclose\" 4", (unsigned)(K * SPP_STILL));
    Scene s;
    Error err = { 0 };
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_objects, 1);
    CHECK_EQ_INT(s.n_instances, 1);
    CHECK_EQ_INT(s.n_motion_keys, 2);
    if (s.n_motion_keys == 2) {
        CHECK_NEAR(s.motion_keys[0].time, 2.0, 0.0);
        CHECK_NEAR(s.motion_keys[1].time, 4.0, 0.0);
    }
    CHECK_NEAR(s.camera.shutter_open, 2.0, 0.0);
    CHECK_NEAR(s.camera.shutter_close, 4.0, 0.0);
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    check_average("moving Shape", text, shape_still, 0.03);
}

/* The camera's two transforms: a camera key at the end time. It slides 1.5 to its
 * left over the shutter (Translate before LookAt moves it in its own space). */
static void camera_still(double u, char *text, size_t size)
{
    char look[160];
    snprintf(look, sizeof look, "Translate %.9g 0 0 " LOOK, 1.5 * u);
    snprintf(text, size, HEAD, look, "", (unsigned)SPP_STILL);
}

static void test_moving_camera_is_average_of_still(void)
{
    char text[8192];
    snprintf(text, sizeof text, HEAD, "ActiveTransform EndTime Translate 1.5 0 0 ActiveTransform All " LOOK, "",
             (unsigned)(K * SPP_STILL));
    Scene s;
    Error err = { 0 };
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_camera_keys, 1);
    if (s.n_camera_keys == 1) CHECK_NEAR(s.camera_keys[0].time, 1.0, 0.0);
    CHECK_NEAR(s.camera.time, 0.0, 0.0);
    scene_free(&s);
    check_average("moving camera", text, camera_still, 0.03);
}

/* A turn seen at one time: a shutter open and closed at 0.8 shows the instance at
 * the pose of its own transform's decomposition, Rotate 96 about the instance's origin
 * (Shoemake's slerp, as pbrt-v4's AnimatedTransform), wherever the camera is. pbrt-v4
 * itself shows another pose there (docs/pbrt.md#motion): it decomposes the instance's
 * transform conjugated by its render space, a translation by the camera position c,
 * so its turn pivots on the camera: translation t + (1 - u) c + u R(120) c - R(120 u) c.
 * The render must be the first still one and far from the second. */
static void turn_at_fixed_time(char *text, size_t size, const char *camera, const char *instance)
{
    snprintf(text, size, HEAD THING "AttributeBegin\n%s\n  ObjectInstance \"thing\"\nAttributeEnd\n", LOOK, camera,
             (unsigned)SPP_STILL, instance);
}

static void test_turn_at_fixed_time_pivots_on_instance(void)
{
    const double u = 0.8, deg = 3.14159265358979323846 / 180.0, cam[3] = { 0.0, 1.4, -6.0 };
    char moving[8192], ours[8192], camera_pivot[8192], key[256];
    turn_at_fixed_time(moving, sizeof moving, "\"float shutteropen\" 0.8 \"float shutterclose\" 0.8",
                       "  ActiveTransform StartTime\n  Translate 0 1 0.5\n"
                       "  ActiveTransform EndTime\n  Translate 0 1 0.5\n  Rotate 120 0 1 0\n  ActiveTransform All");
    turn_at_fixed_time(ours, sizeof ours, "", "  Translate 0 1 0.5 Rotate 96 0 1 0");
    /* R(a) c about y: (c.x cos a + c.z sin a, c.y, -c.x sin a + c.z cos a). */
    double a1 = 120.0 * deg, au = 120.0 * u * deg;
    double shift_x = (1 - u) * cam[0] + u * (cam[0] * cos(a1) + cam[2] * sin(a1)) - (cam[0] * cos(au) + cam[2] * sin(au));
    double shift_z = (1 - u) * cam[2] + u * (-cam[0] * sin(a1) + cam[2] * cos(a1)) -
                     (-cam[0] * sin(au) + cam[2] * cos(au));
    snprintf(key, sizeof key, "  Translate %.9g 1 %.9g Rotate 96 0 1 0", shift_x, 0.5 + shift_z);
    turn_at_fixed_time(camera_pivot, sizeof camera_pivot, "", key);
    Film fm, fo, fp;
    Error err = { 0 };
    CHECK_MSG(render_text(moving, &fm, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_text(ours, &fo, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_text(camera_pivot, &fp, &err) == ST_OK, "%s", err.msg);
    size_t n = (size_t)W * H * 3u;
    float *m = malloc(n * sizeof *m), *o = malloc(n * sizeof *o), *pv = malloc(n * sizeof *pv);
    CHECK(m && o && pv);
    if (m && o && pv) {
        film_resolve(&fm, m);
        film_resolve(&fo, o);
        film_resolve(&fp, pv);
        double to_ours = render_util_block_diff(m, o, o, W, H, 8, 6);
        double to_pivot = render_util_block_diff(m, pv, o, W, H, 8, 6);
        printf("  turn at u = 0.8: %.4f from the instance-pivot still, %.4f from the camera-pivot one\n", to_ours,
               to_pivot);
        CHECK(to_ours < 0.01);
        CHECK(to_pivot > 0.1);
    }
    free(m);
    free(o);
    free(pv);
    film_free(&fm);
    film_free(&fo);
    film_free(&fp);
}

/* A still scene keeps its bits with a shutter, TransformTimes and ActiveTransform
 * that move nothing (both transforms changed alike). */
static void test_still_with_shutter_same_bits(void)
{
    char with[8192], without[8192];
    snprintf(with, sizeof with, "TransformTimes 0.5 3\n" HEAD "ActiveTransform StartTime Translate 0 0 1\n"
             "ActiveTransform EndTime Translate 0 0 1 ActiveTransform All\n" THING "ObjectInstance \"thing\"\n",
             "ActiveTransform All " LOOK, "\"float shutteropen\" 0.2 \"float shutterclose\" 0.7", 8u);
    snprintf(without, sizeof without, HEAD "Translate 0 0 1\n" THING "ObjectInstance \"thing\"\n", LOOK, "", 8u);
    Scene s;
    Error err = { 0 };
    CHECK_MSG(load_text(with, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_camera_keys, 0);
    CHECK(s.instance_motion == NULL);
    scene_free(&s);
    Film a, b;
    CHECK_MSG(render_text(with, &a, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_text(without, &b, &err) == ST_OK, "%s", err.msg);
    CHECK(film_sums_same(&a, &b) == (size_t)W * H * 3u);
    film_free(&a);
    film_free(&b);
}

/* As pbrt-v4-scenes' killeroo-moving.pbrt: a shape spinning about its own axis and
 * sliding (here a sphere and a slab in an object, and a bare sphere), under a camera
 * whose shutter is open half the time: read without warnings and rendered, finite, and
 * unlike the start pose. A moving light stands still, with a warning, as in pbrt-v4. */
static void test_killeroo_moving_like(void)
{
    char text[8192], still[8192];
#define KILLEROO_LIKE                                                                    \
        HEAD THING "AttributeBegin\n"                                                    \
        "  Translate 0 2 0.5\n"                                                          \
        "  ActiveTransform EndTime\n  Rotate 90 0 0 1\n  Translate 0.5 0 0\n  ActiveTransform All\n" \
        "  ObjectInstance \"thing\"\n"                                                 \
        "  Shape \"sphere\" \"float radius\" 0.3\n"                                    \
        "AttributeEnd\n"
    snprintf(text, sizeof text, KILLEROO_LIKE, LOOK, "\"float shutteropen\" 0 \"float shutterclose\" 0.5", 16u);
    snprintf(still, sizeof still, KILLEROO_LIKE, LOOK, "\"float shutteropen\" 0 \"float shutterclose\" 0", 16u);
    Scene s;
    Error err = { 0 };
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_instances, 2);
    CHECK_EQ_INT(s.n_motion_keys, 4);
    CHECK_EQ_INT(s.n_warnings, 0);
    scene_free(&s);
    Film a, b;
    CHECK_MSG(render_text(text, &a, &err) == ST_OK, "%s", err.msg);
    CHECK_MSG(render_text(still, &b, &err) == ST_OK, "%s", err.msg);
    size_t n = (size_t)W * H * 3;
    float *rgb = calloc(n, sizeof *rgb);
    film_resolve(&a, rgb);
    int finite = 1;
    for (size_t i = 0; i < n; i++) finite &= isfinite(rgb[i]) && rgb[i] >= 0;
    CHECK(finite);
    CHECK(film_sums_same(&a, &b) < n);
    free(rgb);
    film_free(&a);
    film_free(&b);

    snprintf(text, sizeof text, "WorldBegin\nActiveTransform EndTime Translate 1 0 0 ActiveTransform All\n"
             "LightSource \"point\" \"rgb I\" [1 1 1]\n");
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_warnings, 1);
    if (s.n_warnings == 1)
        CHECK_STR_CONTAINS(s.warnings[0], "inline.pbrt:3: a LightSource under a moving transform (ActiveTransform) "
                           "stands still at its start-time pose");
    scene_free(&s);
}

/* An object with a still red sphere and a yellow one that rises and grows inside it
 * (its own transforms: Translate 0.9 0 0, and at the end Translate 0.9 1 0 Scale
 * 2.5): pbrt-v4 moves such a shape within each instance (an AnimatedPrimitive in the
 * instance's BVH, src/pbrt/scene.cpp). %s: the instances. */
#define PARTS                                                                            \
    "ObjectBegin \"parts\"\n"                                                             \
    "  Material \"diffuse\" \"rgb reflectance\" [0.8 0.2 0.2]\n"                         \
    "  Shape \"sphere\" \"float radius\" 0.3\n"                                          \
    "  AttributeBegin\n"                                                                \
    "    Material \"diffuse\" \"rgb reflectance\" [0.9 0.9 0.2]\n"                       \
    "    Translate 0.9 0 0\n"                                                           \
    "    ActiveTransform EndTime Translate 0 1 0 Scale 2.5 2.5 2.5 ActiveTransform All\n" \
    "    Shape \"sphere\" \"float radius\" 0.25\n"                                       \
    "  AttributeEnd\n"                                                                  \
    "ObjectEnd\n%s"

static double transform_apart(const Transform *a, const Transform *b)
{
    double d = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) d = fmax(d, fabs(a->m[i][j] - b->m[i][j]));
    return d;
}

/* W times the part's own transform at time u (Translate 0.9 u 0, Scale 1 + 1.5u). */
static Transform part_pose(const Transform *w, double u)
{
    Transform t = transform_translate(0.9, u, 0), sc = transform_scale(1 + 1.5 * u, 1 + 1.5 * u, 1 + 1.5 * u);
    Transform c = transform_compose(&t, &sc);
    return transform_compose(w, &c);
}

/* Three instances of PARTS: under a still similarity (its part a moving instance of 2
 * keys, W C0 and W C1: exact), under a still non-uniform scale and under a sliding
 * transform (17 keys each, W(t) C(t) at each). Every one places the red sphere as a
 * still instance and the yellow one as a moving instance, with no warning; a key's
 * transform is W(t) C(t) at its time, and between keys within 1e-3. */
static void test_object_shape_moves_within_instances(void)
{
    char text[8192];
    snprintf(text, sizeof text, HEAD PARTS, LOOK, "", 16u,
             "AttributeBegin Translate -1.5 2 0.5 Rotate 30 0 1 0 ObjectInstance \"parts\" AttributeEnd\n"
             "AttributeBegin Translate 1.5 2 0.5 Scale 1 1.5 1 ObjectInstance \"parts\" AttributeEnd\n"
             "AttributeBegin Translate 0 3 0.5 ActiveTransform EndTime Translate 0.5 0 0 ActiveTransform All\n"
             "  ObjectInstance \"parts\"\nAttributeEnd\n");
    Scene s;
    Error err = { 0 };
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.n_warnings, 0);
    CHECK_EQ_INT(s.n_objects, 2);
    CHECK_EQ_INT(s.n_instances, 6);
    CHECK_EQ_INT(s.n_motion_keys, 2 + 17 + 2 + 17);   /* the third instance moves its red sphere too */
    Transform r = transform_rotate(0, 1, 0, 30), t = transform_translate(-1.5, 2, 0.5), sc = transform_scale(1, 1.5, 1),
              t2 = transform_translate(1.5, 2, 0.5), t3 = transform_translate(0, 3, 0.5);
    Transform w[3] = { transform_compose(&t, &r), transform_compose(&t2, &sc), t3 };
    const uint counts[3] = { 2, 17, 17 };
    for (int k = 0; k < 3 && s.n_instances == 6 && s.n_motion_keys == 38; k++) {
        uint inst = (uint)(2 * k + 1);
        CHECK(inst < s.n_instance_motion && s.instance_motion[inst] != NO_INDEX);
        if (k < 2) CHECK(2 * (size_t)k >= s.n_instance_motion || s.instance_motion[2 * k] == NO_INDEX);
        if (!(inst < s.n_instance_motion) || s.instance_motion[inst] == NO_INDEX) continue;
        const MotionKey *keys = s.motion_keys + s.instance_motion[inst];
        CHECK_EQ_INT(keys[0].count, counts[k]);
        const double times[4] = { 0.0, 0.5, 1.0, 0.53 };
        for (int j = 0; j < 4; j++) {
            Transform wt = w[k];
            if (k == 2) wt.m[0][3] += 0.5 * times[j];    /* the slide */
            Transform want = part_pose(&wt, times[j]), got = motion_transform_at(keys, counts[k], (float)times[j]);
            double d = transform_apart(&got, &want);
            /* 0.53 lies between keys of the 17; of the 2 (a similarity) it is exact */
            CHECK_MSG(d < (j == 3 && k > 0 ? 1e-3 : 2e-5), "instance %d at %g: %g from W(t) C(t)", k, times[j], d);
        }
    }
    scene_free(&s);

    /* an emitting moving Shape in an object is a light placed at each path's time, as a
     * bare one is (pbrt-v4 refuses any animated area light) */
    snprintf(text, sizeof text, HEAD "ObjectBegin \"lamp\"\n"
             "  AreaLightSource \"diffuse\" \"rgb L\" [4 4 4]\n"
             "  ActiveTransform EndTime Translate 0.5 0 0 ActiveTransform All\n"
             "  Shape \"trianglemesh\" \"point3 P\" [0 3 0 1 3 0 0 3 1] \"integer indices\" [0 2 1]\n"
             "ObjectEnd\nObjectInstance \"lamp\"\n", LOOK, "", 16u);
    CHECK_MSG(load_text(text, &s, &err) == ST_OK, "%s", err.msg);
    RenderScene rs;
    CHECK_MSG(render_scene_prepare(&s, 1, &rs, &err) == ST_OK, "%s", err.msg);
    uint moving = 0;
    for (size_t i = 0; i < s.n_lights; i++) moving += s.lights[i].type == LIGHT_MOVING;
    CHECK_EQ_INT(moving, 1);
    render_scene_free(&rs);
    scene_free(&s);
    error_clear(&err);
}

/* The yellow sphere moving within its instance against the average of 8 still renders
 * with it at its pose then. */
static void parts_still(double u, char *text, size_t size)
{
    snprintf(text, size, HEAD "ObjectBegin \"parts\"\n"
             "  Material \"diffuse\" \"rgb reflectance\" [0.8 0.2 0.2]\n"
             "  Shape \"sphere\" \"float radius\" 0.3\n"
             "  Material \"diffuse\" \"rgb reflectance\" [0.9 0.9 0.2]\n"
             "  Translate 0.9 %.9g 0 Scale %.9g %.9g %.9g Shape \"sphere\" \"float radius\" 0.25\n"
             "ObjectEnd\n"
             "Translate 1.2 1.6 -0.5 Rotate 30 0 1 0 ObjectInstance \"parts\"\n", LOOK, "", (unsigned)SPP_STILL,
             u, 1 + 1.5 * u, 1 + 1.5 * u, 1 + 1.5 * u);
}

static void test_object_shape_is_average_of_still(void)
{
    char text[8192];
    snprintf(text, sizeof text, HEAD PARTS, LOOK, "", (unsigned)(K * SPP_STILL),
             "Translate 1.2 1.6 -0.5 Rotate 30 0 1 0 ObjectInstance \"parts\"\n");
    check_average("moving Shape in an object", text, parts_still, 0.03);
}

/* The poses moving Shapes in objects take are bounded: 64 moving spheres in an object,
 * instanced 1000 times under a non-uniform scale (17 poses each), would take 1,088,000,
 * more than the 2^20 allowed: an error at the instance that passes it. */
static void test_object_shape_poses_bounded(void)
{
    size_t size = 64 * 120 + 1000 * 32 + 256, len = 0;
    char *text = malloc(size);
    len += (size_t)snprintf(text + len, size - len, "WorldBegin\nObjectBegin \"o\"\n");
    for (int i = 0; i < 64; i++)
        len += (size_t)snprintf(text + len, size - len, "AttributeBegin Translate %d 0 0 ActiveTransform EndTime "
                                "Translate 0 1 0 ActiveTransform All Shape \"sphere\" AttributeEnd\n", i);
    len += (size_t)snprintf(text + len, size - len, "ObjectEnd\nScale 1 2 1\n");
    for (int i = 0; i < 1000; i++) len += (size_t)snprintf(text + len, size - len, "ObjectInstance \"o\"\n");
    Scene s;
    Error err = { 0 };
    CHECK(load_text(text, &s, &err) == ST_INPUT);
    /* 963 instances take 963 x 64 x 17 = 1,047,744 poses; the 964th passes 2^20 */
    CHECK_STR_CONTAINS(err.msg, "inline.pbrt:1032:16: ObjectInstance \"o\": the moving Shapes in objects would take "
                       "more than 1048576 poses (2 per instance under a still similarity, else 17)");
    scene_free(&s);
    free(text);
    error_clear(&err);
}

/* A shutter that closes before it opens is swapped with a warning, as pbrt-v4 does. */
static void test_shutter_swapped(void)
{
    Scene s;
    Error err = { 0 };
    CHECK_MSG(load_text("Camera \"perspective\" \"float shutteropen\" 1 \"float shutterclose\" 0.25\nWorldBegin\n", &s,
                        &err) == ST_OK,
              "%s", err.msg);
    CHECK_NEAR(s.camera.shutter_open, 0.25, 0.0);
    CHECK_NEAR(s.camera.shutter_close, 1.0, 0.0);
    CHECK_EQ_INT(s.n_warnings, 1);
    if (s.n_warnings == 1)
        CHECK_STR_CONTAINS(s.warnings[0], "Camera \"shutterclose\" 0.25 is before \"shutteropen\" 1: they are swapped");
    scene_free(&s);
}

int main(void)
{
    RUN(test_moving_instance_is_average_of_still);
    RUN(test_moving_shape_is_average_of_still);
    RUN(test_moving_camera_is_average_of_still);
    RUN(test_turn_at_fixed_time_pivots_on_instance);
    RUN(test_still_with_shutter_same_bits);
    RUN(test_killeroo_moving_like);
    RUN(test_shutter_swapped);
    RUN(test_object_shape_moves_within_instances);
    RUN(test_object_shape_is_average_of_still);
    RUN(test_object_shape_poses_bounded);
    return harness_report();
}
