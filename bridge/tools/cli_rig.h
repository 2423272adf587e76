/* SPDX-License-Identifier: Apache-2.0
 * The rig a pose-bridge subcommand poses (--rig): a .rig file, or, to check
 * a clip without a baked body, a skeleton-only rig made from a clip's
 * hierarchy in its reference pose ("self": the source clip's own; a .bvh or
 * .asf: that file's), in the clip's length unit, with one token tet (the
 * bridge and FK read only joints). Making the skeleton rig reads the clip
 * with the bridge's internal parser; everything else in replay and pose goes
 * through pose/bridge.h. */
#ifndef POSE_BRIDGE_CLI_RIG_H
#define POSE_BRIDGE_CLI_RIG_H

#include <stddef.h>

#include "pose/pose.h"

/**
 * Load or make the rig named by `arg`; `clip`/`skeleton` are the source and
 * its .asf for "self". On failure returns a status and writes why into err.
 */
pose_status pb_cli_rig_load(const char *arg, const char *clip, const char *skeleton, pose_rig **out, char *err,
                            size_t err_size);

#endif /* POSE_BRIDGE_CLI_RIG_H */
