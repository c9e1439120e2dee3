/* view_camera.c — see view_camera.h. The frame is computed in double and the result
 * rounded to float once, as the scene parser stores it. */
#include "viewer/view_camera.h"

#include "base/dvec3.h"

#include <math.h>

/* The camera's orthonormal frame: forward f, right r (the image's +x), true up v. */
typedef struct { dvec3 f, r, v, up; double dist; } Frame;

static Frame frame_of(const SceneCamera *c)
{
    Frame fr;
    dvec3 view = dv3_sub(dv3_of(c->at), dv3_of(c->from));
    fr.dist = sqrt(dv3_dot(view, view));
    fr.f = dv3_norm(view);
    fr.up = dv3_norm(dv3_of(c->up));
    fr.r = dv3_norm(dv3_cross(fr.f, fr.up));
    fr.v = dv3_cross(fr.r, fr.f);
    return fr;
}

void view_camera_move(SceneCamera *c, double right, double up, double forward)
{
    Frame fr = frame_of(c);
    dvec3 d = dv3_add(dv3_add(dv3_scale(fr.r, right), dv3_scale(fr.up, up)), dv3_scale(fr.f, forward));
    c->from = dv3_to_float(dv3_add(dv3_of(c->from), d));
    c->at = dv3_to_float(dv3_add(dv3_of(c->at), d));
}

int view_camera_turn(SceneCamera *c, double yaw, double pitch)
{
    const double deg = 3.14159265358979323846 / 180.0;
    Frame fr = frame_of(c);
    /* yaw in the forward-right plane, then pitch in the forward-up plane */
    dvec3 f = dv3_add(dv3_scale(fr.f, cos(yaw * deg)), dv3_scale(fr.r, sin(yaw * deg)));
    dvec3 r = dv3_norm(dv3_cross(f, fr.up));
    dvec3 v = dv3_cross(r, f);
    f = dv3_norm(dv3_add(dv3_scale(f, cos(pitch * deg)), dv3_scale(v, sin(pitch * deg))));
    if (fabs(dv3_dot(f, fr.up)) > 0.999) return 0;
    dvec3 at = dv3_add(dv3_of(c->from), dv3_scale(f, fr.dist));
    vec3 at_f = dv3_to_float(at);
    if (at_f.x == c->from.x && at_f.y == c->from.y && at_f.z == c->from.z) return 0;
    c->at = at_f;
    return 1;
}

void view_camera_zoom(SceneCamera *c, double factor)
{
    double fov = (double)c->vfov * factor;
    c->vfov = (float)(fov < 1.0 ? 1.0 : (fov > 170.0 ? 170.0 : fov));
}

void view_camera_focus(SceneCamera *c, double factor)
{
    double focus = c->focus_dist > 0.0f ? (double)c->focus_dist : frame_of(c).dist;
    float next = (float)(focus * factor);
    if (next > 0.0f && isfinite(next)) c->focus_dist = next;
}

void view_camera_aperture(SceneCamera *c, double factor, double first)
{
    double a = (double)c->aperture;
    if (a <= 0.0) a = factor > 1.0 ? first : 0.0;
    else a *= factor;
    if (a < first / 8.0) a = 0.0;
    c->aperture = (float)a;
}

/* An orthographic camera given by its view's width (clpt's format) prints as it is. */
static void print_orthographic(FILE *f, const SceneCamera *c)
{
    fprintf(f, "camera { type orthographic  from %.9g %.9g %.9g  at %.9g %.9g %.9g  up %.9g %.9g %.9g  width %.9g }\n",
            (double)c->from.x, (double)c->from.y, (double)c->from.z, (double)c->at.x, (double)c->at.y,
            (double)c->at.z, (double)c->up.x, (double)c->up.y, (double)c->up.z, (double)c->ortho_width);
}

int view_camera_print(FILE *f, const SceneCamera *c)
{
    if (c->type == CAMERA_ORTHOGRAPHIC && c->ortho_width > 0.0f) {
        print_orthographic(f, c);
        return 0;
    }
    int exact = c->type == CAMERA_PERSPECTIVE && !c->course_basis;
    if (!exact)
        fprintf(f, "# this scene's camera (%s) has no form in clpt's scene format; "
                   "the block below is a perspective camera at the same place\n",
                c->type == CAMERA_ORTHOGRAPHIC ? "orthographic, sized by its height" : "the course's perspective basis");
    fprintf(f, "camera { from %.9g %.9g %.9g  at %.9g %.9g %.9g  up %.9g %.9g %.9g  fov %.9g",
            (double)c->from.x, (double)c->from.y, (double)c->from.z, (double)c->at.x, (double)c->at.y,
            (double)c->at.z, (double)c->up.x, (double)c->up.y, (double)c->up.z, (double)c->vfov);
    if (c->aperture > 0.0f) fprintf(f, "  aperture %.9g", (double)c->aperture);
    if (c->focus_dist > 0.0f) fprintf(f, "  focus %.9g", (double)c->focus_dist);
    fputs(" }\n", f);
    return exact ? 0 : -1;
}
