/* SPDX-License-Identifier: Apache-2.0
 * Mapping files: how a source drives a rig. One JSON file (cJSON) with two
 * optional parts:
 *
 *   "joints": mocap retargeting. { "<rig joint>": "<clip joint>" | {
 *       "source": "<clip joint>", "align": true, "filter": {...} }, ... }
 *   "channels": scalar channels (HID, CAN) driving one joint axis each:
 *     [ { "channel": "<pb_channel.name>"  (or "usage": "0x00010030" with
 *         optional "index": n for the n-th channel of that HID usage),
 *         "joint": "<rig joint>",
 *         "dof": "flexion" | "abduction" | "rotation"  (or the rig's own name
 *             for that angle: "dorsiflexion", "pronation" ...): a clinical
 *             angle, degrees from the anatomical neutral posture (pose.h,
 *             pose_joint_clinical); the joint's clinical angles compose as
 *             rotations about its anatomical axes, onto its neutral offset;
 *         or "axis": "x"|"y"|"z" with "order": "XYZ": an Euler angle about
 *             the joint's rest frame (rigs without clinical data, the root),
 *             the joint's channels composing in that order;
 *         "calibration": {"raw": [r0, r1], "deg": [d0, d1]}   two-point, or
 *                        {"offset": o, "scale": s}            deg = (raw + o) * s,
 *         "invert": false, "deadband": 0.0 (deg, around the last output),
 *         "filter": {"min_cutoff": Hz, "beta": b, "d_cutoff": Hz},
 *         "limits": [min_deg, max_deg] }, ... ]
 *
 * Top-level options (all optional):
 *   "source_axes" / "rig_axes": {"up": "+y", "forward": "+z"}: the clip's
 *       and the rig's frames; the clip's motion is rotated from one to the other.
 *   "scale": clip length unit -> rig unit (root motion), default 1.
 *   "root_motion": "none" | "horizontal" | "full" (default "none").
 *   "root_origin": "reference" (default) | "first_frame": where root motion
 *       is measured from. A zero reference pose puts a CMU clip's hips on
 *       the floor (the height is in the channels), so the rig's pelvis
 *       would rise by the performer's hip height; "first_frame" starts the
 *       rig where it rests and moves it by the clip's displacement since its
 *       first frame.
 *   "reference": "zero" (all channels 0, default) or a frame number: the clip
 *       pose taken to correspond to the rig's rest pose.
 *   "align": true (default): per joint, bend the rig's rest bone onto the
 *       clip's reference bone, so limbs point where the clip's do even when
 *       the two rest poses differ, and turn it about the bone so that the
 *       rig's hinges (read from their limits) and the clip's (measured from
 *       its motion) share their axes (retarget.c). Set it false, per joint,
 *       where the clip's joint positions are schematic rather than a
 *       posture (CMU's straight spine and mid-chest collars): the segment
 *       then keeps the rig's rest posture at the clip's reference pose.
 *   "filter": default One Euro parameters for every joint / channel.
 *   "ranges": { "<rig joint>": { "flexion": [min_deg, max_deg],
 *       "abduction": [...], "rotation": [...] }, ... }: the range of motion
 *       the state the bridge drives clamps each listed joint to, in clinical
 *       angles (degrees from neutral; the keys are the generic names or the
 *       joint's own names for its angles, "dorsiflexion", "radial_deviation"
 *       ...), in place of the rig's (AAOS normal ranges on a baked body):
 *       recorded people exceed the normals; devices keep them. Angles not
 *       given keep the rig's range. Resolved when bound to a rig: an unknown
 *       joint or angle, or a joint without clinical data, is an error naming
 *       the file and key. pose_bridge_apply / pose_bridge_pose_at put them on
 *       every state they pose (pose_set_joint_range); tests and tools call
 *       pb_mapping_apply_ranges.
 * Without "joints" and "channels", clip joints drive rig joints of the same
 * name (pb_mapping_identity).
 */
#ifndef POSE_BRIDGE_MAPPING_H
#define POSE_BRIDGE_MAPPING_H

#include <stdint.h>

#include "handoff.h"
#include "mocap.h"
#include "one_euro.h"
#include "rig_skel.h"
#include "source.h"

typedef enum pb_root_motion { PB_ROOT_NONE = 0, PB_ROOT_HORIZONTAL = 1, PB_ROOT_FULL = 2 } pb_root_motion;

typedef struct pb_map_joint {
    char rig[PB_NAME_MAX];
    char source[PB_NAME_MAX];
    int align;                 /**< -1: mapping default */
    int has_filter;
    pb_one_euro_params filter;
} pb_map_joint;

typedef enum pb_calib_kind { PB_CALIB_NONE = 0, PB_CALIB_TWO_POINT = 1, PB_CALIB_LINEAR = 2 } pb_calib_kind;

