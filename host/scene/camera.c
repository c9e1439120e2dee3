/* camera.c — the thin-lens camera of "Ray Tracing in One Weekend" and the orthographic
 * camera of the classic ray tracer, prepared in double precision on the host so every
 * device starts from the same float values. */
#include "scene/camera.h"

#include "base/dvec3.h"
#include "scene/motion.h"
#include "util/kmath.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double camera_min_focus(vec3 from)
{
    double m = fmax(fabs((double)from.x), fmax(fabs((double)from.y), fabs((double)from.z)));
    return fmax(m * 0x1p-12, 0x1p-60);
}

double camera_focus(const SceneCamera *desc)
{
    dvec3 back = dv3_sub(dv3_of(desc->from), dv3_of(desc->at));
    double focus = desc->focus_dist > 0.0f ? (double)desc->focus_dist : sqrt(dv3_dot(back, back));
    /* a pinhole's rays do not depend on the distance of the view rectangle: put it
     * where float keeps the directions precise (a target 1e-40 from the eye rendered
     * black) */
    if (desc->aperture == 0.0f && focus < camera_min_focus(desc->from))
        focus = fmax(1.0, camera_min_focus(desc->from) * 0x1p12);
    return focus;
}

/* The kernel camera, rounded to float once from the double frame. */
static void camera_fill(Camera *out, uint type, dvec3 from, dvec3 corner, dvec3 horizontal, dvec3 vertical,
                        dvec3 u, dvec3 v, dvec3 w, float lens_radius)
{
    memset(out, 0, sizeof *out);
    out->type = type;
    out->origin = dv3_to_float(from);
    out->lens_radius = lens_radius;
    out->corner = dv3_to_float(corner);
    out->horizontal = dv3_to_float(horizontal);
    out->vertical = dv3_to_float(vertical);
    out->lens_u = dv3_to_float(u);
    out->lens_v = dv3_to_float(v);
    out->forward = dv3_to_float(dv3_scale(w, -1.0));
}

Status camera_setup(const SceneCamera *desc, uint width, uint height, Camera *out, Error *err)
{
    dvec3 from = dv3_of(desc->from), at = dv3_of(desc->at), up = dv3_of(desc->up);
    dvec3 back = dv3_sub(from, at);
    double dist = sqrt(dv3_dot(back, back));
    if (!(dist > 0.0) || !isfinite(dist))
        return error_set(err, ST_INPUT, "camera: 'from' and 'at' must be distinct finite points");
    double ortho_h = desc->ortho_width > 0.0f ? (double)desc->ortho_width * height / width : desc->ortho_height;
    if (desc->type == CAMERA_ORTHOGRAPHIC && !(ortho_h > 0.0 && isfinite(ortho_h)))
        return error_set(err, ST_INPUT, "camera: the orthographic view size must be > 0, got %g", ortho_h);
    if (desc->type != CAMERA_ORTHOGRAPHIC && !(desc->vfov > 0.0f && desc->vfov < 180.0f))
        return error_set(err, ST_INPUT, "camera: fov must be between 0 and 180 degrees, got %g",
                         (double)desc->vfov);
    if (!(desc->aperture >= 0.0f) || !isfinite(desc->aperture))
        return error_set(err, ST_INPUT, "camera: aperture must be >= 0, got %g", (double)desc->aperture);
    dvec3 w = dv3_scale(back, 1.0 / dist);
    dvec3 u = dv3_cross(up, w);
    double ulen = sqrt(dv3_dot(u, u));
    if (!(ulen > 1e-9 * sqrt(dv3_dot(up, up))) || !(ulen > 0.0))
        return error_set(err, ST_INPUT, "camera: 'up' must not be zero or parallel to the view direction");
    u = dv3_scale(u, 1.0 / ulen);
    dvec3 v = dv3_cross(w, u);
    /* a left-handed frame (pbrt's camera space) puts +x of the image the other way */
    if (desc->mirror_x) u = dv3_scale(u, -1.0);

    if (desc->type == CAMERA_ORTHOGRAPHIC) {
        /* the view rectangle through the camera centre: ortho_width wide when given
         * (exactly: the width is not recomputed from the height), else ortho_height
         * tall */
        double vp_h = ortho_h, vp_w = desc->ortho_width > 0.0f ? (double)desc->ortho_width
                                                               : vp_h * (double)width / (double)height;
        dvec3 horizontal = dv3_scale(u, vp_w), vertical = dv3_scale(v, vp_h);
        dvec3 corner = { from.x - horizontal.x / 2 + vertical.x / 2, from.y - horizontal.y / 2 + vertical.y / 2,
                         from.z - horizontal.z / 2 + vertical.z / 2 };
        camera_fill(out, CAMERA_ORTHOGRAPHIC, from, corner, horizontal, vertical, u, v, w, 0.0f);
        return ST_OK;
    }

    double focus = camera_focus(desc);
    if (!isfinite(focus))
        return error_set(err, ST_INPUT, "camera: focus distance must be finite");
    if (focus < camera_min_focus(desc->from))
        return error_set(err, ST_INPUT, "camera: the focus distance %g is too short for single precision "
                         "at 'from' %g %g %g (at least %g)", focus, (double)desc->from.x,
                         (double)desc->from.y, (double)desc->from.z, camera_min_focus(desc->from));
    double h = tan((double)desc->vfov * M_PI / 360.0);
    double vp_h = 2.0 * h * focus;
    double vp_w = vp_h * (double)width / (double)height;
    /* the course's camera keeps `up` as given (length too) for the vertical axis, so
     * vertical lines stay vertical when it looks down or up */
    dvec3 horizontal = dv3_scale(u, vp_w), vertical = dv3_scale(desc->course_basis ? up : v, vp_h);
    dvec3 corner = { from.x - horizontal.x / 2 + vertical.x / 2 - focus * w.x,
                     from.y - horizontal.y / 2 + vertical.y / 2 - focus * w.y,
                     from.z - horizontal.z / 2 + vertical.z / 2 - focus * w.z };

    camera_fill(out, CAMERA_PERSPECTIVE, from, corner, horizontal, vertical, u, v, w, (float)(desc->aperture * 0.5));
    return ST_OK;
}

