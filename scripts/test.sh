#!/usr/bin/env bash
# Installs dependencies, builds pose from scratch and runs the whole test
# suite: a normal build with gcc, then the suite again built with clang under
# ASan+UBSan, then the threaded tests (the examples' included) under TSan,
# then libpose cross-built for Windows with its tests run under wine64
# (scripts/windows.sh: it says why it skips where mingw-w64 or wine is missing).
# Warnings are errors in every build, so both compilers are checked. Exits non-zero on any failure.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc)
bash "$root/scripts/install-deps.sh"

run_suite() { # <build dir> <label filter or ""> <cmake args...>
  local dir=$1 filter=$2; shift 2
  CC=${CC:-cc} CXX=${CXX:-c++} cmake -S "$root" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOSE_BUILD_BENCH=OFF "$@" >/dev/null
  cmake --build "$dir" -j "$jobs"
  if [ -n "$filter" ]; then
    ctest --test-dir "$dir" --output-on-failure -j "$jobs" -L "$filter"
  else
    ctest --test-dir "$dir" --output-on-failure -j "$jobs"
  fi
}

echo "== build (gcc, RelWithDebInfo, with benchmarks) and test"
run_suite "$root/build" "" -DPOSE_BUILD_BENCH=ON   # benchmarks are built (not run) so they keep compiling
echo "== build with clang and test under ASan+UBSan"
CC=clang CXX=clang++ run_suite "$root/build-asan" "" -DPOSE_SANITIZE=ON -DPOSE_BUILD_BENCH=ON   # clang compiles the benchmarks too
echo "== threaded tests under TSan (the examples' threads too)"
run_suite "$root/build-tsan" "threads" -DPOSE_TSAN=ON
echo "== Windows: libpose cross-built with mingw-w64, its tests under wine64"
bash "$root/scripts/windows.sh" "$root/build-windows"