typedef struct pb_map_channel {
    char channel[PB_NAME_MAX]; /**< "" when matched by usage */
    uint32_t usage;            /**< HID (page << 16 | usage) when channel is "" */
    int usage_index;           /**< n-th channel with that usage */
    char joint[PB_NAME_MAX];
    int axis;                  /**< rest-frame Euler axis 0 x, 1 y, 2 z; -1: clinical, see dof */
    char dof[32];              /**< clinical angle ("flexion", "abduction", "rotation" or the rig's name for it) */
    pose_euler_order order;
    pb_calib_kind calib;
    double raw[2], deg[2];     /**< two-point */
    double offset, scale;      /**< linear */
    int invert;
    double deadband;
    int has_filter;
    pb_one_euro_params filter;
    int has_limits;
    double limit[2];
} pb_map_channel;

/** A "ranges" entry as written (angle names resolved by pb_mapping_resolve_range). */
typedef struct pb_map_range {
    char joint[PB_NAME_MAX];
    int angle_count;           /**< 1..3 */
    char angle[3][32];         /**< per key: "flexion", "abduction", "rotation" or the rig's name */
    double min_deg[3], max_deg[3];
} pb_map_range;

typedef struct pb_mapping {
    char path[256];
    double axes_q[4];          /**< source frame -> rig frame */
    double up[3];              /**< the rig's up axis (for horizontal root motion) */
    double scale;
    pb_root_motion root_motion;
    int root_from_first_frame; /**< "root_origin": "first_frame" */
    long reference_frame;      /**< -1: zero pose */
    int align;
    int has_filter;
    pb_one_euro_params filter;
    int identity;              /**< map joints by equal names */
    int joint_count;
    pb_map_joint *joints;
    int channel_count;
    pb_map_channel *channels;
    int range_count;
    pb_map_range *ranges;
} pb_mapping;

pose_status pb_mapping_parse(const char *json, size_t size, const char *name, pb_mapping **out, pb_error *err);
pose_status pb_mapping_load(const char *path, pb_mapping **out, pb_error *err);
/** A mapping that drives rig joints from clip joints of the same name. */
pose_status pb_mapping_identity(pb_mapping **out, pb_error *err);
void pb_mapping_free(pb_mapping *m);

/* ---------------------------------------------------------------- ranges */

/** A "ranges" entry bound to a rig: all three angles, the rig's where the
 *  map gives none (an unlimited angle: [-180, 180]). */
typedef struct pb_joint_range {
    int joint;
    float min_deg[3], max_deg[3];
} pb_joint_range;

/** Bind map->ranges[entry] to `rig`. Errors name the map and the key. */
pose_status pb_mapping_resolve_range(const pb_mapping *map, int entry, const pb_rig_skel *rig,
                                     pb_joint_range *out, pb_error *err);
/** Put every "ranges" entry on `state` (a state of the rig `rig` describes). Allocates nothing. */
pose_status pb_mapping_apply_ranges(const pb_mapping *map, const pb_rig_skel *rig, pose_state *state,
                                    pb_error *err);
/** Give `state` the bound range unless it has it already (one read per call
 *  otherwise: cheap enough for every frame). Allocates nothing. */
pose_status pb_joint_range_apply(const pb_joint_range *r, pose_state *state);

/* ------------------------------------------------------------ retargeting */

typedef struct pb_retarget pb_retarget;

/**
 * Bind a mapping to a clip and a rig: resolves names (unknown joints are
 * errors naming the mapping file and entry), computes the clip's reference
 * pose and the per-joint rest alignment.
 */
pose_status pb_retarget_create(const pb_mapping *map, const pb_clip *clip, const pb_rig_skel *rig,
                               pb_retarget **out, pb_error *err);
void pb_retarget_free(pb_retarget *r);
/**
 * Joint targets for clip local transforms (pb_clip_local output) into out
 * (out->joint_count == rig joints). dt_s: time since the previous call, for
 * the filters (<= 0 resets them). Allocates nothing.
 */
void pb_retarget_apply(pb_retarget *r, const double (*lq)[4], const double (*lt)[3], double dt_s, pb_pose *out);
/** Number of rig joints the mapping drives. */
int pb_retarget_mapped_count(const pb_retarget *r);

/* ------------------------------------------------------- scalar channels */

typedef struct pb_chanmap pb_chanmap;

/**
 * Bind the mapping's "channels" to a source's channels (by name, or by HID
 * usage) and to rig joints. Every entry must resolve: an unknown channel or
 * joint is an error naming the mapping file and entry.
 */
pose_status pb_chanmap_create(const pb_mapping *map, const pb_channel *channels, size_t channel_count,
                              const pb_rig_skel *rig, pb_chanmap **out, pb_error *err);
void pb_chanmap_free(pb_chanmap *c);
/** Feed one update (calibrate, invert, deadband, filter, limit); allocates nothing. */
void pb_chanmap_update(pb_chanmap *c, const pb_update *u);
/** Joint targets from the latest values (joints without channels stay inactive). */
void pb_chanmap_pose(const pb_chanmap *c, pb_pose *out);
/** Latest output angle (degrees) of mapping entry i, after all stages. */
double pb_chanmap_value(const pb_chanmap *c, int entry);
/** The calibration/inversion/deadband/limit stages alone (no filter), for tests. */
double pb_map_channel_transform(const pb_map_channel *m, double raw);

#endif /* POSE_BRIDGE_MAPPING_H */
