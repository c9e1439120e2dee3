/* checkpoint.c — see checkpoint.h; the file format is documented in docs/checkpoint.md. */
#include "render/checkpoint.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/bytes.h"
#include "base/limit.h"
#include "device/kernel_source.h"
#include "base/sha256.h"
#include "render/passes.h"

#define CKPT_MAGIC "CLPTCKPT"
/* Version 2: the render key no longer covers the samples per pixel (a render can grow:
 * docs/checkpoint.md); the layout is version 1's. */
#define CKPT_VERSION 2u
/* Version 3: an adaptive render's (--noise-threshold): version 2's, its settings in the
 * header and, after the film, the odd samples' sums and each pixel's sample count.
 * Written only for those, so that version 2 readers still read every other render. */
#define CKPT_VERSION_ADAPTIVE 3u
/* Version 4: a part rendered with --denoise (checkpoint.h, CKPT_FEATURE_*): version 2's,
 * the number of feature films and the samples per pixel they were rendered for in the
 * header, and after the film each feature film as its sample count and its sums.
 * Written only for those parts. */
#define CKPT_VERSION_FEATURES 4u
#define CKPT_HEADER_SIZE 128u
#define CKPT_TRAILER_SIZE SHA256_DIGEST_SIZE

/* ------------------------------------------------------------------ render key */

static void hash_part(Sha256 *h, const char *name, const void *data, size_t bytes)
{
    /* name and length first, so that no two different scenes hash the same bytes */
    uint64_t n = bytes;
    sha256_update(h, name, strlen(name) + 1);
    sha256_update(h, &n, sizeof n);
    if (bytes) sha256_update(h, data, bytes);
}

void checkpoint_id(const DeviceScene *ds, uint spp, CheckpointId *id)
{
    const RenderParams *p = &ds->params;
    Sha256 h;
    sha256_init(&h);
    hash_part(&h, "clpt render key 3", NULL, 0);
    /* The kernels decide every bit of a sample: a clpt with other kernels must not add
     * its samples to this film. The samples per pixel are not hashed: a sample is a pure
     * function of (seed, pixel, sample index, ...) and not of how many the render asks
     * for (the whitted integrator's pixel grid, which does follow the count, is in the
     * params block), so a render of N samples is the first N of one of more samples and
     * a resume or merge may grow it (docs/checkpoint.md, "Adding samples"). */
    hash_part(&h, "kernels", clpt_kernel_source, clpt_kernel_source_len);
    /* every scene buffer of kernels/scene_buffers.h, the params block first: a buffer
     * added to that list is part of the key without a change here */
    for (unsigned i = 0; i < SCENE_BUF_COUNT; i++) {
        SceneBufferBytes b = device_scene_buffer(ds, i);
        hash_part(&h, b.what, b.data, b.bytes);
    }
    memset(id, 0, sizeof *id);
    sha256_final(&h, id->key);
    id->width = p->width;
    id->height = p->height;
    id->spp = spp;
    id->seed = p->seed;
    id->max_depth = p->max_depth;
}

/* ------------------------------------------------------------------ writing */

/* The checkpoint file being written, with the hash of its payload as it goes (for the
 * trailer). */
typedef struct {
    AtomicFile af;
    Sha256 hash;
} CheckpointOut;

static void out_put(CheckpointOut *o, const void *data, size_t n, int hashed)
{
    if (hashed) sha256_update(&o->hash, data, n);
    atomic_write(&o->af, data, n);
}

static void out_values(CheckpointOut *o, const int64_t *v, size_t n)
{
    unsigned char chunk[4096 * 8];
    for (size_t i = 0; i < n && !o->af.failed_step;) {
        size_t k = 0;
        for (; k < 4096 && i < n; k++, i++) bytes_put_le64(chunk + 8 * k, (uint64_t)v[i]);
        out_put(o, chunk, 8 * k, 1);
    }
}

static void out_counts(CheckpointOut *o, const uint *v, size_t n)
{
    unsigned char chunk[4096 * 4];
    for (size_t i = 0; i < n && !o->af.failed_step;) {
        size_t k = 0;
        for (; k < 4096 && i < n; k++, i++) bytes_put_le32(chunk + 4 * k, v[i]);
        out_put(o, chunk, 4 * k, 1);
    }
}

/* What a version-4 file adds: the feature films of a --denoise part. */
typedef struct {
    const Film *films;
    uint n, spp;
} FeatureFilms;

/* One checkpoint file; `af` (with `as`) adds an adaptive render's state, `ff` a --denoise
 * part's features. */
