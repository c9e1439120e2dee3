/* motion.c — keys of moving transforms: the decomposition of PBR 4th ed., 3.10.1
 * (pbrt-v4's AnimatedTransform::Decompose, after Shoemake and Duff, "Matrix Animation
 * and Polar Decomposition", Graphics Interface 1992), written for clpt. */
#include "scene/motion.h"

#include <math.h>
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
