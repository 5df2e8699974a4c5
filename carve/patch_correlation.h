#pragma once

#include <vector>

#include <Eigen/Core>

#include "calib/calibrated_view.h"
#include "carve/consistency.h"
#include "carve/voxel_grid.h"

namespace raycarve {

// How well the views that see a voxel agree on the pattern of the surface there, not only on its
// mean colour: normalised cross-correlation (NCC) of small patches, as multi-view stereo scores a
// depth hypothesis.
//
// A square patch of kSamples x kSamples points on the plane through the voxel's centre that faces
// the mean direction to the views' centres, kPatchVoxels voxels wide, is projected into every view
// that sees the voxel and sampled bilinearly (grey: the mean of R, G and B). On the true surface
// the samples of every view show the same surface points, so the patterns agree up to a gain and
// an offset per view (exposure, white balance: NCC ignores both); a voxel in front of a textured
// surface shows each view a different part of it. A view whose patch has a grey standard deviation
// below kMinTexture is untextured (NCC is undefined there and its noise dominates); the score uses
// only textured views, and needs at least two.
//
// Score: each textured view's NCC against the mean of all textured views' normalised patterns,
// then the mean over the views without the worst quarter (so that a minority of views with a
// highlight or an occluder the volume does not hold do not veto), weighted by the voxel's visible
// pixels in the view. Cost: kSamples^2 bilinear samples per view.
struct PatchCorrelation {
  static constexpr int kSamples = 5;
  static constexpr double kPatchVoxels = 2.0;
  static constexpr double kMinTexture = 4.0;

  int textured_views = 0;
  bool textured = false;  // at least two textured views: `score` is defined
  double score = 1.0;     // in [-1, 1]; 1 where not textured
  // 1 - score: the error the patch test holds to its threshold (0 = perfect agreement, up to 2).
  double error() const { return 1.0 - score; }
};

// The patch correlation of the voxel at `centre` (world, in a grid of voxel size `voxel_size`)
// over the views of `stats` with a non-zero count (indices into `views`, weights their counts).
PatchCorrelation CorrelatePatches(const std::vector<CalibratedView>& views,
                                  const Eigen::Vector3d& centre,
                                  double voxel_size,
                                  const std::vector<ViewColourStats>& stats);

}  // namespace raycarve
