/* SPDX-License-Identifier: Apache-2.0 */
#include "rt_pool.h"

#include <stdatomic.h>
#include <stdint.h>

#include "rt_thread.h"

/* How long a thread polls before it sleeps on a condition variable. A
 * futex wake-up costs 10 us on bare metal and ~100 us where the idle core
 * is a halted virtual CPU, more than a whole pass over a medium rig; polling
 * a little longer than that keeps back-to-back passes (and frames) free of
 * wake-ups, and an idle pool still ends up asleep. */
#define SPIN_NS 200000
/* Polls between clock reads. */
#define SPIN_CHECK 64

struct pose__worker {
    pose__pool *pool;
    unsigned part;
    pose__thread thread;
};

struct pose__pool {
    pose__mutex lock;
    pose__cond start;             /* signalled when a new task (generation) is posted */
    pose__cond done;              /* signalled when the last worker finishes */
    unsigned threads;
    _Atomic unsigned pending;     /* workers still running the current task */
    /* Task counter, times 2, plus 1 for an item task (pose__pool_run_items):
     * a worker runs each generation once, and reads its kind with it. */
    _Atomic uint64_t generation;
    _Atomic int stop;
    pose__task_fn fn;             /* written before generation is bumped (release) */
    void *ctx;
    /* Item tasks: workers take items while the task is open; the caller
     * closes it when none is left and waits only for the workers inside. */
    pose__item_fn item_fn;
    size_t items;
    _Atomic size_t next;          /* next item to take */
    _Atomic int open;
    _Atomic unsigned inside;      /* workers that entered the open task */
    struct pose__worker workers[]; /* threads - 1 */
};

size_t pose__pool_size(unsigned threads)
{
    return sizeof(pose__pool) + (threads > 1 ? threads - 1 : 0) * sizeof(struct pose__worker);
}

static inline void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ volatile("yield");
#endif
}

/* Poll until *gen differs from seen (1) or SPIN_NS pass (0). */
static int spin_for_generation(pose__pool *p, uint64_t seen)
{
    const int64_t deadline = pose__now_ns() + SPIN_NS;
    for (;;) {
        for (int i = 0; i < SPIN_CHECK; i++) {
            if (atomic_load_explicit(&p->generation, memory_order_acquire) != seen)
                return 1;
            cpu_relax();
        }
        if (pose__now_ns() > deadline)
            return 0;
    }
}

/* Poll until every worker is done (1) or SPIN_NS pass (0). */
static int spin_for_done(pose__pool *p)
{
    const int64_t deadline = pose__now_ns() + SPIN_NS;
    for (;;) {
        for (int i = 0; i < SPIN_CHECK; i++) {
            if (atomic_load_explicit(&p->pending, memory_order_acquire) == 0)
                return 1;
            cpu_relax();
        }
        if (pose__now_ns() > deadline)
            return 0;
    }
}

/* Take items until none is left. */
static void take_items(pose__pool *p)
{
    for (;;) {
        const size_t i = atomic_fetch_add_explicit(&p->next, 1, memory_order_relaxed);
        if (i >= p->items)
            return;
        p->item_fn(p->ctx, i);
    }
}

/* A worker's turn at an item task. It may come late, after the task was
 * closed (it never reads the task then) or while a later one is open (it
 * helps with that one: its fields were written before it opened). */
static void worker_items(pose__pool *p)
{
    atomic_fetch_add_explicit(&p->inside, 1, memory_order_seq_cst);
    if (atomic_load_explicit(&p->open, memory_order_seq_cst))
        take_items(p);
    atomic_fetch_sub_explicit(&p->inside, 1, memory_order_release);
}

