#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The install rules, proven by a third party: install pose into a temporary
# prefix, build examples/embed against it with find_package(pose) and with
# the Makefile (pkg-config), build the README quickstart with pkg-config, and
# run all three on the synthetic bar. When the bridge was installed, also
# build examples/embed/bridge_host both ways and drive a state for 100 frames
# from the HID mannequin recording (on BODY_RIG, a body baked from the
# full-body template, else on the bar), and check that libpose_bridge.so
# exports pose_bridge_* only.
#   embed_install.sh BUILD_DIR SOURCE_DIR POSE_SYNTH SCRATCH [BODY_RIG]
set -euo pipefail
build=$1 src=$2 synth=$3 tmp=$4 body=${5:-}
rm -rf "$tmp/prefix" "$tmp/embed-cmake" "$tmp/embed-make" "$tmp/out"
mkdir -p "$tmp/embed-make" "$tmp/out/cmake" "$tmp/out/make"

cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log"
test -f "$tmp/prefix/include/pose/pose.h"
"$synth" bar -o "$tmp/bar.rig" >/dev/null

# 1. CMake: find_package(pose) from the prefix only.
cmake -S "$src/examples/embed" -B "$tmp/embed-cmake" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
    -DCMAKE_BUILD_TYPE=Release >"$tmp/embed-cmake.log"
cmake --build "$tmp/embed-cmake" >>"$tmp/embed-cmake.log"
"$tmp/embed-cmake/embed" "$tmp/bar.rig" "$tmp/out/cmake" 60 20 | tee "$tmp/run-cmake.log"
grep -q "wrote 3 OBJ files" "$tmp/run-cmake.log"
# The executable uses the installed shared library, not the build tree's.
ldd "$tmp/embed-cmake/embed" >"$tmp/ldd.log"
grep -q "$tmp/prefix/.*libpose.so" "$tmp/ldd.log"

# 2. Makefile: pkg-config from the prefix, PKG_CONFIG_PATH on make's command line as the
# README writes it (not in the environment). --define-prefix makes pose.pc answer for where
# it lies, since it was installed with --prefix after configure.
multiarch=$(gcc -print-multiarch 2>/dev/null || true)
pc_path="$tmp/prefix/lib/pkgconfig:$tmp/prefix/lib/$multiarch/pkgconfig"
unset PKG_CONFIG_PATH
make -s -C "$src/examples/embed" OUT="$tmp/embed-make" PKG_CONFIG="pkg-config --define-prefix" \
    PKG_CONFIG_PATH="$pc_path" CFLAGS="-O2 -Wall -Wextra -Werror"
export PKG_CONFIG_PATH="$pc_path"
"$tmp/embed-make/embed" "$tmp/bar.rig" "$tmp/out/make" 60 10 | tee "$tmp/run-make.log"
grep -q "wrote 6 OBJ files" "$tmp/run-make.log"

# The OBJ files of both builds hold the same posed skin at frame 20.
cmp "$tmp/out/cmake/skin_0020.obj" "$tmp/out/make/skin_0020.obj"
# ... and frame 20 is not the rest pose (frame 0).
if cmp -s "$tmp/out/cmake/skin_0000.obj" "$tmp/out/cmake/skin_0020.obj"; then
    echo "embed_install: frame 20 equals frame 0: the joint did not move the skin" >&2
    exit 1
fi

# 3. The README quickstart, built and run by its own Build: and Run: lines, word for word
# (the README's custom-prefix section gives the same Build: line), with no LD_LIBRARY_PATH:
# the rpath finds the prefix's libpose.so.
qs="$src/examples/quickstart/quickstart.c"
build_line=$(sed -n 's/^ \* Build: //p' "$qs")
run_line=$(sed -n 's/^ \* Run: *//p' "$qs" | sed 's/ \[JOINT\] \*\/$//; s/patient\.rig/bar.rig/')
grep -qF -- "$build_line" "$src/README.md" ||
    { echo "embed_install: README's build-by-hand section lacks the quickstart's Build: line" >&2; exit 1; }
rm -rf "$tmp/qs" && mkdir -p "$tmp/qs" && cp "$qs" "$tmp/bar.rig" "$tmp/qs/"
(cd "$tmp/qs" && unset LD_LIBRARY_PATH && eval "$build_line -Wall -Wextra -Werror" &&
    eval "$run_line") | tee "$tmp/run-quickstart.log"
