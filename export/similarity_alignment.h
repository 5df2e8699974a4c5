#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace raycarve {
namespace exporter {

// x -> scale * rotation * x + translation: how a COLMAP SfM frame (arbitrary origin, orientation
// and scale) maps onto a reference frame.
struct Similarity3 {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const {
    return scale * rotation * x + translation;
  }
};

struct AlignmentOptions {
  // Residuals (reference units) beyond which a pair counts as an outlier: the scale of the
  // robust (Cauchy) loss of the refinement, and the inlier test of the report. 0: 5% of the
  // reference points' spread (RMS distance to their centroid).
  double outlier_distance = 0.0;
};

struct Alignment {
  Similarity3 transform;
  int num_pairs = 0;
  int num_inliers = 0;
  double rms_before_refinement = 0.0;  // the closed form's RMS residual
  double rms = 0.0;                    // RMS residual of the inliers after refinement
  double max_inlier_residual = 0.0;
  double outlier_distance = 0.0;       // the one used
  std::string Summary() const;
};

// The similarity taking `source[i]` onto `target[i]`: Umeyama's closed form (least squares), then
// refined with Ceres under a Cauchy loss so that a few wrong pairs (a badly registered camera)
// do not pull it. Needs at least 3 pairs not on one line; throws InputError otherwise.
Alignment AlignPoints(const std::vector<Eigen::Vector3d>& source,
                      const std::vector<Eigen::Vector3d>& target,
                      const AlignmentOptions& options = AlignmentOptions());

}  // namespace exporter
}  // namespace raycarve
