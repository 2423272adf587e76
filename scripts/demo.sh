#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
#
# The main job: from a fresh checkout to pictures of a posed patient.
#   1. installs the Debian packages (scripts/install-deps.sh; needs root)
#   2. configures and builds pose in Release into build/
#   3. bakes the bundled anatomy (data/anatomy) into a rig at reduced
#      resolution with pose-bake
#   4. replays a bundled CMU walk (data/mocap/cmu-bvh/131_01.bvh) onto it
#      through the input bridge (pose-bridge)
#   5. renders frames to PNG (pose-render, off-screen) into out/demo/
#   6. renders the recorded devices of the same demo (a HID mannequin's
#      hid-recorder file, a CAN goniometer rig's candump log) at a few
#      recorded times into out/demo/hid/ and out/demo/can/
# With --view and a display, it then opens pose-view on the same rig and clip.
# Where a stage is missing from this checkout, the script says so and shows
# the same chain on the synthetic bar instead; it never pretends.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/out/demo"
build="$root/build"
jobs=$(nproc 2>/dev/null || echo 2)
view=0
deps=1
clip="$root/data/mocap/cmu-bvh/131_01.bvh"
# Reduced resolution for the demo's bake: ~15 k tet vertices, well under two minutes on 2 cores.
BAKE_ARGS=${BAKE_ARGS:---target-vertices 15000}

usage() {
    cat <<EOF
usage: bash scripts/demo.sh [--view] [--no-deps] [--out DIR] [--build DIR] [--jobs N]
Install dependencies, build, bake the bundled anatomy, replay a CMU walk
onto it and render PNG frames (headless), then frames of a HID mannequin
recording and a CAN rig log. Results go to out/demo/.
  --view      afterwards open pose-view on the result (needs \$DISPLAY)
  --no-deps   skip scripts/install-deps.sh (packages already present)
  --out DIR   where to write the rig, images and logs (default out/demo)
  --build DIR build folder (default build/)
  --jobs N    parallel build jobs (default: number of cores)
Environment: BAKE_ARGS, pose-bake's resolution options (default "--target-vertices 15000").
EOF
}

while [ $# -gt 0 ]; do
    case "$1" in
    --view) view=1 ;;
    --no-deps) deps=0 ;;
    --out) out=$(mkdir -p "$2" && cd "$2" && pwd); shift ;;
    --build) build=$(mkdir -p "$2" && cd "$2" && pwd); shift ;;
    --jobs) jobs=$2; shift ;;
    -h | --help) usage; exit 0 ;;
    *) echo "demo: unknown option '$1'" >&2; usage >&2; exit 2 ;;
    esac
    shift
done

t0=$(date +%s)
stage_t=
stage() { # <title>: prints the time the previous stage took
    local now
    now=$(date +%s)
    if [ -n "$stage_t" ]; then printf '   (%ds)\n' $((now - stage_t)); fi
    stage_t=$now
    printf '\n== %s\n' "$*"
}
die() { echo "demo: $*" >&2; exit 1; }
tool() { # <name>: path of a built tool, or nothing
    find "$build" -maxdepth 3 -type f -name "$1" -perm -u+x -print -quit 2>/dev/null
}

mkdir -p "$out"
log="$out/demo.log"
: >"$log"

stage "1/6 dependencies"
if [ $deps -eq 1 ]; then
    if [ "$(id -u)" -eq 0 ]; then
        bash "$root/scripts/install-deps.sh"
    elif bash "$root/scripts/install-deps.sh" >/dev/null 2>&1; then
        echo "all packages present"
    else
        die "packages are missing and this is not root: run 'sudo bash scripts/install-deps.sh' first"
    fi
else
    echo "skipped (--no-deps)"
fi

stage "2/6 build (Release, $build)"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >>"$log" 2>&1 ||
    die "cmake configure failed; see $log"
