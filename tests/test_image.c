/* test_image.c — format from the extension, sRGB encoding, PNG/PPM/PFM round trips and
 * the atomic writer's failure behaviour. */
#include <dirent.h>
#include <ftw.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stb_image.h>

#include "harness.h"
#include "io/image_write.h"

enum { W = 7, H = 5 };

static char tmpdir[256];

/* A gradient whose top-left corner holds the awkward values: NaN, infinities, negatives,
 * values above 1, a value exactly on the sRGB segment boundary and 0.5. */
static void fill_gradient(float *rgb)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++)
                rgb[(y * W + x) * 3 + c] = (float)x / (W - 1) * 0.9f + (float)y * 0.02f +
                                           (float)c * 0.01f;
    rgb[0] = NAN;
    rgb[1] = INFINITY;
    rgb[2] = -INFINITY;
    rgb[3] = -0.25f;
    rgb[4] = 2.0f;
    rgb[5] = 0.0031308f;
    rgb[6] = 0.5f;
    rgb[7] = 1.0f;
    rgb[8] = 0.0f;
}

static char *path_in(const char *name)
{
    static char buf[512];
    snprintf(buf, sizeof buf, "%s/%s", tmpdir, name);
    return buf;
}

static unsigned char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *data = malloc((size_t)n + 1);
    if (data && fread(data, 1, (size_t)n, f) != (size_t)n) {
        free(data);
        data = NULL;
    }
    fclose(f);
    *len = (size_t)n;
    return data;
}

/* Names in dir that contain ".tmp." — leftovers of an interrupted atomic write. */
static int count_temp_files(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strstr(e->d_name, ".tmp.")) n++;
    closedir(d);
    return n;
}

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) n++;
    closedir(d);
    return n;
}

static void test_format_from_path(void)
{
    ImageFormat f = IMAGE_PFM;
    Error err = {0};
    CHECK_EQ_INT(image_format_from_path("out.png", &f, &err), ST_OK);
    CHECK_EQ_INT(f, IMAGE_PNG);
    CHECK_EQ_INT(image_format_from_path("dir/out.PPM", &f, &err), ST_OK);
    CHECK_EQ_INT(f, IMAGE_PPM);
    CHECK_EQ_INT(image_format_from_path("/a.b/c.Pfm", &f, &err), ST_OK);
    CHECK_EQ_INT(f, IMAGE_PFM);
    CHECK_EQ_INT(image_format_from_path("render.jpg", &f, &err), ST_OK);
    CHECK_EQ_INT(f, IMAGE_JPEG);
    CHECK_EQ_INT(image_format_from_path("render.JPEG", &f, &err), ST_OK);
    CHECK_EQ_INT(f, IMAGE_JPEG);
    CHECK_EQ_INT(image_format_from_path("render.tga", &f, &err), ST_USAGE);
    CHECK_STR_CONTAINS(err.msg, "cannot tell the image format of 'render.tga': unsupported extension '.tga' "
                                "(supported: .png, .jpg, .jpeg, .ppm, .pfm, .bmp, .exr, .hdr)");
    CHECK_EQ_INT(image_format_from_path("render", &f, &err), ST_USAGE);
    CHECK_STR_CONTAINS(err.msg, "no extension");
    CHECK_STR_CONTAINS(err.msg, ".png, .jpg, .jpeg, .ppm, .pfm");
    /* the dot of a folder name is not the file's extension */
    CHECK_EQ_INT(image_format_from_path("out.png/render", &f, &err), ST_USAGE);
    CHECK_EQ_INT(image_format_from_path("out.png.bak", &f, &err), ST_USAGE);
    error_clear(&err);
}

