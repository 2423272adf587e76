/* SPDX-License-Identifier: Apache-2.0
 *
 * pose/bridge.h -- drive a pose_state from input devices and recordings.
 *
 * A bridge reads one source (a mocap clip, a HID device, a CAN bus, or a
 * recording of any of them) on its own thread, decodes, calibrates, filters,
 * limits and retargets it onto a rig through a mapping, and hands the newest
 * joint targets to the host without locks. The host's frame loop calls
 * pose_bridge_apply() once per frame; it never blocks.
 *
 *     pose_bridge *br;
 *     pose_bridge_options opt = {.size = sizeof opt, .map_path = "hid_mannequin_full_body.json"};
 *     if (pose_bridge_open("hid:1209:0001", rig, &opt, &br) < 0) {
 *         fprintf(stderr, "%s\n", pose_last_error());
 *         return 1;
 *     }
 *     for (;;) {                                   // the host's frame loop
 *         pose_bridge_frame f;
 *         pose_bridge_apply(br, state, &f);        // f.fresh, f.held, f.clamped
 *         pose_apply(state);
 *         render(state);
 *     }
 *     pose_bridge_close(br);
 *
 * Sources are named by one string:
 *
 *   path.bvh                    BVH clip
 *   path.amc                    ASF/AMC clip; the skeleton is options.skeleton, else
 *                               the CMU subject's .asf beside it (01_01.amc -> 01.asf)
 *   path.hid                    hid-recorder file (simulated HID device)
 *   path.log                    candump -l log (simulated CAN bus)
 *   path.usbmon                 usbmon text capture (simulated vendor-class USB device)
 *   hid:VID:PID[:PAGE:USAGE]    live HID device (hex USB ids; optionally the top-level
 *                               collection's usage page and usage), through hidapi
 *   /dev/hidrawN                live HID device node
 *   hidusb:VID:PID[:IFACE]      live HID device without a hidraw node, through hidapi's
 *                               libusb backend (usbhid detached, containers)
 *   can:IFACE  or  IFACE        live SocketCAN interface (can0, vcan0 ...)
 *   usb:VID:PID[:SERIAL][/IF/EP]  live vendor-class USB device through libusb (hex ids,
 *                               decimal interface, hex IN endpoint)
 *   KIND:PATH                   a file of another extension: bvh:, amc:,
 *                               hid-recording:, candump:, usbmon:
 *
 * HID, CAN and USB sources need a mapping with "channels" (for CAN also its
 * "can" bus description, whose relative "dbc" path is taken from the mapping
 * file's folder, or from the working directory for map_json; for USB its
 * "usb" frame layout); clips map rig joints
 * to clip joints of the same name without one. Recorded times count from the
 * recording's start (a hid-recorder file's times, a candump log's first
 * frame); a live source's from its first sample. Mappings speak the clinical
 * angle convention of pose.h (pose_joint_clinical) where the rig knows its
 * neutral posture: a device reading 0 in the anatomical neutral posture puts
 * the patient there.
 *
 * Conventions are libpose's: opaque handles, functions that can fail return a
 * pose_status and pose_last_error() (per thread) says what went wrong, naming
 * the file, line or offset; options structs are zero-default and carry their
 * own size. One bridge is used by one host thread at a time (its own thread
 * is internal); any number of bridges may run at once.
 */
#ifndef POSE_BRIDGE_H
#define POSE_BRIDGE_H

#include <stddef.h>
#include <stdint.h>

#include "pose/pose.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32) && !defined(POSE_STATIC)
#  if defined(POSE_BRIDGE_BUILDING)
#    define POSE_BRIDGE_API __declspec(dllexport)
#  else
#    define POSE_BRIDGE_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__) || defined(__clang__)
#  define POSE_BRIDGE_API __attribute__((visibility("default")))
#else
#  define POSE_BRIDGE_API
#endif

typedef struct pose_bridge pose_bridge; /**< one source driving one rig */

/** How a recorded source plays. Live sources always run in real time. */
typedef enum pose_bridge_play {
    POSE_BRIDGE_REALTIME = 0, /**< recorded timing, scaled by options.speed */
    POSE_BRIDGE_AS_FAST_AS_POSSIBLE = 1,
    POSE_BRIDGE_MANUAL = 2,   /**< no thread: the host picks times with pose_bridge_pose_at */
} pose_bridge_play;

/**
 * Options for pose_bridge_open; a zeroed struct (with size set) gives the
 * defaults. `size` lets the struct grow: pose_bridge_open reads the first
 * `size` bytes, so size must be 0 (every option at its default) or at least
 * the 0.2 layout below (POSE_BRIDGE_OPTIONS_SIZE_0_2); fields a later version
 * appends are read only when size covers them.
 */
