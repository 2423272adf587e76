#!/usr/bin/env bash
# The Windows stage: cross-builds libpose (pose.dll and libpose.a) and its
# tests (tests/windows) with Debian's mingw-w64, and runs the tests under
# wine64. Where the cross compiler or wine is missing it says why and skips
# that part (exit 0); a failed build or test exits non-zero.
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

echo "== windows: cross-build with mingw-w64 ($(x86_64-w64-mingw32-gcc -dumpversion))"
cmake -S "$root" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_TOOLCHAIN_FILE="$root/cmake/mingw-w64-x86_64.cmake" \
  -DCMAKE_CROSSCOMPILING_EMULATOR="$wine" \
  -DPOSE_BUILD_BRIDGE=OFF -DPOSE_BUILD_PREPROCESS=OFF -DPOSE_BUILD_EXAMPLES=OFF \
  -DPOSE_BUILD_BENCH=OFF -DPOSE_BUILD_TESTS=ON >/dev/null
cmake --build "$dir" -j "$jobs" --target sdk/all tests/windows/all
echo "== windows: built $(cd "$dir" && ls sdk/*.dll sdk/*.a | tr '\n' ' ')"
# What pose.dll needs from Windows: its own DLLs and msvcrt, nothing of mingw's.
x86_64-w64-mingw32-objdump -p "$dir/sdk/libpose.dll" | sed -n 's/^\s*DLL Name: /   needs /p'

if [ -z "$wine" ]; then
  echo "== windows: tests SKIPPED: no wine64 to run them (Debian: wine64)"
  exit 0
fi
echo "== windows: tests under $wine"
# A prefix of the build's own; no Mono/Gecko installers, no debug chatter.
export WINEPREFIX="$dir/wine" WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml="
ctest --test-dir "$dir" --output-on-failure -j "$jobs"
