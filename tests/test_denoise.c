/*
 * test_denoise.c — --denoise (Open Image Denoise, render/denoise.h): without the library
 * the exact message, before anything is rendered; with it (build/oidn, from `sh
 * tools/deps.sh oidn`), a 16-spp Cornell box comes out finite and much nearer a
 * converged reference (RMSE and SSIM), also after a resume and from `clpt merge`, and
 * an EXR output keeps the noisy colour and the features as channels. Without the
 * library too: the features are those of the surface seen through a mirror or clear
 * glass, the same on the scalar device and OpenCL, while --aov's images stay first-hit.
 */
#include "harness.h"

#include "cli_util.h"
#include "image_metrics.h"
#include "render_util.h"
#include "render/denoise.h"
#include "util/kmath.h"

#define SCENE "scenes/cornell-box.scene"
#define SIZE "96"

static char dir[] = "/tmp/clpt-denoise-XXXXXX";
static char path_buf[8][512];
static int have_oidn;

/* A file in the test's folder (one of a few static buffers, by slot). */
static const char *tmp_path(int slot, const char *name)
{
    snprintf(path_buf[slot], sizeof path_buf[slot], "%s/%s", dir, name);
    return path_buf[slot];
}

/* clpt SCENE at SIZE x SIZE with spp samples, then the extra arguments; 0 on success. */
static int render(const char *spp, const char *out, const char *a, const char *b, const char *c, const char *d)
{
    const char *args[] = { SCENE, "-q", "--width", SIZE, "--height", SIZE, "--spp", spp, "-o", out, a, b, c, d, NULL };
    CliResult r;
    cli_run(args, &r);
    if (r.status != 0) fprintf(stderr, "  clpt -o %s failed (%d): %s\n", out, r.status, r.err);
    return r.status;
}

/* A part rendered with --denoise: samples `range` of spp, its features kept in `ckpt`. */
static int render_denoise_part(const char *spp, const char *out, const char *range, const char *ckpt)
{
    const char *args[] = { SCENE, "-q", "--width", SIZE, "--height", SIZE, "--spp", spp, "-o", out, "--denoise",
                           "--sample-range", range, "--checkpoint", ckpt, NULL };
    CliResult r;
    cli_run(args, &r);
    if (r.status != 0) fprintf(stderr, "  clpt -o %s failed (%d): %s\n", out, r.status, r.err);
    return r.status;
}

static float *reference;
static unsigned char away[96 * 96];   /* 1: away from the lamp (metrics_emitter_mask) */

/* A PFM image's error against the reference: RMSE over the whole image and away from
 * the lamp, and SSIM; all -1 when it is unreadable or not finite. */
typedef struct {
    double rmse, rmse_away, ssim;
} ImageError;

static ImageError error_of(const char *path)
{
    unsigned w = 0, h = 0;
    float *img = metrics_read_pfm(path, &w, &h);
    ImageError e = { -1.0, -1.0, -1.0 };
    if (img && w == 96 && h == 96 && metrics_all_finite(img, (size_t)w * h)) {
        e.rmse = metrics_rmse(img, reference, (size_t)w * h);
        e.rmse_away = metrics_rmse_masked(img, reference, away, (size_t)w * h);
        e.ssim = metrics_ssim(img, reference, w, h);
    }
    free(img);
    return e;
}

static const char expected_missing[] =
    "clpt: error: --denoise needs Intel Open Image Denoise 2 (libOpenImageDenoise.so.2), which is not in '%s' "
    "(named by CLPT_OIDN_DIR); fetch it with: sh tools/deps.sh oidn (./run.sh does too)\n";

/* An empty folder as the only place to look: the message, exit status 5, at once (no
 * image written), from a render and from merge alike. */
static void test_missing_library_message(void)
{
    const char *empty = tmp_path(0, "empty");
    CHECK(mkdir(empty, 0700) == 0);
    setenv(DENOISE_DIR_ENV, empty, 1);
    char want[1024];
    snprintf(want, sizeof want, expected_missing, empty);
    const char *out = tmp_path(1, "never.png");
    const char *args[] = { SCENE, "--denoise", "-o", out, NULL };
    CliResult r;
    cli_run(args, &r);
    CHECK(r.status == 5);
    CHECK_MSG(strcmp(r.err, want) == 0, "got: %s", r.err);
    CHECK(!file_exists(out));
    const char *margs[] = { "merge", "--denoise", "-o", out, "no-such-part.ckpt", NULL };
    cli_run(margs, &r);
    CHECK(r.status == 5);
    CHECK_MSG(strcmp(r.err, want) == 0, "got: %s", r.err);
    Denoiser *d = (Denoiser *)1;
    Error err = { 0 };
    CHECK(denoiser_open(&d, &err) == ST_DEVICE);
    CHECK(d == NULL);
    error_clear(&err);
    unsetenv(DENOISE_DIR_ENV);
    rmdir(empty);
}

