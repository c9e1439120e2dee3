/*
 * test_checkpoint.c — checkpoint and resume: the file round-trips, damaged files and
 * checkpoints of other renders are refused with exit status 3, and a render killed with
 * SIGKILL at several moments (and resumed each time, on other devices) ends with the
 * same PFM bytes as a render never interrupted. Also SIGINT writes a final checkpoint,
 * holding whole batches only.
 * Runs with two PoCL devices (POCL_DEVICES="pthread pthread") plus the scalar device.
 */
#include <dirent.h>
#include <signal.h>
#include <stdlib.h>
#include <time.h>

#include "render/checkpoint.h"
#include "cli_util.h"
#include "harness.h"
#include "render/render_scene.h"
#include "scene/scene.h"
#include "base/timer.h"
#include "file_util.h"

static char dir[64];
static char path_ref[128], path_out[128], path_ck[128];
static CliResult r;
#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

/* A small, quick render with many batches, so that checkpoints catch it part-way. */
#define SCENE "scenes/cornell-box.scene"
#define SIZE "--width", "48", "--height", "36"
#define SPP_TEXT "1200"
#define SPP 1200u

static void make_dir(void)
{
    snprintf(dir, sizeof dir, "/tmp/clpt-test-ckpt-XXXXXX");
    if (!mkdtemp(dir)) perror("mkdtemp");
    snprintf(path_ref, sizeof path_ref, "%s/ref.pfm", dir);
    snprintf(path_out, sizeof path_out, "%s/out.pfm", dir);
    snprintf(path_ck, sizeof path_ck, "%s/render.ckpt", dir);
}

/* Removes the folder and whatever is left in it (temporary files of killed writes). */
static void remove_dir(void)
{
    file_util_remove_dir(dir);
}

static int read_file(const char *path, unsigned char **data, size_t *len)
{
    *len = 0;
    *data = (unsigned char *)file_util_read(path, len);
    return *data != NULL;
}

static int write_file(const char *path, const unsigned char *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    size_t w = fwrite(data, 1, len, f);
    return (fclose(f) == 0) & (w == len);
}

static void sleep_s(double s)
{
    struct timespec ts = { (time_t)s, (long)((s - (double)(time_t)s) * 1e9) };
    nanosleep(&ts, NULL);
}

/* Samples per pixel in the checkpoint at `path`, or -1 when there is none (yet). */
static long checkpoint_samples(const char *path)
{
    Checkpoint c;
    Error err = { 0 };
    long n = checkpoint_read(path, &c, &err) == ST_OK ? (long)c.film.samples : -1;
    checkpoint_free(&c);
    error_clear(&err);
    return n;
}

/* ------------------------------------------------------------------ the file itself */

static void fill_film(Film *f, uint w, uint h, uint64_t samples)
{
    Error err = { 0 };
    film_init(f, w, h, &err);
    int64_t max = (int64_t)samples << 40;   /* every sample at the largest radiance */
    for (size_t i = 0; i < (size_t)w * h * 3u; i++) f->sum[i] = (int64_t)(i * 2654435761u) % max;
    f->sum[0] = 0;               /* the extremes a film can hold survive the encoding */
    f->sum[1] = max;
    f->samples = samples;
}

static void test_write_read_round_trip(void)
{
    CheckpointId id;
    memset(&id, 0, sizeof id);
    for (int i = 0; i < CHECKPOINT_KEY_SIZE; i++) id.key[i] = (unsigned char)(i * 7);
    id.width = 5;
    id.height = 3;
    id.spp = 100;
    id.seed = 42;
    id.max_depth = 8;
    Film f;
    fill_film(&f, 5, 3, 30);
    const Batch done[] = { { 0, 10 }, { 20, 5 }, { 40, 15 } };
    Error err = { 0 };
    CHECK(checkpoint_write(path_ck, &id, &f, done, 3, &err) == ST_OK);
    Checkpoint c;
    CHECK(checkpoint_read(path_ck, &c, &err) == ST_OK);
    CHECK(memcmp(&c.id, &id, sizeof id) == 0);
    CHECK(c.film.width == 5 && c.film.height == 3 && c.film.samples == 30);
    CHECK(c.film.sum && memcmp(c.film.sum, f.sum, 5 * 3 * 3 * sizeof *f.sum) == 0);
    CHECK(c.n_done == 3 && c.done && memcmp(c.done, done, sizeof done) == 0);
    CHECK(checkpoint_check(&c, path_ck, &id, &err) == ST_OK);
    checkpoint_free(&c);

    /* no temporary file is left beside it */
    DIR *d = opendir(dir);
    int others = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        others += strstr(e->d_name, ".tmp.") != NULL;
    if (d) closedir(d);
    CHECK_EQ_INT(others, 0);

    /* an unwritable place is an I/O error naming the file */
    CHECK(checkpoint_write("/nonexistent-folder/x.ckpt", &id, &f, done, 3, &err) == ST_IO);
    CHECK_STR_CONTAINS(err.msg, "/nonexistent-folder/x.ckpt");
    error_clear(&err);
    film_free(&f);
}

