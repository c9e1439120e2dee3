/*
 * gltf_anim.c — glTF animations (glTF 2.0, 3.11): the samplers' keys read and checked,
 * the channels that move nodes' translation, rotation and scale evaluated at a time
 * (scene/keyframes.h), and the file's node tree placed again at that pose into the scene
 * it was read into, from the JSON and buffers kept in memory (gltf_anim.h).
 *
 * A frame is placed by the very walk that reads a static file, with the animated parts
 * of each node's TRS in place of its own: frame k of an animation is the same scene, bit
 * for bit, as a static file whose nodes hold the pose evaluated for it.
 */
#include "io/gltf_anim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/gltf_reader.h"
#include "scene/keyframes.h"
#include "scene/motion.h"
#include "scene/scene_mark.h"

enum { PATH_T, PATH_R, PATH_S };

typedef struct {
    int node, path;       /* path: PATH_T, PATH_R, PATH_S */
    KeyTrack track;       /* its times and values are owned here */
} GltfChannel;

struct GltfAnimated {
    SceneAnimation base;  /* first: the scene frees and poses through it */
    Gltf g;
    char *data;           /* the file's bytes: a GLB's BIN chunk is read from them */
    char *path;
    MeshOptions o;
    GltfView view;
    GltfChannel *ch;      size_t n_ch;
    GltfNodePose *pose;   /* per node */
    GltfNodePose *pose_at;   /* per node: the shutter's samples, while the walk uses pose */
    int *parent;          /* per node: its parent, or -1 */
    SceneMark mark;       /* the scene before the node tree was placed */
};

/* ------------------------------------------------------------------ reading */

static Status anim_interp(Gltf *g, const cJSON *smp, const char *jp, int *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(smp, "interpolation");
    *out = KEY_LINEAR;
    if (!v) return ST_OK;
    if (cJSON_IsString(v) && strcmp(v->valuestring, "LINEAR") == 0) return ST_OK;
    if (cJSON_IsString(v) && strcmp(v->valuestring, "STEP") == 0) *out = KEY_STEP;
    else if (cJSON_IsString(v) && strcmp(v->valuestring, "CUBICSPLINE") == 0) *out = KEY_CUBICSPLINE;
    else return error_set(g->err, ST_INPUT, "%s: %s.interpolation: expected LINEAR, STEP or CUBICSPLINE", g->path, jp);
    return ST_OK;
}

/* A sampler's key times: finite and increasing. */
static Status anim_times(Gltf *g, const cJSON *smp, const char *jp, double **times, size_t *n)
{
    char use[128];
    snprintf(use, sizeof use, "%s.input", jp);
    int ai;
    Status st = gltf_get_index(g, smp, "input", 1, "accessors", jp, &ai);
    if (st || (st = gltf_acc_read(g, ai, 1, use, times, n))) return st;
    if (*n == 0) return gltf_bad(g, use, "no key times (the accessor is empty)");
    for (size_t i = 0; i < *n; i++) {
        if (!isfinite((*times)[i]))
            return error_set(g->err, ST_INPUT, "%s: %s: key %zu's time is not a finite number", g->path, use, i);
        if (i > 0 && !((*times)[i] > (*times)[i - 1]))
            return error_set(g->err, ST_INPUT, "%s: %s: key %zu's time %g is not after key %zu's (%g); key times "
                             "must increase", g->path, use, i, (*times)[i], i - 1, (*times)[i - 1]);
    }
    return ST_OK;
}

/* A sampler's values for `path`: one per key time, three for CUBICSPLINE (in-tangent,
 * value, out-tangent). */
