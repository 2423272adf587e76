/* SPDX-License-Identifier: Apache-2.0 */
/* Shared helpers for the benchmark programs: a monotonic clock and a
 * STREAM-style triad that measures the memory bandwidth a kernel's
 * bytes-per-frame can be compared with. */
#ifndef POSE_BENCH_COMMON_H
#define POSE_BENCH_COMMON_H

#include <stddef.h>

/** Seconds on CLOCK_MONOTONIC. */
double bench_now(void);
/** CPU seconds used by the whole process (all threads). */
double bench_cpu_seconds(void);

/**
 * STREAM triad a[i] = b[i] + s * c[i] over three arrays of `elements`
 * doubles, split statically over `threads` threads; best of `reps` passes.
 * Returns bytes moved per second counted as STREAM does (3 * 8 bytes per
 * element: two reads, one write, write-allocate traffic not counted), or a
 * negative value if memory or threads were not available.
 */
double bench_triad_bytes_per_s(unsigned threads, size_t elements, int reps);

/** 1 when stderr is a terminal (progress lines go there only then). */
int bench_progress_enabled(void);

#endif /* POSE_BENCH_COMMON_H */