static void expect_refused(const unsigned char *data, size_t len, const char *words)
{
    char p[160];
    snprintf(p, sizeof p, "%s/damaged.ckpt", dir);
    CHECK(write_file(p, data, len));
    Checkpoint c;
    Error err = { 0 };
    CHECK_EQ_INT(checkpoint_read(p, &c, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, words);
    checkpoint_free(&c);
    error_clear(&err);
    unlink(p);
}

static void test_damaged_files_are_refused(void)
{
    unsigned char *good;
    size_t len;
    CHECK(read_file(path_ck, &good, &len));    /* from the round trip */
    unsigned char *bad = malloc(len);
    memcpy(bad, good, len);
    bad[len / 2] ^= 0x10;
    expect_refused(bad, len, "checksum");
    memcpy(bad, good, len);
    bad[0] = 'X';
    expect_refused(bad, len, "magic");
    memcpy(bad, good, len);
    bad[8] = 9;
    expect_refused(bad, len, "version 9");
    expect_refused(good, len - 100, "truncated");
    expect_refused(good, 20, "truncated");
    expect_refused(good, 0, "too short");
    /* a header whose counts promise more than the file holds: refused before any
     * allocation from them */
    memcpy(bad, good, len);
    bad[48] = 0xff, bad[49] = 0xff, bad[50] = 0xff;
    expect_refused(bad, len, "checksum");
    free(bad);
    free(good);

    Checkpoint c;
    Error err = { 0 };
    CHECK_EQ_INT(checkpoint_read("/nonexistent.ckpt", &c, &err), ST_IO);
    checkpoint_free(&c);
    error_clear(&err);
}

/* A crafted file with a valid checksum whose film values no render can produce: near
 * INT64_MAX, the resume's further batches would overflow the signed sums (negative
 * pixels); negative, the pixel would be negative at once. */
static void expect_film_refused(int64_t value, uint spp, const char *words)
{
    CheckpointId id;
    memset(&id, 0, sizeof id);
    id.width = 2;
    id.height = 2;
    id.spp = spp;
    Film f;
    fill_film(&f, 2, 2, 10);
    f.sum[7] = value;
    const Batch done[] = { { 0, 10 } };
    char p[160];
    snprintf(p, sizeof p, "%s/crafted.ckpt", dir);
    Error err = { 0 };
    CHECK(checkpoint_write(p, &id, &f, done, 1, &err) == ST_OK);
    Checkpoint c;
    CHECK_EQ_INT(checkpoint_read(p, &c, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, words);
    checkpoint_free(&c);
    error_clear(&err);
    film_free(&f);
    unlink(p);
}

static void test_film_values_are_bounded(void)
{
    expect_film_refused(INT64_MAX, 100, "film value 9223372036854775807 of pixel 2 is outside what 10 samples can "
                                        "hold (0..10995116277760)");
    expect_film_refused(((int64_t)10 << 40) + 1, 100, "outside what 10 samples can hold");
    expect_film_refused(-1, 100, "film value -1 of pixel 2");
    expect_film_refused(INT64_MIN, 100, "film value -9223372036854775808");
    /* the bound relies on the samples per pixel a render can ask for */
    expect_film_refused(0, 4000000000u, "samples per pixel outside 1..1000000");
}

/* A --denoise part's features (format version 4): read back as written, and refused
 * when their counts disagree with the film's or the header's, or a value is beyond
 * what their samples can hold. */
static Status write_read_features(Film *films, uint n, uint features_spp, Checkpoint *c, Error *err)
{
    CheckpointId id;
    memset(&id, 0, sizeof id);
    id.width = 3;
    id.height = 2;
    id.spp = 16;
    Film f;
    fill_film(&f, 3, 2, 5);
    const Batch done[] = { { 3, 5 } };
    char p[160];
    snprintf(p, sizeof p, "%s/features.ckpt", dir);
    Status st = checkpoint_write_features(p, &id, &f, done, 1, films, n, features_spp, err);
    film_free(&f);
    if (st == ST_OK) st = checkpoint_read(p, c, err);
    unlink(p);
    return st;
}

static void test_denoise_features_round_trip(void)
{
    Film films[CKPT_FEATURES_MAX];
    for (uint k = 0; k < CKPT_FEATURES_MAX; k++)
        fill_film(&films[k], 3, 2, k == CKPT_FEATURE_EMISSION_MORE ? 20 : 5);
    Checkpoint c;
    Error err = { 0 };
    CHECK_EQ_INT(write_read_features(films, CKPT_FEATURES_MAX, 16, &c, &err), ST_OK);
    CHECK(c.n_features == CKPT_FEATURES_MAX && c.features_spp == 16 && c.film.samples == 5);
    for (uint k = 0; k < CKPT_FEATURES_MAX && c.n_features == CKPT_FEATURES_MAX; k++)
        CHECK(c.features[k].samples == films[k].samples &&
              memcmp(c.features[k].sum, films[k].sum, 3 * 2 * 3 * sizeof *films[k].sum) == 0);
    checkpoint_free(&c);
    CHECK_EQ_INT(write_read_features(films, 2, 16, &c, &err), ST_OK);   /* albedo and normal alone */
    CHECK(c.n_features == 2 && !c.features[CKPT_FEATURE_EMISSION].sum);
    checkpoint_free(&c);
    static const struct {
        uint n, spp;
        const char *words;
    } bad[] = { { 3, 16, "is not a usable clpt checkpoint: inconsistent header (denoiser features)" },
                { 4, 12, "inconsistent header (denoiser features)" } };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        CHECK_EQ_INT(write_read_features(films, bad[i].n, bad[i].spp, &c, &err), ST_INPUT);
        CHECK_STR_CONTAINS(err.msg, bad[i].words);
        checkpoint_free(&c);
        error_clear(&err);
    }
    films[CKPT_FEATURE_EMISSION_MORE].samples = 5;   /* not 4 x the film's */
    CHECK_EQ_INT(write_read_features(films, CKPT_FEATURES_MAX, 16, &c, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "is not a usable clpt checkpoint: inconsistent feature sample counts");
    checkpoint_free(&c);
    error_clear(&err);
    films[CKPT_FEATURE_EMISSION_MORE].samples = 20;
    films[CKPT_FEATURE_NORMAL].sum[4] = ((int64_t)5 << 40) + 1;
    CHECK_EQ_INT(write_read_features(films, CKPT_FEATURES_MAX, 16, &c, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "film value 5497558138881 of pixel 1 is outside what 5 samples can hold");
    checkpoint_free(&c);
    error_clear(&err);
    for (uint k = 0; k < CKPT_FEATURES_MAX; k++) film_free(&films[k]);
}

/* The render key: stable for the same scene and settings, different when anything that
 * changes the image changes, with a message naming what differs. */
static void test_render_key(void)
{
    CheckpointId ids[6];
    for (int k = 0; k < 6; k++) {
        Scene s;
        Error err = { 0 };
        scene_init(&s);
        CHECK(scene_load(SCENE, &s, &err) == ST_OK);
        s.image.width = 48;
        s.image.height = 36;
        if (k == 2) s.image.seed = 7;
        if (k == 3) s.materials[0].albedo.x += 0.01f;
        if (k == 5) s.shadows = !s.shadows;     /* --shadows changes the image */
        RenderScene rs;
        CHECK(render_scene_prepare(&s, 0, &rs, &err) == ST_OK);
        checkpoint_id(&rs.ds, k == 4 ? 401u : 400u, &ids[k]);
        render_scene_free(&rs);
        scene_free(&s);
    }
    CHECK(memcmp(&ids[0], &ids[1], sizeof ids[0]) == 0);
    for (int k = 2; k < 6; k++)
        if (k != 4) CHECK_MSG(memcmp(ids[0].key, ids[k].key, CHECKPOINT_KEY_SIZE) != 0, "change %d", k);
    /* the samples per pixel are not in the key: 400 samples are the first 400 of 401 */
    CHECK(memcmp(ids[0].key, ids[4].key, CHECKPOINT_KEY_SIZE) == 0);
    Checkpoint c;
    memset(&c, 0, sizeof c);
    Error err = { 0 };
    c.id = ids[2];
    CHECK_EQ_INT(checkpoint_check(&c, "x.ckpt", &ids[0], &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "seed");
    c.id = ids[3];
    CHECK_EQ_INT(checkpoint_check(&c, "x.ckpt", &ids[0], &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "scene differs");
    /* a checkpoint of 401 spp cannot become a render of 400; one of 400 can grow to 401 */
    c.id = ids[4];
    CHECK_EQ_INT(checkpoint_check(&c, "x.ckpt", &ids[0], &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "checkpoint 'x.ckpt' is a render of 401 samples per pixel, this render asks for 400; "
                                "a resume can add samples, never take them away (resume with --spp 401 or more)");
    c.id = ids[0];
    CHECK_EQ_INT(checkpoint_check(&c, "x.ckpt", &ids[4], &err), ST_OK);
    error_clear(&err);
}

/* Every scene buffer of kernels/scene_buffers.h is part of the render key: flipping
 * its first, middle or last byte changes the key (textures and texels were left out
 * once, and a resume after a texture edit was accepted). Each buffer gets 2 elements
 * from a pool of bytes, so the loop needs no knowledge of what the buffers hold. */
static _Alignas(64) unsigned char key_pool[SCENE_BUF_COUNT][4096];

static void test_render_key_covers_every_scene_buffer(void)
{
    DeviceScene ds;
    memset(&ds, 0, sizeof ds);
    for (unsigned i = 0; i < SCENE_BUF_COUNT; i++)
        for (size_t j = 0; j < sizeof key_pool[i]; j++) key_pool[i][j] = (unsigned char)(i * 31u + j);
#define POOL_ONE_(Type, name)
#define POOL_MANY_(Type, name) ds.name = (const Type *)(const void *)key_pool[SCENE_BUF_##name];
#define POOL_(kind, Type, name, count, what) POOL_##kind##_(Type, name)
    SCENE_BUFFERS(POOL_)
#undef POOL_
#undef POOL_MANY_
#undef POOL_ONE_
    RenderParams *p = &ds.params;
    p->width = 2;
    p->height = 1;
    p->n_nodes = p->n_leaf_prims = p->n_spheres = p->n_triangles = p->n_boxes = p->n_planes = 2;
    p->n_lights = p->n_textures = p->n_revsurfaces = p->n_bvh_nodes = p->n_media = p->n_instances = 2;
    ds.n_materials = ds.n_shading = 2;
    ds.n_tri_extra_of = ds.n_tri_extras = 2;
    ds.n_texels = ds.n_rev_points = 2;
    ds.n_env_cdf = ds.n_bvh_leaves = ds.n_sphere_xforms = ds.n_instance_lights = ds.n_grid_data = 2;
    ds.n_motion_keys = ds.n_instance_motion = ds.n_bvh_top = ds.n_kd_protos = 2;
    p->n_grids = p->pixel_list_size = 2;
    CheckpointId base, changed;
    checkpoint_id(&ds, 4u, &base);
    for (unsigned i = 0; i < SCENE_BUF_COUNT; i++) {
        SceneBufferBytes b = device_scene_buffer(&ds, i);
        CHECK_MSG(b.bytes > 0 && b.bytes <= sizeof key_pool[i], "buffer %u (%s): %zu bytes", i, b.what, b.bytes);
        if (b.bytes == 0 || b.bytes > sizeof key_pool[i]) continue;
        /* the parameters end in a count (n_grids): its last byte flipped would make it
         * 2^24 + 2 and the grids' bytes overrun the pool, so flip that count's low byte */
        size_t last = i == SCENE_BUF_params ? b.bytes - sizeof(uint) : b.bytes - 1;
        size_t at[3] = { 0, b.bytes / 2, last };
        for (int k = 0; k < 3; k++) {
            unsigned char *byte = (unsigned char *)(uintptr_t)b.data + at[k];
            *byte ^= 0x01u;
            checkpoint_id(&ds, 4u, &changed);
            *byte ^= 0x01u;
            CHECK_MSG(memcmp(base.key, changed.key, CHECKPOINT_KEY_SIZE) != 0, "byte %zu of the %s is not in the key",
                      at[k], b.what);
        }
    }
    checkpoint_id(&ds, 4u, &changed);
    CHECK(memcmp(&base, &changed, sizeof base) == 0);   /* every byte restored: the same key */
}

/* ------------------------------------------------------------------ the program */

static void render_reference(void)
{
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", SIZE, "--spp", SPP_TEXT, "-o", path_ref), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
}

/* Starts a render that checkpoints every 0.1 s, waits until its checkpoint holds more
 * than `after` samples per pixel (the run has made progress), lets it go on for
 * `extra` seconds and kills it with SIGKILL. Returns the samples per pixel the
 * checkpoint holds then. */
static long run_and_kill(const char *devices, int resume, long after, double extra)
{
    CliChild c = resume ? cli_start(ARGS(SCENE, "-q", "--device", devices, SIZE, "--spp", SPP_TEXT, "--batch", "2",
                                         "-o", path_out, "--resume", path_ck, "--checkpoint-interval", "0.1"))
                        : cli_start(ARGS(SCENE, "-q", "--device", devices, SIZE, "--spp", SPP_TEXT, "--batch", "2",
                                         "-o", path_out, "--checkpoint", path_ck, "--checkpoint-interval", "0.1"));
    double t0 = timer_now();
    while (checkpoint_samples(path_ck) <= after && timer_now() - t0 < 20.0 && waitpid(c.pid, NULL, WNOHANG) == 0)
        sleep_s(0.005);
    sleep_s(extra);
    kill(c.pid, SIGKILL);
    cli_finish(c, &r);
    return checkpoint_samples(path_ck);
}

static void test_sigkill_then_resume_gives_the_same_image(void)
{
    unlink(path_ck);
    /* three kills at different moments, each run on other devices; the last resume
     * finishes the image */
    const char *devices[] = { "scalar", "0", "0,1,scalar" };
    const double extra[] = { 0.0, 0.07, 0.15 };
    long held = 0;
    int partial = 0;
    for (int k = 0; k < 3; k++) {
        long now = run_and_kill(devices[k], k > 0, held, extra[k]);
        CHECK_MSG(now >= held && now > 0, "kill %d: the checkpoint holds %ld spp, before %ld", k, now, held);
        fprintf(stderr, "  kill %d (devices %s): the checkpoint holds %ld of %u spp\n", k, devices[k], now, SPP);
        partial += now > 0 && now < (long)SPP;
        held = now;
    }
    CHECK_MSG(partial >= 2, "only %d of 3 kills caught the render part-way", partial);
    cli_run(ARGS(SCENE, "--device", "0,scalar", SIZE, "--spp", SPP_TEXT, "-o", path_out, "--resume", path_ck), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.err, "resuming from");
    CHECK_MSG(files_equal(path_ref, path_out), "the resumed image differs from the uninterrupted one");
    CHECK_EQ_INT(checkpoint_samples(path_ck), SPP);    /* the final state is saved too */
}

static void test_sigint_writes_a_checkpoint(void)
{
    unlink(path_ck);
    CliChild c = cli_start(ARGS(SCENE, "--device", "scalar", SIZE, "--spp", SPP_TEXT, "--batch", "2", "-o", path_out,
                                "--checkpoint", path_ck, "--checkpoint-interval", "0.1"));
    double t0 = timer_now();
    while (checkpoint_samples(path_ck) <= 0 && timer_now() - t0 < 20.0) sleep_s(0.005);
    kill(c.pid, SIGINT);
    cli_finish(c, &r);
    CHECK_EQ_INT(r.status, 6);
    CHECK_STR_CONTAINS(r.err, "interrupted");
    long held = checkpoint_samples(path_ck);
    CHECK_MSG(held > 0 && held < (long)SPP, "the checkpoint after SIGINT holds %ld spp", held);
    cli_run(ARGS(SCENE, "-q", "--device", "0", SIZE, "--spp", SPP_TEXT, "-o", path_out, "--resume", path_ck), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(files_equal(path_ref, path_out), "the image resumed after SIGINT differs");
}

/* An interrupt drops the batch in flight whole: the image and the checkpoint hold whole
 * batches only, the same bits as a render of that many samples, and a resume from the
 * checkpoint ends with the image of a render never interrupted. */
static void test_sigint_keeps_whole_batches(void)
{
#define BIG "--width", "160", "--height", "120"
    char ref_part[160], ref_full[160], held_text[16];
    snprintf(ref_part, sizeof ref_part, "%s/part.pfm", dir);
    snprintf(ref_full, sizeof ref_full, "%s/full.pfm", dir);
    unlink(path_ck);
    CliChild c = cli_start(ARGS(SCENE, "--device", "scalar", BIG, "--spp", "64", "--batch", "16", "-o", path_out,
                                "--checkpoint", path_ck, "--checkpoint-interval", "0.05"));
    double t0 = timer_now();
    while (checkpoint_samples(path_ck) <= 0 && timer_now() - t0 < 30.0) sleep_s(0.005);
    kill(c.pid, SIGINT);   /* most likely part-way through the second batch */
    cli_finish(c, &r);
    CHECK_EQ_INT(r.status, 6);
    long held = checkpoint_samples(path_ck);
    CHECK_MSG(held > 0 && held < 64 && held % 16 == 0, "the checkpoint after SIGINT holds %ld spp", held);
    snprintf(held_text, sizeof held_text, "%ld", held);
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", BIG, "--spp", held_text, "-o", ref_part), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(files_equal(ref_part, path_out), "the image after SIGINT differs from a %ld spp render", held);
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", BIG, "--spp", "64", "-o", path_out, "--resume", path_ck), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", BIG, "--spp", "64", "-o", ref_full), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(files_equal(ref_full, path_out), "the image resumed after SIGINT differs from an uninterrupted one");
    unlink(ref_part);
    unlink(ref_full);
#undef BIG
}

static void test_other_renders_are_refused(void)
{
    /* path_ck holds the finished render of the tests above */
    char msg[512];
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", SIZE, "--spp", "401", "-o", path_out, "--resume", path_ck), &r);
    CHECK_EQ_INT(r.status, 3);
    snprintf(msg, sizeof msg, "clpt: error: checkpoint '%s' is a render of 1200 samples per pixel, this render asks "
             "for 401; a resume can add samples, never take them away (resume with --spp 1200 or more)\n", path_ck);
    CHECK_STR_CONTAINS(r.err, msg);
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", "--width", "36", "--height", "48", "--spp", SPP_TEXT, "-o",
                 path_out, "--resume", path_ck), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_STR_CONTAINS(r.err, "48x36");
    /* another scene with every setting forced equal: only the key tells them apart */
    cli_run(ARGS("scenes/one-weekend.scene", "-q", "--device", "scalar", SIZE, "--spp", SPP_TEXT, "--seed", "1",
                 "--max-depth", "8", "-o", path_out, "--resume", path_ck), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_STR_CONTAINS(r.err, "scene differs");
    /* the same scene and settings with the other sampler: other random numbers */
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", SIZE, "--spp", SPP_TEXT, "--sampler", "independent", "-o",
                 path_out, "--resume", path_ck), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_STR_CONTAINS(r.err, "sampler, shadows or --accel setting");
    /* ... or the other tree: its buffers are part of the key (the two trees give the
     * same hits but on surfaces of revolution, whose last bits depend on the walk) */
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", SIZE, "--spp", SPP_TEXT, "--accel", "kdtree", "-o", path_out,
                 "--resume", path_ck), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_STR_CONTAINS(r.err, "sampler, shadows or --accel setting");
    /* not a checkpoint at all, and no file */
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", SIZE, "--spp", SPP_TEXT, "-o", path_out, "--resume", path_ref), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_STR_CONTAINS(r.err, "not a usable clpt checkpoint");
    char missing[160];
    snprintf(missing, sizeof missing, "%s/missing.ckpt", dir);
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", SIZE, "-o", path_out, "--resume", missing), &r);
    CHECK_EQ_INT(r.status, 4);
    cli_run(ARGS(SCENE, "-q", "--checkpoint-interval", "5"), &r);
    CHECK_EQ_INT(r.status, 2);
}

/* Adding samples to a finished render: 4 spp, then resumed to 16 (on PoCL, then on
 * PoCL and the scalar device together), is the straight 16-spp render bit for bit, and
 * so is 4 grown to 9 on the scalar device alone. */
static void test_a_finished_render_grows(void)
{
#define GROW "--width", "40", "--height", "30"
    char ref16[160], ref9[160];
    snprintf(ref16, sizeof ref16, "%s/ref16.pfm", dir);
    snprintf(ref9, sizeof ref9, "%s/ref9.pfm", dir);
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", GROW, "--spp", "16", "-o", ref16), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", GROW, "--spp", "9", "-o", ref9), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    const char *devices[][2] = { { "0", "0,scalar" }, { "scalar", "scalar" } };
    const char *grown[] = { "16", "9" };
    const char *refs[] = { ref16, ref9 };
    for (int k = 0; k < 2; k++) {
        unlink(path_ck);
        cli_run(ARGS(SCENE, "-q", "--device", devices[k][0], GROW, "--spp", "4", "-o", path_out, "--checkpoint",
                     path_ck), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_EQ_INT(checkpoint_samples(path_ck), 4);
        cli_run(ARGS(SCENE, "--device", devices[k][1], GROW, "--spp", grown[k], "--batch", "2", "-o", path_out,
                     "--resume", path_ck), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_STR_CONTAINS(r.err, "4 samples per pixel already done, growing the render from 4 to");
        CHECK_MSG(files_equal(refs[k], path_out), "4 spp grown to %s differs from a straight %s-spp render",
                  grown[k], grown[k]);
        CHECK_EQ_INT(checkpoint_samples(path_ck), atol(grown[k]));
    }
    /* and it can no longer shrink back */
    cli_run(ARGS(SCENE, "-q", "--device", "scalar", GROW, "--spp", "4", "-o", path_out, "--resume", path_ck), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_STR_CONTAINS(r.err, "a resume can add samples, never take them away (resume with --spp 9 or more)");
    unlink(ref16);
    unlink(ref9);
#undef GROW
}

/* The whitted integrator's pixel grid follows the samples per pixel (a 2x2 grid at 4, a
 * 3x3 at 9): such a render grows only to a count placed alike (2 -> 3, both jittered),
 * and says why otherwise. */
static void test_whitted_grows_only_on_its_grid(void)
{
#define WHITTED "scenes/classic/spheres.txt", "-q", "--device", "scalar", "--width", "32", "--height", "24"
    char msg[512], ref[160];
    snprintf(ref, sizeof ref, "%s/whitted3.pfm", dir);
    unlink(path_ck);
    cli_run(ARGS(WHITTED, "--spp", "4", "-o", path_out, "--checkpoint", path_ck), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(WHITTED, "--spp", "9", "-o", path_out, "--resume", path_ck), &r);
    CHECK_EQ_INT(r.status, 3);
    snprintf(msg, sizeof msg, "clpt: error: checkpoint '%s' is a whitted render of 4 samples per pixel, placed in a "
             "2x2 grid; 9 would be placed in a 3x3 grid, so it cannot grow to 9 (resume with --spp 4, or a count "
             "placed alike)\n", path_ck);
    CHECK_STR_CONTAINS(r.err, msg);
    unlink(path_ck);
    cli_run(ARGS(WHITTED, "--spp", "2", "-o", path_out, "--checkpoint", path_ck), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(WHITTED, "--spp", "3", "-o", path_out, "--resume", path_ck), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(WHITTED, "--spp", "3", "-o", ref), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(files_equal(ref, path_out), "a whitted render grown from 2 to 3 spp differs from a straight one");
    unlink(ref);
#undef WHITTED
}

int main(void)
{
    /* before anything loads the OpenCL ICD: two PoCL CPU devices */
    setenv("POCL_DEVICES", "pthread pthread", 1);
    make_dir();
    RUN(test_write_read_round_trip);
    RUN(test_damaged_files_are_refused);
    RUN(test_film_values_are_bounded);
    RUN(test_denoise_features_round_trip);
    RUN(test_render_key);
    RUN(test_render_key_covers_every_scene_buffer);
    RUN(render_reference);
    RUN(test_sigkill_then_resume_gives_the_same_image);
    RUN(test_sigint_writes_a_checkpoint);
    RUN(test_other_renders_are_refused);
    RUN(test_sigint_keeps_whole_batches);
    RUN(test_a_finished_render_grows);
    RUN(test_whitted_grows_only_on_its_grid);
    remove_dir();
    return harness_report();
}
