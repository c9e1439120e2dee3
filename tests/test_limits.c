/* test_limits.c — the limits of host/base/limit.h, checked before allocation: header counts
 * against the bytes that follow, byte counts that overflow, image sizes, and files that
 * are too large, endless (/dev/zero) or streamed (a pipe). */
#include <fcntl.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "harness.h"
#include "io/lexer.h"
#include "io/scene_load.h"
#include "base/limit.h"
#include "scene/scene.h"

static void test_count(void)
{
    Error err = { 0 };
    /* 1000 vertices of 12 bytes need 12000 */
    CHECK_EQ_INT(limit_count("m.ply:3:16", "vertices", 1000, 12, 12000, &err), ST_OK);
    CHECK_EQ_INT(limit_count("m.ply:3:16", "vertices", 1001, 12, 12000, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "m.ply:3:16: the header declares 1001 vertices, but the 12000 bytes after it hold "
                                "at most 1000 (at least 12 bytes each): the file is truncated or the count is wrong");
    /* a count near 2^64 must not wrap into "fits" */
    CHECK_EQ_INT(limit_count("h", "faces", UINT64_MAX, 13, 1u << 20, &err), ST_INPUT);
    CHECK_EQ_INT(limit_count("h", "faces", 0, 13, 0, &err), ST_OK);
    error_clear(&err);
}

static void test_bytes(void)
{
    size_t n = 0;
    CHECK_EQ_INT(limit_bytes(1000, 64, &n), 0);
    CHECK_EQ_INT(n, 64000);
    CHECK_EQ_INT(limit_bytes((uint64_t)SIZE_MAX / 8 + 1, 8, &n), -1);
    CHECK_EQ_INT(limit_bytes(UINT64_MAX, 0, &n), 0);
    CHECK_EQ_INT(n, 0);
}

static void test_pixels(void)
{
    Error err = { 0 };
    CHECK_EQ_INT(limit_pixels(16384, 8192, ST_INPUT, "x", &err), ST_OK);
    CHECK_EQ_INT(limit_pixels(8192, 16384, ST_INPUT, "x", &err), ST_OK);
    CHECK_EQ_INT(limit_pixels(16384, 8193, ST_USAGE, "--width/--height", &err), ST_USAGE);
    CHECK_STR_CONTAINS(err.msg, "--width/--height: an image of 16384x8193 pixels is larger than clpt renders");
    CHECK_EQ_INT(limit_pixels(16385, 1, ST_INPUT, "x", &err), ST_INPUT);
    CHECK_EQ_INT(limit_pixels(UINT64_MAX, UINT64_MAX, ST_INPUT, "x", &err), ST_INPUT);
    /* in a scene, at the key that made it too large */
    Scene s;
    scene_init(&s);
    const char *text = "image {\n  height 16384\n  width 16384\n}\n";
    CHECK_EQ_INT(scene_load_text("big.scene", text, strlen(text), &s, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "big.scene:2:3: an image of 16384x16384 pixels is larger than clpt renders");
    scene_free(&s);
    scene_init(&s);
    text = "image { width 16384 height 8192 }";
    CHECK_EQ_INT(scene_load_text("ok.scene", text, strlen(text), &s, &err), ST_OK);
    scene_free(&s);
    /* a size the command line replaces is left to the check after it (host/main.c)... */
    scene_init(&s);
    s.size_overridden = 1;
    text = "image { width 1048576 height 1048576 }";
    CHECK_EQ_INT(scene_load_text("big.scene", text, strlen(text), &s, &err), ST_OK);
    scene_free(&s);
    /* ...but each side still has a bound, so no file asks for absurd sizes */
    scene_init(&s);
    s.size_overridden = 1;
    text = "image { width 1048577 }";
    CHECK_EQ_INT(scene_load_text("big.scene", text, strlen(text), &s, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "big.scene:1:15: expected an integer in 1..1048576 for 'width', found '1048577'");
    scene_free(&s);
    error_clear(&err);
}

static void test_file_too_large(void)
{
    char path[] = "/tmp/clpt-test-large-XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    if (fd < 0) return;
    /* sparse: no disk space, and never read, because the size is checked first */
    CHECK(ftruncate(fd, (off_t)CLPT_MAX_FILE_BYTES + 1) == 0);
    close(fd);
    char *data = NULL;
    size_t len = 0;
    Error err = { 0 };
    CHECK_EQ_INT(lex_read_file(path, &data, &len, &err), ST_INPUT);
    CHECK_STR_CONTAINS(err.msg, "is 4294967297 bytes, more than the 4294967296 (4 GiB) clpt reads from one file");
    CHECK(data == NULL);
    unlink(path);
    error_clear(&err);
}

static void test_device_file(void)
{
    char *data = NULL;
    size_t len = 0;
    Error err = { 0 };
    CHECK_EQ_INT(lex_read_file("/dev/zero", &data, &len, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "cannot read '/dev/zero': it is a device, not a file");
    CHECK(data == NULL);
    error_clear(&err);
}

static void *write_fifo(void *path)
{
    int fd = open(path, O_WRONLY);
    if (fd >= 0) {
        const char *text = "image { width 7 }\n";
        ssize_t w = write(fd, text, strlen(text));
        (void)w;
        close(fd);
    }
    return NULL;
}

/* `clpt <(generate-scene)` reads a pipe: no size known in advance, read to the end */
static void test_pipe(void)
{
    char dir[] = "/tmp/clpt-test-fifo-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[64];
    snprintf(path, sizeof path, "%s/scene", dir);
    CHECK(mkfifo(path, 0600) == 0);
    pthread_t writer;
    CHECK(pthread_create(&writer, NULL, write_fifo, path) == 0);
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    /* through the one loader, which reads the scene once and lets it be a pipe */
    CHECK_EQ_INT(scene_load_file(path, SCENE_FORMAT_AUTO, &s, NULL, &err), ST_OK);
    CHECK_EQ_INT(s.image.width, 7);
    pthread_join(writer, NULL);
    scene_free(&s);
    unlink(path);
    rmdir(dir);
    error_clear(&err);
}

int main(void)
{
    RUN(test_count);
    RUN(test_bytes);
    RUN(test_pixels);
    RUN(test_file_too_large);
    RUN(test_device_file);
    RUN(test_pipe);
    return harness_report();
}