static Status anim_values(Gltf *g, const cJSON *smp, const char *jp, int path, size_t n_keys, int interp,
                          double **values)
{
    char use[128];
    snprintf(use, sizeof use, "%s.output", jp);
    int ai;
    size_t n;
    Status st = gltf_get_index(g, smp, "output", 1, "accessors", jp, &ai);
    if (st || (st = gltf_acc_read(g, ai, path == PATH_R ? 4 : 3, use, values, &n))) return st;
    size_t want = interp == KEY_CUBICSPLINE ? 3 * n_keys : n_keys;
    if (n != want)
        return error_set(g->err, ST_INPUT, "%s: %s: accessor %d has %zu elements; the %zu key times of input ask for "
                         "%zu%s", g->path, use, ai, n, n_keys, want,
                         interp == KEY_CUBICSPLINE ? " (CUBICSPLINE: an in-tangent, a value and an out-tangent each)" : "");
    int width = path == PATH_R ? 4 : 3;
    for (size_t i = 0; i < n * (size_t)width; i++)
        if (!isfinite((*values)[i]))
            return error_set(g->err, ST_INPUT, "%s: %s: element %zu is not finite", g->path, use, i / (size_t)width);
    return ST_OK;
}

static Status channel_add(GltfAnimated *a, const GltfChannel *c)
{
    GltfChannel *grown = realloc(a->ch, (a->n_ch + 1) * sizeof *grown);
    if (!grown) return error_set(a->g.err, ST_INTERNAL, "out of memory");
    a->ch = grown;
    a->ch[a->n_ch++] = *c;
    return ST_OK;
}

static void channel_free(GltfChannel *c)
{
    free((void *)c->track.times);
    free((void *)c->track.values);
}

/* animations[ai].channels[ci]: its target checked and its sampler's keys read. */
static Status channel_read(GltfAnimated *a, const cJSON *anim, int ai, const cJSON *chan, int ci)
{
    Gltf *g = &a->g;
    char jp[96], jt[112], js[96];
    snprintf(jp, sizeof jp, "animations[%d].channels[%d]", ai, ci);
    snprintf(jt, sizeof jt, "%s.target", jp);
    const cJSON *samplers = cJSON_GetObjectItemCaseSensitive(anim, "samplers");
    int n_samplers = cJSON_IsArray(samplers) ? cJSON_GetArraySize(samplers) : 0;
    if (n_samplers == 0) {
        char ja[64];
        snprintf(ja, sizeof ja, "animations[%d].samplers", ai);
        return gltf_bad(g, ja, "missing or empty (a channel needs a sampler)");
    }
    long long si;
    Status st = gltf_get_int(g, chan, "sampler", -1, 0, n_samplers - 1, jp, &si);
    if (st) return st;
    const cJSON *target = cJSON_GetObjectItemCaseSensitive(chan, "target");
    if (!cJSON_IsObject(target)) return gltf_bad(g, jp, "target: expected an object");
    const cJSON *path = cJSON_GetObjectItemCaseSensitive(target, "path");
    const char *p = cJSON_IsString(path) ? path->valuestring : "";
    int which = strcmp(p, "translation") == 0 ? PATH_T : strcmp(p, "rotation") == 0 ? PATH_R
              : strcmp(p, "scale") == 0 ? PATH_S : -1;
    if (which < 0 && strcmp(p, "weights") == 0)
        return scene_warn(g->s, g->err, "%s: %s.path: morph target weights are not animated (clpt has no morph "
                          "targets); the channel is ignored", g->path, jt);
    if (which < 0) return gltf_bad(g, jt, "path: expected translation, rotation, scale or weights");
    int node;
    /* glTF 2.0, 3.11.3: a channel without a node is ignored (an extension may target
     * something else) */
    if ((st = gltf_get_index(g, target, "node", 0, "nodes", jt, &node)) || node < 0) return st;
    if (cJSON_GetObjectItemCaseSensitive(gltf_item_at(g, "nodes", node), "matrix"))
        return error_set(g->err, ST_INPUT, "%s: %s.node: nodes[%d] has a matrix; an animated node must give its "
                         "translation, rotation and scale instead (glTF 2.0, 3.11)", g->path, jt, node);
    for (size_t i = 0; i < a->n_ch; i++)
        if (a->ch[i].node == node && a->ch[i].path == which)
            return error_set(g->err, ST_INPUT, "%s: %s: nodes[%d].%s is animated by an earlier channel already",
                             g->path, jt, node, p);
    snprintf(js, sizeof js, "animations[%d].samplers[%lld]", ai, si);
    const cJSON *smp = cJSON_GetArrayItem(samplers, (int)si);
    GltfChannel c;
    memset(&c, 0, sizeof c);
    c.node = node;
    c.path = which;
    c.track.width = which == PATH_R ? 4 : 3;
    c.track.rotation = which == PATH_R;
    double *times = NULL, *values = NULL;
    if (!(st = anim_interp(g, smp, js, &c.track.interp)) && !(st = anim_times(g, smp, js, &times, &c.track.n)))
        st = anim_values(g, smp, js, which, c.track.n, c.track.interp, &values);
    c.track.times = times;
    c.track.values = values;
    if (!st && which == PATH_R) {
        /* the keys' own quaternions must have a direction (tangents may be zero) */
        for (size_t k = 0; k < c.track.n && !st; k++) {
            const double *q = values + (c.track.interp == KEY_CUBICSPLINE ? 3 * k + 1 : k) * 4;
            if (!(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] > 0))
                st = error_set(g->err, ST_INPUT, "%s: %s.output: key %zu is a zero quaternion", g->path, js, k);
        }
    }
    if (!st) st = channel_add(a, &c);
    if (st) channel_free(&c);
    return st;
}

