/* SPDX-License-Identifier: Apache-2.0 */
#include "hid_open.h"

#include <stdlib.h>
#include <string.h>

#include "hid_hidraw.h"

int pb_hid_spec_is_live(const char *spec)
{
    return strncmp(spec, "hid:", 4) == 0 || strncmp(spec, "/dev/hidraw", 11) == 0;
}

pose_status pb_hid_open(const char *spec, const pb_hid_replay_options *opt, pb_source **out, pb_error *err)
{
    *out = NULL;
    if (!spec || !*spec)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "hid: empty source");
    const pb_hid_source_options *so = opt ? &opt->source : NULL;
    if (strncmp(spec, "/dev/hidraw", 11) == 0) {
        pb_hid_match m = {.path = spec};
        return pb_hid_hidraw_open(&m, so, out, err);
    }
    if (strncmp(spec, "hid:", 4) == 0) {
        unsigned v[4] = {0};
        const char *p = spec + 4;
        int n = 0;
        while (n < 4 && *p) {
            char *end;
            unsigned long x = strtoul(p, &end, 16);
            if (end == p || x > 0xFFFF || (*end && *end != ':'))
                return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                               "%s: expected hid:VID:PID[:USAGE_PAGE:USAGE] in hex", spec);
            v[n++] = (unsigned)x;
            p = *end ? end + 1 : end;
        }
        if (*p || n < 2)
            return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "%s: expected hid:VID:PID[:USAGE_PAGE:USAGE] in hex", spec);
        pb_hid_match m = {v[0], v[1], v[2], v[3], NULL};
        return pb_hid_hidraw_open(&m, so, out, err);
    }
    return pb_hid_replay_open(spec, opt, out, err);
}
