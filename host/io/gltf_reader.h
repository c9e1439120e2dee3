/*
 * gltf_reader.h — the parts of the glTF reader (gltf.h) share this: the reader's state and
 * the functions one part calls in another. The reader is cut by concern:
 *   gltf.c           the container: JSON helpers, buffers and URIs, accessors, GLB, the
 *                    entry point
 *   gltf_material.c  materials, textures and samplers
 *   gltf_scene.c     the scene: primitives, nodes, cameras, lights
 * Not for use outside these files.
 */
#ifndef CLPT_GLTF_READER_H
#define CLPT_GLTF_READER_H

#include <stddef.h>

#include "io/gltf.h"
#include "scene/mesh_sink.h"

#include <cjson/cJSON.h>

#define GLB_MAGIC 0x46546C67u      /* "glTF" */
#define GLB_JSON 0x4E4F534Au       /* "JSON" */
#define GLB_BIN 0x004E4942u        /* "BIN\0" */
/* glTF lights are photometric (candela, lux); clpt's are radiometric: divided by the
 * luminous efficacy of 555 nm light, 683 lm/W (docs/gltf.md). */
#define LUMENS_PER_WATT 683.0
/* Triangles one file may make, every copy included: a small file that copies a large
 * mesh many times must not exhaust memory (each triangle costs clpt a few hundred
 * bytes with its shading record and tree), so the count is bounded by the input's
 * size, and absolutely. A real file's mesh data takes 20 bytes or more per triangle,
 * so one per byte still lets each be copied some 20 times; 16 per byte let a 4 MB
 * strip of 1-byte indices in 16 nodes make 2^26 triangles (issue 39). A mesh in
 * several nodes is an object now, its triangles counted once; copies remain for
 * meshes that emit light and for a file read inside a clpt object. */
#define GLTF_TRIANGLES_PER_BYTE 1u
#define GLTF_MAX_TRIANGLES ((size_t)1 << 26)

typedef struct {
    const unsigned char *p;
    size_t len;
    size_t whole;         /* the bytes of the data before a buffer's byteLength cut them */
    char *owned;          /* heap copy (external file, decoded data: URI), or NULL */
} Buf;

/* The top-level arrays (and the lights of KHR_lights_punctual) as arrays of pointers:
 * cJSON keeps arrays as linked lists, where finding item i walks i items, and a reader
 * that looked every index up that way would be quadratic in its input. */
enum { T_BUFFERS, T_VIEWS, T_ACCESSORS, T_MESHES, T_MATERIALS, T_TEXTURES, T_IMAGES, T_SAMPLERS, T_CAMERAS, T_NODES,
       T_SCENES, T_LIGHTS, T_N };
typedef struct {
    const cJSON **item;
    int n;
} Table;

/* Where the node tree puts a mesh. The meshes are made once the walk has counted every
 * mesh's uses: one used once is copied in place, one used more becomes an object. */
typedef struct {
    int mesh, node;
    int gpu_instanced;     /* the node has EXT_mesh_gpu_instancing */
    Transform w;           /* the node's world matrix (with the MeshOptions' transform) */
} GltfPlacement;

/* A node's pose at a time of the animation (gltf_anim.c): the parts a channel
 * animates replace the node's own translation, rotation and scale. */
enum { GLTF_ANIM_T = 1, GLTF_ANIM_R = 2, GLTF_ANIM_S = 4 };
typedef struct {
    unsigned animated;     /* GLTF_ANIM_* bits: which parts are the animation's */
    double t[3], r[4], s[3];
} GltfNodePose;

/* Motion blur over a shutter (--shutter, gltf_anim.c): the nodes whose world transform
 * changes while it is open, and their world transform at the times sampled over it. A
 * moving node's mesh becomes an instance (an object even when used once) with a key
 * at each of `times` after the first (the open, the walk's own pose). */
typedef struct {
    const unsigned char *moves;      /* per node: 1 when it moves over the shutter */
    const double *times;  size_t n_times;   /* increasing; times[0] the open, the last the close */
    Status (*world_at)(void *ctx, int node, double t, Transform *out, Error *err);
    void *ctx;
} GltfBlur;

