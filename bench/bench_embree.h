/* bench_embree.h — what the benchmarks that compare with Embree 3 share (bench_traverse,
 * bench_build): the scene's triangles as one Embree geometry, and the build of an Embree
 * scene timed with the bytes it allocates. Header-only, as bench_util.h; only the
 * benchmarks link libembree3 (Makefile, .embree-ok). */
#ifndef CLPT_BENCH_EMBREE_H
#define CLPT_BENCH_EMBREE_H

#include <embree3/rtcore.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <sys/types.h>

#include "base/timer.h"
#include "scene/scene.h"

static atomic_llong bench_embree_allocated;

/* Embree's memory monitor: what its allocations and frees add up to. */
static inline bool bench_embree_memory(void *ptr, ssize_t bytes, bool post)
{
    (void)ptr;
    (void)post;
    atomic_fetch_add(&bench_embree_allocated, (long long)bytes);
    return true;
}

/* n triangles as one committed triangle geometry of dev, every corner its own vertex
 * (as clpt stores them), built at RTC_BUILD_QUALITY_HIGH; NULL when Embree could not
 * allocate its buffers. */
static inline RTCGeometry bench_embree_triangles(RTCDevice dev, const Triangle *tris, size_t n)
{
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n);
    unsigned *idx = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n);
    if (!v || !idx) {
        rtcReleaseGeometry(g);
        return NULL;
    }
    for (size_t i = 0; i < n; i++) {
        const vec3 *c[3] = { &tris[i].p0, &tris[i].p1, &tris[i].p2 };
        for (int k = 0; k < 3; k++) {
            v[9 * i + 3 * k + 0] = c[k]->x;
            v[9 * i + 3 * k + 1] = c[k]->y;
            v[9 * i + 3 * k + 2] = c[k]->z;
            idx[3 * i + k] = (unsigned)(3 * i + k);
        }
    }
    rtcCommitGeometry(g);
    return g;
}

/* Commits (builds) scene: its seconds into *seconds, the bytes the build allocated and
 * kept into *bytes. Returns 0, or -1 when Embree reports an error. */
static inline int bench_embree_commit(RTCDevice dev, RTCScene scene, double *seconds, long long *bytes)
{
    atomic_store(&bench_embree_allocated, 0);
    rtcSetDeviceMemoryMonitorFunction(dev, bench_embree_memory, NULL);
    double t0 = timer_now();
    rtcCommitScene(scene);
    *seconds = timer_now() - t0;
    *bytes = atomic_load(&bench_embree_allocated);
    rtcSetDeviceMemoryMonitorFunction(dev, NULL, NULL);
    return rtcGetDeviceError(dev) == RTC_ERROR_NONE ? 0 : -1;
}

#endif
