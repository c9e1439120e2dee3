/* passes.c — the adaptive pass and the auxiliary images (see passes.h). */
#include "render/passes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/timer.h"

/* Gives every device the pass's params block and pixel list (the scene's other buffers
 * stay as loaded), renders samples [first, end) of a render of spp samples per pixel
 * into a new film (end 0: all of them; never the main render's --sample-range, which a
 * pass of another count would fall outside). */
static Status render_pass_range(const PassContext *pc, uint spp, uint first, uint end, Film *film, double *seconds,
                                Error *err)
{
    const DeviceScene *ds = &pc->rs->ds;
    Status st;
    memset(film, 0, sizeof *film);   /* the caller frees it whatever happens */
    if ((st = device_update_all(pc->devices, pc->n_devices, &pc->rs->ds, err))) return st;
    if ((st = film_init(film, ds->params.width, ds->params.height, err))) return st;
    ScheduleConfig cfg = *pc->cfg;
    cfg.spp = spp;
    cfg.range_first = end ? first : 0u;
    cfg.range_end = end;
    cfg.on_tick = NULL;
    cfg.time_limit = 0.0;
    ScheduleStats stats;
    st = schedule_run(pc->devices, pc->n_devices, &cfg, film, &stats, err);
    *seconds += stats.seconds;
    schedule_stats_free(&stats);
    return st;
}

static Status render_pass(const PassContext *pc, uint spp, Film *film, double *seconds, Error *err)
{
    return render_pass_range(pc, spp, 0u, 0u, film, seconds, err);
}

static float clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; }

size_t passes_mark_edges(const float *rgb, uint width, uint height, float threshold, uint *mask)
{
    size_t n = (size_t)width * height;
    memset(mask, 0, n * sizeof *mask);
    for (uint y = 0; y < height; y++)
        for (uint x = 0; x < width; x++) {
            size_t i = (size_t)y * width + x;
            size_t nb[2] = { x + 1 < width ? i + 1 : i, y + 1 < height ? i + width : i };
            for (int k = 0; k < 2; k++) {
                size_t j = nb[k];
                if (j == i) continue;
                for (int c = 0; c < 3; c++) {
                    float d = clamp01(rgb[3 * i + c]) - clamp01(rgb[3 * j + c]);
                    if (d > threshold || -d > threshold) {
                        mask[i] = mask[j] = 1u;
                        break;
                    }
                }
            }
        }
    size_t marked = 0;
    for (size_t i = 0; i < n; i++) marked += mask[i];
    return marked;
}

Status passes_adaptive(const PassContext *pc, float *rgb, uint base_spp, float threshold, uint extra,
                       size_t *marked, double *seconds, Error *err)
{
    RenderParams *p = &pc->rs->ds.params;
    size_t n = (size_t)p->width * p->height;
    *marked = 0;
    *seconds = 0.0;
    uint *mask = malloc(n * sizeof *mask), *list = malloc(n * sizeof *list);
    if (!mask || !list) {
        free(mask);
        free(list);
        return error_set(err, ST_INTERNAL, "out of memory for the adaptive pass");
    }
    *marked = passes_mark_edges(rgb, p->width, p->height, threshold, mask);
    if (*marked == 0) {
        free(mask);
        free(list);
        return ST_OK;
    }
    RenderParams saved = *p;
    /* the pass's batches cover only the marked pixels */
    p->pixel_list_size = render_scene_list_pixels(mask, n, list);
    /* fresh jittered samples: keys after the main pass's, never the pixel centre again */
    p->strata = render_scene_strata(extra) ? render_scene_strata(extra) : 1u;
    p->sample_offset = saved.sample_offset + base_spp;
    pc->rs->ds.pixel_list = list;
    Film film;
    Status st = render_pass(pc, extra, &film, seconds, err);
    *p = saved;
    pc->rs->ds.pixel_list = NULL;
    /* the devices too: none keeps the list freed below */
    Status restored = device_update_all(pc->devices, pc->n_devices, &pc->rs->ds, st == ST_OK ? err : NULL);
    if (st == ST_OK) st = restored;
    if (st == ST_OK && film.samples > 0) {
        float *more = malloc(n * 3 * sizeof *more);
        if (!more) {
            st = error_set(err, ST_INTERNAL, "out of memory for the adaptive pass");
        } else {
            film_resolve(&film, more);
            double wa = (double)base_spp, wb = (double)film.samples;
            for (size_t i = 0; i < n; i++)
                if (mask[i])
                    for (int c = 0; c < 3; c++)
                        rgb[3 * i + c] = (float)((wa * rgb[3 * i + c] + wb * more[3 * i + c]) / (wa + wb));
            free(more);
        }
    }
    film_free(&film);
    free(mask);
    free(list);
    return st;
}