static Status write_file(const char *path, const CheckpointId *id, const Film *film, const Batch *done,
                         size_t n_done, const AdaptiveFilm *af, const AdaptiveSettings *as, const FeatureFilms *ff,
                         Error *err)
{
    CheckpointOut o;
    Status st = atomic_open(&o.af, path, "checkpoint", err);
    if (st) return st;
    sha256_init(&o.hash);

    size_t n_values = (size_t)film->width * film->height * 3u;
    size_t n_pixels = (size_t)film->width * film->height;
    uint64_t payload = (uint64_t)n_done * 8u + (uint64_t)n_values * 8u;
    if (af) payload += (uint64_t)n_values * 8u + (uint64_t)n_pixels * 4u;
    if (ff) payload += (uint64_t)ff->n * (8u + (uint64_t)n_values * 8u);
    unsigned char header[CKPT_HEADER_SIZE];
    memset(header, 0, sizeof header);
    memcpy(header, CKPT_MAGIC, 8);
    bytes_put_le32(header + 8, af ? CKPT_VERSION_ADAPTIVE : ff ? CKPT_VERSION_FEATURES : CKPT_VERSION);
    bytes_put_le32(header + 12, CKPT_HEADER_SIZE);
    memcpy(header + 16, id->key, CHECKPOINT_KEY_SIZE);
    bytes_put_le32(header + 48, id->width);
    bytes_put_le32(header + 52, id->height);
    bytes_put_le32(header + 56, id->spp);
    bytes_put_le32(header + 60, id->seed);
    bytes_put_le32(header + 64, id->max_depth);
    bytes_put_le32(header + 68, (uint32_t)n_done);
    bytes_put_le64(header + 72, film->samples);
    bytes_put_le64(header + 80, payload);
    if (af) {
        uint64_t bits;
        memcpy(&bits, &as->threshold, sizeof bits);
        bytes_put_le64(header + 88, bits);
        bytes_put_le32(header + 96, as->min_spp);
    }
    if (ff) {
        bytes_put_le32(header + 88, ff->n);
        bytes_put_le32(header + 92, ff->spp);
    }
    out_put(&o, header, sizeof header, 1);
    for (size_t i = 0; i < n_done; i++) {
        unsigned char r[8];
        bytes_put_le32(r, done[i].first);
        bytes_put_le32(r + 4, done[i].count);
        out_put(&o, r, sizeof r, 1);
    }
    out_values(&o, film->sum, n_values);
    if (af) {
        out_values(&o, af->odd, n_values);
        out_counts(&o, af->spp, n_pixels);
    }
    for (uint k = 0; ff && k < ff->n; k++) {
        unsigned char count[8];
        bytes_put_le64(count, ff->films[k].samples);
        out_put(&o, count, sizeof count, 1);
        out_values(&o, ff->films[k].sum, n_values);
    }
    unsigned char digest[SHA256_DIGEST_SIZE];
    sha256_final(&o.hash, digest);
    out_put(&o, digest, sizeof digest, 0);
    return atomic_commit(&o.af, err);
}

Status checkpoint_write(const char *path, const CheckpointId *id, const Film *film, const Batch *done,
                        size_t n_done, Error *err)
{
    return write_file(path, id, film, done, n_done, NULL, NULL, NULL, err);
}

Status checkpoint_write_features(const char *path, const CheckpointId *id, const Film *film, const Batch *done,
                                 size_t n_done, const Film *features, uint n_features, uint features_spp, Error *err)
{
    FeatureFilms ff = { features, n_features, features_spp };
    return write_file(path, id, film, done, n_done, NULL, NULL, &ff, err);
}

Status checkpoint_write_adaptive(const char *path, const CheckpointId *id, const AdaptiveFilm *af,
                                 const AdaptiveSettings *s, Error *err)
{
    /* the pixels still rendering hold samples [0, film.samples); the others fewer,
     * which their counts say */
    Batch all = { 0, (uint)af->film.samples };
    return write_file(path, id, &af->film, &all, all.count ? 1 : 0, af, s, NULL, err);
}

/* ------------------------------------------------------------------ reading */

void checkpoint_free(Checkpoint *c)
{
    film_free(&c->film);
    free(c->done);
    free(c->odd);
    free(c->pixel_spp);
    for (uint k = 0; k < CKPT_FEATURES_MAX; k++) film_free(&c->features[k]);
    memset(c, 0, sizeof *c);
}

