#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# pose-bridge pose on the CAN rig's log and the synthetic bar (hip, knee and
# ankle of the left leg drive the bar's three joints): JSON with every joint
# per time; the leg is bent at 2 s (seated) and straight at 6 s (standing),
# held at 5.3 s (KNEE_L silent 5.0-5.5 s); a time past the end fails.
#   cli_pose.sh POSE_BRIDGE BAR_RIG SOURCE_DIR SCRATCH
set -euo pipefail
bridge=$1 rig=$2 src=$3 tmp=$4
mkdir -p "$tmp"
log="$src/data/can-rig/sit_stand_arm_raise.log" map="$src/bridge/maps/can_rig_bar.json"
"$bridge" pose "$log" --rig "$rig" --map "$map" --times 2,5.3,6 --json >"$tmp/pose.json"
cat "$tmp/pose.json"
grep -q '^{"source":".*","times":\[{"t":2,"held":false,"clamped":0,"joints":{"joint0":\[0.000000,0.000000,0.000000\],"joint1":\[' "$tmp/pose.json"
grep -q '{"t":5.3,"held":true,"clamped":[0-9]*,' "$tmp/pose.json"
grep -q '{"t":6,"held":false,' "$tmp/pose.json"
# joint3 (the bar's tip) off the bar's axis when seated, on it when standing
tip() { grep -o "{\"t\":$1,[^}]*}" "$tmp/pose.json" | grep -o '"joint3":\[[^]]*\]' | tr -d '"joint3:[]'; }
awk -F, -v a="$(tip 2)" -v b="$(tip 6)" 'BEGIN {
    split(a, p, ","); split(b, q, ",");
    if (!(p[2] > 0.5 || p[2] < -0.5)) { print "seated tip y = " p[2] " (expected bent, |y| > 0.5)"; exit 1 }
    if (!(q[2] < 0.1 && q[2] > -0.1)) { print "standing tip y = " q[2] " (expected straight, |y| < 0.1)"; exit 1 }
}'
# the table: one line per joint
test "$("$bridge" pose "$log" --rig "$rig" --map "$map" --times 2 | grep -c '^  joint')" = 4
# past the end: exit 1, nothing on stdout, the message on stderr
if "$bridge" pose "$log" --rig "$rig" --map "$map" --times 2,99 --json >"$tmp/out.txt" 2>"$tmp/err.txt"; then
    echo "a time past the end succeeded" >&2; exit 1
fi
test ! -s "$tmp/out.txt"
grep -q "99.000 s is past the end of the recording" "$tmp/err.txt"
echo "cli_pose: OK"
