/* SPDX-License-Identifier: Apache-2.0 */
/* clock.h's wall clock over CLOCK_MONOTONIC (clock_gettime, clock_nanosleep). */
#include "clock.h"

#include <errno.h>
#include <time.h>

int64_t pb_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

void pb_sleep_until_ns(int64_t t_ns)
{
    struct timespec ts = {(time_t)(t_ns / 1000000000), (long)(t_ns % 1000000000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
    }
}
