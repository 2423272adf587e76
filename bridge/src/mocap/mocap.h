/* SPDX-License-Identifier: Apache-2.0
 * Motion clips: a joint hierarchy with channels, and frames of channel
 * values. BVH and Acclaim ASF/AMC both load into a pb_clip so forward
 * kinematics, replay, retargeting and recording share one representation.
 *
 * A joint's local transform is
 *     T(offset + position channels) * C * R(rotation channels) * C^-1
 * where C is the joint's axis frame (ASF `axis`; identity for BVH) and R
 * composes the rotation channels in file order: intrinsically for BVH
 * ("Zrotation Xrotation Yrotation" is Rz*Rx*Ry) and extrinsically for ASF
 * ("dof rx ry rz" applies rx first: Rz*Ry*Rx). Offsets are in the parent's
 * frame and the file's length unit; angles are stored in degrees.
 */
#ifndef POSE_BRIDGE_MOCAP_H
#define POSE_BRIDGE_MOCAP_H

#include <stddef.h>
#include <stdint.h>

#include "pb_error.h"

enum { PB_MAX_JOINTS = 4096, PB_NAME_MAX = 64 };

/** Channel values beyond +-this are warned about (pb_warn) and kept: no joint
 *  turns a million degrees and no capture volume is a million length units
 *  (a kilometre in mm) across, so such a value is corrupt data, and FK turns
 *  it into a pose without meaning. */
#define PB_MOCAP_VALUE_MAX 1e6

typedef enum pb_chan_kind {
    PB_CH_XPOS = 0, PB_CH_YPOS = 1, PB_CH_ZPOS = 2,
    PB_CH_XROT = 3, PB_CH_YROT = 4, PB_CH_ZROT = 5,
    PB_CH_LENGTH = 6, /**< ASF `l`: parsed, carried, not applied */
} pb_chan_kind;

typedef struct pb_clip_joint {
    char name[PB_NAME_MAX];
    int parent;          /**< -1 for the root; parents precede children */
    int is_end;          /**< an end site (BVH End Site, tip of an ASF leaf bone) */
    double offset[3];    /**< from the parent's origin, in the parent's frame */
    double axis_q[4];    /**< C: the joint's axis frame (identity for BVH) */
    int extrinsic;       /**< 1: rotation channels compose first-listed-first (ASF) */
    int chan_first;      /**< index of its first channel in a frame */
    int chan_count;      /**< 0..7 */
    uint8_t chan[7];     /**< pb_chan_kind per channel, in file order */
    int has_limits;      /**< ASF limits present */
    double limit_min[7], limit_max[7]; /**< degrees / length units, per channel */
} pb_clip_joint;

typedef struct pb_clip {
    char format[16];       /**< "bvh" or "asf-amc" */
    char path[256];        /**< where it was loaded from (for messages) */
    int joint_count;
    pb_clip_joint *joints;
    int channel_count;     /**< values per frame */
    size_t frame_count;
    double frame_time;     /**< seconds per frame (> 0) */
    double *frames;        /**< frame_count * channel_count; angles in degrees */
    double length_unit;    /**< ASF :units length (informative), 1 for BVH */
} pb_clip;

/** Parse BVH text (need not be NUL-terminated past size; a copy is made). */
pose_status pb_bvh_parse(const char *text, size_t size, const char *name, pb_clip **out, pb_error *err);
/** Load a BVH file. */
pose_status pb_bvh_load(const char *path, pb_clip **out, pb_error *err);

/** Parse ASF text into a clip with no frames (frame_time 1/120 s). */
pose_status pb_asf_parse(const char *text, size_t size, const char *name, pb_clip **out, pb_error *err);
pose_status pb_asf_load(const char *path, pb_clip **out, pb_error *err);
/** Parse AMC text into the frames of a clip made by pb_asf_*; replaces its frames. */
pose_status pb_amc_parse(pb_clip *clip, const char *text, size_t size, const char *name, pb_error *err);
pose_status pb_amc_load(pb_clip *clip, const char *path, pb_error *err);

/**
 * Load by extension: .bvh, .asf (no frames), or .amc with `skeleton` naming
 * its .asf (NULL: the CMU-style sibling "<subject>.asf" of "<subject>_<take>.amc").
 */
pose_status pb_clip_load(const char *path, const char *skeleton, pb_clip **out, pb_error *err);

/** Free a clip; NULL is a no-op. */
void pb_clip_free(pb_clip *clip);
/** Index of the joint with this exact name, or -1. */
int pb_clip_find_joint(const pb_clip *clip, const char *name);
/** Frame f's values (f < frame_count); NULL for a clip without channels (its reference pose). */
static inline const double *pb_clip_frame(const pb_clip *clip, size_t f)
{
    /* A clip without channels (BVH "CHANNELS 0" everywhere) has no frame
     * storage: frames is NULL, and NULL + 0 is undefined behaviour. */
    if (!clip->frames)
        return NULL;
    return clip->frames + f * (size_t)clip->channel_count;
}

/**
 * Local transforms of every joint for one frame of channel values (NULL:
 * all channels zero, the hierarchy's reference pose): rotation q[j] and
 * translation t[j] relative to the parent.
 */
void pb_clip_local(const pb_clip *clip, const double *values, double (*q)[4], double (*t)[3]);
/** World rotations and positions from local transforms (parents first). */
void pb_clip_world(const pb_clip *clip, const double (*lq)[4], const double (*lt)[3],
                   double (*wq)[4], double (*wp)[3]);
/** pb_clip_local then pb_clip_world; scratch needs 7 doubles per joint. */
void pb_clip_fk(const pb_clip *clip, const double *values, double *scratch,
                double (*wq)[4], double (*wp)[3]);

/** Allocate an empty clip (all zero, identity axes) with room for `joints`. */
pb_clip *pb_clip_alloc(int joints);

#endif /* POSE_BRIDGE_MOCAP_H */
