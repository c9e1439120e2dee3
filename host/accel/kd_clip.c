/* kd_clip.c — the kd-tree build's geometry: boxes, a triangle's bounds, and a triangle
 * clipped to a node's box ("perfect splits", Sutherland-Hodgman), with rounding outward
 * so that the clipped box never loses a point of the triangle. */
#include "accel/kd_build.h"

#include <math.h>

double kd_box_half_area(const Aabb *b)
{
    double dx = (double)b->hi[0] - b->lo[0], dy = (double)b->hi[1] - b->lo[1];
    double dz = (double)b->hi[2] - b->lo[2];
    return dx * dy + dy * dz + dz * dx;
}

int kd_box_intersect(Aabb *b, const Aabb *with)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = k_fmax(b->lo[k], with->lo[k]);   /* compat.h: inlined, unlike fmaxf */
        b->hi[k] = k_fmin(b->hi[k], with->hi[k]);
        if (!(b->lo[k] <= b->hi[k])) return 0;
    }
    return 1;
}

static float round_down(double d)
{
    float f = (float)d;
    return (double)f > d ? nextafterf(f, -INFINITY) : f;
}

static float round_up(double d)
{
    float f = (float)d;
    return (double)f < d ? nextafterf(f, INFINITY) : f;
}

Aabb kd_triangle_bounds(const Triangle *t)
{
    Aabb a = { { t->p0.x, t->p0.y, t->p0.z }, { t->p0.x, t->p0.y, t->p0.z } };
    const vec3 *v[2] = { &t->p1, &t->p2 };
    for (int i = 0; i < 2; i++) {
        const float p[3] = { v[i]->x, v[i]->y, v[i]->z };
        for (int k = 0; k < 3; k++) {
            a.lo[k] = k_fmin(a.lo[k], p[k]);
            a.hi[k] = k_fmax(a.hi[k], p[k]);
        }
    }
    return a;
}

/* Clips the polygon in[0..n) to the side of the plane x_k = bound inside the box (below
 * it when `upper`, above it otherwise) into res; returns the new vertex count. */
static int clip_polygon_plane(double (*in)[3], int n, int k, int upper, double bound, double (*res)[3])
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const double *a = in[i], *b = in[(i + 1) % n];
        int a_in = upper ? a[k] <= bound : a[k] >= bound;
        int b_in = upper ? b[k] <= bound : b[k] >= bound;
        if (a_in) {
            memcpy(res[m], a, sizeof res[m]);
            m++;
        }
        if (a_in != b_in) {
            double s = (bound - a[k]) / (b[k] - a[k]);
            for (int j = 0; j < 3; j++) res[m][j] = a[j] + s * (b[j] - a[j]);
            res[m][k] = bound;
            m++;
        }
    }
    return m;
}

/* Box of the polygon v[0..n), rounded outward to float so that it is conservative. */
static Aabb polygon_bounds(double (*v)[3], int n)
{
    double lo[3], hi[3];
    for (int j = 0; j < 3; j++) lo[j] = hi[j] = v[0][j];
    for (int i = 1; i < n; i++)
        for (int j = 0; j < 3; j++) {
            lo[j] = fmin(lo[j], v[i][j]);
            hi[j] = fmax(hi[j], v[i][j]);
        }
    Aabb out;
    for (int j = 0; j < 3; j++) {
        out.lo[j] = round_down(lo[j]);
        out.hi[j] = round_up(hi[j]);
    }
    return out;
}

/* Box of the part of triangle t inside box c (Sutherland-Hodgman in double, rounded
 * outward to float so the box is conservative); 0 when nothing is inside. */
int kd_clip_triangle(const Triangle *t, const Aabb *c, Aabb *out)
{
    /* A convex polygon gains at most one vertex per plane (3 + 6); rounding could in
     * principle make it slightly non-convex, so there is room for more, and a
     * polygon that still outgrows it gets the conservative box instead. */
    double buf[2][32][3];
    const vec3 *v[3] = { &t->p0, &t->p1, &t->p2 };
    for (int i = 0; i < 3; i++) {
        buf[0][i][0] = v[i]->x;
        buf[0][i][1] = v[i]->y;
        buf[0][i][2] = v[i]->z;
    }
    int n = 3, cur = 0;
    for (int plane = 0; plane < 6; plane++) {
        int k = plane >> 1, upper = plane & 1;
        double bound = upper ? c->hi[k] : c->lo[k];
        double (*in)[3] = buf[cur];
        int outside = 0;
        for (int i = 0; i < n; i++)
            outside += upper ? in[i][k] > bound : in[i][k] < bound;
        if (outside == 0) continue;
        if (outside == n) return 0;
        if (n > 16) {
            *out = kd_triangle_bounds(t);
            return kd_box_intersect(out, c);
        }
        n = clip_polygon_plane(in, n, k, upper, bound, buf[cur ^ 1]);
        cur ^= 1;
    }
    *out = polygon_bounds(buf[cur], n);
    return kd_box_intersect(out, c);
}

