/* SPDX-License-Identifier: Apache-2.0
 * The public bridge handle (pose/bridge.h) and what its files share:
 * bridge_api.c (open, apply, status, controls), bridge_scrub.c (recorded
 * time -> pose, for pose_bridge_pose_at), bridge_source_spec.c (source
 * strings). The handle owns the rig's skeleton, the mapping, a loaded clip,
 * and either a runner (the bridge thread) or nothing (POSE_BRIDGE_MANUAL);
 * the scrubber is opened on the first pose_bridge_pose_at. */
#ifndef POSE_BRIDGE_INTERNAL_H
#define POSE_BRIDGE_INTERNAL_H

#include "bridge_source_spec.h"
#include "mapping.h"
#include "pb_warn.h"
#include "player.h"
#include "pose/bridge.h"
#include "runner.h"

/** Replays a recording as fast as possible up to a recorded time, through
 *  the same decoder, mapping and filters as the bridge thread. Owned by the
 *  host thread that calls pose_bridge_pose_at. */
typedef struct pb_scrub {
    int open;
    /* clips: the runner's ticks, one period apart from media time 0 */
    pb_player player;
    int player_ok;
    pb_retarget *rt;
    double (*lq)[4], (*lt)[3];
    double next_tick;
    /* device recordings: updates up to the time; the first one past it waits in next */
    pb_source *src;
    pb_chanmap *cm;
    int64_t last_t;     /**< recorded time of the last update fed; -1 before the first */
    int have_next;
    pb_update next;
    uint32_t *next_ch;
    double *next_val;
    size_t next_cap;
    uint64_t samples;
    /* the result */
    pb_pose pose;
    double media_s;     /**< time of the newest sample in the pose */
    int held;
    pb_source_state state;
} pb_scrub;

struct pose_bridge {
    pose_allocator alloc;  /**< the host's, or malloc/free */
    char *source;          /**< copies of the open arguments (spec.target points into source) */
    char *map_path, *map_json, *skeleton;
    pb_spec spec;
    pose_bridge_options opt;
    const pose_rig *rig;
    pb_rig_skel *skel;
    pb_mapping *map;
    pb_joint_range *ranges; /**< the map's "ranges", bound to the rig: put on every state posed */
    int range_count;
    pb_clip *clip;
    double period;         /**< clips: media seconds between ticks */
    double duration_s;     /**< recordings: length; < 0 until measured (live: never) */
    pb_runner *runner;     /**< NULL in POSE_BRIDGE_MANUAL */
    int paused;
    pb_scrub scrub;
    pose_bridge_frame manual; /**< the last pose_bridge_pose_at */
    char fault[256];       /**< MANUAL: the scrubber's last fault */
    pb_warnings warnings;
};

void *pb_bridge_alloc(const pose_bridge *b, size_t size);
void pb_bridge_free(const pose_bridge *b, void *p);

/** Set `t_s`'s pose into b->scrub (pose, media_s, held). Restarts when t_s is earlier than the last. */
pose_status pb_scrub_to(pose_bridge *b, double t_s, pb_error *err);
/** Open the scrubber at the recording's start (pose_bridge_open calls it in MANUAL to check the source). */
pose_status pb_scrub_restart(pose_bridge *b, pb_error *err);
/** Length of a recording (clips: last frame's time); measured once by replaying it. */
pose_status pb_scrub_duration(pose_bridge *b, double *out, pb_error *err);
void pb_scrub_close(pose_bridge *b);

/** The source states in which the bridge holds the last good pose. */
static inline int pb_state_holds(pb_source_state s)
{
    return s == PB_SOURCE_STALE || s == PB_SOURCE_DISCONNECTED || s == PB_SOURCE_FAULT;
}

#endif /* POSE_BRIDGE_INTERNAL_H */
