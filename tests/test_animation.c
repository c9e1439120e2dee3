/*
 * test_animation.c — animations (docs/animation.md): the keyed tracks' interpolation
 * (scene/keyframes.c) against values worked by hand; a glTF file's animation posed at
 * a time (io/gltf_anim.c) makes the same scene, and the same image bit for bit, as a
 * static file whose nodes hold the pose evaluated for that time (a mesh copied, a mesh
 * instanced, the camera), posed again after a render too; bad animations give their
 * exact messages with the JSON path. clpt's camera_path: its values between and at keys
 * (linear, step, Catmull-Rom), and a frame at a key renders as the camera block of the
 * key's values. The program's --frames is tested in test_cli_frames below: numbered
 * images that differ, the same on PoCL, a rerun that skips the frames written, a frame
 * resumed from its checkpoint, a camera path's frame, and the flags' errors. (The
 * camera_path's syntax errors are files in tests/data/bad/, test_bad_input.c.)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli_util.h"
#include "harness.h"
#include "io/gltf_anim.h"
#include "io/scene_load.h"
#include "outputs.h"
#include "render_util.h"
#include "scene/keyframes.h"

/* ------------------------------------------------------------------ tracks */

static void test_linear_and_step(void)
{
    static const double times[3] = { 0.0, 1.0, 3.0 };
    static const double values[9] = { 0, 0, 0, 1, 2, -4, 3, 2, 0 };
    KeyTrack k = { KEY_LINEAR, 3, 0, 3, times, values };
    double v[3];
    key_track_eval(&k, 0.25, v);
    CHECK(v[0] == 0.25 && v[1] == 0.5 && v[2] == -1.0);
    key_track_eval(&k, 2.0, v);   /* halfway from key 1 to key 2 */
    CHECK(v[0] == 2.0 && v[1] == 2.0 && v[2] == -2.0);
    key_track_eval(&k, -1.0, v);  /* before the first key: held */
    CHECK(v[0] == 0 && v[1] == 0 && v[2] == 0);
    key_track_eval(&k, 7.0, v);   /* after the last: held */
    CHECK(v[0] == 3 && v[1] == 2 && v[2] == 0);
    key_track_eval(&k, 1.0, v);   /* at a key: its value as it is */
    CHECK(v[0] == 1 && v[1] == 2 && v[2] == -4);
    k.interp = KEY_STEP;
    key_track_eval(&k, 2.999, v);
    CHECK(v[0] == 1 && v[1] == 2 && v[2] == -4);
    key_track_eval(&k, 0.999, v);
    CHECK(v[0] == 0 && v[1] == 0 && v[2] == 0);
    key_track_eval(&k, 3.0, v);
    CHECK(v[0] == 3);
}

static void test_slerp(void)
{
    /* 0 and 90 degrees about y: halfway is 45 degrees, a quarter 22.5, on the arc (a
     * linear blend would be off it before normalising, and at other angles after) */
    const double s45 = sin(M_PI / 8), c45 = cos(M_PI / 8);
    static const double times[2] = { 0.0, 2.0 };
    const double values[8] = { 0, 0, 0, 1, 0, sin(M_PI / 4), 0, cos(M_PI / 4) };
    KeyTrack k = { KEY_LINEAR, 4, 1, 2, times, values };
    double q[4];
    key_track_eval(&k, 1.0, q);
    CHECK_NEAR(q[0], 0, 1e-15);
    CHECK_NEAR(q[1], s45, 1e-15);
    CHECK_NEAR(q[2], 0, 1e-15);
    CHECK_NEAR(q[3], c45, 1e-15);
    key_track_eval(&k, 0.5, q);
    CHECK_NEAR(q[1], sin(M_PI / 16), 1e-15);
    CHECK_NEAR(q[3], cos(M_PI / 16), 1e-15);
    /* the shorter way: -q is the same rotation as q */
    const double flipped[8] = { 0, 0, 0, 1, 0, -sin(M_PI / 4), 0, -cos(M_PI / 4) };
    k.values = flipped;
    key_track_eval(&k, 1.0, q);
    CHECK_NEAR(fabs(q[1]), s45, 1e-15);
    CHECK_NEAR(fabs(q[3]), c45, 1e-15);
    CHECK(q[1] * q[3] > 0);
}

static void test_cubic_spline(void)
{
    /* keys 0 -> 1 over [0, 2], out-tangent 1 at key 0, in-tangent 0 at key 1: at u
     * = 1/2 the Hermite basis is h00 = 1/2, h10 = 1/8, h01 = 1/2, h11 = -1/8, so
     * p = 0/2 + 2 (1/8) 1 + 1/2 + 2 (-1/8) 0 = 0.75 (glTF 2.0, Appendix C.3) */
    static const double times[2] = { 0.0, 2.0 };
    static const double values[18] = {
        9, 9, 9, 0, 0, 0, 1, 0, -2,       /* key 0: in-tangent (unused), value, out-tangent */
        0, 4, 0, 1, 1, 1, 9, 9, 9,        /* key 1: in-tangent, value, out-tangent (unused) */
    };
    KeyTrack k = { KEY_CUBICSPLINE, 3, 0, 2, times, values };
    double v[3];
    key_track_eval(&k, 1.0, v);
    CHECK_NEAR(v[0], 0.75, 1e-15);
    /* y: 0 + 0 + 1/2 + 2 (-1/8) 4 = -0.5; z: 2 (1/8) (-2) + 1/2 = 0 */
    CHECK_NEAR(v[1], -0.5, 1e-15);
    CHECK_NEAR(v[2], 0.0, 1e-15);
    key_track_eval(&k, 2.0, v);
    CHECK(v[0] == 1 && v[1] == 1 && v[2] == 1);
    key_track_eval(&k, 0.0, v);
    CHECK(v[0] == 0 && v[1] == 0 && v[2] == 0);
}

/* ------------------------------------------------------------------ glTF */

static void base64(const unsigned char *in, size_t n, char *out)
{
    static const char abc[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        unsigned v = (unsigned)in[i] << 16 | (i + 1 < n ? (unsigned)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
        out[o++] = abc[v >> 18 & 63];
        out[o++] = abc[v >> 12 & 63];
        out[o++] = i + 1 < n ? abc[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? abc[v & 63] : '=';
    }
    out[o] = '\0';
}

/* The buffer: a triangle, key times, and each channel's values (floats). */
static const float anim_buffer[] = {
    /* 0: POSITION, 3 VEC3 */
    -0.5f, 0, 0, 0.5f, 0, 0, 0, 1, 0,
    /* 36: times, 3 */
    0, 1, 2,
    /* 48: translation, 3 VEC3 (LINEAR) */
    0, 0, 0, 1, 0.5f, 0, 1, 0.5f, -1,
    /* 84: rotation, 3 VEC4 (LINEAR: slerp): 0, 90 and 180 degrees about y */
    0, 0, 0, 1, 0, 0.70710678f, 0, 0.70710678f, 0, 1, 0, 0,
    /* 132: scale, 9 VEC3 (CUBICSPLINE: in-tangent, value, out-tangent per key) */
    0, 0, 0, 1, 1, 1, 0.5f, 0, 0,
    0, 0, 0, 1.5f, 1, 1, 0, 0, 0,
    0, 0, 0, 1, 1, 2, 0, 0, 0,
    /* 240: a second node's translation, 3 VEC3 (STEP) */
    2, 0, 0, 2, 1, 0, 2, 1, 1,
    /* 276: the camera's translation, 3 VEC3 (LINEAR) */
    0, 0.5f, 5, 0.5f, 0.5f, 5, 1, 1, 6,
    /* 312: a rotation, 6 VEC4 (CUBICSPLINE, two keys): q and -q with flat tangents,
     * which pass through zero halfway */
    0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0,
    0, 0, 0, 0, 0, 0, 0, -1, 0, 0, 0, 0,
};

static char anim_uri[600];

/* The accessors and buffer views of anim_buffer. */
#define ANIM_ACCESSORS                                                                                              \
    "\"accessors\":["                                                                                                \
    "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[-0.5,0,0],\"max\":[0.5,1,0]},"  \
    "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\",\"min\":[0],\"max\":[2]},"            \
    "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"                                       \
    "{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},"                                       \
    "{\"bufferView\":4,\"componentType\":5126,\"count\":9,\"type\":\"VEC3\"},"                                       \
    "{\"bufferView\":5,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"                                       \
    "{\"bufferView\":6,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"                                      \
    "{\"bufferView\":7,\"componentType\":5126,\"count\":6,\"type\":\"VEC4\"},"                                      \
    "{\"bufferView\":1,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"}],"                                   \
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":12},"         \
    "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":84,\"byteLength\":48},"        \
    "{\"buffer\":0,\"byteOffset\":132,\"byteLength\":108},{\"buffer\":0,\"byteOffset\":240,\"byteLength\":36},"     \
    "{\"buffer\":0,\"byteOffset\":276,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":312,\"byteLength\":96}],"

