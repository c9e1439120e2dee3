/* test_scene_load.c — the one loader (host/io/scene_load.c): which reader an input goes
 * to, that it is read once (so a pipe or FIFO works), and the file reading it rests on
 * (host/io/lexer.c): regular files only for what a scene names, directories and FIFOs
 * refused without blocking, a UTF-8 byte order mark skipped. */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "harness.h"
#include "io/lexer.h"
#include "io/scene_load.h"
#include "scene/scene.h"

static char dir[64];   /* a temporary folder for this test's files */

static const char *in_dir(const char *name)
{
    static char path[4][160];
    static int next;
    char *p = path[next++ % 4];
    snprintf(p, sizeof path[0], "%s/%s", dir, name);
    return p;
}

static void write_file(const char *name, const char *text, size_t len)
{
    FILE *f = fopen(in_dir(name), "wb");
    if (!f) return;
    fwrite(text, 1, len, f);
    fclose(f);
}

static const char ours[] = "camera { from 0 0 5 at 0 0 0 }\n"
                           "material m { type diffuse albedo 1 1 1 }\n"
                           "sphere { center 0 0 0 radius 1 material m }\n";
static const char classic[] = "# a course scene\n"
                              "PerspectiveCamera { center 0 0 5 direction 0 0 -1 up 0 1 0 angle 30 }\n"
                              "Group { numObjects 1 Sphere { radius 1 } }\n";
static const char obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

static void test_kind(void)
{
    CHECK_EQ_INT(scene_load_kind("a.scene", ours, strlen(ours), SCENE_FORMAT_AUTO), SCENE_KIND_CLPT);
    CHECK_EQ_INT(scene_load_kind("a.txt", classic, strlen(classic), SCENE_FORMAT_AUTO), SCENE_KIND_CLASSIC);
    CHECK_EQ_INT(scene_load_kind("/dev/stdin", classic, strlen(classic), SCENE_FORMAT_AUTO), SCENE_KIND_CLASSIC);
    CHECK_EQ_INT(scene_load_kind("m.OBJ", obj, strlen(obj), SCENE_FORMAT_AUTO), SCENE_KIND_MESH);
    CHECK_EQ_INT(scene_load_kind("d/m.ply", "", 0, SCENE_FORMAT_AUTO), SCENE_KIND_MESH);
    CHECK_EQ_INT(scene_load_kind("m.obj/scene", ours, strlen(ours), SCENE_FORMAT_AUTO), SCENE_KIND_CLPT);
    /* a format given wins over the content and the name */
    CHECK_EQ_INT(scene_load_kind("a.txt", classic, strlen(classic), SCENE_FORMAT_CLPT), SCENE_KIND_CLPT);
    CHECK_EQ_INT(scene_load_kind("a.scene", ours, strlen(ours), SCENE_FORMAT_CLASSIC), SCENE_KIND_CLASSIC);
    CHECK_EQ_INT(scene_load_kind("m.obj", obj, strlen(obj), SCENE_FORMAT_CLPT), SCENE_KIND_CLPT);
}

