#include "export/point_cloud_compare.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>

#include <glog/logging.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include "calib/input_error.h"
#include "export/ply_reader.h"
#include "export/point_cloud_io.h"

namespace raycarve {
namespace exporter {
namespace {

pcl::PointCloud<pcl::PointXYZ>::Ptr ToCloud(const std::vector<Eigen::Vector3f>& points) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (const Eigen::Vector3f& p : points) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return cloud;
}

// For each query point, the distance to its nearest neighbour in `target`.
std::vector<double> NearestDistances(const std::vector<Eigen::Vector3f>& queries,
                                     const std::vector<Eigen::Vector3f>& target) {
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(ToCloud(target));
  std::vector<double> distances;
  distances.reserve(queries.size());
  pcl::Indices index(1);
  std::vector<float> squared(1);
  for (const Eigen::Vector3f& q : queries) {
    tree.nearestKSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), 1, index, squared);
    distances.push_back(std::sqrt(static_cast<double>(squared[0])));
  }
  return distances;
}

double Mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += v;
  return sum / values.size();
}

double ShareWithin(const std::vector<double>& values, double threshold) {
  return static_cast<double>(std::count_if(values.begin(), values.end(),
                                           [&](double v) { return v <= threshold; })) /
         values.size();
}

}  // namespace

bool CompareOptions::IsValid(std::string* reason) const {
  if (!(threshold > 0.0) || !std::isfinite(threshold)) {
    *reason = "threshold must be a positive distance";
    return false;
  }
  if (!(accuracy_quantile > 0.0 && accuracy_quantile <= 1.0)) {
    *reason = "accuracy_quantile must be in (0, 1]";
    return false;
  }
  return true;
}

std::string CloudComparison::Summary() const {
  std::ostringstream text;
  text.precision(4);
  text << "accuracy " << accuracy << ", completeness " << 100.0 * completeness << "%, precision "
       << 100.0 * precision << "%, F-score " << 100.0 * f_score << "% (threshold " << threshold
       << "), chamfer " << chamfer << "; " << num_reconstruction << " points against "
       << num_reference;
  return text.str();
}

CloudComparison CompareClouds(const std::vector<Eigen::Vector3f>& reference,
                              const std::vector<Eigen::Vector3f>& reconstruction,
                              const CompareOptions& options) {
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  CHECK(!reference.empty() && !reconstruction.empty());
  CloudComparison result;
  result.num_reference = reference.size();
  result.num_reconstruction = reconstruction.size();
  result.threshold = options.threshold;
  std::vector<double> to_reference = NearestDistances(reconstruction, reference);
  const std::vector<double> to_reconstruction = NearestDistances(reference, reconstruction);
  result.precision = ShareWithin(to_reference, options.threshold);
  result.completeness = ShareWithin(to_reconstruction, options.threshold);
  result.f_score = result.precision + result.completeness > 0.0
                       ? 2.0 * result.precision * result.completeness /
                             (result.precision + result.completeness)
                       : 0.0;
  result.mean_reconstruction_to_reference = Mean(to_reference);
  result.mean_reference_to_reconstruction = Mean(to_reconstruction);
  result.chamfer =
      0.5 * (result.mean_reconstruction_to_reference + result.mean_reference_to_reconstruction);
  const size_t rank = std::min(
      to_reference.size() - 1,
      static_cast<size_t>(std::ceil(options.accuracy_quantile * to_reference.size())) - 1);
  std::nth_element(to_reference.begin(), to_reference.begin() + rank, to_reference.end());
  result.accuracy = to_reference[rank];
  return result;
}

double MedianNeighbourSpacing(const std::vector<Eigen::Vector3f>& points) {
  std::vector<Eigen::Vector3f> finite;
  finite.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite()) finite.push_back(p);
  }
  if (finite.size() < 2) return 0.0;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(ToCloud(finite));
  std::vector<double> distances;
  distances.reserve(finite.size());
  pcl::Indices index(2);
  std::vector<float> squared(2);
  for (const Eigen::Vector3f& q : finite) {
    if (tree.nearestKSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), 2, index, squared) < 2) continue;
    distances.push_back(std::sqrt(static_cast<double>(squared[1])));
  }
  if (distances.empty()) return 0.0;
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  return distances[distances.size() / 2];
}

std::vector<Eigen::Vector3f> ReadComparablePoints(const std::string& path, int mesh_samples) {
  if (!std::filesystem::is_regular_file(path)) throw InputError(path + ": file not found");
  const PlyData data = ReadPly(path);  // non-finite coordinates and bad faces refused by name
  if (data.xyz.empty()) throw InputError(path + ": no points to compare");
  std::vector<Eigen::Vector3f> points;
  if (data.triangles.empty()) {
    points = data.xyz;
  } else {
    std::vector<std::array<Eigen::Vector3f, 3>> triangles;
    std::vector<double> cumulative_area;
    double total = 0.0;
    for (const Eigen::Vector3i& corners : data.triangles) {
      const std::array<Eigen::Vector3f, 3> triangle = {data.xyz[corners[0]], data.xyz[corners[1]],
                                                      data.xyz[corners[2]]};
      total += 0.5 * (triangle[1] - triangle[0]).cross(triangle[2] - triangle[0]).norm();
      triangles.push_back(triangle);
      cumulative_area.push_back(total);
    }
    if (!(total > 0.0)) throw InputError(path + ": the mesh has no surface area to sample");
    std::mt19937 random(12345);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    points.reserve(mesh_samples);
    for (int i = 0; i < mesh_samples; ++i) {
      const size_t t = std::min(
          triangles.size() - 1,
          static_cast<size_t>(std::lower_bound(cumulative_area.begin(), cumulative_area.end(),
                                               uniform(random) * total) -
                              cumulative_area.begin()));
      // Uniform in the triangle: reflect the unit square's upper half.
      double a = uniform(random), b = uniform(random);
      if (a + b > 1.0) {
        a = 1.0 - a;
        b = 1.0 - b;
      }
      const auto& tri = triangles[t];
      points.push_back(tri[0] + static_cast<float>(a) * (tri[1] - tri[0]) +
                       static_cast<float>(b) * (tri[2] - tri[0]));
    }
  }
  if (points.empty()) throw InputError(path + ": holds no points");
  return points;
}

}  // namespace exporter
}  // namespace raycarve
