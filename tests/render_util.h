/* render_util.h — renders a Scene into a Film with chosen devices, the way main does
 * (render_scene_prepare + schedule_run), for the image-level tests. */
#ifndef CLPT_RENDER_UTIL_H
#define CLPT_RENDER_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "device/device.h"
#include "io/scene_load.h"
#include "render/film.h"
#include "render/render_scene.h"
#include "render/schedule.h"

/* render_util_run_mis's mode for "the scene's own MIS mode". */
#define RENDER_UTIL_SCENE_MIS 0xffffffffu

/* devices: a --device spec; batch: fixed batch size (0 = adaptive); mis_mode: enum
 * MisMode set on the prepared scene (the tests of each strategy alone), or
 * RENDER_UTIL_SCENE_MIS. The film is initialised here; free it with film_free. */
/* render_util_run_mis with the devices opened under cfg (NULL: the defaults), e.g. an
 * OpenCL device's --wave-launch; the first device's counters into *first when given. */
static inline Status render_util_run_counted(Scene *s, uint mis_mode, const char *devices, const DeviceConfig *cfg,
                                             uint batch, Film *film, DeviceCounters *first, Error *err)
{
    RenderScene rs;
    DeviceDesc *all = NULL;
    size_t n_all = 0, *chosen = NULL, n_chosen = 0, n_open = 0;
    Device **devs = NULL;
    ScheduleStats stats;
    memset(&stats, 0, sizeof stats);
    char warning[1100];
    memset(film, 0, sizeof *film);
    Status st = render_scene_prepare(s, 0, &rs, err);
    if (st) return st;
    if (mis_mode != RENDER_UTIL_SCENE_MIS) rs.ds.params.mis_mode = mis_mode;
    if ((st = device_list(&all, &n_all, warning, sizeof warning, err))) goto out;
    if ((st = device_select(devices, all, n_all, &chosen, &n_chosen, err))) goto out;
    devs = calloc(n_chosen, sizeof *devs);
    for (size_t i = 0; i < n_chosen; i++) {
        if ((st = device_open(&all[chosen[i]], cfg, &devs[i], err))) goto out;
        n_open++;
        if ((st = devs[i]->ops->load_scene(devs[i], &rs.ds, err))) goto out;
    }
    if ((st = film_init(film, rs.ds.params.width, rs.ds.params.height, err))) goto out;
    ScheduleConfig sched;
    memset(&sched, 0, sizeof sched);
    sched.spp = s->image.spp;
    sched.fixed_batch = batch;
    st = schedule_run(devs, n_chosen, &sched, film, &stats, err);
    if (first && n_open) *first = devs[0]->counters;
out:
    schedule_stats_free(&stats);
    for (size_t i = 0; i < n_open; i++) device_close(devs[i]);
    free(devs);
    free(chosen);
    free(all);
    render_scene_free(&rs);
    return st;
}

static inline Status render_util_run_cfg(Scene *s, uint mis_mode, const char *devices, const DeviceConfig *cfg,
                                         uint batch, Film *film, Error *err)
{
    return render_util_run_counted(s, mis_mode, devices, cfg, batch, film, NULL, err);
}

static inline Status render_util_run_mis(Scene *s, uint mis_mode, const char *devices, uint batch, Film *film,
                                         Error *err)
{
    return render_util_run_cfg(s, mis_mode, devices, NULL, batch, film, err);
}

static inline Status render_util_run(Scene *s, const char *devices, uint batch, Film *film, Error *err)
{
    return render_util_run_mis(s, RENDER_UTIL_SCENE_MIS, devices, batch, film, err);
}

/* The linear image of s rendered with MIS mode `mode` on `devices`, into rgb (the
 * scene's width x height x 3 floats). */
static inline Status render_util_rgb_mis(Scene *s, uint mode, const char *devices, float *rgb, Error *err)
{
    Film film;
    Status st = render_util_run_mis(s, mode, devices, 0, &film, err);
    if (st == ST_OK) film_resolve(&film, rgb);
    film_free(&film);
    return st;
}

static inline double film_mean(const Film *f)
{
    size_t n = (size_t)f->width * f->height * 3u;
    float *rgb = malloc(n * sizeof *rgb);
    film_resolve(f, rgb);
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) sum += rgb[i];
    free(rgb);
    return sum / (double)n;
}

/* Mean of each channel of a film. */
static inline void film_channel_means(const Film *f, double mean[3])
{
    size_t n = (size_t)f->width * f->height;
    float *rgb = malloc(n * 3 * sizeof *rgb);
    film_resolve(f, rgb);
    mean[0] = mean[1] = mean[2] = 0.0;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) mean[c] += rgb[3 * i + c] / (double)n;
    free(rgb);
}

/* Channel sums that are the same in two films of one size (bit-for-bit comparisons). */
static inline size_t film_sums_same(const Film *a, const Film *b)
{
    size_t n = (size_t)a->width * a->height * 3u, same = 0;
    for (size_t i = 0; i < n; i++) same += a->sum[i] == b->sum[i];
    return same;
}

/* Loads the scene `text` (named `name` in messages), renders it on `devices` and puts
 * its channel means in mean[3]: the whole-image check of the media, grid, emission and
 * subsurface tests. */
static inline Status render_util_text_means(const char *name, const char *text, const char *devices, double mean[3],
                                            Error *err)
{
    Scene s;
    Film f;
    memset(&f, 0, sizeof f);
    scene_init(&s);
    Status st = scene_load_text(name, text, strlen(text), &s, err);
    if (!st) st = render_util_run(&s, devices, 0, &f, err);
    if (!st) film_channel_means(&f, mean);
    film_free(&f);
    scene_free(&s);
    return st;
}