/* Depth samples arrive as (distance, 1, 0) per hit: the resolved pixel is (mean
 * distance x coverage, coverage, 0). See passes.h for the grey scales. */
void passes_depth_grey(float *rgb, size_t n, const DepthScale *scale)
{
    double lo = scale->near, hi = scale->far;
    if (scale->mode == DEPTH_AUTO) {
        int any = 0;
        for (size_t i = 0; i < n; i++) {
            if (!(rgb[3 * i + 1] > 0.0f)) continue;
            double d = (double)rgb[3 * i] / rgb[3 * i + 1];
            if (!any || d < lo) lo = d;
            if (!any || d > hi) hi = d;
            any = 1;
        }
    }
    for (size_t i = 0; i < n; i++) {
        float cover = rgb[3 * i + 1];
        /* A miss is infinitely far: +inf in the float images (PFM, EXR's Z), as
         * compositors expect of a depth pass, and no distance a hit could have (0 was
         * read as "at the camera"). A grey image shows it black, as the farthest. */
        float g = scale->mode == DEPTH_RAW ? INFINITY : 0.0f;
        if (cover > 0.0f) {
            double d = (double)rgb[3 * i] / cover, t = 1.0;
            if (scale->mode == DEPTH_RAW) t = d;
            else if (scale->mode == DEPTH_RANGE) t = hi != lo ? (hi - d) / (hi - lo) : 1.0;   /* lo > hi: inverted */
            else if (hi > lo && d > 0.0) t = (lo / d - lo / hi) / (1.0 - lo / hi);
            if (scale->mode != DEPTH_RAW) t = (t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t)) * cover;
            g = (float)t;
        }
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = g;
    }
}

/* Auxiliary image `aov` with samples [first, end) of `spp` (end 0: all) into *film, the
 * devices given the main render's parameters back after. */
static Status passes__aov_film(const PassContext *pc, uint aov, uint spp, uint first, uint end, Film *film,
                               double *seconds, Error *err)
{
    RenderParams *p = &pc->rs->ds.params;
    RenderParams saved = *p;
    p->integrator = aov;
    p->strata = render_scene_strata(spp);
    Status st = render_pass_range(pc, spp, first, end, film, seconds, err);
    *p = saved;
    Status restored = device_update_all(pc->devices, pc->n_devices, &pc->rs->ds, st == ST_OK ? err : NULL);
    return st == ST_OK ? restored : st;
}

Status passes_aov(const PassContext *pc, uint aov, uint spp, const DepthScale *depth, float *rgb,
                  double *seconds, Error *err)
{
    *seconds = 0.0;
    Film film;
    Status st = passes__aov_film(pc, aov, spp, 0u, 0u, &film, seconds, err);
    if (st == ST_OK) {
        film_resolve(&film, rgb);
        if (aov == INTEGRATOR_AOV_DEPTH) passes_depth_grey(rgb, (size_t)film.width * film.height, depth);
    }
    film_free(&film);
    return st;
}

char *passes_aov_path(const char *output, const char *name)
{
    const char *slash = strrchr(output, '/');
    const char *dot = strrchr(output, '.');
    size_t stem = dot && (!slash || dot > slash + 1) ? (size_t)(dot - output) : strlen(output);
    size_t n = strlen(output) + strlen(name) + 2;
    char *out = malloc(n);
    if (out) snprintf(out, n, "%.*s-%s%s", (int)stem, output, name, output + stem);
    return out;
}

const char *passes_aov_name(unsigned aov)
{
    switch (aov) {
    case INTEGRATOR_AOV_NORMAL: return "normal";
    case INTEGRATOR_AOV_DEPTH: return "depth";
    case INTEGRATOR_AOV_ALBEDO: return "albedo";
    default: return NULL;
    }
}

