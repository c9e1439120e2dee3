/*
 * progress.h — a one-line progress bar on stderr for long renders.
 *
 *     Progress p;
 *     progress_begin(&p, "render", total_samples, "samples", progress_should_enable(quiet));
 *     for (...) progress_update(&p, samples_done);
 *     progress_end(&p);
 *
 * The line shows the label, a bar, the percentage, done/total, the average rate, the
 * elapsed time and the ETA, fitted to the terminal's width. It is redrawn in place ("\r"
 * and erase-to-end-of-line) at most 10 times a second, however often update is called.
 * A disabled Progress prints nothing at all. Not thread-safe: one thread drives it.
 */
#ifndef CLPT_PROGRESS_H
#define CLPT_PROGRESS_H

#include <stddef.h>

typedef struct {
    int enabled;
    char label[40];
    char unit[24];
    double total;     /* units of work; <= 0 when unknown (no bar, no ETA) */
    double done;
    double start;     /* monotonic seconds */
    double last_draw; /* monotonic seconds of the last redraw */
    int drawn;        /* a line has been drawn since begin */
} Progress;

/* Starts the clock and, when enabled, draws the line at 0%. label and unit_name are
 * copied (and truncated if long). */
void progress_begin(Progress *p, const char *label, double total_units, const char *unit_name,
                    int enabled);
/* Records done_units; redraws if the last redraw was at least 0.1 s ago. */
void progress_update(Progress *p, double done_units);
/* Draws the final line — elapsed time and average rate instead of an ETA — and ends it
 * with a newline, so later messages start on a fresh line. */
void progress_end(Progress *p);

/* Whether a progress bar belongs on stderr: it is a terminal that understands the cursor
 * controls (TERM set and not "dumb") and the user did not ask for quiet. */
int progress_should_enable(int quiet);

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
