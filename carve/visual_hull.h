#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "calib/calibrated_view.h"
#include "carve/volume.h"

namespace raycarve {

struct VisualHullStatistics {
  int views_with_masks = 0;
  int64_t carved = 0;
  double seconds = 0.0;
};

// The silhouette pre-carve: carves every solid voxel of `volume` that some view with a mask
// (view.mask not empty; non-zero = object) shows entirely on background: its footprint lies
// inside that view's image and holds no object pixel (of the silhouette grown by one pixel)
// among the pixels with photo data (view.valid). A voxel that a view sees only partly, or not at
// all, is not judged by it, so the result contains the visual hull of the masks. Cost: one
// footprint per voxel per masked view, answered in constant time from integral images; voxels
// are judged on `num_threads` threads (< 1: one per hardware thread), with the same result.
// With `min_background_views` > 1 a voxel is carved only where that many views show it entirely
// on background: a hull that one view's wrong mask cannot cut (AgreeMasks).
VisualHullStatistics CarveVisualHull(const std::vector<CalibratedView>& views,
                                     Volume* volume,
                                     int num_threads = 1,
                                     int min_background_views = 1);

// Where the masks put the object inside `box`: the visual hull of `views`' masks (CarveVisualHull
// with `min_background_views`) on a grid of `resolution` voxels along the box's longest side,
// less what fewer than two photos frame (their centres), cut into 26-connected pieces; the box
// of the piece that holds the most of the sparse `points` and of those that hold at least
// kHullPieceMinPoints at a density (points per voxel) of at least kHullPieceDensityShare of its
// own (every piece when no point is in the hull), grown by one of those voxels. A voxel only partly on the
// object stays, so the hull holds the object and the box holds the hull. `box` itself when no
// view has a mask; empty when the masks leave nothing.
constexpr int kHullPieceMinPoints = 3;
constexpr double kHullPieceDensityShare = 0.1;
struct HullBox {
  Eigen::AlignedBox3d box;
  int64_t voxels = 0;    // the coarse hull's voxels in the pieces kept
  int points = 0;        // sparse points in them
  int pieces = 0;        // pieces kept
  int pieces_left = 0;   // pieces with too few sparse points for their size
  double seconds = 0.0;
};
HullBox VisualHullBox(const std::vector<CalibratedView>& views,
                      const std::vector<Eigen::Vector3d>& points,
                      const Eigen::AlignedBox3d& box,
                      int resolution,
                      int num_threads,
                      int min_background_views);

}  // namespace raycarve