/* The converged image the others are measured against (1024 spp), and the pixels
 * away from its lamp (6 pixels from any brighter than 2). */
static int make_reference(void)
{
    const char *ref = tmp_path(2, "ref.pfm");
    unsigned w = 0, h = 0;
    if (render("1024", ref, NULL, NULL, NULL, NULL) != 0) return 0;
    reference = metrics_read_pfm(ref, &w, &h);
    if (!reference || w != 96 || h != 96) return 0;
    metrics_emitter_mask(reference, w, h, 2.0f, 6, away);
    return 1;
}

static void print_error(const char *what, ImageError e)
{
    fprintf(stderr, "  %-34s RMSE %.5f (away from the lamp %.5f), SSIM %.4f\n", what, e.rmse, e.rmse_away, e.ssim);
}

/* 16 spp denoised against 16 spp as rendered: away from the lamp the error falls to
 * under half; over the whole image the structure (SSIM) rises; every value is finite. */
static void test_denoise_lowers_error(void)
{
    const char *noisy = tmp_path(3, "noisy.pfm"), *den = tmp_path(4, "denoised.pfm");
    CHECK(render("16", noisy, NULL, NULL, NULL, NULL) == 0);
    CHECK(render("16", den, "--denoise", NULL, NULL, NULL) == 0);
    ImageError n = error_of(noisy), d = error_of(den);
    print_error("16 spp:", n);
    print_error("16 spp denoised:", d);
    CHECK(n.rmse > 0.0 && d.rmse > 0.0);
    CHECK_MSG(d.rmse_away < 0.5 * n.rmse_away, "denoised RMSE %g, noisy %g", d.rmse_away, n.rmse_away);
    CHECK_MSG(d.ssim > n.ssim + 0.03, "denoised SSIM %g, noisy %g", d.ssim, n.ssim);
    /* with the lamp's emission left out of the denoiser and added back, the lamp and
     * its edge no longer outweigh the rest: the whole image's error falls too (it rose
     * from 0.0238 to 0.0283 when OIDN was given the lamp) */
    CHECK_MSG(d.rmse < n.rmse, "denoised RMSE over the whole image %g, noisy %g", d.rmse, n.rmse);
}

/* A render stopped after 8 of 16 samples and resumed is denoised once it is complete:
 * the same image as a straight denoised render (the same film, the same features). */
static void test_denoise_after_resume(void)
{
    const char *ck = tmp_path(5, "part.ckpt"), *part = tmp_path(6, "part.pfm"), *resumed = tmp_path(7, "resumed.pfm");
    CHECK(render("16", part, "--sample-range", "0:8", "--checkpoint", ck) == 0);
    CHECK(render("16", resumed, "--denoise", "--resume", ck, NULL) == 0);
    CHECK(error_of(resumed).rmse > 0.0);
    CHECK_MSG(files_equal(resumed, tmp_path(4, "denoised.pfm")), "resumed and straight denoised images differ");
}

/* Two parts rendered without --denoise, merged with --denoise: the colour alone (the
 * parts hold no features); finite, and nearer the reference than the merged image as
 * rendered. */
static void test_merge_denoise(void)
{
    const char *a = tmp_path(0, "a.ckpt"), *b = tmp_path(1, "b.ckpt"), *pa = tmp_path(5, "a.pfm");
    const char *merged = tmp_path(6, "merged.pfm");
    CHECK(render("16", pa, "--sample-range", "0:8", "--checkpoint", a) == 0);
    CHECK(render("16", pa, "--sample-range", "8:16", "--checkpoint", b) == 0);
    const char *args[] = { "merge", "--denoise", "-o", merged, a, b, NULL };
    CliResult r;
    cli_run(args, &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.err, "denoised (colour alone: the parts hold no features; render them with --denoise");
    ImageError m = error_of(merged), n = error_of(tmp_path(3, "noisy.pfm"));
    print_error("merged 16 spp denoised, colour alone:", m);
    CHECK(m.rmse > 0.0);
    CHECK_MSG(m.rmse_away < 0.75 * n.rmse_away, "merged denoised RMSE %g, noisy %g", m.rmse_away, n.rmse_away);
    CHECK_MSG(m.ssim > n.ssim, "merged denoised SSIM %g, noisy %g", m.ssim, n.ssim);
}