char *passes_aov_output_path(const PassRequest *q, const char *output, unsigned aov)
{
    const char *named = q->aov_files[aov - INTEGRATOR_AOV_NORMAL];
    return named ? strdup(named) : passes_aov_path(output, passes_aov_name(aov));
}

int passes_aov_in_exr(const PassRequest *q, const char *output, unsigned aov)
{
    ImageFormat fmt = IMAGE_PNG;
    Error ignored = { 0 };
    image_format_from_path(output, &fmt, &ignored);
    error_clear(&ignored);
    return fmt == IMAGE_EXR && !q->aov_files[aov - INTEGRATOR_AOV_NORMAL];
}

static int passes__is_normal(unsigned aov)
{
    return aov == INTEGRATOR_AOV_NORMAL || aov == INTEGRATOR_FEATURE_NORMAL;
}

/* The normal image rendered with grey misses, (n + 1) / 2, gives 2c - 1 = the
 * pixel's mean normal with misses counting 0. */
void passes_resolve_data(unsigned aov, const Film *film, float *rgb)
{
    film_resolve(film, rgb);
    if (aov == INTEGRATOR_AOV_DEPTH) {
        DepthScale raw = { DEPTH_RAW, 0.0, 0.0 };
        passes_depth_grey(rgb, (size_t)film->width * film->height, &raw);
    }
    if (passes__is_normal(aov))
        for (size_t i = 0; i < (size_t)film->width * film->height * 3u; i++) rgb[i] = 2.0f * rgb[i] - 1.0f;
}

Status passes_data_film(const PassContext *pc, unsigned aov, uint spp, uint first, uint end, Film *film,
                        double *secs, Error *err)
{
    RenderParams *p = &pc->rs->ds.params;
    uint grey = p->normal_miss_grey;
    if (passes__is_normal(aov)) p->normal_miss_grey = 1;
    Status st = passes__aov_film(pc, aov, spp, first, end, film, secs, err);
    p->normal_miss_grey = grey;
    return st;
}

Status passes_aov_data(const PassContext *pc, unsigned aov, uint spp, float *rgb, double *secs, Error *err)
{
    *secs = 0.0;
    Film film;
    Status st = passes_data_film(pc, aov, spp, 0u, 0u, &film, secs, err);
    if (!st) passes_resolve_data(aov, &film, rgb);
    film_free(&film);
    return st;
}

Status passes_write_exr_layers(const char *output, const float *rgb, float *const aov_rgb[3], const float *noisy,
                               const float *emission, const float *emission_more, uint w, uint h, int exr_float,
                               Error *err)
{
    static const char *const names[3][3] = { { "normal.X", "normal.Y", "normal.Z" }, { "Z", NULL, NULL },
                                             { "albedo.R", "albedo.G", "albedo.B" } };
    static const char *const noisy_names[3] = { "noisy.R", "noisy.G", "noisy.B" };
    static const char *const emission_names[2][3] = { { "emission.R", "emission.G", "emission.B" },
                                                      { "emission4x.R", "emission4x.G", "emission4x.B" } };
    ImageLayer layers[6];
    size_t n = 0;
    for (int a = 0; a < 3; a++) {
        if (!aov_rgb[a]) continue;
        memcpy(layers[n].names, names[a], sizeof names[a]);
        layers[n++].rgb = aov_rgb[a];
    }
    if (noisy) {
        memcpy(layers[n].names, noisy_names, sizeof noisy_names);
        layers[n++].rgb = noisy;
    }
    const float *e[2] = { emission, emission_more };
    for (int k = 0; k < 2 && emission && emission_more; k++) {
        memcpy(layers[n].names, emission_names[k], sizeof emission_names[k]);
        layers[n++].rgb = e[k];
    }
    return n ? image_write_exr(output, rgb, layers, n, w, h, exr_float, err) : ST_OK;
}

/* What the albedo and normal channels of an EXR output and the denoiser's inputs are
 * rendered as: with --denoise, its features (seen through mirrors and clear glass,
 * INTEGRATOR_FEATURE_*), so that the EXR keeps what the denoiser saw; else the
 * first-hit images of --aov. */
static unsigned passes__channel_mode(const PassRequest *q, unsigned aov)
{
    if (!q->denoise || aov == INTEGRATOR_AOV_DEPTH) return aov;
    return aov == INTEGRATOR_AOV_NORMAL ? INTEGRATOR_FEATURE_NORMAL : INTEGRATOR_FEATURE_ALBEDO;
}

