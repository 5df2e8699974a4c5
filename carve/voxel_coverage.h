#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/calibrated_view.h"
#include "carve/footprint.h"
#include "carve/voxel_grid.h"

namespace raycarve {

// An exact rasteriser of voxels into one view: the pixels whose centre ray passes through a
// voxel's cube (its true projection, not the footprint's bounding box), with the depth at which
// the ray enters it. This is how GVC renders item buffers and how GVC-LDI builds its layered
// depth images; the rays are the ones ray casting steps (camera centre through pixel centre), so
// the three methods agree on which voxel a pixel sees.
//
// Only usable pixels are drawn: those with photo data (view.valid) and, when the view has a
// mask, on the object, as for ray casting.
class VoxelCoverage {
 public:
  // `view` must outlive this object.
  VoxelCoverage(const CalibratedView& view, const VoxelGrid& grid);

  int width() const { return width_; }
  int height() const { return height_; }

  // Calls visit(pixel, depth) for every usable pixel (row * width + col) whose ray enters
  // `voxel`, row by row; depth is the ray parameter at entry (grid units along the pixel's
  // direction: comparable only between voxels of the same pixel).
  template <typename Visit>
  void ForEach(const Eigen::Vector3i& voxel, Visit&& visit) const;

 private:
  const CalibratedView& view_;
  VoxelGrid grid_;
  Eigen::Matrix3d grid_from_pixel_;  // R^T K^-1 in voxel units
  Eigen::Vector3d centre_grid_;
  int width_;
  int height_;
  cv::Mat usable_;  // CV_8UC1, non-zero where a pixel has a ray
};

template <typename Visit>
void VoxelCoverage::ForEach(const Eigen::Vector3i& voxel, Visit&& visit) const {
  const Footprint footprint = ComputeFootprint(view_.P, width_, height_, grid_, voxel);
  if (footprint.empty()) return;
  const Eigen::Vector3d low = voxel.cast<double>() - centre_grid_;
  const Eigen::Vector3d high = low + Eigen::Vector3d::Ones();
  for (int row = footprint.row_min; row <= footprint.row_max; ++row) {
    const uint8_t* usable = usable_.ptr<uint8_t>(row);
    const Eigen::Vector3d row_start =
        grid_from_pixel_ * Eigen::Vector3d(footprint.col_min + 0.5, row + 0.5, 1.0);
    for (int col = footprint.col_min; col <= footprint.col_max; ++col) {
      if (usable[col] == 0) continue;
      const Eigen::Vector3d d = row_start + (col - footprint.col_min) * grid_from_pixel_.col(0);
      // Slab test of the ray centre + t d (t > 0) against the cube, in grid units.
      double t_enter = 0.0, t_exit = INFINITY;
      bool hit = true;
      for (int axis = 0; axis < 3 && hit; ++axis) {
        if (d[axis] == 0.0) {
          hit = low[axis] <= 0.0 && 0.0 < high[axis];
          continue;
        }
        double t0 = low[axis] / d[axis], t1 = high[axis] / d[axis];
        if (t0 > t1) std::swap(t0, t1);
        t_enter = std::max(t_enter, t0);
        t_exit = std::min(t_exit, t1);
        hit = t_enter < t_exit;
      }
      if (hit) visit(row * width_ + col, t_enter);
    }
  }
}

}  // namespace raycarve
