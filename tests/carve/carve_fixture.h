#pragma once

#include <algorithm>
#include <map>
#include <vector>

#include "calib/calibrated_view.h"
#include "carve/carver.h"
#include "carve/surface_evidence.h"
#include "carve/visibility.h"
#include "carve/volume.h"
#include "samples/synthetic_scene.h"
#include "tests/scene_options.h"

namespace raycarve {
namespace testing {

// A small generated scene with 2,000 sparse points and a patchwork sky.
inline SyntheticScene Scene(int views, int width, int height) {
  return GenerateSyntheticScene(SceneOptions(views, width, height, false, 2000));
}

// Carve options with the grid's resolution and a fixed colour threshold.
inline CarveOptions Options(int resolution, double threshold) {
  CarveOptions options;
  options.resolution = resolution;
  options.threshold = threshold;
  return options;
}

// The synthetic scene's views as carving inputs (undistorted, pinhole), with the scene's exact
// object masks when `with_masks`.
inline std::vector<CalibratedView> SceneViews(const SyntheticScene& scene, bool with_masks = false) {
  std::vector<CalibratedView> views;
  for (const auto& [image_id, image] : scene.reconstruction.images) {
    views.push_back(MakeCalibratedView(scene.reconstruction.cameras.at(image.camera_id), image,
                                       scene.photos.at(image_id), image.name,
                                       with_masks ? scene.masks.at(image_id) : cv::Mat(),
                                       image.name + ".png"));
  }
  return views;
}

// The scene's sparse points seen by at least `min_track` views as surface evidence (views indexed
// as SceneViews orders them).
inline std::vector<SurfacePoint> SceneSurfacePoints(const SyntheticScene& scene, int min_track = 3) {
  std::map<image_t, int> index;
  for (const auto& [id, image] : scene.reconstruction.images) {
    const int next = static_cast<int>(index.size());
    index[id] = next;
  }
  std::vector<SurfacePoint> points;
  for (const auto& [id, point3D] : scene.reconstruction.points3D) {
    SurfacePoint point;
    point.xyz = point3D.xyz;
    for (const TrackElement& element : point3D.track) point.views.push_back(index.at(element.image_id));
    std::sort(point.views.begin(), point.views.end());
    point.views.erase(std::unique(point.views.begin(), point.views.end()), point.views.end());
    if (static_cast<int>(point.views.size()) >= min_track) points.push_back(point);
  }
  return points;
}

// Brute force: whether the ray from `origin` along `direction` (t > 0) passes through the
// voxel's cube with non-zero length, and the ray parameter where it enters.
inline bool RayEntersVoxel(const VoxelGrid& grid, const Eigen::Vector3i& voxel,
                           const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                           double* t_enter) {
  const Eigen::Vector3d lo = grid.Corner(voxel, 0), hi = grid.Corner(voxel, 7);
  double t0 = 0.0, t1 = 1e300;
  for (int axis = 0; axis < 3; ++axis) {
    double a = (lo[axis] - origin[axis]) / direction[axis];
    double b = (hi[axis] - origin[axis]) / direction[axis];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  *t_enter = t0;
  return t1 - t0 > 1e-9;
}

// Brute force: the nearest solid voxel of `volume` on the ray from `origin` along `direction`
// (only voxels the ray passes through with non-zero length), or -1.
inline int64_t NearestSolidVoxel(const Volume& volume,
                                 const Eigen::Vector3d& origin,
                                 const Eigen::Vector3d& direction) {
  const VoxelGrid& grid = volume.grid();
  int64_t best = -1;
  double best_t = 1e300;
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (!volume.IsSolid(index)) continue;
    double t = 0.0;
    if (RayEntersVoxel(grid, grid.Voxel(index), origin, direction, &t) && t < best_t) {
      best_t = t;
      best = index;
    }
  }
  return best;
}

// Vis(V) as (view, pixel) pairs.
inline std::vector<std::pair<uint32_t, uint32_t>> VisOf(Visibility* visibility, int64_t voxel) {
  std::vector<PixelRef> vis;
  visibility->ComputeVis(voxel, &vis);
  std::vector<std::pair<uint32_t, uint32_t>> pixels;
  for (const PixelRef& ref : vis) pixels.emplace_back(ref.view, ref.pixel);
  return pixels;
}

inline Eigen::Vector3d PixelDirection(const CalibratedView& view, int pixel) {
  const int row = pixel / view.width, col = pixel % view.width;
  return view.WorldFromPixel() *
         Eigen::Vector3d(col + 0.5, row + 0.5, 1.0);
}

}  // namespace testing
}  // namespace raycarve