static void test_srgb_encode(void)
{
    CHECK_EQ_INT(image_srgb_encode(0.0f) == 0.0f, 1);
    CHECK_EQ_INT(image_srgb_encode(1.0f) == 1.0f, 1);
    CHECK_EQ_INT(image_srgb_encode(NAN) == 0.0f, 1);
    CHECK_EQ_INT(image_srgb_encode(-3.0f) == 0.0f, 1);
    CHECK_EQ_INT(image_srgb_encode(7.0f) == 1.0f, 1);
    CHECK_EQ_INT(image_srgb_encode(INFINITY) == 1.0f, 1);
    /* the two segments meet (to 1e-7) at the boundary 0.0031308 -> 0.04045 */
    CHECK_NEAR(image_srgb_encode(0.0031308f), 0.04045, 2e-7);
    CHECK_NEAR(image_srgb_encode(0.0031309f), 0.04045, 2e-6);
    CHECK_NEAR(image_srgb_encode(0.001f), 0.01292, 1e-7);
    CHECK_NEAR(image_srgb_encode(0.5f), 0.735356983, 1e-6);
    CHECK_NEAR(image_srgb_encode(0.2f), 0.484529, 1e-6);
    CHECK_EQ_INT(image_to_srgb8(0.5f), 188);
    CHECK_EQ_INT(image_to_srgb8(0.0f), 0);
    CHECK_EQ_INT(image_to_srgb8(1.0f), 255);
    CHECK_EQ_INT(image_to_srgb8(NAN), 0);
    CHECK_EQ_INT(image_to_srgb8(0.0031308f), 10); /* 0.04045 * 255 = 10.31 */
    /* rounded to nearest, not truncated */
    CHECK_EQ_INT(image_to_srgb8(0.2f), 124);   /* 0.484529 * 255 = 123.55 */
    CHECK_EQ_INT(image_to_srgb8(0.214f), 127); /* 0.499956 * 255 = 127.49 */
    /* monotonic over the whole range */
    unsigned prev = 0;
    int monotonic = 1;
    for (int i = 0; i <= 10000; i++) {
        unsigned v = image_to_srgb8((float)i / 10000.0f);
        if (v < prev) monotonic = 0;
        prev = v;
    }
    CHECK(monotonic);
    CHECK_EQ_INT(prev, 255);
}

static void test_png_round_trip(void)
{
    float rgb[W * H * 3];
    fill_gradient(rgb);
    Error err = {0};
    const char *path = path_in("grad.png");
    CHECK_EQ_INT(image_write(path, rgb, W, H, &err), ST_OK);
    int w = 0, h = 0, n = 0;
    unsigned char *px = stbi_load(path, &w, &h, &n, 3);
    CHECK(px != NULL);
    if (!px) return;
    CHECK_EQ_INT(w, W);
    CHECK_EQ_INT(h, H);
    CHECK_EQ_INT(n, 3);
    int mismatches = 0;
    for (int i = 0; i < W * H * 3; i++)
        if (px[i] != image_to_srgb8(rgb[i])) mismatches++;
    CHECK_EQ_INT(mismatches, 0);
    /* NaN, +inf, -inf, -0.25, 2, boundary, 0.5, 1, 0 */
    const unsigned char expect[9] = {0, 255, 0, 0, 255, 10, 188, 255, 0};
    CHECK(memcmp(px, expect, 9) == 0);
    /* top row first: the bottom-right pixel is the brightest of the gradient */
    CHECK_EQ_INT(px[(W * H - 1) * 3], image_to_srgb8(0.9f + 0.08f));
    stbi_image_free(px);
    CHECK_EQ_INT(count_temp_files(tmpdir), 0);
    error_clear(&err);
}

/* 16-bit PNG: each value is the sRGB curve (or the linear value) times 65535, rounded
 * to nearest, read back through stb_image's 16-bit loader. */
