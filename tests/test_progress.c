/* test_progress.c — the formatting helpers, the fitted status line, the recent rate and
 * ETA on a fake clock, and what a disabled progress, a bar and a log actually write to
 * stderr. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "harness.h"
#include "base/progress.h"

static const char *duration(double s)
{
    static char buf[32];
    progress_format_duration(s, buf, sizeof buf);
    return buf;
}

static const char *count(double c)
{
    static char buf[32];
    progress_format_count(c, buf, sizeof buf);
    return buf;
}

static const char *rate(double r)
{
    static char buf[64];
    progress_format_rate(r, "samples", buf, sizeof buf);
    return buf;
}

#define CHECK_STR(got, want) CHECK_MSG(strcmp((got), (want)) == 0, "got \"%s\", want \"%s\"", (got), (want))

static void test_format_duration(void)
{
    CHECK_STR(duration(0.0), "00:00");
    CHECK_STR(duration(59.4), "00:59");
    CHECK_STR(duration(59.6), "01:00");
    CHECK_STR(duration(61.0), "01:01");
    CHECK_STR(duration(3599.4), "59:59");
    CHECK_STR(duration(3600.0), "1:00:00");
    CHECK_STR(duration(3661.0), "1:01:01");
    CHECK_STR(duration(36000.0 + 120.0 + 5.0), "10:02:05");
    CHECK_STR(duration(999.0 * 3600.0), "999:00:00");
    CHECK_STR(duration(4e6), ">999h");
    CHECK_STR(duration(1e300), ">999h");
    CHECK_STR(duration(-1.0), "--:--");
    CHECK_STR(duration(NAN), "--:--");
    CHECK_STR(duration(INFINITY), "--:--");
    char tiny[4];
    progress_format_duration(3661.0, tiny, sizeof tiny); /* truncated, still terminated */
    CHECK_STR(tiny, "1:0");
}

static void test_format_count_and_rate(void)
{
    CHECK_STR(count(0.0), "0");
    CHECK_STR(count(950.0), "950");
    CHECK_STR(count(999.4), "999");
    CHECK_STR(count(999.6), "1.00k");
    CHECK_STR(count(12345.0), "12.3k");
    CHECK_STR(count(99949.0), "99.9k");
    CHECK_STR(count(99950.0), "100k");
    CHECK_STR(count(4e6), "4.00M");
    CHECK_STR(count(1.2e9), "1.20G");
    CHECK_STR(count(-5.0), "--");

    CHECK_STR(rate(1.234e6), "1.23 Msamples/s");
    CHECK_STR(rate(850.0), "850 samples/s");
    CHECK_STR(rate(12.5), "12.5 samples/s");
    CHECK_STR(rate(0.5), "0.50 samples/s");
    CHECK_STR(rate(0.0), "0 samples/s");
    CHECK_STR(rate(2.5e9), "2.50 Gsamples/s");
    CHECK_STR(rate(999.7e3), "1.00 Msamples/s");
    CHECK_STR(rate(-1.0), "-- samples/s");
    CHECK_STR(rate(NAN), "-- samples/s");
    CHECK_STR(rate(INFINITY), "-- samples/s");
}

static Progress sample_progress(double done, double total)
{
    Progress p;
    memset(&p, 0, sizeof p);
    snprintf(p.label, sizeof p.label, "render");
    snprintf(p.unit, sizeof p.unit, "samples");
    p.total = total;
    p.done = done;
    return p;
}

