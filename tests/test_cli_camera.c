/* test_cli_camera.c — the flags that choose what the camera sees and which part of the
 * image is rendered (issue 44): --crop and --pixel-bounds, whose pixels must be the
 * whole render's bit for bit (on the scalar device and on OpenCL), with checkpoints,
 * resume and merge, and pbrt's Film crop; and their errors, with the exact messages. */
#include <stdint.h>

#include "cli_util.h"
#include "harness.h"

static CliResult r;   /* large: static */

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })
#define HINT "Try 'clpt --help' for more information.\n"
#define DIR "/tmp/clpt-test-camera"
/* a render of well under a second on the scalar device: 40x30, 4 samples */
#define SMALL "--width", "40", "--height", "30", "--spp", "4", "-q"

/* The whole of stderr is `want` (a usage error: the message, then the hint once). */
#define CHECK_USAGE(args, want)                                                       \
    do {                                                                              \
        cli_run(args, &r);                                                            \
        CHECK_EQ_INT(r.status, 2);                                                    \
        CHECK_MSG(strcmp(r.err, want) == 0, "stderr:\n%s\nwanted:\n%s", r.err, want); \
    } while (0)

typedef struct {
    unsigned w, h;
    float *rgb;   /* w * h * 3, top row first */
} Image;

/* A PFM file (rows bottom to top) into *img, top row first; 0 when unreadable. */
static int pfm_read(const char *path, Image *img)
{
    FILE *f = fopen(path, "rb");
    img->rgb = NULL;
    if (!f) return 0;
    float scale = 0.0f;
    char kind[3] = { 0 };
    if (fscanf(f, "%2s %u %u %f", kind, &img->w, &img->h, &scale) == 4 && fgetc(f) == '\n' &&
        strcmp(kind, "PF") == 0 && img->w > 0 && img->h > 0 && img->w < 65536 && img->h < 65536) {
        size_t row = (size_t)img->w * 3;
        img->rgb = malloc(row * img->h * sizeof *img->rgb);
        for (unsigned y = img->h; img->rgb && y-- > 0;)
            if (fread(img->rgb + y * row, sizeof *img->rgb, row, f) != row) {
                free(img->rgb);
                img->rgb = NULL;
            }
    }
    fclose(f);
    return img->rgb != NULL;
}

/* Whether `part` is, bit for bit, the w x h window of `whole` at column x0, row y0. */
static int is_window_of(const char *part, const char *whole, unsigned x0, unsigned y0, unsigned w, unsigned h)
{
    Image p, a;
    int ok = pfm_read(part, &p) && pfm_read(whole, &a) && p.w == w && p.h == h && x0 + w <= a.w && y0 + h <= a.h;
    for (unsigned y = 0; ok && y < h; y++)
        ok = memcmp(p.rgb + (size_t)y * w * 3, a.rgb + ((size_t)(y0 + y) * a.w + x0) * 3, (size_t)w * 3 * sizeof(float))
             == 0;
    if (!ok && p.rgb) fprintf(stderr, "    %s is %ux%u, wanted the %ux%u window at (%u, %u) of %s\n", part, p.w, p.h,
                              w, h, x0, y0, whole);
    free(p.rgb);
    free(a.rgb);
    return ok;
}

/* The window's pixels are the whole render's: path tracing and the whitted ray tracer,
 * on the scalar device and on OpenCL; --crop's fractions round as pbrt's (a column
 * is in when ceil(X0 * width) <= it < ceil(X1 * width)). */
