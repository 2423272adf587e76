# SPDX-License-Identifier: Apache-2.0
# Imports pose-export's animated session (.glb) into Blender (headless) with
# its own glTF importer and plays it: one armature with the rig's joints,
# the skinned meshes, one action as long as the session; the skin evaluated
# at AT_S seconds lies where pose-export posed it (a static .glb of that frame).
# usage: blender -b --python-exit-code 1 --python check_blender.py -- SESSION.glb MESHES JOINTS SECONDS POSED.glb AT_S MAX_MEAN_M
import sys

import warnings

import numpy as np

with warnings.catch_warnings():  # Debian 12's Blender 3.4 glTF add-on uses np.bool, gone from numpy 1.24
    warnings.simplefilter("ignore")
    if not hasattr(np, "bool"):
        np.bool = bool
import bpy  # noqa: E402

session, meshes, joints, seconds, posed, at_s, max_mean = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=session)
sc = bpy.context.scene
arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
skinned = [o for o in bpy.data.objects if o.type == "MESH"]
acts = list(bpy.data.actions)
if len(arms) != 1 or len(arms[0].data.bones) != int(joints):
    sys.exit(f"check_blender: {len(arms)} armatures, expected 1 with {joints} bones")
if len(skinned) != int(meshes) or not all(o.find_armature() == arms[0] for o in skinned):
    sys.exit(f"check_blender: {len(skinned)} meshes bound to the armature, expected {meshes}")
if len(acts) != 1:
    sys.exit(f"check_blender: {len(acts)} actions, expected 1")
length = (acts[0].frame_range[1] - acts[0].frame_range[0]) / sc.render.fps
if abs(length - float(seconds)) > 0.05:
    sys.exit(f"check_blender: the action lasts {length} s, expected {seconds}")

skin = next(o for o in skinned if o.name == "skin")
rest = [skin.matrix_world @ v.co for v in skin.data.vertices]
sc.frame_set(int(round(float(at_s) * sc.render.fps)))
ev = skin.evaluated_get(bpy.context.evaluated_depsgraph_get())
pos = [ev.matrix_world @ v.co for v in ev.to_mesh().vertices]
before = set(bpy.data.objects)
bpy.ops.import_scene.gltf(filepath=posed)
ref = next(o for o in bpy.data.objects if o not in before and o.type == "MESH" and o.name.startswith("skin"))
refp = [ref.matrix_world @ v.co for v in ref.data.vertices]
if len(refp) != len(pos):
    sys.exit(f"check_blender: {len(pos)} skin vertices, the posed file has {len(refp)}")
d = [(a - b).length for a, b in zip(pos, refp)]
mean, moved = sum(d) / len(d), max((a - b).length for a, b in zip(pos, rest))
print(f"check_blender: {len(skinned)} skinned meshes, {joints} bones, action {length:.3f} s; skin at {at_s} s: "
      f"mean {mean:.6f} m, max {max(d):.6f} m from pose-export (moved {moved:.3f} m)")
if moved < 0.05:
    sys.exit("check_blender: the skin did not move: nothing was compared")
if mean > float(max_mean):
    sys.exit(f"check_blender: Blender poses the skin {mean} m from pose-export on average (limit {max_mean})")