/* Whether the EXR output holds auxiliary image `aov` as channels: asked by --aov, or a
 * feature the denoiser used (kept so that it can be run again elsewhere). */
static int passes__aov_wanted_in_exr(const PassRequest *q, const char *output, unsigned aov)
{
    int feature = q->denoise && aov != INTEGRATOR_AOV_DEPTH;
    return ((q->aovs & (1u << aov)) || feature) && passes_aov_in_exr(q, output, aov);
}

/* The denoiser's features (INTEGRATOR_FEATURE_*: through mirrors and clear glass), into
 * aov[] (normal and albedo slots) as an EXR's channels hold them, where the EXR pass has
 * not rendered them already. */
static Status passes__features(const PassContext *pc, uint spp, float *aov[3], int quiet, Error *err)
{
    size_t n = (size_t)pc->rs->ds.params.width * pc->rs->ds.params.height * 3u;
    Status st = ST_OK;
    for (unsigned a = INTEGRATOR_AOV_NORMAL; a <= INTEGRATOR_AOV_ALBEDO && !st; a += 2) {
        float **slot = &aov[a - INTEGRATOR_AOV_NORMAL];
        if (*slot) continue;
        double secs = 0.0;
        if (!(*slot = malloc(n * sizeof **slot))) return error_set(err, ST_INTERNAL, "out of memory");
        st = passes_aov_data(pc, a == INTEGRATOR_AOV_NORMAL ? INTEGRATOR_FEATURE_NORMAL : INTEGRATOR_FEATURE_ALBEDO,
                             spp, *slot, &secs, err);
        if (!st && !quiet) fprintf(stderr, "clpt: %s image for the denoiser in %.2f s\n", passes_aov_name(a), secs);
    }
    return st;
}

int passes_emission_splits(const RenderParams *p, int uniform)
{
    return uniform && p->integrator == INTEGRATOR_PATH && !p->has_media;
}

/* The emission feature with `spp` samples per pixel into e, timed to stderr unless quiet. */
static Status passes__emission(const PassContext *pc, uint spp, float *e, int quiet, Error *err)
{
    double secs = 0.0;
    Status st = passes_aov_data(pc, INTEGRATOR_FEATURE_EMISSION, spp, e, &secs, err);
    if (!st && !quiet) fprintf(stderr, "clpt: emission image (%u spp) for the denoiser in %.2f s\n", spp, secs);
    return st;
}

int passes_emission_lit(const float *e, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (e[i] != 0.0f) return 1;
    return 0;
}

Status passes_denoise_split(Denoiser *dn, const float *noisy, const float *albedo, const float *normal,
                            const float *e, const float *more, uint w, uint h, int clean, float *out, Error *err)
{
    size_t n = (size_t)w * h * 3u;
    if (!e || !more) {
        return clean ? denoiser_run_clean(dn, noisy, albedo, normal, w, h, out, err)
                     : denoiser_run(dn, noisy, albedo, normal, w, h, out, err);
    }
    float *rest = malloc(n * sizeof *rest);
    if (!rest) return error_set(err, ST_INTERNAL, "out of memory for the denoiser");
    /* the same rays: the image's samples each hold at least their emission, and the
     * film rounds both alike, so nothing is below 0 but what the colour never had
     * (NaN, which fails the test, becomes 0 as the denoiser would make it) */
    for (size_t i = 0; i < n; i++) {
        float d = noisy[i] - e[i];
        rest[i] = d > 0.0f ? d : 0.0f;
    }
    Status st = clean ? denoiser_run_clean(dn, rest, albedo, normal, w, h, out, err)
                      : denoiser_run(dn, rest, albedo, normal, w, h, out, err);
    for (size_t i = 0; i < n && !st; i++) out[i] += more[i];
    free(rest);
    return st;
}

uint passes_emission_more_spp(uint spp)
{
    return spp <= UINT32_MAX / PASSES_EMISSION_SPP_FACTOR ? spp * PASSES_EMISSION_SPP_FACTOR : spp;
}

