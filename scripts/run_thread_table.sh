#!/usr/bin/env bash
# Evidence for batched parallel carving (not a test; issue "threads that pay off"):
# 1. What batches change in the model: held-out views (every 4th in name order, left out of the
#    carve) of each Middlebury set through both COLMAP models and of the paper's generated scene,
#    at RESOLUTIONS, with the command's defaults (batches of 64 voxels) against --batch_voxels 1
#    (the seed paper's one voxel at a time) and --batch_voxels 256 (fewer hand-overs).
# 2. What threads save: the demo's carve (`raycarve carve --workspace_path out/demo/scene`),
#    whole process, PAIRS alternating runs of the default (every core) and --num_threads 1,
#    wall and CPU seconds (medians).
# Prints Markdown tables; writes out/thread_table/table.json.
# Usage: scripts/run_thread_table.sh [RESOLUTIONS] [PAIRS]   (default "128 256", 5;
#        data: $RAYCARVE_DATA_DIR or ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x /usr/bin/time ] || { echo "run_thread_table.sh needs /usr/bin/time (apt-get install time)" >&2; exit 1; }
resolutions=${1:-128 256}
pairs=${2:-5}
data=${RAYCARVE_DATA_DIR:-../shared/data}
scripts/setup.sh raycarve >&2
out=out/thread_table
mkdir -p "$out"
# shellcheck source=scripts/holdout_projects.sh
source scripts/holdout_projects.sh
holdout_projects
configs=("defaults (batches of 64)|" "one voxel at a time|--batch_voxels 1"
         "batches of 256|--batch_voxels 256")
rows=()
echo "| set | model | voxels | options | held-out PSNR | silhouette IoU | evaluations | threads | convergence s |"
echo "|---|---|---:|---|---:|---:|---:|---:|---:|"
for resolution in $resolutions; do
  for project in "${projects[@]}"; do
    read -r set model args <<< "$project"
    for config in "${configs[@]}"; do
      name=${config%%|*} flags=${config#*|}
      tag=${name%% *}
      dir="$out/${set}_${model}_${resolution}_${tag}"
      # shellcheck disable=SC2086
      build/plugin/raycarve holdout $args --output_path "$dir" --resolution "$resolution" \
        --every 4 $flags > "$dir.log" 2>&1
      report="$dir/holdout/holdout.json"
      psnr=$(json_number "$report" mean_psnr_db) iou=$(json_number "$report" mean_silhouette_iou)
      evaluated=$(json_number "$report" evaluated) threads=$(json_number "$report" threads)
      seconds=$(json_number "$report" convergence_seconds)
      printf "| %s | %s | %s | %s | %.2f dB | %.3f | %s | %s | %.2f |\n" "$set" "$model" \
        "$resolution" "$name" "$psnr" "$iou" "$evaluated" "$threads" "$seconds"
      rows+=("{\"set\": \"$set\", \"model\": \"$model\", \"resolution\": $resolution, \"options\": \"$name\", \"psnr_db\": $psnr, \"silhouette_iou\": $iou, \"evaluated\": $evaluated, \"threads\": $threads, \"convergence_seconds\": $seconds}")
    done
  done
done
echo
[ -d out/demo/scene/sparse ] || scripts/run_demo.sh > "$out/demo.log" 2>&1
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
: > "$out/demo_default.txt"
: > "$out/demo_one.txt"
for ((i = 0; i < pairs; ++i)); do
  for threads in -1 1; do
    file=$([ "$threads" = -1 ] && echo "$out/demo_default.txt" || echo "$out/demo_one.txt")
    /usr/bin/time -f "%e %U %S" -o "$out/time.txt" build/plugin/raycarve carve \
      --workspace_path out/demo/scene --output_path "$out/demo_carve" --num_threads "$threads" \
      > "$out/demo_carve.log" 2>&1
    read -r wall user sys < "$out/time.txt"
    echo "$wall $(awk -v u="$user" -v s="$sys" 'BEGIN { print u + s }') $(json_number "$out/demo_carve/report.json" convergence_seconds)" >> "$file"
  done
done
default_threads=$(json_number "$out/demo_carve/report.json" threads)
echo "| demo carve | wall s (median of $pairs) | CPU s | convergence s |"
echo "|---|---:|---:|---:|"
for file in default one; do
  wall=$(cut -d' ' -f1 "$out/demo_$file.txt" | median)
  cpu=$(cut -d' ' -f2 "$out/demo_$file.txt" | median)
  convergence=$(cut -d' ' -f3 "$out/demo_$file.txt" | median)
  label=$([ "$file" = default ] && echo "default (every core)" || echo "--num_threads 1")
  printf "| %s | %.2f | %.2f | %.2f |\n" "$label" "$wall" "$cpu" "$convergence"
  rows+=("{\"set\": \"demo\", \"options\": \"$label\", \"wall_seconds\": $wall, \"cpu_seconds\": $cpu, \"convergence_seconds\": $convergence}")
done
write_rows "$out/table.json"
echo
echo "holdout --every 4 at the defaults; demo runs alternate; JSON in $out/table.json"
