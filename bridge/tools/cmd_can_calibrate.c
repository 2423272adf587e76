/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge can-calibrate: calibration of a mapping's entries from a CAN
 * interface or candump log, decoded with the mapping's "can" bus description
 * (tools/cli_calibrate.c). */
#include <string.h>

#include "can_bus.h"
#include "can_source.h"
#include "cli_calibrate.h"
#include "pose_bridge_cli.h"

static pose_status open_can(const char *spec, const char *map_path, int afap, pb_source **out, pb_error *err)
{
    pb_can_bus *bus = NULL;
    pose_status st = pb_can_bus_load(map_path, &bus, err);
    if (st != POSE_OK)
        return st;
    size_t n = strlen(spec);
    if (n > 4 && strcmp(spec + n - 4, ".log") == 0)
        return pb_candump_replay_open(spec, bus, &(pb_candump_replay_options){.as_fast_as_possible = afap}, out, err);
    return pb_can_live_open(strncmp(spec, "can:", 4) == 0 ? spec + 4 : spec, bus, NULL, out, err);
}

static int run(int argc, char **argv)
{
    static const pb_cli_calibrate_kind kind = {"can-calibrate", "a candump -l log, or a CAN interface (can0, can:vcan0)",
                                               open_can};
    return pb_cli_calibrate(argc, argv, &kind);
}

const pb_command pb_cmd_can_calibrate = {"can-calibrate", "calibrate a mapping's entries from a CAN bus or log", run};
