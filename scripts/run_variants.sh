#!/usr/bin/env bash
# The seed paper's section 4 measured (not a test): on a generated scene, carve with each CVSVL
# order, decision and number of levels of detail, and with incremental colour statistics (one
# thread each, so that times compare), and score every result against the scene's truth.
# Prints a Markdown table. Usage: scripts/run_variants.sh [VIEWS WIDTH HEIGHT RESOLUTION THRESHOLD]
set -euo pipefail
cd "$(dirname "$0")/.."
views=${1:-8} width=${2:-320} height=${3:-240} resolution=${4:-128} threshold=${5:-30}
scripts/setup.sh raycarve >&2
out=out/variants_${views}x${width}x${height}
[ -d "$out/scene" ] || build/plugin/raycarve synth --output_path "$out/scene" --views "$views" \
  --width "$width" --height "$height" >&2
source scripts/variants.sh
echo "| variant | convergence s | evaluated | carved | final surface | completeness | accuracy (90%) | F-score |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|"
run() {
  local name=$1; shift
  build/plugin/raycarve carve --workspace_path "$out/scene" --output_path "$out/$name" \
    --resolution "$resolution" --threshold "$threshold" --num_threads 1 "$@" > "$out/$name.log" 2>&1
  local report="$out/$name/report.json" voxel
  voxel=$(json_number "$report" voxel_size)
  build/plugin/raycarve compare --reference_path "$out/scene/truth.ply" --input_path "$out/$name/cloud.ply" \
    --threshold "$(awk -v v="$voxel" 'BEGIN { print 2 * v }')" --output_path "$out/$name/compare.json" > /dev/null
  printf "| %s | %.2f | %s | %s | %s | %.1f%% | %.4f | %.1f%% |\n" "$name" \
    "$(json_number "$report" convergence_seconds)" "$(json_number "$report" evaluated)" \
    "$(json_number "$report" carved)" "$(json_number "$report" final_surface)" \
    "$(awk -v v="$(json_number "$out/$name/compare.json" completeness)" 'BEGIN { print 100 * v }')" \
    "$(json_number "$out/$name/compare.json" accuracy)" \
    "$(awk -v v="$(json_number "$out/$name/compare.json" f_score)" 'BEGIN { print 100 * v }')"
}
run_all_variants
echo
echo "Completeness and F-score at 2 voxels against $out/scene/truth.ply; reports in $out/."
