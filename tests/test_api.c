/* test_api.c — the public C interface (include/clpt/clpt.h) through libclpt.so, as a
 * user's program sees it: its errors word for word, the render against the program's
 * bits, cancelling, checkpoints, two contexts at once, and the example program. */
#include <clpt/clpt.h>

#include <pthread.h>
#include <stdint.h>

#include "cli_util.h"
#include "harness.h"

#define SCENE "scenes/cornell-box.scene"
#define W 64
#define H 48

/* A PFM file (rows bottom to top) as floats top row first; NULL when unreadable. */
static float *pfm_read(const char *path, unsigned *w, unsigned *h)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    float scale = 0.0f;
    char kind[3] = { 0 };
    float *rgb = NULL;
    if (fscanf(f, "%2s %u %u %f", kind, w, h, &scale) == 4 && fgetc(f) == '\n' && strcmp(kind, "PF") == 0) {
        size_t row = (size_t)*w * 3;
        rgb = malloc(row * *h * sizeof *rgb);
        for (unsigned y = *h; rgb && y-- > 0;)
            if (fread(rgb + y * row, sizeof *rgb, row, f) != row) {
                free(rgb);
                rgb = NULL;
            }
    }
    fclose(f);
    return rgb;
}

/* The program's image of SCENE with `flags` (a NULL-ended list) as floats. */
static float *cli_render(const char *out, const char *const *flags)
{
    const char *args[40] = { SCENE, "-q", "-o", out };
    size_t n = 4;
    for (size_t i = 0; flags[i] && n < 39; i++) args[n++] = flags[i];
    args[n] = NULL;
    CliResult *r = malloc(sizeof *r);
    cli_run(args, r);
    CHECK_MSG(r->status == 0, "clpt exited %d: %s", r->status, r->err);
    free(r);
    unsigned w = 0, h = 0;
    float *rgb = pfm_read(out, &w, &h);
    CHECK(rgb && w == W && h == H);
    return rgb;
}

typedef struct {
    clpt_context *ctx;
    clpt_scene *scene;
    clpt_settings *set;
} Api;

/* A context on `devices`, the Cornell box, and settings name=value pairs (NULL-ended). */
static int api_open(Api *a, const char *devices, const char *const *pairs)
{
    a->ctx = clpt_context_create();
    a->set = clpt_settings_create(a->ctx);
    a->scene = NULL;
    clpt_status st = clpt_context_set_devices(a->ctx, devices);
    if (st == CLPT_OK) st = clpt_scene_load(a->ctx, SCENE, &a->scene);
    for (size_t i = 0; pairs[i] && st == CLPT_OK; i += 2) st = clpt_settings_set(a->set, pairs[i], pairs[i + 1]);
    CHECK_MSG(st == CLPT_OK, "%s", clpt_last_error(a->ctx));
    return st == CLPT_OK;
}

static void api_close(Api *a)
{
    clpt_scene_free(a->scene);
    clpt_settings_free(a->set);
    clpt_context_free(a->ctx);
}

static const char *const small[] = { "width", "64", "height", "48", "spp", "4", "threads", "2", NULL };

/* Renders with the image's buffers; returns the status. */
static clpt_status api_render(Api *a, clpt_image *img, clpt_progress_fn fn, void *user)
{
    unsigned w = 0, h = 0;
    clpt_status st = clpt_render_size(a->scene, a->set, &w, &h);
    CHECK(st == CLPT_OK && w == W && h == H);
    img->width = w;
    img->height = h;
    return clpt_render(a->scene, a->set, img, fn, user);
}

static int same_floats(const float *a, const float *b, size_t n)
{
    return a && b && memcmp(a, b, n * sizeof *a) == 0;
}

static void test_version_and_devices(void)
{
    char v[32];
    snprintf(v, sizeof v, "%d.%d.%d", CLPT_VERSION_MAJOR, CLPT_VERSION_MINOR, CLPT_VERSION_PATCH);
    CHECK(strcmp(clpt_version(), v) == 0);
    clpt_context *ctx = clpt_context_create();
    size_t n = clpt_device_count(ctx);
    CHECK(n >= 1);
    /* the scalar device is always there, and last */
    CHECK(n >= 1 && strcmp(clpt_device_kind(ctx, n - 1), "scalar") == 0);
    CHECK(clpt_device_index(ctx, n - 1) == -1);
    CHECK(clpt_device_name(ctx, n) == NULL);
    clpt_context_free(ctx);
}

