/*
 * file_id.h — whether two names are one file, as the filesystem sees it: the same
 * device and inode when the file exists (so "x", "./x", a hard link and a symlink to it
 * are one file), else the same folder and name (so "x.png" and "./x.png" are one file
 * before either exists). Used to refuse an output that would overwrite an input or
 * another output before anything is written.
 */
#ifndef CLPT_FILE_ID_H
#define CLPT_FILE_ID_H

#include <stddef.h>
#include <sys/types.h>

#include "base/status.h"

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

/* What a named file is to a run. */
typedef enum { FILE_IMAGE, FILE_CHECKPOINT, FILE_RESUME, FILE_SCENE } FileRole;

/* A file a run names, and what it is to the run. */
typedef struct {
    FileId id;
    const char *what;     /* for messages: "the output image", "the checkpoint" */
    FileRole role;
} NamedFile;

void named_file_init(NamedFile *f, const char *path, const char *what, FileRole role);
/* Whether the run writes the file (an image or a checkpoint). */
int file_role_is_output(FileRole role);
/* Two outputs naming one file would leave one's bytes in the other (a checkpoint where
 * the image should be), and an output over an input destroys the input: both are
 * refused (ST_USAGE, naming both) before anything is done. A checkpoint over the one it
 * resumes from is how --resume goes on, and allowed. */
Status named_files_check_distinct(const NamedFile *files, size_t n, Error *err);

#endif /* CLPT_FILE_ID_H */
