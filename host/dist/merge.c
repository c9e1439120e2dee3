/* merge.c — see merge.h. */
#include "dist/merge.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/atomic_file.h"
#include "base/file_id.h"
#include "io/image_write.h"
#include "render/denoise.h"
#include "render/passes.h"
#include "scene/scene.h"

/* One sample range and the part it came from, for the overlap and gap checks. */
typedef struct {
    Batch b;
    size_t part;
} PartRange;

static int cmp_part_range(const void *x, const void *y)
{
    uint a = ((const PartRange *)x)->b.first, b = ((const PartRange *)y)->b.first;
    return (a > b) - (a < b);
}

/* Adds part `c` (read from paths[k]) into `out`, after checking it is the same render. */
static Status merge_add(Checkpoint *out, const Checkpoint *c, const char *const *paths, size_t k, Error *err)
{
    char what[256];
    if (checkpoint_id_differs(&c->id, &out->id, "the first part", what, sizeof what))
        return error_set(err, ST_INPUT, "cannot merge '%s' with '%s': they are parts of different renders (%s)%s",
                         paths[k], paths[0], what,
                         c->id.spp != out->id.spp ? "; a whitted render's pixel grid follows its samples per pixel, "
                                                    "so it grows only between counts with the same grid" : "");
    if (c->n_features != out->n_features || c->features_spp != out->features_spp) {
        const char *with = c->n_features ? paths[k] : paths[0], *without = c->n_features ? paths[0] : paths[k];
        if (c->n_features && out->n_features)
            return error_set(err, ST_INPUT, "cannot merge '%s' with '%s': their denoiser features were rendered for "
                             "%u and %u samples per pixel; render every part with the same --spp", paths[k],
                             paths[0], c->features_spp, out->features_spp);
        return error_set(err, ST_INPUT, "cannot merge '%s' with '%s': '%s' holds the denoiser's features (a part "
                         "rendered with --denoise) and '%s' does not; render every part with --denoise, or none",
                         paths[k], paths[0], with, without);
    }
    size_t n = (size_t)out->film.width * out->film.height * 3u;
    for (uint f = 0; f < c->n_features; f++) {
        for (size_t i = 0; i < n; i++) out->features[f].sum[i] += c->features[f].sum[i];
        out->features[f].samples += c->features[f].samples;
    }
    /* Each part's values are bounded by its samples (checkpoint_read), and the parts'
     * samples add up to at most spp (checked after), so the sums cannot overflow. */
    for (size_t i = 0; i < n; i++) out->film.sum[i] += c->film.sum[i];
    out->film.samples += c->film.samples;
    /* parts of one render whose total grew (a finished render of 4 spp and the part
     * 4:16 of the render of 16): the merged render is the largest, and every sample of
     * it must then come from some part (merge_check_ranges) */
    if (c->id.spp > out->id.spp) out->id.spp = c->id.spp;
    return ST_OK;
}

/* The ranges of all parts, sorted: any overlap names the two parts, any gap the samples
 * missing. On success *out holds their union, [0, spp) as one range. */
static Status merge_check_ranges(PartRange *r, size_t n, const char *const *paths, uint spp, Checkpoint *out,
                                 Error *err)
{
    qsort(r, n, sizeof *r, cmp_part_range);
    uint at = 0;
    for (size_t i = 0; i < n; i++) {
        if (r[i].b.first < at) {
            const PartRange *p = &r[i - 1];
            uint lo = r[i].b.first, hi = at < r[i].b.first + r[i].b.count ? at : r[i].b.first + r[i].b.count;
            return error_set(err, ST_INPUT, "cannot merge: '%s' and '%s' both hold samples [%u,%u); each sample "
                             "must come from one part", paths[p->part], paths[r[i].part], lo, hi);
        }
        if (r[i].b.first > at)
            return error_set(err, ST_INPUT, "cannot merge: no part holds samples [%u,%u) of the %u per pixel; "
                             "render them with --sample-range %u:%u and merge that part too",
                             at, r[i].b.first, spp, at, r[i].b.first);
        at = r[i].b.first + r[i].b.count;
    }
    if (at < spp)
        return error_set(err, ST_INPUT, "cannot merge: no part holds samples [%u,%u) of the %u per pixel; "
                         "render them with --sample-range %u:%u and merge that part too", at, spp, spp, at, spp);
    free(out->done);
    if (!(out->done = malloc(sizeof *out->done))) return error_set(err, ST_INTERNAL, "out of memory merging");
    out->done[0] = (Batch){ 0, spp };
    out->n_done = 1;
    return ST_OK;
}