static void test_crop_pixels_are_the_whole_renders(void)
{
    const char *devices[2] = { "scalar", TEST_OPENCL };
    for (int d = 0; d < 2; d++) {
        cli_run(ARGS("scenes/cornell-box.scene", "--device", devices[d], SMALL, "-o", DIR "/whole.pfm"), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        cli_run(ARGS("scenes/cornell-box.scene", "--device", devices[d], SMALL, "--pixel-bounds", "5,23,7,20", "-o",
                     DIR "/bounds.pfm"), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_MSG(is_window_of(DIR "/bounds.pfm", DIR "/whole.pfm", 5, 7, 18, 13), "--pixel-bounds on %s", devices[d]);
        /* columns ceil(4) .. ceil(24) - 1, rows ceil(7.5) .. 29 */
        cli_run(ARGS("scenes/cornell-box.scene", "--device", devices[d], SMALL, "--crop", "0.1,0.6,0.25,1", "-o",
                     DIR "/crop.pfm"), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_MSG(is_window_of(DIR "/crop.pfm", DIR "/whole.pfm", 4, 8, 20, 22), "--crop on %s", devices[d]);
    }
    /* the whitted integrator's samples and its auxiliary images; --crop=... as any flag */
    cli_run(ARGS("scenes/classic/spheres.txt", "--device", "scalar", "--spp", "4", "-q", "--aov", "depth",
                 "-o", DIR "/classic.pfm"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS("scenes/classic/spheres.txt", "--device", TEST_OPENCL, "--spp", "4", "-q", "--aov", "depth",
                 "--pixel-bounds=30,90,10,40", "-o", DIR "/classic-crop.pfm"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(is_window_of(DIR "/classic-crop.pfm", DIR "/classic.pfm", 30, 10, 60, 30));
    CHECK(is_window_of(DIR "/classic-crop-depth.pfm", DIR "/classic-depth.pfm", 30, 10, 60, 30));
}

/* A cropped render checkpoints, resumes, grows and merges like a whole one, and its
 * checkpoint is not another window's. */
static void test_crop_with_checkpoints_and_merge(void)
{
#define CROPPED "scenes/cornell-box.scene", "--device", "scalar", "--width", "40", "--height", "30", "-q", \
                "--pixel-bounds", "10,30,0,12"
    cli_run(ARGS(CROPPED, "--spp", "6", "-o", DIR "/c6.pfm"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(CROPPED, "--spp", "2", "--checkpoint", DIR "/c.ckpt", "-o", DIR "/c2.pfm"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(CROPPED, "--spp", "6", "--resume", DIR "/c.ckpt", "-o", DIR "/c-resumed.pfm"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(DIR "/c-resumed.pfm", DIR "/c6.pfm"));
    /* parts of the cropped render merge to it */
    cli_run(ARGS(CROPPED, "--spp", "6", "--sample-range", "0:4", "--checkpoint", DIR "/p1.ckpt", "-o", DIR "/p1.pfm"),
            &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(CROPPED, "--spp", "6", "--sample-range", "4:6", "--checkpoint", DIR "/p2.ckpt", "-o", DIR "/p2.pfm"),
            &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS("merge", "-q", "-o", DIR "/merged.pfm", DIR "/p2.ckpt", DIR "/p1.ckpt"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(DIR "/merged.pfm", DIR "/c6.pfm"));
    /* another window is another render: its checkpoint is refused */
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "40", "--height", "30", "-q",
                 "--pixel-bounds", "10,30,1,13", "--spp", "6", "--resume", DIR "/c.ckpt", "-o", DIR "/other.pfm"), &r);
    CHECK_EQ_INT(r.status, 3);
#undef CROPPED
}

static void test_crop_errors(void)
{
#define SCENE "scenes/cornell-box.scene", "--device", "scalar"
    CHECK_USAGE(ARGS(SCENE, "--crop", "0.5,0.25,0,1"),
                "clpt: error: --crop expects X0,X1,Y0,Y1, fractions of the image with 0 <= X0 < X1 <= 1 and "
                "0 <= Y0 < Y1 <= 1, got '0.5,0.25,0,1'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--crop", "0,1,0"),
                "clpt: error: --crop expects X0,X1,Y0,Y1, fractions of the image with 0 <= X0 < X1 <= 1 and "
                "0 <= Y0 < Y1 <= 1, got '0,1,0'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--crop", "0, 1,0,1"),
                "clpt: error: --crop expects X0,X1,Y0,Y1, fractions of the image with 0 <= X0 < X1 <= 1 and "
                "0 <= Y0 < Y1 <= 1, got '0, 1,0,1'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--crop", "0,1.5,0,1"),
                "clpt: error: --crop expects X0,X1,Y0,Y1, fractions of the image with 0 <= X0 < X1 <= 1 and "
                "0 <= Y0 < Y1 <= 1, got '0,1.5,0,1'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--pixel-bounds", "0,10.5,0,4"),
                "clpt: error: --pixel-bounds expects X0,X1,Y0,Y1, whole pixels with 0 <= X0 < X1 and 0 <= Y0 < Y1 "
                "(columns X0..X1-1, rows Y0..Y1-1), got '0,10.5,0,4'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--pixel-bounds", "4,4,0,4"),
                "clpt: error: --pixel-bounds expects X0,X1,Y0,Y1, whole pixels with 0 <= X0 < X1 and 0 <= Y0 < Y1 "
                "(columns X0..X1-1, rows Y0..Y1-1), got '4,4,0,4'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--crop", "0,1,0,1", "--pixel-bounds", "0,1,0,1"),
                "clpt: error: --crop and --pixel-bounds both choose the window to render: give one\n" HINT);
    /* against the image's size, once the scene is read */
    CHECK_USAGE(ARGS(SCENE, "--width", "10", "--height", "10", "--pixel-bounds", "0,11,0,4"),
                "clpt: error: --pixel-bounds 0,11,0,4 goes past the 10x10 image\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--width", "10", "--height", "10", "--crop", "0.11,0.12,0,1"),
                "clpt: error: --crop 0.11,0.12,0,1 selects no pixel of the 10x10 image\n" HINT);
    CHECK_USAGE(ARGS("scenes/classic/spheres.txt", "--device", "scalar", "--adaptive", "0.1", "--crop", "0,0.5,0,1"),
                "clpt: error: --adaptive cannot render a crop (--crop): it compares each pixel with its neighbours, "
                "which the window's edge leaves out\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--interactive", "--pixel-bounds", "0,1,0,1"),
                "clpt: error: --interactive cannot be combined with --pixel-bounds (the viewer saves frames with the "
                "C key; see docs/viewer.md)\n" HINT);
#undef SCENE
}

