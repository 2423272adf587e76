# SPDX-License-Identifier: Apache-2.0
"""Rig: a loaded rig file, immutable and shareable across threads."""
import collections
import ctypes
import enum
import os

from . import _views
from ._lib import c_float3, libpose
from ._types import FemCoupling, FemSoftCoupling, JointClinical, JointInfo, LoadOptions, TissueInfo
from .errors import PoseError, Status, check


class TissueKind(enum.IntEnum):
    SKIN = 0
    BONE = 1
    MUSCLE = 2
    ORGAN = 3
    OTHER = 4


Joint = collections.namedtuple("Joint", "index name parent limit_flags limit_min_deg limit_max_deg")
Tissue = collections.namedtuple("Tissue", "index name kind joint vertex_count triangle_count")
Clinical = collections.namedtuple("Clinical", "names neutral axes limit_flags limit_min_deg limit_max_deg")


class Rig:
    """A rig file loaded with pose_rig_load (memory-mapped, every section checked).

    Use as a context manager, or call close(); states made from a rig must be
    closed first."""

    def __init__(self, path, verify_crc=True, no_mmap=False):
        self._handle = None  # close() works on a half-made object
        options = LoadOptions(size=ctypes.sizeof(LoadOptions), flags=(0 if verify_crc else 4) | (1 if no_mmap else 0))
        handle = ctypes.c_void_p()
        check(libpose.pose_rig_load_ex_sized(os.fsencode(path), ctypes.byref(options), ctypes.byref(handle)))
        self._handle = handle
        self.path = path

    @property
    def handle(self):
        if not self._handle:
            raise PoseError(Status.INVALID_ARGUMENT, "the rig is closed")
        return self._handle

    def close(self):
        if self._handle:
            libpose.pose_rig_free(self._handle)
            self._handle = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    # ---- joints
    @property
    def joint_count(self):
        return libpose.pose_rig_joint_count(self.handle)

    def joint_index(self, joint):
        """A joint given by index or name, as an index; PoseError(NOT_FOUND) for an unknown name."""
        if isinstance(joint, str):
            index = libpose.pose_rig_find_joint(self.handle, joint.encode())
            if index < 0:
                raise PoseError(Status.NOT_FOUND, "the rig has no joint '%s'" % joint)
            return index
        return int(joint)

    def joint(self, joint):
        index = self.joint_index(joint)
        info = JointInfo()
        check(libpose.pose_rig_joint_info(self.handle, index, ctypes.byref(info)))
        return Joint(index, info.name.decode(), info.parent, info.limit_flags, tuple(info.limit_min_deg),
                     tuple(info.limit_max_deg))

    @property
    def joints(self):
        return [self.joint(j) for j in range(self.joint_count)]

    def clinical(self, joint):
        """The joint's neutral posture, clinical axes and range; PoseError(UNSUPPORTED) without them."""
        c = JointClinical()
        check(libpose.pose_rig_joint_clinical(self.handle, self.joint_index(joint), ctypes.byref(c)))
        return Clinical(tuple(n.decode() for n in c.names), tuple(c.neutral), tuple(tuple(a) for a in c.axes),
                        c.limit_flags, tuple(c.limit_min_deg), tuple(c.limit_max_deg))

    # ---- tissues
    @property
    def tissue_count(self):
        return libpose.pose_rig_tissue_count(self.handle)

    def tissue_index(self, tissue):
        if isinstance(tissue, str):
            index = libpose.pose_rig_find_tissue(self.handle, tissue.encode())
            if index < 0:
                raise PoseError(Status.NOT_FOUND, "the rig has no tissue '%s'" % tissue)
            return index
        return int(tissue)

    def _tissue_info(self, tissue):
        info = TissueInfo()
        check(libpose.pose_rig_tissue_info(self.handle, self.tissue_index(tissue), ctypes.byref(info)))
        return info

    def tissue(self, tissue):
        info = self._tissue_info(tissue)
        return Tissue(self.tissue_index(tissue), info.name.decode(), TissueKind(info.kind), info.joint,
                      info.vertex_count, info.triangle_count)

    @property
    def tissues(self):
        return [self.tissue(t) for t in range(self.tissue_count)]

    def rest_positions(self, tissue):
        """(vertex_count, 3) float32 rest positions, a view of the rig's memory."""
        info = self._tissue_info(tissue)
        return _views.view(info.rest_positions, info.vertex_count, 3, ctypes.c_float, self)

    def triangles(self, tissue):
        """(triangle_count, 3) uint32 vertex indices, a view of the rig's memory."""
        info = self._tissue_info(tissue)
        return _views.view(info.triangles, info.triangle_count, 3, ctypes.c_uint32, self)

    def bounds(self, tissue=-1):
        """((xmin, ymin, zmin), (xmax, ymax, zmax)) at rest, of one tissue or (-1) of all."""
        lo, hi = c_float3(), c_float3()
        check(libpose.pose_rig_bounds(self.handle, tissue if tissue == -1 else self.tissue_index(tissue), lo, hi))
        return tuple(lo), tuple(hi)

    @property
    def has_fem(self):
        """Whether the rig has what Method.FEM and State.step() need (its fem section)."""
        return bool(libpose.pose_rig_has_fem(self.handle))

    def fem_nodes_near(self, joint, reach):
        """Simulation nodes (tet vertex indices) within reach (rig units) of the rest surface of
        the joint's bone tissues, ascending (pose_rig_fem_nodes_near_joint)."""
        j, count = self.joint_index(joint), ctypes.c_size_t()
        check(libpose.pose_rig_fem_nodes_near_joint(self.handle, j, reach, None, 0, ctypes.byref(count)))
        nodes = (ctypes.c_uint32 * count.value)()
        check(libpose.pose_rig_fem_nodes_near_joint(self.handle, j, reach, nodes, count.value, ctypes.byref(count)))
        return list(nodes)

    def fem_couplings(self):
        """The rig's couplings (its `couplings` section) as (node, joint, stiffness, anchor) tuples."""
        n = libpose.pose_rig_fem_couplings(self.handle, None, 0)
        out = (FemCoupling * n)()
        libpose.pose_rig_fem_couplings(self.handle, out, n)
        return [(c.node, c.joint, c.stiffness, tuple(c.anchor)) for c in out]

    def fem_soft_couplings(self):
        """The rig's soft-soft couplings (its `soft_couplings` section) as (node, others, weights,
        stiffness) tuples, others and weights 4 each."""
        size = ctypes.sizeof(FemSoftCoupling)
        n = libpose.pose_rig_fem_soft_couplings(self.handle, None, 0, size)
        out = (FemSoftCoupling * n)()
        libpose.pose_rig_fem_soft_couplings(self.handle, out, n, size)
        return [(c.node, tuple(c.other), tuple(c.weight), c.stiffness) for c in out]

    @property
    def metadata(self):
        return libpose.pose_rig_metadata(self.handle).decode(errors="replace")

    @property
    def format_version(self):
        """The rig file format version this rig was loaded from."""
        return libpose.pose_rig_format_version(self.handle)
