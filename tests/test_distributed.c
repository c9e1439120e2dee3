/*
 * test_distributed.c — one image from several processes (docs/distributed.md):
 * --sample-range parts merged with `clpt merge` are the same PFM bytes as the render of
 * one process, whatever the split; merges of overlapping, incomplete or foreign parts are
 * refused with exact messages and exit status 3.
 */
#include <dirent.h>

#include "cli_util.h"
#include "harness.h"

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
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char p[512];
        while ((e = readdir(d)))
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
                snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
                unlink(p);
            }
        closedir(d);
    }
    rmdir(dir);
}

static int files_equal(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb;
    while (same) {
        int ca = fgetc(fa), cb = fgetc(fb);
        if (ca != cb) same = 0;
        if (ca == EOF || cb == EOF) break;
    }
    if (fa) fclose(fa);
    if (fb) fclose(fb);
    return same;
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

int main(void)
{
    make_dir();
    RUN(render_whole);
    RUN(test_three_parts_merge_to_the_whole);
    RUN(test_another_split_merges_to_the_same_bits);
    RUN(test_merge_refusals);
    RUN(test_sample_range_usage_errors);
    remove_dir();
    return harness_report();
}
