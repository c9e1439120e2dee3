/*
 * device.h — a device that renders batches of samples: an OpenCL device (device_ocl.c)
 * or the scalar C device (device_scalar.c), behind one small interface, plus the listing
 * and --device selection of all of them.
 *
 * A device receives the scene once, then renders batches: sample indices
 * [first, first + count) of every pixel, added into the device's own fixed-point film,
 * which the host takes (adds into its film and clears) after each batch. Because the film
 * is integer and every random number is keyed by (pixel, sample, bounce, dimension), the
 * image does not depend on which device rendered which batch.
 *
 * Batches may be pipelined: `render` may return while the batch's film is still on its
 * way back, and up to `max_in_flight` batches may be rendered before their films are
 * taken; `take_film` takes them in the order they were rendered, waiting if needed. The
 * OpenCL device uses this to read one batch's film back while the next one renders; the
 * scalar device finishes each batch in `render` (max_in_flight 1).
 *
 * A batch can be cancelled: while `cancel` points to a flag that another thread sets,
 * `render` checks it between small steps of work (the scalar device between chunks of
 * about a thousand paths, the OpenCL device between the launches of its waves) and,
 * once it is set, drops the batch's partial film and returns ST_INTERRUPTED. Batches
 * rendered before stay whole and can still be taken, so a film holds whole batches
 * only and the image stays the same whichever moment the cancel came.
 */
#ifndef CLPT_DEVICE_H
#define CLPT_DEVICE_H

#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>

#include "device/ocl.h"
#include "base/status.h"
#include "types.h"

/* Everything a device needs, in kernel layout; counts of spheres, triangles, boxes,
 * planes and lights are in params. Arrays may be NULL when their count is 0. */
typedef struct {
    RenderParams params;
    const KdNode *nodes;          /* params.n_nodes */
    const uint *leaf_prims;       /* params.n_leaf_prims */
    const Sphere *spheres;
    const Triangle *triangles;
    const Box *boxes;
    const Plane *planes;
    const Material *materials;    uint n_materials;
    const Light *lights;
    const TriShading *shading;    uint n_shading;
    const Texture *textures;      /* params.n_textures */
    const uint *texels;           size_t n_texels;
    const uint *pixel_mask;       /* width * height entries when params.use_mask, else NULL */
} DeviceScene;

typedef enum { DEVICE_OPENCL, DEVICE_SCALAR } DeviceKind;

/* One entry of --list-devices. OpenCL devices come first, in platform order; the scalar
 * device is last. */
typedef struct {
    DeviceKind kind;
    unsigned index;               /* position in the listing, what --device N means */
    char name[256];
    OclDeviceInfo ocl;            /* valid for DEVICE_OPENCL */
} DeviceDesc;

typedef struct {
    int threads;                  /* scalar device: worker threads, 0 = every core */
    const char *kernel_dir;       /* OpenCL: load kernels from here instead (developers) */
    unsigned wave_paths;          /* OpenCL: paths per wave, 0 = chosen by device type */
} DeviceConfig;

typedef struct {
    double compile_seconds;       /* OpenCL program build or cache load */
    int from_cache;
    double upload_seconds;
    uint64_t rays;                /* every ray traced: camera, bounce and shadow rays */
    uint64_t samples;             /* pixel samples rendered (pixels x samples) */
} DeviceCounters;

typedef struct Device Device;

typedef struct {
    Status (*load_scene)(Device *d, const DeviceScene *scene, Error *err);
    /* Renders samples [first_sample, first_sample + count) of every pixel; ST_INTERRUPTED,
     * with nothing of the batch kept, when *d->cancel was set meanwhile. */
    Status (*render)(Device *d, uint first_sample, uint count, Error *err);
    /* Adds the film of the oldest batch not yet taken into `film` (n_pixels * 3). */
    Status (*take_film)(Device *d, int64_t *film, Error *err);
    void (*destroy)(Device *d);
} DeviceOps;

struct Device {
    const DeviceOps *ops;
    DeviceDesc desc;
    DeviceCounters counters;
    uint n_pixels;                /* set by load_scene */
    uint max_in_flight;           /* batches rendered and not yet taken, at most (>= 1;
                                     set by load_scene) */
    const atomic_int *cancel;     /* set by the caller; NULL: never cancelled */
    void *impl;
};

/* Lists every device: each OpenCL device of each platform, then the scalar device.
 * A broken OpenCL installation does not fail the listing (the scalar device still
 * works): its error is written to `warning` (empty when none). */
Status device_list(DeviceDesc **out, size_t *n, char *warning, size_t warning_size, Error *err);
void device_list_print(FILE *f, const DeviceDesc *all, size_t n);

/* Chooses devices by SPEC: a comma-separated list of indices, "all", "scalar", "gpu",
 * "cpu", or name substrings (case-insensitive). NULL or "" is the default: every OpenCL
 * GPU, else the OpenCL CPU devices, else the scalar device. `chosen` receives indices
 * into `all`, without duplicates. A spec matching nothing is ST_USAGE, with the list. */
Status device_select(const char *spec, const DeviceDesc *all, size_t n, size_t **chosen,
                     size_t *n_chosen, Error *err);

Status device_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err);
void device_close(Device *d);

/* Constructors used by device_open. */
Status device_scalar_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err);
Status device_ocl_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err);

#endif /* CLPT_DEVICE_H */