/* A pbrt-v4 scene of 32x24 pixels seen from `lookat` (pbrt's LookAt's nine numbers),
 * whose Film has `film_extra` ("" for none), in path. */
static void pbrt_scene(const char *path, const char *lookat, const char *film_extra)
{
    FILE *f = fopen(path, "w");
    if (!f) return;
    fprintf(f, "LookAt %s\n"
               "Camera \"perspective\" \"float fov\" 40\n"
               "Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 24 %s\n"
               "Sampler \"zsobol\" \"integer pixelsamples\" 4\n"
               "WorldBegin\n"
               "LightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n"
               "Material \"diffuse\" \"rgb reflectance\" [0.5 0.3 0.2]\n"
               "Shape \"sphere\" \"float radius\" 0.8\n", lookat, film_extra);
    fclose(f);
}

/* pbrt's Film "cropwindow" and "pixelbounds" crop as --crop and --pixel-bounds do
 * (the bounds of a crop window in either order, as pbrt takes them); the flags win. */
#define PBRT_LOOKAT "0 1 4  0 0.5 0  0 1 0"
static void test_pbrt_film_crop(void)
{
#define PBRT(file) file, "--device", "scalar", "-q"
    pbrt_scene(DIR "/whole.pbrt", PBRT_LOOKAT, "");
    pbrt_scene(DIR "/cropwindow.pbrt", PBRT_LOOKAT, "\"float cropwindow\" [0.5 0.25 0 0.5]");
    pbrt_scene(DIR "/pixelbounds.pbrt", PBRT_LOOKAT, "\"integer pixelbounds\" [3 20 2 9]");
    pbrt_scene(DIR "/past.pbrt", PBRT_LOOKAT, "\"integer pixelbounds\" [0 40 0 4]");
    cli_run(ARGS(PBRT(DIR "/whole.pbrt"), "-o", DIR "/pbrt-whole.pfm"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(PBRT(DIR "/cropwindow.pbrt"), "-o", DIR "/pbrt-cw.pfm"), &r);
    CHECK_MSG(r.status == 0 && r.err[0] == '\0', "%s", r.err);
    CHECK(is_window_of(DIR "/pbrt-cw.pfm", DIR "/pbrt-whole.pfm", 8, 0, 8, 12));
    cli_run(ARGS(PBRT(DIR "/pixelbounds.pbrt"), "-o", DIR "/pbrt-pb.pfm"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(is_window_of(DIR "/pbrt-pb.pfm", DIR "/pbrt-whole.pfm", 3, 2, 17, 7));
    cli_run(ARGS(PBRT(DIR "/pixelbounds.pbrt"), "--crop", "0,1,0.5,1", "-o", DIR "/pbrt-flag.pfm"), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(is_window_of(DIR "/pbrt-flag.pfm", DIR "/pbrt-whole.pfm", 0, 12, 32, 12));
    cli_run(ARGS(PBRT(DIR "/past.pbrt"), "-o", DIR "/pbrt-past.pfm"), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_MSG(strcmp(r.err, "clpt: error: " DIR "/past.pbrt: the pixel bounds 0,40,0,4 go past the 32x24 image\n") == 0,
              "%s", r.err);
#undef PBRT
}

int main(void)
{
    if (system("rm -rf " DIR " && mkdir -p " DIR) != 0) return 1;
    RUN(test_crop_errors);
    RUN(test_crop_pixels_are_the_whole_renders);
    RUN(test_crop_with_checkpoints_and_merge);
    RUN(test_pbrt_film_crop);
    if (system("rm -rf " DIR) != 0) return 1;
    return harness_report();
}