/* Parts rendered with --denoise keep the denoiser's inputs for their samples (the
 * features, and the lamp's emission left out and added back); merged with --denoise,
 * in any order and split unevenly, they are one process's --denoise image, bit for bit,
 * and so is the merged checkpoint merged again. */
static void test_merge_denoise_is_one_process(void)
{
    const char *a = tmp_path(0, "da.ckpt"), *b = tmp_path(1, "db.ckpt"), *pa = tmp_path(5, "da.pfm");
    const char *merged = tmp_path(6, "dmerged.pfm"), *ck = tmp_path(2, "dmerged.ckpt");
    CHECK(render_denoise_part("16", pa, "0:5", a) == 0);
    CHECK(render_denoise_part("16", pa, "5:16", b) == 0);
    const char *args[] = { "merge", "--denoise", "-o", merged, "--checkpoint", ck, b, a, NULL };
    CliResult r;
    cli_run(args, &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.err, "16 spp, denoised with the parts' features -> ");
    CHECK_MSG(files_equal(merged, tmp_path(4, "denoised.pfm")), "merged and one process's denoised images differ");
    const char *again[] = { "merge", "-q", "--denoise", "-o", merged, ck, NULL };
    cli_run(again, &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(files_equal(merged, tmp_path(4, "denoised.pfm")), "the merged checkpoint's denoised image differs");
}

/* Parts that cannot give one process's --denoise image are refused, naming them: one
 * without the features, or features of a render of another count (the albedo and
 * normal's pixel grid follows it); a --denoise part must keep them in a checkpoint. */
static void test_merge_denoise_refusals(void)
{
    const char *with = tmp_path(0, "da.ckpt"), *without = tmp_path(1, "b.ckpt"), *four = tmp_path(2, "d4.ckpt");
    const char *out = tmp_path(6, "refused.pfm");
    char msg[2400];
    CliResult r;
    const char *mixed[] = { "merge", "--denoise", "-o", out, with, without, NULL };
    cli_run(mixed, &r);
    CHECK(r.status == 3);
    snprintf(msg, sizeof msg, "clpt: error: cannot merge '%s' with '%s': '%s' holds the denoiser's features (a part "
             "rendered with --denoise) and '%s' does not; render every part with --denoise, or none\n", without, with,
             with, without);
    CHECK_STR_CONTAINS(r.err, msg);
    /* without --denoise the features are not needed: the same parts merge */
    const char *plain[] = { "merge", "-q", "-o", out, with, without, NULL };
    cli_run(plain, &r);
    CHECK(r.status == 3);   /* refused for the samples missing, not for the features */
    CHECK_STR_CONTAINS(r.err, "no part holds samples [5,8)");
    CHECK(render_denoise_part("4", tmp_path(5, "d4.pfm"), "0:4", four) == 0);
    const char *grown[] = { "merge", "--denoise", "-o", out, four, tmp_path(1, "db.ckpt"), NULL };
    cli_run(grown, &r);
    CHECK(r.status == 3);
    snprintf(msg, sizeof msg, "clpt: error: cannot merge '%s' with '%s': their denoiser features were rendered for 16 "
             "and 4 samples per pixel; render every part with the same --spp\n", tmp_path(1, "db.ckpt"), four);
    CHECK_STR_CONTAINS(r.err, msg);
    const char *args[] = { SCENE, "--denoise", "--sample-range", "0:4", "-o", tmp_path(5, "x.pfm"), NULL };
    cli_run(args, &r);
    CHECK(r.status == 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --denoise with --sample-range keeps the denoiser's inputs in the part's "
                 "checkpoint for clpt merge --denoise: give --checkpoint PART\nTry 'clpt --help' for more "
                 "information.\n");
}

/* Under MPI rank 0 renders the features on its own devices and denoises: the same image
 * as one process's --denoise, and a part rendered by two ranks merges with one rendered
 * alone to it too. Skipped without mpirun. */
static void test_mpi_denoise_is_one_process(void)
{
    if (system("command -v mpirun >/dev/null 2>&1") != 0) {
        printf("     (skipped: no mpirun)\n");
        return;
    }
    const char *mpi = tmp_path(5, "mpi.pfm"), *a = tmp_path(0, "ma.ckpt"), *b = tmp_path(1, "mb.ckpt");
    char cmd[2400];
    const char *run = "mpirun --oversubscribe --allow-run-as-root --mca btl self,vader -np 2 " CLI_PROGRAM " " SCENE
                      " -q --width " SIZE " --height " SIZE " --spp 16 --denoise";
    snprintf(cmd, sizeof cmd, "%s -o '%s' >/dev/null 2>&1", run, mpi);
    CHECK(system(cmd) == 0);
    CHECK_MSG(files_equal(mpi, tmp_path(4, "denoised.pfm")), "MPI and one process's denoised images differ");
    snprintf(cmd, sizeof cmd, "%s --sample-range 0:7 --checkpoint '%s' -o '%s' >/dev/null 2>&1", run, a, mpi);
    CHECK(system(cmd) == 0);
    CHECK(render_denoise_part("16", mpi, "7:16", b) == 0);
    const char *args[] = { "merge", "-q", "--denoise", "-o", mpi, a, b, NULL };
    CliResult r;
    cli_run(args, &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_MSG(files_equal(mpi, tmp_path(4, "denoised.pfm")), "a part of two ranks merged differs");
}

/* Whether the file holds the bytes of `s` (an EXR header's channel names are plain). */
static int file_has(const char *path, const char *s)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    static char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf, f), k = strlen(s);
    fclose(f);
    for (size_t i = 0; i + k <= n; i++)
        if (!memcmp(buf + i, s, k)) return 1;
    return 0;
}

