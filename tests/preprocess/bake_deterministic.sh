#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# pose-bake is deterministic: the coarse body baked with every thread pool
# it may use at 1 thread, then at 4 (pose-bake --threads for mapping and
# centres of rotation, OMP_NUM_THREADS for CHOLMOD, OPENBLAS_NUM_THREADS for
# its BLAS), gives the same rig, byte for byte (same input paths, so the
# provenance metadata is the same too).
# usage: bake_deterministic.sh POSE_BAKE SOURCE_DIR TMP
set -euo pipefail
bake=$1 src=$2 tmp=$3
rm -rf "$tmp"
mkdir -p "$tmp"
args=(--skin "$src/data/anatomy/skin.obj" --bones "$src/data/anatomy/bones"
      --template "$src/preprocess/templates/full_body.json" --target-vertices 8000 --quiet)
for n in 1 4; do
  OMP_NUM_THREADS=$n OPENBLAS_NUM_THREADS=$n GOTO_NUM_THREADS=$n \
    "$bake" "${args[@]}" --threads "$n" --report "$tmp/threads$n.json" -o "$tmp/threads$n.rig" >/dev/null
done
ls -l "$tmp"/*.rig
if ! cmp "$tmp/threads1.rig" "$tmp/threads4.rig"; then
  echo "bake_deterministic: the rigs differ (first differing bytes, offset and octal values):"
  cmp -l "$tmp/threads1.rig" "$tmp/threads4.rig" | head -5
  exit 1
fi
# Both ran the threaded stages (a rig without CoR would leave them out).
python3 -c 'import json, sys; sys.exit(0 if json.load(open(sys.argv[1]))["cor"]["computed"] else 1)' \
  "$tmp/threads4.json" || { echo "bake_deterministic: no CoR in the report"; exit 1; }
echo "bake_deterministic: 1 and 4 threads give the same $(stat -c %s "$tmp/threads1.rig") bytes"