/* The animations: node 0 translated, rotated and scaled, node 2 stepped, the camera's
 * node 3 moved. `bad` replaces the first channel when not NULL. */
static void anim_json(char *out, size_t size, const char *first_channel, const char *extra_samplers)
{
    snprintf(out, size,
             "\"animations\":[{\"channels\":[%s,"
             "{\"sampler\":1,\"target\":{\"node\":0,\"path\":\"rotation\"}},"
             "{\"sampler\":2,\"target\":{\"node\":0,\"path\":\"scale\"}},"
             "{\"sampler\":3,\"target\":{\"node\":2,\"path\":\"translation\"}}]%s,"
             "\"samplers\":[{\"input\":1,\"output\":2},{\"input\":1,\"output\":3,\"interpolation\":\"LINEAR\"},"
             "{\"input\":1,\"output\":4,\"interpolation\":\"CUBICSPLINE\"},"
             "{\"input\":1,\"output\":5,\"interpolation\":\"STEP\"}%s]},"
             "{\"channels\":[{\"sampler\":0,\"target\":{\"node\":3,\"path\":\"translation\"}}],"
             "\"samplers\":[{\"input\":1,\"output\":6}]}],",
             first_channel ? first_channel : "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}", "",
             extra_samplers ? extra_samplers : "");
}

/* A document of four nodes: 0 the animated triangle (its mesh used once: copied), 1
 * and 2 one mesh twice (instances; 2 animated), 3 the camera; `nodes` are their
 * JSON objects, `anim` the animations (or ""). */
static void doc_json(char *out, size_t size, const char *nodes, const char *anim)
{
    snprintf(out, size,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3]}],\"nodes\":[%s],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]},"
             "{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"aspectRatio\":1.5}}],"
             "%s" ANIM_ACCESSORS "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}]}",
             nodes, anim, sizeof anim_buffer, anim_uri);
}

static const char anim_nodes[] = "{\"mesh\":0,\"translation\":[0,0,0]},{\"mesh\":1,\"translation\":[-2,0,0]},"
                                 "{\"mesh\":1},{\"camera\":0,\"translation\":[0,0.5,5]}";

static Status load_doc(const char *text, int animated, Scene *s, Error *err)
{
    scene_init(s);
    s->keep_animation = animated;
    Status st = scene_load_bytes("anim.gltf", text, strlen(text), SCENE_FORMAT_AUTO, s, NULL, err);
    s->image.width = 24;
    s->image.height = 16;
    s->image.spp = 2;
    s->image.max_depth = 3;
    return st;
}

static char *animated_doc(void)
{
    static char anim[4096];
    char *doc = malloc(16384);
    anim_json(anim, sizeof anim, NULL, NULL);
    doc_json(doc, 16384, anim_nodes, anim);
    return doc;
}

/* The static document of the pose at time t: every node's TRS as the animation
 * evaluates it, printed so that it reads back as the same doubles. */
static char *static_doc(GltfAnimated *a, double t)
{
    char nodes[4096], node[4][800];
    static const char *const rest[4] = { "\"mesh\":0", "\"mesh\":1", "\"mesh\":1", "\"camera\":0" };
    for (int n = 0; n < 4; n++) {
        double tr[3], r[4], sc[3];
        Error err = { 0 };
        CHECK(gltf_anim_node_trs(a, n, t, tr, r, sc, &err) == ST_OK);
        snprintf(node[n], sizeof node[n],
                 "{%s,\"translation\":[%.17g,%.17g,%.17g],\"rotation\":[%.17g,%.17g,%.17g,%.17g],"
                 "\"scale\":[%.17g,%.17g,%.17g]}", rest[n], tr[0], tr[1], tr[2], r[0], r[1], r[2], r[3], sc[0],
                 sc[1], sc[2]);
    }
    snprintf(nodes, sizeof nodes, "%s,%s,%s,%s", node[0], node[1], node[2], node[3]);
    char *doc = malloc(16384);
    doc_json(doc, 16384, nodes, "");
    return doc;
}

/* The film of the scene on the scalar device. */
static int render_sums(Scene *s, Film *film)
{
    Error err = { 0 };
    Status st = render_util_run(s, "scalar", 0, film, &err);
    CHECK_MSG(st == ST_OK, "render: %s", err.msg);
    return st == ST_OK;
}

static int films_equal(const Film *a, const Film *b)
{
    return a->width == b->width && a->height == b->height && a->samples == b->samples &&
           memcmp(a->sum, b->sum, (size_t)a->width * a->height * 3u * sizeof *a->sum) == 0;
}

/* The animated scene at time t against the static file of that pose: the same
 * triangles, instances and camera, and the same film. */
static void check_pose(Scene *moving, double t, const char *what)
{
    Error err = { 0 };
    Status st = moving->animation->pose(moving->animation, moving, t, &err);
    CHECK_MSG(st == ST_OK, "%s: pose: %s", what, err.msg);
    char *doc = static_doc((GltfAnimated *)moving->animation, t);
    Scene still;
    st = load_doc(doc, 0, &still, &err);
    CHECK_MSG(st == ST_OK, "%s: static: %s", what, err.msg);
    still.accel = moving->accel;
    CHECK_MSG(still.n_triangles == moving->n_triangles, "%s: %zu triangles, static %zu", what, moving->n_triangles,
              still.n_triangles);
    CHECK_MSG(still.n_instances == moving->n_instances, "%s: instances", what);
    if (still.n_triangles == moving->n_triangles)
        CHECK_MSG(memcmp(still.triangles, moving->triangles, still.n_triangles * sizeof *still.triangles) == 0,
                  "%s: triangles differ", what);
    if (still.n_instances == moving->n_instances)
        CHECK_MSG(memcmp(still.instances, moving->instances, still.n_instances * sizeof *still.instances) == 0,
                  "%s: instances differ", what);
    CHECK_MSG(memcmp(&still.camera, &moving->camera, sizeof still.camera) == 0, "%s: cameras differ", what);
    Film a, b;
    if (render_sums(moving, &a) && render_sums(&still, &b)) {
        CHECK_MSG(films_equal(&a, &b), "%s: the images differ", what);
        film_free(&b);
    }
    film_free(&a);
    scene_free(&still);
    free(doc);
}

static void test_pose_equals_static(void)
{
    char *doc = animated_doc();
    Scene s;
    Error err = { 0 };
    Status st = load_doc(doc, 1, &s, &err);
    CHECK_MSG(st == ST_OK, "load: %s", err.msg);
    if (st == ST_OK) {
        CHECK_NEAR(s.animation->end, 2.0, 0);
        /* node 0's triangle copied, mesh 1's object triangle placed twice */
        CHECK(s.n_triangles == 2 && s.n_instances == 2);
        /* frames of --fps 24 and 4, between keys and at one; each posed after the last
         * one's render (which prepared the scene: lights, its tree) */
        check_pose(&s, 13.0 / 24.0, "t = 13/24");
        check_pose(&s, 1.5, "t = 1.5");
        check_pose(&s, 1.0, "t = 1 (a key)");
        check_pose(&s, 0.25, "t = 0.25 (back)");
        s.accel = ACCEL_KDTREE;   /* the kd-tree's prototypes, posed again */
        check_pose(&s, 0.75, "kdtree t = 0.75");
        check_pose(&s, 1.75, "kdtree t = 1.75");
    }
    scene_free(&s);
    free(doc);
}