typedef struct pose_bridge_options {
    size_t size;              /**< sizeof(pose_bridge_options), or 0 for the defaults */
    const char *map_path;     /**< mapping file (JSON), or NULL */
    const char *map_json;     /**< the mapping as a string (instead of map_path), or NULL */
    const char *skeleton;     /**< .asf for an .amc source, or NULL to look beside it */
    pose_bridge_play play;
    double speed;             /**< media seconds per second for POSE_BRIDGE_REALTIME; 0 = 1 */
    int loop;                 /**< recorded sources start over at their end */
    double start_s;           /**< recorded sources: initial media time */
    double end_s;             /**< recorded sources: end (POSE_BRIDGE_ENDED) after the pose at this
                                   media time; 0 = at the recording's end */
    long max_poses;           /**< end after this many published poses; 0 = no limit */
    int start_paused;
    double rate_hz;           /**< clips: publish rate, slerping between frames; 0 = frame rate */
    double stale_after_s;     /**< live sources: silence after which the pose is held; 0 = 0.25 */
    int rt_priority;          /**< > 0: SCHED_FIFO priority of the bridge thread where allowed */
    const char *record_path;  /**< record the published joint angles as BVH (flushed per pose), or
                                   NULL; ignored in POSE_BRIDGE_MANUAL */
    /**
     * Zero = malloc/free. Used for the handle and what it keeps for the host:
     * copies of the strings above, the warnings, the pose pose_bridge_pose_at
     * builds, status scratch. The parsers, decoders, mapping and the bridge
     * thread's buffers use malloc.
     */
    pose_allocator allocator;
} pose_bridge_options;

/** Size of the 0.2 layout of pose_bridge_options: the least non-zero options.size accepted. */
#define POSE_BRIDGE_OPTIONS_SIZE_0_2 (offsetof(pose_bridge_options, allocator) + sizeof(pose_allocator))

/** Health of the source. */
typedef enum pose_bridge_source_state {
    POSE_BRIDGE_OK = 0,           /**< delivering samples */
    POSE_BRIDGE_WAITING = 1,      /**< open, no sample yet */
    POSE_BRIDGE_STALE = 2,        /**< silent beyond its timeout; last good pose held */
    POSE_BRIDGE_DISCONNECTED = 3, /**< device gone; reopening continues; pose held */
    POSE_BRIDGE_FAULT = 4,        /**< malformed data, error frames, bus-off; pose held */
    POSE_BRIDGE_ENDED = 5,        /**< a recording reached its end (and does not loop) */
} pose_bridge_source_state;

/** What one pose_bridge_apply did. */
typedef struct pose_bridge_frame {
    int fresh;          /**< a pose newer than the last apply was applied */
    int held;           /**< the source is stale, disconnected or faulty (a CAN node silent, a HID
                             device unplugged ...): the last good values hold */
    int clamped;        /**< joints whose request a limit changed (pose_last_error names the last) */
    int joints;         /**< joints the bridge set */
    double media_s;     /**< source time of the applied pose (recorded time, or seconds since open) */
    double age_s;       /**< how old the applied pose is: seconds since the bridge thread published
                             it (pose_bridge_pose_at: t_s minus the time of its newest sample) */
    uint64_t seq;       /**< increases by one per published pose; 0 before the first */
} pose_bridge_frame;

/**
 * Counters and health (pose_bridge_status_get). The caller sets size; fields
 * a later version appends are written only when size covers them.
 */
typedef struct pose_bridge_status {
    size_t size;                    /**< sizeof(pose_bridge_status): at least the 0.2 layout */
    pose_bridge_source_state state;
    int connected;                  /**< live device present (recorded sources: 1) */
    const char *kind;               /**< "bvh", "asf-amc", "hid", "hid-replay", "can", "candump-replay", "usb", "usbmon-replay" */
    uint64_t samples;               /**< source samples read */
    uint64_t drops;                 /**< samples rejected or lost (malformed, gaps in a counter) */
    uint64_t poses;                 /**< poses published */
    double last_sample_age_s;       /**< since the last good sample; -1 before the first */
    double media_s;                 /**< source time of the newest pose */
    double duration_s;              /**< recorded sources: length; live: -1 */
    double lag_p50_ms, lag_p99_ms;  /**< bridge thread wake-up lateness (clips), over every tick so far, within 1 % */
    double lag_max_ms;
    int realtime;                   /**< the bridge thread got the rt_priority it asked for */
    long frame;                     /**< clips: frame of the newest pose; -1 otherwise */
    long frame_count;               /**< clips: frames; -1 otherwise */
    double frame_time_s;            /**< clips: seconds per frame; 0 otherwise */
    char fault[256];                /**< the last stale/disconnected/fault message, "" when none */
} pose_bridge_status;

/**
 * Open `source` (see the table above) for `rig` and, unless options->play is
 * POSE_BRIDGE_MANUAL, start the bridge thread. `options` may be NULL (the
 * defaults). The rig must outlive the bridge. Files are read and checked
 * here: on failure *out is NULL and pose_last_error() says why, naming the
 * file and line (a mapping's unknown joint, a DBC syntax error ...). A live
 * source cannot play POSE_BRIDGE_MANUAL.
 * @since 0.2
 */
