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

#include "base/status.h"
#include "scene_view.h"
#include "types.h"

/* The counts kernels/scene_buffers.h finds in a DeviceScene rather than in params, one
 * list: whatever copies a scene to another place (dist/mpi_driver.c's broadcast) copies
 * every one of them. */
#define DEVICE_SCENE_COUNTS(X)                                                               \
    X(uint, n_materials)                                                                     \
    X(uint, n_shading)                                                                       \
    X(uint, n_tri_extra_of)     /* n_shading, or 0 when no triangle has extras */            \
    X(uint, n_tri_extras)                                                                    \
    X(uint, n_sphere_xforms)    /* Sphere.xform's targets */                                 \
    X(uint, n_instance_lights)  /* the scene's instances when any has lights, else 0 */      \
    X(size_t, n_texels)                                                                      \
    X(size_t, n_rev_points)     /* floats: two per profile control point */                  \
    X(size_t, n_env_cdf)                                                                     \
    X(size_t, n_bvh_leaves)     /* words of the BVH's leaf records */                        \
    X(uint, n_bvh_top)          /* the top level's nodes (BvhTopNode); 0 without instances */ \
    X(uint, n_kd_protos)        /* --accel kdtree with instances: prototypes' kd-trees */    \
    X(size_t, n_grid_data)      /* floats of the density grids and their majorants */        \
    X(uint, n_motion_keys)      /* keys of moving transforms (instances', the camera's) */   \
    X(uint, n_instance_motion)  /* the device's instances when any moves, else 0 */

/* Everything a device needs, in kernel layout: one field per line of
 * kernels/scene_buffers.h (the params block by value, every other buffer as a pointer,
 * NULL when its count is 0), then the counts that list finds here rather than in params.
 * pixel_list has params.pixel_list_size entries, the pixels a batch covers, or is NULL
 * (0: every pixel). */
#define DEVICE_SCENE_FIELD_ONE_(Type, name) Type name;
#define DEVICE_SCENE_FIELD_MANY_(Type, name) const Type *name;
#define DEVICE_SCENE_FIELD_(kind, Type, name, count, what) DEVICE_SCENE_FIELD_##kind##_(Type, name)
#define DEVICE_SCENE_COUNT_FIELD_(Type, name) Type name;
typedef struct {
    SCENE_BUFFERS(DEVICE_SCENE_FIELD_)
    DEVICE_SCENE_COUNTS(DEVICE_SCENE_COUNT_FIELD_)
} DeviceScene;
#undef DEVICE_SCENE_FIELD_
#undef DEVICE_SCENE_FIELD_MANY_
#undef DEVICE_SCENE_FIELD_ONE_

/* One scene buffer of a DeviceScene as bytes: what a device uploads and the render key
 * hashes. data may be NULL when bytes is 0. */
typedef struct {
    const void *data;
    size_t bytes;
    const char *what;     /* "triangles", "texture images" ... (scene_buffers.h) */
} SceneBufferBytes;

/* Buffer `b` (SCENE_BUF_nodes ...) of ds; b < SCENE_BUF_COUNT. */
SceneBufferBytes device_scene_buffer(const DeviceScene *ds, unsigned b);

/* Points every field of `view` at ds's buffers (the scalar device and the tests run the
 * kernel stage functions on the host's own arrays). */
void device_scene_view(const DeviceScene *ds, SceneView *view);

typedef enum { DEVICE_OPENCL, DEVICE_SCALAR } DeviceKind;

/* The kind of processor, as OpenCL reports it (a device may be several). */
enum { DEVICE_TYPE_CPU = 1u, DEVICE_TYPE_GPU = 2u, DEVICE_TYPE_ACCELERATOR = 4u };

/* One entry of --list-devices. OpenCL devices come first, in platform order; the scalar
 * device is last. Plain C: what is OpenCL about a device stays in device_ocl.c, which
 * alone turns the opaque handles back into OpenCL objects. */
typedef struct {
    DeviceKind kind;
    unsigned index;               /* position in the listing; for an OpenCL device, what
                                   * --device N means (the scalar device has none) */
    char name[256];
    unsigned type;                /* DEVICE_TYPE_* bits */
    const char *type_name;        /* "GPU", "CPU" ... (a static string) */
    unsigned compute_units;
    uint64_t global_mem, max_alloc;   /* bytes (OpenCL: after any CLPT_TEST_DEVICE_MEMORY cap) */
    char platform_name[256];      /* OpenCL only, as the rest below */
    char driver_version[128];
    void *ocl_platform, *ocl_device;  /* cl_platform_id, cl_device_id */
    unsigned ocl_platform_index, ocl_device_index;
} DeviceDesc;

typedef struct {
    int threads;                  /* scalar device: worker threads, 0 = every core */
    const char *kernel_dir;       /* OpenCL: load kernels from here instead (developers) */
    unsigned wave_paths;          /* OpenCL: paths per wave, 0 = chosen by device type */
    int profile;                  /* measure DeviceCounters.phase_seconds (--profile) */
    int wave_launch;              /* OpenCL: enum WaveLaunch, 0 = by device type */
} DeviceConfig;