static Status bad(Error *err, const char *path, const char *what)
{
    return error_set(err, ST_INPUT, "'%s' is not a usable clpt checkpoint: %s", path, what);
}

/* The largest film value one sample can add: the kernels clamp a sample's radiance to
 * FILM_MAX_SAMPLE and round it to units of 2^-FILM_FRAC_BITS (kernels/film/film.h). */
#define FILM_MAX_SAMPLE_FIXED ((uint64_t)FILM_MAX_SAMPLE << FILM_FRAC_BITS)

/* Each value must be one that `samples` samples can produce: between 0 and samples
 * times the largest sample. A crafted file could otherwise start the film near
 * INT64_MAX, and the further batches of the resume would overflow the signed sums
 * (undefined behaviour; negative pixels in practice). With samples <= CLPT_MAX_SPP
 * (< 2^20) and the largest sample 2^40, every film stays below 2^60, whatever is
 * resumed and added. */
static Status read_film_values(const unsigned char *p, uint64_t n_values, uint64_t samples, const char *path,
                               int64_t *sum, Error *err)
{
    uint64_t max = samples * FILM_MAX_SAMPLE_FIXED;
    for (uint64_t i = 0; i < n_values; i++, p += 8) {
        uint64_t v = bytes_get_le64(p);
        if (v > max) {
            char msg[256];
            uint64_t pixel = i / 3u;
            snprintf(msg, sizeof msg, "film value %s%llu of pixel %llu is outside what %llu samples can hold "
                     "(0..%llu)", v >> 63 ? "-" : "", (unsigned long long)(v >> 63 ? -v : v),
                     (unsigned long long)pixel, (unsigned long long)samples, (unsigned long long)max);
            return bad(err, path, msg);
        }
        sum[i] = (int64_t)v;
    }
    return ST_OK;
}

/* An adaptive render's part (version 3): its settings from the header, then the odd
 * sums (each between 0 and its pixel's whole sum) and the counts (none past the film's;
 * the pixels at it hold samples [0, count), whose record must say so). */
static Status read_adaptive(const unsigned char *header, const unsigned char *p, const char *path, Checkpoint *c,
                            Error *err)
{
    uint64_t bits = bytes_get_le64(header + 88);
    memcpy(&c->adaptive.threshold, &bits, sizeof bits);
    c->adaptive.min_spp = bytes_get_le32(header + 96);
    if (!(c->adaptive.threshold > 0.0 && c->adaptive.threshold <= 1.0) || c->adaptive.min_spp < 2u)
        return bad(err, path, "inconsistent adaptive sampling settings");
    if (c->n_done > 1 || (c->n_done == 1 && c->done[0].first != 0))
        return bad(err, path, "inconsistent sample ranges");
    size_t n_pixels = (size_t)c->film.width * c->film.height;
    c->odd = malloc(n_pixels * 3u * sizeof *c->odd);
    c->pixel_spp = malloc(n_pixels * sizeof *c->pixel_spp);
    if (!c->odd || !c->pixel_spp) return error_set(err, ST_INTERNAL, "out of memory reading checkpoint '%s'", path);
    for (size_t i = 0; i < n_pixels * 3u; i++, p += 8) {
        uint64_t v = bytes_get_le64(p);
        if (v > (uint64_t)c->film.sum[i]) return bad(err, path, "inconsistent odd-sample sums");
        c->odd[i] = (int64_t)v;
    }
    for (size_t i = 0; i < n_pixels; i++, p += 4)
        if ((c->pixel_spp[i] = bytes_get_le32(p)) > c->film.samples) return bad(err, path, "inconsistent pixel counts");
    return ST_OK;
}

/* A --denoise part's feature films (version 4): each one's sample count, then its sums,
 * each bounded by that count as the film's are. The albedo, normal and emission hold
 * the part's own samples; the emission added back PASSES_EMISSION_SPP_FACTOR times as
 * many. */
static Status read_features(const unsigned char *p, uint64_t n_values, const char *path, Checkpoint *c, Error *err)
{
    for (uint k = 0; k < c->n_features; k++) {
        uint64_t samples = bytes_get_le64(p);
        uint64_t expected = k == CKPT_FEATURE_EMISSION_MORE ? PASSES_EMISSION_SPP_FACTOR * c->film.samples
                                                            : c->film.samples;
        if (samples != expected) return bad(err, path, "inconsistent feature sample counts");
        Film *f = &c->features[k];
        Status st = film_init(f, c->film.width, c->film.height, err);
        if (st) return st;
        f->samples = samples;
        if ((st = read_film_values(p + 8, n_values, samples, path, f->sum, err))) return st;
        p += 8u + n_values * 8u;
    }
    return ST_OK;
}

