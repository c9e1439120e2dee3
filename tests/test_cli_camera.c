/* test_cli_camera.c — the flags that choose what the camera sees and which part of the
 * image is rendered (issue 44): --crop and --pixel-bounds, whose pixels must be the
 * whole render's bit for bit (on the scalar device and on OpenCL), with checkpoints,
 * resume and merge, and pbrt's Film crop; --lookat and --fov, the scene's camera
 * edited in every format; the orthographic camera of clpt's format against its
 * analytic image; and their errors, with the exact messages. */
#include <stdint.h>

#include "cli_util.h"
#include "harness.h"

static CliResult r;   /* large: static */

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })
#define HINT "Try 'clpt --help' for more information.\n"
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
        cli_run(ARGS("scenes/cornell-box.scene", "--device", devices[d], SMALL, "-o", TEST_TMP("whole.pfm")), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        cli_run(ARGS("scenes/cornell-box.scene", "--device", devices[d], SMALL, "--pixel-bounds", "5,23,7,20", "-o",
                     TEST_TMP("bounds.pfm")), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_MSG(is_window_of(TEST_TMP("bounds.pfm"), TEST_TMP("whole.pfm"), 5, 7, 18, 13), "--pixel-bounds on %s", devices[d]);
        /* columns ceil(4) .. ceil(24) - 1, rows ceil(7.5) .. 29 */
        cli_run(ARGS("scenes/cornell-box.scene", "--device", devices[d], SMALL, "--crop", "0.1,0.6,0.25,1", "-o",
                     TEST_TMP("crop.pfm")), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_MSG(is_window_of(TEST_TMP("crop.pfm"), TEST_TMP("whole.pfm"), 4, 8, 20, 22), "--crop on %s", devices[d]);
    }
    /* the whitted integrator's samples and its auxiliary images; --crop=... as any flag */
    cli_run(ARGS("scenes/classic/spheres.txt", "--device", "scalar", "--spp", "4", "-q", "--aov", "depth",
                 "-o", TEST_TMP("classic.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS("scenes/classic/spheres.txt", "--device", TEST_OPENCL, "--spp", "4", "-q", "--aov", "depth",
                 "--pixel-bounds=30,90,10,40", "-o", TEST_TMP("classic-crop.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(is_window_of(TEST_TMP("classic-crop.pfm"), TEST_TMP("classic.pfm"), 30, 10, 60, 30));
    CHECK(is_window_of(TEST_TMP("classic-crop-depth.pfm"), TEST_TMP("classic-depth.pfm"), 30, 10, 60, 30));
}

/* A cropped render checkpoints, resumes, grows and merges like a whole one, and its
 * checkpoint is not another window's. */
static void test_crop_with_checkpoints_and_merge(void)
{
#define CROPPED "scenes/cornell-box.scene", "--device", "scalar", "--width", "40", "--height", "30", "-q", \
                "--pixel-bounds", "10,30,0,12"
    cli_run(ARGS(CROPPED, "--spp", "6", "-o", TEST_TMP("c6.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(CROPPED, "--spp", "2", "--checkpoint", TEST_TMP("c.ckpt"), "-o", TEST_TMP("c2.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(CROPPED, "--spp", "6", "--resume", TEST_TMP("c.ckpt"), "-o", TEST_TMP("c-resumed.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(TEST_TMP("c-resumed.pfm"), TEST_TMP("c6.pfm")));
    /* parts of the cropped render merge to it */
    cli_run(ARGS(CROPPED, "--spp", "6", "--sample-range", "0:4", "--checkpoint", TEST_TMP("p1.ckpt"), "-o", TEST_TMP("p1.pfm")),
            &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(CROPPED, "--spp", "6", "--sample-range", "4:6", "--checkpoint", TEST_TMP("p2.ckpt"), "-o", TEST_TMP("p2.pfm")),
            &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS("merge", "-q", "-o", TEST_TMP("merged.pfm"), TEST_TMP("p2.ckpt"), TEST_TMP("p1.ckpt")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(TEST_TMP("merged.pfm"), TEST_TMP("c6.pfm")));
    /* another window is another render: its checkpoint is refused */
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "40", "--height", "30", "-q",
                 "--pixel-bounds", "10,30,1,13", "--spp", "6", "--resume", TEST_TMP("c.ckpt"), "-o", TEST_TMP("other.pfm")), &r);
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
    pbrt_scene(TEST_TMP("whole.pbrt"), PBRT_LOOKAT, "");
    pbrt_scene(TEST_TMP("cropwindow.pbrt"), PBRT_LOOKAT, "\"float cropwindow\" [0.5 0.25 0 0.5]");
    pbrt_scene(TEST_TMP("pixelbounds.pbrt"), PBRT_LOOKAT, "\"integer pixelbounds\" [3 20 2 9]");
    pbrt_scene(TEST_TMP("past.pbrt"), PBRT_LOOKAT, "\"integer pixelbounds\" [0 40 0 4]");
    cli_run(ARGS(PBRT(TEST_TMP("whole.pbrt")), "-o", TEST_TMP("pbrt-whole.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(PBRT(TEST_TMP("cropwindow.pbrt")), "-o", TEST_TMP("pbrt-cw.pfm")), &r);
    CHECK_MSG(r.status == 0 && r.err[0] == '\0', "%s", r.err);
    CHECK(is_window_of(TEST_TMP("pbrt-cw.pfm"), TEST_TMP("pbrt-whole.pfm"), 8, 0, 8, 12));
    cli_run(ARGS(PBRT(TEST_TMP("pixelbounds.pbrt")), "-o", TEST_TMP("pbrt-pb.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(is_window_of(TEST_TMP("pbrt-pb.pfm"), TEST_TMP("pbrt-whole.pfm"), 3, 2, 17, 7));
    cli_run(ARGS(PBRT(TEST_TMP("pixelbounds.pbrt")), "--crop", "0,1,0.5,1", "-o", TEST_TMP("pbrt-flag.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(is_window_of(TEST_TMP("pbrt-flag.pfm"), TEST_TMP("pbrt-whole.pfm"), 0, 12, 32, 12));
    cli_run(ARGS(PBRT(TEST_TMP("past.pbrt")), "-o", TEST_TMP("pbrt-past.pfm")), &r);
    CHECK_EQ_INT(r.status, 3);
    char want[1024];
    snprintf(want, sizeof want, "clpt: error: %s: the pixel bounds 0,40,0,4 go past the 32x24 image\n",
             TEST_TMP("past.pbrt"));
    CHECK_MSG(strcmp(r.err, want) == 0, "%s", r.err);
#undef PBRT
}

/* Writes `text` to path. */
static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static void test_lookat_and_fov_errors(void)
{
#define SCENE "scenes/cornell-box.scene", "--device", "scalar"
#define LOOKAT_EXPECTS "clpt: error: --lookat expects EX,EY,EZ,AX,AY,AZ,UX,UY,UZ, nine numbers: the eye, the point " \
                       "looked at and the up direction, got "
    CHECK_USAGE(ARGS(SCENE, "--lookat", "0,0,0,0,0,1,0,1"), LOOKAT_EXPECTS "'0,0,0,0,0,1,0,1'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--lookat", "0 0 0 0 0 1 0 1 0"), LOOKAT_EXPECTS "'0 0 0 0 0 1 0 1 0'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--lookat", "0,0,0,0,0,1,0,1,1e39"), LOOKAT_EXPECTS "'0,0,0,0,0,1,0,1,1e39'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--lookat", "1,2,3,1,2,3,0,1,0"),
                "clpt: error: --lookat 1,2,3,1,2,3,0,1,0: the eye and the point looked at are the same point\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--lookat", "0,0,0,0,0,-1,0,0,0"),
                "clpt: error: --lookat 0,0,0,0,0,-1,0,0,0: the up direction is 0,0,0\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--lookat", "0,5,0,0,0,0,0,1,0"),
                "clpt: error: --lookat 0,5,0,0,0,0,0,1,0: the up direction is parallel to the view direction (from the "
                "eye to the point looked at)\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--fov", "180"),
                "clpt: error: --fov expects a vertical field of view in degrees, more than 0 and less than 180, got "
                "'180'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--fov", "0"),
                "clpt: error: --fov expects a vertical field of view in degrees, more than 0 and less than 180, got "
                "'0'\n" HINT);
    CHECK_USAGE(ARGS(SCENE, "--fov", "wide"),
                "clpt: error: --fov expects a vertical field of view in degrees, more than 0 and less than 180, got "
                "'wide'\n" HINT);
    CHECK_USAGE(ARGS("scenes/classic/ortho.txt", "--device", "scalar", "--fov", "30"),
                "clpt: error: --fov sets a perspective camera's field of view; the scene's camera is orthographic\n"
                HINT);
#undef LOOKAT_EXPECTS
#undef SCENE
}

#define LOOKAT "1,2,4,0,0.5,0,0,1,0"
#define TINY_RENDER "--device", "scalar", "--width", "32", "--height", "24", "--spp", "4", "-q"

/* A clpt scene seen by `camera` (a camera block's keys). */
static void clpt_scene(const char *path, const char *camera)
{
    FILE *f = fopen(path, "w");
    if (!f) return;
    fprintf(f, "camera { %s }\n"
               "background { horizon 1 1 1  zenith 0.5 0.7 1.0 }\n"
               "material floor { type diffuse albedo 0.7 0.7 0.7 }\n"
               "plane { point 0 0 0  normal 0 1 0  material floor }\n"
               "sphere { center 0 0.5 0  radius 0.5  material { type diffuse albedo 0.8 0.2 0.2 } }\n", camera);
    fclose(f);
}

/* --lookat and --fov are the scene's camera edited: the same bits as the scene file
 * with that camera written in it. */
static void test_lookat_and_fov_equal_editing_the_scene(void)
{
    clpt_scene(TEST_TMP("cam-a.scene"), "from 0 1 5  at 0 0.5 0  fov 40");
    clpt_scene(TEST_TMP("cam-b.scene"), "from 1 2 4  at 0 0.5 0  up 0 1 0  fov 30");
    cli_run(ARGS(TEST_TMP("cam-a.scene"), TINY_RENDER, "--lookat", LOOKAT, "--fov", "30", "-o", TEST_TMP("cam-flags.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS(TEST_TMP("cam-b.scene"), TINY_RENDER, "-o", TEST_TMP("cam-edited.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(TEST_TMP("cam-flags.pfm"), TEST_TMP("cam-edited.pfm")));
    /* the flags win over --set, as --spp does */
    cli_run(ARGS(TEST_TMP("cam-a.scene"), TINY_RENDER, "--set", "camera.fov=60", "--fov", "30", "--lookat", LOOKAT, "-o",
                 TEST_TMP("cam-set.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(TEST_TMP("cam-set.pfm"), TEST_TMP("cam-edited.pfm")));
}

/* In the other formats the flags replace the file's camera whole: two files that differ
 * only in their camera give the same bits under the same --lookat and --fov. */
static void check_camera_replaced(const char *a, const char *b, const char *what)
{
    cli_run(ARGS(a, TINY_RENDER, "--lookat", LOOKAT, "--fov", "30", "-o", TEST_TMP("replaced-a.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s: %s", what, r.err);
    cli_run(ARGS(b, TINY_RENDER, "--lookat", LOOKAT, "--fov", "30", "-o", TEST_TMP("replaced-b.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s: %s", what, r.err);
    CHECK_MSG(files_equal(TEST_TMP("replaced-a.pfm"), TEST_TMP("replaced-b.pfm")), "%s", what);
    cli_run(ARGS(a, TINY_RENDER, "-o", TEST_TMP("replaced-none.pfm")), &r);
    CHECK_MSG(!files_equal(TEST_TMP("replaced-a.pfm"), TEST_TMP("replaced-none.pfm")), "%s: the flags changed nothing", what);
}

/* A glTF file with one triangle and a camera at `camera_at` (a node translation). */
static void gltf_scene(const char *path, const char *camera_at)
{
    FILE *f = fopen(path, "w");
    if (!f) return;
    fprintf(f, "{\"asset\": {\"version\": \"2.0\"},\n"
               " \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,"
               "AACAvwAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAwD8AAAAA\"}],\n"
               " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}],\n"
               " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}],\n"
               " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}],\n"
               " \"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.6, \"znear\": 0.1}}],\n"
               " \"nodes\": [{\"mesh\": 0}, {\"camera\": 0, \"translation\": [%s]}],\n"
               " \"scenes\": [{\"nodes\": [0, 1]}], \"scene\": 0}\n", camera_at);
    fclose(f);
}

static void test_lookat_and_fov_in_every_format(void)
{
    pbrt_scene(TEST_TMP("cam-a.pbrt"), "0 1 4  0 0.5 0  0 1 0", "");
    pbrt_scene(TEST_TMP("cam-b.pbrt"), "2 3 5  0 0 0  0 1 0", "");
    check_camera_replaced(TEST_TMP("cam-a.pbrt"), TEST_TMP("cam-b.pbrt"), "pbrt");
    gltf_scene(TEST_TMP("cam-a.gltf"), "0, 0.5, 3");
    gltf_scene(TEST_TMP("cam-b.gltf"), "0.5, 1, 5");
    check_camera_replaced(TEST_TMP("cam-a.gltf"), TEST_TMP("cam-b.gltf"), "glTF");
    /* the course format: the same scene under another PerspectiveCamera */
    write_text(TEST_TMP("cam-a.txt"), "PerspectiveCamera { center 0 1 5 direction 0 -0.1 -1 up 0 1 0 angle 35 }\n"
                                 "Lights { numLights 1 DirectionalLight { direction -0.5 -1 -0.5 color 1 1 1 } }\n"
                                 "Background { color 0.2 0.3 0.4 }\n"
                                 "Materials { numMaterials 1 Material { diffuseColor 0.8 0.2 0.2 } }\n"
                                 "Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0.5 0 radius 0.5 } }\n");
    write_text(TEST_TMP("cam-b.txt"), "PerspectiveCamera { center 3 0 2 direction -1 0 0 up 0 1 0 angle 60 }\n"
                                 "Lights { numLights 1 DirectionalLight { direction -0.5 -1 -0.5 color 1 1 1 } }\n"
                                 "Background { color 0.2 0.3 0.4 }\n"
                                 "Materials { numMaterials 1 Material { diffuseColor 0.8 0.2 0.2 } }\n"
                                 "Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0.5 0 radius 0.5 } }\n");
    check_camera_replaced(TEST_TMP("cam-a.txt"), TEST_TMP("cam-b.txt"), "classic");
    /* a mesh shown alone gets a camera that frames it; the flags, and --set, replace it */
    cli_run(ARGS("tests/data/good/square.obj", TINY_RENDER, "--lookat", LOOKAT, "--fov", "30", "-o",
                 TEST_TMP("mesh-flags.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS("tests/data/good/square.obj", TINY_RENDER, "--set", "camera.from=1,2,4", "--set", "camera.at=0,0.5,0",
                 "--set", "camera.up=0,1,0", "--set", "camera.fov=30", "-o", TEST_TMP("mesh-set.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(TEST_TMP("mesh-flags.pfm"), TEST_TMP("mesh-set.pfm")));
    cli_run(ARGS("tests/data/good/square.obj", TINY_RENDER, "-o", TEST_TMP("mesh-framed.pfm")), &r);
    CHECK(!files_equal(TEST_TMP("mesh-flags.pfm"), TEST_TMP("mesh-framed.pfm")));
}

/* An orthographic scene of 64x32 pixels: a lamp of radiance 1, 1 wide and 0.5 tall,
 * facing a camera `camera` (a camera block's keys) on black. */
static void ortho_scene(const char *path, const char *camera)
{
    FILE *f = fopen(path, "w");
    if (!f) return;
    fprintf(f, "image { width 64 height 32 spp 4 }\n"
               "camera { %s }\n"
               "background { color 0 0 0 }\n"
               "material lamp { type emissive radiance 1 1 1 }\n"
               "quad { v0 -0.5 -0.25 0  v1 0.5 -0.25 0  v2 0.5 0.25 0  v3 -0.5 0.25 0  material lamp }\n", camera);
    fclose(f);
}

/* Whether the image at path is exactly 1 in columns [x0, x1) and rows [y0, y1), and
 * exactly 0 elsewhere. */
static int is_lit_rectangle(const char *path, unsigned x0, unsigned x1, unsigned y0, unsigned y1)
{
    Image a;
    if (!pfm_read(path, &a)) return 0;
    size_t wrong = 0;
    for (unsigned y = 0; y < a.h; y++)
        for (unsigned x = 0; x < a.w; x++)
            for (int c = 0; c < 3; c++)
                wrong += a.rgb[((size_t)y * a.w + x) * 3 + c] != (x >= x0 && x < x1 && y >= y0 && y < y1 ? 1.0f : 0.0f);
    free(a.rgb);
    if (wrong) fprintf(stderr, "    %s: %zu values are not the lit rectangle's\n", path, wrong);
    return wrong == 0;
}

/* The analytic image: a view 2 wide over 64 columns is 32 pixels a unit, and 1 tall
 * over 32 rows (the image's shape), so the lamp, 1 x 0.5 at the view's centre, covers
 * columns 16..47 and rows 8..23 exactly, every sample of them. Parallel rays: the same
 * bits from 10 times farther. On the scalar device and on OpenCL. */
static void test_orthographic_camera(void)
{
    ortho_scene(TEST_TMP("ortho.scene"), "type orthographic  from 0 0 5  at 0 0 0  width 2");
    ortho_scene(TEST_TMP("ortho-far.scene"), "type orthographic  from 0 0 50  at 0 0 0  width 2");
    const char *devices[2] = { "scalar", TEST_OPENCL };
    for (int d = 0; d < 2; d++) {
        cli_run(ARGS(TEST_TMP("ortho.scene"), "--device", devices[d], "-q", "-o", TEST_TMP("ortho.pfm")), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK_MSG(is_lit_rectangle(TEST_TMP("ortho.pfm"), 16, 48, 8, 24), "on %s", devices[d]);
    }
    cli_run(ARGS(TEST_TMP("ortho-far.scene"), "--device", "scalar", "-q", "-o", TEST_TMP("ortho-far.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(TEST_TMP("ortho.pfm"), TEST_TMP("ortho-far.pfm")));
    /* --set camera.width: a view 4 wide draws the lamp 16 columns wide, 8 rows tall */
    cli_run(ARGS(TEST_TMP("ortho.scene"), "--device", "scalar", "-q", "--set", "camera.width=4", "-o", TEST_TMP("ortho4.pfm")),
            &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(is_lit_rectangle(TEST_TMP("ortho4.pfm"), 24, 40, 12, 20));
    /* --lookat moves it: a view centred 1 to the right shows the lamp 32 columns left */
    cli_run(ARGS(TEST_TMP("ortho.scene"), "--device", "scalar", "-q", "--lookat", "1,0,5,1,0,0,0,1,0", "-o",
                 TEST_TMP("ortho-moved.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(is_lit_rectangle(TEST_TMP("ortho-moved.pfm"), 0, 16, 8, 24));
}

/* The keys of one type of camera are refused on the other, in the file and by path. */
static void test_orthographic_camera_errors(void)
{
    static const struct { const char *camera, *want; } bad[] = {
        { "type orthographic  from 0 0 5  at 0 0 0",
          ":2:1: an orthographic camera needs 'width', its view's width in scene units\n" },
        { "type orthographic  from 0 0 5  at 0 0 0  width 2  fov 30",
          ":2:60: 'fov' is for a perspective camera; an orthographic camera sees parallel rays across its 'width'\n" },
        { "from 0 0 5  at 0 0 0  width 2", ":2:32: 'width' is the view's width of an orthographic camera (type "
                                           "orthographic)\n" },
        { "type fisheye  from 0 0 5  at 0 0 0", ":2:15: expected a camera type (perspective, orthographic) for "
                                                "'type', found 'fisheye'\n" },
        { "type orthographic  from 0 0 5  at 0 0 0  width 0", ":2:57: expected a width > 0 (scene units) for "
                                                              "'width', found '0'\n" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ortho_scene(TEST_TMP("bad.scene"), bad[i].camera);
        cli_run(ARGS(TEST_TMP("bad.scene"), "--device", "scalar", "-q", "-o", TEST_TMP("bad.pfm")), &r);
        CHECK_EQ_INT(r.status, 3);
        char want[512];
        snprintf(want, sizeof want, "clpt: error: %s%s", TEST_TMP("bad.scene"), bad[i].want);
        CHECK_MSG(strcmp(r.err, want) == 0, "stderr:\n%s\nwanted:\n%s", r.err, want);
    }
    ortho_scene(TEST_TMP("ortho.scene"), "type orthographic  from 0 0 5  at 0 0 0  width 2");
    CHECK_USAGE(ARGS(TEST_TMP("ortho.scene"), "--set", "camera.fov=30"),
                "clpt: error: scene parameter 'camera.fov': the camera is orthographic, with a view width "
                "(camera.width) and no lens or field of view\n" HINT);
    CHECK_USAGE(ARGS("scenes/cornell-box.scene", "--set", "camera.width=3"),
                "clpt: error: scene parameter 'camera.width': the camera is perspective; camera.width is an "
                "orthographic camera's view width\n" HINT);
    CHECK_USAGE(ARGS(TEST_TMP("ortho.scene"), "--fov", "30"),
                "clpt: error: --fov sets a perspective camera's field of view; the scene's camera is orthographic\n"
                HINT);
}

int main(void)
{
    RUN(test_crop_errors);
    RUN(test_crop_pixels_are_the_whole_renders);
    RUN(test_crop_with_checkpoints_and_merge);
    RUN(test_pbrt_film_crop);
    RUN(test_lookat_and_fov_errors);
    RUN(test_lookat_and_fov_equal_editing_the_scene);
    RUN(test_lookat_and_fov_in_every_format);
    RUN(test_orthographic_camera);
    RUN(test_orthographic_camera_errors);
    return harness_report();
}
