// Uses raycarve's installed libraries: generates a small scene (samples), builds its views with
// their exact masks (calib), carves it (carve) and writes the surface voxels as a coloured cloud
// (export).   raycarve_consumer OUTPUT.ply
#include <cstdio>
#include <exception>
#include <vector>

#include "calib/calibrated_view.h"
#include "carve/carver.h"
#include "export/point_cloud_io.h"
#include "samples/synthetic_scene.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT.ply\n", argv[0]);
    return 1;
  }
  try {
    raycarve::SyntheticSceneOptions scene_options;
    scene_options.num_views = 6;
    scene_options.width = 96;
    scene_options.height = 72;
    scene_options.backdrop = raycarve::Backdrop::kUniform;
    const raycarve::SyntheticScene scene = raycarve::GenerateSyntheticScene(scene_options);
    std::vector<raycarve::CalibratedView> views;
    for (const auto& [id, image] : scene.reconstruction.images) {
      views.push_back(raycarve::MakeCalibratedView(scene.reconstruction.cameras.at(image.camera_id),
                                                   image, scene.photos.at(id), image.name,
                                                   scene.masks.at(id), image.name + ".png"));
    }
    raycarve::CarveOptions options;
    options.resolution = 32;
    options.threshold = 60.0;
    const raycarve::CarveResult result = raycarve::CarveVolume(views, scene.object_box, options);
    std::vector<raycarve::exporter::ColouredPoint> points;
    for (const raycarve::ColouredVoxel& voxel : result.surface) {
      raycarve::exporter::ColouredPoint point;
      const raycarve::VoxelGrid& grid = result.volume.grid();
      point.xyz = grid.Centre(grid.Voxel(voxel.index)).cast<float>();
      point.rgb = raycarve::exporter::ToRgb(voxel.colour);
      points.push_back(point);
    }
    raycarve::exporter::WritePointCloudPly(points, argv[1]);
    std::printf("consumer: %lld voxels carved, %zu surface points written to %s\n",
                static_cast<long long>(result.statistics.carved), points.size(), argv[1]);
    return points.empty() ? 1 : 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "consumer: %s\n", error.what());
    return 1;
  }
}
