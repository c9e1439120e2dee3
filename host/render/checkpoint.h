/*
 * checkpoint.h — saving and resuming the accumulation state of a render.
 *
 * A checkpoint holds the integer film (every pixel's fixed-point sums), the number of
 * samples per pixel in it and which sample indices those are, plus an identity of the
 * render: a SHA-256 "render key" over everything that determines each sample (the prepared
 * scene with its tree, camera, size, seed, depth, and the kernel source), the samples per
 * pixel of the complete render, and a few of those settings in clear for the error
 * messages. The key leaves the samples per pixel out: the samples of a render of N are
 * the first N of any longer one, so a checkpoint or a part can be grown to more.
 * Because the film is integer and every sample is a pure function of its indices, a
 * render resumed from a checkpoint ends with the same bits as one never interrupted.
 *
 * Files are written atomically (temporary file beside the target, fsync, rename), so a
 * kill at any moment leaves the previous checkpoint or the new one, never a torn one.
 * The format (little-endian, versioned header, SHA-256 trailer) is in docs/checkpoint.md.
 */
#ifndef CLPT_CHECKPOINT_H
#define CLPT_CHECKPOINT_H

#include <stddef.h>

#include "render/adaptive.h"
#include "render/batch_queue.h"
#include "device/device.h"
#include "render/film.h"
#include "base/status.h"

#define CHECKPOINT_KEY_SIZE 32

/* What a checkpoint belongs to: the key and the settings in clear decide the samples;
 * spp is how many of them the complete render has. */
typedef struct {
    unsigned char key[CHECKPOINT_KEY_SIZE];
    uint width, height, spp, seed, max_depth;
} CheckpointId;

/* The denoiser's inputs a part (--sample-range A:B) rendered with --denoise carries
 * (format version 4), so that `clpt merge --denoise` denoises as one process would:
 * the albedo and normal features and, for an image whose directly seen emission is
 * left out of the denoiser (passes_emission_splits), the emission of the part's own
 * samples and of its share of the emission added back (PASSES_EMISSION_SPP_FACTOR
 * times as many samples). Each is a film of its own samples: integer sums add up
 * across parts exactly as the image's do. */
enum {
    CKPT_FEATURE_ALBEDO,
    CKPT_FEATURE_NORMAL,          /* as passes_aov_data renders it: (n + 1) / 2, misses 1/2 */
    CKPT_FEATURE_EMISSION,        /* samples [A, B) */
    CKPT_FEATURE_EMISSION_MORE,   /* samples [4A, 4B) of the 4x emission image */
    CKPT_FEATURES_MAX
};

typedef struct {
    CheckpointId id;
    Film film;            /* sums and samples per pixel */
    /* a --denoise part's (version 4): 2 films (albedo, normal) or all 4, rendered for
     * features_spp samples per pixel in all (the albedo and normal's pixel grid follows
     * it); n_features 0 otherwise */
    Film features[CKPT_FEATURES_MAX];
    uint n_features, features_spp;
    Batch *done;          /* the sample ranges in the film: sorted, disjoint */
    size_t n_done;
    /* an adaptive render's (--noise-threshold; adaptive.h): the odd samples' sums and
     * each pixel's count, and the settings that decided them; NULL/0 otherwise. The
     * film then holds samples [0, film.samples) of the pixels still rendering. */
    int64_t *odd;
    uint *pixel_spp;
    AdaptiveSettings adaptive;
} Checkpoint;

/* The identity of the render of `ds` with `spp` samples per pixel. */
void checkpoint_id(const DeviceScene *ds, uint spp, CheckpointId *id);

/* Writes the film and its sample ranges to `path`, atomically. ST_IO naming the path and
 * the failed step when it cannot be written. */
Status checkpoint_write(const char *path, const CheckpointId *id, const Film *film, const Batch *done,
                        size_t n_done, Error *err);

/* The same with a --denoise part's features (n_features 2 or 4, for features_spp samples
 * per pixel in all): format version 4. */
Status checkpoint_write_features(const char *path, const CheckpointId *id, const Film *film, const Batch *done,
                                 size_t n_done, const Film *features, uint n_features, uint features_spp, Error *err);

/* The same for an adaptive render's state (a format version of its own). */
Status checkpoint_write_adaptive(const char *path, const CheckpointId *id, const AdaptiveFilm *af,
                                 const AdaptiveSettings *s, Error *err);

/* ST_INPUT unless `c` and this render agree on adaptive sampling: both without, or
 * both with the same threshold and minimum (`s` NULL: this render has none). */
Status checkpoint_check_adaptive(const Checkpoint *c, const char *path, const AdaptiveSettings *s, Error *err);

/* Reads and validates a checkpoint: ST_IO when it cannot be read, ST_INPUT when it is not
 * a checkpoint, of an unknown version, truncated, corrupt (checksum) or inconsistent.
 * Free with checkpoint_free (also after a failure). */
Status checkpoint_read(const char *path, Checkpoint *c, Error *err);

/* 0 when `got` and `expected` draw the same samples (one render, perhaps of other
 * samples per pixel); else 1, with the first difference in words in `what`, `other`
 * naming the expected one ("this render": "its seed is 2, this render's 1"). */
int checkpoint_id_differs(const CheckpointId *got, const CheckpointId *expected, const char *other, char *what,
                          size_t size);

/* ST_INPUT, naming the first difference, unless `c` belongs to the render `expected`
 * with as many samples per pixel or fewer (a resume may add samples, not remove them). */
Status checkpoint_check(const Checkpoint *c, const char *path, const CheckpointId *expected, Error *err);

void checkpoint_free(Checkpoint *c);

#endif /* CLPT_CHECKPOINT_H */