# The tools and libraries, everything `cmake --install` copies (so that works after
# the demo), not the test suite: that is scripts/test.sh's job.
available=$(cmake --build "$build" --target help 2>/dev/null)
grep -q "^pose-render:" <<<"$available" ||
    die "pose-render is not configured (needs libosmesa6-dev and libpng-dev); see $log"
cmake --build "$build" -j "$jobs" --target pose_install_ready >>"$log" 2>&1 || die "build failed; see $log"
built=""
for t in pose-synth pose-bake pose-bridge pose-render pose-export pose-view pose-volume; do
    if grep -q "^$t:" <<<"$available"; then built+="$t "; fi
done
echo "built: ${built}and the libraries (cmake --install $build works now)"

render=$(tool pose-render)
export_tool=$(tool pose-export)
bake=$(tool pose-bake)
bridge=$(tool pose-bridge)
synth=$(tool pose-synth)
pose_view=$(tool pose-view)

frames_dir="$out/frames"
hid_dir="$out/hid"
can_dir="$out/can"
usb_dir="$out/usb"
rm -rf "$frames_dir" "$hid_dir" "$can_dir" "$usb_dir"
mkdir -p "$frames_dir"

# The full chain needs pose-bake and the bridge's replay; both are detected, not assumed.
have_bake=0
[ -n "$bake" ] && "$bake" --help >/dev/null 2>&1 && have_bake=1
have_replay=0
[ -n "$bridge" ] && "$bridge" replay --help >/dev/null 2>&1 && have_replay=1
have_source=0
help=$("$render" --help)
grep -q "built without the bridge" <<<"$help" || have_source=1

bake_failed=0
if [ $have_bake -eq 1 ]; then
    stage "3/6 bake the bundled anatomy (reduced resolution)"
    rig="$out/body.rig"
    # BAKE_ARGS: the reduced resolution (the default is finer and slower).
    # shellcheck disable=SC2086 # BAKE_ARGS holds several options
    if "$bake" --skin "$root/data/anatomy/skin.obj" --bones "$root/data/anatomy/bones" \
        --template "$root/preprocess/templates/full_body.json" ${BAKE_ARGS} -o "$rig" 2>&1 | tee -a "$log"; then
        map="$root/bridge/maps/cmu131_bvh_to_full_body.json"
        kind=body
    else
        bake_failed=1
        echo "demo: pose-bake FAILED (message above). The rest of the chain runs on the synthetic bar"
        echo "      so you still see it work; the demo will exit with status 1."
    fi
fi
if [ $have_bake -eq 0 ] || [ $bake_failed -eq 1 ]; then
    [ $have_bake -eq 0 ] &&
        stage "3/6 bake: pose-bake is not in this build - using the synthetic four-bone bar instead"
    [ -n "$synth" ] || die "neither pose-bake nor pose-synth was built; see $log"
    rig="$out/bar.rig"
    "$synth" bar -o "$rig" | tee -a "$log"
    # The CMU clip's right arm (shoulder, elbow, wrist, hand) drives the bar's four joints.
    map="$root/bridge/maps/cmu131_arm_to_bar.json"
    kind=bar
fi
joints=$("$render" "$rig" --list-joints | awk '{print $1}')
# The joints the comparison panels use: the body's right knee and forearm, or the bar's joint 2.
if grep -qx knee_r <<<"$joints" && grep -qx elbow_r <<<"$joints"; then
    joint=knee_r
    bend=(--pose "knee_r=0,130,0" --pose "hip_r=0,-70,0" --focus knee_r --caption "knee bend 130 deg")
    twist=(--pose "elbow_r=0,0,80" --pose "wrist_r=0,0,80" --focus elbow_r --caption "forearm twist 160 deg")
    panel=(--size 420x480)
else
    joint=$(grep -x -m1 joint2 <<<"$joints" || sed -n 3p <<<"$joints")
    bend=(--pose "$joint=0,90,0" --caption "bend 90 deg at $joint")
    twist=(--pose "$joint=135,0,0" --skin opaque --azimuth 90 --elevation 10 --caption "twist 135 deg at $joint")
    panel=(--size 480x300)