/* An animation of the camera's node alone keeps the geometry (SceneAnimation.camera_only)
 * and still gives the static file's camera and image. */
static void test_camera_only(void)
{
    static const char anim[] = "\"animations\":[{\"channels\":[{\"sampler\":0,\"target\":{\"node\":3,"
                               "\"path\":\"translation\"}}],\"samplers\":[{\"input\":1,\"output\":6}]}],";
    char *doc = malloc(16384);
    doc_json(doc, 16384, anim_nodes, anim);
    Scene s;
    Error err = { 0 };
    Status st = load_doc(doc, 1, &s, &err);
    CHECK_MSG(st == ST_OK, "load: %s", err.msg);
    if (st == ST_OK) {
        CHECK(s.animation->camera_only);
        check_pose(&s, 0.5, "camera only, t = 0.5");
        check_pose(&s, 1.75, "camera only, t = 1.75");
    }
    scene_free(&s);
    /* an animated node outside the scene's tree over 60 levels of children that repeat
     * (2^60 paths): each node is looked at once, and none shows anything */
    char nodes[8192];
    size_t at = (size_t)snprintf(nodes, sizeof nodes, "%s", anim_nodes);
    for (int k = 4; k < 64; k++)
        at += (size_t)snprintf(nodes + at, sizeof nodes - at, ",{\"children\":[%d,%d]}", k + 1, k + 1);
    snprintf(nodes + at, sizeof nodes - at, ",{}");
    static const char far_anim[] = "\"animations\":[{\"channels\":[{\"sampler\":0,\"target\":{\"node\":4,"
                                   "\"path\":\"translation\"}}],\"samplers\":[{\"input\":1,\"output\":6}]}],";
    doc_json(doc, 16384, nodes, far_anim);
    st = load_doc(doc, 1, &s, &err);
    CHECK_MSG(st == ST_OK, "far: %s", err.msg);
    CHECK(st != ST_OK || s.animation->camera_only);
    scene_free(&s);
    /* the document whose meshes move is no camera-only animation */
    free(doc);
    doc = animated_doc();
    st = load_doc(doc, 1, &s, &err);
    CHECK(st == ST_OK && !s.animation->camera_only);
    scene_free(&s);
    free(doc);
}

/* The pose the evaluation gives, by hand: node 0 at t = 0.5 is translated halfway to
 * (1, 0.5, 0), turned 45 degrees about y, and scaled by the cubic spline at u = 1/2:
 * x = 1/2 + (1/8) 0.5 + 1.5/2 = 1.3125 (h10 times the out-tangent 0.5, interval 1). */
static void test_node_pose(void)
{
    char *doc = animated_doc();
    Scene s;
    Error err = { 0 };
    Status st = load_doc(doc, 1, &s, &err);
    CHECK_MSG(st == ST_OK, "load: %s", err.msg);
    if (st == ST_OK) {
        GltfAnimated *a = (GltfAnimated *)s.animation;
        double tr[3], r[4], sc[3];
        CHECK(gltf_anim_node_trs(a, 0, 0.5, tr, r, sc, &err) == ST_OK);
        CHECK(tr[0] == 0.5 && tr[1] == 0.25 && tr[2] == 0);
        CHECK_NEAR(r[1], sin(M_PI / 8), 1e-7);
        CHECK_NEAR(r[3], cos(M_PI / 8), 1e-7);
        CHECK_NEAR(sc[0], 1.3125, 1e-12);
        CHECK_NEAR(sc[1], 1.0, 1e-12);
        /* node 2 steps: (2, 0, 0) until t = 1 */
        CHECK(gltf_anim_node_trs(a, 2, 0.99, tr, r, sc, &err) == ST_OK);
        CHECK(tr[0] == 2 && tr[1] == 0 && tr[2] == 0);
        CHECK(gltf_anim_node_trs(a, 2, 1.0, tr, r, sc, &err) == ST_OK);
        CHECK(tr[1] == 1);
        /* node 1 is not animated: its own translation */
        CHECK(gltf_anim_node_trs(a, 1, 0.5, tr, r, sc, &err) == ST_OK);
        CHECK(tr[0] == -2 && r[3] == 1 && sc[2] == 1);
        /* the world transform carries the node's translation */
        Transform w;
        CHECK(gltf_anim_node_world(a, 3, 2.0, &w, &err) == ST_OK);
        CHECK(w.m[0][3] == 1 && w.m[1][3] == 1 && w.m[2][3] == 6);
    }
    scene_free(&s);
    free(doc);
}

/* ------------------------------------------------------------------ bad animations */

static void check_bad(const char *first_channel, const char *extra_samplers, const char *message)
{
    static char anim[4096];
    char *doc = malloc(16384);
    anim_json(anim, sizeof anim, first_channel, extra_samplers);
    doc_json(doc, 16384, anim_nodes, anim);
    Scene s;
    Error err = { 0 };
    Status st = load_doc(doc, 1, &s, &err);
    CHECK_MSG(st == ST_INPUT, "%s: status %d", message, st);
    CHECK_MSG(strcmp(err.msg, message) == 0, "\n    got:      %s\n    expected: %s", err.msg, message);
    scene_free(&s);
    free(doc);
}

static void test_bad_animations(void)
{
    check_bad("{\"sampler\":0,\"target\":{\"node\":9,\"path\":\"translation\"}}", NULL,
              "anim.gltf: animations[0].channels[0].target.node: nodes[9] does not exist (the file has 4)");
    check_bad("{\"sampler\":7,\"target\":{\"node\":0,\"path\":\"translation\"}}", NULL,
              "anim.gltf: animations[0].channels[0].sampler: expected an integer from 0 to 3");
    check_bad("{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"color\"}}", NULL,
              "anim.gltf: animations[0].channels[0].target: path: expected translation, rotation, scale or weights");
    check_bad("{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"rotation\"}}", NULL,
              "anim.gltf: animations[0].samplers[0].output: accessor 2: type must be VEC4 here");
    check_bad("{\"sampler\":4,\"target\":{\"node\":1,\"path\":\"scale\"}}", ",{\"input\":1,\"output\":4}",
              "anim.gltf: animations[0].samplers[4].output: accessor 4 has 9 elements; the 3 key times of input "
              "ask for 3");
    check_bad("{\"sampler\":4,\"target\":{\"node\":1,\"path\":\"scale\"}}",
              ",{\"input\":1,\"output\":2,\"interpolation\":\"CUBIC\"}",
              "anim.gltf: animations[0].samplers[4].interpolation: expected LINEAR, STEP or CUBICSPLINE");
    check_bad("{\"sampler\":4,\"target\":{\"node\":1,\"path\":\"scale\"}}", ",{\"input\":5,\"output\":2}",
              "anim.gltf: animations[0].samplers[4].input: accessor 5: type must be SCALAR here");
    check_bad("{\"sampler\":4,\"target\":{\"node\":1,\"path\":\"scale\"}}", ",{\"input\":17,\"output\":2}",
              "anim.gltf: animations[0].samplers[4].input: accessors[17] does not exist (the file has 9)");
    check_bad("{\"sampler\":1,\"target\":{\"node\":0,\"path\":\"rotation\"}}", NULL,
              "anim.gltf: animations[0].channels[1].target: nodes[0].rotation is animated by an earlier channel "
              "already");
}

