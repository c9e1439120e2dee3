/*
 * progress.c — the stderr progress line: pure formatting helpers plus a thin drawing layer
 * that owns the clock and the terminal.
 */
#include "base/progress.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

/* At most this often, so a fast render loop does not spend its time writing to the terminal
 * (and a slow terminal or ssh link does not flicker). */
#define REDRAW_INTERVAL_S 0.1
#define DEFAULT_COLUMNS 80
/* Narrower than this, the bar says too little to be worth its space and is left out;
 * wider, it stops growing (a bar across a 300-column terminal only makes the eye travel). */
#define MIN_BAR 8
#define MAX_BAR 100

/* ------------------------------------------------------------------ pure formatting */

void progress_format_duration(double seconds, char *buf, size_t size)
{
    if (!isfinite(seconds) || seconds < 0.0) {
        snprintf(buf, size, "--:--");
        return;
    }
    if (seconds >= 1000.0 * 3600.0 - 0.5) {
        snprintf(buf, size, ">999h");
        return;
    }
    long long t = (long long)floor(seconds + 0.5);
    long long h = t / 3600, m = t / 60 % 60, s = t % 60;
    if (h > 0) snprintf(buf, size, "%lld:%02lld:%02lld", h, m, s);
    else snprintf(buf, size, "%02lld:%02lld", m, s);
}

/* Scales v into [0, 999.5) with an SI prefix; 999.5 and up would print as "1000". */
static const char *si_scale(double v, double *scaled)
{
    static const char *const prefix[] = {"", "k", "M", "G", "T", "P", "E"};
    int i = 0;
    while (i < 6 && v >= 999.5) {
        v /= 1000.0;
        i++;
    }
    *scaled = v;
    return prefix[i];
}

/* Three significant digits; the thresholds are where rounding would add a fourth. */
static void format_sig3(double v, const char *prefix, char *buf, size_t size)
{
    if (v < 9.995) snprintf(buf, size, "%.2f%s", v, prefix);
    else if (v < 99.95) snprintf(buf, size, "%.1f%s", v, prefix);
    else snprintf(buf, size, "%.0f%s", v, prefix);
}

void progress_format_count(double count, char *buf, size_t size)
{
    if (!isfinite(count) || count < 0.0) {
        snprintf(buf, size, "--");
        return;
    }
    double v;
    const char *prefix = si_scale(count, &v);
    /* Counts below a thousand are whole units: "950", not "950." or "9.00". */
    if (!prefix[0]) snprintf(buf, size, "%.0f", v);
    else format_sig3(v, prefix, buf, size);
}

void progress_format_rate(double per_sec, const char *unit, char *buf, size_t size)
{
    if (!isfinite(per_sec) || per_sec < 0.0) {
        snprintf(buf, size, "-- %s/s", unit);
        return;
    }
    double v;
    const char *prefix = si_scale(per_sec, &v);
    char num[32];
    if (v == 0.0) snprintf(num, sizeof num, "0");
    else format_sig3(v, "", num, sizeof num);
    snprintf(buf, size, "%s %s%s/s", num, prefix, unit);
}

/* label [bar] stats, or label  stats; 0 when that does not fit in avail characters. */
static int compose_line(const Progress *p, const char *stats, double frac, int with_bar,
                        size_t avail, char *line, size_t size)
{
    size_t label_len = strlen(p->label);
    const char *sep = label_len ? " " : "";
    if (!with_bar) {
        if (label_len + 2 * strlen(sep) + strlen(stats) > avail) return 0;
        int n = snprintf(line, size, "%s%s%s%s", p->label, sep, sep, stats);
        return n >= 0 && (size_t)n < size;
    }
    size_t fixed = label_len + strlen(sep) + 3 + strlen(stats);
    if (avail < fixed + MIN_BAR) return 0;
    size_t bar = avail - fixed < MAX_BAR ? avail - fixed : MAX_BAR;
    size_t full = (size_t)floor(frac * (double)bar);
    char cells[MAX_BAR + 1];
    for (size_t i = 0; i < bar; i++) cells[i] = i < full ? '=' : ' ';
    if (full < bar && full > 0) cells[full - 1] = '>'; /* the tip, while unfinished */
    cells[bar] = '\0';
    int n = snprintf(line, size, "%s%s[%s] %s", p->label, sep, cells, stats);
    return n >= 0 && (size_t)n < size;
}