fi

if [ $have_source -eq 1 ] && [ -n "$map" ] && [ -f "$map" ]; then
    stage "4/6 replay $(basename "$clip") (CMU walk) onto the $kind through the bridge, mapping $(basename "$map")"
    if [ $have_replay -eq 1 ]; then
        # Real time (x1) for the first 4 s: the bridge thread publishes, a 60 Hz host loop applies.
        echo "pose-bridge replay, first 4 s in real time:"
        if ! "$bridge" replay "$clip" --rig "$rig" --map "$map" --duration 4 --quiet --json 2>"$out/bridge.log" |
            tee -a "$log" | sed 's/^/  /'; then
            die "pose-bridge replay failed; see $out/bridge.log"
        fi
    else
        echo "(pose-bridge replay is not in this build yet: the frames below are decoded, retargeted"
        echo " and applied by the bridge library linked into pose-render)"
    fi
    stage "5/6 render frames (OSMesa, off-screen)"
    "$render" "$rig" --source "$clip" --map "$map" --frames 1-961:60 --fit follow --caption "CMU 131_01 walk" \
        "${panel[@]}" -o "$frames_dir" | tee -a "$log"
    "$render" "$rig" --compare --source "$clip" --map "$map" --frames 481 --caption "walk frame 481" \
        "${panel[@]}" -o "$out/compare_walk.png" | tee -a "$log"
else
    stage "4/6 replay: this build has no bridge - posing joint $joint by hand instead"
    stage "5/6 render frames (OSMesa, off-screen)"
    for a in 0 30 60 90; do
        "$render" "$rig" --pose "$joint=0,$a,0" --caption "bend $a deg" \
            -o "$frames_dir/bend_$(printf %03d "$a").png" | tee -a "$log"
    done
fi
# The paper's comparisons (Fig. 7-8) on the same rig, and the weights of one joint (Fig. 5).
"$render" "$rig" --compare "${bend[@]}" "${panel[@]}" -o "$out/compare_bend.png" | tee -a "$log"
"$render" "$rig" --compare "${twist[@]}" "${panel[@]}" -o "$out/compare_twist.png" | tee -a "$log"
"$render" "$rig" --weights "$joint" --caption "weight of $joint" -o "$out/weights.png" | tee -a "$log"
if [ -n "$export_tool" ]; then
    "$export_tool" "$rig" --pose "$joint=0,90,0" --obj "$out/posed.obj" --vtu "$out/posed.vtu" \
        --weights "$joint" | tee -a "$log"
fi

# The recorded devices (data/hid, data/can-rig): each recording replays as fast as
# possible through the bridge's own decoder (HID report descriptor, DBC) and the
# mapping, up to each time asked for; the image shows the pose held at that time.
hid_rec="$root/data/hid/mannequin_sit_to_stand.hid"
can_rec="$root/data/can-rig/sit_stand_arm_raise.log"
if [ $have_source -eq 0 ]; then
    stage "6/6 device recordings: this build has no bridge - skipped"
