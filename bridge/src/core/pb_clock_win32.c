/* SPDX-License-Identifier: Apache-2.0 */
/* clock.h's wall clock over QueryPerformanceCounter. */
#include "clock.h"

#define WIN32_LEAN_AND_MEAN
#include <windows.h>

int64_t pb_now_ns(void)
{
    LARGE_INTEGER count, freq;
    QueryPerformanceCounter(&count);
    QueryPerformanceFrequency(&freq);
    /* whole seconds and the remainder apart: count * 1e9 overflows after days */
    int64_t s = count.QuadPart / freq.QuadPart, r = count.QuadPart % freq.QuadPart;
    return s * 1000000000 + r * 1000000000 / freq.QuadPart;
}

void pb_sleep_until_ns(int64_t t_ns)
{
    /* Sleep whole milliseconds short of the deadline (Sleep may overrun by a
     * timer tick), then yield the rest away. */
    for (int64_t left; (left = t_ns - pb_now_ns()) > 0;) {
        if (left > 2000000)
            Sleep((DWORD)(left / 1000000 - 1));
        else
            SwitchToThread();
    }
}
