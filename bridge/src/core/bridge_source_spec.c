/* SPDX-License-Identifier: Apache-2.0 */
#include "bridge_source_spec.h"

#include <stdlib.h>
#include <string.h>

#if POSE_BRIDGE_HAVE_DEVICES
#include "can_source.h"
#include "hid_open.h"
#include "usb_hid.h"
#include "usb_source.h"
#endif

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcmp(s + n - m, suffix) == 0;
}

static const char *after_prefix(const char *s, const char *prefix)
{
    size_t n = strlen(prefix);
    return strncmp(s, prefix, n) == 0 ? s + n : NULL;
}

pose_status pb_spec_parse(const char *source, pb_spec *out, pb_error *err)
{
    if (!source || !*source)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pose_bridge_open: empty source string");
    /* Explicit kinds first, so any file name can be given. */
    static const struct {
        const char *prefix;
        pb_spec_kind kind;
    } prefixed[] = {
        {"bvh:", PB_SPEC_BVH},
        {"amc:", PB_SPEC_AMC},
        {"hid-recording:", PB_SPEC_HID_FILE},
        {"candump:", PB_SPEC_CANDUMP},
        {"can:", PB_SPEC_CAN_LIVE},
        {"usbmon:", PB_SPEC_USBMON},
    };
    for (size_t i = 0; i < sizeof prefixed / sizeof prefixed[0]; i++) {
        const char *rest = after_prefix(source, prefixed[i].prefix);
        if (rest) {
            if (!*rest)
                return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "%s: nothing after '%s'", source,
                               prefixed[i].prefix);
            *out = (pb_spec){prefixed[i].kind, rest};
            return POSE_OK;
        }
    }
    /* hid:VID:PID keeps its prefix: the HID opener parses the whole spec. */
    if (after_prefix(source, "hid:") || after_prefix(source, "/dev/hidraw") || after_prefix(source, "hidusb:")) {
        *out = (pb_spec){PB_SPEC_HID_LIVE, source};
        return POSE_OK;
    }
    /* usb:VID:PID... keeps its prefix too (pb_usb_parse_spec). */
    if (after_prefix(source, "usb:")) {
        *out = (pb_spec){PB_SPEC_USB_LIVE, source};
        return POSE_OK;
    }
    static const struct {
        const char *ext;
        pb_spec_kind kind;
    } by_ext[] = {
        {".bvh", PB_SPEC_BVH}, {".BVH", PB_SPEC_BVH}, {".amc", PB_SPEC_AMC}, {".AMC", PB_SPEC_AMC},
        {".hid", PB_SPEC_HID_FILE}, {".log", PB_SPEC_CANDUMP}, {".usbmon", PB_SPEC_USBMON},
    };
    for (size_t i = 0; i < sizeof by_ext / sizeof by_ext[0]; i++) {
        if (ends_with(source, by_ext[i].ext)) {
            *out = (pb_spec){by_ext[i].kind, source};
            return POSE_OK;
        }
    }
    /* A bare word is a network interface name (can0, vcan0, slcan0). */
    if (!strchr(source, '/') && !strchr(source, '.') && !strchr(source, ':') && strlen(source) < 16) {
        *out = (pb_spec){PB_SPEC_CAN_LIVE, source};
        return POSE_OK;
    }
    return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                   "%s: unknown kind of source (expected a .bvh or .amc clip, a .hid hid-recorder file, "
                   "a candump .log, a .usbmon capture, hid:VID:PID, /dev/hidrawN, hidusb:VID:PID, usb:VID:PID, can:IFACE or an "
                   "interface name such as can0, or KIND:PATH with KIND bvh, amc, hid-recording, candump or usbmon)",
                   source);
}

const char *pb_spec_kind_name(pb_spec_kind kind)
{
    switch (kind) {
    case PB_SPEC_BVH: return "bvh";
    case PB_SPEC_AMC: return "asf-amc";
    case PB_SPEC_HID_FILE: return "hid-replay";
    case PB_SPEC_HID_LIVE: return "hid";
    case PB_SPEC_CANDUMP: return "candump-replay";
    case PB_SPEC_CAN_LIVE: return "can";
    case PB_SPEC_USBMON: return "usbmon-replay";
    case PB_SPEC_USB_LIVE: return "usb";
    }
    return "?";
}

