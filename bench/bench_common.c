/* SPDX-License-Identifier: Apache-2.0 */
#include "bench_common.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

double bench_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

double bench_cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

int bench_progress_enabled(void)
{
    return isatty(STDERR_FILENO);
}

typedef struct triad_part {
    double *a, *b, *c;
    size_t begin, end;
    int init;
    pthread_barrier_t *barrier;
    int reps;
    double best; /* written by part 0 only */
} triad_part;

static void *triad_main(void *arg)
{
    triad_part *p = arg;
    /* first touch by the thread that will use the pages */
    for (size_t i = p->begin; i < p->end; i++) {
        p->a[i] = 0.0;
        p->b[i] = 1.0;
        p->c[i] = 2.0;
    }
    p->best = 1e30;
    for (int r = 0; r < p->reps; r++) {
        pthread_barrier_wait(p->barrier);
        double t = bench_now();
        for (size_t i = p->begin; i < p->end; i++)
            p->a[i] = p->b[i] + 3.0 * p->c[i];
        pthread_barrier_wait(p->barrier);
        t = bench_now() - t;
        if (t < p->best)
            p->best = t;
    }
    return NULL;
}

double bench_triad_bytes_per_s(unsigned threads, size_t n, int reps)
{
    if (threads < 1)
        threads = 1;
    double *a = malloc(n * sizeof(double)), *b = malloc(n * sizeof(double)),
           *c = malloc(n * sizeof(double));
    triad_part *parts = calloc(threads, sizeof *parts);
    pthread_t *tid = calloc(threads, sizeof *tid);
    pthread_barrier_t barrier;
    double result = -1.0;
    if (!a || !b || !c || !parts || !tid || pthread_barrier_init(&barrier, NULL, threads) != 0)
        goto done;
    for (unsigned t = 0; t < threads; t++) {
        parts[t] = (triad_part){a, b, c, n * t / threads, n * (t + 1) / threads, 1, &barrier,
                                reps, 0.0};
        if (t > 0 && pthread_create(&tid[t], NULL, triad_main, &parts[t]) != 0) {
            /* the started threads wait at the barrier: nothing to unwind */
            fprintf(stderr, "triad: could not start thread %u\n", t);
            exit(1);
        }
    }
    triad_main(&parts[0]);
    /* every pass ends at a barrier, so part 0's time covers all parts */
    result = 3.0 * sizeof(double) * (double)n / parts[0].best;
    for (unsigned t = 1; t < threads; t++)
        pthread_join(tid[t], NULL);
    pthread_barrier_destroy(&barrier);
done:
    free(a);
    free(b);
    free(c);
    free(parts);
    free(tid);
    return result;
}
