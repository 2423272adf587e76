/* SPDX-License-Identifier: Apache-2.0
 * Lock-free hand-off of joint targets from the bridge thread (one writer)
 * to the host's frame loop (one reader): a triple buffer. The writer fills
 * the back slot and swaps it with the shared middle slot; the reader swaps
 * its front slot with the middle one when a newer pose is there. Neither
 * side ever waits for the other and a pose is never seen half-written:
 * each slot is owned by exactly one side at any time. */
#ifndef POSE_BRIDGE_HANDOFF_H
#define POSE_BRIDGE_HANDOFF_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

/** Joint targets for a rig: what pose_set_joint / pose_set_root take. */
typedef struct pb_pose {
    int joint_count;
    float (*q)[4];       /**< per rig joint: local rotation relative to rest {x,y,z,w} */
    uint8_t *active;     /**< per rig joint: 1 when a mapping drives it */
    float root_t[3];     /**< root motion for pose_set_root (model space) */
    float root_q[4];     /**< root rotation for pose_set_root ({0,0,0,1} when the root joint carries it) */
    int has_root;        /**< root_t/root_q are meaningful */
    int64_t t_ns;        /**< when the bridge produced it (CLOCK_MONOTONIC) */
    int64_t lag_ns;      /**< how late: t_ns minus the recorded timing's deadline (0 for live sources) */
    double media_s;      /**< clip or source time it shows */
    long frame;          /**< clip frame (floor of media time), -1 for live sources */
    uint64_t seq;        /**< increases by one per published pose */
} pb_pose;

/** Allocate a pose for `joints` joints, at rest; free with pb_pose_free. */
int pb_pose_init(pb_pose *p, int joints);
void pb_pose_free(pb_pose *p);
/** All rotations identity, nothing active, no root motion. */
void pb_pose_reset(pb_pose *p);
/** Copy values (same joint_count). */
void pb_pose_copy(pb_pose *dst, const pb_pose *src);

typedef struct pb_handoff {
    pb_pose slot[3];
    atomic_uint middle; /**< slot index | PB_HANDOFF_FRESH */
    unsigned back;      /**< writer's slot */
    unsigned front;     /**< reader's slot */
    uint64_t seq;
} pb_handoff;

int pb_handoff_init(pb_handoff *h, int joints);
void pb_handoff_free(pb_handoff *h);
/** Writer: the slot to fill (stays the writer's until publish). */
pb_pose *pb_handoff_back(pb_handoff *h);
/** Writer: make the back slot the newest pose; never blocks. */
void pb_handoff_publish(pb_handoff *h);
/**
 * Reader: the newest published pose (or the one read last time when none is
 * newer; seq 0 before the first publish). Valid until the reader's next call.
 * Never blocks. *fresh (may be NULL) says whether it is new.
 */
const pb_pose *pb_handoff_latest(pb_handoff *h, int *fresh);

#endif /* POSE_BRIDGE_HANDOFF_H */