/* The camera-to-world frame of a pose, as camera_setup spans the image: columns right
 * (u, flipped for a left-handed frame), v and back (w), and `from`. */
static Transform camera_frame(const SceneCamera *desc)
{
    dvec3 from = dv3_of(desc->from), at = dv3_of(desc->at), up = dv3_of(desc->up);
    dvec3 w = dv3_norm(dv3_sub(from, at));
    dvec3 u = dv3_norm(dv3_cross(up, w));
    dvec3 v = dv3_cross(w, u);
    if (desc->mirror_x) u = dv3_scale(u, -1.0);
    Transform t = { { { u.x, v.x, w.x, from.x }, { u.y, v.y, w.y, from.y }, { u.z, v.z, w.z, from.z } } };
    return t;
}

/* A world point or vector of the prepared camera carried into the frame f (whose
 * linear part is orthonormal: its inverse is its transpose); w = 1 for a point. */
static vec3 camera_local(const Transform *f, vec3 a, double w)
{
    double d[3] = { a.x - w * f->m[0][3], a.y - w * f->m[1][3], a.z - w * f->m[2][3] };
    return v3((float)(f->m[0][0] * d[0] + f->m[1][0] * d[1] + f->m[2][0] * d[2]),
              (float)(f->m[0][1] * d[0] + f->m[1][1] * d[1] + f->m[2][1] * d[2]),
              (float)(f->m[0][2] * d[0] + f->m[1][2] * d[1] + f->m[2][2] * d[2]));
}

Status camera_setup_moving(const Scene *scene, uint width, uint height, uint motion_first, Camera *out,
                           MotionKey **keys, Error *err)
{
    *keys = NULL;
    const SceneCamera *desc = &scene->camera;
    Status st = camera_setup(desc, width, height, out, err);
    if (st) return st;
    /* read only where something moves (Camera.moving) */
    out->shutter_open = desc->shutter_open;
    out->shutter_close = desc->shutter_close;
    if (scene->n_camera_keys == 0) return ST_OK;
    size_t n = scene->n_camera_keys + 1;
    MotionKey *k = calloc(n, sizeof *k);
    if (!k) return error_set(err, ST_INTERNAL, "out of memory");
    for (size_t i = 0; i < n; i++) {
        SceneCamera pose = *desc;
        if (i > 0) {
            const SceneCameraKey *ck = &scene->camera_keys[i - 1];
            pose.from = ck->from;
            pose.at = ck->at;
            pose.up = ck->up;
            pose.time = ck->time;
            Camera check;
            if ((st = camera_setup(&pose, width, height, &check, err))) break;
        }
        Transform f = camera_frame(&pose);
        if ((st = motion_key_make(&f, pose.time, &k[i], err))) break;
    }
    if (st) {
        free(k);
        return st;
    }
    motion_keys_shortest_arcs(k, n);
    Transform f0 = camera_frame(desc);
    out->origin = camera_local(&f0, out->origin, 1.0);
    out->corner = camera_local(&f0, out->corner, 1.0);
    out->horizontal = camera_local(&f0, out->horizontal, 0.0);
    out->vertical = camera_local(&f0, out->vertical, 0.0);
    out->lens_u = camera_local(&f0, out->lens_u, 0.0);
    out->lens_v = camera_local(&f0, out->lens_v, 0.0);
    out->forward = camera_local(&f0, out->forward, 0.0);
    out->motion_first = motion_first;
    out->motion_keys = (uint)n;
    *keys = k;
    return ST_OK;
}
