# SPDX-License-Identifier: Apache-2.0
"""Drive a rig from a BVH clip and save how far its skin moves, per frame, as CSV.

    python3 bvh_displacement.py patient.rig data/mocap/cmu-bvh/131_01.bvh \
        bridge/maps/cmu131_bvh_to_full_body.json skin.csv [SECONDS]
"""
import sys

import pose

rig_path, clip, mapping, out = sys.argv[1:5]
seconds = float(sys.argv[5]) if len(sys.argv) > 5 else 4.0
with pose.Rig(rig_path) as rig, pose.State(rig, method=pose.Method.DQS) as state, \
        pose.Bridge(clip, rig, map_path=mapping, play=pose.Play.MANUAL) as clip_source, open(out, "w") as csv:
    skin = next(t.index for t in rig.tissues if t.kind == pose.TissueKind.SKIN)
    rest = rig.rest_positions(skin)
    csv.write("time_s,max_displacement,mean_displacement\n")
    for frame in range(int(seconds * 30)):
        clip_source.pose_at(frame / 30, state)
        state.apply()
        moved = [sum((p - r) ** 2 for p, r in zip(posed, still)) ** 0.5
                 for posed, still in zip(state.positions(skin).tolist(), rest.tolist())]
        csv.write("%.4f,%.6f,%.6f\n" % (frame / 30, max(moved), sum(moved) / len(moved)))
print("wrote", out)
