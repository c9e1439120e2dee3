/*
 * test_distributed.c — one image from several processes (docs/distributed.md):
 * --sample-range parts merged with `clpt merge` are the same PFM bytes as the render of
 * one process, whatever the split; merges of overlapping, incomplete or foreign parts are
 * refused with exact messages and exit status 3. When mpirun is installed: renders with
 * 2 and 3 MPI ranks are the same PFM bytes as one process's; a rank killed mid-render
 * ends the job with rank 0's message and an intact checkpoint, from which --resume (with
 * another number of ranks) ends with the same bytes; under mpirun --enable-recovery the
 * render goes on without the dead rank; ranks that read different settings are refused.
 */
#include <dirent.h>
#include <time.h>

#include "render/checkpoint.h"

#include "cli_util.h"
#include "harness.h"
#include "file_util.h"

static char dir[64];
static CliResult r;
#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

/* Tiny and quick: the machine running the suite may have two cores. */
#define RENDER "scenes/cornell-box.scene", "--width", "24", "--height", "18", "--spp", "12", "--device", "scalar", \
               "--threads", "1", "-q", "--batch", "2"

static const char *in_dir(const char *name)
{
    static char paths[16][128];
    static int next;
    char *p = paths[next++ % 16];
    snprintf(p, sizeof paths[0], "%s/%s", dir, name);
    return p;
}

static void make_dir(void)
{
    snprintf(dir, sizeof dir, "/tmp/clpt-test-dist-XXXXXX");
    if (!mkdtemp(dir)) perror("mkdtemp");
}

static void remove_dir(void)
{
    file_util_remove_dir(dir);
}

/* The reference: every sample in one process. */
static void render_whole(void)
{
    cli_run(ARGS(RENDER, "-o", in_dir("whole.pfm")), &r);
    CHECK_EQ_INT(r.status, 0);
}

/* Renders part [a, b) into NAME.ckpt (and NAME.pfm). */
static void render_part(const char *range, const char *name)
{
    char ck[128], img[128];
    snprintf(ck, sizeof ck, "%s/%s.ckpt", dir, name);
    snprintf(img, sizeof img, "%s/%s.pfm", dir, name);
    cli_run(ARGS(RENDER, "--sample-range", range, "--checkpoint", ck, "-o", img), &r);
    CHECK_MSG(r.status == 0, "part %s: %s", range, r.err);
}