static void test_errors(void)
{
    clpt_context *ctx = clpt_context_create();
    clpt_settings *set = clpt_settings_create(ctx);
    clpt_scene *s = (clpt_scene *)&s;
    CHECK(clpt_scene_load(ctx, "/nonexistent/x.scene", &s) == CLPT_ERROR_IO && s == NULL);
    CHECK(strcmp(clpt_last_error(ctx), "cannot open '/nonexistent/x.scene': No such file or directory") == 0);
    CHECK(clpt_scene_load_string(ctx, "camera { fov wide }", 19, "bad.scene", &s) == CLPT_ERROR_INPUT);
    CHECK(strcmp(clpt_last_error(ctx), "bad.scene:1:14: expected a number of degrees in (0, 180) for 'fov', "
                                       "found 'wide'") == 0);
    CHECK(clpt_settings_set(set, "spp2", "4") == CLPT_ERROR_USAGE);
    CHECK(strcmp(clpt_last_error(ctx), "unknown option 'spp2'") == 0);
    CHECK(clpt_settings_set(set, "spp", "0") == CLPT_ERROR_USAGE);
    CHECK(strcmp(clpt_last_error(ctx), "--spp must be between 1 and 1000000, got 0") == 0);
    CHECK(clpt_settings_set(set, "integrator", "foo") == CLPT_ERROR_USAGE);
    CHECK(strcmp(clpt_last_error(ctx), "--integrator expects 'path' or 'whitted', got 'foo'") == 0);
    CHECK(clpt_settings_set(set, "output", "x.png") == CLPT_ERROR_USAGE);
    CHECK(strcmp(clpt_last_error(ctx), "'output' is not a render setting: the library renders into your memory "
                                       "(clpt_image)") == 0);
    CHECK(clpt_settings_set(set, "--spp", "8") == CLPT_OK && clpt_last_error(ctx)[0] == '\0');
    CHECK(clpt_context_set_devices(ctx, "nosuchdevice") == CLPT_ERROR_USAGE);
    CHECK_STR_CONTAINS(clpt_last_error(ctx), "no device matches 'nosuchdevice'; the devices are: ");
    CHECK(clpt_scene_load(ctx, SCENE, &s) == CLPT_OK);
    CHECK(clpt_scene_set(s, "camera.fvo", "40") == CLPT_ERROR_USAGE);
    CHECK(strcmp(clpt_last_error(ctx), "unknown scene parameter 'camera.fvo': the camera has from, eye, at, "
                                       "look_at, up, fov, aperture, focus, width (did you mean 'fov'?)") == 0);
    CHECK(clpt_scene_set(s, "material.rde.albedo", "1") == CLPT_ERROR_USAGE);
    CHECK(strcmp(clpt_last_error(ctx), "scene parameter 'material.rde.albedo': the scene has no material named "
                                       "'rde' (did you mean 'red'?)") == 0);
    CHECK(clpt_scene_set(s, "camera.fov", "200") == CLPT_ERROR_USAGE);
    CHECK(strcmp(clpt_last_error(ctx), "scene parameter 'camera.fov' expects a number in (0, 180), got '200'") == 0);
    /* a buffer of the wrong size is refused before anything is rendered */
    float one[3];
    clpt_image img = { 1, 1, one, NULL, NULL, NULL, 0 };
    CHECK(clpt_render(s, set, &img, NULL, NULL) == CLPT_ERROR_USAGE);
    CHECK_STR_CONTAINS(clpt_last_error(ctx), "the image is 1x1, the render ");
    clpt_scene_free(s);
    clpt_settings_free(set);
    clpt_context_free(ctx);
}

/* The library's image (`spp` samples per pixel) is the program's .pfm, bit for bit;
 * CLPT_ERROR_DEVICE when the library cannot render it (no Open Image Denoise), else
 * CLPT_OK. */
