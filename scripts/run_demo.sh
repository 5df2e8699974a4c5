#!/usr/bin/env bash
# README command 1: set-up, build, and the main job on the embedded default scene.
# Generates a synthetic COLMAP project (ray-traced sphere, box and checkered ground, 8 views with
# OPENCV lens distortion), then runs raycarve's calibration on it: views undistorted, the volume
# bounded, every sparse point reprojected through its view. Outputs go to out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh raycarve
out=${1:-out/demo}
mkdir -p "$out"
build/plugin/raycarve synth --output_path "$out/scene" --camera_model OPENCV --views 8 \
  --width 640 --height 480
build/plugin/raycarve model_info --input_path "$out/scene/sparse/0" \
  --output_path "$out/model_info.json"
build/plugin/raycarve calibrate --workspace_path "$out/scene" --output_path "$out/calibration"
echo
echo "Outputs in $out/:"
echo "  scene/images/*.png, scene/sparse/0/   the generated COLMAP project (open in colmap gui)"
echo "  model_info.json                       cameras, images, points and the carving bounds"
echo "  calibration/report.json               per-view projections and reprojection errors"
echo "  calibration/undistorted/*.png         photos resampled to ideal pinhole views"
echo "  calibration/masks/*.png.png           where each undistorted view holds photo pixels"
