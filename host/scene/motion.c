/* motion.c — keys of moving transforms: the decomposition of PBR 4th ed., 3.10.1
 * (pbrt-v4's AnimatedTransform::Decompose, after Shoemake and Duff, "Matrix Animation
 * and Polar Decomposition", Graphics Interface 1992), written for clpt. */
#include "scene/motion.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/motion.h"

/* The inverse transpose of the 3x3 a into out; 0 when a is singular or not finite. */
static int inverse_transpose3(double a[3][3], double out[3][3])
{
    double c[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            c[i][j] = a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1];   /* cofactor */
        }
    double det = a[0][0] * c[0][0] + a[0][1] * c[0][1] + a[0][2] * c[0][2];
    if (!(fabs(det) > 0.0) || !isfinite(det)) return 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) out[i][j] = c[i][j] / det;
    return 1;
}

/* The unit quaternion (x, y, z, w) of rotation matrix r (Shoemake's method: from the
 * largest of the diagonal's combinations, so no square root of a small number). */
static void quaternion_of(double r[3][3], double q[4])
{
    double tr = r[0][0] + r[1][1] + r[2][2];
    if (tr > 0.0) {
        double s = sqrt(tr + 1.0) * 2.0;
        q[3] = 0.25 * s;
        q[0] = (r[2][1] - r[1][2]) / s;
        q[1] = (r[0][2] - r[2][0]) / s;
        q[2] = (r[1][0] - r[0][1]) / s;
    } else if (r[0][0] > r[1][1] && r[0][0] > r[2][2]) {
        double s = sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2.0;
        q[3] = (r[2][1] - r[1][2]) / s;
        q[0] = 0.25 * s;
        q[1] = (r[0][1] + r[1][0]) / s;
        q[2] = (r[0][2] + r[2][0]) / s;
    } else if (r[1][1] > r[2][2]) {
        double s = sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2.0;
        q[3] = (r[0][2] - r[2][0]) / s;
        q[0] = (r[0][1] + r[1][0]) / s;
        q[1] = 0.25 * s;
        q[2] = (r[1][2] + r[2][1]) / s;
    } else {
        double s = sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2.0;
        q[3] = (r[1][0] - r[0][1]) / s;
        q[0] = (r[0][2] + r[2][0]) / s;
        q[1] = (r[1][2] + r[2][1]) / s;
        q[2] = 0.25 * s;
    }
    double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; i++) q[i] /= len;
}

Status motion_key_make(const Transform *m, float time, MotionKey *out, Error *err)
{
    double a[3][3], r[3][3], rit[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) a[i][j] = m->m[i][j];
    /* the polar decomposition a = R S by averaging R with its inverse transpose until
     * it stops changing (Higham's iteration, as pbrt), from R = a */
    memcpy(r, a, sizeof r);
    for (int it = 0; it < 100; it++) {
        if (!inverse_transpose3(r, rit))
            return error_set(err, ST_INPUT, "a moving transform's key at time %g is singular", (double)time);
        double change = 0.0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double next = 0.5 * (r[i][j] + rit[i][j]);
                change = fmax(change, fabs(next - r[i][j]));
                r[i][j] = next;
            }
        if (change < 1e-13) break;
    }
    /* a mirror: R is a rotation times -1; -R is the rotation and S takes the sign */
    double det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                 r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if (det < 0.0)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) r[i][j] = -r[i][j];
    double s[3][3];   /* R^T a */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) s[i][j] = r[0][i] * a[0][j] + r[1][i] * a[1][j] + r[2][i] * a[2][j];
    double q[4];
    quaternion_of(r, q);
    memset(out, 0, sizeof *out);
    out->time = time;
    out->translate = v3((float)m->m[0][3], (float)m->m[1][3], (float)m->m[2][3]);
    for (int i = 0; i < 4; i++) out->rotate[i] = (float)q[i];
    /* S is symmetric up to rounding: its upper triangle from the mean of both halves */
    out->stretch[0] = (float)s[0][0];
    out->stretch[1] = (float)(0.5 * (s[0][1] + s[1][0]));
    out->stretch[2] = (float)(0.5 * (s[0][2] + s[2][0]));
    out->stretch[3] = (float)s[1][1];
    out->stretch[4] = (float)(0.5 * (s[1][2] + s[2][1]));
    out->stretch[5] = (float)s[2][2];
    for (int i = 0; i < 6; i++)
        if (!isfinite(out->stretch[i]) || !isfinite(out->translate.x) || !isfinite(out->translate.y) ||
            !isfinite(out->translate.z))
            return error_set(err, ST_INPUT, "a moving transform's key at time %g does not fit floats", (double)time);
    return ST_OK;
}

void motion_keys_shortest_arcs(MotionKey *keys, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        const float *a = keys[i - 1].rotate;
        float *b = keys[i].rotate;
        if (a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] < 0.0f)
            for (int j = 0; j < 4; j++) b[j] = -b[j];
    }
}

