#include "calib/photos_up.h"

#include <algorithm>
#include <array>

#include <Eigen/Geometry>

namespace raycarve {

bool PhotosUp::Known() const {
  return photos > 0 && agreement >= kMinPhotosUpAgreement &&
         held_alike >= kMinPhotosHeldAlike * photos;
}

PhotosUp EstimatePhotosUp(const std::vector<Rigid3d>& cams_from_world) {
  PhotosUp estimate;
  estimate.photos = static_cast<int>(cams_from_world.size());
  if (cams_from_world.empty()) return estimate;
  // Each photo's frame sides in the world (the rows of the rotation are the camera's axes): the
  // top (-y) first.
  std::vector<std::array<Eigen::Vector3d, 4>> sides;
  std::array<Eigen::Vector3d, 4> means;
  means.fill(Eigen::Vector3d::Zero());
  for (const Rigid3d& pose : cams_from_world) {
    const Eigen::Matrix3d rotation = pose.rotation.toRotationMatrix();
    sides.push_back({-rotation.row(1).transpose(), rotation.row(1).transpose(),
                     rotation.row(0).transpose(), -rotation.row(0).transpose()});
    for (int k = 0; k < 4; ++k) means[k] += sides.back()[k];
  }
  Eigen::Vector3d mean = *std::max_element(
      means.begin(), means.end(),
      [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.norm() < b.norm(); });
  mean /= static_cast<double>(sides.size());
  for (int round = 0; round < 2 && mean.norm() > 1e-9; ++round) {
    const Eigen::Vector3d towards = mean.normalized();
    mean.setZero();
    std::array<int, 4> held = {0, 0, 0, 0};
    for (const std::array<Eigen::Vector3d, 4>& photo : sides) {
      int nearest = 0;
      for (int k = 1; k < 4; ++k) {
        if (photo[k].dot(towards) > photo[nearest].dot(towards)) nearest = k;
      }
      ++held[nearest];
      mean += photo[nearest];
    }
    mean /= static_cast<double>(sides.size());
    estimate.held_alike = *std::max_element(held.begin(), held.end());
    estimate.turned = estimate.photos - held[0];
  }
  estimate.agreement = mean.norm();
  if (mean.norm() > 1e-9) estimate.up = mean.normalized();
  return estimate;
}

}  // namespace raycarve