static void test_exr_keeps_noisy_and_features(void)
{
    const char *exr = tmp_path(7, "denoised.exr");
    CHECK(render("4", exr, "--denoise", NULL, NULL, NULL) == 0);
    /* and the lamp's emission left out of the denoiser and added back */
    static const char *const names[] = { "noisy.R", "noisy.B", "albedo.G", "normal.X", "normal.Z", "emission.R",
                                         "emission.B", "emission4x.G" };
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) CHECK_MSG(file_has(exr, names[i]), "%s", names[i]);
}

/* ------------------------------------------------------------ features through mirrors */

#define FW 8
#define FH 6
#define WALL_RED v3(0.8f, 0.1f, 0.1f)

/* An infinite plane {p : normal . p = offset} of material m. */
static void add_plane(Scene *s, vec3 normal, float offset, uint m)
{
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = normal;
    pl.offset = offset;
    pl.material = m;
    CHECK(scene_add_plane(s, pl, NULL) == ST_OK);
}

/* The camera at the origin looking down -z at `front` (a perfect mirror at z = -2, or a
 * clear thin glass sheet at z = -1), and a red diffuse wall where its rays go next: at
 * z = +5 facing the mirror (behind the camera), or at z = -3 behind the glass. */
static void specular_scene(Scene *s, int glass)
{
    scene_init(s);
    s->image.width = FW;
    s->image.height = FH;
    s->image.spp = 1;
    s->camera.from = v3(0.0f, 0.0f, 0.0f);
    s->camera.at = v3(0.0f, 0.0f, -1.0f);
    s->camera.up = v3(0.0f, 1.0f, 0.0f);
    s->camera.vfov = 30.0f;
    uint wall, front;
    Material sheet = material_dielectric(1.5f);
    sheet.flags |= MAT_THIN;
    CHECK(scene_add_material(s, "wall", material_diffuse(WALL_RED), &wall, NULL) == ST_OK);
    CHECK(scene_add_material(s, "front", glass ? sheet : material_metal(v3s(1.0f), 0.0f), &front, NULL) == ST_OK);
    add_plane(s, v3(0.0f, 0.0f, 1.0f), glass ? -1.0f : -2.0f, front);
    if (glass) add_plane(s, v3(0.0f, 0.0f, 1.0f), -3.0f, wall);
    else add_plane(s, v3(0.0f, 0.0f, -1.0f), -5.0f, wall);
}

/* The front of the mirror scene made a rough metal: Schlick's conductor with the given
 * reflectance at normal incidence (kernels/bsdf/conductor.h), or, with f0 zero, the
 * measured complex index of gold. */
