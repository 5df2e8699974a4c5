#!/usr/bin/env bash
# Camera layouts and backdrops at the defaults (not a test). For each layout of `raycarve synth
# --layout` (ring, hemisphere, arc, close) and each backdrop (the five studio backdrops, whose
# masks raycarve makes itself, and the patchwork sky, which gets none), 12 views of 640x480:
#   - `raycarve carve --workspace_path S` against the scene's true surface (`raycarve compare
#     --threshold 0.027`, one voxel at 128): F-score;
#   - `raycarve holdout --workspace_path S --every 4 --score_mask_path S/masks`: held-out PSNR and
#     IoU against the exact masks.
# With a second build (RAYCARVE_BEFORE=path/to/raycarve) each row shows it too. Prints a Markdown
# table; scenes and logs under out/layout_table/.
# Usage: scripts/run_layout_table.sh
set -euo pipefail
cd "$(dirname "$0")/.."
command -v python3 > /dev/null || { echo "run_layout_table.sh needs python3 (apt-get install python3)" >&2; exit 1; }
scripts/setup.sh raycarve >&2
rc=build/plugin/raycarve
before=${RAYCARVE_BEFORE:-}
out=out/layout_table
mkdir -p "$out"
figures() {  # RAYCARVE SCENE TAG -> "F-score / PSNR / IoU"
  local bin=$1 scene=$2 tag=$3
  "$bin" carve --workspace_path "$scene" --output_path "$scene.$tag.carve" > "$scene.$tag.carve.log" 2>&1
  local f
  f=$("$bin" compare --reference_path "$scene/truth.ply" --input_path "$scene.$tag.carve/cloud.ply" \
      --threshold 0.027 2>&1 | grep -o 'F-score [0-9.]*%' | head -1 | grep -o '[0-9.]*%')
  "$bin" holdout --workspace_path "$scene" --every 4 --score_mask_path "$scene/masks" \
      --output_path "$scene.$tag.holdout" > "$scene.$tag.holdout.log" 2>&1
  python3 -c 'import json,sys; h=json.load(open(sys.argv[1])); print("%s / %.2f / %.3f" % (sys.argv[2], h["mean_psnr_db"], h["mean_silhouette_iou"]))' \
      "$scene.$tag.holdout/holdout/holdout.json" "$f"
}
if [ -n "$before" ]; then
  echo "| layout | backdrop | before: F-score / PSNR / IoU | now |"
  echo "|---|---|---:|---:|"
else
  echo "| layout | backdrop | F-score / PSNR / IoU |"
  echo "|---|---|---:|"
fi
for layout in ring hemisphere arc close; do
  for backdrop in two_tone gradient vignetted shadowed_table uniform patchwork; do
    scene="$out/$layout-$backdrop"
    rm -rf "$scene" "$scene".*
    $rc synth --output_path "$scene" --layout "$layout" --backdrop "$backdrop" --views 12 \
        --width 640 --height 480 > "$scene.synth.log" 2>&1
    now=$(figures "$rc" "$scene" now)
    if [ -n "$before" ]; then
      echo "| $layout | $backdrop | $(figures "$before" "$scene" before) | $now |"
    else
      echo "| $layout | $backdrop | $now |"
    fi
  done
done
