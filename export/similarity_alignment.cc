#include "export/similarity_alignment.h"

#include <cmath>
#include <sstream>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/SVD>

#include "calib/input_error.h"

namespace raycarve {
namespace exporter {
namespace {

// Residual of one pair: scale * R(angle_axis) * source + translation - target.
struct PairResidual {
  PairResidual(const Eigen::Vector3d& source, const Eigen::Vector3d& target)
      : source_(source), target_(target) {}

  template <typename T>
  bool operator()(const T* log_scale, const T* angle_axis, const T* translation, T* residual) const {
    const T point[3] = {T(source_.x()), T(source_.y()), T(source_.z())};
    T rotated[3];
    ceres::AngleAxisRotatePoint(angle_axis, point, rotated);
    const T scale = exp(log_scale[0]);
    for (int i = 0; i < 3; ++i) residual[i] = scale * rotated[i] + translation[i] - T(target_[i]);
    return true;
  }

  Eigen::Vector3d source_;
  Eigen::Vector3d target_;
};

Similarity3 Umeyama(const std::vector<Eigen::Vector3d>& source,
                    const std::vector<Eigen::Vector3d>& target) {
  const int n = static_cast<int>(source.size());
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (int i = 0; i < n; ++i) {
    src.col(i) = source[i];
    dst.col(i) = target[i];
  }
  const Eigen::Matrix4d m = Eigen::umeyama(src, dst, /*with_scaling=*/true);
  Similarity3 result;
  const Eigen::Matrix3d sr = m.topLeftCorner<3, 3>();
  result.scale = std::cbrt(sr.determinant());
  result.rotation = sr / result.scale;
  result.translation = m.topRightCorner<3, 1>();
  return result;
}

double Rms(const std::vector<Eigen::Vector3d>& source, const std::vector<Eigen::Vector3d>& target,
           const Similarity3& transform) {
  double sum = 0.0;
  for (size_t i = 0; i < source.size(); ++i) sum += (transform(source[i]) - target[i]).squaredNorm();
  return std::sqrt(sum / source.size());
}

}  // namespace

std::string Alignment::Summary() const {
  std::ostringstream text;
  text.precision(4);
  text << "similarity from " << num_pairs << " pairs: scale " << transform.scale << ", "
       << num_inliers << " inliers within " << outlier_distance << ", RMS " << rms
       << " (closed form " << rms_before_refinement << "), largest inlier residual "
       << max_inlier_residual;
  return text.str();
}

Alignment AlignPoints(const std::vector<Eigen::Vector3d>& source,
                      const std::vector<Eigen::Vector3d>& target,
                      const AlignmentOptions& options) {
  if (source.size() != target.size()) {
    throw InputError("alignment: " + std::to_string(source.size()) + " source points but " +
                     std::to_string(target.size()) + " target points");
  }
  if (source.size() < 3) {
    throw InputError("alignment: needs at least 3 matched points (camera centres), got " +
                     std::to_string(source.size()));
  }
  for (const auto* points : {&source, &target}) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : *points) centroid += p;
    centroid /= static_cast<double>(points->size());
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& p : *points) scatter += (p - centroid) * (p - centroid).transpose();
    const Eigen::Vector3d spread = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvalues();
    if (!(spread(1) > 1e-12 * std::max(1.0, spread(2)))) {
      throw InputError("alignment: the matched points lie on one line (or one point); a "
                       "similarity is not determined");
    }
  }
  Alignment alignment;
  alignment.num_pairs = static_cast<int>(source.size());
  const Similarity3 closed = Umeyama(source, target);
  alignment.rms_before_refinement = Rms(source, target, closed);

  double outlier = options.outlier_distance;
  if (!(outlier > 0.0)) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : target) centroid += p;
    centroid /= static_cast<double>(target.size());
    double spread = 0.0;
    for (const Eigen::Vector3d& p : target) spread += (p - centroid).squaredNorm();
    outlier = 0.05 * std::sqrt(spread / target.size());
  }
  alignment.outlier_distance = outlier;

  double log_scale = std::log(closed.scale);
  double angle_axis[3];
  ceres::RotationMatrixToAngleAxis(
      ceres::ColumnMajorAdapter3x3(closed.rotation.data()), angle_axis);
  double translation[3] = {closed.translation.x(), closed.translation.y(), closed.translation.z()};
  ceres::Problem problem;
  for (size_t i = 0; i < source.size(); ++i) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PairResidual, 3, 1, 3, 3>(new PairResidual(source[i], target[i])),
        new ceres::CauchyLoss(outlier), &log_scale, angle_axis, translation);
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = 100;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);

  Similarity3& result = alignment.transform;
  result.scale = std::exp(log_scale);
  ceres::AngleAxisToRotationMatrix(angle_axis, ceres::ColumnMajorAdapter3x3(result.rotation.data()));
  result.translation = Eigen::Vector3d(translation[0], translation[1], translation[2]);
  double sum = 0.0;
  for (size_t i = 0; i < source.size(); ++i) {
    const double residual = (result(source[i]) - target[i]).norm();
    if (residual > outlier) continue;
    ++alignment.num_inliers;
    sum += residual * residual;
    alignment.max_inlier_residual = std::max(alignment.max_inlier_residual, residual);
  }
  alignment.rms = alignment.num_inliers > 0 ? std::sqrt(sum / alignment.num_inliers) : NAN;
  return alignment;
}

}  // namespace exporter
}  // namespace raycarve
