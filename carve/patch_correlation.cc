#include "carve/patch_correlation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace raycarve {
namespace {

constexpr int kNumSamples = PatchCorrelation::kSamples * PatchCorrelation::kSamples;
using Pattern = std::array<double, kNumSamples>;

// Grey (mean of R, G, B) at COLMAP pixel (x, y), bilinear over cv::Mat cells; false outside the
// image or on pixels beyond the photo's frame.
bool SampleGrey(const CalibratedView& view, double x, double y, double* grey) {
  const double col = x - 0.5, row = y - 0.5;
  const int c0 = static_cast<int>(std::floor(col)), r0 = static_cast<int>(std::floor(row));
  if (c0 < 0 || r0 < 0 || c0 + 1 >= view.width || r0 + 1 >= view.height) return false;
  const double fc = col - c0, fr = row - r0;
  double value = 0.0;
  for (int dr = 0; dr < 2; ++dr) {
    const uint8_t* rgb = view.image.ptr<uint8_t>(r0 + dr);
    const uint8_t* valid = view.valid.empty() ? nullptr : view.valid.ptr<uint8_t>(r0 + dr);
    for (int dc = 0; dc < 2; ++dc) {
      const int c = c0 + dc;
      if (valid != nullptr && valid[c] == 0) return false;
      const double weight = (dr ? fr : 1.0 - fr) * (dc ? fc : 1.0 - fc);
      value += weight * (rgb[3 * c] + rgb[3 * c + 1] + rgb[3 * c + 2]) / 3.0;
    }
  }
  *grey = value;
  return true;
}

}  // namespace

PatchCorrelation CorrelatePatches(const std::vector<CalibratedView>& views,
                                  const Eigen::Vector3d& centre,
                                  double voxel_size,
                                  const std::vector<ViewColourStats>& stats) {
  PatchCorrelation result;
  Eigen::Vector3d facing = Eigen::Vector3d::Zero();
  for (const ViewColourStats& view : stats) {
    if (view.count > 0) facing += (views[view.view].centre - centre).normalized();
  }
  if (facing.norm() < 1e-9) return result;
  facing.normalize();
  // Two unit vectors spanning the plane that faces the views.
  const Eigen::Vector3d helper =
      std::abs(facing.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = facing.cross(helper).normalized();
  const Eigen::Vector3d v = facing.cross(u);
  const double step = PatchCorrelation::kPatchVoxels * voxel_size / (PatchCorrelation::kSamples - 1);
  const double half = 0.5 * (PatchCorrelation::kSamples - 1);

  std::vector<std::pair<Pattern, double>> patterns;  // unit-norm, zero-mean; weight
  for (const ViewColourStats& view_stats : stats) {
    if (view_stats.count == 0) continue;
    const CalibratedView& view = views[view_stats.view];
    Pattern grey;
    bool inside = true;
    for (int i = 0; i < PatchCorrelation::kSamples && inside; ++i) {
      for (int j = 0; j < PatchCorrelation::kSamples; ++j) {
        const Eigen::Vector3d point = centre + ((i - half) * step) * u + ((j - half) * step) * v;
        const Eigen::Vector3d pixel = view.P * point.homogeneous();
        if (pixel.z() <= 0.0 ||
            !SampleGrey(view, pixel.x() / pixel.z(), pixel.y() / pixel.z(),
                        &grey[i * PatchCorrelation::kSamples + j])) {
          inside = false;
          break;
        }
      }
    }
    if (!inside) continue;
    double mean = 0.0;
    for (double g : grey) mean += g;
    mean /= kNumSamples;
    double variance = 0.0;
    for (double& g : grey) {
      g -= mean;
      variance += g * g;
    }
    if (std::sqrt(variance / kNumSamples) < PatchCorrelation::kMinTexture) continue;
    const double norm = std::sqrt(variance);
    for (double& g : grey) g /= norm;
    patterns.emplace_back(grey, static_cast<double>(view_stats.count));
  }
  result.textured_views = static_cast<int>(patterns.size());
  if (patterns.size() < 2) return result;
  result.textured = true;
  Pattern sum{};
  for (const auto& [pattern, weight] : patterns) {
    for (int k = 0; k < kNumSamples; ++k) sum[k] += weight * pattern[k];
  }
  // Each view against the others' weighted mean pattern (leave one out: with two views this is
  // their NCC).
  std::vector<std::pair<double, double>> scores;  // (NCC, weight)
  for (const auto& [pattern, weight] : patterns) {
    double dot = 0.0, others_norm = 0.0;
    for (int k = 0; k < kNumSamples; ++k) {
      const double other = sum[k] - weight * pattern[k];
      dot += pattern[k] * other;
      others_norm += other * other;
    }
    scores.emplace_back(others_norm > 0.0 ? dot / std::sqrt(others_norm) : 0.0, weight);
  }
  std::sort(scores.begin(), scores.end());
  const size_t dropped = scores.size() / 4;
  double weighted = 0.0, weights = 0.0;
  for (size_t k = dropped; k < scores.size(); ++k) {
    weighted += scores[k].first * scores[k].second;
    weights += scores[k].second;
  }
  result.score = weighted / weights;
  return result;
}

}  // namespace raycarve
