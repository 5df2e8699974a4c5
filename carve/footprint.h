#pragma once

#include <Eigen/Core>

#include "carve/voxel_grid.h"

namespace raycarve {

// The pixels a voxel may cover in a view: the bounding box of its 8 projected corners, clipped to
// the image (the seed paper's footprint). Pixels are cv::Mat cells whose centre (COLMAP
// coordinates (col + 0.5, row + 0.5)) lies inside the box, from (col_min, row_min) to
// (col_max, row_max) inclusive; empty when col_min > col_max or row_min > row_max.
struct Footprint {
  int col_min = 0;
  int col_max = -1;
  int row_min = 0;
  int row_max = -1;

  bool empty() const { return col_min > col_max || row_min > row_max; }
  int area() const { return empty() ? 0 : (col_max - col_min + 1) * (row_max - row_min + 1); }
};

// `P` maps world points to homogeneous COLMAP pixels. A voxel with a corner at or behind the
// camera's plane gets an empty footprint (the view is not used for it). With `span` > 1, the
// footprint of the cube of span x span x span voxels whose first voxel is `voxel` (it holds the
// footprint of each of them); the cube may reach beyond the grid.
Footprint ComputeFootprint(const Eigen::Matrix<double, 3, 4>& P,
                           int width,
                           int height,
                           const VoxelGrid& grid,
                           const Eigen::Vector3i& voxel,
                           int span = 1);

}  // namespace raycarve
