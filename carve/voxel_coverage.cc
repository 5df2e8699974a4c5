#include "carve/voxel_coverage.h"

#include <glog/logging.h>

namespace raycarve {

VoxelCoverage::VoxelCoverage(const CalibratedView& view, const VoxelGrid& grid)
    : view_(view),
      grid_(grid),
      grid_from_pixel_(view.cam_from_world.rotation.toRotationMatrix().transpose() *
                       view.K.inverse() / grid.voxel_size()),
      centre_grid_((view.centre - grid.origin()) / grid.voxel_size()),
      width_(view.width),
      height_(view.height) {
  CHECK(view.valid.empty() || (view.valid.cols == width_ && view.valid.rows == height_));
  usable_ = view.valid.empty() ? cv::Mat(height_, width_, CV_8UC1, cv::Scalar(255))
                               : view.valid.clone();
  if (!view.mask.empty()) usable_ &= view.mask;
}

}  // namespace raycarve