static void test_png16_round_trip(void)
{
    float rgb[W * H * 3];
    fill_gradient(rgb);
    Error err = {0};
    const char *path = path_in("grad16.png");
    for (int linear = 0; linear < 2; linear++) {
        ImageStyle style = { (ImageEncoding)(IMAGE_PNG16 | (linear ? IMAGE_LINEAR : 0)), { VIEW_STANDARD, 0.0 }, 0 };
        CHECK_EQ_INT(image_write_styled(path, rgb, W, H, &style, &err), ST_OK);
        int w = 0, h = 0, n = 0;
        CHECK(stbi_is_16_bit(path));
        stbi_us *px = stbi_load_16(path, &w, &h, &n, 3);
        CHECK(px != NULL);
        if (!px) return;
        CHECK_EQ_INT(w, W);
        CHECK_EQ_INT(h, H);
        int mismatches = 0;
        for (int i = 0; i < W * H * 3; i++) {
            double x = rgb[i], c = !(x > 0.0) ? 0.0 : x >= 1.0 ? 1.0 : x;
            if (!linear) c = c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
            /* image_srgb_encode rounds to float before the scaling */
            double v = linear ? c : (double)(float)c;
            if (px[i] != (stbi_us)floor(v * 65535.0 + 0.5)) mismatches++;
        }
        CHECK_EQ_INT(mismatches, 0);
        /* NaN, +inf, -inf, -0.25, 2 and 1 are the ends; 0.5 is 0.7354 in sRGB */
        CHECK(px[0] == 0 && px[1] == 65535 && px[2] == 0 && px[3] == 0 && px[4] == 65535 && px[7] == 65535);
        CHECK_EQ_INT(px[6], linear ? 32768 : 48192);
        stbi_image_free(px);
    }
    CHECK_EQ_INT(count_temp_files(tmpdir), 0);
    error_clear(&err);
}

/* JPEG is lossy: the decoded gradient stays within a few steps of the 8-bit sRGB
 * bytes at the default quality, and a lower quality makes a smaller file. */
static void test_jpeg_round_trip(void)
{
    float rgb[W * H * 3];
    for (int i = 0; i < W * H * 3; i++) rgb[i] = (float)(i / 3 % W) / (float)W * 0.8f + 0.1f;
    Error err = {0};
    const char *path = path_in("grad.jpg");
    CHECK_EQ_INT(image_write(path, rgb, W, H, &err), ST_OK);
    int w = 0, h = 0, n = 0;
    unsigned char *px = stbi_load(path, &w, &h, &n, 3);
    CHECK(px != NULL);
    if (!px) return;
    CHECK_EQ_INT(w, W);
    CHECK_EQ_INT(h, H);
    int worst = 0;
    for (int i = 0; i < W * H * 3; i++) {
        int d = abs((int)px[i] - (int)image_to_srgb8(rgb[i]));
        worst = d > worst ? d : worst;
    }
    CHECK_MSG(worst <= 6, "worst difference %d", worst);
    stbi_image_free(px);
    struct stat big, small;
    CHECK(stat(path, &big) == 0);
    ImageStyle low = { IMAGE_SRGB, { VIEW_STANDARD, 0.0 }, 5 };
    CHECK_EQ_INT(image_write_styled(path, rgb, W, H, &low, &err), ST_OK);
    CHECK(stat(path, &small) == 0 && small.st_size < big.st_size);
    CHECK_EQ_INT(count_temp_files(tmpdir), 0);
    error_clear(&err);
}

static void test_ppm_round_trip(void)
{
    float rgb[W * H * 3];
    fill_gradient(rgb);
    Error err = {0};
    const char *path = path_in("grad.ppm");
    CHECK_EQ_INT(image_write(path, rgb, W, H, &err), ST_OK);
    size_t len = 0;
    unsigned char *data = read_file(path, &len);
    CHECK(data != NULL);
    if (!data) return;
    const char header[] = "P6\n7 5\n255\n";
    size_t hl = sizeof header - 1;
    CHECK_EQ_INT(len, hl + W * H * 3);
    CHECK(memcmp(data, header, hl) == 0);
    int mismatches = 0;
    for (int i = 0; i < W * H * 3 && hl + (size_t)i < len; i++)
        if (data[hl + (size_t)i] != image_to_srgb8(rgb[i])) mismatches++;
    CHECK_EQ_INT(mismatches, 0);
    CHECK_EQ_INT(data[hl + 6], 188);
    free(data);
    error_clear(&err);
}

