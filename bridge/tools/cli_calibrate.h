/* SPDX-License-Identifier: Apache-2.0
 * hid-calibrate and can-calibrate: one command line over any source. */
#ifndef POSE_BRIDGE_CLI_CALIBRATE_H
#define POSE_BRIDGE_CLI_CALIBRATE_H

#include "pb_error.h"
#include "source.h"

typedef struct pb_cli_calibrate_kind {
    const char *command; /**< "hid-calibrate" */
    const char *sources; /**< what SOURCE may be, for --help */
    /** Open spec for mapping map_path; afap: a recording plays as fast as possible (measuring at --at times). */
    pose_status (*open)(const char *spec, const char *map_path, int afap, pb_source **out, pb_error *err);
} pb_cli_calibrate_kind;

/** The whole subcommand: parse argv, measure, write the mapping; returns the exit status. */
int pb_cli_calibrate(int argc, char **argv, const pb_cli_calibrate_kind *kind);

#endif /* POSE_BRIDGE_CLI_CALIBRATE_H */
