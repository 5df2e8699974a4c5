#!/usr/bin/env bash
# The smooth mesh against the voxel volume it is made from (not a test): for each shared
# Middlebury set (both COLMAP models) and the demo scene, at the defaults,
#   - `raycarve holdout --every 4`: held-out PSNR and silhouette IoU of the mesh render and of the
#     volume render of the same carve;
#   - `raycarve carve`: mesh triangles, components, closed 2-manifold or not, carve and mesh time.
# Prints a Markdown table; JSON per run under out/mesh_table/.
# Usage: scripts/run_mesh_table.sh [RESOLUTIONS]   (default "128"; data: $RAYCARVE_DATA_DIR or ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
resolutions=${1:-128}
data=${RAYCARVE_DATA_DIR:-../shared/data}
scripts/setup.sh raycarve >&2
out=out/mesh_table
mkdir -p "$out"
if [ ! -d out/demo/scene/sparse ]; then
  scripts/run_demo.sh >&2
fi
projects=()
for set in templeSparseRing dinoSparseRing dinoRing; do
  for model in given sfm; do
    projects+=("$set $model --input_path $data/middlebury/$set/colmap/$model --image_path $data/middlebury/$set")
  done
done
projects+=("demo generated --workspace_path out/demo/scene")
echo "| set | model | voxels | mesh PSNR / IoU | volume PSNR / IoU | mesh - volume dB | triangles | components | closed 2-manifold | carve s | mesh s |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---|---:|---:|"
for resolution in $resolutions; do
  for project in "${projects[@]}"; do
    read -r set model args <<< "$project"
    dir="$out/${set}_${model}_${resolution}"
    # shellcheck disable=SC2086
    build/plugin/raycarve holdout $args --output_path "$dir/holdout_run" --resolution "$resolution" \
      --every 4 > "$dir.holdout.log" 2>&1
    # shellcheck disable=SC2086
    build/plugin/raycarve carve $args --output_path "$dir/carve" --resolution "$resolution" \
      > "$dir.carve.log" 2>&1
    h="$dir/holdout_run/holdout/holdout.json" r="$dir/carve/report.json"
    row=$(python3 - "$h" "$r" "$set" "$model" "$resolution" <<'EOF'
import json, sys
h = json.load(open(sys.argv[1])); r = json.load(open(sys.argv[2]))
def iou(x): return "n/a" if x < 0 else "%.3f" % x
m = r["mesh"]; s = r["stage_seconds"]
print("| %s | %s | %s | %.2f / %s | %.2f / %s | %+.2f | %d | %d | %s | %.1f | %.1f |" % (
    sys.argv[3], sys.argv[4], sys.argv[5], h["mean_psnr_db"], iou(h["mean_silhouette_iou"]),
    h["mean_volume_psnr_db"], iou(h["mean_volume_silhouette_iou"]),
    h["mean_psnr_db"] - h["mean_volume_psnr_db"], r["outputs"]["mesh_triangles"], m["components"],
    "yes" if m["closed_manifold"] else "no", s["carve_setup"] + s["carve"] + s["colour"], s["mesh"]))
EOF
)
    echo "$row"
  done
done
echo
echo "defaults (raycarve holdout / carve with --resolution only); holdout --every 4; JSON in $out/"
