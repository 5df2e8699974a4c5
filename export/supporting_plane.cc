#include "export/supporting_plane.h"

#include <sstream>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/ransac.h>
#include <pcl/sample_consensus/sac_model_plane.h>

namespace raycarve {
namespace exporter {

std::string SupportingPlane::Summary() const {
  std::ostringstream text;
  text.precision(3);
  if (points < 20) return "no supporting plane (too few sparse points)";
  text << (found ? "a supporting plane" : "no supporting plane") << ": normal (" << normal.x()
       << ", " << normal.y() << ", " << normal.z() << "), " << 100.0 * on_plane_share
       << "% of " << points << " sparse points on it (within " << tolerance << "), "
       << 100.0 * below_share << "% below it, " << 100.0 * cameras_above_share
       << "% of the cameras above it";
  return text.str();
}

SupportingPlane FitSupportingPlane(const std::vector<Eigen::Vector3d>& points,
                                   const std::vector<Eigen::Vector3d>& cameras, double tolerance) {
  SupportingPlane plane;
  plane.points = static_cast<int>(points.size());
  plane.tolerance = tolerance;
  if (points.size() < 20 || !(tolerance > 0.0)) return plane;
  // Centred, so that single precision keeps the points' detail far from the origin.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d q = p - centre;
    cloud->push_back(pcl::PointXYZ(static_cast<float>(q.x()), static_cast<float>(q.y()),
                                   static_cast<float>(q.z())));
  }
  pcl::SampleConsensusModelPlane<pcl::PointXYZ>::Ptr model(
      new pcl::SampleConsensusModelPlane<pcl::PointXYZ>(cloud));  // fixed seed
  pcl::RandomSampleConsensus<pcl::PointXYZ> ransac(model, tolerance);
  ransac.setMaxIterations(1000);
  if (!ransac.computeModel()) return plane;
  pcl::Indices inliers;
  ransac.getInliers(inliers);
  Eigen::VectorXf coefficients;
  ransac.getModelCoefficients(coefficients);
  Eigen::VectorXf refined = coefficients;
  if (inliers.size() >= 3) model->optimizeModelCoefficients(inliers, coefficients, refined);
  Eigen::Vector3d normal(refined[0], refined[1], refined[2]);
  if (!(normal.norm() > 0.0)) return plane;
  double offset = refined[3] / normal.norm();
  normal.normalize();
  offset -= normal.dot(centre);  // back to the world frame
  int above = 0;
  for (const Eigen::Vector3d& c : cameras) above += normal.dot(c) + offset > 0.0;
  if (2 * above < static_cast<int>(cameras.size())) {
    normal = -normal;
    offset = -offset;
    above = static_cast<int>(cameras.size()) - above;
  }
  int on = 0, below = 0;
  for (const Eigen::Vector3d& p : points) {
    const double distance = normal.dot(p) + offset;
    on += std::abs(distance) <= tolerance;
    below += distance < -tolerance;
  }
  plane.normal = normal;
  plane.offset = offset;
  plane.on_plane_share = static_cast<double>(on) / points.size();
  plane.below_share = static_cast<double>(below) / points.size();
  plane.cameras_above_share = cameras.empty() ? 0.0 : static_cast<double>(above) / cameras.size();
  plane.found = plane.on_plane_share >= kMinSupportShare && plane.below_share <= kMaxBelowShare &&
                plane.cameras_above_share >= kMinCamerasAbove;
  return plane;
}

}  // namespace exporter
}  // namespace raycarve
