# SPDX-License-Identifier: Apache-2.0
"""State: one posed patient made from a Rig, used by one thread at a time."""
import ctypes
import enum

from . import _views
from ._lib import c_float3, c_float4, libpose
from ._types import DynamicsOptions, DynamicsStats, FemCoupling, FemSoftCoupling, FemStats, StateOptions, Transform
from .errors import PoseError, Status, check


class Method(enum.IntEnum):
    LBS = 0
    DQS = 1
    COR = 2
    FEM = 3  # CoR refined to quasi-static co-rotational elasticity (rigs with a fem section)


class EulerOrder(enum.IntEnum):
    XYZ = 0
    XZY = 1
    YXZ = 2
    YZX = 3
    ZXY = 4
    ZYX = 5


class State:
    """pose_state_create_ex: the rig at rest. Setters return True when a joint
    limit clamped the request (pose.last_error() says how) and raise PoseError
    on failure; apply() poses every tissue. Use as a context manager, or close()."""

    def __init__(self, rig, threads=0, method=Method.LBS):
        self._handle = None  # close() works on a half-made object
        options = StateOptions(size=ctypes.sizeof(StateOptions), threads=threads, method=int(method))
        handle = ctypes.c_void_p()
        check(libpose.pose_state_create_ex_sized(rig.handle, ctypes.byref(options), ctypes.byref(handle)))
        self._handle = handle
        self.rig = rig  # a state needs its rig: keep it alive

    @property
    def handle(self):
        if not self._handle:
            raise PoseError(Status.INVALID_ARGUMENT, "the state is closed")
        return self._handle

    def close(self):
        if self._handle:
            libpose.pose_state_free(self._handle)
            self._handle = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    # ---- setting the pose
    def set_joint(self, joint, quat_xyzw):
        return check(libpose.pose_set_joint(self.handle, self.rig.joint_index(joint), c_float4(*quat_xyzw)))

    def get_joint(self, joint):
        q = c_float4()
        check(libpose.pose_get_joint(self.handle, self.rig.joint_index(joint), q))
        return tuple(q)

    def set_joint_euler(self, joint, degrees_xyz, order=EulerOrder.XYZ):
        return check(libpose.pose_set_joint_euler(self.handle, self.rig.joint_index(joint), c_float3(*degrees_xyz),
                                                  int(order)))

    def set_joint_clinical(self, joint, degrees):
        """(flexion, abduction, rotation) in degrees from the neutral posture."""
        return check(libpose.pose_set_joint_clinical(self.handle, self.rig.joint_index(joint), c_float3(*degrees)))

    def get_joint_clinical(self, joint):
        d = c_float3()
        check(libpose.pose_get_joint_clinical(self.handle, self.rig.joint_index(joint), d))
        return tuple(d)

    def set_neutral(self):
        return check(libpose.pose_set_neutral(self.handle))

    def set_root(self, translation=None, quat_xyzw=None):
        t = c_float3(*translation) if translation is not None else None
        q = c_float4(*quat_xyzw) if quat_xyzw is not None else None
        return check(libpose.pose_set_root(self.handle, t, q))

    def reset(self):
        return check(libpose.pose_reset(self.handle))

    @property
    def method(self):
        return Method(libpose.pose_get_method(self.handle))

    @method.setter
    def method(self, method):
        check(libpose.pose_set_method(self.handle, int(method)))

    def set_threads(self, threads):
        """Worker threads for apply() (0: one per core); results are identical for any count."""
        check(libpose.pose_set_threads(self.handle, threads))

    def apply(self):
        """pose_apply: forward kinematics, skinning, every tissue vertex and normal."""
        check(libpose.pose_apply(self.handle))

    def fem_stats(self):
        """What the last apply() with Method.FEM did (pose_fem_stats as a dict)."""
        s = FemStats(size=ctypes.sizeof(FemStats))
        check(libpose.pose_get_fem_stats(self.handle, ctypes.byref(s)))
        return {name: getattr(s, name) for name, _ in FemStats._fields_ if name != "size"}

    # ---- dynamics (rigs with a fem section and massive soft tissue)
    def set_dynamics(self, **options):
        """pose_set_dynamics_options from the defaults, with keyword overrides
        (mass_damping, stiffness_damping, gravity, coupling_stiffness, tolerance,
        cg_iterations)."""
        o = DynamicsOptions()
        libpose.pose_dynamics_defaults(ctypes.byref(o))
        for name, value in options.items():
            if name == "size" or name not in dict(DynamicsOptions._fields_):
                raise TypeError("unknown dynamics option %r" % name)
            setattr(o, name, (ctypes.c_float * 3)(*value) if name == "gravity" else value)
        check(libpose.pose_set_dynamics_options(self.handle, ctypes.byref(o)))

    def step(self, dt):
        """pose_step: advance the soft tissue by dt seconds toward the posed skeleton."""
        check(libpose.pose_step(self.handle, dt))

    def reset_dynamics(self):
        """Restart the simulation at rest in the current skinned pose."""
        check(libpose.pose_reset_dynamics(self.handle))

    def dynamics_stats(self):
        """What the last step() did (pose_dynamics_stats as a dict)."""
        s = DynamicsStats(size=ctypes.sizeof(DynamicsStats))
        check(libpose.pose_get_dynamics_stats(self.handle, ctypes.byref(s)))
        return {name: getattr(s, name) for name, _ in DynamicsStats._fields_ if name != "size"}

    def set_fem_couplings(self, couplings):
        """Replace the state's couplings (pose_set_fem_couplings): (node, joint, stiffness,
        anchor xyz) tuples, each node tied by a zero-length spring to its joint's bone at
        anchor (rest, model space); [] removes them."""
        items = list(couplings)
        array = (FemCoupling * len(items))()
        for c, (node, joint, stiffness, anchor) in zip(array, items):
            c.node, c.joint, c.stiffness, c.anchor = node, joint, stiffness, (ctypes.c_float * 3)(*anchor)
        check(libpose.pose_set_fem_couplings(self.handle, array, len(items), ctypes.sizeof(FemCoupling)))

    def fem_coupling_count(self):
        """How many of the state's couplings are in effect (on nodes the simulation moves)."""
        return libpose.pose_fem_coupling_count(self.handle)

    def set_fem_soft_couplings(self, couplings):
        """Replace the state's soft-soft couplings (pose_set_fem_soft_couplings): (node, others,
        weights, stiffness) tuples, each node tied by a zero-length spring to the point
        sum(weights[c] * x[others[c]]) (up to 4; a node pair: ([b], [1.0])); [] removes them."""
        items = list(couplings)
        array = (FemSoftCoupling * len(items))()
        for c, (node, others, weights, stiffness) in zip(array, items):
            c.node, c.stiffness = node, stiffness
            c.other[:len(others)] = list(others)
            c.weight[:len(weights)] = list(weights)
        check(libpose.pose_set_fem_soft_couplings(self.handle, array, len(items),
                                                  ctypes.sizeof(FemSoftCoupling)))

    def fem_soft_coupling_count(self):
        """How many of the state's soft-soft couplings are in effect (every end moved freely)."""
        return libpose.pose_fem_soft_coupling_count(self.handle)

    # ---- results (views of the state's memory, rewritten by apply())
    def _tissue_array(self, fn, tissue):
        n = ctypes.c_size_t()
        pointer = fn(self.handle, self.rig.tissue_index(tissue), ctypes.byref(n))
        if not pointer:
            raise PoseError(Status.INVALID_ARGUMENT, "no tissue %r" % (tissue,))
        return _views.view(pointer, n.value, 3, ctypes.c_float, self)

    def positions(self, tissue):
        """(vertex_count, 3) float32 posed positions after the last apply(), without a copy."""
        return self._tissue_array(libpose.pose_tissue_positions, tissue)

    def normals(self, tissue):
        return self._tissue_array(libpose.pose_tissue_normals, tissue)

    def tet_positions(self):
        n = ctypes.c_size_t()
        pointer = libpose.pose_tet_positions(self.handle, ctypes.byref(n))
        return _views.view(pointer, n.value, 3, ctypes.c_float, self)

    def joint_world(self, joint):
        """(rotation xyzw, translation) of the joint's frame in model space after apply()."""
        t = Transform()
        check(libpose.pose_joint_world(self.handle, self.rig.joint_index(joint), ctypes.byref(t)))
        return tuple(t.rotation), tuple(t.translation)

    def bounds(self, tissue=-1):
        lo, hi = c_float3(), c_float3()
        index = tissue if tissue == -1 else self.rig.tissue_index(tissue)
        check(libpose.pose_state_bounds(self.handle, index, lo, hi))
        return tuple(lo), tuple(hi)
