/*
 * progress.h — progress of a long render on stderr: a one-line bar on a terminal, plain
 * lines in a log.
 *
 *     Progress p;
 *     progress_begin(&p, "render", total_samples, "samples", progress_should_enable(quiet));
 *     for (...) progress_update(&p, samples_done);
 *     progress_end(&p);
 *
 * On a terminal (PROGRESS_TERMINAL) the line shows the label, a bar, the percentage,
 * done/total, the rate, the elapsed time and the ETA, fitted to the terminal's width. It
 * is redrawn in place ("\r" and erase-to-end-of-line) at most 10 times a second, however
 * often update is called. Where stderr is a file or a pipe (PROGRESS_LOG) a plain line,
 * with no control characters, is written at the first update and then every
 * PROGRESS_LOG_INTERVAL_S seconds, so a batch log shows a long render advancing; the
 * end adds nothing there (the caller's summary follows). PROGRESS_OFF prints nothing.
 *
 * The rate and the ETA come from the recent rate, an exponentially weighted average
 * over about the last PROGRESS_RATE_WINDOW_S seconds: the average since the start
 * includes the start-up and the small first batches and ran about 2x high early on.
 * Not thread-safe: one thread drives it.
 */
#ifndef CLPT_PROGRESS_H
#define CLPT_PROGRESS_H

#include <stddef.h>

#define PROGRESS_LOG_INTERVAL_S 5.0
#define PROGRESS_RATE_WINDOW_S 3.0

enum { PROGRESS_OFF = 0, PROGRESS_TERMINAL = 1, PROGRESS_LOG = 2 };

typedef struct {
    int enabled;      /* PROGRESS_OFF, PROGRESS_TERMINAL or PROGRESS_LOG */
    char label[40];
    char unit[24];
    double total;     /* units of work; <= 0 when unknown (no bar, no ETA) */
    double done;
    double start;     /* monotonic seconds */
    double last_draw; /* monotonic seconds of the last redraw */
    int drawn;        /* a line has been drawn since begin */
    double step;      /* units per step for log lines ("24/64 spp"); 0: in units */
    char step_name[16];
    double rate;      /* recent units per second; 0 until a change was observed */
    double changed;   /* monotonic seconds when done last changed (start before) */
    double changed_done;
} Progress;

/* Starts the clock and, on a terminal, draws the line at 0%. label and unit_name are
 * copied (and truncated if long). mode is PROGRESS_OFF, _TERMINAL or _LOG. */
void progress_begin(Progress *p, const char *label, double total_units, const char *unit_name,
                    int mode);
/* Log lines count in steps of `units_per_step` units called `name` ("spp": a step is
 * a sample of every pixel) instead of in units. */
void progress_set_step(Progress *p, double units_per_step, const char *name);
/* Records done_units; redraws if the last redraw was at least 0.1 s ago (a terminal) or
 * PROGRESS_LOG_INTERVAL_S ago (a log). */
void progress_update(Progress *p, double done_units);
/* On a terminal, draws the final line — elapsed time and average rate instead of an
 * ETA — and ends it with a newline, so later messages start on a fresh line. */
void progress_end(Progress *p);

/* How progress belongs on stderr: PROGRESS_OFF when the user asked for quiet, a bar
 * (PROGRESS_TERMINAL) on a terminal that understands the cursor controls (TERM set and
 * not "dumb"), else plain lines (PROGRESS_LOG). */
int progress_should_enable(int quiet);

/* ------------------------------------------------------------------ pure, given a clock */

/* progress_begin without the clock or drawing: the work starts at `now`. */
void progress_begin_at(Progress *p, const char *label, double total_units, const char *unit_name,
                       int mode, double now);
/* Records done_units at `now` and, when they changed, folds the rate since the last
 * change into the recent rate. */
void progress_observe(Progress *p, double now, double done_units);
/* Units per second: the recent rate once one was measured, else the average over
 * `elapsed`; -1 when nothing is known yet. */
double progress_rate(const Progress *p, double elapsed);
/* Seconds left at `now` (monotonic, as given to observe) at the recent rate, counting
 * down between changes; -1 when unknown. */
double progress_eta(const Progress *p, double now);
/* The plain log line at `now`: "clpt: render 37%, 24/64 spp, 1.90 Msamples/s, 00:12
 * elapsed, ETA 00:20" (no newline). */
void progress_format_log(const Progress *p, double now, char *buf, size_t size);

/* ------------------------------------------------------------------ pure formatting */

/* "mm:ss" below an hour, "h:mm:ss" from there, rounded to the nearest second; ">999h"
 * beyond 999 hours; "--:--" when seconds is negative or not finite. */
void progress_format_duration(double seconds, char *buf, size_t size);
/* A count with three significant digits and an SI prefix: "950", "12.3k", "4.00M", "1.20G". */
void progress_format_count(double count, char *buf, size_t size);
/* A rate: "1.23 Msamples/s", "850 samples/s"; "-- samples/s" when negative or not finite. */
void progress_format_rate(double per_sec, const char *unit, char *buf, size_t size);
/* The whole status line for p's state at `elapsed` seconds, at most columns-1 characters
 * (the last column is left free so the terminal never wraps). final selects progress_end's
 * form. Pure: no clock, no terminal. */
void progress_format_line(const Progress *p, double elapsed, int columns, int final, char *buf,
                          size_t size);

#endif /* CLPT_PROGRESS_H */