#define METAL_F0 v3(0.9f, 0.6f, 0.3f)
#define GOLD_ETA v3(0.1678f, 0.3504f, 1.5085f)   /* host/scene/material.c's Au */
#define GOLD_K v3(3.1378f, 2.7141f, 1.8788f)
enum { FRONT_MIRROR, FRONT_GLASS, FRONT_ROUGH_F0, FRONT_ROUGH_GOLD, FRONT_LAMP };
#define LAMP v3(17.0f, 12.0f, 4.0f)

/* FRONT_LAMP: the mirror made a grey diffuse wall, and before it a small spherical lamp
 * whose edge crosses pixels (16 samples a pixel: some partly covered). */
static void add_lamp(Scene *s)
{
    uint lamp;
    s->materials[1] = material_diffuse(v3s(0.5f));
    s->image.spp = 16;
    CHECK(scene_add_material(s, "lamp", material_emissive(LAMP), &lamp, NULL) == ST_OK);
    Sphere sp;
    memset(&sp, 0, sizeof sp);
    sp.center = v3(0.13f, 0.05f, -1.5f);
    sp.radius = 0.2f;
    sp.material = lamp;
    sp.light = NO_INDEX;
    CHECK(scene_add_sphere(s, sp, NULL) == ST_OK);
}

/* Image `mode` (enum Integrator) of the scene with `front` (FRONT_*) on `devices`, into
 * rgb (FW x FH x 3). */
static int render_mode(int front, uint mode, const char *devices, float *rgb)
{
    Scene s;
    specular_scene(&s, front == FRONT_GLASS);
    if (front == FRONT_ROUGH_F0) s.materials[1] = material_conductor_f0(METAL_F0, 0.4f);
    if (front == FRONT_ROUGH_GOLD) s.materials[1] = material_conductor(GOLD_ETA, GOLD_K, 0.4f);
    if (front == FRONT_LAMP) add_lamp(&s);
    s.integrator = mode;
    Error err = { 0 };
    Status st = render_util_rgb_mis(&s, RENDER_UTIL_SCENE_MIS, devices, rgb, &err);
    if (st) fprintf(stderr, "  rendering image %u on %s: %s\n", mode, devices, err.msg);
    error_clear(&err);
    scene_free(&s);
    return st == ST_OK;
}

/* Whether every pixel of rgb is within 1e-4 of k c for a k in [lo, 1] of its own (the
 * transmittance of glass changes with the angle). */
static int all_near_scaled(const float *rgb, vec3 c, float lo)
{
    for (int i = 0; i < FW * FH; i++) {
        float k = rgb[3 * i] / c.x;
        if (!(k >= lo && k <= 1.0f + 1e-4f) || fabsf(rgb[3 * i + 1] - k * c.y) > 1e-4f ||
            fabsf(rgb[3 * i + 2] - k * c.z) > 1e-4f)
            return 0;
    }
    return 1;
}

/* Whether every pixel of rgb is within 1e-4 of c. */
static int all_near(const float *rgb, vec3 c) { return all_near_scaled(rgb, c, 1.0f - 1e-4f); }

/* A red wall seen in a perfect white mirror, and through a thin glass sheet: the
 * denoiser's albedo is the wall's (through the glass times its transmittance, 1 - F:
 * about 0.92 at normal incidence), its normal the wall's ((n + 1) / 2), on the scalar
 * device and OpenCL bit for bit; --aov albedo and normal still show the mirror itself. */
