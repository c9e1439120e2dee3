/*
 * intersect.h -- ray against sphere, triangle, axis-aligned box and plane (and, in
 * revsurface.h, surfaces of revolution).
 *
 * A ray is o + t*d with d of any length; a hit needs tmin < t < tmax (strict), so a
 * caller shrinks tmax to the closest hit so far and a tie keeps the first primitive
 * found. Each test writes t, u and v of *hit and returns 1 on a hit; it leaves the
 * primitive id to the caller. Per-ray constants (1/d and the triangle test's shear)
 * are computed once by ray_prepare.
 *
 * Zero direction components give 1/d = +-inf (IEEE), and every comparison is written
 * so that a NaN (0 * inf, a NaN ray) makes the test fail rather than loop or crash.
 */
#ifndef CLPT_INTERSECT_H
#define CLPT_INTERSECT_H

#include "util/kmath.h"

#define K_INF k_as_float(0x7f800000u)

/* Per-ray constants. The components are arrays so that the traversal and the triangle
 * test pick an axis by indexing: a select chain on a per-node axis is a data-dependent
 * branch the processor mispredicts. */
typedef struct {
    float org[3], dir[3];
    float inv_d[3];        /* 1/d per component: +-inf where that component is +-0 */
    uint neg;              /* bit a set when dir[a] has its sign bit set (-0 included) */
    int kx, ky, kz;        /* axes of the triangle test; kz is where |d| is largest */
    float sx, sy, sz;      /* shear taking d to (0, 0, 1) in the permuted frame */
} RayPre;

/* Fills *p for the ray. In place rather than returned: gcc built a returned RayPre
 * field by field and then copied it with 16-byte loads, each waiting for the narrower
 * stores before it to retire (no store-to-load forwarding), 10-18% of the scalar walk's
 * samples; in place, its camera any-hit rays got 19% faster (bench/RESULTS.md). */
KFN_INLINE void ray_prepare(Ray ray, RayPre *p)
{
    p->org[0] = ray.o.x; p->org[1] = ray.o.y; p->org[2] = ray.o.z;
    p->dir[0] = ray.d.x; p->dir[1] = ray.d.y; p->dir[2] = ray.d.z;
    p->inv_d[0] = 1.0f / ray.d.x;
    p->inv_d[1] = 1.0f / ray.d.y;
    p->inv_d[2] = 1.0f / ray.d.z;
    p->neg = (k_as_uint(ray.d.x) >> 31) | ((k_as_uint(ray.d.y) >> 31) << 1) | ((k_as_uint(ray.d.z) >> 31) << 2);
    float ax = k_fabs(ray.d.x), ay = k_fabs(ray.d.y), az = k_fabs(ray.d.z);
    int kz = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    int kx = kz == 2 ? 0 : kz + 1;
    int ky = kx == 2 ? 0 : kx + 1;
    float dz = p->dir[kz];
    /* Keep the winding (the sign of the determinant) independent of the permutation. */
    if (dz < 0.0f) { int swap = kx; kx = ky; ky = swap; }
    p->kx = kx; p->ky = ky; p->kz = kz;
    p->sx = p->dir[kx] / dz;
    p->sy = p->dir[ky] / dz;
    p->sz = p->inv_d[kz];   /* 1.0f / dz, computed above: a division costs ~10 cycles */
}

/* ------------------------------------------------------------------ sphere */

/* Ray Tracing Gems ch. 7 (Haines et al., "Precision Improvements for Ray/Sphere
 * Intersection"): the discriminant from the squared distance between the centre and
 * the line, which does not cancel catastrophically for distant spheres, and the two
 * roots as c/q and q/a, so the smaller one does not lose its digits either. */
