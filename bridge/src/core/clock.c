/* SPDX-License-Identifier: Apache-2.0 */
/* The media clock; pb_now_ns and pb_sleep_until_ns are pb_clock_posix.c's or
 * pb_clock_win32.c's. */
#include "clock.h"

void pb_clock_start(pb_clock *c, double speed, double media_s, int64_t now_ns)
{
    c->speed = speed > 0.0 ? speed : 1.0;
    c->paused = 0;
    c->anchor_ns = now_ns;
    c->anchor_s = media_s;
}

double pb_clock_media(const pb_clock *c, int64_t now_ns)
{
    if (c->paused)
        return c->anchor_s;
    return c->anchor_s + (double)(now_ns - c->anchor_ns) * 1e-9 * c->speed;
}

int64_t pb_clock_wall(const pb_clock *c, double media_s)
{
    if (c->paused)
        return INT64_MAX;
    return c->anchor_ns + (int64_t)((media_s - c->anchor_s) / c->speed * 1e9);
}

void pb_clock_set_speed(pb_clock *c, double speed, int64_t now_ns)
{
    c->anchor_s = pb_clock_media(c, now_ns);
    c->anchor_ns = now_ns;
    if (speed > 0.0)
        c->speed = speed;
}

void pb_clock_pause(pb_clock *c, int paused, int64_t now_ns)
{
    c->anchor_s = pb_clock_media(c, now_ns);
    c->anchor_ns = now_ns;
    c->paused = paused != 0;
}

void pb_clock_seek(pb_clock *c, double media_s, int64_t now_ns)
{
    c->anchor_s = media_s;
    c->anchor_ns = now_ns;
}
