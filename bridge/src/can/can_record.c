/* SPDX-License-Identifier: Apache-2.0 */
#include "can_record.h"

#include <errno.h>
#include <string.h>

#include "can_rx.h"
#include "candump_log.h"

int pb_can_record_run(int fd, const char *iface, FILE *out, const pb_can_record_options *opt,
                      pb_can_record_result *res, pb_error *err)
{
    const pb_can_record_options none = {0};
    if (!opt)
        opt = &none;
    pb_can_rx rx;
    pb_can_rx_init(&rx, fd);
    const int64_t start = pb_can_mono_ns();
    int64_t next_report = start + 1000000000;
    memset(res, 0, sizeof *res);
    while (!(opt->stop && *opt->stop)) {
        const int64_t now = pb_can_mono_ns();
        if (opt->seconds > 0 && now - start >= (int64_t)(opt->seconds * 1e9))
            return 0;
        if (opt->progress && now >= next_report) {
            fprintf(stderr, "\rpose-bridge can-record: %llu frames, %llu dropped, %.0f s", res->frames, res->drops,
                    (double)(now - start) * 1e-9);
            next_report += 1000000000;
        }
        pb_can_frame f;
        int64_t real;
        uint64_t d;
        /* 200 ms: the limits and the stop flag are checked at least that often */
        const int r = pb_can_rx_read(&rx, &f, &real, &d, 200);
        res->drops += d;
        if (r == 1) {
            f.t_ns = real;
            if (pb_candump_write(out, &f, iface) != 0) {
                pb_fail(err, POSE_ERR_IO, "write failed: %s", strerror(errno));
                return -1;
            }
            if (++res->frames == opt->count)
                return 0;
        } else if (r == -1 && errno != EINTR) {
            pb_fail(err, POSE_ERR_IO, "%s: %s", iface, strerror(errno));
            return -1;
        }
    }
    return 0;
}