else
    if [ "$kind" = body ]; then
        hid_map="$root/bridge/maps/hid_mannequin_full_body.json"
        can_map="$root/bridge/maps/can_rig_fullbody.json"
        what="the body"
    else # the bar carries the right leg (hip, knee, ankle) of either device
        hid_map="$root/bridge/maps/hid_mannequin_bar.json"
        can_map="$root/bridge/maps/can_rig_bar.json"
        what="the bar (right leg only)"
    fi
    stage "6/6 device recordings onto $what: HID mannequin $(basename "$hid_rec"), CAN rig $(basename "$can_rec")"
    # Seen from the front-right, so hip and knee flexion show; one camera for all times of a recording.
    look=(--azimuth 50 --elevation 10 "${panel[@]}")
    "$render" "$rig" --source "$hid_rec" --map "$hid_map" --times 0.5,2.5,4,7 \
        --caption "HID mannequin sit-to-stand" "${look[@]}" -o "$hid_dir" | tee -a "$log"
    "$render" "$rig" --source "$can_rec" --map "$can_map" --times 0.5,2.2,4,7 \
        --caption "CAN rig sit, stand, arms up" "${look[@]}" -o "$can_dir" | tee -a "$log"
    # The vendor-class USB goniometer box's usbmon capture (data/usb), through the same bridge.
    if [ "$kind" = body ] && [ -f "$root/data/usb/gonio_arm_raise.usbmon" ]; then
        "$render" "$rig" --source "$root/data/usb/gonio_arm_raise.usbmon" \
            --map "$root/bridge/maps/usb_gonio_full_body.json" --times 0.5,3.5,7.5 \
            --caption "USB goniometer box arm raise" "${look[@]}" -o "$usb_dir" | tee -a "$log"
    fi
fi

# A volumetric patient (issue 11): the bundled CT and its labels baked (coarse), both hips
# flexed 45 degrees (sitting), the posed CT and labels written as NIfTI and slice PNGs.
volume_tool=$(tool pose-volume)
vol_dir="$out/volume"
rm -rf "$vol_dir"
if [ $have_bake -eq 1 ] && [ -n "$volume_tool" ] && [ -f "$root/data/volume/example_seg.nii.gz" ]; then
    stage "+ volumetric patient: bake the bundled CT (data/volume), sit (hips flexed 45 deg)"
    mkdir -p "$vol_dir"
    if "$bake" --labels "$root/data/volume/example_seg.nii.gz" \
        --label-names "$root/data/volume/labels.json" --volume "$root/data/volume/example_ct.nii.gz" \
        --template "$root/preprocess/templates/lumbar_pelvis_hips.json" --target-vertices 15000 \
        --no-cor --quiet --report "$vol_dir/bake.json" -o "$vol_dir/ct.rig" >>"$log" 2>&1; then
        "$volume_tool" "$vol_dir/ct.rig" --ct "$root/data/volume/example_ct.nii.gz" \
            --labels "$root/data/volume/example_seg.nii.gz" --pose hip_l=45,0,0 --pose hip_r=45,0,0 \
            --nifti "$vol_dir/sitting" --png "$vol_dir/sitting" --json | tee -a "$log"
    else
        echo "demo: pose-bake --labels failed on the bundled CT; see $log"
    fi
fi

now=$(date +%s)
printf '   (%ds)\n' $((now - stage_t))
echo
if [ $bake_failed -eq 1 ]; then
    echo "demo: pose-bake failed (see $log); the images show the synthetic bar. Done in $((now - t0)) s: $out"
else
    echo "demo: done in $((now - t0)) s. Images and files are in: $out"
fi
find "$out" -maxdepth 1 -type f | sort | sed "s|^$out/|  |"
echo "  frames/: $(find "$frames_dir" -name '*.png' | wc -l) PNG images"
for d in "$hid_dir" "$can_dir" "$usb_dir" "$vol_dir"; do
    if [ -d "$d" ]; then echo "  $(basename "$d")/: $(find "$d" -name '*.png' | wc -l) PNG images"; fi
done

if [ $view -eq 1 ]; then
    if [ -z "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
        echo "demo: --view asked, but there is no display (DISPLAY is unset); the PNGs above are the result"
    elif [ -z "$pose_view" ]; then
        echo "demo: --view asked, but pose-view was not built (needs libglfw3-dev)"
    elif [ $have_source -eq 1 ] && [ -n "$map" ] && [ -f "$map" ]; then
        "$pose_view" "$rig" --source "$clip" --map "$map"
    else
        "$pose_view" "$rig"
    fi
fi
[ $bake_failed -eq 0 ]
