/* SPDX-License-Identifier: Apache-2.0
 * Opening a HID source from one string, as users type it:
 *   "recording.hid"            a hid-recorder file (simulated device)
 *   "/dev/hidraw3"             one hidraw node
 *   "hid:1209:0001"            the first device with these USB IDs (hex)
 *   "hid:1209:0001:0001:0008"  ... and this top-level usage page:usage
 */
#ifndef POSE_BRIDGE_HID_OPEN_H
#define POSE_BRIDGE_HID_OPEN_H

#include "hid_replay.h"

/** Open a source from spec; opt (may be NULL) applies to recordings, opt->source to all. */
pose_status pb_hid_open(const char *spec, const pb_hid_replay_options *opt, pb_source **out, pb_error *err);

/** True when spec names a live device rather than a file. */
int pb_hid_spec_is_live(const char *spec);

#endif /* POSE_BRIDGE_HID_OPEN_H */