Status passes_denoise_emission(const PassContext *pc, uint spp, int uniform, float **e, float **more, int quiet,
                               Error *err)
{
    *e = *more = NULL;
    if (!passes_emission_splits(&pc->rs->ds.params, uniform)) return ST_OK;
    size_t n = (size_t)pc->rs->ds.params.width * pc->rs->ds.params.height * 3u;
    Status st = (*e = malloc(n * sizeof **e)) ? ST_OK : error_set(err, ST_INTERNAL, "out of memory for the denoiser");
    if (!st) st = passes__emission(pc, spp, *e, quiet, err);
    /* nothing seen emitted (the dragon's lamp out of view, a black background): the
     * colour as it is, without the second pass, which would only add its rare emitter
     * a few samples found (E(spp) = 0 estimates the same) */
    if (!st && !passes_emission_lit(*e, n)) {
        free(*e);
        *e = NULL;
        return ST_OK;
    }
    if (!st && !(*more = malloc(n * sizeof **more))) st = error_set(err, ST_INTERNAL, "out of memory for the denoiser");
    if (!st) st = passes__emission(pc, passes_emission_more_spp(spp), *more, quiet, err);
    return st;
}

Status passes_denoise(const PassContext *pc, uint spp, int uniform, const float *noisy, const float *albedo,
                      const float *normal, float *out, float **emission, float **emission_more, int quiet, Error *err)
{
    uint w = pc->rs->ds.params.width, h = pc->rs->ds.params.height;
    float *e = NULL, *more = NULL;
    Status st = passes_denoise_emission(pc, spp, uniform, &e, &more, quiet, err);
    if (!st) st = passes_denoise_split(pc->denoiser, noisy, albedo, normal, e, more, w, h, 0, out, err);
    if (!st && emission && emission_more) {
        *emission = e;
        *emission_more = more;
    } else {
        free(e);
        free(more);
    }
    return st;
}

/* Denoises rgb in place with the features in aov[]; *noisy keeps the colour as it was,
 * emission[0] and [1] the emission left out and added back (NULL when the colour was
 * denoised whole); all freed by the caller. */
static Status passes__denoise(const PassContext *pc, uint spp, int uniform, float *rgb, float *const aov[3],
                              float **noisy, float *emission[2], int quiet, Error *err)
{
    uint w = pc->rs->ds.params.width, h = pc->rs->ds.params.height;
    size_t n = (size_t)w * h * 3u;
    if (!(*noisy = malloc(n * sizeof **noisy))) return error_set(err, ST_INTERNAL, "out of memory");
    memcpy(*noisy, rgb, n * sizeof *rgb);
    double t0 = timer_now();
    Status st = passes_denoise(pc, spp, uniform, *noisy, aov[INTEGRATOR_AOV_ALBEDO - INTEGRATOR_AOV_NORMAL], aov[0],
                               rgb, &emission[0], &emission[1], quiet, err);
    if (!st && !quiet)
        fprintf(stderr, "clpt: denoised in %.2f s (Open Image Denoise, %s device, %s)\n", timer_now() - t0,
                denoiser_device_kind(pc->denoiser), denoiser_library(pc->denoiser));
    return st;
}

/* The features and the denoiser (q->denoise), and the channels of an EXR output: the
 * image at `output` is rewritten when either changed it. */
