/*
 * file_id.h — whether two names are one file, as the filesystem sees it: the same
 * device and inode when the file exists (so "x", "./x", a hard link and a symlink to it
 * are one file), else the same folder and name (so "x.png" and "./x.png" are one file
 * before either exists). Used to refuse an output that would overwrite an input or
 * another output before anything is written.
 */
#ifndef CLPT_FILE_ID_H
#define CLPT_FILE_ID_H

#include <sys/types.h>

typedef struct {
    const char *path;     /* as given (not copied) */
    int known;            /* dev/ino were found */
    dev_t dev;
    ino_t ino;
    const char *name;     /* NULL: dev/ino are the file's own; else its folder's, and this
                           * is the file's name in it */
} FileId;

/* Finds what `path` names now; symlinks are followed. */
void file_id_init(FileId *id, const char *path);
/* Whether a and b name one file: the same text, or the same device and inode (of the
 * files, or of their folders with the same name in it). */
int file_id_same(const FileId *a, const FileId *b);

#endif /* CLPT_FILE_ID_H */