static clpt_status check_same_as_cli_spp(const char *devices, unsigned spp, const char *const *extra_pairs,
                                         const char *const *extra_flags)
{
    const char *pairs[32];
    size_t n = 0;
    for (size_t i = 0; small[i]; i++) pairs[n++] = small[i];
    for (size_t i = 0; extra_pairs[i]; i++) pairs[n++] = extra_pairs[i];
    pairs[n] = NULL;
    Api a;
    if (!api_open(&a, devices, pairs)) {
        api_close(&a);
        return CLPT_ERROR_USAGE;
    }
    float *rgb = malloc(W * H * 3 * sizeof *rgb);
    clpt_image img = { 0, 0, rgb, NULL, NULL, NULL, 0 };
    clpt_status st = api_render(&a, &img, NULL, NULL);
    if (st == CLPT_ERROR_DEVICE && strstr(clpt_last_error(a.ctx), "needs Intel Open Image Denoise")) {
        printf("     (skipped: %s)\n", clpt_last_error(a.ctx));
        free(rgb);
        api_close(&a);
        return st;
    }
    CHECK_MSG(st == CLPT_OK, "%s", clpt_last_error(a.ctx));
    CHECK_MSG(img.spp == spp, "%u spp", img.spp);
    const char *flags[32] = { "--device", devices, "--width", "64", "--height", "48", "--spp", "4", "--threads", "2" };
    n = 10;
    for (size_t i = 0; extra_flags[i]; i++) flags[n++] = extra_flags[i];
    flags[n] = NULL;
    float *cli = cli_render(TEST_TMP("clpt-test-api-cli.pfm"), flags);
    CHECK_MSG(same_floats(rgb, cli, W * H * 3), "devices %s", devices);
    free(cli);
    free(rgb);
    api_close(&a);
    return CLPT_OK;
}

/* The same at the 4 samples per pixel of `small`. */
static void check_same_as_cli(const char *devices, const char *const *extra_pairs, const char *const *extra_flags)
{
    check_same_as_cli_spp(devices, 4, extra_pairs, extra_flags);
}

static void test_same_as_cli(void)
{
    static const char *const none[] = { NULL };
    check_same_as_cli("scalar", none, none);
    check_same_as_cli(TEST_OPENCL, none, none);
    static const char *const pairs[] = { "seed", "7", "max-depth", "3", "sampler", "independent", NULL };
    static const char *const flags[] = { "--seed", "7", "--max-depth", "3", "--sampler", "independent", NULL };
    check_same_as_cli("scalar", pairs, flags);
    /* --set through the settings, as on the command line */
    static const char *const set_pairs[] = { "set", "material.red.albedo=0.1,0.2,0.9", NULL };
    static const char *const set_flags[] = { "--set", "material.red.albedo=0.1,0.2,0.9", NULL };
    check_same_as_cli("scalar", set_pairs, set_flags);
}

typedef struct {
    unsigned calls, last_done, total, cancel_at;
} Progress;

static int on_progress(void *user, unsigned done, unsigned total)
{
    Progress *p = user;
    p->calls++;
    p->last_done = done;
    p->total = total;
    return p->cancel_at && done >= p->cancel_at;
}

/* noise_threshold is the program's --noise-threshold: adaptive sampling gives the same
 * bits through the library, on the scalar and the OpenCL CPU device; img.spp is the
 * most a pixel got. */
static void test_adaptive_same_as_cli(void)
{
    static const char *const pairs[] = { "spp", "48", "noise-threshold", "0.05", "min-spp", "8", NULL };
    static const char *const flags[] = { "--spp", "48", "--noise-threshold", "0.05", "--min-spp", "8", NULL };
    check_same_as_cli_spp("scalar", 48, pairs, flags);
    check_same_as_cli_spp(TEST_OPENCL, 48, pairs, flags);
    /* progress comes after each round, and a cancel stops at the next one */
    static const char *const more[] = { "width", "64", "height", "48", "spp", "512", "threads", "2",
                                        "noise-threshold", "0.0001", "min-spp", "8", NULL };
    Api a;
    if (!api_open(&a, "scalar", more)) {
        api_close(&a);
        return;
    }
    float *rgb = malloc(W * H * 3 * sizeof *rgb);
    clpt_image img = { 0, 0, rgb, NULL, NULL, NULL, 0 };
    Progress p = { 0, 0, 0, 16 };
    clpt_status st = api_render(&a, &img, on_progress, &p);
    CHECK_MSG(st == CLPT_INTERRUPTED, "%d: %s", st, clpt_last_error(a.ctx));
    CHECK(p.calls >= 1 && p.total == 512 && p.last_done >= 16);
    CHECK_MSG(img.spp >= 16 && img.spp < 512, "%u spp", img.spp);
    free(rgb);
    api_close(&a);
}