/* Appends part k's ranges to the list of all ranges. */
static Status merge_note_ranges(const Checkpoint *c, size_t k, PartRange **r, size_t *n, size_t *cap, Error *err)
{
    if (array_reserve((void **)r, cap, *n + c->n_done, sizeof **r))
        return error_set(err, ST_INTERNAL, "out of memory merging");
    for (size_t i = 0; i < c->n_done; i++) (*r)[(*n)++] = (PartRange){ c->done[i], k };
    return ST_OK;
}

/* An adaptive render (--noise-threshold) is no part: its pixels stopped at counts that
 * the whole film decided, so it is never split into sample ranges. */
static Status merge_refuse_adaptive(const Checkpoint *c, const char *path, Error *err)
{
    if (!c->pixel_spp) return ST_OK;
    return error_set(err, ST_INPUT, "cannot merge '%s': it is an adaptive render (--noise-threshold), whose pixels "
                     "hold samples of their own counts; resume it with --resume instead", path);
}

/* Without --denoise a part's features are not needed: dropped, so that parts with and
 * without them merge. */
static void merge_drop_features(Checkpoint *c)
{
    for (uint k = 0; k < CKPT_FEATURES_MAX; k++) film_free(&c->features[k]);
    c->n_features = c->features_spp = 0;
}

Status merge_parts(const char *const *paths, size_t n, int features, Checkpoint *out, Error *err)
{
    memset(out, 0, sizeof *out);
    if (n == 0) return error_set(err, ST_USAGE, "merge needs at least one PART");
    PartRange *ranges = NULL;
    size_t n_ranges = 0, cap = 0;
    Status st = checkpoint_read(paths[0], out, err);
    if (!features) merge_drop_features(out);
    if (st == ST_OK) st = merge_refuse_adaptive(out, paths[0], err);
    if (st == ST_OK) st = merge_note_ranges(out, 0, &ranges, &n_ranges, &cap, err);
    for (size_t k = 1; k < n && st == ST_OK; k++) {
        Checkpoint c;
        st = checkpoint_read(paths[k], &c, err);
        if (!features) merge_drop_features(&c);
        if (st == ST_OK) st = merge_refuse_adaptive(&c, paths[k], err);
        if (st == ST_OK) st = merge_add(out, &c, paths, k, err);
        if (st == ST_OK) st = merge_note_ranges(&c, k, &ranges, &n_ranges, &cap, err);
        checkpoint_free(&c);
    }
    if (st == ST_OK) st = merge_check_ranges(ranges, n_ranges, paths, out->id.spp, out, err);
    free(ranges);
    return st;
}

/* ------------------------------------------------------------------ command */

typedef struct {
    const char *output, *checkpoint;
    int linear, quiet;
    ViewLook look;                /* --view, --exposure, as a render's */
    int denoise;                  /* --denoise: with the parts' features, else the colour alone */
    const char **parts;
    size_t n_parts;
} MergeOptions;

/* --view NAME or --exposure EV, read as the render's flags are. */
static Status merge_parse_look(const char *flag, const char *v, ViewLook *look, Error *err)
{
    if (!strcmp(flag, "--exposure")) {
        char *end;
        double ev = strtod(v, &end);
        if (*end || isspace((unsigned char)v[0]) || !(ev >= -32.0 && ev <= 32.0))
            return error_set(err, ST_USAGE, "merge: --exposure expects a number of stops from -32 to 32, got '%s'", v);
        look->exposure = ev;
        return ST_OK;
    }
    for (int k = VIEW_STANDARD; k <= VIEW_FILMIC; k++)
        if (!strcmp(v, view_name((ViewTransform)k))) {
            look->view = (ViewTransform)k;
            return ST_OK;
        }
    return error_set(err, ST_USAGE, "merge: --view expects 'standard', 'agx' or 'filmic', got '%s'", v);
}