#if POSE_BRIDGE_HAVE_DEVICES

static pose_status open_can(const pb_spec *spec, const pb_spec_open_options *o, pb_source **out, pb_error *err)
{
    pb_can_bus *bus = NULL;
    pose_status s = o->map_json ? pb_can_bus_parse(o->map_json, strlen(o->map_json), "map_json", NULL, &bus, err)
                                : pb_can_bus_load(o->map_path, &bus, err);
    if (s < 0)
        return s;
    if (spec->kind == PB_SPEC_CAN_LIVE)
        return pb_can_live_open(spec->target, bus, NULL, out, err);
    pb_candump_replay_options ro = {.as_fast_as_possible = o->as_fast_as_possible, .speed = o->speed, .loop = o->loop};
    return pb_candump_replay_open(spec->target, bus, &ro, out, err);
}

static pose_status open_usb(const pb_spec *spec, const pb_spec_open_options *o, pb_source **out, pb_error *err)
{
    pb_usb_layout *l = malloc(sizeof *l);
    if (!l)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", spec->target);
    pose_status s = o->map_json ? pb_usb_layout_parse(o->map_json, strlen(o->map_json), "map_json", l, err)
                                : pb_usb_layout_load(o->map_path, l, err);
    pb_usb_source_options so = {.stale_ms = o->stale_ms, .hold_channel = l->hold_channel[0] ? l->hold_channel : NULL};
    if (s >= 0 && spec->kind == PB_SPEC_USB_LIVE)
        s = pb_usb_live_open(spec->target, l, &so, out, err);
    else if (s >= 0)
        s = pb_usb_replay_open(spec->target, l,
                               &(pb_usb_replay_options){.source = so, .as_fast_as_possible = o->as_fast_as_possible,
                                                        .speed = o->speed, .loop = o->loop},
                               out, err);
    free(l);
    return s;
}

pose_status pb_spec_open_device(const pb_spec *spec, const pb_spec_open_options *o, pb_source **out, pb_error *err)
{
    *out = NULL;
    if (pb_spec_is_clip(spec->kind))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "%s: a clip is not a device source", spec->target);
    if (!o->map_path && !o->map_json)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                       "%s: a HID, CAN or USB source needs a mapping with \"channels\" (options.map_path or map_json)",
                       spec->target);
    if (spec->kind == PB_SPEC_CAN_LIVE || spec->kind == PB_SPEC_CANDUMP)
        return open_can(spec, o, out, err);
    if (spec->kind == PB_SPEC_USB_LIVE || spec->kind == PB_SPEC_USBMON)
        return open_usb(spec, o, out, err);
    pb_hid_replay_options ho = {.source = {.stale_ms = o->stale_ms}, .speed = o->speed,
                                .as_fast_as_possible = o->as_fast_as_possible, .loop = o->loop};
    if (spec->kind == PB_SPEC_HID_LIVE && after_prefix(spec->target, "hidusb:"))
        return pb_usb_hid_open(spec->target, &ho.source, out, err);
    if (spec->kind == PB_SPEC_HID_LIVE)
        return pb_hid_open(spec->target, &ho, out, err);
    return pb_hid_replay_open(spec->target, &ho, out, err);
}

uint64_t pb_spec_source_drops(pb_source *src)
{
    if (pb_source_is_hid(src)) {
        pb_hid_source_stats s = pb_hid_source_get_stats(src);
        return s.bad_reports + s.unknown_ids;
    }
    if (pb_source_is_usb(src))
        return pb_usb_source_drops(src);
    pb_can_decoder *dec = pb_can_source_decoder(src);
    if (dec) {
        const pb_can_stats *s = pb_can_decoder_stats(dec);
        return s->short_frames + s->dropped + s->bad_lines;
    }
    return 0;
}

#else /* the core-only build has no device backends */

pose_status pb_spec_open_device(const pb_spec *spec, const pb_spec_open_options *o, pb_source **out, pb_error *err)
{
    (void)o;
    *out = NULL;
    return pb_fail(err, POSE_ERR_UNSUPPORTED, "%s: this libpose_bridge was built without the HID and CAN backends",
                   spec->target);
}

uint64_t pb_spec_source_drops(pb_source *src)
{
    (void)src;
    return 0;
}

#endif