/* denoise is the program's --denoise: the denoised image's bits, where Open Image
 * Denoise is found (build/oidn, from `sh tools/deps.sh oidn`); without it the library
 * refuses as the program does, before rendering. */
static void test_denoise_same_as_cli(void)
{
    static const char *const pairs[] = { "denoise", "1", NULL };
    static const char *const flags[] = { "--denoise", NULL };
    check_same_as_cli("scalar", pairs, flags);
    /* with the features also asked for: the denoiser uses the caller's buffers */
    Api a;
    static const char *const both[] = { "width", "64", "height", "48", "spp", "4", "threads", "2", "denoise", "on",
                                        NULL };
    if (!api_open(&a, "scalar", both)) {
        api_close(&a);
        return;
    }
    float *rgb = malloc(W * H * 3 * sizeof *rgb), *albedo = malloc(W * H * 3 * sizeof *albedo);
    clpt_image img = { 0, 0, rgb, albedo, NULL, NULL, 0 };
    clpt_status st = api_render(&a, &img, NULL, NULL);
    if (st != CLPT_ERROR_DEVICE) {
        CHECK_MSG(st == CLPT_OK, "%s", clpt_last_error(a.ctx));
        float *cli = pfm_read(TEST_TMP("clpt-test-api-cli.pfm"), &img.width, &img.height);
        CHECK(same_floats(rgb, cli, W * H * 3));
        free(cli);
    }
    free(albedo);
    free(rgb);
    api_close(&a);
}

/* clpt_scene_set is --set: the same image as the program with the same edits. */
static void test_scene_set(void)
{
    Api a;
    if (!api_open(&a, "scalar", small)) {
        api_close(&a);
        return;
    }
    CHECK(clpt_scene_set(a.scene, "camera.fov", "50") == CLPT_OK);
    CHECK(clpt_scene_set(a.scene, "material.light.radiance", "30,30,30") == CLPT_OK);
    float *rgb = malloc(W * H * 3 * sizeof *rgb);
    clpt_image img = { 0, 0, rgb, NULL, NULL, NULL, 0 };
    CHECK_MSG(api_render(&a, &img, NULL, NULL) == CLPT_OK, "%s", clpt_last_error(a.ctx));
    static const char *const flags[] = { "--device", "scalar", "--width", "64", "--height", "48", "--spp", "4",
                                         "--set", "camera.fov=50", "--set", "material.light.radiance=30,30,30",
                                         NULL };
    float *cli = cli_render(TEST_TMP("clpt-test-api-set.pfm"), flags);
    CHECK(same_floats(rgb, cli, W * H * 3));
    free(cli);
    free(rgb);
    api_close(&a);
}

/* A scene from a string renders as the same scene from its file. */
static void test_scene_from_string(void)
{
    FILE *f = fopen(SCENE, "rb");
    char *text = malloc(1 << 16);
    size_t len = f ? fread(text, 1, (1 << 16) - 1, f) : 0;
    if (f) fclose(f);
    Api a;
    if (!api_open(&a, "scalar", small)) {
        api_close(&a);
        free(text);
        return;
    }
    clpt_scene *s2 = NULL;
    CHECK(clpt_scene_load_string(a.ctx, text, len, SCENE, &s2) == CLPT_OK);
    float *a_rgb = malloc(W * H * 3 * sizeof *a_rgb), *b_rgb = malloc(W * H * 3 * sizeof *b_rgb);
    clpt_image ia = { W, H, a_rgb, NULL, NULL, NULL, 0 }, ib = { W, H, b_rgb, NULL, NULL, NULL, 0 };
    CHECK(clpt_render(a.scene, a.set, &ia, NULL, NULL) == CLPT_OK);
    CHECK(clpt_render(s2, a.set, &ib, NULL, NULL) == CLPT_OK);
    CHECK(same_floats(a_rgb, b_rgb, W * H * 3));
    clpt_scene_free(s2);
    free(a_rgb);
    free(b_rgb);
    free(text);
    api_close(&a);
}

