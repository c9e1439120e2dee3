/*
 * path.h — where a file that a scene or mesh names is read from: one resolver, with the
 * rule each reader follows as its policy.
 *
 * Every policy takes a relative name from the folder of a file `from` (nothing when
 * `from` has no '/': the current folder) and keeps an absolute name ('/...') as written.
 * The readers and their rules:
 *
 *   reader            from                     policy
 *   clpt (scene_parse) the file naming it       PATH_BESIDE       (an include's own folder)
 *   pbrt-v4           the main scene file      PATH_BESIDE       (includes too, as pbrt does)
 *   glTF              the .gltf file           PATH_BESIDE       (URIs decoded first; absolute
 *                                                                  ones refused before this)
 *   classic (6.837)   the scene file           PATH_BESIDE_OR_CWD
 *   OBJ / MTL         the .obj / .mtl file     PATH_ANY_CASE
 */
#ifndef CLPT_PATH_H
#define CLPT_PATH_H

#include <stddef.h>

typedef enum {
    /* beside `from`, whether or not the file exists there */
    PATH_BESIDE,
    /* beside `from` when a file (or folder) exists there, else the name as written (from
     * the current folder: course scenes are run from the course's code folder) when it
     * exists; neither: path_resolve returns PATH_MISSING */
    PATH_BESIDE_OR_CWD,
    /* Windows habits of mesh files: '\' is taken as '/' (so '\...' is absolute), and when
     * the file does not exist beside `from`, each path component is matched without
     * regard to case (the Sponza's MTL names "SP_LUK.JPG" for sp_luk.JPG); the path as
     * written when nothing matches */
    PATH_ANY_CASE
} PathPolicy;

enum { PATH_OK = 0, PATH_NO_MEMORY = -1, PATH_MISSING = 1 };

/* The file `name` (`len` bytes, not NUL-terminated) as `policy` finds it from the file
 * `from`, in *out (a heap string, free'd by the caller). Returns PATH_OK;
 * PATH_NO_MEMORY (*out NULL); or, with PATH_BESIDE_OR_CWD, PATH_MISSING when neither
 * place has it, *out then being the path beside `from`, for the message. */
int path_resolve(const char *from, const char *name, size_t len, PathPolicy policy, char **out);

#endif /* CLPT_PATH_H */
