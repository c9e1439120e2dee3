/* scene_precision.c — what float32 kernels cannot render faithfully, found before a
 * render: distances past 2^62, spheres too large for their camera distance, triangles
 * too small for their place (scene_check_precision). */
#include "scene/scene.h"

#include <float.h>
#include <math.h>
#include <stdio.h>

#include "util/kmath.h"

/* Radii and distances the kernels square: 2^62 squared is 2^124, far enough below
 * FLT_MAX (2^128) for sums of three squares. */
#define PRECISION_MAX_SQUARED_DISTANCE 0x1p62
/* A sphere's radius over the camera's distance from its surface: at 2^24 the camera
 * ray's hit computes |o - c|^2 - r^2 with no digit left; 2^22 leaves a margin. */
#define PRECISION_MAX_SPHERE_RATIO 0x1p22

static vec3 vmin(vec3 a, vec3 b) { return v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)); }
static vec3 vmax(vec3 a, vec3 b) { return v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)); }

void scene_count_tiny_triangles(const Scene *s, size_t first, size_t end, size_t *tiny, size_t *with_area,
                                vec3 *lo, vec3 *hi)
{
    *tiny = *with_area = 0;
    vec3 l = v3s(INFINITY), h = v3s(-INFINITY);
    for (size_t i = first; i < end && i < s->n_triangles; i++) {
        const Triangle *t = &s->triangles[i];
        l = vmin(l, vmin(t->p0, vmin(t->p1, t->p2)));
        h = vmax(h, vmax(t->p0, vmax(t->p1, t->p2)));
        /* the kernels' geometric normal (surface.h): float edges, cross, length */
        vec3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0);
        double x = (double)e1.y * e2.z - (double)e1.z * e2.y, y = (double)e1.z * e2.x - (double)e1.x * e2.z,
               z = (double)e1.x * e2.y - (double)e1.y * e2.x;
        if (!(x * x + y * y + z * z > 0.0)) continue;
        (*with_area)++;
        /* a subnormal squared length still normalises (measured: the bunny 1.5e-9
         * across renders right, 1.5e-11 black); below 2^-140 it keeps too few bits */
        vec3 n = v3_cross(e1, e2);
        if (!(v3_dot(n, n) >= 0x1p-140f)) (*tiny)++;
    }
    if (lo) *lo = l;
    if (hi) *hi = h;
}

double scene_triangles_reach(const Scene *s, size_t first, size_t end)
{
    double reach = 0.0;
    for (size_t i = first; i < end && i < s->n_triangles; i++) {
        const Triangle *t = &s->triangles[i];
        const vec3 c[3] = { t->p0, t->p1, t->p2 };
        for (int k = 0; k < 3; k++)
            reach = fmax(reach, fmax(fabs((double)c[k].x), fmax(fabs((double)c[k].y), fabs((double)c[k].z))));
    }
    return reach;
}

static Status check_sphere(const Scene *s, size_t i, Error *err)
{
    const Sphere *sp = &s->spheres[i];
    double fx = (double)s->camera.from.x - sp->center.x, fy = (double)s->camera.from.y - sp->center.y,
           fz = (double)s->camera.from.z - sp->center.z;
    double r = sp->radius, dist = sqrt(fx * fx + fy * fy + fz * fz);
    double gap = fabs(dist - r);
    const char *path = s->path ? s->path : "scene";
    if (r > PRECISION_MAX_SQUARED_DISTANCE || dist > PRECISION_MAX_SQUARED_DISTANCE)
        return error_set(err, ST_INPUT, "%s: sphere %zu (centre %g %g %g, radius %g) is too large or too far "
                         "from the camera for single precision: its radius and its distance from the camera "
                         "(%g) must be at most 2^62 (%g)", path, i + 1, (double)sp->center.x,
                         (double)sp->center.y, (double)sp->center.z, r, dist, PRECISION_MAX_SQUARED_DISTANCE);
    if (r > PRECISION_MAX_SPHERE_RATIO * gap)
        return error_set(err, ST_INPUT, "%s: sphere %zu (centre %g %g %g, radius %g) is %g from the camera, "
                         "more than 2^22 times closer than its radius: single precision cannot find where "
                         "the camera's rays meet it (use a plane for a ground this large, or move the camera "
                         "at least %g from it)", path, i + 1, (double)sp->center.x, (double)sp->center.y,
                         (double)sp->center.z, r, gap, r / PRECISION_MAX_SPHERE_RATIO);
    return ST_OK;
}

Status scene_check_precision(const Scene *s, Error *err)
{
    for (size_t i = 0; i < s->n_spheres; i++) {
        Status st = check_sphere(s, i, err);
        if (st) return st;
    }
    double reach = scene_triangles_reach(s, 0, s->n_triangles);
    if (reach > SCENE_MAX_COORDINATE)
        return error_set(err, ST_INPUT, "%s: a triangle has a corner %g from the origin, beyond the 2^62 (%g) "
                         "single precision can intersect: scale the scene down", s->path ? s->path : "scene",
                         reach, SCENE_MAX_COORDINATE);
    size_t tiny, with_area;
    vec3 lo, hi;
    scene_count_tiny_triangles(s, 0, s->n_triangles, &tiny, &with_area, &lo, &hi);
    if (tiny > 0 && tiny * 2 >= with_area)
        return error_set(err, ST_INPUT, "%s: %zu of the scene's %zu triangles are too small for single "
                         "precision (their normals underflow; the triangles span %g x %g x %g): scale them up",
                         s->path ? s->path : "scene", tiny, with_area, (double)(hi.x - lo.x),
                         (double)(hi.y - lo.y), (double)(hi.z - lo.z));
    return ST_OK;
}