static void test_format_line(void)
{
    char line[512];
    Progress p = sample_progress(5e5, 2e6);
    progress_format_line(&p, 10.0, 80, 0, line, sizeof line);
    CHECK(strlen(line) <= 79);
    CHECK(strncmp(line, "render [", 8) == 0);
    CHECK_STR_CONTAINS(line, " 25%");
    CHECK_STR_CONTAINS(line, "500k/2.00M");
    CHECK_STR_CONTAINS(line, "50.0 ksamples/s");
    CHECK_STR_CONTAINS(line, "00:10 ETA 00:30");
    /* the bar is a quarter full */
    const char *open = strchr(line, '['), *close = strchr(line, ']');
    CHECK(open && close && close > open);
    if (open && close && close > open) {
        int cells = (int)(close - open - 1), filled = 0;
        for (const char *c = open + 1; c < close; c++) filled += *c == '=' || *c == '>';
        CHECK(cells >= 8);
        CHECK_EQ_INT(filled, cells / 4);
    }

    /* fitted: exactly the width less one on a wide terminal, bar capped at 100 cells */
    progress_format_line(&p, 10.0, 120, 0, line, sizeof line);
    CHECK_EQ_INT(strlen(line), 119);
    progress_format_line(&p, 10.0, 400, 0, line, sizeof line);
    CHECK(strlen(line) < 399);
    CHECK_STR_CONTAINS(line, "ETA");

    /* narrowing: first the bar goes, then the counts and rate (and the bar comes back in
     * the room they leave), then the bar again, and at last the line is cut */
    progress_format_line(&p, 10.0, 66, 0, line, sizeof line);
    CHECK(strlen(line) <= 65);
    CHECK(strchr(line, '[') == NULL);
    CHECK_STR_CONTAINS(line, "500k/2.00M");
    progress_format_line(&p, 10.0, 50, 0, line, sizeof line);
    CHECK_EQ_INT(strlen(line), 49);
    CHECK(strncmp(line, "render [", 8) == 0);
    CHECK(strstr(line, "samples") == NULL);
    CHECK_STR_CONTAINS(line, "]  25%  00:10 ETA 00:30");
    progress_format_line(&p, 10.0, 32, 0, line, sizeof line);
    CHECK(strcmp(line, "render   25%  00:10 ETA 00:30") == 0);
    progress_format_line(&p, 10.0, 20, 0, line, sizeof line);
    CHECK_EQ_INT(strlen(line), 19);
    CHECK(strncmp(line, "render   25%", 12) == 0);

    /* the final form reports the time taken instead of an ETA */
    p.done = 2e6;
    progress_format_line(&p, 40.0, 80, 1, line, sizeof line);
    CHECK_STR_CONTAINS(line, "100%");
    CHECK_STR_CONTAINS(line, "in 00:40");
    CHECK(strstr(line, "ETA") == NULL);

    /* at the very start nothing is known yet about rate or ETA */
    p.done = 0.0;
    progress_format_line(&p, 0.0, 80, 0, line, sizeof line);
    CHECK_STR_CONTAINS(line, "  0%");
    CHECK_STR_CONTAINS(line, "-- samples/s");
    CHECK_STR_CONTAINS(line, "ETA --:--");

    /* unknown total: no percentage, no bar */
    Progress u = sample_progress(1234.0, 0.0);
    progress_format_line(&u, 2.0, 80, 0, line, sizeof line);
    CHECK(strchr(line, '%') == NULL);
    CHECK(strchr(line, '[') == NULL);
    CHECK_STR_CONTAINS(line, "1.23k samples");
    CHECK_STR_CONTAINS(line, "617 samples/s");

    /* more done than planned never shows more than 100% */
    Progress over = sample_progress(300.0, 200.0);
    progress_format_line(&over, 1.0, 80, 0, line, sizeof line);
    CHECK_STR_CONTAINS(line, "100%");
}

/* Runs fn with stderr sent to a temporary file; returns what it wrote (malloc'd). */
static char *capture_stderr(void (*fn)(void))
{
    char path[] = "/tmp/clpt-test-progress.XXXXXX";
    int fd = mkstemp(path);
    if (fd < 0) return NULL;
    unlink(path);
    fflush(stderr);
    int saved = dup(STDERR_FILENO);
    dup2(fd, STDERR_FILENO);
    fn();
    fflush(stderr);
    dup2(saved, STDERR_FILENO);
    close(saved);
    off_t n = lseek(fd, 0, SEEK_END);
    char *out = malloc((size_t)n + 1);
    if (out) {
        ssize_t got = pread(fd, out, (size_t)n, 0);
        out[got > 0 ? got : 0] = '\0';
    }
    close(fd);
    return out;
}

static int should_enable_result = -1;

static void drive_disabled(void)
{
    Progress p;
    progress_begin(&p, "render", 100.0, "samples", 0);
    for (int i = 0; i <= 100; i++) progress_update(&p, i);
    progress_end(&p);
    /* stderr is a regular file here, not a terminal: plain lines */
    should_enable_result = progress_should_enable(0);
}

static void sleep_ms(long ms)
{
    struct timespec ts = {0, ms * 1000000L};
    nanosleep(&ts, NULL);
}

static void drive_enabled(void)
{
    Progress p;
    progress_begin(&p, "render", 100.0, "samples", 1);
    sleep_ms(120);
    progress_update(&p, 50.0);
    /* a burst of updates inside one redraw interval draws nothing more */
    for (int i = 0; i < 10000; i++) progress_update(&p, 50.0 + i * 1e-3);
    progress_update(&p, 100.0);
    progress_end(&p);
    progress_end(&p); /* a second end adds nothing */
}

static void test_disabled_prints_nothing(void)
{
    char *out = capture_stderr(drive_disabled);
    CHECK(out != NULL);
    if (out) CHECK_EQ_INT(strlen(out), 0);
    free(out);
    CHECK_EQ_INT(should_enable_result, PROGRESS_LOG);
    CHECK_EQ_INT(progress_should_enable(1), PROGRESS_OFF);
}

static void test_enabled_draws_line(void)
{
    char *out = capture_stderr(drive_enabled);
    CHECK(out != NULL);
    if (!out) return;
    /* begin at 0%, the update at 50%, the final line: three redraws, one newline */
    int returns = 0, newlines = 0;
    for (const char *c = out; *c; c++) {
        returns += *c == '\r';
        newlines += *c == '\n';
    }
    CHECK_EQ_INT(returns, 3);
    CHECK_EQ_INT(newlines, 1);
    CHECK(out[0] == '\r');
    CHECK(strlen(out) > 0 && out[strlen(out) - 1] == '\n');
    CHECK_STR_CONTAINS(out, "  0%");
    CHECK_STR_CONTAINS(out, " 50%");
    CHECK_STR_CONTAINS(out, "ETA ");
    CHECK_STR_CONTAINS(out, "\033[K");
    const char *last = strrchr(out, '\r');
    CHECK_STR_CONTAINS(last, "100%");
    CHECK_STR_CONTAINS(last, "100/100");
    CHECK_STR_CONTAINS(last, " in 00:00");
    free(out);
}