/* Loads the scene `text` (named `name` in messages, read as `format`) and renders it on
 * `devices` into film (initialised here; free it with film_free). */
static inline Status render_util_text_film(const char *name, const char *text, SceneFormat format,
                                           const char *devices, Film *film, Error *err)
{
    Scene s;
    memset(film, 0, sizeof *film);
    scene_init(&s);
    Status st = scene_load_bytes(name, text, strlen(text), format, &s, NULL, err);
    if (!st) st = render_util_run(&s, devices, 0, film, err);
    scene_free(&s);
    return st;
}

/* The largest difference of a's and b's channel sums over bw x bh pixel blocks of a
 * width x height image, relative to ref's sum in the same block (at least 1e-3): the
 * within-noise comparison of the motion-blur tests, where a pixel alone is too noisy. */
static inline double render_util_block_diff(const float *a, const float *b, const float *ref, int width, int height,
                                            int bw, int bh)
{
    double worst = 0.0;
    for (int by = 0; by < height / bh; by++)
        for (int bx = 0; bx < width / bw; bx++)
            for (int c = 0; c < 3; c++) {
                double sa = 0, sb = 0, sr = 0;
                for (int y = by * bh; y < by * bh + bh; y++)
                    for (int x = bx * bw; x < bx * bw + bw; x++) {
                        size_t i = ((size_t)y * (size_t)width + (size_t)x) * 3 + (size_t)c;
                        sa += a[i];
                        sb += b[i];
                        sr += ref[i];
                    }
                worst = fmax(worst, fabs(sa - sb) / fmax(sr, 1e-3));
            }
    return worst;
}

/* Writes the scene text of the still frame at shutter time u in [0, 1]. */
typedef void (*RenderUtilStillText)(double u, char *text, size_t size);

/* A motion-blurred render and the still ones it is checked against, each n floats of
 * linear RGB: the still renders at the times u = (i + 1/2) / k (the shutter's midpoint
 * rule) averaged, and the one at i = k / 2 alone. */
typedef struct {
    uint width, height;
    size_t n;
    float *moving, *average, *middle;
} RenderUtilMotionImages;

static inline void render_util_motion_images_free(RenderUtilMotionImages *im)
{
    free(im->moving);
    free(im->average);
    free(im->middle);
    memset(im, 0, sizeof *im);
}

/* Renders the scene text `moving` and the k still scenes `still` writes (all named
 * `name`, read as `format`, on the scalar device) into im (freed with
 * render_util_motion_images_free, on failure too). */
static inline Status render_util_motion_images(const char *name, SceneFormat format, const char *moving,
                                               RenderUtilStillText still, int k, RenderUtilMotionImages *im,
                                               Error *err)
{
    enum { TEXT_SIZE = 8192 };
    Film film;
    memset(im, 0, sizeof *im);
    Status st = render_util_text_film(name, moving, format, "scalar", &film, err);
    if (st) return st;
    im->width = film.width;
    im->height = film.height;
    im->n = (size_t)film.width * film.height * 3u;
    im->moving = calloc(im->n, sizeof *im->moving);
    im->average = calloc(im->n, sizeof *im->average);
    im->middle = calloc(im->n, sizeof *im->middle);
    char *text = malloc(TEXT_SIZE);
    float *rgb = malloc(im->n * sizeof *rgb);
    if (!im->moving || !im->average || !im->middle || !text || !rgb)
        st = error_set(err, ST_INTERNAL, "out of memory");
    else
        film_resolve(&film, im->moving);
    film_free(&film);
    for (int i = 0; !st && i < k; i++) {
        still((i + 0.5) / k, text, TEXT_SIZE);
        st = render_util_text_film(name, text, format, "scalar", &film, err);
        if (!st) film_resolve(&film, rgb);
        film_free(&film);
        if (st) break;
        for (size_t j = 0; j < im->n; j++) im->average[j] += rgb[j] / k;
        if (i == k / 2) memcpy(im->middle, rgb, im->n * sizeof *im->middle);
    }
    free(rgb);
    free(text);
    return st;
}

/* The motion-blur check's two measures over 8 x 6 pixel blocks: *worst, how far the
 * moving render is from the still ones' average (relative to the average), and
 * *worst_mid, how far from the middle still one (relative to the middle one's sums when
 * mid_by_middle, else the average's: each test keeps the measure it was written with).
 * Both are 0 when a render failed; both are printed to stderr after `what`. */
static inline Status render_util_motion_diffs(const char *what, const char *name, SceneFormat format,
                                              const char *moving, RenderUtilStillText still, int k, int mid_by_middle,
                                              double *worst, double *worst_mid, Error *err)
{
    RenderUtilMotionImages im;
    *worst = *worst_mid = 0.0;
    Status st = render_util_motion_images(name, format, moving, still, k, &im, err);
    if (!st) {
        int w = (int)im.width, h = (int)im.height;
        *worst = render_util_block_diff(im.moving, im.average, im.average, w, h, 8, 6);
        *worst_mid = render_util_block_diff(im.moving, im.middle, mid_by_middle ? im.middle : im.average, w, h, 8, 6);
        fprintf(stderr, "  %s: blocks against the average of still ones %.2f%%, against the middle one %.2f%%\n",
                what, 100.0 * *worst, 100.0 * *worst_mid);
    }
    render_util_motion_images_free(&im);
    return st;
}

#endif /* CLPT_RENDER_UTIL_H */