static Status passes__final_image(const PassRequest *q, const PassContext *pc, const char *output,
                                  const ImageStyle *style, float *rgb, uint spp, Error *err)
{
    uint w = pc->rs->ds.params.width, h = pc->rs->ds.params.height;
    float *in_exr[3] = { NULL, NULL, NULL }, *noisy = NULL, *emission[2] = { NULL, NULL };
    Status st = ST_OK;
    for (unsigned aov = INTEGRATOR_AOV_NORMAL; aov <= INTEGRATOR_AOV_ALBEDO && !st; aov++) {
        if (!passes__aov_wanted_in_exr(q, output, aov)) continue;
        float **slot = &in_exr[aov - INTEGRATOR_AOV_NORMAL];
        double secs = 0.0;
        if (!(*slot = malloc((size_t)w * h * 3u * sizeof **slot))) st = error_set(err, ST_INTERNAL, "out of memory");
        if (!st) st = passes_aov_data(pc, passes__channel_mode(q, aov), spp, *slot, &secs, err);
        if (!st && !q->quiet) fprintf(stderr, "clpt: %s image in %.2f s\n", passes_aov_name(aov), secs);
    }
    if (!st && q->denoise) st = passes__features(pc, spp, in_exr, q->quiet, err);
    if (!st && q->denoise) st = passes__denoise(pc, spp, !q->varying_spp, rgb, in_exr, &noisy, emission, q->quiet, err);
    int exr = passes_aov_in_exr(q, output, INTEGRATOR_AOV_NORMAL) || passes_aov_in_exr(q, output, INTEGRATOR_AOV_ALBEDO);
    if (!st && exr)
        st = passes_write_exr_layers(output, rgb, in_exr, noisy, emission[0], emission[1], w, h, q->exr_float, err);
    else if (!st && q->denoise) st = image_write_styled(output, rgb, w, h, style, err);
    if (!st && !q->quiet && exr && (in_exr[0] || in_exr[1] || in_exr[2]))
        fprintf(stderr, "clpt: %sauxiliary images as channels -> %s\n", noisy ? "denoised image, noisy colour and " : "",
                output);
    else if (!st && !q->quiet && q->denoise)
        fprintf(stderr, "clpt: denoised image -> %s\n", output);
    if (!st && noisy && pc->on_denoised) pc->on_denoised(pc->on_denoised_ctx, rgb);
    for (int a = 0; a < 3; a++) free(in_exr[a]);
    free(noisy);
    free(emission[0]);
    free(emission[1]);
    return st;
}

/* The adaptive pass, the denoiser and the auxiliary images, after the main image is in
 * rgb (and written). A failure here is the run's failure; the main image stays
 * written. */
Status passes_after_image(const PassRequest *q, const PassContext *pc, const char *output, const ImageStyle *style,
                         float *rgb, uint spp, Error *err)
{
    uint w = pc->rs->ds.params.width, h = pc->rs->ds.params.height;
    Status st = ST_OK;
    if (q->adaptive > 0.0) {
        size_t marked = 0;
        double secs = 0.0;
        if ((st = passes_adaptive(pc, rgb, spp, (float)q->adaptive, q->adaptive_spp, &marked, &secs, err)))
            return st;
        if ((st = image_write_styled(output, rgb, w, h, style, err))) return st;
        if (!q->quiet)
            fprintf(stderr, "clpt: adaptive pass: %zu of %u pixels (%.1f%%) got %u more samples in %.2f s -> %s\n",
                    marked, w * h, 100.0 * (double)marked / ((double)w * h), q->adaptive_spp, secs, output);
    }
    st = passes__final_image(q, pc, output, style, rgb, spp, err);
    if (st) return st;
    for (unsigned aov = INTEGRATOR_AOV_NORMAL; aov <= INTEGRATOR_AOV_ALBEDO; aov++) {
        if (!(q->aovs & (1u << aov)) || passes_aov_in_exr(q, output, aov)) continue;
        char *path = passes_aov_output_path(q, output, aov);
        if (!path) return error_set(err, ST_INTERNAL, "out of memory");
        ImageFormat fmt = IMAGE_PNG;
        image_format_from_path(path, &fmt, err);
        double secs = 0.0;
        DepthScale depth = { fmt == IMAGE_PFM ? DEPTH_RAW : (q->depth_far != q->depth_near ? DEPTH_RANGE : DEPTH_AUTO),
                             q->depth_near, q->depth_far };
        /* a PFM holds data as the EXR's channels do: the signed normal (misses 0), not
         * the colours (n + 1) / 2 an 8-bit image needs; a course's own -normals file
         * keeps its course's convention */
        if (fmt == IMAGE_PFM && aov == INTEGRATOR_AOV_NORMAL && !q->aov_files[aov - INTEGRATOR_AOV_NORMAL])
            st = passes_aov_data(pc, aov, spp, rgb, &secs, err);
        else
            st = passes_aov(pc, aov, spp, &depth, rgb, &secs, err);
        /* auxiliary images hold data, not light: no sRGB curve */
        if (!st) st = image_write_encoded(path, rgb, w, h, IMAGE_LINEAR, err);
        if (!st && !q->quiet)
            fprintf(stderr, "clpt: %s image in %.2f s -> %s\n", passes_aov_name(aov), secs, path);
        free(path);
        if (st) return st;
    }
    return ST_OK;
}
