/* path.c — the one resolver of file names that scenes and meshes give (path.h). */
#include "io/path.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

static int path_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Replaces the component path[start, end) by a directory entry of the folder path[0,
 * start) that equals it without regard to case; 0 when there is none. Entries have the
 * same length as the component when they match, so the path is rewritten in place. */
static int match_component(char *path, size_t start, size_t end)
{
    char saved = path[start];
    size_t len = end - start;
    char name[256];
    if (len >= sizeof name) return 0;
    memcpy(name, path + start, len);
    name[len] = '\0';
    path[start] = '\0';
    DIR *d = opendir(start == 0 ? "." : path);
    path[start] = saved;
    if (!d) return 0;
    int found = 0;
    struct dirent *e;
    while (!found && (e = readdir(d)) != NULL) {
        if (strlen(e->d_name) == len && strcasecmp(e->d_name, name) == 0) {
            memcpy(path + start, e->d_name, len);
            found = 1;
        }
    }
    closedir(d);
    return found;
}

/* A copy of `path` whose components that do not exist are replaced by entries that
 * match them without regard to case; NULL when one has no match (or out of memory). */
static char *match_case(const char *path)
{
    size_t n = strlen(path), start = 0;
    char *fixed = malloc(n + 1);
    if (!fixed) return NULL;
    memcpy(fixed, path, n + 1);
    while (start < n) {
        while (start < n && fixed[start] == '/') start++;
        size_t end = start;
        while (end < n && fixed[end] != '/') end++;
        if (end == start) break;
        char saved = fixed[end];
        fixed[end] = '\0';
        int exists = path_exists(fixed);
        fixed[end] = saved;
        if (!exists && !match_component(fixed, start, end)) {
            free(fixed);
            return NULL;
        }
        start = end;
    }
    return fixed;
}

int path_resolve(const char *from, const char *name, size_t len, PathPolicy policy, char **out)
{
    int any_case = policy == PATH_ANY_CASE;
    int absolute = len > 0 && (name[0] == '/' || (any_case && name[0] == '\\'));
    const char *slash = strrchr(from, '/');
    size_t dir = absolute || !slash ? 0 : (size_t)(slash - from) + 1;
    char *path = *out = malloc(dir + len + 1);
    if (!path) return PATH_NO_MEMORY;
    memcpy(path, from, dir);
    for (size_t i = 0; i < len; i++) path[dir + i] = any_case && name[i] == '\\' ? '/' : name[i];
    path[dir + len] = '\0';
    switch (policy) {
    case PATH_BESIDE:
        return PATH_OK;
    case PATH_BESIDE_OR_CWD: {
        if (absolute || path_exists(path)) return PATH_OK;
        char *written = malloc(len + 1);
        if (!written) {
            free(path);
            *out = NULL;
            return PATH_NO_MEMORY;
        }
        memcpy(written, name, len);
        written[len] = '\0';
        if (!path_exists(written)) {
            free(written);
            return PATH_MISSING;
        }
        free(path);
        *out = written;
        return PATH_OK;
    }
    case PATH_ANY_CASE: {
        if (path_exists(path)) return PATH_OK;
        char *fixed = match_case(path);    /* NULL: no match (or out of memory): as written */
        if (fixed) {
            free(path);
            *out = fixed;
        }
        return PATH_OK;
    }
    }
    return PATH_OK;
}
