#!/usr/bin/env bash
# Automatic masks against exact ones (not a test). For each generated backdrop (raycarve synth
# --backdrop, 12 views of 640x480, no mask files given to raycarve):
#   - mask IoU of `raycarve carve`'s automatic masks (<output>/masks) against the scene's exact
#     masks, with the graph cut (the default) and without (--mask_graph_cut 0);
#   - `raycarve holdout --every 4` at the defaults with automatic masks and with the exact masks
#     (--mask_path), both scored against the exact masks (--score_mask_path): PSNR and IoU.
# The patchwork sky is the natural scene: it must get no mask, and carve as with
# --background_colour none. Then the shared Middlebury sets (given models): what the masks found
# and the held-out figures at the defaults. Prints Markdown tables; logs under out/mask_table/.
# Usage: scripts/run_mask_table.sh   (data: $RAYCARVE_DATA_DIR or ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
command -v python3 > /dev/null || { echo "run_mask_table.sh needs python3 (apt-get install python3)" >&2; exit 1; }
data=${RAYCARVE_DATA_DIR:-../shared/data}
scripts/setup.sh raycarve >&2
make -C build mask_iou >/dev/null
rc=build/plugin/raycarve
out=out/mask_table
mkdir -p "$out"
holdout_figures() {  # holdout.json -> "PSNR / IoU"
  python3 -c 'import json,sys; h=json.load(open(sys.argv[1])); print("%.2f / %.3f" % (h["mean_psnr_db"], h["mean_silhouette_iou"]))' "$1"
}
echo "| backdrop | masks made | mask IoU min / mean | without graph cut | held-out PSNR / IoU, auto masks | exact masks | IoU ratio |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for backdrop in two_tone gradient vignetted shadowed_table uniform patchwork; do
  dir="$out/$backdrop"
  rm -rf "$dir"
  $rc synth --output_path "$dir/scene" --backdrop "$backdrop" --views 12 --width 640 --height 480 > "$dir.synth.log" 2>&1
  $rc carve --workspace_path "$dir/scene" --output_path "$dir/carve" > "$dir.carve.log" 2>&1
  $rc carve --workspace_path "$dir/scene" --output_path "$dir/carve_no_cut" --mask_graph_cut 0 > "$dir.carve_no_cut.log" 2>&1
  made=$(python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(sum(m["source"]=="backdrop" for m in r["masks"]))' "$dir/carve/report.json")
  if [ "$made" -gt 0 ]; then
    iou=$(build/samples/mask_iou "$dir/scene/masks" "$dir/carve/masks" | tail -1 | python3 -c 'import json,sys; j=json.load(sys.stdin); print("%.4f / %.4f" % (j["min_iou"], j["mean_iou"]))')
    iou_no_cut=$(build/samples/mask_iou "$dir/scene/masks" "$dir/carve_no_cut/masks" | tail -1 | python3 -c 'import json,sys; j=json.load(sys.stdin); print("%.4f / %.4f" % (j["min_iou"], j["mean_iou"]))')
  else
    iou="none made" iou_no_cut="none made"
  fi
  $rc holdout --workspace_path "$dir/scene" --output_path "$dir/holdout_auto" --score_mask_path "$dir/scene/masks" > "$dir.holdout_auto.log" 2>&1
  if [ "$backdrop" = patchwork ]; then
    # The natural scene: against carving with no masks at all.
    $rc holdout --workspace_path "$dir/scene" --output_path "$dir/holdout_exact" --background_colour none --score_mask_path "$dir/scene/masks" > "$dir.holdout_exact.log" 2>&1
    label="no mask (--background_colour none)"
  else
    $rc holdout --workspace_path "$dir/scene" --output_path "$dir/holdout_exact" --mask_path "$dir/scene/masks" --score_mask_path "$dir/scene/masks" > "$dir.holdout_exact.log" 2>&1
    label=""
  fi
  auto=$(holdout_figures "$dir/holdout_auto/holdout/holdout.json")
  exact=$(holdout_figures "$dir/holdout_exact/holdout/holdout.json")
  ratio=$(python3 -c 'import json,sys; a,e=(json.load(open(p))["mean_silhouette_iou"] for p in sys.argv[1:]); print("%.3f" % (a/e))' "$dir/holdout_auto/holdout/holdout.json" "$dir/holdout_exact/holdout/holdout.json")
  echo "| $backdrop | $made of 12 | $iou | $iou_no_cut | $auto | $exact ${label} | $ratio |"
done
echo
echo "| Middlebury set (given model) | masks | held-out PSNR / IoU, own masks | photos and masks s | carve s |"
echo "|---|---|---:|---:|---:|"
for set in templeSparseRing dinoSparseRing dinoRing; do
  args="--input_path $data/middlebury/$set/colmap/given --image_path $data/middlebury/$set"
  dir="$out/$set"
  # shellcheck disable=SC2086
  $rc carve $args --output_path "$dir/carve" > "$dir.carve.log" 2>&1
  # shellcheck disable=SC2086
  $rc holdout $args --output_path "$dir/holdout" > "$dir.holdout.log" 2>&1
  masks=$(grep -m1 "^  masks " "$dir.carve.log" | sed 's/^  masks *//')
  seconds=$(python3 -c 'import json,sys; s=json.load(open(sys.argv[1]))["stage_seconds"]; print("%.2f | %.2f" % (s["load_project"], s["carve_setup"] + s["carve"]))' "$dir/carve/report.json")
  echo "| $set | $masks | $(holdout_figures "$dir/holdout/holdout/holdout.json") | $seconds |"
done