/* Albedo and depth are the program's --aov images (.pfm: the albedo as it is, the
 * distance in every channel); the normal is unit length where something is hit. */
static void test_aovs(void)
{
    Api a;
    if (!api_open(&a, "scalar", small)) {
        api_close(&a);
        return;
    }
    float *rgb = malloc(W * H * 3 * sizeof *rgb), *albedo = malloc(W * H * 3 * sizeof *albedo);
    float *normal = malloc(W * H * 3 * sizeof *normal), *depth = malloc(W * H * sizeof *depth);
    clpt_image img = { 0, 0, rgb, albedo, normal, depth, 0 };
    CHECK_MSG(api_render(&a, &img, NULL, NULL) == CLPT_OK, "%s", clpt_last_error(a.ctx));
    static const char *const flags[] = { "--device", "scalar", "--width", "64", "--height", "48", "--spp", "4",
                                         "--aov", "albedo,depth", NULL };
    free(cli_render(TEST_TMP("clpt-test-api-aov.pfm"), flags));
    unsigned w, h;
    float *cli_albedo = pfm_read(TEST_TMP("clpt-test-api-aov-albedo.pfm"), &w, &h);
    float *cli_depth = pfm_read(TEST_TMP("clpt-test-api-aov-depth.pfm"), &w, &h);
    CHECK(same_floats(albedo, cli_albedo, W * H * 3));
    int depth_same = cli_depth != NULL;
    size_t unit = 0, longer = 0;
    for (size_t i = 0; cli_depth && i < W * H; i++) {
        if (memcmp(&depth[i], &cli_depth[3 * i], sizeof *depth) != 0) depth_same = 0;
        /* a pixel whose samples hit one surface has a unit mean normal (shorter along
         * edges, 0 where nothing is hit); none is longer */
        float len = sqrtf(normal[3 * i] * normal[3 * i] + normal[3 * i + 1] * normal[3 * i + 1] +
                          normal[3 * i + 2] * normal[3 * i + 2]);
        unit += len > 0.999f && len < 1.001f;
        longer += len >= 1.001f;
    }
    CHECK(depth_same);
    CHECK_MSG(unit > W * H / 2 && longer == 0, "%zu unit normals, %zu longer", unit, longer);
    free(cli_albedo);
    free(cli_depth);
    free(rgb);
    free(albedo);
    free(normal);
    free(depth);
    api_close(&a);
}

/* The progress callback cancels: the render stops with the whole batches finished. */
static void test_cancel(void)
{
    static const char *const pairs[] = { "width", "64", "height", "48", "spp", "512", "batch", "1", "threads", "2",
                                         NULL };
    Api a;
    if (!api_open(&a, "scalar", pairs)) {
        api_close(&a);
        return;
    }
    float *rgb = malloc(W * H * 3 * sizeof *rgb);
    clpt_image img = { 0, 0, rgb, NULL, NULL, NULL, 0 };
    Progress p = { 0, 0, 0, 2 };
    clpt_status st = api_render(&a, &img, on_progress, &p);
    CHECK_MSG(st == CLPT_INTERRUPTED, "%d: %s", st, clpt_last_error(a.ctx));
    CHECK_STR_CONTAINS(clpt_last_error(a.ctx), "cancelled: ");
    CHECK(img.spp >= 2 && img.spp < 512);
    CHECK(p.total == 512 && p.calls >= 1);
    free(rgb);
    api_close(&a);
}