void progress_format_line(const Progress *p, double elapsed, int columns, int final, char *buf,
                          size_t size)
{
    if (size == 0) return;
    buf[0] = '\0';
    size_t avail = columns > 1 ? (size_t)columns - 1 : 0;
    if (avail >= size) avail = size - 1;

    int known_total = p->total > 0.0;
    double frac = known_total ? p->done / p->total : 0.0;
    if (!(frac > 0.0)) frac = 0.0;
    if (frac > 1.0) frac = 1.0;
    int pct = (int)floor(frac * 100.0); /* floor: 100% only when truly done */
    double rate = elapsed > 0.0 ? p->done / elapsed : -1.0;

    char done[32], total[32], rate_s[64], el[16], eta[16];
    progress_format_count(p->done, done, sizeof done);
    progress_format_count(p->total, total, sizeof total);
    progress_format_rate(rate, p->unit, rate_s, sizeof rate_s);
    progress_format_duration(elapsed, el, sizeof el);
    progress_format_duration(known_total && rate > 0.0 ? (p->total - p->done) / rate : -1.0, eta,
                             sizeof eta);

    /* The full form, and a short one (percentage and times) for narrow terminals. Counts
     * and rates are padded to their widest form ("999k", "1.23 M<unit>/s") so the bar
     * keeps its length from one redraw to the next. */
    int rate_w = (int)strlen(p->unit) + 8;
    char when[48], full[192], brief[96];
    if (final) snprintf(when, sizeof when, "in %s", el);
    else snprintf(when, sizeof when, "%s ETA %s", el, eta);
    if (known_total) {
        snprintf(full, sizeof full, "%3d%%  %5s/%s  %*s  %s", pct, done, total, rate_w, rate_s,
                 when);
        snprintf(brief, sizeof brief, "%3d%%  %s", pct, when);
    } else {
        snprintf(full, sizeof full, "%s %s  %*s  %s", done, p->unit, rate_w, rate_s, el);
        snprintf(brief, sizeof brief, "%s %s  %s", done, p->unit, el);
    }

    /* In order of preference; the bar goes before the numbers do. */
    char line[512];
    if (!(known_total && compose_line(p, full, frac, 1, avail, line, sizeof line)) &&
        !compose_line(p, full, frac, 0, avail, line, sizeof line) &&
        !(known_total && compose_line(p, brief, frac, 1, avail, line, sizeof line)) &&
        !compose_line(p, brief, frac, 0, avail, line, sizeof line)) {
        /* Too narrow for anything: cut, rather than let the terminal wrap. */
        snprintf(line, sizeof line, "%s%s%s", p->label, p->label[0] ? "  " : "", brief);
    }
    snprintf(buf, avail + 1, "%s", line);
}

/* ------------------------------------------------------------------ clock and terminal */

static double monotonic_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int terminal_columns(void)
{
    struct winsize ws;
    if (ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return ws.ws_col;
    return DEFAULT_COLUMNS;
}

static void progress_draw(Progress *p, double now, int final)
{
    char line[512];
    progress_format_line(p, now - p->start, terminal_columns(), final, line, sizeof line);
    /* One write per redraw: "\r", the line, erase whatever a longer earlier line left. */
    fprintf(stderr, "\r%s\033[K%s", line, final ? "\n" : "");
    fflush(stderr);
    p->last_draw = now;
    p->drawn = 1;
}

int progress_should_enable(int quiet)
{
    if (quiet || !isatty(STDERR_FILENO)) return 0;
    /* No TERM at all gives no reason to think "\r" and ESC[K are understood either. */
    const char *term = getenv("TERM");
    return term && term[0] && strcmp(term, "dumb") != 0;
}

void progress_begin(Progress *p, const char *label, double total_units, const char *unit_name,
                    int enabled)
{
    memset(p, 0, sizeof *p);
    p->enabled = enabled;
    snprintf(p->label, sizeof p->label, "%s", label ? label : "");
    snprintf(p->unit, sizeof p->unit, "%s", unit_name ? unit_name : "units");
    p->total = total_units;
    p->start = monotonic_seconds();
    if (p->enabled) progress_draw(p, p->start, 0);
}

void progress_update(Progress *p, double done_units)
{
    p->done = done_units;
    if (!p->enabled) return;
    double now = monotonic_seconds();
    if (p->drawn && now - p->last_draw < REDRAW_INTERVAL_S) return;
    progress_draw(p, now, 0);
}

void progress_end(Progress *p)
{
    if (!p->enabled) return;
    progress_draw(p, monotonic_seconds(), 1);
    /* A second end (say, on an error path after the normal one) prints nothing more. */
    p->enabled = 0;
}
