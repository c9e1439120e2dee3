/* jobs.c — jobs run side by side on threads (see jobs.h). */
#include "base/jobs.h"

#include <pthread.h>

void jobs_run(void *(*fn)(void *), void *jobs, size_t job_size, int n)
{
    pthread_t tid[JOBS_MAX];
    int started[JOBS_MAX] = { 0 };
    char *job = jobs;
    for (int i = 1; i < n; i++) started[i] = pthread_create(&tid[i], NULL, fn, job + (size_t)i * job_size) == 0;
    fn(job);
    for (int i = 1; i < n; i++) {
        if (started[i]) pthread_join(tid[i], NULL);
        else fn(job + (size_t)i * job_size);
    }
}

int jobs_threads(int threads, size_t n, size_t min_items)
{
    if (n < min_items || threads < 1) return 1;
    return threads > JOBS_MAX ? JOBS_MAX : threads;
}
