/* file_id.c — see file_id.h. */
#include "base/file_id.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

void file_id_init(FileId *id, const char *path)
{
    struct stat sb;
    memset(id, 0, sizeof *id);
    id->path = path;
    if (stat(path, &sb) == 0) {
        id->known = 1;
    } else {
        const char *slash = strrchr(path, '/');
        char dir[4096];
        snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) + 1 : 1, slash ? path : ".");
        if (stat(dir, &sb) != 0) return;
        id->known = 1;
        id->name = slash ? slash + 1 : path;
    }
    id->dev = sb.st_dev;
    id->ino = sb.st_ino;
}

int file_id_same(const FileId *a, const FileId *b)
{
    if (strcmp(a->path, b->path) == 0) return 1;
    if (!a->known || !b->known || a->dev != b->dev || a->ino != b->ino) return 0;
    if (!a->name || !b->name) return !a->name && !b->name;
    return strcmp(a->name, b->name) == 0;
}

void named_file_init(NamedFile *f, const char *path, const char *what, FileRole role)
{
    file_id_init(&f->id, path);
    f->what = what;
    f->role = role;
}

int file_role_is_output(FileRole role)
{
    return role == FILE_IMAGE || role == FILE_CHECKPOINT;
}

Status named_files_check_distinct(const NamedFile *files, size_t n, Error *err)
{
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            const NamedFile *a = &files[i], *b = &files[j];
            if (!file_role_is_output(a->role) && !file_role_is_output(b->role)) continue;
            if (a->role == FILE_CHECKPOINT && b->role == FILE_RESUME) continue;
            if (!file_id_same(&a->id, &b->id)) continue;
            return error_set(err, ST_USAGE, "%s '%s' and %s '%s' are the same file; give each its own name",
                             a->what, a->id.path, b->what, b->id.path);
        }
    return ST_OK;
}
