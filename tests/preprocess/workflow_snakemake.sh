#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The Snakemake workflow (preprocess/workflow) on two copies of the bundled
# anatomy as a folder of patients, with coarse settings: both rigs baked in
# parallel (local profile), a second run finds nothing to do, and the Slurm
# profile submits one job (a stand-in sbatch runs it: no cluster here).
# Exits 77 (skipped) without snakemake (Debian: snakemake).
# usage: workflow_snakemake.sh POSE_BAKE SOURCE_DIR TMP
set -euo pipefail
bake=$1 src=$2 tmp=$3
if ! command -v snakemake >/dev/null; then
  echo "workflow_snakemake: skipped: snakemake is not installed (apt-get install snakemake)"
  exit 77
fi
wf="$src/preprocess/workflow"
rm -rf "$tmp"
mkdir -p "$tmp/patients"
for p in alice bob; do
  mkdir -p "$tmp/patients/$p"
  cp "$src/data/anatomy/skin.obj" "$tmp/patients/$p/skin.obj"
  cp -r "$src/data/anatomy/bones" "$tmp/patients/$p/bones"
done
conf=(patients="$tmp/patients" out="$tmp/rigs" pose_bake="$bake" "bake_args=--target-vertices 8000 --no-cor")
run() { snakemake -s "$wf/Snakefile" --directory "$tmp" --config "${conf[@]}" "$@"; }

run --profile "$wf/profiles/local" --cores 2 --quiet
for p in alice bob; do
  [ -s "$tmp/rigs/$p.rig" ] || { echo "workflow_snakemake: no rig for $p"; cat "$tmp/rigs/logs/$p.log" || true; exit 1; }
  python3 - "$tmp/rigs/$p.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["rig_bytes"] > 0 and r["tetmesh"], r
print(f"{sys.argv[1]}: {r['rig_bytes']} bytes in {r['total_seconds']:.1f} s")
PY
done
ls -l "$tmp/rigs"
# The same anatomy makes the same rig, but for the input paths in its provenance text.
[ "$(stat -c %s "$tmp/rigs/alice.rig")" = "$(stat -c %s "$tmp/rigs/bob.rig")" ] ||
  { echo "workflow_snakemake: the two copies baked to different sizes"; exit 1; }

cp "$tmp/rigs/bob.rig" "$tmp/bob_local.rig"

# Up to date: nothing left to run.
run --cores 2 -n >"$tmp/again.txt" 2>&1
grep -q "Nothing to be done" "$tmp/again.txt" || { echo "workflow_snakemake: a second run would bake again:"; cat "$tmp/again.txt"; exit 1; }

# The Slurm profile, through a stand-in sbatch that runs the job script
# Snakemake submits (as a Slurm node would) and records its options: bob's
# rig, removed, is baked again as one cluster job sized by the rule.
mkdir -p "$tmp/bin"
cat >"$tmp/bin/sbatch" <<'SH'
#!/usr/bin/env bash
echo "$*" >>"$SBATCH_LOG"
script="${!#}"
bash "$script" >>"$SBATCH_LOG.out" 2>&1 </dev/null &
echo 4242
SH
chmod +x "$tmp/bin/sbatch"
rm -f "$tmp/rigs/bob.rig" "$tmp/rigs/bob.json"
SBATCH_LOG="$tmp/sbatch.log" PATH="$tmp/bin:$PATH" run --profile "$wf/profiles/slurm" --quiet >"$tmp/slurm.txt" 2>&1 ||
  { echo "workflow_snakemake: the Slurm run failed:"; cat "$tmp/slurm.txt" "$tmp/sbatch.log"* || true; exit 1; }
cat "$tmp/sbatch.log"
[ "$(wc -l <"$tmp/sbatch.log")" = 1 ] || { echo "workflow_snakemake: expected one sbatch job (bob)"; exit 1; }
grep -q -- "--job-name=pose-bake-bob --cpus-per-task=1 --mem=4000 --time=30 --partition=compute" "$tmp/sbatch.log" ||
  { echo "workflow_snakemake: sbatch was not given the rule's resources"; exit 1; }
cmp "$tmp/rigs/bob.rig" "$tmp/bob_local.rig" ||
  { echo "workflow_snakemake: the cluster job baked a different rig than the local run"; exit 1; }
echo "workflow_snakemake: 2 patients baked locally, up to date on a second run, the Slurm job baked bob again to the same bytes"
