/* octa_env.c — pbrt-v4's equal-area octahedral environment maps (see octa_env.h). */
#include "scene/octa_env.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void octa_square_to_sphere(double u, double v, double d[3])
{
    /* to [-1, 1]^2; the signed distance from the diamond |u| + |v| = 1 picks the
     * hemisphere, and r (0 at the centre or the corners, 1 on the diamond) the ring */
    double su = 2.0 * u - 1.0, sv = 2.0 * v - 1.0;
    double au = fabs(su), av = fabs(sv);
    double signed_dist = 1.0 - (au + av), r = 1.0 - fabs(signed_dist);
    /* the angle around z, from 0 on the u axis to pi/2 on the v axis in each quadrant:
     * along a ring, equal steps of the square are equal steps of the angle */
    double phi = (r == 0.0 ? 1.0 : (av - au) / r + 1.0) * M_PI / 4.0;
    double z = copysign(1.0 - r * r, signed_dist);
    double s = r * sqrt(fmax(2.0 - r * r, 0.0));   /* sin(theta): 1 - z^2 = r^2 (2 - r^2) */
    d[0] = copysign(cos(phi), su) * s;
    d[1] = copysign(sin(phi), sv) * s;
    d[2] = z;
}

void octa_sphere_to_square(const double d[3], double *u, double *v)
{
    double x = fabs(d[0]), y = fabs(d[1]), z = fabs(d[2]);
    double r = sqrt(fmax(1.0 - z, 0.0));   /* the ring: 1 - |z| = r^2 */
    double a = fmax(x, y), b = fmin(x, y);
    double phi = a == 0.0 ? 0.0 : atan(b / a) * 2.0 / M_PI;   /* in [0, 1/2] of the quadrant */
    if (x < y) phi = 1.0 - phi;
    double sv = phi * r, su = r - sv;
    if (d[2] < 0.0) {
        /* the lower hemisphere folds out over the triangles outside the diamond */
        double t = su;
        su = 1.0 - sv;
        sv = 1.0 - t;
    }
    su = copysign(su, d[0]);
    sv = copysign(sv, d[1]);
    *u = (su + 1.0) * 0.5;
    *v = (sv + 1.0) * 0.5;
}

/* Brings coordinate *a of an N x N square back from one past an edge across it: the
 * sphere joins the two halves of that edge to each other, mirrored, so the other
 * coordinate *b flips too. */
static void octa_fold(long *a, long *b, long N)
{
    if (*a < 0) {
        *a = -*a - 1;
        *b = N - 1 - *b;
    } else if (*a >= N) {
        *a = 2 * N - 1 - *a;
        *b = N - 1 - *b;
    }
}

/* Texel (x, y), either possibly one past an edge, brought back as the sphere joins the
 * square's edges (octa_fold): x first, then y. */
static const float *octa_texel(const float *rgb, uint n, long x, long y)
{
    octa_fold(&x, &y, (long)n);
    octa_fold(&y, &x, (long)n);
    return rgb + 3u * ((size_t)y * n + (size_t)x);
}

void octa_lookup(const float *rgb, uint n, double u, double v, float out[3])
{
    double px = u * n - 0.5, py = v * n - 0.5;
    double fx = floor(px), fy = floor(py);
    double wx = px - fx, wy = py - fy;
    long x0 = (long)fx, y0 = (long)fy;
    const float *t00 = octa_texel(rgb, n, x0, y0), *t10 = octa_texel(rgb, n, x0 + 1, y0);
    const float *t01 = octa_texel(rgb, n, x0, y0 + 1), *t11 = octa_texel(rgb, n, x0 + 1, y0 + 1);
    for (int c = 0; c < 3; c++)
        out[c] = (float)((1.0 - wy) * ((1.0 - wx) * t00[c] + wx * t10[c]) + wy * ((1.0 - wx) * t01[c] + wx * t11[c]));
}

Status octa_env_set(Scene *s, const float *rgb, uint n, const double light_from_world[9], float scale,
                    Error *err)
{
    uint H = n < OCTA_ENV_MIN_HEIGHT ? OCTA_ENV_MIN_HEIGHT : n > OCTA_ENV_MAX_HEIGHT ? OCTA_ENV_MAX_HEIGHT : n;
    uint W = 2u * H;
    size_t count = 3u * (size_t)W * H;
    uint *texels = malloc(count * sizeof *texels);
    if (!texels) return error_set(err, ST_INTERNAL, "out of memory resampling the environment map");
    const double *m = light_from_world;
    for (uint j = 0; j < H; j++)
        for (uint i = 0; i < W; i++) {
            /* the texel centre's world direction (kernels/light/envmap.h: phi = 2 pi u,
             * theta = pi v, (sin t sin p, cos t, -sin t cos p)) into the light's frame */
            double th = M_PI * ((double)j + 0.5) / H, ph = 2.0 * M_PI * ((double)i + 0.5) / W;
            double w[3] = { sin(th) * sin(ph), cos(th), -sin(th) * cos(ph) };
            double l[3];
            for (int r = 0; r < 3; r++) l[r] = m[3 * r] * w[0] + m[3 * r + 1] * w[1] + m[3 * r + 2] * w[2];
            double len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
            for (int r = 0; r < 3; r++) l[r] = len > 0.0 ? l[r] / len : (r == 2);
            double u, v;
            octa_sphere_to_square(l, &u, &v);
            float c[3];
            octa_lookup(rgb, n, u, v, c);
            for (int k = 0; k < 3; k++) c[k] = c[k] > 0.0f ? c[k] : 0.0f;   /* pbrt's ClampZero */
            memcpy(texels + 3u * ((size_t)j * W + i), c, sizeof c);
        }
    Status st = scene_set_envmap_texels(s, texels, W, H, scale, err);
    free(texels);
    return st;
}