/* A render whose first batches are slow (start-up, small batches) and then steady at
 * 1000 units/s: the average since the start stays far below that for long; the recent
 * rate, and so the ETA, find it within a few seconds. */
static void test_recent_rate_and_eta(void)
{
    Progress p;
    progress_begin_at(&p, "render", 100000.0, "samples", PROGRESS_OFF, 100.0);
    CHECK(progress_rate(&p, 0.0) < 0.0);
    CHECK(progress_eta(&p, 100.0) < 0.0);
    /* 4 s of start-up for the first 1000 units */
    progress_observe(&p, 104.0, 1000.0);
    CHECK(fabs(progress_rate(&p, 4.0) - 250.0) < 1e-9);
    /* then a batch of 1000 every second */
    double done = 1000.0, now = 104.0;
    for (int i = 0; i < 10; i++) {
        now += 1.0;
        done += 1000.0;
        progress_observe(&p, now, done);
    }
    /* the average since the start: 11000 / 14 s = 786/s, an ETA of 113 s; the truth is 89 s */
    double rate = progress_rate(&p, now - p.start), eta = progress_eta(&p, now);
    CHECK_MSG(rate > 950.0 && rate <= 1000.0, "recent rate %.1f", rate);
    CHECK_MSG(eta > 89.0 && eta < 94.0, "ETA %.1f s, want about 89", eta);
    /* between batches the ETA counts down instead of standing still */
    CHECK_MSG(fabs(progress_eta(&p, now + 0.5) - (eta - 0.5)) < 1e-9, "ETA half a second later %.2f",
              progress_eta(&p, now + 0.5));
    /* observations without progress change nothing */
    progress_observe(&p, now + 0.5, done);
    CHECK(fabs(progress_rate(&p, 0.0) - rate) < 1e-12);
    /* a slow-down shows within a few seconds, too */
    for (int i = 0; i < 10; i++) {
        now += 2.0;
        done += 1000.0;
        progress_observe(&p, now, done);
    }
    rate = progress_rate(&p, now - p.start);
    CHECK_MSG(rate > 500.0 && rate < 520.0, "recent rate after the slow-down %.1f", rate);
    /* never below zero past the end */
    CHECK(progress_eta(&p, now + 1e6) == 0.0);
}

static void test_format_log(void)
{
    Progress p;
    char line[256];
    progress_begin_at(&p, "render", 64.0 * 10000.0, "samples", PROGRESS_LOG, 0.0);
    progress_set_step(&p, 10000.0, "spp");
    progress_format_log(&p, 0.0, line, sizeof line);
    CHECK_STR(line, "clpt: render 0%, 0/64 spp, -- samples/s, 00:00 elapsed, ETA --:--");
    progress_observe(&p, 2.0, 8.0 * 10000.0);
    progress_observe(&p, 3.0, 24.0 * 10000.0);
    progress_format_log(&p, 3.0, line, sizeof line);
    CHECK_STR_CONTAINS(line, "clpt: render 37%, 24/64 spp, ");
    CHECK_STR_CONTAINS(line, "ksamples/s, 00:03 elapsed, ETA 00:");
    for (const char *c = line; *c; c++) CHECK((unsigned char)*c >= ' ');
}

static void drive_log_begin_end(void)
{
    Progress p;
    progress_begin(&p, "render", 100.0, "samples", PROGRESS_LOG);
    progress_end(&p);
}

static void drive_log(void)
{
    Progress p;
    progress_begin(&p, "render", 100.0, "samples", PROGRESS_LOG);
    for (int i = 0; i <= 100; i++) progress_update(&p, i);
    progress_end(&p);
}

/* in a log: one plain line at the first update (the next comes after
 * PROGRESS_LOG_INTERVAL_S), no carriage returns or escape codes, nothing at the end */
static void test_log_writes_plain_lines(void)
{
    char *out = capture_stderr(drive_log);
    CHECK(out != NULL);
    if (!out) return;
    CHECK_STR(out, "clpt: render 0%, 0/100 samples, -- samples/s, 00:00 elapsed, ETA --:--\n");
    free(out);
    out = capture_stderr(drive_log_begin_end);
    CHECK_STR(out ? out : "(null)", "");
    free(out);
}

int main(void)
{
    RUN(test_format_duration);
    RUN(test_format_count_and_rate);
    RUN(test_format_line);
    RUN(test_disabled_prints_nothing);
    RUN(test_enabled_draws_line);
    RUN(test_recent_rate_and_eta);
    RUN(test_format_log);
    RUN(test_log_writes_plain_lines);
    return harness_report();
}
