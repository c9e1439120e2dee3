/* camera_path.c — a camera moved along keys (camera_path.h). */
#include "scene/camera_path.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/keyframes.h"
#include "util/kmath.h"
#include "scene/scene.h"

/* One track per camera value, with its times and values (CUBICSPLINE's layout for the
 * smooth path: in-tangent, value, out-tangent per key). */
enum { TRACK_FROM, TRACK_AT, TRACK_UP, TRACK_FOV, TRACK_N };

typedef struct {
    SceneAnimation base;       /* first: the scene frees and poses through it */
    double *times;
    double *values[TRACK_N];
    KeyTrack track[TRACK_N];
} CameraPath;

static Status path_pose(SceneAnimation *base, void *vscene, double t, Error *err)
{
    CameraPath *cp = (CameraPath *)base;
    Scene *s = vscene;
    double v[TRACK_N][3];
    for (int i = 0; i < TRACK_N; i++) key_track_eval(&cp->track[i], t, v[i]);
    /* a smooth path overshoots its keys: near the float range's end it may leave it */
    for (int i = 0; i < TRACK_N; i++)
        for (int j = 0; j < (i == TRACK_FOV ? 1 : 3); j++)
            if (!(fabs(v[i][j]) <= FLT_MAX))
                return error_set(err, ST_INPUT, "%s: the camera_path at %g s leaves the float range", s->path, t);
    s->camera.from = v3((float)v[TRACK_FROM][0], (float)v[TRACK_FROM][1], (float)v[TRACK_FROM][2]);
    s->camera.at = v3((float)v[TRACK_AT][0], (float)v[TRACK_AT][1], (float)v[TRACK_AT][2]);
    s->camera.up = v3((float)v[TRACK_UP][0], (float)v[TRACK_UP][1], (float)v[TRACK_UP][2]);
    s->camera.vfov = (float)v[TRACK_FOV][0];
    /* a degenerate pose between keys (the eye through the point looked at) is refused
     * by camera_setup when the frame is prepared */
    return ST_OK;
}

static void path_free(SceneAnimation *base)
{
    CameraPath *cp = (CameraPath *)base;
    free(cp->times);
    for (int i = 0; i < TRACK_N; i++) free(cp->values[i]);
    free(cp);
}

/* Key k's value of track `track` (width doubles). */
static const double *key_value(const CameraKey *k, int track)
{
    return track == TRACK_FROM ? k->from : track == TRACK_AT ? k->at : track == TRACK_UP ? k->up : &k->fov;
}

/* The smooth path's tangent at key k: Catmull-Rom's, the chord of the neighbours over
 * their time apart (Catmull and Rom 1974, in the non-uniform form for keys at any
 * times), one-sided at the ends. */
static double tangent(const CameraKey *keys, size_t n, size_t k, int track, int j)
{
    if (n < 2) return 0.0;
    size_t a = k > 0 ? k - 1 : 0, b = k + 1 < n ? k + 1 : n - 1;
    return (key_value(&keys[b], track)[j] - key_value(&keys[a], track)[j]) / (keys[b].t - keys[a].t);
}

Status camera_path_animation(const CameraKey *keys, size_t n, int interp, SceneAnimation **out, Error *err)
{
    CameraPath *cp = calloc(1, sizeof *cp);
    int smooth = interp == CAMERA_PATH_SMOOTH;
    size_t per_key = smooth ? 3 : 1;
    if (cp) cp->times = malloc(n * sizeof *cp->times);
    for (int i = 0; cp && i < TRACK_N; i++) cp->values[i] = malloc(n * per_key * 3 * sizeof(double));
    int failed = !cp || !cp->times;
    for (int i = 0; !failed && i < TRACK_N; i++) failed = !cp->values[i];
    if (failed) {
        if (cp) path_free(&cp->base);
        return error_set(err, ST_INTERNAL, "out of memory for the camera path");
    }
    cp->base.pose = path_pose;
    cp->base.free = path_free;
    cp->base.end = keys[n - 1].t;
    cp->base.camera_only = 1;
    for (size_t k = 0; k < n; k++) cp->times[k] = keys[k].t;
    for (int i = 0; i < TRACK_N; i++) {
        int w = i == TRACK_FOV ? 1 : 3;
        for (size_t k = 0; k < n; k++) {
            double *v = cp->values[i] + k * per_key * (size_t)w;
            for (int j = 0; j < w; j++) {
                if (!smooth) {
                    v[j] = key_value(&keys[k], i)[j];
                    continue;
                }
                double m = tangent(keys, n, k, i, j);
                v[j] = m;
                v[w + j] = key_value(&keys[k], i)[j];
                v[2 * w + j] = m;
            }
        }
        KeyTrack tr = { smooth ? KEY_CUBICSPLINE : interp == CAMERA_PATH_STEP ? KEY_STEP : KEY_LINEAR, w, 0, n,
                        cp->times, cp->values[i] };
        cp->track[i] = tr;
    }
    *out = &cp->base;
    return ST_OK;
}
