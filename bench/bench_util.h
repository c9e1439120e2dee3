/* bench_util.h — what the C benchmarks share: medians of repeated rounds, the process's
 * CPU clock, and the machine's load printed beside the numbers (bench/RESULTS.md quotes
 * medians measured on shared, noisy machines). Header-only: each benchmark is one file. */
#ifndef CLPT_BENCH_UTIL_H
#define CLPT_BENCH_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static inline int bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median of v[0..n) (sorts v). */
static inline double bench_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, bench_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* CPU seconds of every thread of this process. */
static inline double bench_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Prints /proc/loadavg, "load average WHEN: ...", so a result carries how busy the
 * machine was. */
static inline void bench_print_load(const char *when)
{
    FILE *f = fopen("/proc/loadavg", "r");
    char line[128] = "?\n";
    if (f) {
        if (!fgets(line, sizeof line, f)) strcpy(line, "?\n");
        fclose(f);
    }
    printf("load average %s: %s", when, line);
}

#endif /* CLPT_BENCH_UTIL_H */
