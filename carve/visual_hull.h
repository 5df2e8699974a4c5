#pragma once

#include <cstdint>
#include <vector>

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

}  // namespace raycarve