/* A node with a matrix cannot be animated; key times must increase. */
static void test_bad_documents(void)
{
    static char anim[4096];
    char *doc = malloc(16384);
    anim_json(anim, sizeof anim, NULL, NULL);
    doc_json(doc, 16384, "{\"mesh\":0,\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]},{\"mesh\":1},{\"mesh\":1},"
             "{\"camera\":0}", anim);
    Scene s;
    Error err = { 0 };
    CHECK(load_doc(doc, 1, &s, &err) == ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "anim.gltf: animations[0].channels[0].target.node: nodes[0] has a matrix; an "
                                "animated node must give its translation, rotation and scale instead");
    scene_free(&s);
    /* times 0, 1, 2 read from the translation's floats instead: 0, 0, 0 */
    anim_json(anim, sizeof anim, "{\"sampler\":4,\"target\":{\"node\":1,\"path\":\"scale\"}}",
              ",{\"input\":9,\"output\":2}");
    doc_json(doc, 16384, anim_nodes, anim);
    char *at = strstr(doc, "\"accessors\":[");
    char patched[16384];
    snprintf(patched, sizeof patched, "%.*s\"accessors\":[%s", (int)(at - doc), doc,
             at + strlen("\"accessors\":[") - 0);
    /* accessor 9: the first three floats of the translation (0, 0, 0) as times */
    char *end = strstr(patched, "}],\"bufferViews\"");
    char final[16384];
    snprintf(final, sizeof final, "%.*s},{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\"%s",
             (int)(end - patched), patched, end);
    error_clear(&err);
    CHECK(load_doc(final, 1, &s, &err) == ST_INPUT);
    CHECK_MSG(strcmp(err.msg, "anim.gltf: animations[0].samplers[4].input: key 1's time 0 is not after key 0's "
                              "(0); key times must increase") == 0, "got: %s", err.msg);
    scene_free(&s);
    /* weights: a warning, the channel ignored */
    anim_json(anim, sizeof anim, "{\"sampler\":0,\"target\":{\"node\":1,\"path\":\"weights\"}}", NULL);
    doc_json(doc, 16384, anim_nodes, anim);
    error_clear(&err);
    CHECK(load_doc(doc, 1, &s, &err) == ST_OK);
    CHECK(s.n_warnings == 1 && s.n_warnings && strstr(s.warnings[0], "animations[0].channels[0].target.path: morph "
                                                                      "target weights are not animated"));
    scene_free(&s);
    /* q to -q on a cubic spline with flat tangents passes through zero halfway: the
     * file loads (its keys are rotations), the frame there is refused */
    anim_json(anim, sizeof anim, "{\"sampler\":4,\"target\":{\"node\":1,\"path\":\"rotation\"}}",
              ",{\"input\":8,\"output\":7,\"interpolation\":\"CUBICSPLINE\"}");
    doc_json(doc, 16384, anim_nodes, anim);
    error_clear(&err);
    CHECK(load_doc(doc, 1, &s, &err) == ST_OK);
    if (s.animation) {
        CHECK(s.animation->pose(s.animation, &s, 0.25, &err) == ST_OK);
        CHECK(s.animation->pose(s.animation, &s, 0.5, &err) == ST_INPUT);
        CHECK_MSG(strcmp(err.msg, "anim.gltf: nodes[1]: rotation: the animation makes a zero quaternion") == 0,
                  "got: %s", err.msg);
    }
    scene_free(&s);
    /* no animation at all */
    doc_json(doc, 16384, anim_nodes, "");
    error_clear(&err);
    CHECK(load_doc(doc, 1, &s, &err) == ST_INPUT);
    CHECK_MSG(strcmp(err.msg, "anim.gltf: the file has no animation of a node's translation, rotation or scale to "
                              "pose (--frames, --time)") == 0, "got: %s", err.msg);
    scene_free(&s);
    free(doc);
}

/* ------------------------------------------------------------------ camera paths */

#define PATH_SCENE_REST                                                                                  \
    "material red { type diffuse albedo 0.8 0.1 0.1 }\n"                                                \
    "sphere { center 0 0.5 0 radius 0.5 material red }\n"                                               \
    "plane { point 0 0 0 normal 0 1 0 material red }\n"                                                 \
    "light { type point position 2 4 2 intensity 30 30 30 }\n"

static Status load_path_scene(const char *interp, int animated, Scene *s, Error *err)
{
    char text[2048];
    snprintf(text, sizeof text,
             "image { width 24 height 16 spp 2 depth 2 }\n"
             "camera { from 0 1 6 at 0 0.5 0 fov 40 }\n"
             "camera_path { interpolation %s\n"
             "    key 0 { }\n"
             "    key 1 { from 3 1.5 5 fov 30 }\n"
             "    key 2 { from 5 2 0 at 0 0.3 0 }\n"
             "}\n" PATH_SCENE_REST, interp);
    scene_init(s);
    s->keep_animation = animated;
    return scene_load_bytes("path.scene", text, strlen(text), SCENE_FORMAT_AUTO, s, NULL, err);
}

/* The camera at time t of a path with interpolation `interp`. */
static SceneCamera path_camera(const char *interp, double t)
{
    Scene s;
    Error err = { 0 };
    SceneCamera c;
    memset(&c, 0, sizeof c);
    Status st = load_path_scene(interp, 1, &s, &err);
    CHECK_MSG(st == ST_OK && s.animation, "%s: %s", interp, err.msg);
    if (st == ST_OK && s.animation) {
        CHECK(s.animation->end == 2.0);
        CHECK(s.animation->pose(s.animation, &s, t, &err) == ST_OK);
        c = s.camera;
    }
    scene_free(&s);
    return c;
}

static void test_camera_path_values(void)
{
    /* a plain load keeps no animation and looks through the camera block */
    Scene s;
    Error err = { 0 };
    CHECK(load_path_scene("linear", 0, &s, &err) == ST_OK);
    CHECK(s.animation == NULL && s.camera.from.z == 6.0f && s.camera.vfov == 40.0f);
    scene_free(&s);
    /* at a key: its values, the rest the keys' before it */
    SceneCamera c = path_camera("linear", 1.0);
    CHECK(c.from.x == 3.0f && c.from.y == 1.5f && c.from.z == 5.0f && c.at.y == 0.5f && c.vfov == 30.0f);
    c = path_camera("linear", 0.5);
    CHECK(c.from.x == 1.5f && c.from.y == 1.25f && c.from.z == 5.5f && c.vfov == 35.0f);
    c = path_camera("linear", 1.5);
    CHECK(c.from.x == 4.0f && c.at.y == 0.4f && c.vfov == 30.0f);
    c = path_camera("linear", 9.0);   /* after the end: the last key */
    CHECK(c.from.x == 5.0f && c.from.z == 0.0f && c.at.y == 0.3f);
    c = path_camera("step", 1.999);
    CHECK(c.from.x == 3.0f && c.at.y == 0.5f);
    /* smooth: Catmull-Rom tangents (3 - 0) / 1 at key 0 (one-sided), (5 - 0) / 2 at
     * key 1; at u = 1/2 of [0, 1]: 0/2 + 3/8 + 3/2 - 2.5/8 = 1.5625 */
    c = path_camera("smooth", 0.5);
    CHECK(c.from.x == 1.5625f);
    c = path_camera("smooth", 1.0);
    CHECK(c.from.x == 3.0f && c.vfov == 30.0f);
}

