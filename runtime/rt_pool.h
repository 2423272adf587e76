/* SPDX-License-Identifier: Apache-2.0 */
/* A fixed worker pool: run one task as N parts, the caller doing part 0.
 * Parts are assigned statically (part i always goes to worker i), so a
 * kernel that splits its range by part gives the same result every time. */
#ifndef POSE_RT_POOL_H
#define POSE_RT_POOL_H

#include <stddef.h>

typedef struct pose__pool pose__pool;

/** A task part: do share `part` (0..parts-1) of the work. */
typedef void (*pose__task_fn)(void *ctx, unsigned part, unsigned parts);

/** Bytes pose__pool_init needs for `threads` threads (>= 1). */
size_t pose__pool_size(unsigned threads);
/**
 * Start threads - 1 workers in caller-provided memory of pose__pool_size
 * bytes (aligned to 64). Returns 0, or -1 if a thread could not be started
 * (nothing is left running then).
 */
int pose__pool_init(pose__pool *pool, unsigned threads);
/** Stop and join the workers (the memory stays the caller's). */
void pose__pool_destroy(pose__pool *pool);
/** Number of parts a task runs as. */
unsigned pose__pool_threads(const pose__pool *pool);
/** Run fn(ctx, i, n) for i in 0..n-1 (part 0 on the caller) and wait for all. */
void pose__pool_run(pose__pool *pool, pose__task_fn fn, void *ctx);

/** An item of an item task: do item `item`. */
typedef void (*pose__item_fn)(void *ctx, size_t item);
/**
 * Run fn(ctx, i) for i in 0..items-1, each once, on whichever threads take
 * them (the caller takes items too) and wait for all. Items go to whoever
 * is running: a worker the OS has not scheduled (a loaded machine) is not
 * waited for, where pose__pool_run waits for every part. Results do not
 * depend on who runs an item when each item writes only its own outputs.
 */
void pose__pool_run_items(pose__pool *pool, pose__item_fn fn, void *ctx, size_t items);

/** Start of part `part` of `parts` over n items (end = start of part + 1). */
static inline size_t pose__part_begin(size_t n, unsigned part, unsigned parts)
{
    return (size_t)((unsigned long long)n * part / parts);
}

/* Part `part` of n items split in whole blocks of 8 (for loops that run 8
 * wide): items [*begin, *end). */
static inline void pose__part_range8(size_t n, unsigned part, unsigned parts, size_t *begin, size_t *end)
{
    const size_t blocks = (n + 7) / 8;
    size_t e = 8 * pose__part_begin(blocks, part + 1, parts);
    *begin = 8 * pose__part_begin(blocks, part, parts);
    *end = e < n ? e : n;
}

#endif /* POSE_RT_POOL_H */
