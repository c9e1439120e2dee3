/* mesh_view.c — the automatic scene around a bare mesh (mesh_view.h). */
#include "io/mesh_view.h"

#include "util/kmath.h"
#include "io/mesh_load.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define VIEW_FOV_DEGREES 40.0
/* Direction from the mesh's centre to the camera and to the sun (need not be unit). */
static const double view_dir[3] = { 0.35, 0.3, 1.0 };
static const double sun_dir[3] = { -0.5, 1.0, 0.35 };
/* The sun: its angular radius, its distance in bounding-sphere radii, and the
 * irradiance it gives a surface facing it (the sky adds about half as much again). */
#define SUN_HALF_ANGLE_DEGREES 1.25
#define SUN_DISTANCE_RADII 20.0
#define SUN_IRRADIANCE 1.6

/* Centre and radius of the bounding sphere of the finite vertices. */
static int mesh_sphere(const Scene *s, double c[3], double *radius)
{
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t i = 0; i < s->n_triangles; i++) {
        const vec3 *p[3] = { &s->triangles[i].p0, &s->triangles[i].p1, &s->triangles[i].p2 };
        for (int j = 0; j < 3; j++) {
            const double q[3] = { p[j]->x, p[j]->y, p[j]->z };
            if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
            for (int a = 0; a < 3; a++) {
                lo[a] = fmin(lo[a], q[a]);
                hi[a] = fmax(hi[a], q[a]);
            }
        }
    }
    if (!(lo[0] <= hi[0])) return 0;
    double r2 = 0.0;
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5 * (lo[a] + hi[a]);
        r2 += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    *radius = sqrt(r2) > 0.0 ? sqrt(r2) : 1.0;
    return 1;
}

static vec3 along(const double c[3], const double dir[3], double dist)
{
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    return v3((float)(c[0] + dir[0] / len * dist), (float)(c[1] + dir[1] / len * dist),
              (float)(c[2] + dir[2] / len * dist));
}

Status mesh_view_fit(Scene *s, Error *err)
{
    double c[3], r;
    if (!mesh_sphere(s, c, &r)) return ST_OK;
    /* the narrower of the two fields of view must hold the sphere */
    double half_v = VIEW_FOV_DEGREES * M_PI / 360.0;
    double aspect = (double)s->image.width / (double)s->image.height;
    double half_h = atan(tan(half_v) * aspect);
    double half = fmin(half_v, half_h);
    double dist = 1.05 * r / sin(half);
    vec3 from = along(c, view_dir, dist);
    if (!isfinite(from.x) || !isfinite(from.y) || !isfinite(from.z))
        return error_set(err, ST_INPUT, "%s: the mesh is too large to frame: a camera %g units from its "
                         "centre is beyond the largest float (about 3.4e38)", s->path ? s->path : "mesh", dist);
    s->camera.from = from;
    s->camera.at = v3((float)c[0], (float)c[1], (float)c[2]);
    s->camera.up = v3(0.0f, 1.0f, 0.0f);
    s->camera.vfov = (float)VIEW_FOV_DEGREES;
    s->camera.aperture = 0.0f;
    s->camera.focus_dist = 0.0f;
    return ST_OK;
}

Status mesh_view_load(const char *path, Scene *s, Error *err)
{
    MeshOptions o = mesh_options(NO_INDEX);
    Status st = mesh_load(path, s, &o, err);
    return st ? st : mesh_view_frame(path, s, err);
}

Status mesh_view_frame(const char *path, Scene *s, Error *err)
{
    Status st = scene_set_path(s, path, err);
    if (st) return st;
    double c[3], r;
    if (!mesh_sphere(s, c, &r))
        return error_set(err, ST_INPUT, "%s: the mesh has no triangles to show", path);
    s->bg_type = BG_SKY;
    s->bg_color = v3(0.35f, 0.38f, 0.42f);     /* horizon */
    s->bg_zenith = v3(0.18f, 0.28f, 0.5f);
    double half = SUN_HALF_ANGLE_DEGREES * M_PI / 180.0;
    double dist = SUN_DISTANCE_RADII * r;
    Sphere sun;
    memset(&sun, 0, sizeof sun);
    sun.center = along(c, sun_dir, dist);
    sun.radius = (float)(dist * sin(half));
    if (!isfinite(sun.center.x) || !isfinite(sun.center.y) || !isfinite(sun.center.z) || !isfinite(sun.radius))
        return error_set(err, ST_INPUT, "%s: the mesh is too large to light: its sun, %g units away, is beyond "
                         "the largest float (about 3.4e38)", path, dist);
    /* a disc of radiance L subtending half-angle a gives irradiance L * pi * sin^2(a) */
    float radiance = (float)(SUN_IRRADIANCE / (M_PI * sin(half) * sin(half)));
    uint m;
    Material sun_m = material_emissive(v3(radiance, radiance * 0.95f, radiance * 0.85f));
    if ((st = scene_add_material(s, "", sun_m, &m, err))) return st;
    sun.material = m;
    if ((st = scene_add_sphere(s, sun, err))) return st;
    return mesh_view_fit(s, err);
}
