/* test_cli.c — the program as a user meets it: help, exit codes, error messages, the
 * device flag, and a real render to each output format. */
#include "cli_util.h"
#include "harness.h"

static CliResult r;   /* large: static */

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static void test_help_documents_every_flag(void)
{
    cli_run(ARGS("--help"), &r);
    CHECK_EQ_INT(r.status, 0);
    const char *flags[] = { "--output", "--spp", "--width", "--height", "--seed", "--max-depth", "--time-limit",
                            "--progressive-output", "--list-devices", "--device", "--threads", "--stats",
                            "--quiet", "--help", "--version", "--kernel-dir", "--batch", "--wave-paths",
                            "Exit status" };
    for (size_t i = 0; i < sizeof flags / sizeof flags[0]; i++) CHECK_STR_CONTAINS(r.out, flags[i]);
}

static void test_usage_errors(void)
{
    cli_run(ARGS("--spp"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--spp needs a value");
    cli_run(ARGS("scenes/cornell-box.scene", "--spp", "ten"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "--spp expects an integer, got 'ten'");
    cli_run(ARGS("scenes/cornell-box.scene", "--width", "0"), &r);
    CHECK_EQ_INT(r.status, 2);
    cli_run(ARGS("--frobnicate"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "unknown option '--frobnicate'");
    cli_run(ARGS("-q"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "no scene given");
    cli_run(ARGS("scenes/cornell-box.scene", "-o", "image.jpg"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, ".jpg");
}

static void test_missing_scene_is_io_error(void)
{
    cli_run(ARGS("/nonexistent/scene.scene", "-o", "/tmp/x.png"), &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "/nonexistent/scene.scene");
}

static void test_parse_error_names_line_and_column(void)
{
    char path[256];
    write_temp(path, sizeof path, ".scene", "# a bad scene\ncamera { from 0 0 5 at 0 0 0 }\nsphere { center 0 0 zero radius 1 }\n");
    cli_run(ARGS(path, "-o", "/tmp/clpt-never.png"), &r);
    CHECK_EQ_INT(r.status, 3);
    char where[300];
    snprintf(where, sizeof where, "%s:3:", path);
    CHECK_STR_CONTAINS(r.err, where);
    CHECK_STR_CONTAINS(r.err, "zero");
    CHECK(!file_exists("/tmp/clpt-never.png"));
    unlink(path);
}

static void test_unknown_device_lists_devices(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "99", "-o", "/tmp/clpt-never.png"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "no device matches '99'");
    CHECK_STR_CONTAINS(r.err, "scalar");
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "no-such-gpu", "-o", "/tmp/clpt-never.png"), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "no-such-gpu");
}

static void test_list_devices(void)
{
    cli_run(ARGS("--list-devices"), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_STR_CONTAINS(r.out, "scalar");
    CHECK_STR_CONTAINS(r.out, "opencl");   /* PoCL is installed by make test */
}

static void check_render(const char *device, const char *out, const char *magic)
{
    unlink(out);
    cli_run(ARGS("scenes/cornell-box.scene", "--device", device, "--width", "16", "--height", "12", "--spp", "2",
                 "-o", out),
            &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
    FILE *f = fopen(out, "rb");
    CHECK_MSG(f != NULL, "no output %s", out);
    if (f) {
        char head[8] = { 0 };
        size_t n = fread(head, 1, strlen(magic), f);
        CHECK(n == strlen(magic) && memcmp(head, magic, n) == 0);
        fclose(f);
    }
    CHECK_STR_CONTAINS(r.err, "Msamples/s");   /* the summary line */
    unlink(out);
}

static void test_render_each_format(void)
{
    check_render("scalar", "/tmp/clpt-test-render.png", "\x89PNG");
    check_render("cpu", "/tmp/clpt-test-render.ppm", "P6");
    check_render("0", "/tmp/clpt-test-render.pfm", "PF");
}

static void test_quiet_prints_nothing(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "-q", "--device", "scalar", "--width", "8", "--height", "8", "--spp", "1",
                 "-o", "/tmp/clpt-test-quiet.png"),
            &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_EQ_INT(strlen(r.err), 0);
    unlink("/tmp/clpt-test-quiet.png");
}

static void test_unwritable_output_is_io_error(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--device", "scalar", "--width", "8", "--height", "8", "--spp", "1",
                 "-o", "/nonexistent-dir/out.png"),
            &r);
    CHECK_EQ_INT(r.status, 4);
    CHECK_STR_CONTAINS(r.err, "/nonexistent-dir/out.png");
}

static void test_stats(void)
{
    cli_run(ARGS("scenes/cornell-box.scene", "--stats", "-q", "--device", "cpu", "--width", "8", "--height", "8",
                 "--spp", "1", "-o", "/tmp/clpt-test-stats.png"),
            &r);
    CHECK_EQ_INT(r.status, 0);
    const char *want[] = { "kd-tree: built in", "nodes", "leaves", "depth", "SAH cost", "kernels", "Msamples/s",
                           "Mrays/s", "total" };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) CHECK_STR_CONTAINS(r.out, want[i]);
    unlink("/tmp/clpt-test-stats.png");
}

/* Runs `script` with sh -c, $CLPT naming the program: for pipes and FIFOs, which need a
 * shell around clpt. Each clpt in a script runs under `timeout`, so that a regression
 * that blocks on a pipe fails the test (exit 124) instead of hanging it. */
static void shell_run(const char *script, CliResult *res)
{
    char out_name[] = "/tmp/clpt-cli-out-XXXXXX", err_name[] = "/tmp/clpt-cli-err-XXXXXX";
    int out_fd = mkstemp(out_name), err_fd = mkstemp(err_name);
    unlink(out_name);
    unlink(err_name);
    pid_t pid = fork();
    if (pid == 0) {
        dup2(out_fd, 1);
        dup2(err_fd, 2);
        setenv("CLPT", CLI_PROGRAM, 1);
        execl("/bin/sh", "sh", "-c", script, (char *)NULL);
        _exit(127);
    }
    CliChild c = { pid, out_fd, err_fd };
    cli_finish(c, res);
}

#define PIPE_FLAGS "-q --device scalar --width 16 --height 12 --spp 2"

/* The scene read from a pipe or a FIFO is read once: it renders the same image as from
 * the file (it was read twice, once to tell the format, and rendered empty). */
static void test_scene_from_pipe(void)
{
    shell_run("set -e; d=$(mktemp -d /tmp/clpt-test-pipe-XXXXXX); trap 'rm -rf \"$d\"' EXIT\n"
              "timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/file.pfm\" scenes/cornell-box.scene\n"
              "cat scenes/cornell-box.scene | timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/stdin.pfm\" /dev/stdin\n"
              "cmp \"$d/file.pfm\" \"$d/stdin.pfm\"\n"
              "mkfifo \"$d/fifo\"; cat scenes/cornell-box.scene > \"$d/fifo\" &\n"
              "timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/fifo.pfm\" \"$d/fifo\"\n"
              "cmp \"$d/file.pfm\" \"$d/fifo.pfm\"\n"
              /* a classic scene is told from ours by its content: read once, it is both */
              "timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/classic.pfm\" scenes/classic/spheres.txt\n"
              "cat scenes/classic/spheres.txt | timeout 60 \"$CLPT\" " PIPE_FLAGS " -o \"$d/classic-stdin.pfm\" /dev/stdin\n"
              "cmp \"$d/classic.pfm\" \"$d/classic-stdin.pfm\"\n"
              /* --format still chooses */
              "cat scenes/classic/spheres.txt | timeout 60 \"$CLPT\" " PIPE_FLAGS " --format classic "
              "-o \"$d/classic-forced.pfm\" /dev/stdin\n"
              "cmp \"$d/classic.pfm\" \"$d/classic-forced.pfm\"\n"
              "echo all-same\n", &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
    CHECK_STR_CONTAINS(r.out, "all-same");
}

/* What a scene names (a mesh, a texture, an include, an MTL file) must be a regular
 * file: a FIFO there is refused at once (it blocked clpt for ever), a directory is an
 * I/O error (exit 4). */
static void test_named_files_must_be_regular(void)
{
    static const struct {
        const char *scene;      /* written to $d/s.scene; $d/x.* are FIFOs or folders */
        const char *message;
    } cases[] = {
        { "mesh { file \"x.obj\" material m }",
          "/s.scene:3:13: cannot read '" },
        { "texture t { type image file \"x.png\" }",
          "cannot read '" },
        { "include \"x.scene\"",
          "/s.scene:3:9: cannot read '" },
    };
    for (int dir = 0; dir < 2; dir++)
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            char script[2048];
            snprintf(script, sizeof script,
                     "d=$(mktemp -d /tmp/clpt-test-fifo-XXXXXX); trap 'rm -rf \"$d\"' EXIT\n"
                     "for x in x.obj x.png x.scene; do %s \"$d/$x\"; done\n"
                     "printf 'camera { from 0 0 5 at 0 0 0 }\\nmaterial m { type diffuse albedo 1 1 1 }\\n%%s\\n' '%s' "
                     "> \"$d/s.scene\"\n"
                     "timeout 20 \"$CLPT\" " PIPE_FLAGS " -o \"$d/o.png\" \"$d/s.scene\"\n",
                     dir ? "mkdir" : "mkfifo", cases[i].scene);
            shell_run(script, &r);
            CHECK_MSG(r.status == 4, "%s (%s): exit %d: %s", cases[i].scene, dir ? "a folder" : "a FIFO", r.status,
                      r.err);
            CHECK_STR_CONTAINS(r.err, cases[i].message);
            CHECK_STR_CONTAINS(r.err, dir ? "it is a directory, not a file" : "it is a pipe, not a regular file");
        }
    /* an OBJ's MTL file that is a FIFO is skipped like a missing one, without waiting */
    shell_run("d=$(mktemp -d /tmp/clpt-test-fifo-XXXXXX); trap 'rm -rf \"$d\"' EXIT\n"
              "mkfifo \"$d/x.mtl\"\n"
              "printf 'mtllib x.mtl\\nv 0 0 0\\nv 1 0 0\\nv 0 1 0\\nusemtl a\\nf 1 2 3\\n' > \"$d/m.obj\"\n"
              "timeout 20 \"$CLPT\" " PIPE_FLAGS " -o \"$d/o.png\" \"$d/m.obj\"\n", &r);
    CHECK_MSG(r.status == 0, "exit %d: %s", r.status, r.err);
}

int main(void)
{
    RUN(test_help_documents_every_flag);
    RUN(test_usage_errors);
    RUN(test_missing_scene_is_io_error);
    RUN(test_parse_error_names_line_and_column);
    RUN(test_unknown_device_lists_devices);
    RUN(test_list_devices);
    RUN(test_render_each_format);
    RUN(test_quiet_prints_nothing);
    RUN(test_unwritable_output_is_io_error);
    RUN(test_stats);
    RUN(test_scene_from_pipe);
    RUN(test_named_files_must_be_regular);
    return harness_report();
}
