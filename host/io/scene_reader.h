/*
 * scene_reader.h — the parts of the scene file reader (scene_load.h; the format is
 * docs/scene-format.md) share this: the key tables' types, the parser's state, and the
 * functions one part calls in another. The reader is cut by concern:
 *   scene_parse.c     blocks read against key tables, camera, image, background,
 *                     includes, the statement loop, the entry points
 *   scene_material.c  materials (their keys and types) and textures
 *   scene_shape.c     spheres, planes, triangles, quads, boxes, meshes, lights
 *   scene_object.c    objects and their instances
 *   scene_medium.c    participating media
 * Not for use outside these files.
 */
#ifndef CLPT_SCENE_READER_H
#define CLPT_SCENE_READER_H

#include <math.h>
#include <stddef.h>

#include "io/lexer.h"
#include "scene/camera_path.h"
#include "scene/scene.h"

typedef enum {
    VK_NUMBER,      /* one float within the key's range */
    VK_UINT,        /* one unsigned integer within the key's range */
    VK_VEC3,        /* three floats */
    VK_COLOR,       /* three floats >= 0 */
    VK_DIR,         /* three floats, not all zero */
    VK_WORD,        /* a bare word (checked by the statement) */
    VK_MATERIAL,    /* a material name, or an inline anonymous material block */
    VK_PATH,        /* a string or a word */
    VK_TEXTURE,     /* the name of a texture defined before */
    VK_ROTATE,      /* an axis (three floats, not all zero) and an angle in degrees */
    VK_SCALE,       /* one non-zero float, or three */
    VK_MATRIX,      /* sixteen floats, a 4x4 matrix row by row */
    VK_MEDIUM,      /* a medium name defined before, or none (vacuum): u = 0 or 1 + index */
    VK_NUMBER_LIST, /* [ numbers ... ]: u of them, in Parser.list from list_at */
    VK_PAIR         /* two numbers, in a[0] and a[1] */
} ValueKind;

/* The most numbers one VK_NUMBER_LIST may hold (a 256^3 density grid): a bound on what
 * a scene file can make the reader allocate. */
#define SCENE_LIST_MAX (1u << 24)

typedef struct {
    const char *key;
    ValueKind kind;
    int required;
    double lo, hi;          /* VK_NUMBER, VK_UINT: the allowed range */
    int lo_open, hi_open;   /* whether the bound itself is excluded */
    const char *what;       /* VK_NUMBER, VK_UINT, VK_WORD: "a number in (0, 180)" */
} KeySpec;

/* Key lists more than one block takes, so that each reads and checks them the same
 * way. A block's enum names its ids with the *_KEY_IDS list and its table takes the
 * matching *_KEYS entries; the order is kept where a reader relies on it.
 *
 * A surface's material and the media on either side of it: shape_surface
 * (scene_shape.c) reads the three from v[prefix##_MATERIAL] onwards. */
