/*
 * mtl.h — Wavefront MTL material libraries, mapped onto clpt's materials.
 *
 * Read: newmtl, Kd, Ks, Ke, Ns, Ni, d, Tr, illum, map_Kd (with its options skipped).
 * Every other statement (Ka, Tf, map_Ka, bump, the PBR extensions, ...) is accepted and
 * ignored: MTL is extended freely by exporters. A statement that is read must be well
 * formed (three numbers, or one for a grey, after Kd ...), else the error gives
 * file:line:column. The mapping onto our material types (docs/meshes.md):
 *
 *   Ke not black                        emissive, radiance Ke
 *   illum 4, 6, 7 or 9, or d < 1        dielectric, ior Ni (1.5 when Ni is absent or <= 0)
 *   illum 3, 5 or 8                     metal, albedo Ks, fuzz sqrt(2 / (Ns + 2))
 *   anything else                       diffuse, albedo Kd (0.8 grey when absent)
 *
 * Ks and Ns are also kept in every material's `specular` and `shininess`. map_Kd is
 * resolved against the MTL file's folder with path_resolve (case-insensitive when
 * the exact name is missing) and kept as a path for the texture loader.
 */
#ifndef CLPT_MTL_H
#define CLPT_MTL_H

#include "base/strmap.h"
#include "scene/scene.h"

typedef struct {
    char *name;
    Material m;
    char *texture;       /* resolved map_Kd path, or NULL */
    char *texture_at;    /* where map_Kd names it ("file.mtl:12:8"), for messages */
} MtlMaterial;

typedef struct {
    MtlMaterial *items;
    size_t n, cap;
    StrMap by_name;      /* name -> index in items, so that reading is linear */
} MtlLibrary;

/* Reads an MTL file and appends its materials; a name defined again replaces the
 * earlier definition (later mtllib files win, as in most OBJ readers). */
Status mtl_load(const char *path, MtlLibrary *lib, Error *err);
/* The same from text in memory, NUL-terminated at text[len]; `path` names it in
 * messages and is the folder textures are resolved against. */
Status mtl_parse(const char *path, const char *text, size_t len, MtlLibrary *lib, Error *err);
void mtl_free(MtlLibrary *lib);
/* The material named name[0, len), or NULL. */
const MtlMaterial *mtl_find(const MtlLibrary *lib, const char *name, size_t len);

#endif /* CLPT_MTL_H */
