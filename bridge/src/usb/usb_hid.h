/* SPDX-License-Identifier: Apache-2.0
 *
 * HID devices without a hidraw node, through hidapi's libusb backend
 * (usb_hid.c): "hidusb:VID:PID[:INTERFACE]" (hex ids, decimal interface
 * number; default the first HID interface). The same HID source as hidraw
 * devices (hid_source.h): descriptor, decoding, states, reopening.
 *
 * Which to use: "hid:VID:PID" (hidraw) whenever the kernel's usbhid driver
 * is bound to the device, the normal case (no root, no detaching, other
 * programs keep working); "hidusb:" when there is no hidraw node: usbhid
 * detached or blacklisted, a container without /dev/hidraw but with
 * /dev/bus/usb, or a device usbhid refuses. hidapi's libusb backend detaches
 * a bound kernel driver itself, so on a normal desktop "hidusb:" takes the
 * device away from the kernel until it is closed.
 */
#ifndef POSE_BRIDGE_USB_HID_H
#define POSE_BRIDGE_USB_HID_H

#include "hid_source.h"

/**
 * Open as a HID source. POSE_ERR_NOT_FOUND when no such device is plugged
 * in, POSE_ERR_UNSUPPORTED without libusb/hidapi at build time or without
 * libhidapi-libusb0 at run time, POSE_ERR_INVALID_ARGUMENT for a bad spec.
 */
pose_status pb_usb_hid_open(const char *spec, const pb_hid_source_options *opt, pb_source **out, pb_error *err);

#endif /* POSE_BRIDGE_USB_HID_H */
