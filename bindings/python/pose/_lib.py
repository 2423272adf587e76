# SPDX-License-Identifier: Apache-2.0
"""Finding libpose and libpose_bridge, and their C declarations (ctypes).

Search order, for each library: the folders in $POSE_LIBRARY_PATH (os.pathsep
separated: a build tree's sdk/ and bridge/, or an install's lib/); the lib
folder of the prefix this package was installed into by `cmake --install`
(_install.py, written at install); the build/ tree beside this source
checkout; then the system's search (ldconfig, /usr/local/lib).
"""
import ctypes
import ctypes.util
import os

from ._types import (BridgeFrame, BridgeOptions, BridgeStatus, DynamicsOptions, DynamicsStats, FemCoupling,
                     FemSoftCoupling, FemStats, JointClinical, JointInfo, LoadOptions, StateOptions, TissueInfo, TetInfo, Transform)

_here = os.path.dirname(os.path.abspath(__file__))


def _folders():
    env = os.environ.get("POSE_LIBRARY_PATH", "")
    folders = [f for f in env.split(os.pathsep) if f]
    try:
        from . import _install  # written by cmake --install only
        folders.append(os.path.normpath(os.path.join(_here, _install.LIBDIR_FROM_PACKAGE)))
    except ImportError:
        pass
    source_build = os.path.normpath(os.path.join(_here, "..", "..", "..", "build"))
    folders += [os.path.join(source_build, "sdk"), os.path.join(source_build, "bridge")]
    return folders


def _load(name):
    """Load lib<name>.so; OSError naming every place looked at when it is nowhere."""
    file = "lib%s.so" % name
    tried = []
    for folder in _folders():
        path = os.path.join(folder, file)
        tried.append(path)
        if os.path.exists(path):
            return ctypes.CDLL(path)
    found = ctypes.util.find_library(name)
    for path in ([found] if found else []) + ["/usr/local/lib/" + file]:
        tried.append(path)
        try:
            return ctypes.CDLL(path)
        except OSError:
            pass
    raise OSError("%s not found (set POSE_LIBRARY_PATH to the folder that holds it); looked at: %s"
                  % (file, ", ".join(tried)))


P = ctypes.POINTER
c_float3 = ctypes.c_float * 3
c_float4 = ctypes.c_float * 4
_rig, _state, _bridge = ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p


def _declare(lib, table):
    for name, restype, argtypes in table:
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = restype, argtypes


_int, _size, _status, _str = ctypes.c_int, ctypes.c_size_t, ctypes.c_int, ctypes.c_char_p

libpose = _load("pose")
_declare(libpose, [
    ("pose_version_string", _str, []),
    ("pose_last_error", _str, []),
    ("pose_status_string", _str, [_int]),
    ("pose_rig_format_version", ctypes.c_uint32, [_rig]),
    ("pose_rig_load_ex_sized", _status, [_str, P(LoadOptions), P(_rig)]),
    ("pose_rig_free", None, [_rig]),
    ("pose_rig_joint_count", _size, [_rig]),
    ("pose_rig_find_joint", _int, [_rig, _str]),
    ("pose_rig_joint_info", _status, [_rig, _int, P(JointInfo)]),
    ("pose_rig_tissue_count", _size, [_rig]),
    ("pose_rig_find_tissue", _int, [_rig, _str]),
    ("pose_rig_tissue_info", _status, [_rig, _int, P(TissueInfo)]),
    ("pose_rig_tet_info", _status, [_rig, P(TetInfo)]),
    ("pose_rig_metadata", _str, [_rig]),
    ("pose_rig_joint_clinical", _status, [_rig, _int, P(JointClinical)]),
    ("pose_rig_bounds", _status, [_rig, _int, c_float3, c_float3]),
    ("pose_state_create_ex_sized", _status, [_rig, P(StateOptions), P(_state)]),
    ("pose_state_free", None, [_state]),
    ("pose_set_joint", _status, [_state, _int, c_float4]),
    ("pose_set_joint_euler", _status, [_state, _int, c_float3, _int]),
    ("pose_set_joint_clinical", _status, [_state, _int, c_float3]),
    ("pose_get_joint_clinical", _status, [_state, _int, c_float3]),
    ("pose_get_joint", _status, [_state, _int, c_float4]),
    ("pose_set_neutral", _status, [_state]),
    ("pose_set_root", _status, [_state, P(ctypes.c_float), P(ctypes.c_float)]),
    ("pose_reset", _status, [_state]),
    ("pose_set_method", _status, [_state, _int]),
    ("pose_get_method", _int, [_state]),
    ("pose_set_threads", _status, [_state, _int]),
    ("pose_apply", _status, [_state]),
    ("pose_tissue_positions", P(ctypes.c_float), [_state, _int, P(_size)]),
    ("pose_tissue_normals", P(ctypes.c_float), [_state, _int, P(_size)]),
    ("pose_tet_positions", P(ctypes.c_float), [_state, P(_size)]),
    ("pose_joint_world", _status, [_state, _int, P(Transform)]),
    ("pose_state_bounds", _status, [_state, _int, c_float3, c_float3]),
    ("pose_rig_has_fem", _int, [_rig]),
    ("pose_get_fem_stats", _status, [_state, P(FemStats)]),
    ("pose_dynamics_defaults", None, [P(DynamicsOptions)]),
    ("pose_set_dynamics_options", _status, [_state, P(DynamicsOptions)]),
    ("pose_step", _status, [_state, ctypes.c_double]),
    ("pose_reset_dynamics", _status, [_state]),
    ("pose_get_dynamics_stats", _status, [_state, P(DynamicsStats)]),
    ("pose_rig_fem_couplings", _size, [_rig, P(FemCoupling), _size]),
    ("pose_rig_fem_nodes_near_joint", _status, [_rig, _int, ctypes.c_float, P(ctypes.c_uint32), _size, P(_size)]),
    ("pose_set_fem_couplings", _status, [_state, P(FemCoupling), _size, _size]),
    ("pose_fem_coupling_count", _size, [_state]),
    ("pose_rig_fem_soft_couplings", _size, [_rig, P(FemSoftCoupling), _size, _size]),
    ("pose_set_fem_soft_couplings", _status, [_state, P(FemSoftCoupling), _size, _size]),
    ("pose_fem_soft_coupling_count", _size, [_state]),
])

_libbridge = None


def libbridge():
    """libpose_bridge, loaded on first use (a host without devices never needs it)."""
    global _libbridge
    if _libbridge is None:
        lib = _load("pose_bridge")
        _declare(lib, [
            ("pose_bridge_open", _status, [_str, _rig, P(BridgeOptions), P(_bridge)]),
            ("pose_bridge_close", None, [_bridge]),
            ("pose_bridge_apply", _status, [_bridge, _state, P(BridgeFrame)]),
            ("pose_bridge_pose_at", _status, [_bridge, ctypes.c_double, _state, P(BridgeFrame)]),
            ("pose_bridge_status_get", _status, [_bridge, P(BridgeStatus)]),
            ("pose_bridge_pause", _status, [_bridge, _int]),
            ("pose_bridge_seek", _status, [_bridge, ctypes.c_double]),
            ("pose_bridge_wait", _int, [_bridge, _int]),
            ("pose_bridge_warning_count", _size, [_bridge]),
            ("pose_bridge_warning", _str, [_bridge, _size]),
            ("pose_bridge_state_name", _str, [_int]),
        ])
        _libbridge = lib
    return _libbridge
