/* SPDX-License-Identifier: Apache-2.0 */
#include "rt_pool.h"

#include <pthread.h>
#include <stdint.h>

struct pose__worker {
    pose__pool *pool;
    unsigned part;
    pthread_t thread;
};

struct pose__pool {
    pthread_mutex_t lock;
    pthread_cond_t start;     /* signalled when a new task (generation) is posted */
    pthread_cond_t done;      /* signalled when the last worker finishes */
    unsigned threads;
    unsigned pending;         /* workers still running the current task */
    uint64_t generation;      /* task counter: a worker runs each generation once */
    int stop;
    pose__task_fn fn;
    void *ctx;
    struct pose__worker workers[]; /* threads - 1 */
};

size_t pose__pool_size(unsigned threads)
{
    return sizeof(pose__pool) + (threads > 1 ? threads - 1 : 0) * sizeof(struct pose__worker);
}

static void *worker_main(void *arg)
{
    struct pose__worker *w = arg;
    pose__pool *p = w->pool;
    uint64_t seen = 0;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (!p->stop && p->generation == seen)
            pthread_cond_wait(&p->start, &p->lock);
        if (p->stop)
            break;
        seen = p->generation;
        pose__task_fn fn = p->fn;
        void *ctx = p->ctx;
        pthread_mutex_unlock(&p->lock);
        fn(ctx, w->part, p->threads);
        pthread_mutex_lock(&p->lock);
        if (--p->pending == 0)
            pthread_cond_signal(&p->done);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

static void stop_workers(pose__pool *p, unsigned started)
{
    pthread_mutex_lock(&p->lock);
    p->stop = 1;
    pthread_cond_broadcast(&p->start);
    pthread_mutex_unlock(&p->lock);
    for (unsigned i = 0; i < started; i++)
        pthread_join(p->workers[i].thread, NULL);
    pthread_cond_destroy(&p->done);
    pthread_cond_destroy(&p->start);
    pthread_mutex_destroy(&p->lock);
}

int pose__pool_init(pose__pool *p, unsigned threads)
{
    if (threads < 1)
        threads = 1;
    p->threads = threads;
    p->pending = 0;
    p->generation = 0;
    p->stop = 0;
    p->fn = NULL;
    p->ctx = NULL;
    if (pthread_mutex_init(&p->lock, NULL) != 0)
        return -1;
    if (pthread_cond_init(&p->start, NULL) != 0) {
        pthread_mutex_destroy(&p->lock);
        return -1;
    }
    if (pthread_cond_init(&p->done, NULL) != 0) {
        pthread_cond_destroy(&p->start);
        pthread_mutex_destroy(&p->lock);
        return -1;
    }
    for (unsigned i = 0; i + 1 < threads; i++) {
        p->workers[i].pool = p;
        p->workers[i].part = i + 1;
        if (pthread_create(&p->workers[i].thread, NULL, worker_main, &p->workers[i]) != 0) {
            stop_workers(p, i);
            return -1;
        }
    }
    return 0;
}

void pose__pool_destroy(pose__pool *p)
{
    if (p)
        stop_workers(p, p->threads - 1);
}

unsigned pose__pool_threads(const pose__pool *p)
{
    return p->threads;
}

void pose__pool_run(pose__pool *p, pose__task_fn fn, void *ctx)
{
    if (p->threads == 1) {
        fn(ctx, 0, 1);
        return;
    }
    pthread_mutex_lock(&p->lock);
    p->fn = fn;
    p->ctx = ctx;
    p->pending = p->threads - 1;
    p->generation++;
    pthread_cond_broadcast(&p->start);
    pthread_mutex_unlock(&p->lock);
    fn(ctx, 0, p->threads);
    pthread_mutex_lock(&p->lock);
    while (p->pending > 0)
        pthread_cond_wait(&p->done, &p->lock);
    pthread_mutex_unlock(&p->lock);
}