static void test_features_through_specular(void)
{
    static float a[FW * FH * 3], b[FW * FH * 3];
    for (int glass = 0; glass <= 1; glass++) {
        const char *what = glass ? "glass" : "mirror";
        vec3 wall_normal = glass ? v3(0.5f, 0.5f, 1.0f) : v3(0.5f, 0.5f, 0.0f);
        if (!render_mode(glass ? FRONT_GLASS : FRONT_MIRROR, INTEGRATOR_FEATURE_ALBEDO, "scalar", a)) return;
        CHECK_MSG(all_near_scaled(a, WALL_RED, glass ? 0.85f : 1.0f - 1e-4f), "%s: albedo feature %g %g %g, not the wall's",
                  what, a[0], a[1], a[2]);
        if (glass) CHECK_MSG(a[0] < 0.8f * 0.95f, "glass: albedo feature %g, not dimmed by the reflection", a[0]);
        if (!render_mode(glass ? FRONT_GLASS : FRONT_MIRROR, INTEGRATOR_FEATURE_ALBEDO, TEST_OPENCL, b)) return;
        CHECK_MSG(!memcmp(a, b, sizeof a), "%s: the albedo feature differs between scalar and OpenCL", what);
        if (!render_mode(glass ? FRONT_GLASS : FRONT_MIRROR, INTEGRATOR_FEATURE_NORMAL, "scalar", a)) return;
        CHECK_MSG(all_near(a, wall_normal), "%s: normal feature %g %g %g, not the wall's", what, a[0], a[1], a[2]);
        if (!render_mode(glass ? FRONT_GLASS : FRONT_MIRROR, INTEGRATOR_FEATURE_NORMAL, TEST_OPENCL, b)) return;
        CHECK_MSG(!memcmp(a, b, sizeof a), "%s: the normal feature differs between scalar and OpenCL", what);
        /* the first-hit images --aov writes are unchanged: the mirror's (or glass's) own */
        if (!render_mode(glass ? FRONT_GLASS : FRONT_MIRROR, INTEGRATOR_AOV_ALBEDO, "scalar", a)) return;
        CHECK_MSG(all_near(a, v3s(1.0f)), "%s: --aov albedo %g %g %g", what, a[0], a[1], a[2]);
        if (!render_mode(glass ? FRONT_GLASS : FRONT_MIRROR, INTEGRATOR_AOV_NORMAL, "scalar", a)) return;
        CHECK_MSG(all_near(a, v3(0.5f, 0.5f, 1.0f)), "%s: --aov normal %g %g %g", what, a[0], a[1], a[2]);
    }
}


/* A rough metal is the first surface the features stop at; its albedo there is its
 * reflectance at normal incidence (OIDN's documentation, "Albedo"), not the tint of 1
 * that --aov albedo shows: Schlick's F0 as given, and for a complex index eta + i k the
 * conductor Fresnel reflectance at normal incidence, ((eta - 1)^2 + k^2) / ((eta + 1)^2
 * + k^2) per channel (Born and Wolf, "Principles of Optics", 14.2). Scalar and OpenCL
 * agree bit for bit. */
static void test_metal_albedo_feature(void)
{
    static float a[FW * FH * 3], b[FW * FH * 3];
    if (!render_mode(FRONT_ROUGH_F0, INTEGRATOR_FEATURE_ALBEDO, "scalar", a)) return;
    CHECK_MSG(all_near(a, METAL_F0), "rough metal: albedo feature %g %g %g, not its F0", a[0], a[1], a[2]);
    if (!render_mode(FRONT_ROUGH_F0, INTEGRATOR_FEATURE_ALBEDO, TEST_OPENCL, b)) return;
    CHECK_MSG(!memcmp(a, b, sizeof a), "rough metal: the albedo feature differs between scalar and OpenCL");
    if (!render_mode(FRONT_ROUGH_GOLD, INTEGRATOR_FEATURE_ALBEDO, "scalar", a)) return;
    vec3 eta = GOLD_ETA, k = GOLD_K, f0;
    f0.x = ((eta.x - 1) * (eta.x - 1) + k.x * k.x) / ((eta.x + 1) * (eta.x + 1) + k.x * k.x);
    f0.y = ((eta.y - 1) * (eta.y - 1) + k.y * k.y) / ((eta.y + 1) * (eta.y + 1) + k.y * k.y);
    f0.z = ((eta.z - 1) * (eta.z - 1) + k.z * k.z) / ((eta.z + 1) * (eta.z + 1) + k.z * k.z);
    CHECK_MSG(all_near_scaled(a, f0, 1.0f - 1e-3f), "gold: albedo feature %g %g %g, not its F0 %g %g %g", a[0], a[1],
              a[2], f0.x, f0.y, f0.z);
    if (!render_mode(FRONT_ROUGH_GOLD, INTEGRATOR_FEATURE_ALBEDO, TEST_OPENCL, b)) return;
    CHECK_MSG(!memcmp(a, b, sizeof a), "gold: the albedo feature differs between scalar and OpenCL");
    if (!render_mode(FRONT_ROUGH_F0, INTEGRATOR_AOV_ALBEDO, "scalar", a)) return;
    CHECK_MSG(all_near(a, v3s(1.0f)), "rough metal: --aov albedo %g %g %g, not its tint", a[0], a[1], a[2]);
}