Status checkpoint_read(const char *path, Checkpoint *c, Error *err)
{
    memset(c, 0, sizeof *c);
    /* Opened without blocking, so that a FIFO named by --resume is refused below instead
     * of waiting for a writer that never comes. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    FILE *f = fd >= 0 ? fdopen(fd, "rb") : NULL;
    if (!f) {
        Status io = error_set(err, ST_IO, "cannot read checkpoint '%s': %s", path, strerror(errno));
        if (fd >= 0) close(fd);
        return io;
    }
    Status st = ST_OK;
    unsigned char *data = NULL;
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0 || !S_ISREG(sb.st_mode)) {
        st = error_set(err, ST_IO, "cannot read checkpoint '%s': not a regular file", path);
        goto out;
    }
    /* Everything is checked against the file's size before anything is allocated from
     * the header's counts. */
    uint64_t size = (uint64_t)sb.st_size;
    if (size < CKPT_HEADER_SIZE + CKPT_TRAILER_SIZE) {
        st = bad(err, path, size >= 8 ? "truncated (shorter than its header)" : "too short to be one");
        goto out;
    }
    if (size > SIZE_MAX || !(data = malloc((size_t)size))) {
        st = error_set(err, ST_INTERNAL, "out of memory reading checkpoint '%s' (%llu bytes)", path,
                       (unsigned long long)size);
        goto out;
    }
    if (fread(data, 1, (size_t)size, f) != (size_t)size) {
        st = error_set(err, ST_IO, "cannot read checkpoint '%s': %s", path, ferror(f) ? strerror(errno) : "short read");
        goto out;
    }
    if (memcmp(data, CKPT_MAGIC, 8) != 0) {
        st = bad(err, path, "wrong magic (not a checkpoint file)");
        goto out;
    }
    uint32_t version = bytes_get_le32(data + 8);
    if (version != CKPT_VERSION && version != CKPT_VERSION_ADAPTIVE && version != CKPT_VERSION_FEATURES) {
        char msg[128];
        snprintf(msg, sizeof msg, "format version %u, this clpt reads versions %u to %u", version, CKPT_VERSION,
                 CKPT_VERSION_FEATURES);
        st = bad(err, path, msg);
        goto out;
    }
    uint64_t payload = bytes_get_le64(data + 80);
    if (bytes_get_le32(data + 12) != CKPT_HEADER_SIZE || payload != size - CKPT_HEADER_SIZE - CKPT_TRAILER_SIZE) {
        st = bad(err, path, "truncated or extended (its size does not match its header)");
        goto out;
    }
    unsigned char digest[SHA256_DIGEST_SIZE];
    sha256(data, (size_t)(size - CKPT_TRAILER_SIZE), digest);
    if (memcmp(digest, data + size - CKPT_TRAILER_SIZE, SHA256_DIGEST_SIZE) != 0) {
        st = bad(err, path, "corrupt (checksum mismatch)");
        goto out;
    }
    CheckpointId *id = &c->id;
    memcpy(id->key, data + 16, CHECKPOINT_KEY_SIZE);
    id->width = bytes_get_le32(data + 48);
    id->height = bytes_get_le32(data + 52);
    id->spp = bytes_get_le32(data + 56);
    id->seed = bytes_get_le32(data + 60);
    id->max_depth = bytes_get_le32(data + 64);
    uint32_t n_done = bytes_get_le32(data + 68);
    uint64_t samples = bytes_get_le64(data + 72);
    uint64_t n_values = (uint64_t)id->width * id->height * 3u;
    int adaptive = version == CKPT_VERSION_ADAPTIVE;
    uint64_t extra = adaptive ? n_values * 8u + (n_values / 3u) * 4u : 0u;
    if (version == CKPT_VERSION_FEATURES) {
        c->n_features = bytes_get_le32(data + 88);
        c->features_spp = bytes_get_le32(data + 92);
        if ((c->n_features != 2u && c->n_features != CKPT_FEATURES_MAX) || c->features_spp != id->spp) {
            st = bad(err, path, "inconsistent header (denoiser features)");
            goto out;
        }
        extra = (uint64_t)c->n_features * (8u + n_values * 8u);
    }
    if (id->width == 0 || id->height == 0 || payload != (uint64_t)n_done * 8u + n_values * 8u + extra) {
        st = bad(err, path, "inconsistent header (image size and payload disagree)");
        goto out;
    }
    /* No render asks for more; the bound on the film values below relies on it. */
    if (id->spp == 0 || id->spp > CLPT_MAX_SPP) {
        st = bad(err, path, "inconsistent header (samples per pixel outside 1.." CLPT_STR(CLPT_MAX_SPP) ")");
        goto out;
    }
    if ((st = film_init(&c->film, id->width, id->height, err))) goto out;
    c->done = malloc((n_done ? n_done : 1) * sizeof *c->done);
    if (!c->done) {
        st = error_set(err, ST_INTERNAL, "out of memory reading checkpoint '%s'", path);
        goto out;
    }
    const unsigned char *p = data + CKPT_HEADER_SIZE;
    uint64_t total = 0, end = 0;
    for (uint32_t i = 0; i < n_done; i++, p += 8) {
        Batch b = { bytes_get_le32(p), bytes_get_le32(p + 4) };
        /* sorted, disjoint, non-empty and within the render's samples */
        if (b.count == 0 || b.first < end || (uint64_t)b.first + b.count > id->spp) {
            st = bad(err, path, "inconsistent sample ranges");
            goto out;
        }
        end = (uint64_t)b.first + b.count;
        total += b.count;
        c->done[i] = b;
    }
    c->n_done = n_done;
    if (total != samples) {
        st = bad(err, path, "inconsistent sample count");
        goto out;
    }
    c->film.samples = samples;
    if ((st = read_film_values(p, n_values, samples, path, c->film.sum, err))) goto out;
    if (adaptive) st = read_adaptive(data, p + n_values * 8u, path, c, err);
    if (c->n_features) st = read_features(p + n_values * 8u, n_values, path, c, err);

out:
    free(data);
    fclose(f);
    return st;
}

