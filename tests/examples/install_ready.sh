#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `cmake --install build` after scripts/demo.sh: the demo builds only the
# target pose_install_ready, so that target must bring every file the install
# rules copy from the build tree (a library or tool missing from it makes the
# install fail after the demo). Checked on the build graph (Ninja), so no
# second build is needed; exit 77 (skipped) with another generator.
#   install_ready.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 src=$2
grep -q -- '--target pose_install_ready' "$src/scripts/demo.sh" ||
    { echo "install_ready: scripts/demo.sh does not build pose_install_ready" >&2; exit 1; }
if [ ! -f "$build/build.ninja" ]; then
    echo "install_ready: skipped: needs the Ninja generator (ninja -t query)"
    exit 77
fi
# What the target depends on: its direct inputs (query) and everything below them (inputs).
inputs=$(cd "$build" && { ninja -t query pose_install_ready | sed -n 's/^    //p'; ninja -t inputs pose_install_ready; })
# Built files the install scripts copy (generated at configure time: exports, .pc, _install.py).
installed=$(grep -rhoE 'FILES "[^"]*"' --include=cmake_install.cmake "$build" | sed -E 's/^FILES "//; s/"$//' |
    grep "^$build/" | grep -vE '/CMakeFiles/|\.pc$|\.py$|\.cmake$' | sort -u)
[ -n "$installed" ] || { echo "install_ready: found no installed build files" >&2; exit 1; }
missing=0
for f in $installed; do
    rel=${f#"$build"/}
    if ! grep -qxF -- "$rel" <<<"$inputs"; then
        echo "install_ready: $rel is installed but pose_install_ready does not build it (cmake/PoseInstall.cmake)" >&2
        missing=1
    fi
done
[ $missing -eq 0 ] && echo "install_ready: pose_install_ready builds all $(wc -l <<<"$installed") installed files"
exit $missing
