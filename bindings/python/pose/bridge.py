# SPDX-License-Identifier: Apache-2.0
"""Bridge: drive a State from a device or a recording (pose/bridge.h)."""
import collections
import ctypes
import enum
import os

from ._lib import libbridge
from ._types import BridgeFrame, BridgeOptions, BridgeStatus
from .errors import check


class Play(enum.IntEnum):
    REALTIME = 0
    AS_FAST_AS_POSSIBLE = 1
    MANUAL = 2  # no thread: the host picks times with pose_at()


Frame = collections.namedtuple("Frame", "fresh held clamped joints media_s age_s seq")


def _frame(f):
    return Frame(bool(f.fresh), bool(f.held), f.clamped, f.joints, f.media_s, f.age_s, f.seq)


def _path(p):
    return os.fsencode(p) if p is not None else None


class Bridge:
    """pose_bridge_open(source, rig, options): a source string as pose/bridge.h
    names them (a .bvh/.amc clip, a .hid or candump .log recording,
    hid:VID:PID, can0 ...). Options are pose_bridge_options' fields by name
    (map_path, map_json, skeleton, play, speed, loop, start_s, end_s,
    max_poses, start_paused, rate_hz, stale_after_s, rt_priority,
    record_path). Use as a context manager, or close()."""

    def __init__(self, source, rig, **options):
        self._handle = None  # close() works on a half-made object
        o = BridgeOptions(size=ctypes.sizeof(BridgeOptions))
        for name, value in options.items():
            if name not in dict(BridgeOptions._fields_) or name in ("size", "allocator"):
                raise TypeError("unknown bridge option '%s'" % name)
            if name in ("map_path", "map_json", "skeleton", "record_path"):
                value = _path(value) if name != "map_json" else value.encode()
            elif name == "play":
                value = int(value)
            setattr(o, name, value)
        self._lib = libbridge()
        handle = ctypes.c_void_p()
        check(self._lib.pose_bridge_open(_path(source), rig.handle, ctypes.byref(o), ctypes.byref(handle)))
        self._handle = handle
        self.rig = rig

    def close(self):
        if self._handle:
            self._lib.pose_bridge_close(self._handle)
            self._handle = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    def apply(self, state):
        """The newest pose onto state (never blocks); a Frame. The host's pose_apply is state.apply()."""
        f = BridgeFrame()
        check(self._lib.pose_bridge_apply(self._handle, state.handle, ctypes.byref(f)))
        return _frame(f)

    def pose_at(self, t_s, state):
        """Recorded sources: state set to the pose at recorded time t_s; a Frame."""
        f = BridgeFrame()
        check(self._lib.pose_bridge_pose_at(self._handle, t_s, state.handle, ctypes.byref(f)))
        return _frame(f)

    def status(self):
        """pose_bridge_status as a dict (state named: "ok", "stale", "ended" ...)."""
        s = BridgeStatus(size=ctypes.sizeof(BridgeStatus))
        check(self._lib.pose_bridge_status_get(self._handle, ctypes.byref(s)))
        out = {name: getattr(s, name) for name, _ in BridgeStatus._fields_ if name != "size"}
        out["state"] = self._lib.pose_bridge_state_name(s.state).decode()
        out["kind"] = s.kind.decode() if s.kind else None
        out["fault"] = s.fault.decode(errors="replace")
        return out

    def pause(self, paused=True):
        check(self._lib.pose_bridge_pause(self._handle, int(paused)))

    def seek(self, t_s):
        check(self._lib.pose_bridge_seek(self._handle, t_s))

    def wait(self, timeout_ms=-1):
        """True when the bridge thread has ended (a recording's end, end_s, max_poses)."""
        return self._lib.pose_bridge_wait(self._handle, timeout_ms) == 1

    @property
    def warnings(self):
        return [self._lib.pose_bridge_warning(self._handle, i).decode(errors="replace")
                for i in range(self._lib.pose_bridge_warning_count(self._handle))]
