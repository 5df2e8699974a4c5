#!/usr/bin/env bash
# A carve in tiles run for real by Slurm, on this one machine (issue 46): starts a single-node
# Slurm (munged, slurmctld, slurmd) from a configuration of its own in a temporary folder, plans a
# carve of a generated scene in 2x2x2 tiles, submits the plan's submit_slurm.sh (an array job and
# the merge after it), waits for both, and compares the merged model with one carve of the same
# options (raycarve compare, the truth and each other). Stops what it started, also on failure.
#
# Needs root (munged and slurmd run as root here) and Debian's slurm-wlm and munge, installed if
# missing. Not part of scripts/run_tests.sh (it starts daemons and takes a few minutes); CI runs
# the same jobs as local processes in tests/plugin/tile_command_test.
#
# Usage: scripts/run_tile_slurm.sh [OUTPUT_DIR] [RESOLUTION]   (defaults: out/tile_slurm, 256)
# Prints the jobs' states and walls (sacct is not configured: from the logs) and the comparison.
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(realpath -m "${1:-out/tile_slurm}")
resolution=${2:-256}
raycarve=$(realpath build/plugin/raycarve)
[ -x "$raycarve" ] || scripts/setup.sh raycarve
if ! command -v slurmctld > /dev/null || ! command -v munged > /dev/null; then
  echo "[tile_slurm] installing slurm-wlm and munge" >&2
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >&2
fi

state=$(mktemp -d /tmp/raycarve-slurm.XXXXXX)
node=$(hostname -s)
memory=$(free -m | awk '/^Mem:/ {print int($2 * 0.9)}')
export SLURM_CONF=$state/slurm.conf
cat > "$SLURM_CONF" <<EOF
ClusterName=raycarve
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
CredType=cred/munge
StateSaveLocation=$state/state
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=$state/slurmctld.log
SlurmdLogFile=$state/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=$node CPUs=$(nproc) RealMemory=$memory State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
mkdir -p "$state/state" "$state/spool" "$state/munge"
munge_socket=$state/munge/munge.socket
cleanup() {
  [ -f "$state/slurmd.pid" ] && kill "$(cat "$state/slurmd.pid")" 2> /dev/null || true
  [ -f "$state/slurmctld.pid" ] && kill "$(cat "$state/slurmctld.pid")" 2> /dev/null || true
  [ -f "$state/munged.pid" ] && kill "$(cat "$state/munged.pid")" 2> /dev/null || true
  sleep 1
  rm -rf "$state"
}
trap cleanup EXIT
# Munge with its own socket, so that a munged the machine already runs is left alone; Slurm's
# plugin finds it through the configuration.
echo "AuthInfo=socket=$munge_socket" >> "$SLURM_CONF"
munged --force --socket="$munge_socket" --pid-file="$state/munged.pid" \
  --log-file="$state/munged.log" --seed-file="$state/munge/seed" \
  --key-file=/etc/munge/munge.key
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 1 30); do
  if sinfo -h -o "%T" 2> /dev/null | grep -q idle; then break; fi
  sleep 1
done
sinfo
if ! sinfo -h -o "%T" | grep -q idle; then
  echo "[tile_slurm] the node did not come up; slurmctld's log:" >&2
  tail -20 "$state/slurmctld.log" "$state/slurmd.log" >&2
  exit 1
fi

rm -rf "$out"
mkdir -p "$out"
"$raycarve" synth --output_path "$out/scene" --scene paper --views 14 --width 800 --height 600 > "$out/synth.log" 2>&1
start=$(date +%s.%N)
"$raycarve" carve --workspace_path "$out/scene" --resolution "$resolution" --output_path "$out/single" > "$out/single.log" 2>&1
single_wall=$(echo "$(date +%s.%N) - $start" | bc)
start=$(date +%s.%N)
"$raycarve" tile plan --workspace_path "$out/scene" --resolution "$resolution" --output_path "$out/tiled" --tiles 2 > "$out/plan.log" 2>&1
grep "^tile plan" "$out/plan.log"
"$out/tiled_tiles/submit_slurm.sh" | tee "$out/submit.log"
merge_job=$(sed -n 's/.*merge: job \([0-9]*\).*/\1/p' "$out/submit.log")
# Wait for the merge (it runs after every array task succeeded), then for the queue to empty.
for _ in $(seq 1 1200); do
  if ! squeue -h | grep -q .; then break; fi
  sleep 1
done
tiled_wall=$(echo "$(date +%s.%N) - $start" | bc)
if [ ! -f "$out/tiled/report.json" ]; then
  echo "[tile_slurm] the merge (job $merge_job) wrote no model; its log:" >&2
  cat "$out/tiled_tiles/logs/merge.log" >&2 || true
  exit 1
fi
echo "array task logs:"
grep -h "^tile " "$out"/tiled_tiles/logs/tile_*.log
printf "walls: one carve %.1f s; plan + Slurm array on %d cores + merge %.1f s\n" "$single_wall" "$(nproc)" "$tiled_wall"
voxel=$(python3 -c "import json; print(json.load(open('$out/single/report.json'))['statistics']['voxel_size'])")
for model in single tiled; do
  echo "$model against the truth at 2 voxels:"
  "$raycarve" compare --input_path "$out/$model/cloud.ply" --reference_path "$out/scene/truth.ply" \
    --threshold "$(python3 -c "print(2 * $voxel)")" 2>&1 | grep "F-score"
done
echo "tiled against single at 1 voxel:"
"$raycarve" compare --input_path "$out/tiled/cloud.ply" --reference_path "$out/single/cloud.ply" \
  --threshold "$voxel" 2>&1 | grep "F-score"