static void *worker_main(void *arg)
{
    struct pose__worker *w = arg;
    pose__pool *p = w->pool;
    uint64_t seen = 0;
    for (;;) {
        if (!spin_for_generation(p, seen)) {
            pose__mutex_lock(&p->lock);
            while (atomic_load_explicit(&p->generation, memory_order_acquire) == seen)
                pose__cond_wait(&p->start, &p->lock);
            pose__mutex_unlock(&p->lock);
        }
        if (atomic_load_explicit(&p->stop, memory_order_acquire))
            break;
        seen = atomic_load_explicit(&p->generation, memory_order_acquire);
        if (seen & 1u) {
            worker_items(p);
            continue;
        }
        p->fn(p->ctx, w->part, p->threads);
        if (atomic_fetch_sub_explicit(&p->pending, 1, memory_order_acq_rel) == 1) {
            /* under the lock: the caller may be between its check and its wait */
            pose__mutex_lock(&p->lock);
            pose__cond_signal(&p->done);
            pose__mutex_unlock(&p->lock);
        }
    }
    return NULL;
}

/* Bump the generation under the lock (sleeping workers re-check it there)
 * and wake the sleepers; polling workers see it directly. */
static void post(pose__pool *p, int items)
{
    pose__mutex_lock(&p->lock);
    const uint64_t g = atomic_load_explicit(&p->generation, memory_order_relaxed);
    atomic_store_explicit(&p->generation, (g | 1u) + 1u + (items ? 1u : 0u), memory_order_release);
    pose__cond_broadcast(&p->start);
    pose__mutex_unlock(&p->lock);
}

static void stop_workers(pose__pool *p, unsigned started)
{
    atomic_store_explicit(&p->stop, 1, memory_order_release);
    post(p, 0);
    for (unsigned i = 0; i < started; i++)
        pose__thread_join(&p->workers[i].thread);
    pose__cond_destroy(&p->done);
    pose__cond_destroy(&p->start);
    pose__mutex_destroy(&p->lock);
}

int pose__pool_init(pose__pool *p, unsigned threads)
{
    if (threads < 1)
        threads = 1;
    p->threads = threads;
    atomic_init(&p->pending, 0);
    atomic_init(&p->generation, 0);
    atomic_init(&p->stop, 0);
    atomic_init(&p->next, 0);
    atomic_init(&p->open, 0);
    atomic_init(&p->inside, 0);
    p->fn = NULL;
    p->item_fn = NULL;
    p->items = 0;
    p->ctx = NULL;
    if (pose__mutex_init(&p->lock) != 0)
        return -1;
    if (pose__cond_init(&p->start) != 0) {
        pose__mutex_destroy(&p->lock);
        return -1;
    }
    if (pose__cond_init(&p->done) != 0) {
        pose__cond_destroy(&p->start);
        pose__mutex_destroy(&p->lock);
        return -1;
    }
    for (unsigned i = 0; i + 1 < threads; i++) {
        p->workers[i].pool = p;
        p->workers[i].part = i + 1;
        if (pose__thread_start(&p->workers[i].thread, worker_main, &p->workers[i]) != 0) {
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
    /* no worker reads these until it sees the new generation */
    p->fn = fn;
    p->ctx = ctx;
    atomic_store_explicit(&p->pending, p->threads - 1, memory_order_relaxed);
    post(p, 0);
    fn(ctx, 0, p->threads);
    if (spin_for_done(p))
        return;
    pose__mutex_lock(&p->lock);
    while (atomic_load_explicit(&p->pending, memory_order_acquire) > 0)
        pose__cond_wait(&p->done, &p->lock);
    pose__mutex_unlock(&p->lock);
}

void pose__pool_run_items(pose__pool *p, pose__item_fn fn, void *ctx, size_t items)
{
    p->item_fn = fn;
    p->ctx = ctx;
    p->items = items;
    atomic_store_explicit(&p->next, 0, memory_order_relaxed);
    if (p->threads == 1) {
        take_items(p);
        return;
    }
    atomic_store_explicit(&p->open, 1, memory_order_seq_cst);
    post(p, 1);
    take_items(p);
    /* Close, then wait for the workers that entered: each is finishing its
     * last item; one that enters now finds the task closed. A worker that
     * has not woken up is not waited for. */
    atomic_store_explicit(&p->open, 0, memory_order_seq_cst);
    while (atomic_load_explicit(&p->inside, memory_order_acquire) > 0)
        cpu_relax();
}