static Status merge_parse(int argc, char **argv, MergeOptions *m, Error *err)
{
    memset(m, 0, sizeof *m);
    if (!(m->parts = calloc((size_t)argc, sizeof *m->parts))) return error_set(err, ST_INTERNAL, "out of memory");
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int takes_value = !strcmp(a, "-o") || !strcmp(a, "--output") || !strcmp(a, "--checkpoint") ||
                          !strcmp(a, "--gamma") || !strcmp(a, "--view") || !strcmp(a, "--exposure");
        if (takes_value && (i + 1 >= argc || !argv[i + 1][0]))
            return error_set(err, ST_USAGE, "merge: %s needs a value", a);
        if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            m->output = argv[++i];
        } else if (!strcmp(a, "--checkpoint")) {
            m->checkpoint = argv[++i];
        } else if (!strcmp(a, "--gamma")) {
            const char *v = argv[++i];
            if (strcmp(v, "srgb") != 0 && strcmp(v, "none") != 0)
                return error_set(err, ST_USAGE, "merge: --gamma expects 'srgb' or 'none', got '%s'", v);
            m->linear = !strcmp(v, "none");
        } else if (!strcmp(a, "--view") || !strcmp(a, "--exposure")) {
            Status st = merge_parse_look(a, argv[++i], &m->look, err);
            if (st) return st;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            m->quiet = 1;
        } else if (!strcmp(a, "--denoise")) {
            m->denoise = 1;
        } else if (a[0] == '-' && a[1]) {
            return error_set(err, ST_USAGE, "merge: unknown option '%s' (usage: clpt merge -o OUT PART...)", a);
        } else {
            m->parts[m->n_parts++] = a;
        }
    }
    if (!m->output) return error_set(err, ST_USAGE, "merge needs -o OUT (usage: clpt merge -o OUT PART...)");
    if (m->n_parts == 0) return error_set(err, ST_USAGE, "merge needs at least one PART (usage: clpt merge -o OUT PART...)");
    return ST_OK;
}

/* The image and the checkpoint written must be neither one of the parts (writing it
 * would destroy that part: `merge -o p2.pfm p1.ckpt p2.pfm` lost p2) nor each other.
 * Compared as files (device and inode), so a link or "./p2" is caught too. */
static Status merge_check_outputs(const MergeOptions *m, Error *err)
{
    FileId out, ck, part;
    file_id_init(&out, m->output);
    if (m->checkpoint) {
        file_id_init(&ck, m->checkpoint);
        if (file_id_same(&out, &ck))
            return error_set(err, ST_USAGE, "merge: the output image '%s' and the checkpoint '%s' are the same file; "
                             "give each its own name", m->output, m->checkpoint);
    }
    for (size_t k = 0; k < m->n_parts; k++) {
        file_id_init(&part, m->parts[k]);
        const char *what = NULL, *path = NULL;
        if (file_id_same(&out, &part)) what = "output image", path = m->output;
        else if (m->checkpoint && file_id_same(&ck, &part)) what = "checkpoint", path = m->checkpoint;
        if (what)
            return error_set(err, ST_USAGE, "merge: the %s '%s' is the part '%s': writing it would destroy that "
                             "part; give the %s another name", what, path, m->parts[k], what);
    }
    return ST_OK;
}

/* --denoise: the merged image through Open Image Denoise. Parts rendered with --denoise
 * hold the denoiser's inputs for their samples (checkpoint.h, CKPT_FEATURE_*): added up,
 * they are the films one process renders, resolved and denoised by the same functions
 * (passes_resolve_data, passes_denoise_split), so the image is that process's, bit for
 * bit. Parts without them get the colour alone, as before. An EXR keeps what the
 * denoiser saw as channels, as a render's does. */
