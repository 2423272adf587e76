/* SPDX-License-Identifier: Apache-2.0
 *
 * The bridge's source interface: anything that yields timestamped channel
 * values (a HID device, a CAN bus, a mocap file, a recording of any of them).
 * One backend per file, each filling a pb_source_ops table: hid/hid_source.c
 * over the transports hid/hid_hidraw.c and hid/hid_replay.c,
 * can/can_socketcan.c and can/candump_replay.c, mocap/mocap_source.c.
 * Simulated devices are sources that replay recordings through the same
 * decoder as the live path.
 *
 * Lifetime: a backend's open function allocates its whole struct (which
 * embeds pb_source first) with malloc/calloc and hands out the pb_source
 * pointer; pb_source_destroy() calls ops->close and then frees it.
 * Threads: a source is used by one thread at a time (the bridge thread).
 * The mapping layer (mapping.h) turns channel values into joint targets:
 * it binds mapping entries to channels by name (pb_channel.name) or by
 * HID usage (pb_channel.usage), so name channels stably.
 */
#ifndef POSE_BRIDGE_SOURCE_H
#define POSE_BRIDGE_SOURCE_H

#include <stddef.h>
#include <stdint.h>

/** Health of a source, as reported to the host. */
typedef enum pb_source_state {
    PB_SOURCE_OK = 0,          /**< delivering samples */
    PB_SOURCE_WAITING = 1,     /**< open, no sample yet */
    PB_SOURCE_STALE = 2,       /**< silent beyond its timeout; last values held */
    PB_SOURCE_DISCONNECTED = 3,/**< device gone; reopen attempts continue */
    PB_SOURCE_FAULT = 4,       /**< malformed data, error frames, bus-off; see message */
    PB_SOURCE_ENDED = 5,       /**< a recording reached its end (and does not loop) */
} pb_source_state;

/** One scalar channel a source delivers. */
typedef struct pb_channel {
    char name[64];   /**< e.g. "GenericDesktop.X#0", "ELBOW_R.angle", "Hips.Zrotation" */
    char unit[16];   /**< "deg", "rad", "" (unitless) ... */
    uint32_t usage;  /**< HID (page << 16 | usage), 0 when not HID */
    double min, max; /**< physical range when known, else min > max */
} pb_channel;

/** A batch of channel values that share one timestamp. */
typedef struct pb_update {
    int64_t t_ns;             /**< source timestamp: CLOCK_MONOTONIC (live) or recorded */
    size_t count;             /**< entries in channels/values */
    const uint32_t *channels; /**< channel indices, owned by the source until the next read */
    const double *values;     /**< values in the channel's unit */
} pb_update;

typedef struct pb_source pb_source;

/** Called on every state change, from the thread that reads the source. */
typedef void (*pb_status_fn)(pb_source *src, pb_source_state state, const char *message, void *user);

typedef struct pb_source_ops {
    const char *kind; /**< "hid", "hid-replay", "can", "candump-replay", "bvh", "asf-amc" ... */
    /**
     * Wait at most timeout_ms (0 = poll, -1 = forever) for the next update.
     * Returns 1 with *out filled, 0 when nothing arrived in time, -1 when the
     * source cannot deliver (state and message say why).
     */
    int (*read)(pb_source *src, pb_update *out, int timeout_ms);
    /** Replays only (NULL otherwise): jump to a recorded time. */
    int (*seek)(pb_source *src, int64_t t_ns);
    /** Release everything the backend owns (not the pb_source itself). */
    void (*close)(pb_source *src);
} pb_source_ops;

/** Common part of every source; backends embed it first in their struct. */
struct pb_source {
    const pb_source_ops *ops;
    pb_channel *channels;     /**< owned by the source */
    size_t channel_count;
    pb_source_state state;
    char message[256];        /**< detail for the current state */
    pb_status_fn on_status;   /**< may be NULL */
    void *on_status_user;
};

/** Backends call this on every state change: stores it and calls on_status. */
void pb_source_set_state(pb_source *src, pb_source_state state, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/** Lower-case name of a state ("ok", "stale" ...); static storage. */
const char *pb_source_state_name(pb_source_state state);
/** ops->read with argument checks: 1 update, 0 timeout, -1 error. */
int pb_source_read(pb_source *src, pb_update *out, int timeout_ms);
/** ops->seek, or -1 when the source cannot seek. */
int pb_source_seek(pb_source *src, int64_t t_ns);
/** ops->close only (the struct stays allocated). NULL is a no-op. */
void pb_source_close(pb_source *src);
/** ops->close, then free(src). NULL is a no-op. */
void pb_source_destroy(pb_source *src);
/** Index of the channel with this exact name, or -1. */
long pb_source_find_channel(const pb_source *src, const char *name);

#endif /* POSE_BRIDGE_SOURCE_H */