/* Each kind from bytes in memory, with and without a byte order mark. */
static void test_bytes(void)
{
    static const struct { const char *name, *text; SceneKind kind; uint integrator; size_t spheres, tris; } cases[] = {
        { "a.scene", ours, SCENE_KIND_CLPT, INTEGRATOR_PATH, 1, 0 },
        { "a.txt", classic, SCENE_KIND_CLASSIC, INTEGRATOR_WHITTED, 1, 0 },
        { "m.obj", obj, SCENE_KIND_MESH, INTEGRATOR_PATH, 1, 1 },   /* and the sun */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        for (int bom = 0; bom < 2; bom++) {
            char text[512];
            int n = snprintf(text, sizeof text, "%s%s", bom ? "\xEF\xBB\xBF" : "", cases[i].text);
            Scene s;
            Error err = { 0 };
            scene_init(&s);
            SceneKind kind = 0;
            Status st = scene_load_bytes(in_dir(cases[i].name), text, (size_t)n, SCENE_FORMAT_AUTO, &s, &kind, &err);
            CHECK_MSG(st == ST_OK, "%s%s: %s", cases[i].name, bom ? " with a BOM" : "", err.msg);
            CHECK_EQ_INT(kind, cases[i].kind);
            CHECK_EQ_INT(s.integrator, cases[i].integrator);
            CHECK_EQ_INT(s.n_spheres, cases[i].spheres);
            CHECK_EQ_INT(s.n_triangles, cases[i].tris);
            scene_free(&s);
            error_clear(&err);
        }
}

/* The file is read once: a FIFO with a writer behind it loads whole, in either format. */
static void test_fifo_scene(void)
{
    const char *texts[2] = { ours, classic };
    for (int i = 0; i < 2; i++) {
        const char *path = in_dir("fifo");
        unlink(path);
        CHECK_EQ_INT(mkfifo(path, 0600), 0);
        pid_t pid = fork();
        if (pid == 0) {
            int fd = open(path, O_WRONLY);
            ssize_t w = fd >= 0 ? write(fd, texts[i], strlen(texts[i])) : -1;
            _exit(w == (ssize_t)strlen(texts[i]) ? 0 : 1);
        }
        Scene s;
        Error err = { 0 };
        scene_init(&s);
        SceneKind kind = 0;
        Status st = scene_load_file(path, SCENE_FORMAT_AUTO, &s, &kind, &err);
        int wstatus = 0;
        waitpid(pid, &wstatus, 0);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        CHECK_EQ_INT(kind, i ? SCENE_KIND_CLASSIC : SCENE_KIND_CLPT);
        CHECK_EQ_INT(s.n_spheres, 1);
        scene_free(&s);
        error_clear(&err);
        unlink(path);
    }
}

/* What a scene names must be a regular file: FIFOs and folders are refused at once. */
static void test_regular_files_only(void)
{
    const char *fifo = in_dir("named.obj"), *folder = in_dir("folder.obj");
    unlink(fifo);
    CHECK_EQ_INT(mkfifo(fifo, 0600), 0);
    mkdir(folder, 0700);
    char *data = NULL;
    size_t len;
    Error err = { 0 };
    char want[300];
    CHECK_EQ_INT(lex_read_file(fifo, &data, &len, &err), ST_IO);
    snprintf(want, sizeof want, "cannot read '%s': it is a pipe, not a regular file", fifo);
    CHECK_STR_CONTAINS(err.msg, want);
    CHECK_EQ_INT(lex_check_file(fifo, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, want);
    CHECK_EQ_INT(lex_read_file(folder, &data, &len, &err), ST_IO);
    snprintf(want, sizeof want, "cannot read '%s': it is a directory, not a file", folder);
    CHECK(strcmp(err.msg, want) == 0);
    CHECK_EQ_INT(lex_check_file(folder, &err), ST_IO);
    CHECK(strcmp(err.msg, want) == 0);
    /* the scene itself may not be a folder either */
    Scene s;
    scene_init(&s);
    CHECK_EQ_INT(scene_load_file(folder, SCENE_FORMAT_AUTO, &s, NULL, &err), ST_IO);
    CHECK(strcmp(err.msg, want) == 0);
    scene_free(&s);
    /* a mesh named by a scene, a FIFO: refused, not waited on */
    char text[256];
    int n = snprintf(text, sizeof text, "camera { from 0 0 5 at 0 0 0 }\nmesh { file \"named.obj\" }\n");
    write_file("mesh.scene", text, (size_t)n);
    scene_init(&s);
    CHECK_EQ_INT(scene_load_file(in_dir("mesh.scene"), SCENE_FORMAT_AUTO, &s, NULL, &err), ST_IO);
    CHECK_STR_CONTAINS(err.msg, "mesh.scene:2:13: cannot read '");
    CHECK_STR_CONTAINS(err.msg, "it is a pipe, not a regular file");
    scene_free(&s);
    /* a regular file is read whole, its byte order mark dropped */
    write_file("bom.txt", "\xEF\xBB\xBFv 1\n", 7);
    CHECK_EQ_INT(lex_read_file(in_dir("bom.txt"), &data, &len, &err), ST_OK);
    CHECK_EQ_INT(len, 4);
    CHECK(data && strcmp(data, "v 1\n") == 0);
    free(data);
    CHECK_EQ_INT(lex_check_file(in_dir("bom.txt"), &err), ST_OK);
    unlink(fifo);
    rmdir(folder);
    error_clear(&err);
}

/* A bare mesh from a pipe is a mesh scene too: the name decides, the bytes are read once. */
static void test_mesh_file(void)
{
    write_file("m.obj", obj, strlen(obj));
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    SceneKind kind = 0;
    CHECK_EQ_INT(scene_load_file(in_dir("m.obj"), SCENE_FORMAT_AUTO, &s, &kind, &err), ST_OK);
    CHECK_EQ_INT(kind, SCENE_KIND_MESH);
    CHECK_EQ_INT(s.n_triangles, 1);
    CHECK_EQ_INT(s.bg_type, BG_SKY);
    CHECK(s.path && strcmp(s.path, in_dir("m.obj")) == 0);
    scene_free(&s);
    error_clear(&err);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/clpt-test-load-XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(test_kind);
    RUN(test_bytes);
    RUN(test_fifo_scene);
    RUN(test_regular_files_only);
    RUN(test_mesh_file);
    const char *names[] = { "m.obj", "mesh.scene", "bom.txt", "fifo", "named.obj" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) unlink(in_dir(names[i]));
    rmdir(dir);
    return harness_report();
}