int checkpoint_id_differs(const CheckpointId *g, const CheckpointId *e, const char *other, char *what, size_t size)
{
    if (g->width != e->width || g->height != e->height)
        snprintf(what, size, "it is %ux%u pixels, %s %ux%u", g->width, g->height, other, e->width, e->height);
    else if (g->seed != e->seed)
        snprintf(what, size, "its seed is %u, %s's %u", g->seed, other, e->seed);
    else if (g->max_depth != e->max_depth)
        snprintf(what, size, "its maximum depth is %u, %s's %u", g->max_depth, other, e->max_depth);
    else if (memcmp(g->key, e->key, CHECKPOINT_KEY_SIZE) != 0)
        snprintf(what, size, "the scene differs (geometry, materials, camera or lights, or the "
                             "sampler, shadows or --accel setting), or it was made by a clpt with other kernels");
    else
        return 0;
    return 1;
}

Status checkpoint_check(const Checkpoint *c, const char *path, const CheckpointId *e, Error *err)
{
    char what[256];
    if (checkpoint_id_differs(&c->id, e, "this render", what, sizeof what))
        return error_set(err, ST_INPUT,
                         "checkpoint '%s' belongs to another render: %s; refusing to resume (resume with the scene "
                         "and settings it was made with, or start afresh without --resume)", path, what);
    /* more samples extend the render; fewer would leave samples of the film unasked for */
    if (c->id.spp > e->spp)
        return error_set(err, ST_INPUT,
                         "checkpoint '%s' is a render of %u samples per pixel, this render asks for %u; a resume can "
                         "add samples, never take them away (resume with --spp %u or more)", path, c->id.spp, e->spp,
                         c->id.spp);
    return ST_OK;
}

Status checkpoint_check_adaptive(const Checkpoint *c, const char *path, const AdaptiveSettings *s, Error *err)
{
    const AdaptiveSettings *had = c->pixel_spp ? &c->adaptive : NULL;
    if (!had && !s) return ST_OK;
    if (!had)
        return error_set(err, ST_INPUT, "checkpoint '%s' is not an adaptive render (it was made without "
                         "--noise-threshold); resume it without --noise-threshold, or start afresh", path);
    if (!s)
        return error_set(err, ST_INPUT, "checkpoint '%s' is an adaptive render (--noise-threshold %g --min-spp %u); "
                         "resume it with those settings", path, had->threshold, had->min_spp);
    if (had->threshold != s->threshold || had->min_spp != s->min_spp)
        return error_set(err, ST_INPUT, "checkpoint '%s' is an adaptive render with --noise-threshold %g --min-spp "
                         "%u, this render asks for --noise-threshold %g --min-spp %u; resume it with its settings",
                         path, had->threshold, had->min_spp, s->threshold, s->min_spp);
    return ST_OK;
}