/* A frame at a key renders what the camera block of the key's values renders. */
static void test_camera_path_frame(void)
{
    Scene moving, still;
    Error err = { 0 };
    CHECK(load_path_scene("smooth", 1, &moving, &err) == ST_OK);
    static const char text[] = "image { width 24 height 16 spp 2 depth 2 }\n"
                               "camera { from 3 1.5 5 at 0 0.5 0 fov 30 }\n" PATH_SCENE_REST;
    scene_init(&still);
    CHECK(scene_load_bytes("still.scene", text, strlen(text), SCENE_FORMAT_AUTO, &still, NULL, &err) == ST_OK);
    Film a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    if (moving.animation && moving.animation->pose(moving.animation, &moving, 0.3, &err) == ST_OK &&
        render_sums(&moving, &a)) {
        film_free(&a);
        /* posed again after a render */
        CHECK(moving.animation->pose(moving.animation, &moving, 1.0, &err) == ST_OK);
        CHECK(memcmp(&moving.camera, &still.camera, sizeof still.camera) == 0);
        if (render_sums(&moving, &a) && render_sums(&still, &b)) CHECK(films_equal(&a, &b));
    }
    film_free(&a);
    film_free(&b);
    scene_free(&moving);
    scene_free(&still);
}

/* ------------------------------------------------------------------ the program */

/* The numbered names (docs/animation.md): the stem, an underscore, four digits or more,
 * the extension. */