/* Cancelled with a checkpoint, then resumed: the bits of the render never cancelled. */
static void test_checkpoint_resume(void)
{
    const char *ck = TEST_TMP("clpt-test-api.ckpt");
    remove(ck);
    /* 512 samples, so that the cancel after 4 lands mid-render on a fast, idle machine
     * too (at 64 all were rendered before the callback's answer was seen) */
    static const char *const pairs[] = { "width", "64", "height", "48", "spp", "512", "batch", "2", "threads", "2",
                                         NULL };
    Api a;
    if (!api_open(&a, "scalar", pairs)) {
        api_close(&a);
        return;
    }
    float *full = malloc(W * H * 3 * sizeof *full), *resumed = malloc(W * H * 3 * sizeof *resumed);
    clpt_image img = { 0, 0, full, NULL, NULL, NULL, 0 };
    CHECK(api_render(&a, &img, NULL, NULL) == CLPT_OK);
    CHECK(clpt_settings_set(a.set, "checkpoint", ck) == CLPT_OK);
    img.rgb = resumed;
    Progress p = { 0, 0, 0, 4 };
    CHECK(api_render(&a, &img, on_progress, &p) == CLPT_INTERRUPTED);
    CHECK_MSG(img.spp < 512 && file_exists(ck), "%u spp, checkpoint %s: %s", img.spp,
              file_exists(ck) ? "written" : "missing", clpt_last_error(a.ctx));
    CHECK(clpt_settings_set(a.set, "resume", ck) == CLPT_OK);
    CHECK_MSG(api_render(&a, &img, NULL, NULL) == CLPT_OK, "%s", clpt_last_error(a.ctx));
    CHECK(img.spp == 512);
    CHECK(same_floats(full, resumed, W * H * 3));
    remove(ck);
    free(full);
    free(resumed);
    api_close(&a);
}

/* Two contexts in one process, rendering at the same time on two threads, each give the
 * image one alone gives. */
typedef struct {
    const char *seed;
    float *rgb;
    clpt_status st;
} Job;

static void *render_job(void *vj)
{
    Job *j = vj;
    const char *pairs[] = { "width", "64", "height", "48", "spp", "4", "threads", "1", "seed", j->seed, NULL };
    Api a;
    j->st = CLPT_ERROR_INTERNAL;
    if (api_open(&a, "scalar", pairs)) {
        clpt_image img = { W, H, j->rgb, NULL, NULL, NULL, 0 };
        j->st = clpt_render(a.scene, a.set, &img, NULL, NULL);
    }
    api_close(&a);
    return NULL;
}

static void test_two_contexts(void)
{
    Job jobs[2] = { { "1", malloc(W * H * 3 * sizeof(float)), 0 }, { "2", malloc(W * H * 3 * sizeof(float)), 0 } };
    pthread_t t[2];
    for (int i = 0; i < 2; i++) pthread_create(&t[i], NULL, render_job, &jobs[i]);
    for (int i = 0; i < 2; i++) pthread_join(t[i], NULL);
    CHECK(jobs[0].st == CLPT_OK && jobs[1].st == CLPT_OK);
    Job alone = { "2", malloc(W * H * 3 * sizeof(float)), 0 };
    render_job(&alone);
    CHECK(alone.st == CLPT_OK && same_floats(alone.rgb, jobs[1].rgb, W * H * 3));
    CHECK(!same_floats(jobs[0].rgb, jobs[1].rgb, W * H * 3));
    free(alone.rgb);
    free(jobs[0].rgb);
    free(jobs[1].rgb);
}

/* examples/render.c writes the program's .pfm, byte for byte. */
static void test_example_program(void)
{
    const char *out = TEST_TMP("clpt-test-api-example.pfm");
    char command[1024];
    snprintf(command, sizeof command,
             CLPT_BUILD_DIR "/examples/render " SCENE " '%s' --device=scalar "
             "--width=64 --height=48 --spp=4 --set=camera.fov=45 2>/dev/null", out);
    int status = system(command);
    CHECK_MSG(status == 0, "build/examples/render: status %d", status);
    static const char *const flags[] = { "--device", "scalar", "--width", "64", "--height", "48", "--spp", "4",
                                         "--set", "camera.fov=45", NULL };
    free(cli_render(TEST_TMP("clpt-test-api-example-cli.pfm"), flags));
    CHECK(files_equal(out, TEST_TMP("clpt-test-api-example-cli.pfm")));
}

int main(void)
{
    RUN(test_version_and_devices);
    RUN(test_errors);
    RUN(test_same_as_cli);
    RUN(test_adaptive_same_as_cli);
    RUN(test_denoise_same_as_cli);
    RUN(test_scene_set);
    RUN(test_scene_from_string);
    RUN(test_aovs);
    RUN(test_cancel);
    RUN(test_checkpoint_resume);
    RUN(test_two_contexts);
    RUN(test_example_program);
    return harness_report();
}
