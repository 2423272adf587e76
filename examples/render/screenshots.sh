#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Regenerates the README's screenshots in docs/images/ with pose-render, from
# the rigs the demo makes (bash scripts/demo.sh bakes out/demo/body.rig):
#   bash examples/render/screenshots.sh [BODY_RIG] [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
body=${1:-$root/out/demo/body.rig}
build=${2:-$root/build}
render=$(find "$build" -maxdepth 3 -type f -name pose-render -perm -u+x -print -quit)
synth=$(find "$build" -maxdepth 3 -type f -name pose-synth -perm -u+x -print -quit)
if [ -z "$render" ] || [ -z "$synth" ]; then
    echo "screenshots: build pose-render and pose-synth first" >&2
    exit 1
fi
[ -f "$body" ] || { echo "screenshots: $body not found (run bash scripts/demo.sh first)" >&2; exit 1; }
img="$root/docs/images"
mkdir -p "$img"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
clip="$root/data/mocap/cmu-bvh/131_01.bvh"

"$render" "$body" --size 360x440 --caption "bundled anatomy, rest pose" -o "$img/body_rest.png"
"$render" "$body" --weights knee_r --size 360x440 --caption "weight of knee_r" -o "$img/body_weights_knee.png"
"$render" "$body" --source "$clip" --map "$root/bridge/maps/cmu131_bvh_to_full_body.json" --frames 181 \
    --fit follow --size 360x440 --caption "CMU 131_01 walk" -o "$tmp/walk"
cp "$tmp/walk/frame_00181.png" "$img/body_walk.png"
"$render" "$body" --compare --pose knee_r=0,130,0 --pose hip_r=0,-70,0 --focus knee_r --size 300x360 \
    --caption "knee bend 130 deg" -o "$img/body_compare_knee.png"
"$synth" bar -o "$tmp/bar.rig" >/dev/null
"$render" "$tmp/bar.rig" --compare --pose joint2=135,0,0 --skin opaque --azimuth 90 --elevation 10 \
    --size 300x160 --caption "bar: twist 135 deg" -o "$img/bar_compare_twist.png"
ls -l "$img"
