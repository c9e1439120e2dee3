/* mesh_load.c — a mesh file read by the reader its extension names (mesh_load.h). */
#include "io/mesh_load.h"

#include "io/gltf.h"
#include "io/lexer.h"
#include "io/obj.h"
#include "io/ply.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

MeshKind mesh_kind(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot) return MESH_NONE;
    /* "mesh.ply.gz" is a PLY file that the reader inflates as it reads it (lex_read_file
     * does for any name ending in .gz); glTF has its own compression and is not wrapped */
    size_t n = (size_t)(dot - base);
    if (strcmp(dot, ".gz") == 0 && n >= 4) {
        if (strncasecmp(dot - 4, ".obj", 4) == 0) return MESH_OBJ;
        if (strncasecmp(dot - 4, ".ply", 4) == 0) return MESH_PLY;
        return MESH_NONE;
    }
    if (strcasecmp(dot, ".obj") == 0) return MESH_OBJ;
    if (strcasecmp(dot, ".ply") == 0) return MESH_PLY;
    if (strcasecmp(dot, ".gltf") == 0 || strcasecmp(dot, ".glb") == 0) return MESH_GLTF;
    return MESH_NONE;
}

Status mesh_read_with(const char *path, MeshParseFn parse, Scene *s, const MeshOptions *o, Error *err)
{
    char *data;
    size_t len;
    Status st = lex_read_file(path, &data, &len, err);
    if (st) return st;
    st = parse(path, data, len, s, o, err);
    free(data);
    return st;
}

Status mesh_load(const char *path, Scene *s, const MeshOptions *o, Error *err)
{
    /* a name that is no mesh's is refused before the file is read (mesh_parse says why) */
    if (mesh_kind(path) == MESH_NONE) return mesh_parse(path, "", 0, s, o, err);
    return mesh_read_with(path, mesh_parse, s, o, err);
}

Status mesh_parse(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o, Error *err)
{
    switch (mesh_kind(path)) {
    case MESH_OBJ: return obj_parse_with(path, data, len, s, o, err);
    case MESH_PLY: return ply_parse(path, data, len, s, o, err);
    case MESH_GLTF: return gltf_parse(path, data, len, s, o, NULL, err);
    case MESH_NONE: break;
    }
    return error_set(err, ST_INPUT,
                     "'%s': not a mesh file (expected a name ending in .obj, .ply, .obj.gz, .ply.gz, .gltf or .glb)",
                     path);
}
