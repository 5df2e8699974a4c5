#!/usr/bin/env bash
# Unmasked captures with known truth (not a test). For each generated scene (raycarve synth, 12
# views of 320x240, its exact masks deleted so that raycarve sees what a user without masks
# has): carve and holdout (--every 4) at the defaults and with the colour test off
# (--threshold 1000000), and report
#   - the capture raycarve found (object / scene) and whether the box went round the focus;
#   - the share of the surface on the volume box's walls (left out of the mesh);
#   - the cloud against the scene's truth (truth.ply: the objects, the ground square, the clutter
#     and the room's floor and wall) inside the volume carved: precision, completeness and F-score
#     at two voxels (raycarve compare --bbox);
#   - held-out photos: PSNR over the whole photo, PSNR and SSIM inside the truth's silhouettes
#     (the exact masks, kept apart from the project), and the share of their sparse points
#     (triangulated from the other photos) the mesh draws at their depth and hides behind
#     something nearer; and, as
#     the truth is known, how many of those points the truth itself hides (wrong matches, points
#     triangulated off an occluding contour) and the share the mesh hides of those the truth
#     shows at their depth (samples/truth_sparse_depth on holdout's sparse_depth.csv).
# Prints a Markdown table and writes out/unmasked_table/table.json.
#
# With --sift_points the sparse points are COLMAP's instead of exact samples of the truth
# (scripts/triangulate_sift_points.sh: SIFT features matched and triangulated at the true poses),
# as in a user's model: fewer, noisier, short tracks, some wrong matches. --views N and --size WxH
# change the photos (SIFT needs more and larger photos than the exact points do: 36 of 640x480
# give a ring's neighbours 10 degrees apart). Written to out/unmasked_table_sift.
# --scene "room ring" runs that scene alone (backdrop and layout, then "clutter" where it has some).
# Usage: scripts/run_unmasked_table.sh [--sift_points] [--views 12] [--size 320x240] [--scene S]
set -euo pipefail
cd "$(dirname "$0")/.."
command -v python3 > /dev/null || { echo "run_unmasked_table.sh needs python3" >&2; exit 1; }
sift=0 views=12 size=320x240 only=""
while [ $# -gt 0 ]; do
  case "$1" in
    --sift_points) sift=1; shift ;;
    --views) views=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --scene) only=$2; shift 2 ;;
    *) echo "usage: $0 [--sift_points] [--views N] [--size WxH] [--scene S]" >&2; exit 1 ;;
  esac
done
width=${size%x*} height=${size#*x}
scripts/setup.sh raycarve truth_sparse_depth >&2
rc=build/plugin/raycarve
out=out/unmasked_table
[ "$sift" = 1 ] && out=out/unmasked_table_sift
rm -rf "$out"
mkdir -p "$out"
rows="$out/rows.jsonl"
: > "$rows"
for scene in "room ring" "room arc" "room forward" "patchwork ring" "patchwork arc" \
             "patchwork forward" "room arc clutter" "patchwork ring clutter" \
             "patchwork eye_level" "cloudy eye_level"; do
  [ -n "$only" ] && [ "$scene" != "$only" ] && continue
  set -- $scene
  backdrop=$1 layout=$2 kind=${3:-simple} name="$1_$2${3:+_$3}"
  dir="$out/$name"
  $rc synth --output_path "$dir/scene" --scene "$kind" --backdrop "$backdrop" --layout "$layout" \
    --views "$views" --width "$width" --height "$height" > "$dir.synth.log" 2>&1
  mv "$dir/scene/masks" "$dir/truth_masks"
  if [ "$sift" = 1 ]; then
    echo "$name: $(scripts/triangulate_sift_points.sh "$dir/scene")" >&2
  fi
  for run in defaults colour_off; do
    flags=""
    [ "$run" = colour_off ] && flags="--threshold 1000000"
    $rc carve --workspace_path "$dir/scene" --output_path "$dir/$run" $flags > "$dir.$run.carve.log" 2>&1
    voxel=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["statistics"]["voxel_size"])' "$dir/$run/report.json")
    # Inside the volume carved: what lies beyond it (the room's far floor and wall) no carve of
    # that box can hold.
    box=$(python3 -c 'import json,sys; b=json.load(open(sys.argv[1]))["bounds"]; print(",".join(str(v) for v in b["min"] + b["max"]))' "$dir/$run/report.json")
    $rc compare --reference_path "$dir/scene/truth.ply" --input_path "$dir/$run/cloud.ply" \
      --threshold "$(python3 -c "print(2 * $voxel)")" --bbox "$box" \
      --output_path "$dir/$run/compare.json" > "$dir.$run.compare.log" 2>&1
    $rc holdout --workspace_path "$dir/scene" --output_path "$dir/$run" --every 4 $flags > "$dir.$run.holdout.log" 2>&1
    # The same model scored inside the truth's silhouettes (the exact masks, which the carve never
    # saw): what the photos show of the scene's objects and ground.
    $rc holdout --workspace_path "$dir/scene" --output_path "$dir/$run/truth_scored" --every 4 $flags \
      --score_mask_path "$dir/truth_masks" > "$dir.$run.holdout_truth.log" 2>&1
    tolerance=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["sparse_depth_tolerance"])' "$dir/$run/holdout/holdout.json")
    build/samples/truth_sparse_depth "$dir/scene" "$dir/$run/holdout/sparse_depth.csv" "$tolerance" \
      "$kind" "$backdrop" | tail -1 > "$dir/$run/truth_sparse_depth.json"
    python3 - "$name" "$run" "$dir/$run" >> "$rows" <<'EOF'
