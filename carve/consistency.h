#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace raycarve {

// The colour statistics of a voxel's visible pixels in one view (RGB, 0-255).
struct ViewColourStats {
  int view = 0;
  int count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_squares = Eigen::Vector3d::Zero();

  void Add(const Eigen::Vector3d& rgb) {
    ++count;
    sum += rgb;
    sum_squares += rgb.cwiseProduct(rgb);
  }
};

enum class ConsistencyMethod {
  kMeanColour,         // the seed paper's weighted difference of per-view mean colours
  kStandardDeviation,  // Seitz and Dyer's standard deviation of all visible pixels
  // The mean-colour test, and where the views see texture also the agreement of their patterns
  // (patch_correlation.h: normalised cross-correlation, blind to exposure and white balance).
  kPatchCorrelation,
};
std::string ConsistencyMethodToString(ConsistencyMethod method);
// Returns false when `text` names no method.
bool ConsistencyMethodFromString(const std::string& text, ConsistencyMethod* method);

struct Consistency {
  bool judged = false;      // seen by at least min_views views; otherwise kept unjudged
  bool consistent = true;   // false: carve
  double error = 0.0;       // the method's error (RGB units, 0-255)
  double threshold = 0.0;   // the threshold it was held to (with the adaptive allowance)
  Eigen::Vector3d colour = Eigen::Vector3d::Zero();  // the voxel's colour: pixel-weighted mean
  int num_views = 0;
  int num_pixels = 0;
  // kPatchCorrelation: 1 - NCC of the views' patterns, or -1 where not measured (not textured,
  // or already inconsistent by colour).
  double pattern_error = -1.0;
};

// How far a voxel's visible pixels are from agreeing on one colour: the interface a new
// photo-consistency measure implements. Inputs: the per-view statistics (views with count 0 are
// skipped), the pixel-weighted mean colour and the pixel count (> 0). Output: the error in RGB
// units.
class ConsistencyFunction {
 public:
  virtual ~ConsistencyFunction() = default;
  virtual double Error(const std::vector<ViewColourStats>& views,
                       const Eigen::Vector3d& mean,
                       int num_pixels) const = 0;
};

// The seed paper's test: per view j the mean m_j of its n_j pixels; m = sum n_j m_j / sum n_j;
// the error is sum n_j |m_j - m| / sum n_j with |.| the Euclidean norm in RGB.
// With `correct_view_count`, times sqrt(k / (k - 1)) for the k views with pixels: the means'
// distance from their own mean understates their spread by that factor (for k equal views it is
// exact: 0.71 for two views, 0.96 for twelve), so that a voxel seen by two or three views is
// judged on the same scale as one seen by ten, instead of passing more easily.
class MeanColourDifference : public ConsistencyFunction {
 public:
  explicit MeanColourDifference(bool correct_view_count = false)
      : correct_view_count_(correct_view_count) {}
  double Error(const std::vector<ViewColourStats>& views,
               const Eigen::Vector3d& mean,
               int num_pixels) const override;

 private:
  bool correct_view_count_ = false;
};

// Seitz and Dyer's test: the root mean square over the channels of the standard deviation of all
// visible pixels together.
class PooledStandardDeviation : public ConsistencyFunction {
 public:
  double Error(const std::vector<ViewColourStats>& views,
               const Eigen::Vector3d& mean,
               int num_pixels) const override;
};

std::unique_ptr<ConsistencyFunction> MakeConsistencyFunction(ConsistencyMethod method,
                                                             bool correct_view_count = false);

// Decides whether a voxel's visible pixels agree on one colour: inconsistent when the function's
// error exceeds `threshold` + `adaptive` x the voxel's within-view spread, or `spread_floor` x
// that spread where that is more; a voxel seen by fewer than `min_views` views is not judged and
// stays.
//
// The within-view spread is the pixel-weighted mean over views of each view's RGB standard
// deviation (the Euclidean norm of the per-channel deviations). A voxel on a texture edge shows
// both colours within each view, so its per-view means differ with the viewpoint even on the true
// surface; the allowance grows with that spread (Slabaugh et al.'s adaptive threshold), while a
// voxel whose views each see one uniform but different colour (empty space in front of a
// background) gets none. The floor allows the same without raising a threshold already above it.
class ConsistencyTest {
 public:
  ConsistencyTest(ConsistencyMethod method, double threshold, int min_views, double adaptive = 0.0,
                  bool correct_view_count = false, double spread_floor = 0.0);
  Consistency Evaluate(const std::vector<ViewColourStats>& views) const;

  // The within-view spread of `views` (RGB units; 0 without pixels).
  static double WithinViewSpread(const std::vector<ViewColourStats>& views);

 private:
  std::unique_ptr<ConsistencyFunction> function_;
  double threshold_;
  int min_views_;
  double adaptive_;
  double spread_floor_;
};

}  // namespace raycarve
