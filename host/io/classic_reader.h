/*
 * classic_reader.h — the parts of the classic scene reader (classic_parse.h; the format
 * is docs/classic-format.md) share this: the reader's state, the field tables' types, and
 * the functions one part calls in another. The reader is cut by concern:
 *   classic_parse.c     tokens and field blocks, camera, lights, background, the entry
 *                       points
 *   classic_material.c  Materials: Phong materials and checkerboards
 *   classic_object.c    objects: Group, Transform, spheres, planes, triangles, meshes,
 *                       curves and surfaces of revolution
 * Not for use outside these files.
 */
#ifndef CLPT_CLASSIC_READER_H
#define CLPT_CLASSIC_READER_H

#include <stddef.h>

#include "io/lexer.h"
#include "scene/scene.h"
#include "scene/transform.h"

typedef struct {
    Scene *s;
    Lexer lx;
    Error *err;
    uint first_material;       /* scene index of the classic material 0 */
    uint n_materials;          /* classic materials defined so far */
    uint current;              /* scene material of new objects (MaterialIndex) */
    uint fallback;             /* white material for objects before any material */
    int seen_camera, seen_lights, seen_background, seen_materials;
    int ambient_given;
    int camera_sized;      /* the camera gave width/height: Tsinghua's dialect */
    int keys_2004;         /* a material gave a key only MIT 2004 has (reflectiveColor,
                            * transparentColor, indexOfRefraction, exponent) */
    size_t tessellated;        /* triangles made from tilted surfaces of revolution so far */
    uint depth;                /* Group and Transform blocks open around the reader */
} Classic;

/* Field kinds: what a value must be. */
typedef enum {
    CK_VEC3,        /* three numbers */
    CK_COLOR,       /* three numbers >= 0 */
    CK_DIR,         /* three numbers, not all 0 */
    CK_NUMBER,      /* a number >= 0 */
    CK_ANY,         /* any number */
    CK_POSITIVE,    /* a number > 0 */
    CK_COUNT,       /* a whole number 1..16384 */
    CK_PATH         /* a file name: a word or a string */
} ClassicKind;

typedef struct {
    const char *key;
    ClassicKind kind;
    int required;
} ClassicKey;

typedef struct {
    int given;
    Token key;
    vec3 v;
    float f;
    unsigned long long u;
    Token word;
} ClassicValue;

/* classic_parse.c: tokens, field blocks, paths */
Status classic_next(Classic *c, Token *t);
Status classic_expected(Classic *c, const Token *t, const char *what);
Status classic_expect_brace(Classic *c, TokenKind kind, const char *what);
Status classic_read_float(Classic *c, float *out, Token *where, const char *what);
Status classic_read_value(Classic *c, const ClassicKey *k, ClassicValue *v);
Status classic_read_block(Classic *c, const Token *kw, const char *block, const ClassicKey *keys, size_t n,
                          ClassicValue *vals);
Status classic_only_one(Classic *c, const ClassicValue *a, const ClassicValue *b, const char *block);
Status classic_read_count(Classic *c, const char *key, unsigned long long *n);
Status classic_resolve_path(Classic *c, const Token *t, char **out);

/* classic_material.c: the Materials block */
Status classic_parse_materials(Classic *c, const Token *kw);

/* classic_object.c: objects and their transforms */
Status classic_parse_transform_ops(Classic *c, Transform *m, Token *stop);
Status classic_parse_object(Classic *c, const Token *kw, const Transform *m);
/* At the end of the file: when no mesh object is placed more than once, its instances
 * become the world copies they stand for (scene_flatten_instances). */
Status classic_finish_instances(Classic *c);

#endif /* CLPT_CLASSIC_READER_H */
