#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include <opencv2/core.hpp>

#include "calib/calibrated_view.h"
#include "export/point_renderer.h"

namespace raycarve {
namespace exporter {

// How well a rendering of the model reproduces a photo the model was not made from.
struct HoldoutScore {
  double psnr = 0.0;            // dB over the scored pixels (RGB, peak 255)
  int scored_pixels = 0;        // the union of the rendered silhouette and the photo's object
                                // mask when it has one; otherwise every pixel with photo data
  double silhouette_iou = -1.0; // rendered silhouette vs the photo's mask; -1 without a mask
  // Structural similarity (Wang, Bovik, Sheikh and Simoncelli 2004: Gaussian window of sigma 1.5
  // pixels, C1 = (0.01 * 255)^2, C2 = (0.03 * 255)^2), per RGB channel, its map averaged over the
  // scored pixels and the channels: 1 for the photo itself. Unlike PSNR it does not prefer a flat
  // mean colour to the photo's pattern drawn a pixel or two off.
  double ssim = 0.0;
};

// The SSIM map of two images of one size (CV_8UC3), the mean of the channels' maps (CV_32FC1).
cv::Mat SsimMap(const cv::Mat& a, const cv::Mat& b);

// Scores `rendering` against `view` (its undistorted photo, valid pixels and mask).
HoldoutScore ScoreRendering(const Rendering& rendering, const CalibratedView& view);

// The PSNR of `view`'s photo against itself with every aligned block x block square of pixels
// replaced by its mean (the last row and column of blocks may be partial), over the object
// (mask and valid pixels; every valid pixel without a mask). What a model giving each block one
// colour would score with perfect geometry: an estimate of the most a voxel model can reach where
// a voxel covers about `block` pixels across (real voxels project to hexagons and mix several
// views, so they would do worse). Infinite for a photo that is uniform within every block.
double BlockMeanPsnr(const CalibratedView& view, int block);

// photo | render | error (absolute difference, amplified 4x), side by side, RGB.
cv::Mat SideBySide(const Rendering& rendering, const CalibratedView& view);

// Whether a model's depth agrees with sparse points that a held-out view saw (and two or more
// other photos triangulated): a measure that a model cannot win by painting a backdrop on the
// volume's walls. Each point inside the view's frame and in front of it is looked up in the
// rendering's depth buffer at its pixel: `at_depth` where the model is drawn within `tolerance`
// of the point's depth, `hidden` where it is drawn nearer by more than that (something the
// photo did not see stands in front), `behind` where it is drawn farther (a hole in the model
// there), the rest with nothing drawn there.
struct SparseDepthAgreement {
  int points = 0;
  int at_depth = 0;
  int hidden = 0;
  int behind = 0;
  double AtDepthShare() const { return Share(at_depth); }
  double HiddenShare() const { return Share(hidden); }
  double BehindShare() const { return Share(behind); }
  double UndrawnShare() const { return Share(points - at_depth - hidden - behind); }

 private:
  double Share(int count) const { return points > 0 ? static_cast<double>(count) / points : 0.0; }
};
// One point's verdict, for a look at where the model and the points disagree.
enum class SparseDepthVerdict { kAtDepth, kHidden, kBehind, kUndrawn };
const char* SparseDepthVerdictName(SparseDepthVerdict verdict);
struct SparsePointDepth {
  Eigen::Vector3d point;
  double depth = 0.0;        // the point's, along the view's axis
  double drawn_depth = 0.0;  // the model's at the point's pixel (infinite where nothing is drawn)
  SparseDepthVerdict verdict = SparseDepthVerdict::kUndrawn;
};
// `records`, where given, receives every point counted, in the order given.
SparseDepthAgreement MeasureSparseDepth(const Rendering& rendering, const CalibratedView& view,
                                        const std::vector<Eigen::Vector3d>& points,
                                        double tolerance,
                                        std::vector<SparsePointDepth>* records = nullptr);

}  // namespace exporter
}  // namespace raycarve
