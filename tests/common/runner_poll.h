/* SPDX-License-Identifier: Apache-2.0 */
/* Tests of the bridge thread: act as a host frame loop while a source plays. */
#ifndef POSE_TEST_RUNNER_POLL_H
#define POSE_TEST_RUNNER_POLL_H

#include <time.h>

#include "runner.h"

/** Poll pb_runner_latest `polls` times, 10 ms apart (never blocking), and
 *  return how many polls saw a fresh pose. */
static inline int runner_poll_fresh(pb_runner *run, int polls)
{
    int fresh_seen = 0;
    for (int i = 0; i < polls; i++) {
        int fresh = 0;
        const pb_pose *p = pb_runner_latest(run, &fresh);
        fresh_seen += fresh && p->seq > 0;
        struct timespec ts = {0, 10000000};
        nanosleep(&ts, NULL);
    }
    return fresh_seen;
}

#endif /* POSE_TEST_RUNNER_POLL_H */