#define SURFACE_KEY_IDS(prefix) prefix##_MATERIAL, prefix##_INTERIOR, prefix##_EXTERIOR
#define MEDIUM_KEYS(prefix)                                              \
    [prefix##_INTERIOR] = {"interior", VK_MEDIUM, 0, 0, 0, 0, 0, NULL}, \
    [prefix##_EXTERIOR] = {"exterior", VK_MEDIUM, 0, 0, 0, 0, 0, NULL}
#define SURFACE_KEYS(prefix)                                              \
    [prefix##_MATERIAL] = {"material", VK_MATERIAL, 1, 0, 0, 0, 0, NULL}, \
    MEDIUM_KEYS(prefix)

/* A block's placement: scene_parse_transform reads these seven as consecutive values
 * from v[prefix##_TRANSLATE], in this order. */
#define TRANSFORM_KEY_IDS(prefix) \
    prefix##_TRANSLATE, prefix##_ROTATE, prefix##_RX, prefix##_RY, prefix##_RZ, prefix##_SCALE, prefix##_MATRIX
#define TRANSFORM_KEYS(prefix)                                                                  \
    [prefix##_TRANSLATE] = {"translate", VK_VEC3, 0, 0, 0, 0, 0, NULL},                        \
    [prefix##_ROTATE] = {"rotate", VK_ROTATE, 0, 0, 0, 0, 0, NULL},                            \
    [prefix##_RX] = {"rx", VK_NUMBER, 0, -INFINITY, INFINITY, 0, 0, "an angle in degrees"}, \
    [prefix##_RY] = {"ry", VK_NUMBER, 0, -INFINITY, INFINITY, 0, 0, "an angle in degrees"}, \
    [prefix##_RZ] = {"rz", VK_NUMBER, 0, -INFINITY, INFINITY, 0, 0, "an angle in degrees"}, \
    [prefix##_SCALE] = {"scale", VK_SCALE, 0, 0, 0, 0, 0, NULL},                               \
    [prefix##_MATRIX] = {"matrix", VK_MATRIX, 0, 0, 0, 0, 0, NULL}

typedef struct {
    int given;
    Token key;              /* where the key was written */
    Token value;            /* its first value token */
    float f;
    unsigned long long u;
    vec3 v;
    uint material;
    Token word;             /* VK_WORD, VK_PATH */
    float a[16];            /* VK_ROTATE (axis, degrees), VK_SCALE (x y z), VK_MATRIX */
    size_t list_at;         /* VK_NUMBER_LIST: where its numbers start in Parser.list */
} Value;

typedef struct {
    Scene *s;
    Error *err;
    uint depth;                       /* include nesting: 0 for the top file */
    char *camera_at, *image_at, *background_at;   /* "file:line:col" once given */
    char **material_at;               /* per material index, where it was defined */
    size_t n_material_at, cap_material_at;
    int depth_exceeded;               /* the include limit error is not annotated further */
    uint object;                      /* the object whose block is being read, or NO_INDEX */
    uint last_instance;               /* the last instance read (instance_key moves it), or
                                       * NO_INDEX */
    float last_instance_time;         /* ... and the time of its own pose */
    int last_instance_nests;          /* whether last_instance is NO_INDEX because the
                                       * instance was inside an object or placed several
                                       * (instance_key's message says which) */
    Token object_name;                /* where that object was named */
    float *list;                      /* VK_NUMBER_LIST values of the block being read
                                       * (emptied when a block starts; freed at the end) */
    size_t n_list, cap_list;
    char *camera_path_at;             /* "file:line:col" of the camera_path, once given */
    CameraKey *path_keys;             /* its keys, each whole (scene_camera_path.c) */
    size_t n_path_keys, cap_path_keys;
    int path_interp;                  /* enum CameraPathInterp */
} Parser;

/* scene_camera_path.c: the camera_path statement, and the scene's animation made of it
 * once the file is read (when the scene keeps animations) */
Status scene_parse_camera_path(Parser *p, Lexer *lx, const Token *kw);
Status scene_camera_path_finish(Parser *p);

/* scene_parse.c: blocks, paths, vector helpers */
char *scene_path_beside(const char *from, const char *file, size_t file_len);
Status scene_parse_block(Parser *p, Lexer *lx, const Token *kw, int brace_taken,
                         const char *block, const KeySpec *keys, size_t n, Value *vals);
double scene_len_d(vec3 a);
vec3 scene_cross_d(vec3 a, vec3 b, double *length);

/* The statement handlers declared below all take (Parser, Lexer, the statement's
 * token), the signature scene_parse.c's statement table calls: their declarations are
 * alike by design, one per entry of that table. */
/* scene_material.c: material, texture */
Status scene_parse_material_block(Parser *p, Lexer *lx, const Token *kw, int brace_taken,
                                  const char *name, uint *index);
Status scene_parse_material(Parser *p, Lexer *lx, const Token *kw);
Status scene_parse_texture(Parser *p, Lexer *lx, const Token *kw);

/* scene_shape.c: sphere, plane, triangle, quad, box, mesh, light */
/* sphere, plane, triangle, quad and box: the shape kw names */
Status scene_parse_shape(Parser *p, Lexer *lx, const Token *kw);
Status scene_parse_mesh(Parser *p, Lexer *lx, const Token *kw);
Status scene_parse_light(Parser *p, Lexer *lx, const Token *kw);
/* The transform of a block's keys translate, rotate, rx, ry, rz, scale, matrix (seven
 * consecutive values from t, in that order); `what` names the block ("mesh",
 * "instance") in the message for a singular one. */
Status scene_parse_transform(Parser *p, const Lexer *lx, const Token *kw, const Value *t, const char *what,
                             Transform *out);

/* scene_object.c: object, instance (docs/instancing.md) */
Status scene_parse_object(Parser *p, Lexer *lx, const Token *kw);
Status scene_parse_instance(Parser *p, Lexer *lx, const Token *kw);
Status scene_parse_instance_key(Parser *p, Lexer *lx, const Token *kw);

/* scene_medium.c: the medium statement, shapes' interior and exterior media */
Status scene_parse_medium(Parser *p, Lexer *lx, const Token *kw);
/* A VK_MEDIUM value at token t: *ref = 0 for none, else 1 + the medium's index. */
Status scene_read_medium_ref(Parser *p, Lexer *lx, const Token *t, uint *ref);
/* The material a shape of `material` gets with its optional interior and exterior
 * values (NULL or not given: the background's medium); itself when neither is given. */
Status scene_shape_media(Parser *p, const Value *interior, const Value *exterior, uint material, uint *bound);
/* The same for the triangles [first, n_triangles) of a mesh, each of its own material. */
Status scene_mesh_media(Parser *p, const Value *interior, const Value *exterior, size_t first);

#endif /* CLPT_SCENE_READER_H */