grep -q "moved up to" "$tmp/run-quickstart.log"

# 4. The bridge, when installed: pose::bridge (CMake) and pose_bridge.pc (pkg-config).
if [ -f "$tmp/prefix/include/pose/bridge.h" ]; then
    test -x "$tmp/embed-cmake/bridge_host"
    # The installed headers are self-contained: each compiles alone, strictly.
    for h in pose/pose.h pose/bridge.h; do
        printf '#include <%s>\nint main(void) { return 0; }\n' "$h" >"$tmp/alone.c"
        cc -std=c11 -Wall -Wextra -Werror -pedantic -I"$tmp/prefix/include" -c "$tmp/alone.c" -o "$tmp/alone.o"
    done
    if [ -n "$body" ] && [ -f "$body" ]; then
        rig=$body map="$src/bridge/maps/hid_mannequin_full_body.json"
    else
        rig="$tmp/bar.rig" map="$src/bridge/maps/hid_mannequin_bar.json"
    fi
    hid="$src/data/hid/mannequin_sit_to_stand.hid"
    "$tmp/embed-cmake/bridge_host" "$rig" "$hid" "$map" 100 | tee "$tmp/run-bridge-cmake.log"
    grep -q "in 100 frames" "$tmp/run-bridge-cmake.log"
    # (through a file: under pipefail, grep -q leaving early can fail the pipe with SIGPIPE)
    ldd "$tmp/embed-cmake/bridge_host" >"$tmp/ldd-bridge.log"
    grep -q "$tmp/prefix/.*libpose_bridge.so" "$tmp/ldd-bridge.log"
    make -s -C "$src/examples/embed" OUT="$tmp/embed-make" PKG_CONFIG="pkg-config --define-prefix" \
        CFLAGS="-O2 -Wall -Wextra -Werror" bridge_host
    "$tmp/embed-make/bridge_host" "$rig" "$hid" "$map" 100 | tee "$tmp/run-bridge-make.log"
    grep -q "in 100 frames" "$tmp/run-bridge-make.log"
    # The shared library exports the public API and nothing else.
    lib=$(find "$tmp/prefix" -name 'libpose_bridge.so' | head -n 1)
    nm -D --defined-only "$lib" | awk '{print $3}' >"$tmp/bridge-symbols.txt"
    grep -q '^pose_bridge_open$' "$tmp/bridge-symbols.txt"
    if grep -v '^pose_bridge_' "$tmp/bridge-symbols.txt"; then
        echo "embed_install: libpose_bridge.so exports symbols outside pose/bridge.h (above)" >&2
        exit 1
    fi
fi
# 5. The installed tools run from the prefix; pose-bridge replay without --map points at the
# installed mappings; the installed Python package finds the prefix's libpose by itself.
"$tmp/prefix/bin/pose-synth" --help >/dev/null
if [ -x "$tmp/prefix/bin/pose-bridge" ]; then
    if "$tmp/prefix/bin/pose-bridge" replay "$src/data/hid/mannequin_sit_to_stand.hid" --rig "$tmp/bar.rig" \
        2>"$tmp/replay-nomap.log"; then
        echo "embed_install: replay of a HID recording without --map succeeded" >&2
        exit 1
    fi
    grep -q "hint: .*--map.* $tmp/prefix/bin/../share/pose/maps: .*hid_mannequin_bar.json" "$tmp/replay-nomap.log" ||
        { cat "$tmp/replay-nomap.log" >&2; echo "embed_install: no hint at the installed maps" >&2; exit 1; }
    test -f "$tmp/prefix/share/pose/maps/hid_mannequin_full_body.json"
fi
py=$(command -v /usr/bin/python3 || command -v python3 || true)
if [ -n "$py" ]; then
    site=$(find "$tmp/prefix" -type d -name site-packages | head -n 1)
    env -u POSE_LIBRARY_PATH PYTHONPATH="$site" PYTHONDONTWRITEBYTECODE=1 "$py" -c \
        "import pose, sys; rig = pose.Rig(sys.argv[1]); print('python:', rig.joint_count, 'joints', pose.__file__)" \
        "$tmp/bar.rig" | tee "$tmp/python.log"
    grep -q "python: 4 joints $tmp/prefix/" "$tmp/python.log"
fi
test -f "$tmp/prefix/share/pose/csharp/Pose.cs"
echo "embed_install: OK"
