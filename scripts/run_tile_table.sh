#!/usr/bin/env bash
# docs/scaling.md's table: the paper scene carved once and in 2x2x2 tiles (plan, each job, merge
# one after the other), each step's wall and peak memory, and both models against the truth and
# each other. Usage: scripts/run_tile_table.sh [RESOLUTION] [OUTPUT_DIR]   (defaults: 512,
# out/tile_table). About 4 minutes at 512 on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
resolution=${1:-512}
out=$(realpath -m "${2:-out/tile_table}")
raycarve=$(realpath build/plugin/raycarve)
[ -x "$raycarve" ] || scripts/setup.sh raycarve
mkdir -p "$out"
cd "$out"
[ -f paper/truth.ply ] || "$raycarve" synth --output_path paper --scene paper --views 14 --width 800 --height 600 > synth.log 2>&1
rm -rf single tiled tiled_tiles
step() {  # step NAME COMMAND...: runs it, prints its wall and peak memory
  local name=$1; shift
  /usr/bin/time -f "$name: wall %e s, peak %M KB" "$@" > "$name.log" 2>&1 || { tail -5 "$name.log"; exit 1; }
  tail -1 "$name.log"
}
step single "$raycarve" carve --workspace_path paper --resolution "$resolution" --output_path single
step plan "$raycarve" tile plan --workspace_path paper --resolution "$resolution" --output_path tiled --tiles 2
grep "^tile plan" plan.log
jobs=$(python3 -c "import json; print(json.load(open('tiled_tiles/plan.json'))['jobs'])")
for job in $(seq 0 $((jobs - 1))); do
  step "job$job" "$raycarve" tile run --plan tiled_tiles/plan.json --index "$job"
  grep "^tile" "job$job.log"
done
step merge "$raycarve" tile merge --plan tiled_tiles/plan.json
voxel256=$(python3 -c "import json; r = json.load(open('single/report.json')); print(r['statistics']['voxel_size'] * $resolution / 256)")
voxel=$(python3 -c "import json; print(json.load(open('single/report.json'))['statistics']['voxel_size'])")
for model in single tiled; do
  for voxels in 2 1; do
    echo "$model against the truth at $voxels voxels of 256:"
    "$raycarve" compare --input_path "$model/cloud.ply" --reference_path paper/truth.ply \
      --threshold "$(python3 -c "print($voxels * $voxel256)")" 2>&1 | grep "F-score"
  done
done
echo "tiled against single at one voxel:"
"$raycarve" compare --input_path tiled/cloud.ply --reference_path single/cloud.ply --threshold "$voxel" 2>&1 | grep "F-score"
