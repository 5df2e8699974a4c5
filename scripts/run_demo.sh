#!/usr/bin/env bash
# README command 1: set-up, build, and the main job on the embedded default scene.
# Generates a synthetic COLMAP project (ray-traced sphere, striped box and checkered ground under
# a patchwork sky, 8 views of 640x480 through an OPENCV camera with lens distortion), then carves
# it with raycarve: photos undistorted, volume bounded from the sparse points, incremental voxel
# colouring with ray-cast visibility, coloured cloud and mesh exported. Outputs go to out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh raycarve render_cloud
out=${1:-out/demo}
mkdir -p "$out"
build/plugin/raycarve synth --output_path "$out/scene" --camera_model OPENCV --views 8 \
  --width 640 --height 480
build/plugin/raycarve model_info --input_path "$out/scene/sparse/0" \
  --output_path "$out/model_info.json" > /dev/null
build/plugin/raycarve carve --workspace_path "$out/scene" --output_path "$out/carve"
# Measured against the scene's true surface (truth.ply); 0.05 is about 2 voxels at 128.
build/plugin/raycarve compare --reference_path "$out/scene/truth.ply" --input_path "$out/carve/cloud.ply" \
  --threshold 0.05 --output_path "$out/carve/compare.json" | head -2
echo
echo "Outputs in $out/:"
echo "  scene/images/*.png, scene/sparse/0/   the generated COLMAP project (colmap gui can open it)"
echo "  scene/truth.ply                       the true surface, densely sampled (ground truth)"
echo "  model_info.json                       cameras, images, points and the carving bounds"
echo "  carve/cloud.ply                       coloured points with normals sampled on the mesh (COLMAP fused.ply layout)"
echo "  carve/cloud.ply.vis                   the images that see each point (COLMAP fused.ply.vis format)"
echo "  carve/mesh.ply                        smooth welded mesh, coloured from the photos"
echo "  carve/mesh.glb, mesh.obj (+ .mtl, _texture.png)  the same mesh textured from the photos"
echo "  carve/report.html                     open in a browser: the model in 3D, the summary, the pictures"
echo "  carve/preview.png                     three photos beside the mesh drawn from their cameras, and views from outside them"
echo "  carve/fused.ply, fused.ply.vis, sparse/  the same cloud under COLMAP's dense-workspace names, and the model"
echo "  carve/report.json, convergence.csv    statistics, timings per stage, carving curve"
echo "  carve/compare.json                    accuracy, completeness, F-score against truth.ply"
echo "Open $out/carve/report.html in a browser; the PLY files in MeshLab, CloudCompare or Open3D (e.g. meshlab $out/carve/mesh.ply); mesh.glb in Blender."