static void test_three_parts_merge_to_the_whole(void)
{
    render_part("0:5", "a");
    render_part("5:7", "b");
    render_part("7:12", "c");
    /* in any order */
    cli_run(ARGS("merge", "-q", "-o", in_dir("merged.pfm"), "--checkpoint", in_dir("merged.ckpt"), in_dir("c.ckpt"),
                 in_dir("a.ckpt"), in_dir("b.ckpt")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("merged.pfm"), in_dir("whole.pfm")));
    /* a part's own image is not the whole */
    CHECK(!files_equal(in_dir("a.pfm"), in_dir("whole.pfm")));
    /* the merged checkpoint is a finished render: resuming it renders nothing more */
    cli_run(ARGS(RENDER, "--resume", in_dir("merged.ckpt"), "-o", in_dir("resumed.pfm")), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK(files_equal(in_dir("resumed.pfm"), in_dir("whole.pfm")));
}

static void test_another_split_merges_to_the_same_bits(void)
{
    render_part("0:1", "s1");
    render_part("1:12", "s2");
    cli_run(ARGS("merge", "-q", "-o", in_dir("merged2.pfm"), in_dir("s1.ckpt"), in_dir("s2.ckpt")), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK(files_equal(in_dir("merged2.pfm"), in_dir("whole.pfm")));
}

/* A finished render of 5 spp and parts 5:7 and 7:12 of the render of 12 (a render grown
 * after it finished) merge to the 12-spp render, in any order; without the part 5:7 the
 * merge names the samples missing of the 12. */
static void test_a_grown_render_merges(void)
{
    cli_run(ARGS(RENDER, "--spp", "5", "--checkpoint", in_dir("five.ckpt"), "-o", in_dir("five.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS("merge", "-o", in_dir("grown.pfm"), in_dir("c.ckpt"), in_dir("five.ckpt"), in_dir("b.ckpt")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.err, "clpt: merged 3 parts: 24x18, 12 spp -> ");
    CHECK(files_equal(in_dir("grown.pfm"), in_dir("whole.pfm")));
    char msg[256];
    snprintf(msg, sizeof msg, "clpt: error: cannot merge: no part holds samples [5,7) of the 12 per pixel; render "
             "them with --sample-range 5:7 and merge that part too\n");
    cli_run(ARGS("merge", "-o", in_dir("refused.pfm"), in_dir("five.ckpt"), in_dir("c.ckpt")), &r);
    CHECK_EQ_INT(r.status, 3);
    CHECK_STR_CONTAINS(r.err, msg);
    CHECK(!file_exists(in_dir("refused.pfm")));
}

static void expect_merge_refused(const char *const *args, int status, const char *message)
{
    cli_run(args, &r);
    CHECK_EQ_INT(r.status, status);
    CHECK_STR_CONTAINS(r.err, message);
    CHECK(!file_exists(in_dir("refused.pfm")));
}

static void test_merge_refusals(void)
{
    char msg[512];
    snprintf(msg, sizeof msg, "clpt: error: cannot merge: no part holds samples [5,7) of the 12 per pixel; render "
             "them with --sample-range 5:7 and merge that part too\n");
    expect_merge_refused(ARGS("merge", "-o", in_dir("refused.pfm"), in_dir("a.ckpt"), in_dir("c.ckpt")), 3, msg);
    snprintf(msg, sizeof msg, "clpt: error: cannot merge: no part holds samples [7,12) of the 12 per pixel");
    expect_merge_refused(ARGS("merge", "-o", in_dir("refused.pfm"), in_dir("b.ckpt"), in_dir("a.ckpt")), 3, msg);
    snprintf(msg, sizeof msg, "clpt: error: cannot merge: '%s' and '%s' both hold samples [1,5); each sample must "
             "come from one part\n", in_dir("a.ckpt"), in_dir("s2.ckpt"));
    expect_merge_refused(ARGS("merge", "-o", in_dir("refused.pfm"), in_dir("a.ckpt"), in_dir("s2.ckpt")), 3, msg);
    /* another seed is another render */
    cli_run(ARGS(RENDER, "--seed", "7", "--sample-range", "5:7", "--checkpoint", in_dir("seed7.ckpt"), "-o",
                 in_dir("seed7.pfm")), &r);
    CHECK_EQ_INT(r.status, 0);
    snprintf(msg, sizeof msg, "clpt: error: cannot merge '%s' with '%s': they are parts of different renders (its "
             "seed is 7, the first part's 1)\n", in_dir("seed7.ckpt"), in_dir("a.ckpt"));
    expect_merge_refused(ARGS("merge", "-o", in_dir("refused.pfm"), in_dir("a.ckpt"), in_dir("seed7.ckpt"),
                              in_dir("c.ckpt")), 3, msg);
    expect_merge_refused(ARGS("merge", in_dir("a.ckpt")), 2,
                         "clpt: error: merge needs -o OUT (usage: clpt merge -o OUT PART...)\n");
    expect_merge_refused(ARGS("merge", "-o", in_dir("refused.pfm")), 2,
                         "clpt: error: merge needs at least one PART (usage: clpt merge -o OUT PART...)\n");
    snprintf(msg, sizeof msg, "clpt: error: cannot read checkpoint '%s': No such file or directory\n",
             in_dir("missing.ckpt"));
    expect_merge_refused(ARGS("merge", "-o", in_dir("refused.pfm"), in_dir("missing.ckpt")), 4, msg);
}

static void copy_file(const char *from, const char *to)
{
    FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
    char buf[4096];
    size_t n;
    while (in && out && (n = fread(buf, 1, sizeof buf, in)) > 0) fwrite(buf, 1, n, out);
    if (in) fclose(in);
    if (out) fclose(out);
}

/* An output that is one of the parts, by name or through a link, is refused before
 * anything is written: `merge -o p2.pfm p1.ckpt p2.pfm` exited 0 and p2 was gone. */
static void test_merge_refuses_to_overwrite_a_part(void)
{
    char msg[1024];
    copy_file(in_dir("b.ckpt"), in_dir("pb.pfm"));   /* a part whose name reads like an image */
    copy_file(in_dir("a.ckpt"), in_dir("pa.ckpt"));
    unlink(in_dir("pa-link.ckpt"));
    CHECK(symlink("pa.ckpt", in_dir("pa-link.ckpt")) == 0);
    cli_run(ARGS("merge", "-o", in_dir("pb.pfm"), in_dir("a.ckpt"), in_dir("pb.pfm"), in_dir("c.ckpt")), &r);
    CHECK_EQ_INT(r.status, 2);
    snprintf(msg, sizeof msg, "clpt: error: merge: the output image '%s' is the part '%s': writing it would destroy "
             "that part; give the output image another name\n", in_dir("pb.pfm"), in_dir("pb.pfm"));
    CHECK_STR_CONTAINS(r.err, msg);
    CHECK(files_equal(in_dir("pb.pfm"), in_dir("b.ckpt")));
    cli_run(ARGS("merge", "-o", in_dir("refused.pfm"), "--checkpoint", in_dir("pa.ckpt"), in_dir("pa.ckpt"),
                 in_dir("b.ckpt"), in_dir("c.ckpt")), &r);
    CHECK_EQ_INT(r.status, 2);
    snprintf(msg, sizeof msg, "clpt: error: merge: the checkpoint '%s' is the part '%s'", in_dir("pa.ckpt"),
             in_dir("pa.ckpt"));
    CHECK_STR_CONTAINS(r.err, msg);
    /* through a symlink: the same file */
    cli_run(ARGS("merge", "-o", in_dir("refused.pfm"), "--checkpoint", in_dir("pa-link.ckpt"), in_dir("pa.ckpt"),
                 in_dir("b.ckpt"), in_dir("c.ckpt")), &r);
    CHECK_EQ_INT(r.status, 2);
    snprintf(msg, sizeof msg, "clpt: error: merge: the checkpoint '%s' is the part '%s'", in_dir("pa-link.ckpt"),
             in_dir("pa.ckpt"));
    CHECK_STR_CONTAINS(r.err, msg);
    CHECK(files_equal(in_dir("pa.ckpt"), in_dir("a.ckpt")));
    CHECK(!file_exists(in_dir("refused.pfm")));
    /* the image and the checkpoint one file */
    cli_run(ARGS("merge", "-o", in_dir("both.pfm"), "--checkpoint", in_dir("both.pfm"), in_dir("a.ckpt"),
                 in_dir("b.ckpt"), in_dir("c.ckpt")), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "are the same file; give each its own name");
    CHECK(!file_exists(in_dir("both.pfm")));
    unlink(in_dir("refused.pfm"));   /* when this failed: not to fail the tests after it */
    unlink(in_dir("both.pfm"));
}

static void test_sample_range_usage_errors(void)
{
    cli_run(ARGS(RENDER, "--sample-range", "5:13", "-o", in_dir("refused.pfm")), &r);
    CHECK_EQ_INT(r.status, 2);
    CHECK_STR_CONTAINS(r.err, "clpt: error: --sample-range 5:13 goes past the render's 12 samples per pixel\n");
    const char *bad[] = { "5:5", "7:3", "-1:3", "3", "a:b", "1:2:3", ":4" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        cli_run(ARGS(RENDER, "--sample-range", bad[i], "-o", in_dir("refused.pfm")), &r);
        CHECK_MSG(r.status == 2, "'%s' gave %d", bad[i], r.status);
        char msg[200];
        snprintf(msg, sizeof msg, "--sample-range expects A:B, sample indices with 0 <= A < B <= 1000000, got '%s'\n",
                 bad[i]);
        CHECK_STR_CONTAINS(r.err, msg);
    }
    /* a part resumed with another range would hold samples of another part */
    cli_run(ARGS(RENDER, "--sample-range", "8:12", "--resume", in_dir("c.ckpt"), "-o", in_dir("refused.pfm")), &r);
    CHECK_EQ_INT(r.status, 3);
    char msg[300];
    snprintf(msg, sizeof msg, "clpt: error: checkpoint '%s' holds samples [7,12), outside --sample-range 8:12; resume "
             "it with the range it was made with\n", in_dir("c.ckpt"));
    CHECK_STR_CONTAINS(r.err, msg);
}

/* ------------------------------------------------------------------ MPI */

/* The machine may have two cores: every rank gets one thread, and mpirun is told that
 * more ranks than cores is fine (and that root may run them, in containers). */
#define MPIRUN "mpirun", "--oversubscribe", "--allow-run-as-root", "--mca", "btl", "self,vader"

static int have_mpirun(void)
{
    return system("command -v mpirun >/dev/null 2>&1") == 0;
}

/* Starts argv[0] (found in PATH) with its output captured, as cli_start does. */
static CliChild spawn(const char *const *args)
{
    CliChild c;
    char out_name[] = "/tmp/clpt-mpi-out-XXXXXX", err_name[] = "/tmp/clpt-mpi-err-XXXXXX";
    c.out_fd = mkstemp(out_name);
    c.err_fd = mkstemp(err_name);
    unlink(out_name);
    unlink(err_name);
    c.pid = fork();
    if (c.pid == 0) {
        dup2(c.out_fd, 1);
        dup2(c.err_fd, 2);
        setpgid(0, 0);   /* the test's own kill reaches mpirun's ranks only */
        /* Under `make test-asan`: Open MPI unloads its components in MPI_Finalize, so
         * LeakSanitizer cannot tell their leftovers from clpt's (every frame is an
         * "<unknown module>"): leak checks are off for the MPI runs, the address and
         * undefined-behaviour checks stay on. Without ASan the variable is unread. */
        const char *asan = getenv("ASAN_OPTIONS");
        char opts[1024];
        snprintf(opts, sizeof opts, "%s%sdetect_leaks=0", asan ? asan : "", asan && *asan ? ":" : "");
        setenv("ASAN_OPTIONS", opts, 1);
        execvp(args[0], (char *const *)args);
        _exit(127);
    }
    return c;
}

static void spawn_run(const char *const *args, CliResult *res)
{
    cli_finish(spawn(args), res);
}

static void sleep_s(double s)
{
    struct timespec ts = { (time_t)s, (long)((s - (double)(time_t)s) * 1e9) };
    nanosleep(&ts, NULL);
}

static void test_mpi_two_and_three_ranks_are_bit_identical(void)
{
    spawn_run(ARGS(MPIRUN, "-np", "2", CLI_PROGRAM, RENDER, "-o", in_dir("np2.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("np2.pfm"), in_dir("whole.pfm")));
    /* three ranks, the scene read by rank 0 alone and sent to the others */
    spawn_run(ARGS(MPIRUN, "-np", "3", CLI_PROGRAM, RENDER, "--mpi-broadcast", "-o", in_dir("np3.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("np3.pfm"), in_dir("whole.pfm")));
    /* --split auto: rank 0's pilot runs on every rank's devices and chooses as one
     * process does (one-weekend at 400x225 is large enough for a pilot; it chooses 2) */
#define PILOT_RENDER "scenes/one-weekend.scene", "--spp", "2", "--device", "scalar", "--threads", "1", "--stats", "-q"
    cli_run(ARGS(PILOT_RENDER, "-o", in_dir("pilot1.pfm")), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK_STR_CONTAINS(r.out, "split: 2, chosen by a pilot");
    spawn_run(ARGS(MPIRUN, "-np", "2", CLI_PROGRAM, PILOT_RENDER, "-o", in_dir("pilot2.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.out, "split: 2, chosen by a pilot");
    CHECK(files_equal(in_dir("pilot1.pfm"), in_dir("pilot2.pfm")));
#undef PILOT_RENDER
    /* every buffer travels, those whose counts are not in the params block too (the
     * environment map's distribution, the BVH's leaves) */
    if (shared_model_present("../shared/envmaps/courtyard.hdr", "the broadcast of an environment map is not checked")) {
#define ENV_RENDER "scenes/envmap.scene", "--width", "24", "--height", "14", "--spp", "4", "--device", "scalar", \
                   "--threads", "1", "-q"
        cli_run(ARGS(ENV_RENDER, "-o", in_dir("env1.pfm")), &r);
        CHECK_EQ_INT(r.status, 0);
        spawn_run(ARGS(MPIRUN, "-np", "2", CLI_PROGRAM, ENV_RENDER, "--mpi-broadcast", "-o", in_dir("env2.pfm")), &r);
        CHECK_MSG(r.status == 0, "%s", r.err);
        CHECK(files_equal(in_dir("env1.pfm"), in_dir("env2.pfm")));
#undef ENV_RENDER
    }
    /* and every count that is not in the params block: a density grid, moving
     * instances and the camera's keys, lights inside instances (each was missing from
     * the broadcast once, and rank 1 refused the scene) */
    const char *counted[] = { "scenes/smoke.scene", "scenes/motion-blur.scene", "scenes/instanced-lamps.scene" };
    for (size_t i = 0; i < sizeof counted / sizeof counted[0]; i++) {
#define COUNTED_RENDER(scene) scene, "--width", "24", "--height", "14", "--spp", "4", "--device", "scalar", \
                              "--threads", "1", "-q"
        cli_run(ARGS(COUNTED_RENDER(counted[i]), "-o", in_dir("counted1.pfm")), &r);
        CHECK_MSG(r.status == 0, "%s: %s", counted[i], r.err);
        spawn_run(ARGS(MPIRUN, "-np", "2", CLI_PROGRAM, COUNTED_RENDER(counted[i]), "--mpi-broadcast", "-o",
                       in_dir("counted2.pfm")), &r);
        CHECK_MSG(r.status == 0, "%s: %s", counted[i], r.err);
        CHECK_MSG(files_equal(in_dir("counted1.pfm"), in_dir("counted2.pfm")), "%s", counted[i]);
#undef COUNTED_RENDER
    }
    /* a --sample-range part rendered by two ranks merges like any other */
    spawn_run(ARGS(MPIRUN, "-np", "2", CLI_PROGRAM, RENDER, "--sample-range", "5:7", "--checkpoint", in_dir("mb.ckpt"),
                   "-o", in_dir("mb.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    cli_run(ARGS("merge", "-q", "-o", in_dir("mmerged.pfm"), in_dir("a.ckpt"), in_dir("mb.ckpt"), in_dir("c.ckpt")), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK(files_equal(in_dir("mmerged.pfm"), in_dir("whole.pfm")));
}

/* A crop (--pixel-bounds) rendered by two ranks is the one-process crop's bytes: every
 * rank renders the same window of the same image, the scene read by each or sent. */
static void test_mpi_crop(void)
{
#define CROP "--pixel-bounds", "3,20,4,15"
    cli_run(ARGS(RENDER, CROP, "-o", in_dir("crop1.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    spawn_run(ARGS(MPIRUN, "-np", "2", CLI_PROGRAM, RENDER, CROP, "-o", in_dir("crop2.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("crop1.pfm"), in_dir("crop2.pfm")));
    spawn_run(ARGS(MPIRUN, "-np", "2", CLI_PROGRAM, RENDER, CROP, "--mpi-broadcast", "-o", in_dir("crop3.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("crop1.pfm"), in_dir("crop3.pfm")));
#undef CROP
}

/* Ranks on different devices: rank 0 on the scalar device, rank 1 on PoCL's CPU device
 * (MPMD, the way docs/distributed.md gives ranks different devices). The film is the
 * same integers whichever device rendered a batch, so the image is still the bytes of
 * the one-process render. */
#define RENDER_ON(device) "scenes/cornell-box.scene", "--width", "24", "--height", "18", "--spp", "12", \
                          "--device", device, "--threads", "1", "-q", "--batch", "2"

static void test_mpi_ranks_on_a_mix_of_devices(void)
{
    spawn_run(ARGS(MPIRUN, "-np", "1", CLI_PROGRAM, RENDER_ON("scalar"), "--stats", "-o", in_dir("mix.pfm"), ":",
                   "-np", "1", CLI_PROGRAM, RENDER_ON(TEST_OPENCL), "--stats", "-o", in_dir("mix.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("mix.pfm"), in_dir("whole.pfm")));
}

/* --noise-threshold under MPI: rank 0 decides each round's pixels from the merged film
 * and sends every rank the round's params and pixel list (TAG_PARAMS), so two and three
 * ranks, on the scalar device or a mix with PoCL, give the one-process adaptive image;
 * a checkpoint of a job resumes in one process to the same bytes. */
#define ADAPTIVE_ON(device) "scenes/cornell-box.scene", "--width", "24", "--height", "18", "--spp", "96", \
                            "--noise-threshold", "0.05", "--device", device, "--threads", "1", "-q", "--batch", "2"

static void test_mpi_adaptive_is_bit_identical(void)
{
    cli_run(ARGS(ADAPTIVE_ON("scalar"), "--stats", "-o", in_dir("ad1.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK_STR_CONTAINS(r.out, "each pixel its own count (--noise-threshold)");
    spawn_run(ARGS(MPIRUN, "-np", "2", CLI_PROGRAM, ADAPTIVE_ON("scalar"), "-o", in_dir("ad2.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("ad1.pfm"), in_dir("ad2.pfm")));
    spawn_run(ARGS(MPIRUN, "-np", "3", CLI_PROGRAM, ADAPTIVE_ON("scalar"), "--mpi-broadcast", "--checkpoint",
                   in_dir("ad3.ckpt"), "-o", in_dir("ad3.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("ad1.pfm"), in_dir("ad3.pfm")));
    spawn_run(ARGS(MPIRUN, "-np", "1", CLI_PROGRAM, ADAPTIVE_ON("scalar"), "-o", in_dir("ad4.pfm"), ":", "-np", "1",
                   CLI_PROGRAM, ADAPTIVE_ON(TEST_OPENCL), "-o", in_dir("ad4.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("ad1.pfm"), in_dir("ad4.pfm")));
    /* the job's checkpoint is a finished adaptive render: resumed, the same image */
    cli_run(ARGS(ADAPTIVE_ON("scalar"), "--resume", in_dir("ad3.ckpt"), "-o", in_dir("ad5.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("ad1.pfm"), in_dir("ad5.pfm")));
}
#undef ADAPTIVE_ON

static void test_mpi_ranks_with_other_settings_are_refused(void)
{
    /* MPMD: rank 1 runs with another seed, so another render key */
    spawn_run(ARGS(MPIRUN, "-np", "1", CLI_PROGRAM, RENDER, "-o", in_dir("refused.pfm"), ":", "-np", "1", CLI_PROGRAM,
                   RENDER, "--seed", "9", "-o", in_dir("refused.pfm")), &r);
    CHECK(r.status != 0);
    CHECK_STR_CONTAINS(r.err, "clpt: error: MPI rank 1 (");
    CHECK_STR_CONTAINS(r.err, ") read another scene or settings than rank 0 (its render key differs): give every rank "
                              "the same files, or use --mpi-broadcast\n");
    CHECK_STR_CONTAINS(r.err, "Exit code:    3");
    CHECK(!file_exists(in_dir("refused.pfm")));
}

/* Every start-up failure on one rank ends the whole job with rank 0's message, in
 * bounded time: these hung for ever when one rank of an MPMD job stopped before the
 * render (its own usage error, --help, --aov) or never joined MPI at all. `timeout`
 * turns a hang into a failed check instead of a stuck suite. */
#define BOUNDED "timeout", "60"

static void expect_start_refused(const char *const *args, int status, const char *message)
{
    spawn_run(args, &r);
    CHECK_MSG(r.status == status, "status %d, stderr: %s", r.status, r.err);
    CHECK_STR_CONTAINS(r.err, message);
    CHECK(!file_exists(in_dir("refused.pfm")));
}

static void test_mpi_a_rank_that_cannot_start_ends_the_job(void)
{
    expect_start_refused(ARGS(BOUNDED, MPIRUN, "-np", "1", CLI_PROGRAM, RENDER, "-o", in_dir("refused.pfm"), ":",
                              "-np", "1", CLI_PROGRAM, RENDER, "--bogus", "-o", in_dir("refused.pfm")), 2,
                         "clpt: error: MPI rank 1 could not start: unknown option '--bogus'\n");
    expect_start_refused(ARGS(BOUNDED, MPIRUN, "-np", "1", CLI_PROGRAM, RENDER, "-o", in_dir("refused.pfm"), ":",
                              "-np", "1", CLI_PROGRAM, RENDER, "--aov", "normal", "-o", in_dir("refused.pfm")), 2,
                         "clpt: error: MPI rank 1 could not start: --adaptive and --aov are not available under MPI "
                         "(run them in one process)\n");
    /* the failing rank may be rank 0 too; every rank of the three then stops */
    expect_start_refused(ARGS(BOUNDED, MPIRUN, "-np", "1", CLI_PROGRAM, RENDER, "--spp", "x", "-o",
                              in_dir("refused.pfm"), ":", "-np", "2", CLI_PROGRAM, RENDER, "-o", in_dir("refused.pfm")),
                         2, "clpt: error: --spp expects");
}

static void test_mpi_ranks_given_different_commands_are_refused(void)
{
    expect_start_refused(ARGS(BOUNDED, MPIRUN, "-np", "1", CLI_PROGRAM, RENDER, "-o", in_dir("refused.pfm"), ":",
                              "-np", "1", CLI_PROGRAM, "--help"), 2,
                         "clpt: error: MPI ranks 0 and 1 were given different commands (rank 0: a render without "
                         "--mpi-broadcast; rank 1: --help): every rank of a job must run the same command, only the "
                         "device flags may differ\n");
    expect_start_refused(ARGS(BOUNDED, MPIRUN, "-np", "1", CLI_PROGRAM, "--version", ":", "-np", "1", CLI_PROGRAM,
                              RENDER, "-o", in_dir("refused.pfm")), 2,
                         "clpt: error: MPI ranks 0 and 1 were given different commands (rank 0: --version; rank 1: a "
                         "render without --mpi-broadcast)");
    /* a rank without --mpi-broadcast would wait for a scene that is never sent */
    expect_start_refused(ARGS(BOUNDED, MPIRUN, "-np", "2", CLI_PROGRAM, RENDER, "--mpi-broadcast", "-o",
                              in_dir("refused.pfm"), ":", "-np", "1", CLI_PROGRAM, RENDER, "-o", in_dir("refused.pfm")),
                         2, "clpt: error: MPI ranks 0 and 2 were given different commands (rank 0: a render with "
                            "--mpi-broadcast; rank 2: a render without --mpi-broadcast)");
    /* the same command on every rank is fine: rank 0 alone prints */
    spawn_run(ARGS(BOUNDED, MPIRUN, "-np", "2", CLI_PROGRAM, "--version"), &r);
    CHECK_EQ_INT(r.status, 0);
    CHECK(strncmp(r.out, "clpt ", 5) == 0 && strchr(r.out, '\n') == r.out + strlen(r.out) - 1);
}

/* A process of the job that never joins MPI held the others in MPI_Init for ever: they
 * now give up after --mpi-timeout. `sleep 30` never joins and outlives the timeout, so
 * only clpt's watchdog can end the job, with its message and status 5. */
static void test_mpi_a_process_that_never_joins_ends_the_job(void)
{
    expect_start_refused(ARGS(BOUNDED, MPIRUN, "-np", "1", CLI_PROGRAM, RENDER, "--mpi-timeout", "2", "-o",
                              in_dir("refused.pfm"), ":", "-np", "1", "sleep", "30"), 5,
                         "clpt: MPI rank 0: error: the MPI job did not start within 2 s: a process of the job never "
                         "joined it (in an MPMD job, one that is not a clpt render, or that ended first), or the "
                         "launcher hangs; see --mpi-timeout\n");
}

/* A process that ends at once without joining (`true`, status 0) races clpt's start: if
 * it is gone before rank 0 registers with Open MPI, rank 0 waits in MPI_Init and its
 * watchdog ends the job (status 5, the message above); if it ends after, mpirun itself
 * ends the job as "exiting improperly" (status 1; CI once saw that status with nothing
 * on stderr). 20 ms either way decides, so a loaded machine sees both; each ends the job
 * in bounded time without an image. */
static void test_mpi_a_process_that_ends_without_joining_ends_the_job(void)
{
    spawn_run(ARGS(BOUNDED, MPIRUN, "-np", "1", CLI_PROGRAM, RENDER, "--mpi-timeout", "2", "-o", in_dir("refused.pfm"),
                   ":", "-np", "1", "true"), &r);
    CHECK_MSG(r.status == 5 || r.status == 1, "status %d, stderr: %s", r.status, r.err);
    if (r.status == 5) CHECK_STR_CONTAINS(r.err, "clpt: MPI rank 0: error: the MPI job did not start within 2 s");
    CHECK(!file_exists(in_dir("refused.pfm")));
}

/* A longer render, so that a rank can be killed in it: 1440 spp of 24 x 18 pixels is 0.6
 * million samples, several seconds for three ranks on two cores (at 360 spp a loaded
 * machine sometimes saw the whole render done before the kill landed). */
#define LONG_SPP 1440
#define LONG_RENDER "scenes/cornell-box.scene", "--width", "24", "--height", "18", "--spp", "1440", "--device", \
                    "scalar", "--threads", "1", "-q", "--batch", "3"

/* The pid of the process of rank `rank` among mpirun's children (its environment says
 * OMPI_COMM_WORLD_RANK); 0 if none. */
static pid_t rank_pid(pid_t mpirun, int rank)
{
    DIR *d = opendir("/proc");
    pid_t found = 0;
    struct dirent *e;
    char want[64];
    snprintf(want, sizeof want, "OMPI_COMM_WORLD_RANK=%d", rank);
    while (d && !found && (e = readdir(d))) {
        pid_t pid = (pid_t)atoi(e->d_name);
        char path[64], buf[1 << 16];
        if (pid <= 0) continue;
        snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
        FILE *f = fopen(path, "r");
        int ppid = 0;
        if (!f) continue;
        if (fscanf(f, "%*d %*s %*c %d", &ppid) != 1) ppid = 0;
        fclose(f);
        if (ppid != mpirun) continue;
        snprintf(path, sizeof path, "/proc/%d/environ", (int)pid);
        f = fopen(path, "r");
        if (!f) continue;
        size_t n = fread(buf, 1, sizeof buf - 1, f);
        fclose(f);
        for (size_t i = 0; i < n; i += strlen(buf + i) + 1) {
            buf[n] = '\0';
            if (strcmp(buf + i, want) == 0) found = pid;
        }
    }
    if (d) closedir(d);
    return found;
}

/* Starts a 3-rank render with checkpoints, and kills rank 2 once a checkpoint is
 * written (the render is then under way). */
static CliChild start_and_kill_rank(const char *const *args)
{
    CliChild c = spawn(args);
    pid_t victim = 0;
    for (int i = 0; i < 400 && !(file_exists(in_dir("killed.ckpt")) && victim); i++) {
        sleep_s(0.025);
        if (!victim) victim = rank_pid(c.pid, 2);
    }
    CHECK(victim > 0);
    CHECK(file_exists(in_dir("killed.ckpt")));
    if (victim > 0) kill(victim, SIGKILL);
    return c;
}

static void test_mpi_killed_rank_then_resume(void)
{
    cli_run(ARGS(LONG_RENDER, "-o", in_dir("long.pfm")), &r);
    CHECK_EQ_INT(r.status, 0);
    /* mpirun's default: the job ends when a rank dies; rank 0 writes what is finished */
    cli_finish(start_and_kill_rank(ARGS(MPIRUN, "-np", "3", CLI_PROGRAM, LONG_RENDER, "--checkpoint",
                                        in_dir("killed.ckpt"), "--checkpoint-interval", "0.1", "-o",
                                        in_dir("killed.pfm"))), &r);
    CHECK(r.status != 0);
    CHECK_STR_CONTAINS(r.err, "clpt: stopping on SIGINT/SIGTERM (from you, or from mpirun because another MPI rank "
                              "died; mpirun names it): writing what is finished\n");
    CHECK_STR_CONTAINS(r.err, "process rank 2 with PID");
    CHECK_STR_CONTAINS(r.err, "exited on signal 9 (Killed)");
    Checkpoint ck;
    Error err = { 0 };
    CHECK(checkpoint_read(in_dir("killed.ckpt"), &ck, &err) == ST_OK);
    CHECK_MSG(ck.film.samples > 0 && ck.film.samples < LONG_SPP, "%llu samples per pixel",
              (unsigned long long)ck.film.samples);
    checkpoint_free(&ck);
    error_clear(&err);
    /* resumed with two ranks: the same bits as the render never interrupted */
    spawn_run(ARGS(MPIRUN, "-np", "2", CLI_PROGRAM, LONG_RENDER, "--resume", in_dir("killed.ckpt"), "-o",
                   in_dir("resumed.pfm")), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    CHECK(files_equal(in_dir("resumed.pfm"), in_dir("long.pfm")));
}

/* --mpi-timeout 4: the live ranks send ALIVE every second, and on a loaded machine a
 * live rank can go unscheduled for more than a second; 4 s keeps that from dropping it. */
static void test_mpi_recovery_goes_on_without_the_dead_rank(void)
{
    unlink(in_dir("killed.ckpt"));
    cli_finish(start_and_kill_rank(ARGS(MPIRUN, "--enable-recovery", "-np", "3", CLI_PROGRAM, LONG_RENDER,
                                        "--mpi-timeout", "4", "--checkpoint", in_dir("killed.ckpt"),
                                        "--checkpoint-interval", "0.1", "-o", in_dir("recovered.pfm"))), &r);
    CHECK_MSG(r.status == 0, "%s", r.err);
    /* The kill lands between messages or in the middle of one (a film on its way), or
     * MPI itself reports the dead peer: rank 0 names rank 2 and drops it in every case,
     * with the wording of what it saw (host/dist/mpi_driver.c), and finishes the image.
     * The usual case, its exact message: */
    static const char dropped[] = "failed and was dropped; its samples go to the other devices: MPI rank 2 ";
    static const char between[] = "stopped answering: no word from it for 4 s (its process or node died, or it "
                                  "hangs; see --mpi-timeout)\n";
    char want[512];
    snprintf(want, sizeof want, "%s%s", dropped, between);
    const char *drop = strstr(r.err, dropped);
    CHECK_MSG(drop != NULL, "no drop message in: %s", r.err);
    if (drop && !strstr(r.err, want)) fprintf(stderr, "  rank 2 dropped with another message: %s\n", drop);
    CHECK(files_equal(in_dir("recovered.pfm"), in_dir("long.pfm")));
}

int main(void)
{
    make_dir();
    RUN(render_whole);
    RUN(test_three_parts_merge_to_the_whole);
    RUN(test_merge_refuses_to_overwrite_a_part);
    RUN(test_another_split_merges_to_the_same_bits);
    RUN(test_merge_refusals);
    RUN(test_a_grown_render_merges);
    RUN(test_sample_range_usage_errors);
    if (have_mpirun()) {
        RUN(test_mpi_two_and_three_ranks_are_bit_identical);
        RUN(test_mpi_crop);
        RUN(test_mpi_adaptive_is_bit_identical);
        RUN(test_mpi_ranks_with_other_settings_are_refused);
        RUN(test_mpi_a_rank_that_cannot_start_ends_the_job);
        RUN(test_mpi_ranks_given_different_commands_are_refused);
        RUN(test_mpi_a_process_that_never_joins_ends_the_job);
        RUN(test_mpi_a_process_that_ends_without_joining_ends_the_job);
        RUN(test_mpi_ranks_on_a_mix_of_devices);
        RUN(test_mpi_killed_rank_then_resume);
        RUN(test_mpi_recovery_goes_on_without_the_dead_rank);
    } else {
        fprintf(stderr, "mpirun not found: the MPI tests were not run\n");
    }
    remove_dir();
    return harness_report();
}
