# SPDX-License-Identifier: Apache-2.0
"""The C structs of pose/pose.h and pose/bridge.h, field for field (ctypes)."""
import ctypes

_f3, _f4 = ctypes.c_float * 3, ctypes.c_float * 4


class Allocator(ctypes.Structure):
    _fields_ = [("alloc", ctypes.c_void_p), ("free", ctypes.c_void_p), ("user", ctypes.c_void_p)]


class LoadOptions(ctypes.Structure):
    _fields_ = [("size", ctypes.c_size_t), ("allocator", Allocator), ("flags", ctypes.c_uint32)]


class StateOptions(ctypes.Structure):
    _fields_ = [("size", ctypes.c_size_t), ("allocator", Allocator), ("threads", ctypes.c_int),
                ("method", ctypes.c_int)]


class Transform(ctypes.Structure):
    _fields_ = [("rotation", _f4), ("translation", _f3)]


class JointInfo(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("parent", ctypes.c_int), ("rest_model", Transform),
                ("rest_local", Transform), ("limit_flags", ctypes.c_uint32), ("limit_order", ctypes.c_int),
                ("limit_min_deg", _f3), ("limit_max_deg", _f3)]


class TissueInfo(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("kind", ctypes.c_int), ("joint", ctypes.c_int),
                ("vertex_count", ctypes.c_size_t), ("triangle_count", ctypes.c_size_t),
                ("rest_positions", ctypes.POINTER(ctypes.c_float)),
                ("triangles", ctypes.POINTER(ctypes.c_uint32))]


class TetInfo(ctypes.Structure):
    _fields_ = [("vertex_count", ctypes.c_size_t), ("tet_count", ctypes.c_size_t),
                ("rest_positions", ctypes.POINTER(ctypes.c_float)), ("tets", ctypes.POINTER(ctypes.c_uint32)),
                ("labels", ctypes.POINTER(ctypes.c_uint16)), ("influences", ctypes.c_uint),
                ("weight_joints", ctypes.POINTER(ctypes.c_uint16)), ("weights", ctypes.POINTER(ctypes.c_float)),
                ("cor", ctypes.POINTER(ctypes.c_float))]


class JointClinical(ctypes.Structure):
    _fields_ = [("neutral", _f4), ("axes", _f3 * 3), ("names", ctypes.c_char_p * 3),
                ("limit_flags", ctypes.c_uint32), ("limit_min_deg", _f3), ("limit_max_deg", _f3),
                ("flags", ctypes.c_uint32)]


class BridgeOptions(ctypes.Structure):
    _fields_ = [("size", ctypes.c_size_t), ("map_path", ctypes.c_char_p), ("map_json", ctypes.c_char_p),
                ("skeleton", ctypes.c_char_p), ("play", ctypes.c_int), ("speed", ctypes.c_double),
                ("loop", ctypes.c_int), ("start_s", ctypes.c_double), ("end_s", ctypes.c_double),
                ("max_poses", ctypes.c_long), ("start_paused", ctypes.c_int), ("rate_hz", ctypes.c_double),
                ("stale_after_s", ctypes.c_double), ("rt_priority", ctypes.c_int),
                ("record_path", ctypes.c_char_p), ("allocator", Allocator)]


class BridgeFrame(ctypes.Structure):
    _fields_ = [("fresh", ctypes.c_int), ("held", ctypes.c_int), ("clamped", ctypes.c_int),
                ("joints", ctypes.c_int), ("media_s", ctypes.c_double), ("age_s", ctypes.c_double),
                ("seq", ctypes.c_uint64)]


class BridgeStatus(ctypes.Structure):
    _fields_ = [("size", ctypes.c_size_t), ("state", ctypes.c_int), ("connected", ctypes.c_int),
                ("kind", ctypes.c_char_p), ("samples", ctypes.c_uint64), ("drops", ctypes.c_uint64),
                ("poses", ctypes.c_uint64), ("last_sample_age_s", ctypes.c_double), ("media_s", ctypes.c_double),
                ("duration_s", ctypes.c_double), ("lag_p50_ms", ctypes.c_double), ("lag_p99_ms", ctypes.c_double),
                ("lag_max_ms", ctypes.c_double), ("realtime", ctypes.c_int), ("frame", ctypes.c_long),
                ("frame_count", ctypes.c_long), ("frame_time_s", ctypes.c_double), ("fault", ctypes.c_char * 256)]


class FemStats(ctypes.Structure):
    _fields_ = [("size", ctypes.c_size_t), ("outer_iterations", ctypes.c_int), ("cg_iterations", ctypes.c_int),
                ("residual", ctypes.c_double), ("seconds_skin", ctypes.c_double),
                ("seconds_rotations", ctypes.c_double), ("seconds_cg", ctypes.c_double),
                ("seconds_transfer", ctypes.c_double)]


class DynamicsOptions(ctypes.Structure):
    _fields_ = [("size", ctypes.c_size_t), ("mass_damping", ctypes.c_float), ("stiffness_damping", ctypes.c_float),
                ("gravity", _f3), ("coupling_stiffness", ctypes.c_float), ("tolerance", ctypes.c_float),
                ("cg_iterations", ctypes.c_int)]


class DynamicsStats(ctypes.Structure):
    _fields_ = [("size", ctypes.c_size_t), ("islands", ctypes.c_int), ("cg_iterations", ctypes.c_int),
                ("residual", ctypes.c_double), ("kinetic_energy", ctypes.c_double), ("time", ctypes.c_double),
                ("seconds_skin", ctypes.c_double), ("seconds_assembly", ctypes.c_double),
                ("seconds_cg", ctypes.c_double), ("seconds_transfer", ctypes.c_double),
                ("contacts", ctypes.c_int), ("contact_iterations", ctypes.c_int),
                ("max_impulse", ctypes.c_double), ("seconds_contact", ctypes.c_double)]


class FemCoupling(ctypes.Structure):
    _fields_ = [("node", ctypes.c_uint32), ("joint", ctypes.c_int), ("stiffness", ctypes.c_float),
                ("anchor", _f3)]


class FemSoftCoupling(ctypes.Structure):
    _fields_ = [("node", ctypes.c_uint32), ("other", ctypes.c_uint32 * 4), ("weight", ctypes.c_float * 4),
                ("stiffness", ctypes.c_float)]
