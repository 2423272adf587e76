#!/usr/bin/env bash
# The Windows stage: cross-builds libpose (pose.dll and libpose.a), its tests
# (tests/windows) and the bridge's core and file sources (libpose_bridge.a)
# with Debian's mingw-w64, and runs the tests under wine64. Where the cross
# compiler or wine is missing it says why and skips that part (exit 0); a
# failed build or test exits non-zero.
#   scripts/windows.sh [build folder]        (default: build-windows)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=${1:-$root/build-windows}
jobs=${JOBS:-$(nproc)}

if ! command -v x86_64-w64-mingw32-gcc >/dev/null; then
  echo "== windows: SKIPPED: no x86_64-w64-mingw32-gcc (Debian: gcc-mingw-w64-x86-64-win32)"
  exit 0
fi
wine=""
for w in wine64 /usr/lib/wine/wine64; do
  if command -v "$w" >/dev/null; then
    wine=$(command -v "$w")
    break
  fi
done

# cJSON for the bridge: a mingw-w64 build of it when there is one (pkg-config
# in the mingw prefix); Debian ships none, so otherwise the bridge compiles
# against the host's cJSON header (plain C) into libpose_bridge.a alone: the
# program that links it brings cJSON, and pose_bridge.dll, pose-bridge.exe and
# the bridge's tests are not built.
mingw_pc=/usr/x86_64-w64-mingw32/lib/pkgconfig
bridge_targets=()
if PKG_CONFIG_LIBDIR=$mingw_pc pkg-config --exists libcjson; then
  export PKG_CONFIG_LIBDIR=$mingw_pc
  bridge_targets=(bridge/all)
  bridge_note="bridge: core + mocap file sources, DLL and static (mingw-w64 cJSON found)"
elif [ -f /usr/include/cjson/cJSON.h ]; then
  mkdir -p "$dir/cjson-header/cjson" "$dir/pkgconfig"
  cp /usr/include/cjson/cJSON.h "$dir/cjson-header/cjson/"
  printf 'Name: libcjson\nDescription: the cJSON header only (no mingw-w64 cJSON)\nVersion: 1\nCflags: -I%s\nLibs: -lcjson\n' \
    "$dir/cjson-header" >"$dir/pkgconfig/libcjson.pc"
  export PKG_CONFIG_LIBDIR="$dir/pkgconfig:$mingw_pc"
  bridge_targets=(pose_bridge_static)
  bridge_note="bridge: core + mocap file sources compiled into libpose_bridge.a only: Debian has no mingw-w64 cJSON, so pose_bridge.dll, pose-bridge.exe and the bridge tests are not built (the program linking libpose_bridge.a brings cJSON)"
else
  bridge_note="bridge: SKIPPED: no cJSON header (Debian: libcjson-dev) and no mingw-w64 cJSON"
fi

echo "== windows: cross-build with mingw-w64 ($(x86_64-w64-mingw32-gcc -dumpversion))"
cmake -S "$root" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_TOOLCHAIN_FILE="$root/cmake/mingw-w64-x86_64.cmake" \
  -DCMAKE_CROSSCOMPILING_EMULATOR="$wine" \
  -DPOSE_BUILD_BRIDGE=$([ ${#bridge_targets[@]} -gt 0 ] && echo ON || echo OFF) -DPOSE_BRIDGE_CORE_ONLY=ON \
  -DPOSE_BUILD_PREPROCESS=OFF -DPOSE_BUILD_EXAMPLES=OFF \
  -DPOSE_BUILD_BENCH=OFF -DPOSE_BUILD_TESTS=ON >/dev/null
cmake --build "$dir" -j "$jobs" --target sdk/all tests/windows/all "${bridge_targets[@]}"
echo "== windows: $bridge_note"
echo "== windows: built $(cd "$dir" && ls sdk/*.dll sdk/*.a bridge/*.dll bridge/*.a 2>/dev/null | tr '\n' ' ')"
# What pose.dll needs from Windows: its own DLLs and msvcrt, nothing of mingw's.
x86_64-w64-mingw32-objdump -p "$dir/sdk/libpose.dll" | sed -n 's/^\s*DLL Name: /   needs /p'

if [ -z "$wine" ]; then
  echo "== windows: tests SKIPPED: no wine64 to run them (Debian: wine64)"
  exit 0
fi
echo "== windows: tests under $wine"
# A prefix of the build's own; no Mono/Gecko installers, no debug chatter.
export WINEPREFIX="$dir/wine" WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml="
# Make the prefix before the tests run in parallel: two wine processes that
# both find no prefix race to create it, and one of them fails.
"$wine" wineboot --init >/dev/null 2>&1 || true
ctest --test-dir "$dir" --output-on-failure -j "$jobs"