static void test_frame_names(void)
{
    static const struct { const char *path; long frame; const char *want; } cases[] = {
        { "out.png", 0, "out_0000.png" },           { "out.png", 42, "out_0042.png" },
        { "dir/a.b.exr", 7, "dir/a.b_0007.exr" },   { "frame.pfm", 12345, "frame_12345.pfm" },
        { "ck", 3, "ck_0003" },                     { "dir.x/out", 3, "dir.x/out_0003" },
        { ".hidden", 1, ".hidden_0001" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *got = outputs_frame_path(cases[i].path, cases[i].frame);
        CHECK_MSG(got && strcmp(got, cases[i].want) == 0, "%s %ld: %s", cases[i].path, cases[i].frame, got);
        free(got);
    }
}

#define CLI_DIR CLPT_BUILD_DIR "/tests/frames-cli"

static long file_size(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 ? (long)st.st_size : -1;
}

/* A glTF animation of the camera alone: frames in a row on the OpenCL device (the
 * scene kept, the camera renewed) equal each frame rendered alone on the scalar
 * device. */
static void test_cli_camera_only(void)
{
    static const char anim[] = "\"animations\":[{\"channels\":[{\"sampler\":0,\"target\":{\"node\":3,"
                               "\"path\":\"translation\"}}],\"samplers\":[{\"input\":1,\"output\":6}]}],";
    char *doc = malloc(16384);
    doc_json(doc, 16384, anim_nodes, anim);
    FILE *f = fopen(CLI_DIR "/cam.gltf", "w");
    CHECK(f != NULL);
    if (f) {
        fputs(doc, f);
        fclose(f);
    }
    free(doc);
    static CliResult r;
    const char *a1[] = { "--device", TEST_OPENCL, "--spp", "2", "--width", "24", "--height", "16", "-q", "--frames",
                         "10:12", "-o", CLI_DIR "/cam.pfm", CLI_DIR "/cam.gltf", NULL };
    cli_run(a1, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *a2[] = { "--device", "scalar", "--spp", "2", "--width", "24", "--height", "16", "-q", "--frames",
                         "12:12", "-o", CLI_DIR "/camone.pfm", CLI_DIR "/cam.gltf", NULL };
    cli_run(a2, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/cam_0012.pfm", CLI_DIR "/camone_0012.pfm"));
    CHECK(!files_equal(CLI_DIR "/cam_0010.pfm", CLI_DIR "/cam_0012.pfm"));
}

static void test_cli_frames(void)
{
    char *doc = animated_doc();
    (void)system("rm -rf " CLI_DIR " && mkdir -p " CLI_DIR);
    FILE *f = fopen(CLI_DIR "/anim.gltf", "w");
    CHECK(f != NULL);
    if (!f) return;
    fputs(doc, f);
    fclose(f);
    free(doc);
    static CliResult r;
    const char *const base[] = { "--device", "scalar", "--spp", "2", "--width", "24", "--height", "16", "-q" };
    /* frames 23..25 at 24 fps: before, at and after the key at 1 s */
    const char *a1[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--frames",
                         "23:25", "-o", CLI_DIR "/out.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a1, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(file_exists(CLI_DIR "/out_0023.pfm") && file_exists(CLI_DIR "/out_0024.pfm") &&
          file_exists(CLI_DIR "/out_0025.pfm"));
    CHECK(!file_exists(CLI_DIR "/out.pfm") && !file_exists(CLI_DIR "/out_0022.pfm"));
    CHECK(!files_equal(CLI_DIR "/out_0023.pfm", CLI_DIR "/out_0024.pfm"));
    CHECK(!files_equal(CLI_DIR "/out_0024.pfm", CLI_DIR "/out_0025.pfm"));
    CHECK(file_size(CLI_DIR "/out_0023.pfm") > 24 * 16 * 12);
    /* the OpenCL device (PoCL): the same bits, its kernels compiled (or loaded) once
     * for the three frames */
    const char *a0[] = { "--device", TEST_OPENCL, base[2], base[3], base[4], base[5], base[6], base[7], "--frames",
                         "23:25", "-o", CLI_DIR "/ocl.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a0, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *c1 = strstr(r.err, "compiling kernels");
    CHECK_MSG(!c1 || !strstr(c1 + 1, "compiling kernels"), "compiled more than once: %s", r.err);
    CHECK(files_equal(CLI_DIR "/ocl_0023.pfm", CLI_DIR "/out_0023.pfm"));
    CHECK(files_equal(CLI_DIR "/ocl_0024.pfm", CLI_DIR "/out_0024.pfm"));
    CHECK(files_equal(CLI_DIR "/ocl_0025.pfm", CLI_DIR "/out_0025.pfm"));
    /* a rerun skips the frames that are there: one removed is made again, the same */
    (void)system("mv " CLI_DIR "/out_0024.pfm " CLI_DIR "/first_0024.pfm");
    const char *a2[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], "--frames", "23:25",
                         "-o", CLI_DIR "/out.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a2, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK_STR_CONTAINS(r.err, "clpt: frame 23: '" CLI_DIR "/out_0023.pfm' is there already; skipped");
    CHECK_STR_CONTAINS(r.err, "clpt: frame 25: '" CLI_DIR "/out_0025.pfm' is there already; skipped");
    CHECK(files_equal(CLI_DIR "/out_0024.pfm", CLI_DIR "/first_0024.pfm"));
    /* a frame resumed from its checkpoint: half its samples, then the rest, the
     * same bits as the whole frame rendered at once */
    const char *a3[] = { base[0], base[1], "--spp", "1", base[4], base[5], base[6], base[7], base[8], "--frames",
                         "24:24", "--checkpoint", CLI_DIR "/ck.ckpt", "-o", CLI_DIR "/half.pfm",
                         CLI_DIR "/anim.gltf", NULL };
    cli_run(a3, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(file_exists(CLI_DIR "/ck_0024.ckpt"));
    const char *a4[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], "--frames", "24:24",
                         "--resume", CLI_DIR "/ck.ckpt", "-o", CLI_DIR "/resumed.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a4, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK_STR_CONTAINS(r.err, "resuming from '" CLI_DIR "/ck_0024.ckpt': 1 samples per pixel already done, growing "
                              "the render from 1 to 2");
    CHECK(files_equal(CLI_DIR "/resumed_0024.pfm", CLI_DIR "/first_0024.pfm"));
    /* an unfinished frame (its time limit) writes its checkpoint and no image, exit
     * status 7; --resume finishes it, the same bits as the frame rendered at once.
     * 4096 one-sample batches: far more than fit in the limit. The limit must also
     * let the first batch finish, and a device thread's start alone may take longer
     * than a millisecond on a loaded machine under ASan (CI, 2026-11-28): nothing
     * rendered is status 7 too, with no checkpoint. So the limit grows, from 1 ms, until
     * a batch finished. */
    static const char *const limits[] = { "0.001", "0.004", "0.016", "0.064", "0.25" };
    int cut = 0;
    for (size_t i = 0; i < sizeof limits / sizeof *limits && !cut; i++) {
        const char *a7[] = { base[0], base[1], "--spp", "4096", base[4], base[5], base[6], base[7], "--batch", "1",
                             "--time-limit", limits[i], "--frames", "24:24", "--checkpoint", CLI_DIR "/ck2.ckpt",
                             "-o", CLI_DIR "/cut.pfm", CLI_DIR "/anim.gltf", NULL };
        cli_run(a7, &r);
        CHECK_MSG(r.status == 7, "status %d: %s", r.status, r.err);
        cut = file_exists(CLI_DIR "/ck2_0024.ckpt");
        if (!cut)
            CHECK_STR_CONTAINS(r.err, "was reached before the first batch finished: nothing was rendered");
    }
    CHECK_MSG(cut, "no batch finished within 0.25 s: %s", r.err);
    CHECK_STR_CONTAINS(r.err, "clpt: the frame is unfinished: '" CLI_DIR "/cut_0024.pfm' is not written; --resume "
                              "goes on from its checkpoint");
    CHECK(!file_exists(CLI_DIR "/cut_0024.pfm"));
    const char *a8[] = { base[0], base[1], "--spp", "4096", base[4], base[5], base[6], base[7], base[8], "--batch", "1",
                         "--frames", "24:24", "--resume", CLI_DIR "/ck2.ckpt", "-o", CLI_DIR "/cut.pfm",
                         CLI_DIR "/anim.gltf", NULL };
    cli_run(a8, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *a9[] = { base[0], base[1], "--spp", "4096", base[4], base[5], base[6], base[7], base[8], "--frames",
                         "24:24", "-o", CLI_DIR "/whole.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a9, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/cut_0024.pfm", CLI_DIR "/whole_0024.pfm"));
    /* clpt's camera_path: frame 1 at --fps 1 is key 1, what the camera block of its
     * values renders */
    static const char path_text[] = "image { width 24 height 16 spp 2 depth 2 }\n"
                                    "camera { from 0 1 6 at 0 0.5 0 fov 40 }\n"
                                    "camera_path { key 0 { } key 1 { from 3 1.5 5 fov 30 } }\n" PATH_SCENE_REST;
    static const char still_text[] = "image { width 24 height 16 spp 2 depth 2 }\n"
                                     "camera { from 3 1.5 5 at 0 0.5 0 fov 30 }\n" PATH_SCENE_REST;
    FILE *pf = fopen(CLI_DIR "/path.scene", "w"), *sf = fopen(CLI_DIR "/still.scene", "w");
    if (pf) fputs(path_text, pf);
    if (sf) fputs(still_text, sf);
    if (pf) fclose(pf);
    if (sf) fclose(sf);
    const char *a5[] = { "--device", "scalar", "-q", "--frames", "0:1", "--fps", "1", "-o", CLI_DIR "/path.pfm",
                         CLI_DIR "/path.scene", NULL };
    cli_run(a5, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *a6[] = { "--device", "scalar", "-q", "-o", CLI_DIR "/still.pfm", CLI_DIR "/still.scene", NULL };
    cli_run(a6, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/path_0001.pfm", CLI_DIR "/still.pfm"));
    CHECK(file_exists(CLI_DIR "/path_0000.pfm") && !files_equal(CLI_DIR "/path_0000.pfm", CLI_DIR "/still.pfm"));
    /* frame 1 kept frame 0's trees and buffers and renewed the camera alone; the
     * OpenCL device too, through its params block */
    const char *a10[] = { "--device", TEST_OPENCL, "-q", "--frames", "0:1", "--fps", "1", "-o", CLI_DIR "/pathcl.pfm",
                          CLI_DIR "/path.scene", NULL };
    cli_run(a10, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/pathcl_0001.pfm", CLI_DIR "/still.pfm"));
    CHECK(files_equal(CLI_DIR "/pathcl_0000.pfm", CLI_DIR "/path_0000.pfm"));
}

/* --time T: one image posed at T seconds, the bits of the frame at T of --frames (at a
 * key and between keys, the scalar device and PoCL); a camera_path's --time at a key is
 * the camera block of the key's values; the time's errors. Uses test_cli_frames' files. */
static void test_cli_time(void)
{
    static CliResult r;
    const char *const base[] = { "--device", "scalar", "--spp", "2", "--width", "24", "--height", "16", "-q" };
    /* frame 12 at 24 fps is 0.5 s, between the keys at 0 and 1 s; frame 24 is 1 s, at one */
    const char *a1[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--frames",
                         "12:12", "-o", CLI_DIR "/half.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a1, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *a2[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--time",
                         "0.5", "-o", CLI_DIR "/t05.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a2, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/t05.pfm", CLI_DIR "/half_0012.pfm"));
    const char *a3[] = { "--device", TEST_OPENCL, base[2], base[3], base[4], base[5], base[6], base[7], base[8],
                         "--time", "1", "-o", CLI_DIR "/t1cl.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a3, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/t1cl.pfm", CLI_DIR "/out_0024.pfm"));
    CHECK(!files_equal(CLI_DIR "/t1cl.pfm", CLI_DIR "/t05.pfm"));
    /* the end of the animation (2 s) is a time to pose, as the last frame is */
    const char *a4[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--time",
                         "2", "-o", CLI_DIR "/t2.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a4, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *a5[] = { "--device", "scalar", "-q", "--time", "1", "-o", CLI_DIR "/patht1.pfm",
                         CLI_DIR "/path.scene", NULL };
    cli_run(a5, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/patht1.pfm", CLI_DIR "/still.pfm"));
    /* a checkpoint of one time resumes that time to the straight render's bits, and is
     * refused for another (the posed scene differs) */
    const char *c1[] = { base[0], base[1], "--spp", "1", base[4], base[5], base[6], base[7], base[8], "--time",
                         "0.5", "--checkpoint", CLI_DIR "/tck.ckpt", "-o", CLI_DIR "/thalf.pfm",
                         CLI_DIR "/anim.gltf", NULL };
    cli_run(c1, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *c2[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--time",
                         "1", "--resume", CLI_DIR "/tck.ckpt", "-o", CLI_DIR "/tother.pfm", CLI_DIR "/anim.gltf",
                         NULL };
    cli_run(c2, &r);
    CHECK_EQ_INT(r.status, ST_INPUT);
    CHECK_STR_CONTAINS(r.err, "belongs to another render: the scene differs");
    const char *c3[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--time",
                         "0.5", "--resume", CLI_DIR "/tck.ckpt", "-o", CLI_DIR "/tresumed.pfm",
                         CLI_DIR "/anim.gltf", NULL };
    cli_run(c3, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/tresumed.pfm", CLI_DIR "/t05.pfm"));
    const char *e1[] = { "--time", "2.5", "-o", CLI_DIR "/x.png", CLI_DIR "/anim.gltf", NULL };
    cli_run(e1, &r);
    CHECK(r.status == ST_USAGE);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --time 2.5 is after the end of the animation of '" CLI_DIR "/anim.gltf' "
                              "at 2 s");
    const char *bad_times[] = { "-1", "nan", "inf", "1e999", "1s", "" };
    for (size_t i = 0; i < sizeof bad_times / sizeof bad_times[0]; i++) {
        const char *e2[] = { "--time", bad_times[i], CLI_DIR "/anim.gltf", NULL };
        cli_run(e2, &r);
        CHECK_MSG(r.status == ST_USAGE, "--time '%s': status %d", bad_times[i], r.status);
        char want[160];
        snprintf(want, sizeof want, "clpt: error: --time expects a time in seconds, a finite number 0 or more, "
                 "got '%s'", bad_times[i]);
        CHECK_STR_CONTAINS(r.err, want);
    }
    const char *e3[] = { "--time", "0", "-o", CLI_DIR "/x.png", "scenes/cornell-box.scene", NULL };
    cli_run(e3, &r);
    CHECK(r.status == ST_USAGE);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --time poses the animation of a glTF file given as the scene, or a "
                              "clpt scene's camera_path; 'scenes/cornell-box.scene' has neither");
    const char *e4[] = { "--time", "1", "--frames", "0:1", CLI_DIR "/anim.gltf", NULL };
    cli_run(e4, &r);
    CHECK(r.status == ST_USAGE);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --time poses the animation at one time and --frames at each frame's: "
                              "give one");
}

/* ------------------------------------------------------------------ --shutter */

/* Node 0's triangle sliding linearly from (0,0,0) at 0 s to (1,0.5,0) at 1 s (sampler 0's
 * first two keys); the instanced mesh and the camera stand still. */
static const char slide_anim[] = "\"animations\":[{\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,"
                                 "\"path\":\"translation\"}}],\"samplers\":[{\"input\":1,\"output\":2}]}],";

/* Each 8x8 block's mean of the film (sums over samples): 3 x 2 blocks of 24 x 16, RGB. */
static void block_means(const Film *f, double out[6][3])
{
    memset(out, 0, 6 * sizeof out[0]);
    for (uint y = 0; y < f->height; y++)
        for (uint x = 0; x < f->width; x++)
            for (int c = 0; c < 3; c++)
                out[(y / 8) * 3 + x / 8][c] += (double)f->sum[((size_t)y * f->width + x) * 3 + (size_t)c] /
                                               (64.0 * (double)f->samples);
}

/* The largest difference of two blocks' means, over the largest mean. */
static double blocks_apart(double a[6][3], double b[6][3])
{
    double d = 0, top = 0;
    for (int i = 0; i < 6; i++)
        for (int c = 0; c < 3; c++) {
            d = fmax(d, fabs(a[i][c] - b[i][c]));
            top = fmax(top, fmax(a[i][c], b[i][c]));
        }
    return d / top;
}

/* A node moving linearly, blurred over [0, 1] (512 samples), against the average of 8
 * still poses at the middles of eighths of the shutter (8 x 64): within noise, and
 * far from the still pose at the middle. */
static void test_shutter_equals_average(void)
{
    char *doc = malloc(16384);
    doc_json(doc, 16384, anim_nodes, slide_anim);
    Scene s;
    Error err = { 0 };
    Status st = load_doc(doc, KEEP_ANIMATION_IF_ANY, &s, &err);
    CHECK_MSG(st == ST_OK, "load: %s", err.msg);
    if (st == ST_OK) st = s.animation->pose_shutter(s.animation, &s, 0.0, 1.0, &err);
    CHECK_MSG(st == ST_OK, "shutter: %s", err.msg);
    /* the slid triangle is a moving instance now; the still ones are not */
    CHECK(s.n_instances == 3 && s.n_motion_keys == 2 && s.camera.shutter_close == 1.0f);
    s.image.spp = 512;
    Film blurred;
    double blur[6][3], avg[6][3], mid[6][3];
    memset(avg, 0, sizeof avg);
    if (st == ST_OK && render_sums(&s, &blurred)) {
        block_means(&blurred, blur);
        film_free(&blurred);
    }
    scene_free(&s);
    for (int i = 0; i < 8; i++) {
        Scene still;
        st = load_doc(doc, KEEP_ANIMATION_NEEDED, &still, &err);
        if (st == ST_OK) st = still.animation->pose(still.animation, &still, (i + 0.5) / 8.0, &err);
        CHECK_MSG(st == ST_OK, "still %d: %s", i, err.msg);
        still.image.spp = 64;
        Film f;
        if (st == ST_OK && render_sums(&still, &f)) {
            double m[6][3];
            block_means(&f, m);
            for (int b = 0; b < 6; b++)
                for (int c = 0; c < 3; c++) avg[b][c] += m[b][c] / 8.0;
            film_free(&f);
        }
        scene_free(&still);
    }
    Scene middle;
    st = load_doc(doc, KEEP_ANIMATION_NEEDED, &middle, &err);
    if (st == ST_OK) st = middle.animation->pose(middle.animation, &middle, 0.5, &err);
    middle.image.spp = 512;
    Film f;
    if (st == ST_OK && render_sums(&middle, &f)) {
        block_means(&f, mid);
        film_free(&f);
    }
    scene_free(&middle);
    double near = blocks_apart(blur, avg), far = blocks_apart(blur, mid);
    CHECK_MSG(near < 0.02, "blurred against the average of still poses: %.4f apart", near);
    CHECK_MSG(far > 4 * near, "blurred against the middle pose: %.4f apart (average: %.4f)", far, near);
    printf("     blurred vs average of 8 poses: %.4f; vs the middle pose: %.4f\n", near, far);
    free(doc);
}

/* An emissive mesh on a moving node is a moving instance under --shutter, and its
 * triangle a light placed at each path's time (LIGHT_MOVING, docs/motion.md), not
 * only found by BSDF sampling: the sliding node's mesh made emissive. */
static void test_shutter_emitter_is_light(void)
{
    char *doc = malloc(16384);
    doc_json(doc, 16384, anim_nodes, slide_anim);
    /* mesh 0 (node 0's, which slides) glows; mesh 1 does not */
    static const char plain[] = "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]},";
    static const char glowing[] = "\"materials\":[{\"emissiveFactor\":[1,0.8,0.6]}],"
                                  "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]},";
    char *at = strstr(doc, plain), *glow = malloc(16384);
    CHECK(at != NULL);
    if (at) {
        snprintf(glow, 16384, "%.*s%s%s", (int)(at - doc), doc, glowing, at + strlen(plain));
        Scene s;
        RenderScene rs;
        Error err = { 0 };
        Status st = load_doc(glow, KEEP_ANIMATION_IF_ANY, &s, &err);
        if (st == ST_OK) st = s.animation->pose_shutter(s.animation, &s, 0.0, 1.0, &err);
        CHECK_MSG(st == ST_OK, "shutter: %s", err.msg);
        if (st == ST_OK) st = render_scene_prepare(&s, 1, &rs, &err);
        CHECK_MSG(st == ST_OK, "prepare: %s", err.msg);
        if (st == ST_OK) {
            CHECK_EQ_INT(s.n_lights, 1);
            if (s.n_lights == 1) CHECK(s.lights[0].type == LIGHT_MOVING && s.lights[0].pick_pdf == 1.0f);
            render_scene_free(&rs);
        }
        scene_free(&s);
        error_clear(&err);
    }
    free(glow);
    free(doc);
}

/* The program: a still glTF file keeps its bits under a shutter; PoCL gives the scalar
 * device's bits on a blurred one; --frames with --shutter F; the shutter's errors. */
static void test_cli_shutter(void)
{
    static CliResult r;
    char *doc = malloc(16384);
    doc_json(doc, 16384, anim_nodes, "");
    FILE *f = fopen(CLI_DIR "/still.gltf", "w");
    CHECK(f != NULL);
    if (f) {
        fputs(doc, f);
        fclose(f);
    }
    free(doc);
    const char *const base[] = { "--device", "scalar", "--spp", "2", "--width", "24", "--height", "16", "-q" };
    const char *a1[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "-o",
                         CLI_DIR "/still.pfm", CLI_DIR "/still.gltf", NULL };
    cli_run(a1, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *a2[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--shutter",
                         "0:1", "-o", CLI_DIR "/stillsh.pfm", CLI_DIR "/still.gltf", NULL };
    cli_run(a2, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/still.pfm", CLI_DIR "/stillsh.pfm"));
    /* the whole animation (translation, slerp, a cubic spline, a step, the camera) */
    const char *a3[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--shutter",
                         "0.5:1.5", "-o", CLI_DIR "/blur.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a3, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *a4[] = { "--device", TEST_OPENCL, base[2], base[3], base[4], base[5], base[6], base[7], base[8],
                         "--shutter", "0.5:1.5", "-o", CLI_DIR "/blurcl.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(a4, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/blur.pfm", CLI_DIR "/blurcl.pfm"));
    CHECK(!files_equal(CLI_DIR "/blur.pfm", CLI_DIR "/t1cl.pfm"));
    static const struct { const char *value, *msg; } bad[] = {
        { "1:0.5", "clpt: error: --shutter 1:0.5: it closes at 0.5 s, not after it opens at 1 s (for one time, "
                   "--time)" },
        { "1:1", "clpt: error: --shutter 1:1: it closes at 1 s, not after it opens at 1 s (for one time, --time)" },
        { "nan:1", "clpt: error: --shutter expects A:B, the times in seconds it opens and closes (finite, 0 or "
                   "more), got 'nan:1'" },
        { "0:inf", "clpt: error: --shutter expects A:B, the times in seconds it opens and closes (finite, 0 or "
                   "more), got '0:inf'" },
        { "-1:1", "clpt: error: --shutter expects A:B, the times in seconds it opens and closes (finite, 0 or "
                  "more), got '-1:1'" },
        { "0", "clpt: error: --shutter expects A:B, the times in seconds it opens and closes, or with --frames F, "
               "the fraction of each frame's time it is open (0 < F <= 1), got '0'" },
        { "1.5:3", "clpt: error: --shutter 1.5:3 closes after the end of the animation of '" CLI_DIR "/anim.gltf' "
                   "at 2 s" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const char *e[] = { "--shutter", bad[i].value, "-o", CLI_DIR "/x.png", CLI_DIR "/anim.gltf", NULL };
        cli_run(e, &r);
        CHECK_MSG(r.status == ST_USAGE, "--shutter '%s': status %d", bad[i].value, r.status);
        CHECK_STR_CONTAINS(r.err, bad[i].msg);
    }
    static const CliRefusal refused[] = {
        { { "--shutter", "0:1", "-o", CLI_DIR "/x.png", "scenes/cornell-box.scene" },
          "clpt: error: --shutter blurs the animation of a glTF file given as the scene; "
          "'scenes/cornell-box.scene' is not one" },
        { { "--shutter", "0:1", "--time", "1", CLI_DIR "/anim.gltf" },
          "clpt: error: --shutter blurs the animation over a time and --time poses it at one: "
          "give one" },
        { { "--shutter", "0:1", "--frames", "0:1", CLI_DIR "/anim.gltf" },
          "clpt: error: --shutter A:B opens once; with --frames give --shutter F, the fraction "
          "of each frame's time it is open" },
    };
    cli_check_refusals(refused, sizeof refused / sizeof refused[0], ST_USAGE);
    /* --frames with --shutter F: frame 1 at 2 fps open half a frame is --shutter
     * 0.5:0.75, rendered in a row after a blurred frame 0 (its keys gone) and alone;
     * PoCL the same */
    const char *f1[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--frames",
                         "0:2", "--fps", "2", "--shutter", "0.5", "-o", CLI_DIR "/fblur.pfm", CLI_DIR "/anim.gltf",
                         NULL };
    cli_run(f1, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    const char *f2[] = { base[0], base[1], base[2], base[3], base[4], base[5], base[6], base[7], base[8], "--shutter",
                         "0.5:0.75", "-o", CLI_DIR "/fone.pfm", CLI_DIR "/anim.gltf", NULL };
    cli_run(f2, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/fblur_0001.pfm", CLI_DIR "/fone.pfm"));
    CHECK(!files_equal(CLI_DIR "/fblur_0000.pfm", CLI_DIR "/fblur_0001.pfm"));
    const char *f3[] = { "--device", TEST_OPENCL, base[2], base[3], base[4], base[5], base[6], base[7], base[8],
                         "--frames", "0:2", "--fps", "2", "--shutter", "0.5", "-o", CLI_DIR "/fblurcl.pfm",
                         CLI_DIR "/anim.gltf", NULL };
    cli_run(f3, &r);
    CHECK_MSG(r.status == 0, "status %d: %s", r.status, r.err);
    CHECK(files_equal(CLI_DIR "/fblur_0000.pfm", CLI_DIR "/fblurcl_0000.pfm"));
    CHECK(files_equal(CLI_DIR "/fblur_0002.pfm", CLI_DIR "/fblurcl_0002.pfm"));
    static const CliRefusal refused_frames[] = {
        { { "--shutter", "0.5", CLI_DIR "/anim.gltf" },
          "clpt: error: --shutter F is a fraction of each frame's time, for --frames; for one "
          "image give --shutter A:B in seconds" },
        { { "--frames", "0:1", "--shutter", "1.5", CLI_DIR "/anim.gltf" },
          "clpt: error: --shutter expects A:B, the times in seconds it opens and closes, or with "
          "--frames F, the fraction of each frame's time it is open (0 < F <= 1), got '1.5'" },
        { { "--frames", "0:1", "--fps", "1", "--shutter", "0.5", "-o", CLI_DIR "/x.pfm", CLI_DIR "/path.scene" },
          "clpt: error: --shutter blurs the animation of a glTF file given as the scene; '"
          CLI_DIR "/path.scene' is not one" },
    };
    cli_check_refusals(refused_frames, sizeof refused_frames / sizeof refused_frames[0], ST_USAGE);
}

static void test_cli_errors(void)
{
    static const CliRefusal bad[] = {
        { { "--frames", "5:3", CLI_DIR "/anim.gltf" },
          "clpt: error: --frames 5:3: the first frame, 5, is after the last, 3" },
        { { "--frames", "40:49", "-o", CLI_DIR "/x.png", CLI_DIR "/anim.gltf" },
          "clpt: error: --frames 40:49: frame 49 (at 2.04167 s) is after the end of the animation "
          "of '" CLI_DIR "/anim.gltf' at 2 s; at 24 frames per second its frames are 0 to 48" },
        { { "--frames", "0:10", "--fps", "4", "-o", CLI_DIR "/x.png", CLI_DIR "/anim.gltf" },
          "at 4 frames per second its frames are 0 to 8" },
        { { "--fps", "30", CLI_DIR "/anim.gltf" },
          "clpt: error: --fps sets the frame rate of --frames A:B; give both, or neither" },
        { { "--frames", "0:1", "-o", CLI_DIR "/x.png", "scenes/cornell-box.scene" },
          "clpt: error: --frames renders the animation of a glTF file given as the scene, or a "
          "clpt scene's camera_path; 'scenes/cornell-box.scene' has neither" },
        { { "--frames", "0:1", "--display-server", "localhost:14158", CLI_DIR "/anim.gltf" },
          "clpt: error: --frames cannot be used with --display-server (the live display shows "
          "one image; open each frame's file instead)" },
        { { "--frames", "0:1", "--sample-range", "0:1", CLI_DIR "/anim.gltf" },
          "clpt: error: --frames cannot be used with --sample-range (render each frame whole)" },
        { { "--frames", "0:1", "-o", "-", CLI_DIR "/anim.gltf" },
          "clpt: error: --frames cannot be used with -o -" },
        { { "--frames", "1", CLI_DIR "/anim.gltf" },
          "clpt: error: --frames expects A:B, frame numbers with 0 <= A <= B <= 999999, got '1'" },
    };
    cli_check_refusals(bad, sizeof bad / sizeof bad[0], ST_USAGE);
}

int main(void)
{
    base64((const unsigned char *)anim_buffer, sizeof anim_buffer, anim_uri + 37);
    memcpy(anim_uri, "data:application/octet-stream;base64,", 37);
    RUN(test_linear_and_step);
    RUN(test_slerp);
    RUN(test_cubic_spline);
    RUN(test_node_pose);
    RUN(test_pose_equals_static);
    RUN(test_camera_only);
    RUN(test_bad_animations);
    RUN(test_bad_documents);
    RUN(test_camera_path_values);
    RUN(test_camera_path_frame);
    RUN(test_frame_names);
    RUN(test_cli_frames);
    RUN(test_cli_camera_only);
    RUN(test_cli_errors);
    RUN(test_cli_time);
    RUN(test_shutter_equals_average);
    RUN(test_shutter_emitter_is_light);
    RUN(test_cli_shutter);
    return harness_report();
}
