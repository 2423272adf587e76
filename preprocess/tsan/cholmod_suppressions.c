/* SPDX-License-Identifier: Apache-2.0
 * Compiled into every program that links pose_preprocess in a ThreadSanitizer
 * build (-DPOSE_TSAN=ON): pose-bake, the tests and fixtures that bake.
 * CHOLMOD's supernodal factorisation runs OpenMP threads (libgomp, not
 * instrumented), and its BLAS may run threads of its own (below): TSan sees a worker's memset of CHOLMOD's workspace but not
 * the OpenMP barrier that orders it before the main thread's next use, in
 * these two CHOLMOD functions, nor the fork that hands a fresh workspace from
 * cholmod_malloc on the main thread to the worker that clears it (the
 * worker's frames are libgomp's, without symbols). Every other frame, pose-bake's own threads included, stays
 * checked. Built in rather than a suppressions file so that no test has to
 * carry TSAN_OPTIONS for the pose-bake it runs. */
const char *__tsan_default_suppressions(void);

/* Default visibility: the build hides symbols, and TSan's runtime (a shared
 * library) only sees this definition over its own weak one when the program
 * exports it. */
__attribute__((visibility("default"))) const char *__tsan_default_suppressions(void)
{
    return "race:cholmod_clear_flag\n"
           "race:cholmod_super_numeric\n"
           "race:cholmod_malloc\n"
           /* The same hand-offs where TSan could not restore the main thread's
            * stack: the only frame left to name is the worker's, in libgomp
            * (which pose's own code never calls: its threads are pthreads). */
           "race:libgomp.so.1\n"
           /* Where the BLAS is OpenBLAS built with its own pthreads
            * (libopenblas0-pthread, which apt may pick for libblas.so.3):
            * CHOLMOD's dense updates run in its workers, whose hand-offs TSan
            * cannot see either (uninstrumented, no symbols past the kernel). */
           "race:libopenblas.so.0\n";
}
