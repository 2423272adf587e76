/* SPDX-License-Identifier: Apache-2.0 */
#include "timeline.h"

/* Stamps come from files: sums saturate rather than overflow. */
static int64_t sat_add(int64_t a, int64_t b)
{
    int64_t s;
    if (__builtin_add_overflow(a, b, &s))
        return a > 0 ? INT64_MAX : INT64_MIN;
    return s;
}

static int64_t sat_sub(int64_t a, int64_t b)
{
    int64_t s;
    if (__builtin_sub_overflow(a, b, &s))
        return a >= 0 ? INT64_MAX : INT64_MIN;
    return s;
}

void pb_timeline_init(pb_timeline *t, int64_t max_gap_ns)
{
    *t = (pb_timeline){.max_gap_ns = max_gap_ns > 0 ? max_gap_ns : PB_TIMELINE_MAX_GAP_NS};
}

int64_t pb_timeline_map(pb_timeline *t, int64_t t_ns, int64_t *jump_ns)
{
    int64_t out = sat_add(t_ns, t->offset_ns), jump = 0;
    if (t->have) {
        const int64_t step = sat_sub(out, t->last_ns);
        if (step < 0 || step > t->max_gap_ns) {
            jump = step;
            out = sat_add(t->last_ns, t->step_ns);
            t->offset_ns = sat_sub(out, t_ns);
        } else {
            t->step_ns = step;
        }
    }
    t->last_ns = out;
    t->have = 1;
    if (jump_ns)
        *jump_ns = jump;
    return out;
}
