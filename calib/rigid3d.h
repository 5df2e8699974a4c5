#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace raycarve {

// A rigid transform target_from_source: x_target = rotation * x_source + translation.
// COLMAP's image pose (QW QX QY QZ TX TY TZ) is cam_from_world in this form.
struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return rotation * x + translation; }

  Rigid3d Inverse() const {
    Rigid3d inverse;
    inverse.rotation = rotation.inverse();
    inverse.translation = -(inverse.rotation * translation);
    return inverse;
  }

  // The 3x4 matrix [R | t].
  Eigen::Matrix<double, 3, 4> ToMatrix() const {
    Eigen::Matrix<double, 3, 4> matrix;
    matrix.leftCols<3>() = rotation.toRotationMatrix();
    matrix.col(3) = translation;
    return matrix;
  }
};

}  // namespace raycarve