/* The emission feature (what passes_denoise leaves out of the denoiser) traces the path
 * tracer's own camera rays: on every pixel it is at most the path-traced image (whose
 * samples each add at least that emission), the lamp's radiance where the lamp covers
 * the pixel, 0 where the lamp is not seen, in between on its edge; scalar and OpenCL
 * agree bit for bit. */
static void test_emission_feature(void)
{
    static float e[FW * FH * 3], b[FW * FH * 3], c[FW * FH * 3];
    if (!render_mode(FRONT_LAMP, INTEGRATOR_FEATURE_EMISSION, "scalar", e)) return;
    if (!render_mode(FRONT_LAMP, INTEGRATOR_FEATURE_EMISSION, TEST_OPENCL, b)) return;
    CHECK_MSG(!memcmp(e, b, sizeof e), "the emission feature differs between scalar and OpenCL");
    if (!render_mode(FRONT_LAMP, INTEGRATOR_PATH, "scalar", c)) return;
    int full = 0, none = 0, part = 0, above = 0;
    for (int i = 0; i < FW * FH; i++) {
        float k = e[3 * i] / LAMP.x;
        full += k == 1.0f && e[3 * i + 1] == LAMP.y && e[3 * i + 2] == LAMP.z;
        none += k == 0.0f;
        part += k > 0.0f && k < 1.0f;
        for (int ch = 0; ch < 3; ch++) above += e[3 * i + ch] > c[3 * i + ch];
    }
    CHECK_MSG(full > 0 && none > 0 && part > 0, "lamp fully in %d pixels, partly in %d, not in %d", full, part, none);
    CHECK_MSG(above == 0, "the emission exceeds the image in %d channels", above);
}

/* A raised cancel flag (denoiser_set_cancel, the viewer's stop flag) stops a denoise
 * before any filter with its own status and message; lowered, the same denoiser works
 * again. (OIDN's own stop mid-filter, through its progress monitor, is test_viewer's
 * test_quit_cancels_denoise.) */
static Denoiser *opened;   /* main's, while the tests that need it run */

static void test_cancel_flag(void)
{
    Denoiser *d = opened;
    enum { W = 16, H = 16 };
    static float color[W * H * 3], out[W * H * 3];
    for (int i = 0; i < W * H * 3; i++) color[i] = 0.5f;
    volatile sig_atomic_t cancel = 1;
    denoiser_set_cancel(d, &cancel);
    Error err = { 0 };
    CHECK_EQ_INT(denoiser_run(d, color, NULL, NULL, W, H, out, &err), ST_INTERRUPTED);
    CHECK_MSG(strcmp(err.msg, "denoising was cancelled") == 0, "message '%s'", err.msg);
    error_clear(&err);
    cancel = 0;
    CHECK_EQ_INT(denoiser_run(d, color, NULL, NULL, W, H, out, &err), ST_OK);
    CHECK_MSG(out[0] > 0.4f && out[0] < 0.6f, "a flat 0.5 image denoised to %g", out[0]);
    denoiser_set_cancel(d, NULL);
    error_clear(&err);
}

int main(void)
{
    if (!mkdtemp(dir)) return 1;
    RUN(test_missing_library_message);
    RUN(test_features_through_specular);
    RUN(test_metal_albedo_feature);
    RUN(test_emission_feature);
    Denoiser *d = NULL;
    Error err = { 0 };
    have_oidn = denoiser_open(&d, &err) == ST_OK;
    if (!have_oidn) {
        printf("     (skipped the denoising tests: %s)\n", err.msg);
    } else if (!make_reference()) {
        fprintf(stderr, "  the reference image could not be rendered\n");
        harness_failed++;
    } else {
        printf("     (Open Image Denoise from %s, %s device)\n", denoiser_library(d), denoiser_device_kind(d));
        opened = d;
        RUN(test_cancel_flag);
        RUN(test_denoise_lowers_error);
        RUN(test_denoise_after_resume);
        RUN(test_merge_denoise);
        RUN(test_merge_denoise_is_one_process);
        RUN(test_merge_denoise_refusals);
        RUN(test_mpi_denoise_is_one_process);
        RUN(test_exr_keeps_noisy_and_features);
    }
    error_clear(&err);
    denoiser_close(d);
    free(reference);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "  could not remove %s\n", dir);
    return harness_report();
}
