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

#include "base/timer.h"

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
    /* the final line reports the average; a running one the recent rate */
    double rate = final ? (elapsed > 0.0 ? p->done / elapsed : -1.0) : progress_rate(p, elapsed);

    char done[32], total[32], rate_s[64], el[16], eta[16];
    progress_format_count(p->done, done, sizeof done);
    progress_format_count(p->total, total, sizeof total);
    progress_format_rate(rate, p->unit, rate_s, sizeof rate_s);
    progress_format_duration(elapsed, el, sizeof el);
    progress_format_duration(known_total ? progress_eta(p, p->start + elapsed) : -1.0, eta, sizeof eta);

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

void progress_begin_at(Progress *p, const char *label, double total_units, const char *unit_name,
                       int mode, double now)
{
    memset(p, 0, sizeof *p);
    p->enabled = mode;
    snprintf(p->label, sizeof p->label, "%s", label ? label : "");
    snprintf(p->unit, sizeof p->unit, "%s", unit_name ? unit_name : "units");
    p->total = total_units;
    p->start = now;
    p->changed = now;
}

void progress_set_step(Progress *p, double units_per_step, const char *name)
{
    p->step = units_per_step > 0.0 ? units_per_step : 0.0;
    snprintf(p->step_name, sizeof p->step_name, "%s", name ? name : "");
}

/* Work arrives in batches, so the rate is measured from one change of `done` to the
 * next and weighted by how long that took: an interval of dt seconds counts
 * 1 - exp(-dt / window), so what happened more than a few windows ago hardly counts
 * (the first measurement, start-up included, is replaced within seconds). */
void progress_observe(Progress *p, double now, double done_units)
{
    p->done = done_units;
    double dt = now - p->changed;
    if (done_units == p->changed_done || !(dt > 0.0)) return;
    double r = (done_units - p->changed_done) / dt;
    if (p->rate > 0.0) {
        double w = 1.0 - exp(-dt / PROGRESS_RATE_WINDOW_S);
        p->rate += w * (r - p->rate);
    } else {
        p->rate = r;
    }
    p->changed = now;
    p->changed_done = done_units;
}

double progress_rate(const Progress *p, double elapsed)
{
    if (p->rate > 0.0) return p->rate;
    return elapsed > 0.0 && p->done > 0.0 ? p->done / elapsed : -1.0;
}

double progress_eta(const Progress *p, double now)
{
    if (!(p->total > 0.0)) return -1.0;
    if (p->rate > 0.0) {
        /* counts down between batches instead of standing still until the next one */
        double left = (p->total - p->changed_done) / p->rate - (now - p->changed);
        return left > 0.0 ? left : 0.0;
    }
    double rate = progress_rate(p, now - p->start);
    return rate > 0.0 ? (p->total - p->done) / rate : -1.0;
}

void progress_format_log(const Progress *p, double now, char *buf, size_t size)
{
    double elapsed = now - p->start;
    char done[32], total[32], rate_s[64], el[16], eta[16], amount[96], pct[16] = "";
    if (p->step > 0.0) {
        snprintf(amount, sizeof amount, "%.0f/%.0f %s", floor(p->done / p->step), floor(p->total / p->step),
                 p->step_name);
    } else {
        progress_format_count(p->done, done, sizeof done);
        progress_format_count(p->total, total, sizeof total);
        snprintf(amount, sizeof amount, "%s/%s %s", done, total, p->unit);
    }
    if (p->total > 0.0) {
        double frac = p->done / p->total;
        snprintf(pct, sizeof pct, " %d%%,", (int)floor((frac > 1.0 ? 1.0 : frac > 0.0 ? frac : 0.0) * 100.0));
    }
    progress_format_rate(progress_rate(p, elapsed), p->unit, rate_s, sizeof rate_s);
    progress_format_duration(elapsed, el, sizeof el);
    progress_format_duration(progress_eta(p, now), eta, sizeof eta);
    snprintf(buf, size, "clpt: %s%s %s, %s, %s elapsed, ETA %s", p->label, pct, amount, rate_s, el, eta);
}

/* ------------------------------------------------------------------ clock and terminal */

static int terminal_columns(void)
{
    struct winsize ws;
    if (ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return ws.ws_col;
    return DEFAULT_COLUMNS;
}

static void progress_draw(Progress *p, double now, int final)
{
    char line[512];
    if (p->enabled == PROGRESS_LOG) {
        progress_format_log(p, now, line, sizeof line);
        fprintf(stderr, "%s\n", line);
    } else {
        progress_format_line(p, now - p->start, terminal_columns(), final, line, sizeof line);
        /* One write per redraw: "\r", the line, erase whatever a longer earlier line left. */
        fprintf(stderr, "\r%s\033[K%s", line, final ? "\n" : "");
    }
    fflush(stderr);
    p->last_draw = now;
    p->drawn = 1;
}

int progress_should_enable(int quiet)
{
    if (quiet) return PROGRESS_OFF;
    if (!isatty(STDERR_FILENO)) return PROGRESS_LOG;
    /* No TERM at all gives no reason to think "\r" and ESC[K are understood either. */
    const char *term = getenv("TERM");
    return term && term[0] && strcmp(term, "dumb") != 0 ? PROGRESS_TERMINAL : PROGRESS_LOG;
}

void progress_begin(Progress *p, const char *label, double total_units, const char *unit_name,
                    int mode)
{
    progress_begin_at(p, label, total_units, unit_name, mode, timer_now());
    /* a log's first line waits for the first update, so that progress_set_step is in
     * effect (and a log gets no line for work that ends at once) */
    if (p->enabled == PROGRESS_TERMINAL) progress_draw(p, p->start, 0);
}

void progress_update(Progress *p, double done_units)
{
    double now = timer_now();
    progress_observe(p, now, done_units);
    if (!p->enabled) return;
    double interval = p->enabled == PROGRESS_LOG ? PROGRESS_LOG_INTERVAL_S : REDRAW_INTERVAL_S;
    if (p->drawn && now - p->last_draw < interval) return;
    progress_draw(p, now, 0);
}

void progress_end(Progress *p)
{
    /* a log's last word is the caller's summary */
    if (p->enabled == PROGRESS_TERMINAL) progress_draw(p, timer_now(), 1);
    /* A second end (say, on an error path after the normal one) prints nothing more. */
    p->enabled = PROGRESS_OFF;
}
