/* keyframes.c — keyed values interpolated in time (keyframes.h). */
#include "scene/keyframes.h"

#include <math.h>
#include <string.h>

static void normalise4(double *q)
{
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(l > 0)) return;
    for (int i = 0; i < 4; i++) q[i] /= l;
}

void key_slerp(const double *a, const double *b, double u, double *out)
{
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], sign = 1.0;
    if (d < 0) {
        d = -d;
        sign = -1.0;
    }
    double wa, wb;
    if (d > 0.9995) {
        /* sin(theta) near 0: the chord is the arc to within 1e-7 */
        wa = 1.0 - u;
        wb = u;
    } else {
        double theta = acos(d), s = sin(theta);
        wa = sin((1.0 - u) * theta) / s;
        wb = sin(u * theta) / s;
    }
    for (int i = 0; i < 4; i++) out[i] = wa * a[i] + sign * wb * b[i];
    normalise4(out);
}

/* The key k with times[k] <= t < times[k + 1] (0 <= k < n - 1), for n >= 2 and t
 * inside the keys: binary search, since a long clip has thousands of keys. */
static size_t key_before(const KeyTrack *k, double t)
{
    size_t lo = 0, hi = k->n - 1;   /* times[lo] <= t < times[hi] */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (k->times[mid] <= t) lo = mid;
        else hi = mid;
    }
    return lo;
}

/* The value of key i (for CUBICSPLINE, the middle of its three). */
static const double *key_value(const KeyTrack *k, size_t i)
{
    size_t w = (size_t)k->width;
    return k->interp == KEY_CUBICSPLINE ? k->values + (3 * i + 1) * w : k->values + i * w;
}

void key_track_eval(const KeyTrack *k, double t, double *out)
{
    size_t w = (size_t)k->width;
    /* outside the keys, and at a key's own time: that key's value as it is */
    if (k->n == 1 || !(t > k->times[0])) {
        memcpy(out, key_value(k, 0), w * sizeof *out);
        return;
    }
    if (t >= k->times[k->n - 1]) {
        memcpy(out, key_value(k, k->n - 1), w * sizeof *out);
        return;
    }
    size_t i = key_before(k, t);
    const double *a = key_value(k, i), *b = key_value(k, i + 1);
    double td = k->times[i + 1] - k->times[i], u = (t - k->times[i]) / td;
    if (k->interp == KEY_STEP || t == k->times[i]) {
        memcpy(out, a, w * sizeof *out);
        return;
    }
    if (k->interp == KEY_LINEAR) {
        if (k->rotation) {
            key_slerp(a, b, u, out);
            return;
        }
        for (size_t j = 0; j < w; j++) out[j] = (1.0 - u) * a[j] + u * b[j];
        return;
    }
    /* glTF 2.0, Appendix C.3: the Hermite basis over [t_i, t_i+1], the out-tangent of
     * key i and the in-tangent of key i + 1 scaled by the interval's length */
    const double *out_tangent = a + w, *in_tangent = b - w;
    double u2 = u * u, u3 = u2 * u;
    double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
    for (size_t j = 0; j < w; j++)
        out[j] = h00 * a[j] + td * h10 * out_tangent[j] + h01 * b[j] + td * h11 * in_tangent[j];
    if (k->rotation) normalise4(out);
}