Transform motion_transform_at(const MotionKey *keys, size_t n, float time)
{
    float m[12];
    motion_at(keys, (uint)n, time, m);
    Transform t;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) t.m[i][j] = m[i * 4 + j];
    return t;
}

Status scene_add_instance_key(Scene *s, float own_time, float time, const Transform *m, Error *err)
{
    if (s->n_instances == 0) return error_set(err, ST_INPUT, "no instance to move");
    size_t inst = s->n_instances - 1;
    if (s->n_instance_motion < s->n_instances) {
        uint *grown = realloc(s->instance_motion, s->n_instances * sizeof *grown);
        if (!grown) return error_set(err, ST_INTERNAL, "out of memory");
        for (size_t i = s->n_instance_motion; i < s->n_instances; i++) grown[i] = NO_INDEX;
        s->instance_motion = grown;
        s->n_instance_motion = s->n_instances;
    }
    Instance *x = &s->instances[inst];
    uint first = s->instance_motion[inst];
    size_t have = first == NO_INDEX ? 0 : s->n_motion_keys - first;
    if (have + (first == NO_INDEX ? 2 : 1) > MOTION_MAX_KEYS)
        return error_set(err, ST_INPUT, "more than %u poses of one instance", MOTION_MAX_KEYS);
    float before = first == NO_INDEX ? own_time : s->motion_keys[s->n_motion_keys - 1].time;
    if (!(time > before))
        return error_set(err, ST_INPUT, "instance_key time %g is not after the instance's pose before it (time %g): "
                         "poses are given in increasing time", (double)time, (double)before);
    if (s->n_motion_keys + 2 > s->cap_motion_keys) {
        size_t cap = s->cap_motion_keys ? 2 * s->cap_motion_keys : 8;
        MotionKey *grown = realloc(s->motion_keys, cap * sizeof *grown);
        if (!grown) return error_set(err, ST_INTERNAL, "out of memory");
        s->motion_keys = grown;
        s->cap_motion_keys = cap;
    }
    Status st;
    if (first == NO_INDEX) {
        /* its own pose first, from the record's M */
        Transform own;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) own.m[i][j] = x->to_world[4 * i + j];
        if ((st = motion_key_make(&own, own_time, &s->motion_keys[s->n_motion_keys], err))) return st;
        first = (uint)s->n_motion_keys++;
    }
    if ((st = motion_key_make(m, time, &s->motion_keys[s->n_motion_keys], err))) return st;
    s->n_motion_keys++;
    size_t n = s->n_motion_keys - first;
    motion_keys_shortest_arcs(s->motion_keys + first, n);
    for (size_t i = first; i < s->n_motion_keys; i++) s->motion_keys[i].count = (uint)n;
    s->instance_motion[inst] = first;
    x->flags = (x->flags & ~INST_IDENTITY) | INST_MOTION;
    return ST_OK;
}

/* The world transform of the keys at time t, in double from the keys' floats (the
 * kernels' interpolation, for bounds). */
static void key_transform(const MotionKey *keys, size_t n, double t, double m[12])
{
    size_t i = 0;
    while (i + 2 < n && !(t < keys[i + 1].time)) i++;
    const MotionKey *k0 = keys + i, *k1 = keys + (n > 1 ? i + 1 : i);
    double u = 0.0;
    if (k1->time > k0->time) u = fmin(fmax((t - k0->time) / ((double)k1->time - k0->time), 0.0), 1.0);
    double a[4], b[4], q[4], c = 0.0;
    for (int j = 0; j < 4; j++) {
        a[j] = k0->rotate[j];
        b[j] = k1->rotate[j];
        c += a[j] * b[j];
    }
    double wa = 1.0 - u, wb = u;
    if (c < 0.9995) {
        double theta = acos(fmin(fmax(c, -1.0), 1.0));
        wa = sin((1.0 - u) * theta) / sin(theta);
        wb = sin(u * theta) / sin(theta);
    }
    double len = 0.0;
    for (int j = 0; j < 4; j++) {
        q[j] = wa * a[j] + wb * b[j];
        len += q[j] * q[j];
    }
    len = sqrt(len);
    double x = q[0] / len, y = q[1] / len, z = q[2] / len, w = q[3] / len, sv[6];
    for (int j = 0; j < 6; j++) sv[j] = (1.0 - u) * k0->stretch[j] + u * k1->stretch[j];
    double r[9] = { 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                    2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                    2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y) };
    double sm[9] = { sv[0], sv[1], sv[2], sv[1], sv[3], sv[4], sv[2], sv[4], sv[5] };
    for (int row = 0; row < 3; row++)
        for (int col = 0; col < 3; col++)
            m[row * 4 + col] = r[row * 3] * sm[col] + r[row * 3 + 1] * sm[3 + col] + r[row * 3 + 2] * sm[6 + col];
    m[3] = (1.0 - u) * k0->translate.x + u * k1->translate.x;
    m[7] = (1.0 - u) * k0->translate.y + u * k1->translate.y;
    m[11] = (1.0 - u) * k0->translate.z + u * k1->translate.z;
}

