#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, -DPOSE_FUZZ=ON: ASan + UBSan, undefined
# behaviour aborts) and runs each for MINUTES (default 10), starting from its
# real-file seed corpus. New inputs go to a working corpus per target and
# crashes to a folder per target, both under BUILD/fuzz-runs/<target>/; the seed corpora
# in the tree are left as they are. Prints one line per target (executions,
# crashes) and exits non-zero when any target crashed.
#
#   scripts/fuzz.sh [MINUTES]
#   POSE_FUZZ_BUILD=dir     build folder (default build-fuzz)
#   POSE_FUZZ_PARALLEL=N    targets run at once (default: half the cores, at least 1)
#   POSE_FUZZ_TARGETS="a b" only these targets (fuzz_<name>)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
minutes=${1:-10}
build=${POSE_FUZZ_BUILD:-$root/build-fuzz}
runs=$build/fuzz-runs
parallel=${POSE_FUZZ_PARALLEL:-$(( $(nproc) / 2 > 0 ? $(nproc) / 2 : 1 ))}

CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOSE_FUZZ=ON \
  -DPOSE_BUILD_BENCH=OFF -DPOSE_BUILD_EXAMPLES=OFF >/dev/null
# fuzz_targets.txt: "fuzz_<name> <seed corpus>" per target, written by pose_add_fuzzer.
mapfile -t manifest < "$build/fuzz_targets.txt"
targets=()
for line in "${manifest[@]}"; do
  name=${line%% *}
  if [ -z "${POSE_FUZZ_TARGETS:-}" ] || [[ " $POSE_FUZZ_TARGETS " == *" $name "* ]]; then
    targets+=("$name")
  fi
done
cmake --build "$build" -j "$(nproc)" --target "${targets[@]}"

run_target() { # <name> <seed corpus>: runs one target, leaves its figures in <work>/result
  local name=$1 seeds=$2 work="$runs/$1" bin
  bin=$(find "$build" -path "$runs" -prune -o -type f -name "$name" -perm -u+x -print | head -n 1)
  mkdir -p "$work/corpus" "$work/crashes"
  touch "$work/started" # crashes of earlier runs stay, but are not this run's
  "$bin" -max_total_time=$((minutes * 60)) -print_final_stats=1 \
    -artifact_prefix="$work/crashes/" "$work/corpus" "$seeds" >"$work/log" 2>&1 || true
  local execs crashes
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log" | tail -n 1)
  crashes=$(find "$work/crashes" -type f -newer "$work/started" | wc -l)
  echo "$name: ${execs:-?} executions, $crashes crashes, $minutes min (log $work/log)" >"$work/result"
}

running=0
for line in "${manifest[@]}"; do
  name=${line%% *} seeds=${line#* }
  [[ " ${targets[*]} " == *" $name "* ]] || continue
  rm -f "$runs/$name/result"
  run_target "$name" "$seeds" &
  running=$((running + 1))
  if [ "$running" -ge "$parallel" ]; then
    wait -n
    running=$((running - 1))
  fi
done
wait
status=0
for name in "${targets[@]}"; do
  cat "$runs/$name/result"
  grep -q ", 0 crashes," "$runs/$name/result" || status=1
done
exit $status