static Status merge_write_denoised(const MergeOptions *m, Denoiser *dn, const Checkpoint *merged, ImageFormat fmt,
                                   const ImageStyle *style, Error *err)
{
    const Film *film = &merged->film;
    uint w = film->width, h = film->height;
    size_t n = (size_t)w * h * 3u;
    float *noisy = malloc(n * sizeof *noisy), *rgb = malloc(n * sizeof *rgb);
    float *feature[CKPT_FEATURES_MAX] = { NULL, NULL, NULL, NULL };
    static const unsigned mode[CKPT_FEATURES_MAX] = { INTEGRATOR_FEATURE_ALBEDO, INTEGRATOR_FEATURE_NORMAL,
                                                      INTEGRATOR_FEATURE_EMISSION, INTEGRATOR_FEATURE_EMISSION };
    Status st = noisy && rgb ? ST_OK : error_set(err, ST_INTERNAL, "out of memory");
    for (uint k = 0; k < merged->n_features && st == ST_OK; k++) {
        if (!(feature[k] = malloc(n * sizeof *feature[k]))) st = error_set(err, ST_INTERNAL, "out of memory");
        else passes_resolve_data(mode[k], &merged->features[k], feature[k]);
    }
    /* as passes_denoise_emission: nothing seen emitted, the colour whole */
    float *e = feature[CKPT_FEATURE_EMISSION], *more = feature[CKPT_FEATURE_EMISSION_MORE];
    if (e && !passes_emission_lit(e, n)) e = more = NULL;
    if (st == ST_OK) {
        film_resolve(film, noisy);
        st = passes_denoise_split(dn, noisy, feature[CKPT_FEATURE_ALBEDO], feature[CKPT_FEATURE_NORMAL], e, more, w,
                                  h, 0, rgb, err);
    }
    float *aov[3] = { feature[CKPT_FEATURE_NORMAL], NULL, feature[CKPT_FEATURE_ALBEDO] };
    if (st == ST_OK && fmt == IMAGE_EXR) st = passes_write_exr_layers(m->output, rgb, aov, noisy, e, more, w, h, 0, err);
    else if (st == ST_OK)
        st = image_write_styled(m->output, rgb, w, h, style, err);
    free(noisy);
    free(rgb);
    for (uint k = 0; k < CKPT_FEATURES_MAX; k++) free(feature[k]);
    return st;
}

Status merge_command(int argc, char **argv, Error *err)
{
    Denoiser *dn = NULL;
    MergeOptions m;
    Checkpoint merged;
    memset(&merged, 0, sizeof merged);
    ImageFormat fmt;
    Status st = merge_parse(argc, argv, &m, err);
    /* the outputs are checked before the parts are read: a typo costs a second */
    if (st == ST_OK) st = image_format_from_path(m.output, &fmt, err);
    if (st == ST_OK) st = image_check_look(m.output, &m.look, err);
    if (st == ST_OK) st = merge_check_outputs(&m, err);
    if (st == ST_OK) st = atomic_probe(m.output, "", err);
    if (st == ST_OK && m.checkpoint) st = atomic_probe(m.checkpoint, "checkpoint", err);
    if (st == ST_OK && m.denoise) st = denoiser_open(&dn, err);
    if (st == ST_OK) st = merge_parts(m.parts, m.n_parts, m.denoise, &merged, err);
    if (st == ST_OK && m.checkpoint)
        st = merged.n_features ? checkpoint_write_features(m.checkpoint, &merged.id, &merged.film, merged.done,
                                                           merged.n_done, merged.features, merged.n_features,
                                                           merged.features_spp, err)
                               : checkpoint_write(m.checkpoint, &merged.id, &merged.film, merged.done, merged.n_done,
                                                  err);
    ImageStyle style = { m.linear ? IMAGE_LINEAR : IMAGE_SRGB, m.look, 0 };
    if (st == ST_OK && !dn) st = film_write(&merged.film, m.output, &style, err);
    if (st == ST_OK && dn) st = merge_write_denoised(&m, dn, &merged, fmt, &style, err);
    if (st == ST_OK && !m.quiet)
        fprintf(stderr, "clpt: merged %zu part%s: %ux%u, %llu spp%s -> %s\n", m.n_parts, m.n_parts == 1 ? "" : "s",
                merged.film.width, merged.film.height, (unsigned long long)merged.film.samples,
                !dn ? "" : merged.n_features ? ", denoised with the parts' features" : ", denoised (colour alone: the parts "
                "hold no features; render them with --denoise for those)", m.output);
    denoiser_close(dn);
    checkpoint_free(&merged);
    free(m.parts);
    return st;
}