static Status animations_read(GltfAnimated *a)
{
    Gltf *g = &a->g;
    const cJSON *anims = cJSON_GetObjectItemCaseSensitive(g->root, "animations");
    if (anims && !cJSON_IsArray(anims)) return gltf_bad(g, "animations", "expected an array");
    int ai = 0;
    Status st = ST_OK;
    for (const cJSON *an = gltf_first_of(anims); an && !st; an = an->next, ai++) {
        const cJSON *chans = cJSON_GetObjectItemCaseSensitive(an, "channels");
        char jp[64];
        snprintf(jp, sizeof jp, "animations[%d]", ai);
        if (!cJSON_IsArray(chans)) return gltf_bad(g, jp, "channels: expected an array");
        int ci = 0;
        for (const cJSON *c = gltf_first_of(chans); c && !st; c = c->next, ci++) st = channel_read(a, an, ai, c, ci);
    }
    return st;
}

/* Each node's parent (-1 for a root), for a node's world transform. */
static Status parents_find(GltfAnimated *a)
{
    Gltf *g = &a->g;
    a->parent = malloc(((size_t)g->n_nodes + 1) * sizeof *a->parent);
    if (!a->parent) return error_set(g->err, ST_INTERNAL, "out of memory");
    for (int n = 0; n < g->n_nodes; n++) a->parent[n] = -1;
    for (int n = 0; n < g->n_nodes; n++) {
        const cJSON *kids = cJSON_GetObjectItemCaseSensitive(gltf_item_at(g, "nodes", n), "children");
        for (const cJSON *c = gltf_first_of(kids); c; c = c->next)
            if (cJSON_IsNumber(c) && c->valuedouble >= 0 && c->valuedouble < g->n_nodes)
                a->parent[(int)c->valuedouble] = n;
    }
    return ST_OK;
}

/* ------------------------------------------------------------------ evaluation */

/* Every animated node's animated parts at time t into pose (per node). */
static void gltf_anim_eval(const GltfAnimated *a, double t, GltfNodePose *pose)
{
    for (int n = 0; n < a->g.n_nodes; n++) pose[n].animated = 0;
    for (size_t i = 0; i < a->n_ch; i++) {
        const GltfChannel *c = &a->ch[i];
        GltfNodePose *p = &pose[c->node];
        double *out = c->path == PATH_T ? p->t : c->path == PATH_R ? p->r : p->s;
        key_track_eval(&c->track, t, out);
        p->animated |= c->path == PATH_T ? GLTF_ANIM_T : c->path == PATH_R ? GLTF_ANIM_R : GLTF_ANIM_S;
    }
}

