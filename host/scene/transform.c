/* transform.c — affine transforms in double (transform.h). */
#include "scene/transform.h"

#include "util/kmath.h"

#include <math.h>
#include <string.h>

Transform transform_identity(void)
{
    Transform t;
    memset(&t, 0, sizeof t);
    t.m[0][0] = t.m[1][1] = t.m[2][2] = 1.0;
    return t;
}

int transform_is_identity(const Transform *t)
{
    Transform id = transform_identity();
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            if (t->m[i][j] != id.m[i][j]) return 0;
    return 1;
}

Transform transform_compose(const Transform *a, const Transform *b)
{
    Transform r;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 4; j++) {
            double v = j == 3 ? a->m[i][3] : 0.0;
            for (int k = 0; k < 3; k++) v += a->m[i][k] * b->m[k][j];
            r.m[i][j] = v;
        }
    }
    return r;
}

Transform transform_translate(double x, double y, double z)
{
    Transform t = { { { 1, 0, 0, x }, { 0, 1, 0, y }, { 0, 0, 1, z } } };
    return t;
}

Transform transform_scale(double x, double y, double z)
{
    Transform t = { { { x, 0, 0, 0 }, { 0, y, 0, 0 }, { 0, 0, z, 0 } } };
    return t;
}

/* sin and cos of an angle in degrees, exact at multiples of 90 (so that `ry 90` maps
 * axes onto axes without 6e-17 residue). */
static void sincos_degrees(double deg, double *s, double *c)
{
    double q = deg / 90.0;
    if (q == floor(q) && fabs(q) < 1e15) {
        long k = (long)fmod(q, 4.0);
        if (k < 0) k += 4;
        static const double sv[4] = { 0.0, 1.0, 0.0, -1.0 }, cv[4] = { 1.0, 0.0, -1.0, 0.0 };
        *s = sv[k];
        *c = cv[k];
        return;
    }
    double r = deg * (M_PI / 180.0);
    *s = sin(r);
    *c = cos(r);
}

Transform transform_rotate(double x, double y, double z, double degrees)
{
    Transform t = transform_identity();
    double len = sqrt(x * x + y * y + z * z);
    if (!(len > 0.0) || !isfinite(len)) return t;
    x /= len;
    y /= len;
    z /= len;
    double s, c;
    sincos_degrees(degrees, &s, &c);
    double d = 1.0 - c;
    /* Rodrigues' formula */
    t.m[0][0] = c + x * x * d;      t.m[0][1] = x * y * d - z * s;  t.m[0][2] = x * z * d + y * s;
    t.m[1][0] = y * x * d + z * s;  t.m[1][1] = c + y * y * d;      t.m[1][2] = y * z * d - x * s;
    t.m[2][0] = z * x * d - y * s;  t.m[2][1] = z * y * d + x * s;  t.m[2][2] = c + z * z * d;
    return t;
}

double transform_det(const Transform *t)
{
#define M(i, j) t->m[i][j]
    return M(0, 0) * (M(1, 1) * M(2, 2) - M(1, 2) * M(2, 1)) -
           M(0, 1) * (M(1, 0) * M(2, 2) - M(1, 2) * M(2, 0)) +
           M(0, 2) * (M(1, 0) * M(2, 1) - M(1, 1) * M(2, 0));
#undef M
}

vec3 transform_point(const Transform *t, vec3 p)
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = t->m[i][0] * p.x + t->m[i][1] * p.y + t->m[i][2] * p.z + t->m[i][3];
    return v3((float)r[0], (float)r[1], (float)r[2]);
}

int transform_normal_matrix(const Transform *t, double n[3][3])
{
    double det = transform_det(t);
    if (!(fabs(det) > 0.0) || !isfinite(det)) return 0;
    const double (*m)[4] = t->m;
    for (int i = 0; i < 3; i++) {
        int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (int j = 0; j < 3; j++) {
            int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            n[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / det;
        }
    }
    return 1;
}

Transform transform_inverse(const Transform *t, int *ok)
{
    double n[3][3];
    Transform r = transform_identity();
    *ok = transform_normal_matrix(t, n);
    if (!*ok) return r;
    /* n is the inverse transpose: the inverse's linear part is its transpose; then -A^-1 b */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) r.m[i][j] = n[j][i];
    for (int i = 0; i < 3; i++)
        r.m[i][3] = -(r.m[i][0] * t->m[0][3] + r.m[i][1] * t->m[1][3] + r.m[i][2] * t->m[2][3]);
    return r;
}

int transform_invert(const Transform *t, Transform *inv)
{
    int ok;
    Transform r = transform_inverse(t, &ok);
    if (!ok) return 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            if (!isfinite(r.m[i][j])) return 0;
    *inv = r;
    return 1;
}
