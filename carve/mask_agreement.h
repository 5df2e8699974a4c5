#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "calib/calibrated_view.h"

namespace raycarve {

struct MaskAgreementOptions {
  int resolution = 64;           // the voting grid over the box: voxels along its longest side
  int min_background_views = 2;  // views that must show a voxel on background to drop it
  // A background pixel becomes object only where its colour lies within this RGB distance of
  // the median colour the other views show, on their object, at its ray's first hull voxel.
  double colour_tolerance = 30.0;
  int num_threads = -1;  // < 1: one per core
};

struct MaskAgreementStatistics {
  int views = 0;            // masked views that took part (none below 3: no majority to form)
  int64_t hull_voxels = 0;  // voxels of the voting hull
  // Per view (all views, in order; 0 for views without a mask): background pixels made object,
  // and the object pixels before.
  std::vector<int64_t> added;
  std::vector<int64_t> object_before;
  double seconds = 0.0;
  int64_t TotalAdded() const;
  int64_t TotalObjectBefore() const;
  // One line: views, the share of object pixels added, the view changed most (by `names`).
  std::string Summary(const std::vector<std::string>& names) const;
};

// Makes the views' object masks agree where one photo's colours failed. A mask made from a
// photo's colours alone loses the object where it shares a colour with the backdrop (a white
// object against a white-to-blue gradient: holes, or most of the object in one photo), and the
// visual hull, which trusts every mask, then cuts the model in every photo. Here the views vote:
// 1. the voting hull: the voxels of the box (at `options.resolution`) that fewer than
//    `min_background_views` masked views show entirely on background (CarveVisualHull's test),
//    so that one photo's mask alone cannot cut it;
// 2. in each masked view, a background pixel whose ray meets the voting hull at least a voxel's
//    width (in that view's pixels, at the box's centre) inside the hull's outline becomes
//    object, where its colour is what the 8 nearest masked views show there: at one of the
//    points every half voxel over the hull's first three voxels along its ray, fewer than
//    `min_background_views` of them show the point on background, two or more on their object,
//    and the pixel lies within `colour_tolerance` of their median colour. A pixel that shows
//    something else, the backdrop through a gap only this view sees (which the voting hull
//    keeps), stays background.
// Object pixels stay object, and each mask keeps its own outline. Views without a mask, and
// every view when fewer than 3 have one, are left as they are.
MaskAgreementStatistics AgreeMasks(const Eigen::AlignedBox3d& box,
                                   const MaskAgreementOptions& options,
                                   std::vector<CalibratedView>* views);

}  // namespace raycarve