static void test_pfm_round_trip(void)
{
    float rgb[W * H * 3];
    fill_gradient(rgb);
    Error err = {0};
    const char *path = path_in("grad.pfm");
    CHECK_EQ_INT(image_write(path, rgb, W, H, &err), ST_OK);
    size_t len = 0;
    unsigned char *data = read_file(path, &len);
    CHECK(data != NULL);
    if (!data) return;
    const char header[] = "PF\n7 5\n-1.0\n";
    size_t hl = sizeof header - 1;
    CHECK_EQ_INT(len, hl + W * H * 12);
    CHECK(memcmp(data, header, hl) == 0);
    /* file row r holds image row H-1-r; floats little-endian, bits unchanged (NaN too) */
    int mismatches = 0;
    for (int r = 0; r < H && len == hl + W * H * 12; r++)
        for (int i = 0; i < W * 3; i++) {
            const unsigned char *b = data + hl + ((size_t)r * W * 3 + (size_t)i) * 4;
            uint32_t got = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
                           (uint32_t)b[3] << 24;
            uint32_t want;
            memcpy(&want, &rgb[(H - 1 - r) * W * 3 + i], 4);
            if (got != want) mismatches++;
        }
    CHECK_EQ_INT(mismatches, 0);
    /* the special values sit in the last stored row (the image's top row) */
    const unsigned char *top = data + hl + (size_t)(H - 1) * W * 12;
    float first;
    uint32_t bits = (uint32_t)top[0] | (uint32_t)top[1] << 8 | (uint32_t)top[2] << 16 |
                    (uint32_t)top[3] << 24;
    memcpy(&first, &bits, 4);
    CHECK(isnan(first));
    free(data);
    error_clear(&err);
}

