/* kd_input.c — what the kd-tree is built over: every primitive's box (spheres, ellipsoids,
 * triangles, boxes, surfaces of revolution), the ones that are not finite left out. */
#include "accel/kd_build.h"

#include <math.h>
#include <stdlib.h>

#include "base/jobs.h"

static int aabb_finite(const Aabb *a)
{
    for (int k = 0; k < 3; k++)
        if (!isfinite(a->lo[k]) || !isfinite(a->hi[k])) return 0;
    return 1;
}

/* An ellipsoid's box: the unit sphere under M reaches sqrt(sum_j M_ij^2) along world
 * axis i from M's origin (the row's length: max of row . n over unit n). A relative
 * 2^-20 more covers the kernels' rounding of the object-space test near the rim. */
static Aabb ellipsoid_bounds(const SphereXform *x)
{
    Aabb a;
    for (int k = 0; k < 3; k++) {
        const float *row = x->to_world + 4 * k;
        double e = sqrt((double)row[0] * row[0] + (double)row[1] * row[1] + (double)row[2] * row[2]);
        e *= 1.0 + 0x1p-20;
        a.lo[k] = nextafterf((float)(row[3] - e), -INFINITY);
        a.hi[k] = nextafterf((float)(row[3] + e), INFINITY);
    }
    return a;
}

static Aabb sphere_bounds(const KdInput *in, const Sphere *s)
{
    if (s->xform != 0u && s->xform <= in->n_sphere_xforms) return ellipsoid_bounds(&in->sphere_xforms[s->xform - 1u]);
    /* Rounded outward: the centre +- radius in float can land a hair inside. */
    float r = fabsf(s->radius);
    const float c[3] = { s->center.x, s->center.y, s->center.z };
    Aabb a;
    for (int k = 0; k < 3; k++) {
        a.lo[k] = nextafterf(c[k] - r, -INFINITY);
        a.hi[k] = nextafterf(c[k] + r, INFINITY);
    }
    return a;
}

static int triangle_finite(const Triangle *t)
{
    return isfinite(t->p0.x) && isfinite(t->p0.y) && isfinite(t->p0.z) &&
           isfinite(t->p1.x) && isfinite(t->p1.y) && isfinite(t->p1.z) &&
           isfinite(t->p2.x) && isfinite(t->p2.y) && isfinite(t->p2.z);
}

static Aabb box_bounds(const Box *bx)
{
    const float lo[3] = { bx->lo.x, bx->lo.y, bx->lo.z }, hi[3] = { bx->hi.x, bx->hi.y, bx->hi.z };
    Aabb a;
    for (int k = 0; k < 3; k++) {
        a.lo[k] = fminf(lo[k], hi[k]);
        a.hi[k] = fmaxf(lo[k], hi[k]);
    }
    /* fminf drops a NaN operand: keep it so the finiteness test sees it. */
    for (int k = 0; k < 3; k++)
        if (isnan(lo[k]) || isnan(hi[k])) a.lo[k] = NAN;
    return a;
}

int kd_prim_box(const KdInput *in, uint gid, float lo[3], float hi[3])
{
    Aabb a;
    int finite;
    size_t n_sph = in->n_spheres, n_tri = in->n_triangles, n_box = in->n_boxes;
    if (gid < n_sph) {
        a = sphere_bounds(in, &in->spheres[gid]);
        finite = aabb_finite(&a);
    } else if ((gid -= (uint)n_sph) < n_tri) {
        a = kd_triangle_bounds(&in->triangles[gid]);
        finite = triangle_finite(&in->triangles[gid]);
    } else if ((gid -= (uint)n_tri) < n_box) {
        a = box_bounds(&in->boxes[gid]);
        finite = aabb_finite(&a);
    } else {
        gid -= (uint)n_box;
        Box bx = { in->revs[gid].lo, 0u, in->revs[gid].hi, 0u };
        a = box_bounds(&bx);
        finite = aabb_finite(&a);
    }
    memcpy(lo, a.lo, sizeof a.lo);
    memcpy(hi, a.hi, sizeof a.hi);
    return finite;
}

/* The bounds of primitives [first, end), each at its own index, and whether they are
 * finite. */
typedef struct { const KdInput *in; Aabb *bounds; uint8_t *finite; uint first, end; } BoundsJob;

static void *bounds_range(void *arg)
{
    const BoundsJob *j = arg;
    for (uint gid = j->first; gid < j->end; gid++)
        j->finite[gid] = (uint8_t)kd_prim_box(j->in, gid, j->bounds[gid].lo, j->bounds[gid].hi);
    return NULL;
}

/* The build's lists for `total` primitives (global ids, triangle indices, bounds) and a
 * flag a primitive for finite bounds, which is returned (NULL: out of memory; the lists
 * the build frees). */
