#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Reads a ParaView series (.pvd) pose-export wrote back with meshio, frame
by frame, and checks each has the expected points and triangles, unit
normals, and that the frames differ (the pose moved).
usage: check_pvd.py SERIES.pvd FRAMES POINTS TRIANGLES
Exits 77 (skipped) when meshio is absent (Debian: python3-meshio)."""
import json
import os
import sys
import xml.etree.ElementTree as ET

try:
    import meshio
    import numpy as np
except ImportError as e:
    print(f"check_pvd: skipped: {e} (apt-get install python3-meshio)")
    sys.exit(77)


def main():
    pvd, frames, points, triangles = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
    sets = ET.parse(pvd).getroot().findall("./Collection/DataSet")
    if len(sets) != frames:
        sys.exit(f"check_pvd: {len(sets)} frames in {pvd}, expected {frames}")
    times = [float(d.get("timestep")) for d in sets]
    if any(b <= a for a, b in zip(times, times[1:])):
        sys.exit(f"check_pvd: times do not increase: {times}")
    first = None
    moved = []
    for d in sets:
        path = os.path.join(os.path.dirname(pvd), d.get("file"))
        m = meshio.read(path)
        tri = m.get_cells_type("triangle")
        if m.points.shape != (points, 3) or tri.shape != (triangles, 3):
            sys.exit(f"check_pvd: {path}: {m.points.shape[0]} points and {tri.shape[0]} triangles, "
                     f"expected {points} and {triangles}")
        n = np.linalg.norm(m.point_data["Normals"], axis=1)
        if np.mean(np.abs(n - 1.0) < 1e-3) < 0.99:
            sys.exit(f"check_pvd: {path}: normals are not unit length")
        if tri.max() >= points or tri.min() < 0:
            sys.exit(f"check_pvd: {path}: a triangle names a point out of range")
        if first is None:
            first = m.points
        moved.append(float(np.max(np.linalg.norm(m.points - first, axis=1))))
    if max(moved) < 0.05:
        sys.exit(f"check_pvd: the frames hardly differ (at most {max(moved)} m)")
    print(json.dumps({"frames": len(sets), "points": points, "triangles": triangles,
                      "times": [times[0], times[-1]], "max_moved_m": max(moved)}))


if __name__ == "__main__":
    main()
