#!/usr/bin/env bash
# Real-photo and generated-scene evidence for the carve's defaults (not a test): held-out views
# (every 4th in name order, left out of the carve, the bounds, the threshold and the known
# surface) of each Middlebury set through both COLMAP models, and of the paper's generated scene
# (14 views of 800x600, as the paper's experiment), at RESOLUTIONS, with the command's defaults,
# --threshold 30, --threshold 60 and silhouettes only (--threshold 1000000 --consistency
# mean_colour --free_space_margin 0 --floater_expected_points 0: the visual hull alone, nothing carved
# by colour, by the sparse points' sight lines or as floaters). Prints a Markdown table; writes out/threshold_table/table.json.
# Usage: scripts/run_threshold_table.sh [RESOLUTIONS]   (default "128 256"; data: $RAYCARVE_DATA_DIR or ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
resolutions=${1:-128 256}
data=${RAYCARVE_DATA_DIR:-../shared/data}
scripts/setup.sh raycarve >&2
out=out/threshold_table
mkdir -p "$out"
# shellcheck source=scripts/holdout_projects.sh
source scripts/holdout_projects.sh
holdout_projects
configs=("defaults|" "threshold 30|--threshold 30" "threshold 60|--threshold 60" "silhouettes only|--threshold 1000000 --consistency mean_colour --free_space_margin 0 --floater_expected_points 0")
echo "| set | model | voxels | options | held-out PSNR | silhouette IoU | thresholds (coarse to fine) | carve s |"
echo "|---|---|---:|---|---:|---:|---|---:|"
rows=()
for resolution in $resolutions; do
  for project in "${projects[@]}"; do
    read -r set model args <<< "$project"
    for config in "${configs[@]}"; do
      name=${config%%|*} flags=${config#*|}
      dir="$out/${set}_${model}_${resolution}_${name// /_}"
      start=$(date +%s.%N)
      # shellcheck disable=SC2086
      build/plugin/raycarve holdout $args --output_path "$dir" --resolution "$resolution" \
        --every 4 $flags > "$dir.log" 2>&1
      seconds=$(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN { printf "%.1f", e - s }')
      report="$dir/holdout/holdout.json"
      psnr=$(json_number "$report" mean_psnr_db) iou=$(json_number "$report" mean_silhouette_iou)
      thresholds=$(grep -o '"thresholds": "[^"]*"' "$report" | sed 's/.*: "//; s/"$//')
      printf "| %s | %s | %s | %s | %.2f dB | %.3f | %s | %s |\n" "$set" "$model" "$resolution" \
        "$name" "$psnr" "$iou" "$thresholds" "$seconds"
      rows+=("{\"set\": \"$set\", \"model\": \"$model\", \"resolution\": $resolution, \"options\": \"$name\", \"psnr_db\": $psnr, \"silhouette_iou\": $iou, \"seconds\": $seconds}")
    done
  done
done
write_rows "$out/table.json"
echo
echo "holdout --every 4; the seconds are the whole holdout command (load, carve, render); JSON in $out/table.json"