KFN int sphere_intersect_at(vec3 center, float radius, Ray ray, Hit *hit)
{
    vec3 f = v3_sub(ray.o, center);
    float a = v3_dot(ray.d, ray.d);
    float b = v3_dot(f, ray.d);                    /* half the usual b */
    float c = v3_dot(f, f) - radius * radius;
    vec3 l = v3_sub(f, v3_scale(ray.d, b / a));    /* centre to the closest point of the line */
    float disc = a * (radius * radius - v3_dot(l, l));
    if (!(disc >= 0.0f)) return 0;
    float q = -(b + k_copysign(k_sqrt(disc), b));
    float t0 = c / q, t1 = q / a;
    float tn = k_fmin(t0, t1), tf = k_fmax(t0, t1);
    float t = tn > ray.tmin ? tn : tf;
    if (!(t > ray.tmin && t < ray.tmax)) return 0;
    hit->t = t;
    hit->u = 0.0f;
    hit->v = 0.0f;
    return 1;
}

KFN int sphere_intersect(Sphere s, Ray ray, Hit *hit)
{
    return sphere_intersect_at(s.center, s.radius, ray, hit);
}

/* The point p and the direction d under a 3x4 row-major matrix (SphereXform). */
KFN vec3 xform_point(GLOBAL const float *m, vec3 p)
{
    return v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
              m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

KFN vec3 xform_vector(GLOBAL const float *m, vec3 d)
{
    return v3(m[0] * d.x + m[1] * d.y + m[2] * d.z, m[4] * d.x + m[5] * d.y + m[6] * d.z,
              m[8] * d.x + m[9] * d.y + m[10] * d.z);
}

/* The ray in the object space of a transformed sphere. The direction is not
 * renormalised, so a point's t is the same in both spaces (the map is affine). */
KFN Ray sphere_xform_ray(GLOBAL const SphereXform *x, Ray ray)
{
    Ray r = ray;
    r.o = xform_point(x->to_object, ray.o);
    r.d = xform_vector(x->to_object, ray.d);
    return r;
}

/* An ellipsoid: the unit sphere in its object space (PBR 4th ed., 6.2, as pbrt-v4's
 * Sphere). The same test as a plain sphere's, so its robustness carries over. */
KFN int sphere_xform_intersect(GLOBAL const SphereXform *x, Ray ray, Hit *hit)
{
    return sphere_intersect_at(v3s(0.0f), 1.0f, sphere_xform_ray(x, ray), hit);
}

/* ---------------------------------------------------------------- triangle */

/* The error-free product of Dekker (1971): a*b == p + e exactly, given round-to-nearest
 * and no contraction into fma (compat.h) and no overflow; returns e. */
KFN float k_two_product_error(float a, float b, float p)
{
    float ca = 4097.0f * a, cb = 4097.0f * b;
    float ah = ca - (ca - a), bh = cb - (cb - b);
    float al = a - ah, bl = b - bh;
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl;
}

/* a*d - b*c when its float evaluation gave exactly 0, i.e. when the rounded products
 * are equal: then the true value is the difference of the two rounding errors, whose
 * sign this returns exactly (what Woop et al. do by re-evaluating in double). */
KFN float k_edge_exact(float a, float d, float b, float c)
{
    float p = a * d;
    return k_two_product_error(a, d, p) - k_two_product_error(b, c, p);
}

/* Woop, Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013. The
 * vertices go to a frame where the ray is the +z axis through the origin; the edge
 * functions U, V, W are then 2D cross products. An edge shared by two triangles gives
 * the same product difference with opposite sign in both, so a ray through the edge
 * cannot slip between them. A value that is exactly 0 is re-evaluated exactly
 * (k_edge_exact); a value still 0 is on the edge and counts as inside for both
 * triangles, so such a ray hits both (at the same t) rather than neither. */
KFN int triangle_intersect(const RayPre *rp, GLOBAL const Triangle *tri, Ray ray, Hit *hit)
{
    /* The corners as floats: p0 at 0, p1 at 4, p2 at 8 (types.h layout), read by the
     * ray's axis permutation. */
    GLOBAL const float *f = (GLOBAL const float *)tri;
    int kx = rp->kx, ky = rp->ky, kz = rp->kz;
    float ox = rp->org[kx], oy = rp->org[ky], oz = rp->org[kz];
    float az = f[kz] - oz, bz = f[4 + kz] - oz, cz = f[8 + kz] - oz;
    float ax = (f[kx] - ox) - rp->sx * az, ay = (f[ky] - oy) - rp->sy * az;
    float bx = (f[4 + kx] - ox) - rp->sx * bz, by = (f[4 + ky] - oy) - rp->sy * bz;
    float cx = (f[8 + kx] - ox) - rp->sx * cz, cy = (f[8 + ky] - oy) - rp->sy * cz;
    float U = cx * by - cy * bx;
    float V = ax * cy - ay * cx;
    float W = bx * ay - by * ax;
    /* The tests combine comparisons with | and & rather than || and &&: each short
     * circuit is a branch on data, and mispredicting them cost two thirds of the time
     * of this function (12.3 against 4.6 ns per test). */
    if ((U == 0.0f) | (V == 0.0f) | (W == 0.0f)) {
        if (U == 0.0f) U = k_edge_exact(cx, by, cy, bx);
        if (V == 0.0f) V = k_edge_exact(ax, cy, ay, cx);
        if (W == 0.0f) W = k_edge_exact(bx, ay, by, ax);
    }
    int neg = (U < 0.0f) | (V < 0.0f) | (W < 0.0f);
    int pos = (U > 0.0f) | (V > 0.0f) | (W > 0.0f);
    if (neg & pos) return 0;
    float det = U + V + W;
    if (det == 0.0f) return 0;
    float T = U * (rp->sz * az) + V * (rp->sz * bz) + W * (rp->sz * cz);
    float inv_det = 1.0f / det;
    float t = T * inv_det;
    if (!(t > ray.tmin && t < ray.tmax)) return 0;
    hit->t = t;
    hit->u = V * inv_det;
    hit->v = W * inv_det;
    return 1;
}

/* triangle_intersect on the KD_GROUP (8) triangles of a kd-tree leaf group at once.
 * `rows` are the group's corners, 9 rows of KD_GROUP floats (types.h). Each lane
 * computes the very operations of triangle_intersect, so a lane's t, u and v are bit
 * for bit what triangle_intersect gives for that triangle, tmax fixed for the group.
 * OpenCL runs the 8 lanes as one float8, as does C compiled with AVX (K_VEC8,
 * compat.h: the scalar device's AVX2 builds); C for any x86-64 runs them as two float4
 * halves, because without AVX gcc splits 8-wide vectors badly. The same operations per
 * lane give the same bits either way.
 *
 * TRI_LANES_BODY is the body for W lanes of vector type VT (comparisons IT) starting
 * at lane `first`: it leaves the lanes hit as bits in `mask` and, when there are any,
 * their t, u and v in the arrays ta, ua, va (at [first, first + W)). ANY(m) and BITS(m)
 * reduce a comparison's lanes (k_any8, k_bits8 and the 4-lane ones, compat.h: one
 * instruction where the target has it). */
#if KD_GROUP != 8
#error "triangle_intersect_group is written for groups of 8 lanes"
#endif
#define TRI_LANES_BODY(VT, IT, W, LOAD, STORE, ANY, BITS)                               \
    int kx = rp->kx, ky = rp->ky, kz = rp->kz;                                           \
    float ox = rp->org[kx], oy = rp->org[ky], oz = rp->org[kz];                          \
    float sx = rp->sx, sy = rp->sy, sz = rp->sz;                                         \
    GLOBAL const float *r = rows + first;                                                \
    VT p0x, p0y, p0z, p1x, p1y, p1z, p2x, p2y, p2z;                                      \
    LOAD(p0x, r + KD_GROUP * kx);                                                        \
    LOAD(p0y, r + KD_GROUP * ky);                                                        \
    LOAD(p0z, r + KD_GROUP * kz);                                                        \
    LOAD(p1x, r + KD_GROUP * (3 + kx));                                                  \
    LOAD(p1y, r + KD_GROUP * (3 + ky));                                                  \
    LOAD(p1z, r + KD_GROUP * (3 + kz));                                                  \
    LOAD(p2x, r + KD_GROUP * (6 + kx));                                                  \
    LOAD(p2y, r + KD_GROUP * (6 + ky));                                                  \
    LOAD(p2z, r + KD_GROUP * (6 + kz));                                                  \
    VT az = p0z - oz, bz = p1z - oz, cz = p2z - oz;                                      \
    VT ax = (p0x - ox) - sx * az, ay = (p0y - oy) - sy * az;                             \
    VT bx = (p1x - ox) - sx * bz, by = (p1y - oy) - sy * bz;                             \
    VT cx = (p2x - ox) - sx * cz, cy = (p2y - oy) - sy * cz;                             \
    VT U = cx * by - cy * bx;                                                            \
    VT V = ax * cy - ay * cx;                                                            \
    VT W_ = bx * ay - by * ax;                                                           \
    IT zero = (U == 0.0f) | (V == 0.0f) | (W_ == 0.0f);                                  \
    if (ANY(zero)) {                                                                     \
        for (int i = 0; i < W; i++) {                                                    \
            if (U[i] == 0.0f) U[i] = k_edge_exact(cx[i], by[i], cy[i], bx[i]);           \
            if (V[i] == 0.0f) V[i] = k_edge_exact(ax[i], cy[i], ay[i], cx[i]);           \
            if (W_[i] == 0.0f) W_[i] = k_edge_exact(bx[i], ay[i], by[i], ax[i]);         \
        }                                                                                \
    }                                                                                    \
    IT neg = (U < 0.0f) | (V < 0.0f) | (W_ < 0.0f);                                      \
    IT pos = (U > 0.0f) | (V > 0.0f) | (W_ > 0.0f);                                      \
    VT det = U + V + W_;                                                                 \
    VT T = U * (sz * az) + V * (sz * bz) + W_ * (sz * cz);                               \
    VT inv_det = 1.0f / det;                                                             \
    VT t = T * inv_det;                                                                  \
    IT ok = ~(neg & pos) & (det != 0.0f) & (t > tmin) & (t < tmax);                      \
    uint mask = BITS(ok);                                                                \
    if (mask) {                                                                          \
        VT u = V * inv_det, v = W_ * inv_det;                                            \
        STORE(t, ta + first);                                                            \
        STORE(u, ua + first);                                                            \
        STORE(v, va + first);                                                            \
    }

#if K_VEC8
KFN_INLINE uint tri_lanes(const RayPre *rp, GLOBAL const float *rows, int first, float tmin, float tmax,
                          float *ta, float *ua, float *va)
{
    TRI_LANES_BODY(float8, int8, 8, k_load8, k_store8, k_any8, k_bits8)
    return mask;
}
#else
KFN_INLINE uint tri_lanes(const RayPre *rp, GLOBAL const float *rows, int first, float tmin, float tmax,
                          float *ta, float *ua, float *va)
{
    TRI_LANES_BODY(float4, int4, 4, k_load4, k_store4, k_any4, k_bits4)
    return mask;
}
#endif

/* The group's lanes hit (bits, lane i: 1 << i); when there are any, *hit gets the
 * nearest one's t, u and v and its lane in hit->prim (the first of equals: what testing
 * the lanes one by one in order would keep). */
KFN_INLINE uint triangle_intersect_group(const RayPre *rp, GLOBAL const float *rows, float tmin, float tmax,
                                         Hit *hit)
{
    float ta[KD_GROUP], ua[KD_GROUP], va[KD_GROUP];
#if K_VEC8
    uint mask = tri_lanes(rp, rows, 0, tmin, tmax, ta, ua, va);
#else
    uint mask = tri_lanes(rp, rows, 0, tmin, tmax, ta, ua, va);
    mask |= tri_lanes(rp, rows, 4, tmin, tmax, ta, ua, va) << 4;
#endif
    if (mask) {
        /* over the lanes hit only, in lane order (usually one: a loop over all eight
         * held 5% of the samples of a Cornell box profile on PoCL) */
        uint lane = k_lowest_bit(mask);
        float bt = ta[lane];
        for (uint m = mask & (mask - 1u); m != 0u; m &= m - 1u) {
            uint l = k_lowest_bit(m);
            if (ta[l] < bt) {
                bt = ta[l];
                lane = l;
            }
        }
        hit->t = bt;
        hit->u = ua[lane];
        hit->v = va[lane];
        hit->prim = lane;
    }
    return mask;
}

#ifndef KERNEL_OPENCL
_Static_assert(offsetof(Triangle, p1) == 16 && offsetof(Triangle, p2) == 32,
               "triangle_intersect reads the corners at float offsets 0, 4 and 8");
#endif

/* --------------------------------------------------------------------- box */

/* The parameter interval [*tn, *tf] in which the ray is inside the slab lo..hi of one
 * axis. With d == 0 along the axis, 1/d = +-inf makes it everything or nothing; 0*inf
 * = NaN happens only when the origin lies on a face plane, and then it is inside the
 * closed slab: everything. */
KFN void k_slab(float lo, float hi, float o, float inv, float *tn, float *tf)
{
    float t1 = (lo - o) * inv, t2 = (hi - o) * inv;
    int in_plane = !(t1 == t1) || !(t2 == t2);
    *tn = in_plane ? -K_INF : k_fmin(t1, t2);
    *tf = in_plane ? K_INF : k_fmax(t1, t2);
}

/* Slab test of a solid box (lo <= hi). From outside the hit is where the ray enters,
 * from inside where it leaves; u is the face of the hit as a float: 0 -x, 1 +x, 2 -y,
 * 3 +y, 4 -z, 5 +z. A box flat along an axis is hit on its face there. */
KFN int box_intersect(const RayPre *rp, Box b, Ray ray, Hit *hit)
{
    float nx, fx, ny, fy, nz, fz;
    k_slab(b.lo.x, b.hi.x, ray.o.x, rp->inv_d[0], &nx, &fx);
    k_slab(b.lo.y, b.hi.y, ray.o.y, rp->inv_d[1], &ny, &fy);
    k_slab(b.lo.z, b.hi.z, ray.o.z, rp->inv_d[2], &nz, &fz);
    float tn = k_fmax(nx, k_fmax(ny, nz));
    float tf = k_fmin(fx, k_fmin(fy, fz));
    if (!(tn <= tf)) return 0;
    int entering = tn > ray.tmin;
    float t = entering ? tn : tf;
    if (!(t > ray.tmin && t < ray.tmax)) return 0;
    /* The face: the axis whose slab bound is t, and whether that bound is the lo plane
     * (a ray going +axis enters there and leaves through hi). */
    int axis;
    if (entering) axis = (nx >= ny && nx >= nz) ? 0 : (ny >= nz ? 1 : 2);
    else axis = (fx <= fy && fx <= fz) ? 0 : (fy <= fz ? 1 : 2);
    float d = v3_get(ray.d, axis);
    int hi_face = entering ? (d < 0.0f) : (d > 0.0f);
    hit->t = t;
    hit->u = (float)(2 * axis + hi_face);
    hit->v = 0.0f;
    return 1;
}

/* ------------------------------------------------------------------- plane */

/* Both sides; a ray parallel to the plane gives 0/0 or x/0 and misses. */
KFN int plane_intersect(Plane pl, Ray ray, Hit *hit)
{
    float t = (pl.offset - v3_dot(pl.normal, ray.o)) / v3_dot(pl.normal, ray.d);
    if (!(t > ray.tmin && t < ray.tmax)) return 0;
    hit->t = t;
    hit->u = 0.0f;
    hit->v = 0.0f;
    return 1;
}

#include "geom/revsurface.h"

#endif /* CLPT_INTERSECT_H */