typedef struct {
    const char *path;
    Scene *s;
    Error *err;
    const MeshOptions *o;
    GltfView *view;
    cJSON *root;
    const unsigned char *bin;  size_t bin_len;   /* the GLB's BIN chunk */
    Buf *bufs;        int n_bufs;
    StrMap buffer_files;             /* resolved file name -> the first buffer read from it */
    int reading_buffer;              /* the buffer uri_read reads for, or -1 (an image) */
    StrMap image_sources[2];         /* an image's source -> its scene texture, sRGB [0] and linear [1] */
    uint *mats;       int n_mats;      /* scene material per glTF material, or NO_INDEX */
    uint default_mat;
    uint *tex;        int n_images;    /* per image: sRGB [2i], linear [2i+1] texture */
    unsigned char *visited;  int n_nodes;
    size_t triangles, max_triangles;
    GltfPlacement *placed;  size_t n_placed, cap_placed;
    size_t singular;                 /* instances skipped for a singular transform */
    int has_lights;
    const GltfNodePose *pose;        /* per node, an animation's pose; NULL: the file's own */
    const GltfBlur *blur;            /* NULL: still; else moving nodes' meshes get keys */
    int camera_node, camera_index;   /* the node and camera the scene looks through, or -1 */
    Table t[T_N];
} Gltf;

/* gltf.c: JSON helpers, buffers and URIs, accessors, the GLB container */
Status gltf_bad(Gltf *g, const char *jpath, const char *what);
/* The first element of an array (walk on with ->next), or NULL. */
const cJSON *gltf_first_of(const cJSON *a);
Status gltf_get_int(Gltf *g, const cJSON *obj, const char *key, long long def, long long lo, long long hi,
                    const char *jpath, long long *out);
Status gltf_get_index(Gltf *g, const cJSON *obj, const char *key, int required, const char *array,
                      const char *jpath, int *out);
Status gltf_get_num(Gltf *g, const cJSON *obj, const char *key, double def, double lo, double hi,
                    const char *jpath, double *out);
Status gltf_get_nums(Gltf *g, const cJSON *obj, const char *key, int n, const double *def, const char *jpath,
                     double *out);
const cJSON *gltf_ext_of(const cJSON *obj, const char *name);
const cJSON *gltf_item_at(const Gltf *g, const char *array, int i);
Status gltf_uri_file(Gltf *g, const char *uri, const char *jpath, char **file);
Status gltf_uri_read(Gltf *g, const char *uri, const char *jpath, Buf *out);
Status gltf_view_bytes(Gltf *g, int v, Buf *out, size_t *stride);
/* accessors[a] as `width`-wide elements of doubles (*out, *count elements), read for
 * the JSON path `use`. */
Status gltf_acc_read(Gltf *g, int a, int width, const char *use, double **out, size_t *count);
/* The same for an accessor that may be `width` or `width2` wide (0: only width); *got
 * says which. */
Status gltf_acc_read_either(Gltf *g, int a, int width, int width2, const char *use, double **out, size_t *count,
                            int *got);

/* gltf_material.c: materials, textures and samplers */
Status gltf_material_get(Gltf *g, int i, uint *out);

/* g set up as gltf_parse sets it up, nothing read. */
void gltf_init(Gltf *g, const char *path, Scene *s, const MeshOptions *o, GltfView *view, Error *err);
/* The file read and checked into g (its fields set as gltf_parse sets them), nothing
 * placed yet; gltf_close frees what it holds. */
Status gltf_open(Gltf *g, const char *data, size_t len);
void gltf_close(Gltf *g);

/* gltf_scene.c: primitives, nodes, cameras, lights */
/* The from, at and up of a camera whose node's world transform is xf (looking down
 * its -Z, up its +Y: glTF 2.0, 3.10). */
void gltf_camera_frame(const Transform *xf, vec3 *from, vec3 *at, vec3 *up);
/* Places the chosen scene's node tree (with g->pose when set); the node walk's own
 * state (visited, placed, counts) starts afresh each time. */
Status gltf_scene_walk(Gltf *g);
/* gltf_scene_walk, then the camera asked for found (view->camera). */
Status gltf_place(Gltf *g);
/* The scene camera from glTF camera `cam` under the world transform xf (the MeshOptions'
 * transform included); the image height from its aspect ratio. */
Status gltf_camera_set(Gltf *g, int cam, const Transform *xf);
/* Node n's local transform with g->pose's parts when set, checked (jp: "nodes[n]"). */
Status gltf_node_local(Gltf *g, int n, Transform *out);

#endif /* CLPT_GLTF_READER_H */