Status gltf_anim_node_trs(GltfAnimated *a, int node, double t, double tr[3], double r[4], double sc[3], Error *err)
{
    Gltf *g = &a->g;
    if (node < 0 || node >= g->n_nodes) return error_set(err, ST_INTERNAL, "no node %d", node);
    g->err = err;
    static const double t0[3] = { 0, 0, 0 }, r0[4] = { 0, 0, 0, 1 }, s0[3] = { 1, 1, 1 };
    char jp[64];
    snprintf(jp, sizeof jp, "nodes[%d]", node);
    const cJSON *n = gltf_item_at(g, "nodes", node);
    Status st;
    if ((st = gltf_get_nums(g, n, "translation", 3, t0, jp, tr)) || (st = gltf_get_nums(g, n, "rotation", 4, r0, jp, r)) ||
        (st = gltf_get_nums(g, n, "scale", 3, s0, jp, sc)))
        return st;
    gltf_anim_eval(a, t, a->pose);
    const GltfNodePose *p = &a->pose[node];
    if (p->animated & GLTF_ANIM_T) memcpy(tr, p->t, sizeof p->t);
    if (p->animated & GLTF_ANIM_R) memcpy(r, p->r, sizeof p->r);
    if (p->animated & GLTF_ANIM_S) memcpy(sc, p->s, sizeof p->s);
    return ST_OK;
}

/* Node `node`'s world transform at time t, evaluated into the per-node buffer `pose`
 * (the walk's own, or the shutter's second one while the walk uses the first). */
static Status node_world(GltfAnimated *a, GltfNodePose *pose, int node, double t, Transform *out, Error *err)
{
    Gltf *g = &a->g;
    if (node < 0 || node >= g->n_nodes) return error_set(err, ST_INTERNAL, "no node %d", node);
    g->err = err;
    /* the chain from the node up to its root */
    int depth = 0;
    for (int n = node; n >= 0; n = a->parent[n])
        if (++depth > g->n_nodes) return gltf_bad(g, "nodes", "the node tree has a cycle");
    int *chain = malloc((size_t)depth * sizeof *chain);
    if (!chain) return error_set(err, ST_INTERNAL, "out of memory");
    int i = depth;
    for (int n = node; n >= 0; n = a->parent[n]) chain[--i] = n;
    gltf_anim_eval(a, t, pose);
    const GltfNodePose *walk_pose = g->pose;
    g->pose = pose;
    /* composed from the root down, as the node walk composes it: the same bits */
    Transform xf = transform_identity();
    Status st = ST_OK;
    for (i = 0; i < depth && !st; i++) {
        Transform local;
        if (!(st = gltf_node_local(g, chain[i], &local))) xf = transform_compose(&xf, &local);
    }
    g->pose = walk_pose;
    free(chain);
    *out = transform_compose(&a->o.xf, &xf);
    return st;
}

Status gltf_anim_node_world(GltfAnimated *a, int node, double t, Transform *out, Error *err)
{
    return node_world(a, a->pose, node, t, out, err);
}

/* Whether a node shows something but a camera: a mesh (with EXT_mesh_gpu_instancing
 * or not) or a punctual light. */
static int node_shows(const Gltf *g, int n)
{
    const cJSON *node = gltf_item_at(g, "nodes", n);
    return cJSON_GetObjectItemCaseSensitive(node, "mesh") || gltf_ext_of(node, "KHR_lights_punctual");
}

/* An animation that moves only cameras: no animated node carries a mesh or a light,
 * itself or below it. A search over the nodes below the animated ones, each looked at
 * once (an animated node outside the scene's tree was not checked by the walk: its
 * children may repeat or loop). Without memory: no (the safe answer). */