static void test_missing_folder_fails_cleanly(void)
{
    float rgb[W * H * 3];
    fill_gradient(rgb);
    char sub[512];
    snprintf(sub, sizeof sub, "%s/empty", tmpdir);
    CHECK_EQ_INT(mkdir(sub, 0755), 0);
    char path[600];
    snprintf(path, sizeof path, "%s/no/such/dir/out.png", sub);
    Error err = {0};
    CHECK_EQ_INT(image_write(path, rgb, W, H, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "cannot write '");
    CHECK_STR_CONTAINS(err.msg, "no/such/dir/out.png");
    CHECK_STR_CONTAINS(err.msg, "No such file or directory");
    /* the new formats go through the same atomic file */
    snprintf(path, sizeof path, "%s/no/such/dir/out.jpg", sub);
    CHECK_EQ_INT(image_write(path, rgb, W, H, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "no/such/dir/out.jpg");
    ImageStyle deep = { IMAGE_PNG16, { VIEW_STANDARD, 0.0 }, 0 };
    snprintf(path, sizeof path, "%s/no/such/dir/out16.png", sub);
    CHECK_EQ_INT(image_write_styled(path, rgb, W, H, &deep, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "no/such/dir/out16.png");
    CHECK_EQ_INT(count_entries(sub), 0);
    error_clear(&err);
}

static void test_folder_is_a_file(void)
{
    float rgb[W * H * 3];
    fill_gradient(rgb);
    char sub[512];
    snprintf(sub, sizeof sub, "%s/filedir", tmpdir);
    CHECK_EQ_INT(mkdir(sub, 0755), 0);
    char file[600], path[700];
    snprintf(file, sizeof file, "%s/plain", sub);
    FILE *f = fopen(file, "w");
    CHECK(f != NULL);
    if (f) fclose(f);
    snprintf(path, sizeof path, "%s/out.pfm", file);
    Error err = {0};
    CHECK_EQ_INT(image_write(path, rgb, W, H, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "Not a directory");
    CHECK_EQ_INT(count_entries(sub), 1);
    CHECK_EQ_INT(count_temp_files(sub), 0);
    error_clear(&err);
}

/* The temporary file is created, then the rename fails (a folder stands at the target):
 * the temporary file must be removed and the folder left as it was. Works as root too. */
static void test_failed_rename_leaves_no_temp(void)
{
    float rgb[W * H * 3];
    fill_gradient(rgb);
    char sub[512];
    snprintf(sub, sizeof sub, "%s/renamefail", tmpdir);
    CHECK_EQ_INT(mkdir(sub, 0755), 0);
    char path[600], inner[700];
    snprintf(path, sizeof path, "%s/taken.ppm", sub);
    CHECK_EQ_INT(mkdir(path, 0755), 0);
    snprintf(inner, sizeof inner, "%s/keep", path);
    FILE *f = fopen(inner, "w");
    CHECK(f != NULL);
    if (f) fclose(f);
    Error err = {0};
    CHECK_EQ_INT(image_write(path, rgb, W, H, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "rename");
    CHECK_EQ_INT(count_temp_files(sub), 0);
    CHECK_EQ_INT(count_entries(sub), 1);
    struct stat st;
    CHECK(stat(path, &st) == 0 && S_ISDIR(st.st_mode));
    CHECK(access(inner, F_OK) == 0);
    error_clear(&err);
}

static void test_overwrite_replaces(void)
{
    const char *path = path_in("over.ppm");
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f) return;
    /* longer than the new image, so a non-truncating write would leave a tail */
    for (int i = 0; i < 400; i++) fputs("old contents ", f);
    fclose(f);
    float rgb[2 * 1 * 3] = {0.5f, 0.5f, 0.5f, 1.0f, 0.0f, 0.0f};
    Error err = {0};
    CHECK_EQ_INT(image_write(path, rgb, 2, 1, &err), ST_OK);
    size_t len = 0;
    unsigned char *data = read_file(path, &len);
    const unsigned char want[] = "P6\n2 1\n255\n\xbc\xbc\xbc\xff\x00\x00";
    CHECK_EQ_INT(len, sizeof want - 1);
    CHECK(data && len == sizeof want - 1 && memcmp(data, want, len) == 0);
    free(data);
    /* an ordinary file's mode, not mkstemp's 0600 */
    mode_t mask = umask(0);
    umask(mask);
    struct stat st;
    CHECK(stat(path, &st) == 0);
    CHECK_EQ_INT(st.st_mode & 0777, 0666 & ~mask);
    CHECK_EQ_INT(count_temp_files(tmpdir), 0);
    error_clear(&err);
}

static void test_unknown_extension_writes_nothing(void)
{
    float rgb[3] = {1.0f, 1.0f, 1.0f};
    Error err = {0};
    int before = count_entries(tmpdir);
    CHECK_EQ_INT(image_write(path_in("out.tiff"), rgb, 1, 1, &err), ST_USAGE);
    CHECK_EQ_INT(count_entries(tmpdir), before);
    CHECK_EQ_INT(image_write(path_in("empty.png"), rgb, 0, 1, &err), ST_INTERNAL);
    CHECK_EQ_INT(count_entries(tmpdir), before);
    error_clear(&err);
}

static int remove_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
    (void)sb;
    (void)flag;
    (void)ftw;
    return remove(path);
}

int main(void)
{
    const char *base = getenv("TMPDIR");
    snprintf(tmpdir, sizeof tmpdir, "%s/clpt-test-image.XXXXXX", base && base[0] ? base : "/tmp");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(test_format_from_path);
    RUN(test_srgb_encode);
    RUN(test_png_round_trip);
    RUN(test_png16_round_trip);
    RUN(test_jpeg_round_trip);
    RUN(test_ppm_round_trip);
    RUN(test_pfm_round_trip);
    RUN(test_missing_folder_fails_cleanly);
    RUN(test_folder_is_a_file);
    RUN(test_failed_rename_leaves_no_temp);
    RUN(test_overwrite_replaces);
    RUN(test_unknown_extension_writes_nothing);
    nftw(tmpdir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    return harness_report();
}
