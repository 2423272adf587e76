/* SPDX-License-Identifier: Apache-2.0
 * Where the shipped mappings (the JSON files of bridge/maps) are, so a command that
 * failed for want of --map can say where to find one. */
#ifndef POSE_BRIDGE_CLI_MAPS_H
#define POSE_BRIDGE_CLI_MAPS_H

#include <stddef.h>

/**
 * The folder of the shipped mappings: <prefix>/share/pose/maps beside this
 * executable's <prefix>/bin (an install, wherever it was moved), else the
 * configured install folder, else the source tree's bridge/maps (a build
 * tree). 0, or -1 when none exists.
 */
int pb_cli_maps_dir(char *dir, size_t size);

/**
 * After `source` failed to open without a mapping: on stderr, "hint: ..."
 * naming --map, the maps folder and the mappings whose file name matches
 * the source's kind (hid_*, can_*, cmu*). Nothing for sources that need no map.
 */
void pb_cli_hint_maps(const char *source);

#endif /* POSE_BRIDGE_CLI_MAPS_H */