/* How an OpenCL device launches a wave's bounces (device_ocl.c). */
enum WaveLaunch {
    WAVE_LAUNCH_AUTO = 0,     /* bounded on GPUs, megakernel elsewhere (counted there
                               * with --profile, whose phases one kernel cannot tell) */
    WAVE_LAUNCH_COUNTED = 1,  /* each bounce over the live count read back first */
    WAVE_LAUNCH_BOUNDED = 2,  /* every bounce at once over the wave's size */
    WAVE_LAUNCH_MEGAKERNEL = 3,   /* one kernel runs each path from birth to end */
};

/* Where a device's time goes (--profile). OpenCL: device time of each command, from
 * its profiling event (k_raygen, k_intersect, k_shade with its queue compaction,
 * k_shadow, k_film with the film's read-back and clearing; the queue counters' clearing
 * and read-backs), and the host's time blocked waiting for the device. Scalar: thread
 * time in each stage function, summed over the threads and divided by their number. */
enum DevicePhase {
    PHASE_RAYGEN, PHASE_TRAVERSE, PHASE_SHADE, PHASE_SHADOW, PHASE_FILM, PHASE_QUEUES, PHASE_HOST_WAIT,
    PHASE_N
};

typedef struct {
    double compile_seconds;       /* OpenCL program build or cache load */
    int from_cache;
    double upload_seconds;
    uint64_t bytes_in_place;      /* OpenCL CPU devices: the loaded scene's bytes used
                                   * where the host made them, not copied (ocl_buffers.c) */
    /* OpenCL, for --stats: the loaded scene's waves (paths each) and how one runs (a
     * static string: "bounded bounces", "megakernel k_path", ...) */
    unsigned wave_paths;
    const char *wave_run;
    /* the scalar device, for --stats: the build of the kernels the loaded scene runs on
     * (a static string, scalar_paths.h: "mesh", "basic", "lean", "all") */
    const char *kernel_build;
    uint64_t rays;                /* every ray traced: camera, bounce and shadow rays */
    uint64_t samples;             /* pixel samples rendered (pixels x samples) */
    double phase_seconds[PHASE_N];  /* --profile only: enum DevicePhase */
} DeviceCounters;

typedef struct Device Device;

typedef struct {
    /* Gives the device a scene. Its arrays may be read where they are until the next
     * load_scene or the device's end (the scalar device reads them all in place, an
     * OpenCL CPU device those on huge pages, ocl_buffers.c), so the caller keeps them,
     * unchanged, until then; the params block is copied. */
    Status (*load_scene)(Device *d, const DeviceScene *scene, Error *err);
    /* Replaces the params block and the pixel list of the loaded scene, keeping every
     * other buffer (a pass that changes the integrator, the samples or the pixels need
     * not upload the kd-tree again). The image size must be the one loaded; pixel_list
     * holds params->pixel_list_size pixel indices (NULL when 0: every pixel). */
    Status (*update_params)(Device *d, const RenderParams *params, const uint *pixel_list, Error *err);
    /* Renders samples [first_sample, first_sample + count) of every pixel, or of every
     * pixel of the list; ST_INTERRUPTED, with nothing of the batch kept, when *d->cancel
     * was set meanwhile. */
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

/* The default choice falls back group by group: when no device of the default choice
 * can be used (their kernels do not build, say), `chosen` receives the next group of
 * the default order after the one of all[failed] that has any device (OpenCL GPUs,
 * then OpenCL CPUs, then the scalar device); none when no group is left. */
Status device_select_fallback(const DeviceDesc *all, size_t n, size_t failed, size_t **chosen,
                              size_t *n_chosen, Error *err);

Status device_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err);
void device_close(Device *d);

/* Prints a warning for the caller (clpt clears its progress bar first). */
typedef void (*DeviceWarn)(void *ctx, const char *msg);

/* The policy a render opens its devices by: lists them (warning through `warn` when
 * OpenCL is missing or broken), chooses by `spec` (device_select), then opens each and
 * gives it the scene. A device that fails is dropped with a warning as long as another
 * works; when none of the default choice works, the next default group is tried
 * (device_select_fallback). *out (calloc'd, *n_out devices) is the caller's to close
 * and free. One chosen device that fails returns its own error, with its build log. */
Status device_open_all(const char *spec, const DeviceConfig *cfg, const DeviceScene *ds, DeviceWarn warn,
                       void *warn_ctx, Device ***out, size_t *n_out, Error *err);

/* Gives each of n devices ds's params block and pixel list (update_params): the step
 * every pass, adaptive round and pilot that changes the params takes. */
Status device_update_all(Device **devs, size_t n, const DeviceScene *ds, Error *err);

/* Constructors used by device_open. */
Status device_scalar_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err);
Status device_ocl_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err);

#endif /* CLPT_DEVICE_H */
