#!/usr/bin/env bash
# The seed paper's section 4 on real photos (not a test): a Middlebury set through its calibration
# model, carved with each CVSVL order, decision, number of levels of detail and with incremental
# statistics (one thread each, so that times compare), with backdrop masks; scored on held-out
# views (every 4th left out: silhouette IoU, PSNR) and against the model's sparse points.
# Prints a Markdown table.
# Usage: scripts/run_variants_photos.sh [SET RESOLUTION THRESHOLD]   (default dinoRing 128 60;
#        data: $RAYCARVE_DATA_DIR or ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
set=${1:-dinoRing} resolution=${2:-128} threshold=${3:-60}
data=${RAYCARVE_DATA_DIR:-../shared/data}/middlebury/$set
[ -d "$data/colmap/given" ] || { echo "no $data/colmap/given: set RAYCARVE_DATA_DIR" >&2; exit 1; }
scripts/setup.sh raycarve >&2
out=out/variants_${set}_$resolution
mkdir -p "$out"
source scripts/variants.sh
echo "| variant | convergence s | evaluated | carved | final surface | sparse points within 2 voxels | held-out silhouette IoU | held-out PSNR |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|"
run() {
  local name=$1; shift
  local dir="$out/$name"
  local input=(--input_path "$data/colmap/given" --image_path "$data" --output_path "$dir"
               --resolution "$resolution" --threshold "$threshold" --num_threads 1)
  build/plugin/raycarve carve "${input[@]}" "$@" > "$dir.carve.log" 2>&1
  build/plugin/raycarve holdout "${input[@]}" --every 4 "$@" > "$dir.holdout.log" 2>&1
  local report="$dir/report.json" holdout="$dir/holdout/holdout.json"
  printf "| %s | %.2f | %s | %s | %s | %.1f%% | %.3f | %.2f dB |\n" "$name" \
    "$(json_number "$report" convergence_seconds)" "$(json_number "$report" evaluated)" \
    "$(json_number "$report" carved)" "$(json_number "$report" final_surface)" \
    "$(awk -v v="$(json_number "$report" within_2_voxels)" 'BEGIN { print 100 * v }')" \
    "$(json_number "$holdout" mean_silhouette_iou)" "$(json_number "$holdout" mean_psnr_db)"
}
run_all_variants
echo
echo "$set (its calibration), $resolution voxels, threshold $threshold; reports in $out/."
