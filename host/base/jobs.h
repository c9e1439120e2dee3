/*
 * jobs.h — a fixed set of jobs run side by side on threads: the tree builders'
 * parallel passes (host/accel). Each job is a struct the caller lays out in an array;
 * the first runs on the calling thread. A job whose thread cannot start runs on the
 * caller afterwards, so a pass never fails for want of threads.
 */
#ifndef CLPT_JOBS_H
#define CLPT_JOBS_H

#include <stddef.h>

/* The most jobs one call runs, and so the most threads a pass uses. */
#define JOBS_MAX 16

/* Runs fn on each of the n jobs (n <= JOBS_MAX), job_size bytes apart in `jobs`: job
 * 0 on this thread, the others on threads of their own. Returns when all are done. */
void jobs_run(void *(*fn)(void *), void *jobs, size_t job_size, int n);

/* How many of `threads` a pass over n items uses: 1 for fewer than `min_items` (a
 * thread's start costs more than the pass), else threads, at most JOBS_MAX. */
int jobs_threads(int threads, size_t n, size_t min_items);

#endif /* CLPT_JOBS_H */