import json, sys
name, run, folder = sys.argv[1:4]
report = json.load(open(folder + "/report.json"))
compare = json.load(open(folder + "/compare.json"))
holdout = json.load(open(folder + "/holdout/holdout.json"))
truth_scored = json.load(open(folder + "/truth_scored/holdout/holdout.json"))
truth_depth = json.load(open(folder + "/truth_sparse_depth.json"))
def find(obj, key):
    if isinstance(obj, dict):
        if key in obj:
            return obj[key]
        for value in obj.values():
            found = find(value, key)
            if found is not None:
                return found
    return None
print(json.dumps({
    "scene": name, "run": run,
    "capture": report["capture"]["kind"], "around_focus": report["bounds"]["around_focus"],
    "box_wall_share": find(report, "box_wall_share"),
    "precision": find(compare, "precision"), "completeness": find(compare, "completeness"),
    "f_score": find(compare, "f_score"),
    "psnr_db": holdout["mean_psnr_db"], "psnr_in_truth_db": truth_scored["mean_psnr_db"],
    "ssim_in_truth": truth_scored["mean_ssim"],
    "silhouette_iou": truth_scored["mean_silhouette_iou"], "sparse_points": holdout["sparse_points"],
    "at_depth": holdout["sparse_at_depth_share"], "hidden": holdout["sparse_hidden_share"],
    "truth_hidden": truth_depth["truth_hidden_share"],
    "hidden_of_truth_at_depth": truth_depth["model_hidden_of_truth_at_depth"],
    "at_depth_of_truth_at_depth": truth_depth["model_at_depth_of_truth_at_depth"]}))
EOF
  done
done
python3 - "$rows" "$out/table.json" <<'EOF'
import json, sys
rows = [json.loads(line) for line in open(sys.argv[1])]
json.dump(rows, open(sys.argv[2], "w"), indent=1)
print("| scene | run | capture (box) | on box walls | precision | completeness | F-score | held-out PSNR, whole / in truth | SSIM in truth | sparse at depth | hidden (the truth hides) | of those the truth shows: at depth / hidden |")
print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for r in rows:
    print("| %s | %s | %s%s | %.1f%% | %.1f%% | %.1f%% | %.1f%% | %.2f / %.2f dB | %.3f | %.1f%% | %.1f%% (%.1f%%) | %.1f%% / %.1f%% |" % (
        r["scene"], r["run"], r["capture"], " (focus)" if r["around_focus"] else "",
        100 * r["box_wall_share"], 100 * r["precision"], 100 * r["completeness"],
        100 * r["f_score"], r["psnr_db"], r["psnr_in_truth_db"], r["ssim_in_truth"],
        100 * r["at_depth"],
        100 * r["hidden"], 100 * r["truth_hidden"], 100 * r["at_depth_of_truth_at_depth"],
        100 * r["hidden_of_truth_at_depth"]))
EOF
