#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The C# bindings under Debian's mono: compile bindings/csharp/Pose.cs with the
# console sample (mcs, warnings as errors), run it, and compare every tissue's
# positions with the C API's (pose_positions) byte for byte, check that its
# couplings are read back and removed; a missing rig is
# a PoseException naming the file. Exit 77 (skipped) where mono is missing.
#   csharp_sample.sh POSE_POSITIONS SOURCE_DIR SCRATCH LIBDIRS RIG [CLIP MAP TIME]
set -euo pipefail
helper=$1 src=$2 tmp=$3 libdirs=$4; shift 4
for tool in mcs mono; do
    if ! command -v "$tool" >/dev/null; then
        echo "csharp_sample: skipped: '$tool' not found (apt-get install mono-mcs mono-runtime; scripts/install-deps.sh installs them)"
        exit 77
    fi
done
mcs -nologo -warnaserror -out:"$tmp/sample.exe" "$src/bindings/csharp/Pose.cs" "$src/bindings/csharp/examples/Sample.cs"
export LD_LIBRARY_PATH="$libdirs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
mono "$tmp/sample.exe" "$1" "$tmp/csharp.bin" "${@:2}" | tee "$tmp/sample.log"
grep -q "format 1; .* bent" "$tmp/sample.log"
grep -Eq "^dynamics: (6 steps, 0\.0500 s simulated, [1-9][0-9]* islands|unsupported)" "$tmp/sample.log"
grep -Eq "^(couplings: 8 of [0-9]+ nodes near .*, 8 in effect, 0 after removal|dynamics: unsupported)" "$tmp/sample.log"
grep -Eq "^(soft couplings: 1 in effect, 0 after removal|dynamics: unsupported)" "$tmp/sample.log"
"$helper" "$1" "$tmp/c.bin" "${@:2}"
cmp "$tmp/csharp.bin" "$tmp/c.bin"
if mono "$tmp/sample.exe" "$tmp/missing.rig" "$tmp/x.bin" 2>"$tmp/err.log"; then
    echo "csharp_sample: a missing rig did not fail" >&2
    exit 1
fi
grep -q "IO: file '$tmp/missing.rig': cannot open" "$tmp/err.log"
echo "csharp_sample: OK (positions equal the C API's, $(stat -c %s "$tmp/c.bin") bytes)"
