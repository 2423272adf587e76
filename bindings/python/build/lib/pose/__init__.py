# SPDX-License-Identifier: Apache-2.0
"""pose: put a virtual patient's whole anatomy into any pose, from Python.

    import pose
    with pose.Rig("patient.rig") as rig, pose.State(rig, method=pose.Method.DQS) as state:
        state.set_joint_euler("knee_r", (0, 90, 0))
        state.apply()
        skin = state.positions("skin")   # (n, 3) float32, no copy (numpy when installed)

A thin layer over libpose's C ABI (ctypes, standard library only): failures
raise PoseError carrying pose_last_error(); Bridge (pose/bridge.h) drives a
state from a clip, a recording or a device.
"""
from ._lib import libpose
from .bridge import Bridge, Frame, Play
from .errors import PoseError, Status, last_error
from .rig import Rig, TissueKind
from .state import EulerOrder, Method, State

__version__ = libpose.pose_version_string().decode()
RIG_FORMAT_VERSION = libpose.pose_rig_format_version(None)

__all__ = ["Bridge", "EulerOrder", "Frame", "Method", "Play", "PoseError", "RIG_FORMAT_VERSION", "Rig", "State",
           "Status", "TissueKind", "last_error"]