POSE_BRIDGE_API pose_status pose_bridge_open(const char *source, const pose_rig *rig,
                                             const pose_bridge_options *options, pose_bridge **out);
/** Stop the thread, close the source and any recording, free; NULL is a no-op. @since 0.2 */
POSE_BRIDGE_API void pose_bridge_close(pose_bridge *bridge);

/**
 * Apply the newest pose to `state` (a state of the bridge's rig): never
 * blocks, allocates nothing. Joints the mapping drives are set (every call,
 * fresh or not); the others are left as they are; nothing is set before the
 * first pose. The mapping's "ranges" become the state's ranges of motion for
 * the joints they list (pose_set_joint_range), here and in
 * pose_bridge_pose_at. `frame` may be NULL. POSE_CLAMPED when a limit
 * changed a joint. In POSE_BRIDGE_MANUAL it sets nothing and reports the
 * last pose_bridge_pose_at. @since 0.2
 */
POSE_BRIDGE_API pose_status pose_bridge_apply(pose_bridge *bridge, pose_state *state, pose_bridge_frame *frame);
/**
 * Recorded sources: set `state` to the pose at recorded time t_s, replaying
 * through the same decoder, mapping and filters as live play (as fast as
 * possible up to t_s; an earlier time starts over): the pose the bridge
 * thread publishes at that time (clips: the last tick at or before t_s;
 * recordings: after every sample up to t_s). frame->held when the source was
 * stale or faulty at t_s, or its newest sample is older than stale_after_s.
 * Works in any play mode, on the calling thread (its own replay, not the
 * bridge thread's); POSE_ERR_INVALID_ARGUMENT past the recording's end, and
 * POSE_ERR_UNSUPPORTED for live sources. @since 0.2
 */
POSE_BRIDGE_API pose_status pose_bridge_pose_at(pose_bridge *bridge, double t_s, pose_state *state,
                                                pose_bridge_frame *frame);

/**
 * Snapshot of the counters; status->size must be set. Takes a short lock the
 * bridge thread holds only between samples. The first call on a HID or CAN
 * recording reads it through once, as fast as possible, to learn its length
 * (milliseconds for the bundled recordings). @since 0.2
 */
POSE_BRIDGE_API pose_status pose_bridge_status_get(pose_bridge *bridge, pose_bridge_status *status);
/**
 * Recorded sources played by the bridge thread: pause or resume. A paused
 * recording reads nothing and resumes where it stopped. Live sources and
 * POSE_BRIDGE_MANUAL: POSE_ERR_UNSUPPORTED. @since 0.2
 */
POSE_BRIDGE_API pose_status pose_bridge_pause(pose_bridge *bridge, int paused);
/**
 * Recorded sources played by the bridge thread: continue from media time
 * t_s. A paused clip publishes the pose at t_s at once (so seeking while
 * paused steps). @since 0.2
 */
POSE_BRIDGE_API pose_status pose_bridge_seek(pose_bridge *bridge, double t_s);
/**
 * Clips played by the bridge thread: playing speed (media s per s; > 0).
 * HID and CAN recordings play at the options.speed they were opened with
 * (POSE_ERR_UNSUPPORTED here). @since 0.2
 */
POSE_BRIDGE_API pose_status pose_bridge_set_speed(pose_bridge *bridge, double speed);
/**
 * Block until the bridge thread has ended (1: a recording's end, end_s or
 * max_poses) or timeout_ms passed (0); -1 waits forever. POSE_BRIDGE_MANUAL:
 * 0 at once. @since 0.2
 */
POSE_BRIDGE_API int pose_bridge_wait(pose_bridge *bridge, int timeout_ms);

/**
 * Warnings the source's files raised while loading (a HID descriptor's
 * trailing bytes, a DBC's repeated pseudo-message signals, a mapping's
 * duplicate key ...) and while playing (a recording's time stamp jumping
 * more than a minute or going back, a line cut by a killed recorder, a HID
 * report longer than its descriptor): each names the file and line or
 * offset. The list may grow while the bridge thread plays; entries already
 * counted do not change. Valid until the bridge is closed; NULL past the
 * count. The first 32 are kept. @since 0.2
 */
POSE_BRIDGE_API size_t pose_bridge_warning_count(const pose_bridge *bridge);
POSE_BRIDGE_API const char *pose_bridge_warning(const pose_bridge *bridge, size_t index);

/** Name of a source state ("ok", "stale" ...); static storage. @since 0.2 */
POSE_BRIDGE_API const char *pose_bridge_state_name(pose_bridge_source_state state);

#ifdef __cplusplus
}
#endif
#endif /* POSE_BRIDGE_H */
