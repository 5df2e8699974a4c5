#!/usr/bin/env bash
# Real-photo evidence (not a test): the Middlebury sets through both of their COLMAP models
# (colmap/given: the calibration; colmap/sfm: COLMAP's own structure-from-motion), carved at
# RESOLUTION voxels with backdrop masks, scored on held-out views (every 4th left out) and against
# the model's sparse points. Prints a Markdown table.
# Usage: scripts/run_real_photos.sh [RESOLUTION THRESHOLD]   (data: $RAYCARVE_DATA_DIR or ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
resolution=${1:-128} threshold=${2:-60}
data=${RAYCARVE_DATA_DIR:-../shared/data}/middlebury
scripts/setup.sh raycarve >&2
out=out/real_photos
mkdir -p "$out"
json_number() { grep -o "\"$2\": [-0-9.e+]*" "$1" | head -1 | sed 's/.*: //'; }
echo "| set | model | views | sparse points within 2 voxels | 90% of them within | held-out silhouette IoU | held-out PSNR | carve s |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
for set in templeSparseRing dinoSparseRing dinoRing; do
  for model in given sfm; do
    dir="$out/${set}_$model"
    input=(--input_path "$data/$set/colmap/$model" --image_path "$data/$set")
    build/plugin/raycarve carve "${input[@]}" --output_path "$dir" --resolution "$resolution" \
      --threshold "$threshold" > "$dir.carve.log" 2>&1
    build/plugin/raycarve holdout "${input[@]}" --output_path "$dir" --resolution "$resolution" \
      --threshold "$threshold" --every 4 > "$dir.holdout.log" 2>&1
    report="$dir/report.json" holdout="$dir/holdout/holdout.json"
    printf "| %s | %s | %s | %.1f%% | %.2f voxels | %.3f | %.2f dB | %.2f |\n" "$set" "$model" \
      "$(json_number "$report" num_views)" \
      "$(awk -v v="$(json_number "$report" within_2_voxels)" 'BEGIN { print 100 * v }')" \
      "$(json_number "$report" distance_90_percent_voxels)" \
      "$(json_number "$holdout" mean_silhouette_iou)" "$(json_number "$holdout" mean_psnr_db)" \
      "$(json_number "$report" convergence_seconds)"
  done
done
echo
echo "Resolution $resolution, threshold $threshold; reports and held-out images in $out/."