static uint8_t *alloc_lists(Build *b, size_t total)
{
    b->gid = malloc((total + 1) * sizeof *b->gid);
    b->tri = malloc((total + 1) * sizeof *b->tri);
    b->bounds = malloc((total + 1) * sizeof *b->bounds);
    uint8_t *finite = malloc(total + 1);
    if (!b->gid || !b->tri || !b->bounds || !finite) {
        free(finite);
        return NULL;
    }
    return finite;
}

/* Moves the `listed` primitives whose bounds are finite down, in order, and frees the
 * flags: slot i is global id b->gid[i] (by_list) or i. */
static void keep_finite(Build *b, const KdInput *in, uint8_t *finite, uint listed, int by_list, uint *skipped)
{
    uint first_tri = (uint)in->n_spheres, end_tri = first_tri + (uint)in->n_triangles, n = 0;
    for (uint i = 0; i < listed; i++) {
        if (!finite[i]) continue;
        uint gid = by_list ? b->gid[i] : i;
        b->gid[n] = gid;
        b->tri[n] = gid >= first_tri && gid < end_tri ? gid - first_tri : NO_INDEX;
        b->bounds[n++] = b->bounds[i];
    }
    free(finite);
    b->n_prims = n;
    *skipped = listed - n;
    b->triangles = in->triangles;
}

/* The bounds of the listed primitives gids[first .. end), each at its place in the
 * list (a prototype's ranges, KdInput.ranges). */
typedef struct { const KdInput *in; const uint *gids; Aabb *bounds; uint8_t *finite; uint first, end; } ListJob;

static void *bounds_list(void *arg)
{
    const ListJob *j = arg;
    for (uint i = j->first; i < j->end; i++)
        j->finite[i] = (uint8_t)kd_prim_box(j->in, j->gids[i], j->bounds[i].lo, j->bounds[i].hi);
    return NULL;
}

/* kd_gather over the primitives of in->ranges alone (a prototype of an instanced scene,
 * docs/instancing.md): the same result as over a KdInput holding just those, in
 * increasing global id. */
static Status gather_ranges(Build *b, const KdInput *in, uint *skipped, Error *err)
{
    uint64_t total = 0;
    for (size_t r = 0; r < in->n_ranges; r++)
        if (in->ranges[r].hi > in->ranges[r].lo) total += in->ranges[r].hi - in->ranges[r].lo;
    if (total > KD_MAX_PRIMS)
        return error_set(err, ST_INPUT, "kd-tree: %llu primitives, more than the %u supported",
                         (unsigned long long)total, KD_MAX_PRIMS);
    uint8_t *finite = alloc_lists(b, (size_t)total);
    if (!finite) return error_set(err, ST_INTERNAL, "kd-tree: out of memory for %llu primitives", (unsigned long long)total);
    uint listed = 0;
    for (size_t r = 0; r < in->n_ranges; r++)
        for (uint gid = in->ranges[r].lo; gid < in->ranges[r].hi; gid++) b->gid[listed++] = gid;
    int n_jobs = jobs_threads(b->threads, total, 65536);
    ListJob jobs[JOBS_MAX];
    for (int i = 0; i < n_jobs; i++)
        jobs[i] = (ListJob){ in, b->gid, b->bounds, finite, (uint)(total * (uint64_t)i / (uint64_t)n_jobs),
                             (uint)(total * (uint64_t)(i + 1) / (uint64_t)n_jobs) };
    jobs_run(bounds_list, jobs, sizeof *jobs, n_jobs);
    keep_finite(b, in, finite, listed, 1, skipped);
    return ST_OK;
}

/* Collects the primitives (global ids, bounds). A primitive whose bounds are not
 * finite (a NaN or inf coordinate or radius) is left out of the tree, and so can never
 * be hit: no finite ray could hit it meaningfully, and one infinite box would make
 * every SAH area infinite. The bounds are computed on the build's threads, then the
 * finite ones moved down in order. With in->ranges, only the primitives they list. */
Status kd_gather(Build *b, const KdInput *in, uint *skipped, Error *err)
{
    if (in->n_ranges) return gather_ranges(b, in, skipped, err);
    size_t total = in->n_spheres + in->n_triangles + in->n_boxes + in->n_revs;
    if (total > KD_MAX_PRIMS)
        return error_set(err, ST_INPUT, "kd-tree: %zu primitives, more than the %u supported",
                         total, KD_MAX_PRIMS);
    uint8_t *finite = alloc_lists(b, total);
    if (!finite) return error_set(err, ST_INTERNAL, "kd-tree: out of memory for %zu primitives", total);
    int n_jobs = jobs_threads(b->threads, total, 65536);
    BoundsJob jobs[JOBS_MAX];
    for (int i = 0; i < n_jobs; i++)
        jobs[i] = (BoundsJob){ in, b->bounds, finite, (uint)(total * (size_t)i / (size_t)n_jobs),
                               (uint)(total * (size_t)(i + 1) / (size_t)n_jobs) };
    jobs_run(bounds_range, jobs, sizeof *jobs, n_jobs);
    keep_finite(b, in, finite, (uint)total, 0, skipped);
    return ST_OK;
}

