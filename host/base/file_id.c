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
