#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# pose-export's session outputs, read back by the tools they are for.
#   gltf: a 4 s replay of a CMU walk (01_01, 120 Hz, every 12th frame) as an
#         animated .glb, loaded by three.js's GLTFLoader under node (npm
#         `three`, pinned by tests/examples/gltf/package-lock.json, installed
#         with npm ci into TMP once): its skinned meshes, joints, clip length,
#         and the skin posed by three.js at 2 s against pose-export's own pose
#         of frame 240 (LBS both).
#   blender: the same replay imported by Blender's glTF importer (headless):
#         one armature, the meshes bound to it, the action's length, the skin
#         at 2 s against frame 240. Blender is not in scripts/deps (large).
#   pvd:  a ParaView series of the same replay's first second, every frame
#         read back with meshio (python3-meshio) with the expected counts,
#         and one pose's --surfaces file.
#   args: what the session options refuse, each named.
# Exits 77 (skipped, with the reason) when node/npm, blender or meshio is missing.
# usage: export_session.sh gltf|blender|pvd|args POSE_EXPORT RIG SOURCE_DIR TMP
set -euo pipefail
kind=$1 export_bin=$2 rig=$3 src=$4 tmp=$5
clip="$src/data/mocap/cmu-bvh/01_01.bvh"
map="$src/bridge/maps/cmu_cgspeed_bvh_to_full_body.json"
mkdir -p "$tmp"
rm -rf "$tmp/$kind"
mkdir -p "$tmp/$kind"
json() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$@"; }
# The 4 s walk as an animated glTF, and pose-export's own pose of its frame 240 (2 s), both LBS.
walk() {
  "$export_bin" "$rig" --method lbs --source "$clip" --map "$map" --frames 0-480:12 \
    --gltf-anim "$tmp/$kind/walk.glb" --json >"$tmp/$kind/session.json"
  "$export_bin" "$rig" --method lbs --source "$clip" --map "$map" --frame 240 \
    --glb "$tmp/$kind/frame240.glb" --json >"$tmp/$kind/frame.json"
  cat "$tmp/$kind/session.json"
  [ "$(json "$tmp/$kind/session.json" frames)" = 41 ] || { echo "expected 41 frames"; exit 1; }
  meshes=$(json "$tmp/$kind/session.json" skinned_meshes)
  [ "$meshes" -gt 1 ] || { echo "expected skin and bones, got $meshes skinned meshes"; exit 1; }
  ls -l "$tmp/$kind/walk.glb" "$tmp/$kind/frame240.glb"
}

case $kind in
gltf)
  if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
    echo "export_session gltf: skipped: node and npm are needed to run three.js's GLTFLoader"
    exit 77
  fi
  node_dir="$tmp/node"
  if [ ! -f "$node_dir/node_modules/three/package.json" ] ||
     ! cmp -s "$src/tests/examples/gltf/package-lock.json" "$node_dir/package-lock.json"; then
    rm -rf "$node_dir"
    mkdir -p "$node_dir"
    cp "$src/tests/examples/gltf/package.json" "$src/tests/examples/gltf/package-lock.json" "$node_dir/"
    if ! (cd "$node_dir" && timeout 120 npm ci --no-audit --no-fund --loglevel=error >npm.log 2>&1); then
      echo "export_session gltf: skipped: npm ci could not install three (no registry?):"
      tail -5 "$node_dir/npm.log"
      rm -rf "$node_dir/node_modules"
      exit 77
    fi
  fi
  cp "$src/tests/examples/gltf/check_glb.mjs" "$node_dir/"
  walk
  # 19 joints in the full-body template; mean skin distance within 5 mm of pose-export's pose
  node "$node_dir/check_glb.mjs" "$tmp/gltf/walk.glb" "$meshes" 19 4.0 "$tmp/gltf/frame240.glb" 2.0 skin 0.005
  ;;
blender)
  if ! command -v blender >/dev/null; then
    echo "export_session blender: skipped: blender is not installed (apt-get install --no-install-recommends blender)"
    exit 77
  fi
  walk
  rc=0
  timeout 200 blender -b --factory-startup --python-exit-code 1 --python "$src/tests/examples/gltf/check_blender.py" -- \
    "$tmp/blender/walk.glb" "$meshes" 19 4.0 "$tmp/blender/frame240.glb" 2.0 0.005 >"$tmp/blender/blender.log" 2>&1 || rc=$?
  grep -v '^Read \|^$' "$tmp/blender/blender.log" | tail -n 20
  [ "$rc" = 0 ] || { echo "export_session blender: the check failed (blender exit $rc)"; exit 1; }
  ;;
pvd)
  py=""
  for p in /usr/bin/python3 python3; do # Debian's python3 first: python3-meshio is its
    if "$p" -c "import meshio" 2>/dev/null; then py=$p; break; fi
  done
  if [ -z "$py" ]; then
    echo "export_session pvd: skipped: python3-meshio is not installed"
    exit 77
  fi
  "$export_bin" "$rig" --source "$clip" --map "$map" --frames 0-120:30 \
    --pvd "$tmp/pvd/walk.pvd" --json >"$tmp/pvd/session.json"
  cat "$tmp/pvd/session.json"
  ls -l "$tmp/pvd"
  "$py" "$src/tests/examples/check_pvd.py" "$tmp/pvd/walk.pvd" 5 \
    "$(json "$tmp/pvd/session.json" tissue_vertices)" "$(json "$tmp/pvd/session.json" tissue_triangles)"
  # one pose: the same surfaces in one file
  "$export_bin" "$rig" --pose knee_r=0,60,0 --surfaces "$tmp/pvd/knee.vtu" >/dev/null
  "$py" - "$tmp/pvd/knee.vtu" "$(json "$tmp/pvd/session.json" tissue_vertices)" <<'PY'
import sys, meshio
m = meshio.read(sys.argv[1])
assert m.points.shape == (int(sys.argv[2]), 3), m.points.shape
assert abs(m.point_data["displacement"]).max() > 0.05, "the knee did not move"
print(f"{sys.argv[1]}: {m.points.shape[0]} points, tissues {int(m.cell_data['tissue'][0].max()) + 1}")
PY
  ;;
args)
  # refused: each line is an argument list and the message it must give (exit 2)
  while IFS='|' read -r args want; do
    out=$("$export_bin" "$rig" $args 2>&1) && { echo "accepted: $args"; exit 1; }
    case $out in *"$want"*) ;; *) echo "pose-export $args: expected '$want', got: $out"; exit 1 ;; esac
  done <<EOT
--frames 0-10:5 --pvd $tmp/args/x.pvd|need --source
--source $clip --frames 0-10:5 --obj $tmp/args/x.obj|the other outputs hold one pose
--source $clip --frame 3 --pvd $tmp/args/x.pvd|give --source with --frames or --times
--source $clip --frames 0-10:5 --times 0-1:0.5 --pvd $tmp/args/x.pvd|one of --frame, --frames, --times
--source $clip --frames 10-0:5 --pvd $tmp/args/x.pvd|--frames
--source $clip --map $map --frames 0-99999:5000 --gltf-anim $tmp/args/x.glb|out of range
--source $clip --map $map --frames 0-10:5 --pvd $tmp/args/missing/x.pvd|cannot create
EOT
  echo "export_session args: 7 refusals, each named"
  ;;
*)
  echo "usage: $0 gltf|blender|pvd|args POSE_EXPORT RIG SOURCE_DIR TMP" >&2
  exit 2
  ;;
esac
