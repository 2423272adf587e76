/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge hid-calibrate: calibration of a mapping's entries from a HID
 * device or hid-recorder file (tools/cli_calibrate.c). */
#include "cli_calibrate.h"
#include "hid_open.h"
#include "pose_bridge_cli.h"

static pose_status open_hid(const char *spec, const char *map_path, int afap, pb_source **out, pb_error *err)
{
    (void)map_path;
    pb_hid_replay_options opt = {.as_fast_as_possible = afap};
    return pb_hid_open(spec, &opt, out, err);
}

static int run(int argc, char **argv)
{
    static const pb_cli_calibrate_kind kind = {"hid-calibrate", "a hid-recorder file, /dev/hidrawN or hid:VID:PID[:SERIAL]",
                                               open_hid};
    return pb_cli_calibrate(argc, argv, &kind);
}

const pb_command pb_cmd_hid_calibrate = {"hid-calibrate", "calibrate a mapping's entries from a HID source", run};