static int moves_camera_only(const GltfAnimated *a)
{
    const Gltf *g = &a->g;
    unsigned char *seen = calloc((size_t)g->n_nodes + 1, 1);
    int *stack = malloc(((size_t)g->n_nodes + 1) * sizeof *stack);
    int only = seen && stack, top = 0;
    for (size_t i = 0; i < a->n_ch && only; i++) {
        if (seen[a->ch[i].node]) continue;
        seen[a->ch[i].node] = 1;
        stack[top++] = a->ch[i].node;
        while (top > 0 && only) {
            int n = stack[--top];
            if (node_shows(g, n)) only = 0;
            const cJSON *kids = cJSON_GetObjectItemCaseSensitive(gltf_item_at(g, "nodes", n), "children");
            for (const cJSON *c = gltf_first_of(kids); c && only; c = c->next) {
                if (!cJSON_IsNumber(c) || !(c->valuedouble >= 0 && c->valuedouble < g->n_nodes)) continue;
                int k = (int)c->valuedouble;
                if (seen[k]) continue;
                seen[k] = 1;
                stack[top++] = k;
            }
        }
    }
    free(seen);
    free(stack);
    return only;
}

/* ------------------------------------------------------------------ frames */

static Status anim_pose(SceneAnimation *base, void *vscene, double t, Error *err)
{
    GltfAnimated *a = (GltfAnimated *)base;
    Scene *s = vscene;
    Gltf *g = &a->g;
    g->s = s;
    g->err = err;
    uint width = s->image.width, height = s->image.height;
    if (a->base.camera_only) {
        /* the geometry stays as placed (the devices keep it): the camera alone, by the
         * transform the walk would give its node */
        Transform w;
        Status st = g->camera_node < 0 ? ST_OK : gltf_anim_node_world(a, g->camera_node, t, &w, err);
        if (!st && g->camera_node >= 0) st = gltf_camera_set(g, g->camera_index, &w);
        s->image.width = width;
        s->image.height = height;
        return st;
    }
    Status st = scene_rewind(s, &a->mark, err);
    if (st) return st;
    size_t n_warnings = s->n_warnings;
    gltf_anim_eval(a, t, a->pose);
    g->pose = a->pose;
    st = gltf_place(g);
    g->pose = NULL;
    /* the size was settled by the first frame and the command line */
    s->image.width = width;
    s->image.height = height;
    /* the first placement's warnings were said; each frame's would be the same */
    while (s->n_warnings > n_warnings) free(s->warnings[--s->n_warnings]);
    return st;
}

/* ------------------------------------------------------------------ shutter */

/* Adds t to the increasing times[*n] (room for MOTION_MAX_KEYS + 1) unless it is not
 * after the last as a float, the time a key keeps: keys must increase there. */
static void time_add(double *times, size_t *n, double t)
{
    if (*n > MOTION_MAX_KEYS) return;
    if (*n > 0 && !((float)t > (float)times[*n - 1])) return;
    times[(*n)++] = t;
}

/* The times the shutter [open, close] is sampled at: the open, every key time of a
 * channel inside it, the close; a CUBICSPLINE channel's curve between keys is followed
 * by 3 more times in each interval (the keys' own interpolation is linear in
 * translation and scale, slerp in rotation: exact for LINEAR channels of one node).
 * More than MOTION_MAX_KEYS: that many times evenly over the shutter instead. */
