#include "export/volume_renderer.h"

#include <algorithm>
#include <limits>

#include <glog/logging.h>

#include "carve/block_occupancy.h"
#include "carve/ray_image.h"

namespace raycarve {
namespace exporter {
namespace {

// The colour of a surface voxel, from `surface` (sorted by index); nullptr when it has none.
const ColouredVoxel* Find(const std::vector<ColouredVoxel>& surface, int64_t index) {
  const auto it = std::lower_bound(
      surface.begin(), surface.end(), index,
      [](const ColouredVoxel& voxel, int64_t wanted) { return voxel.index < wanted; });
  return it != surface.end() && it->index == index ? &*it : nullptr;
}

// The mean colour of the coloured surface voxels among the 26 neighbours of `index` (black when
// none).
Eigen::Vector3f NeighbourColour(const VoxelGrid& grid,
                                const std::vector<ColouredVoxel>& surface,
                                int64_t index) {
  const Eigen::Vector3i centre = grid.Voxel(index);
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  int count = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const Eigen::Vector3i neighbour = centre + Eigen::Vector3i(dx, dy, dz);
        if (neighbour == centre || !grid.Contains(neighbour)) continue;
        const ColouredVoxel* coloured = Find(surface, grid.Index(neighbour));
        if (coloured == nullptr || coloured->num_pixels == 0) continue;
        sum += coloured->colour;
        ++count;
      }
    }
  }
  return count > 0 ? Eigen::Vector3f(sum / count) : Eigen::Vector3f::Zero();
}

}  // namespace

VolumeRendering RenderVolume(const Volume& volume,
                             const std::vector<ColouredVoxel>& surface,
                             const CalibratedView& view) {
  CHECK(std::is_sorted(surface.begin(), surface.end(),
                       [](const ColouredVoxel& a, const ColouredVoxel& b) {
                         return a.index < b.index;
                       }));
  VolumeRendering rendering;
  rendering.image = cv::Mat(view.height, view.width, CV_8UC3, cv::Scalar::all(0));
  rendering.silhouette = cv::Mat(view.height, view.width, CV_8UC1, cv::Scalar(0));
  rendering.depth = cv::Mat(view.height, view.width, CV_32FC1,
                            cv::Scalar(std::numeric_limits<float>::infinity()));
  const VoxelGrid& grid = volume.grid();
  const Eigen::Matrix3d world_from_pixel = view.WorldFromPixel();
  RayImage rays(grid, world_from_pixel, view.centre, view.width, view.height);
  const BlockOccupancy blocks(volume);
  rays.Initialise(volume, &blocks);
  for (int pixel = 0; pixel < view.width * view.height; ++pixel) {
    const int64_t index = rays.CurrentVoxel(pixel);
    if (index == RayImage::kNoVoxel) continue;
    const ColouredVoxel* voxel = Find(surface, index);
    Eigen::Vector3f colour;
    if (voxel != nullptr && voxel->num_pixels > 0) {
      colour = voxel->colour;
    } else {
      colour = NeighbourColour(grid, surface, index);
      ++rendering.uncoloured_pixels;
    }
    const int row = pixel / view.width, col = pixel % view.width;
    for (int c = 0; c < 3; ++c) {
      rendering.image.at<cv::Vec3b>(row, col)[c] =
          static_cast<uint8_t>(std::clamp(std::lround(colour[c]), 0L, 255L));
    }
    rendering.silhouette.at<uint8_t>(row, col) = 255;
    rendering.depth.at<float>(row, col) =
        static_cast<float>(view.Depth(grid.Centre(grid.Voxel(index))));
  }
  return rendering;
}

}  // namespace exporter
}  // namespace raycarve