#define MOTION_BOUND_STEPS 32

void motion_bounds(const MotionKey *keys, size_t n, const double lo[3], const double hi[3], double wl[3], double wh[3])
{
    for (int k = 0; k < 3; k++) {
        wl[k] = INFINITY;
        wh[k] = -INFINITY;
    }
    if (!(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2])) return;
    double prev[8][3], step = 0.0;
    int have_prev = 0;
    for (size_t seg = 0; seg + 1 < n || (n == 1 && seg == 0); seg++) {
        double t0 = keys[seg].time, t1 = n > 1 ? keys[seg + 1].time : t0;
        for (int i = 0; i <= MOTION_BOUND_STEPS; i++) {
            double m[12];
            key_transform(keys, n, t0 + (t1 - t0) * i / MOTION_BOUND_STEPS, m);
            for (int c = 0; c < 8; c++) {
                double p[3] = { (c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1], (c & 4) ? hi[2] : lo[2] }, w[3];
                for (int k = 0; k < 3; k++) {
                    w[k] = m[4 * k] * p[0] + m[4 * k + 1] * p[1] + m[4 * k + 2] * p[2] + m[4 * k + 3];
                    wl[k] = fmin(wl[k], w[k]);
                    wh[k] = fmax(wh[k], w[k]);
                }
                if (have_prev) {
                    double d2 = 0.0;
                    for (int k = 0; k < 3; k++) d2 += (w[k] - prev[c][k]) * (w[k] - prev[c][k]);
                    step = fmax(step, sqrt(d2));
                }
                memcpy(prev[c], w, sizeof w);
            }
            have_prev = 1;
        }
    }
    for (int k = 0; k < 3; k++) {
        wl[k] -= step;
        wh[k] += step;
    }
}

/* |S a x S b| for the symmetric stretch sv (s00 s01 s02 s11 s12 s22). */
static double stretched_area(const double sv[6], const double a[3], const double b[3])
{
    const double sm[3][3] = { { sv[0], sv[1], sv[2] }, { sv[1], sv[3], sv[4] }, { sv[2], sv[4], sv[5] } };
    double sa[3], sb[3];
    for (int r = 0; r < 3; r++) {
        sa[r] = sm[r][0] * a[0] + sm[r][1] * a[1] + sm[r][2] * a[2];
        sb[r] = sm[r][0] * b[0] + sm[r][1] * b[1] + sm[r][2] * b[2];
    }
    double cx = sa[1] * sb[2] - sa[2] * sb[1], cy = sa[2] * sb[0] - sa[0] * sb[2], cz = sa[0] * sb[1] - sa[1] * sb[0];
    return sqrt(cx * cx + cy * cy + cz * cz);
}

/* The area under the keys' stretch at time t (key_transform's interpolation). */
static double area_at(const MotionKey *keys, size_t n, double t, const double a[3], const double b[3])
{
    size_t i = 0;
    while (i + 2 < n && !(t < keys[i + 1].time)) i++;
    const MotionKey *k0 = keys + i, *k1 = keys + (n > 1 ? i + 1 : i);
    double u = 0.0, sv[6];
    if (k1->time > k0->time) u = fmin(fmax((t - k0->time) / ((double)k1->time - k0->time), 0.0), 1.0);
    for (int j = 0; j < 6; j++) sv[j] = (1.0 - u) * k0->stretch[j] + u * k1->stretch[j];
    return stretched_area(sv, a, b);
}

/* Panels of Simpson's rule per stretch between key times. Between two keys the area is
 * |c(u)|, c a quadratic in u: a square root of a quartic, smooth unless c passes near
 * zero (a stretch that flattens the shape), where it is still continuous. */
#define MOTION_AREA_PANELS 8

double motion_mean_area(const MotionKey *keys, size_t n, double open, double close, const double a[3],
                        const double b[3])
{
    if (n == 0) return 0.0;
    if (!(close > open)) return area_at(keys, n, open, a, b);
    /* the shutter cut at the key times inside it, where the area has kinks; Simpson's
     * rule (composite, even panel count) on each piece (Press et al., Numerical
     * Recipes, 3rd ed., 4.1) */
    double sum = 0.0, t0 = open;
    for (size_t k = 0; k <= n; k++) {
        double t1 = k < n ? (double)keys[k].time : close;
        if (!(t1 > t0)) continue;
        if (t1 > close) t1 = close;
        double h = (t1 - t0) / MOTION_AREA_PANELS, piece = 0.0;
        for (int j = 0; j <= MOTION_AREA_PANELS; j++) {
            double w = (j == 0 || j == MOTION_AREA_PANELS) ? 1.0 : (j % 2 ? 4.0 : 2.0);
            piece += w * area_at(keys, n, t0 + h * j, a, b);
        }
        sum += piece * h / 3.0;
        t0 = t1;
        if (!(t0 < close)) break;
    }
    return sum / (close - open);
}