static size_t shutter_times(const GltfAnimated *a, double open, double close, double *times)
{
    size_t n_inside = 0;
    int cubic = 0, no_memory = 0;
    double *inside = NULL;
    size_t cap = 0;
    for (size_t i = 0; i < a->n_ch && !no_memory; i++) {
        const KeyTrack *k = &a->ch[i].track;
        cubic |= k->interp == KEY_CUBICSPLINE;
        for (size_t j = 0; j < k->n && !no_memory; j++) {
            if (!(k->times[j] > open && k->times[j] < close)) continue;
            if (n_inside == cap) {
                double *grown = realloc(inside, (cap ? 2 * cap : 16) * sizeof *grown);
                no_memory = !grown;
                if (no_memory) break;
                inside = grown;
                cap = cap ? 2 * cap : 16;
            }
            inside[n_inside++] = k->times[j];
        }
    }
    /* without memory for the key times: the even spread */
    if (no_memory) n_inside = MOTION_MAX_KEYS + 1;
    size_t n = 0;
    size_t steps = cubic ? 4 : 1;
    if ((n_inside + 1) * steps + 1 <= MOTION_MAX_KEYS) {
        /* sorted by insertion: few keys lie inside a shutter */
        for (size_t i = 1; i < n_inside; i++)
            for (size_t j = i; j > 0 && inside[j - 1] > inside[j]; j--) {
                double x = inside[j];
                inside[j] = inside[j - 1];
                inside[j - 1] = x;
            }
        double prev = open;
        time_add(times, &n, open);
        for (size_t i = 0; i <= n_inside; i++) {
            double next = i < n_inside ? inside[i] : close;
            if (!(next > prev)) continue;
            for (size_t j = 1; j <= steps; j++)
                time_add(times, &n, j == steps ? next : prev + (next - prev) * (double)j / (double)steps);
            prev = next;
        }
    } else {
        for (size_t j = 0; j < MOTION_MAX_KEYS; j++)
            time_add(times, &n, j + 1 == MOTION_MAX_KEYS ? close : open + (close - open) * (double)j /
                                                                   (double)(MOTION_MAX_KEYS - 1));
    }
    free(inside);
    return n;
}

static Status blur_world_at(void *ctx, int node, double t, Transform *out, Error *err)
{
    GltfAnimated *a = ctx;
    return node_world(a, a->pose_at, node, t, out, err);
}

/* The nodes whose world transform at some sampled time differs from the open's: a
 * node animated while the shutter is open, or below one. One whose chain cannot be
 * evaluated (the walk reports why) is taken as still. */
static Status moving_nodes(GltfAnimated *a, const double *times, size_t n, unsigned char *moves, Error *err)
{
    for (int node = 0; node < a->g.n_nodes; node++) {
        Transform w0, w;
        Error ignored = { 0 };
        if (node_world(a, a->pose_at, node, times[0], &w0, &ignored)) continue;
        for (size_t k = 1; k < n && !moves[node]; k++) {
            if (node_world(a, a->pose_at, node, times[k], &w, &ignored)) break;
            moves[node] = memcmp(&w, &w0, sizeof w) != 0;
        }
    }
    (void)err;
    return ST_OK;
}

/* The camera's node moving: the camera's pose at times[0] is the walk's; a camera key
 * at each later time (docs/motion.md). */
static Status camera_keys_add(GltfAnimated *a, Scene *s, const double *times, size_t n, Error *err)
{
    free(s->camera_keys);
    s->camera_keys = calloc(n, sizeof *s->camera_keys);
    s->n_camera_keys = s->cap_camera_keys = 0;
    if (!s->camera_keys) return error_set(err, ST_INTERNAL, "out of memory");
    s->cap_camera_keys = n;
    s->camera.time = (float)times[0];
    for (size_t k = 1; k < n; k++) {
        Transform w;
        Status st = node_world(a, a->pose_at, a->g.camera_node, times[k], &w, err);
        if (st) return st;
        SceneCameraKey *ck = &s->camera_keys[s->n_camera_keys++];
        ck->time = (float)times[k];
        gltf_camera_frame(&w, &ck->from, &ck->at, &ck->up);
    }
    return ST_OK;
}

/* The scene placed at the open's pose, the nodes that move over [open, close] with
 * keys sampled from the animation (meshes as moving instances, the camera with camera
 * keys) and the camera's shutter [open, close]. Again for each frame of --frames. */
static Status anim_pose_shutter(SceneAnimation *base, void *vscene, double open, double close, Error *err)
{
    GltfAnimated *a = (GltfAnimated *)base;
    Scene *s = vscene;
    /* the keys of a frame before (--frames with --shutter F) go: this reader made every
     * key the scene holds (scene_rewind keeps the instances before the node tree, and
     * a glTF file's own have none) */
    s->n_motion_keys = 0;
    s->n_instance_motion = 0;
    s->n_camera_keys = 0;
    double times[MOTION_MAX_KEYS + 1];
    size_t n = shutter_times(a, open, close, times);
    unsigned char *moves = calloc((size_t)a->g.n_nodes + 1, 1);
    if (!moves) return error_set(err, ST_INTERNAL, "out of memory");
    Status st = moving_nodes(a, times, n, moves, err);
    int any = 0;
    for (int i = 0; i < a->g.n_nodes; i++) any |= moves[i];
    if (!st && !any) {
        /* nothing moves while it is open: the still pose, the same bits as --time */
        free(moves);
        return anim_pose(base, vscene, open, err);
    }
    GltfBlur blur = { moves, times, n, blur_world_at, a };
    /* the whole scene is placed again, with the moving meshes as instances */
    int camera_only = a->base.camera_only;
    a->base.camera_only = 0;
    a->g.blur = &blur;
    if (!st) st = anim_pose(base, vscene, open, err);
    a->g.blur = NULL;
    a->base.camera_only = camera_only;
    if (!st && a->g.camera_node >= 0 && moves[a->g.camera_node]) st = camera_keys_add(a, s, times, n, err);
    if (!st) {
        s->camera.shutter_open = (float)open;
        s->camera.shutter_close = (float)close;
    }
    free(moves);
    return st;
}

static void anim_free(SceneAnimation *base)
{
    GltfAnimated *a = (GltfAnimated *)base;
    if (!a) return;
    gltf_close(&a->g);
    for (size_t i = 0; i < a->n_ch; i++) channel_free(&a->ch[i]);
    free(a->ch);
    free(a->pose);
    free(a->pose_at);
    free(a->parent);
    free(a->data);
    free(a->path);
    free(a);
}

Status gltf_parse_animated(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o,
                           GltfView *view, Error *err)
{
    GltfAnimated *a = calloc(1, sizeof *a);
    if (!a) return error_set(err, ST_INTERNAL, "out of memory");
    a->base.pose = anim_pose;
    a->base.pose_shutter = anim_pose_shutter;
    a->base.free = anim_free;
    a->data = malloc(len + 1);
    a->path = strdup(path);
    a->o = *o;
    if (view) a->view = *view;
    gltf_init(&a->g, a->path, s, &a->o, view ? &a->view : NULL, err);
    if (!a->data || !a->path) {
        anim_free(&a->base);
        return error_set(err, ST_INTERNAL, "out of memory");
    }
    memcpy(a->data, data, len);
    a->data[len] = '\0';
    Status st = gltf_open(&a->g, a->data, len);
    if (!st) st = animations_read(a);
    if (!st) st = parents_find(a);
    if (!st && (!(a->pose = calloc((size_t)a->g.n_nodes + 1, sizeof *a->pose)) ||
                !(a->pose_at = calloc((size_t)a->g.n_nodes + 1, sizeof *a->pose_at))))
        st = error_set(err, ST_INTERNAL, "out of memory");
    scene_mark(s, &a->mark);
    if (!st) st = gltf_place(&a->g);
    if (view) {
        view->has_camera = a->view.has_camera;
        view->has_lights = a->g.has_lights;
    }
    for (size_t i = 0; i < a->n_ch; i++) {
        const KeyTrack *k = &a->ch[i].track;
        a->base.end = fmax(a->base.end, k->times[k->n - 1]);
    }
    /* --shutter takes a still file as it is (nothing moves); --frames and --time need
     * something to pose */
    if (!st && a->n_ch == 0 && s->keep_animation != KEEP_ANIMATION_IF_ANY)
        st = error_set(err, ST_INPUT, "%s: the file has no animation of a node's translation, rotation or scale "
                       "to pose (--frames, --time)", path);
    a->base.camera_only = !st && moves_camera_only(a);
    if (st) {
        anim_free(&a->base);
        return st;
    }
    s->animation = &a->base;
    return ST_OK;
}
