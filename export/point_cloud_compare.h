#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace raycarve {
namespace exporter {

// How two point sets are compared, the way multi-view stereo benchmarks do.
struct CompareOptions {
  // Distance (world units) within which a point counts as matched, for completeness, precision
  // and the F-score.
  double threshold = 0.01;
  // The accuracy quantile: accuracy is the distance within which this share of the
  // reconstruction lies from the reference (Middlebury uses 90%).
  double accuracy_quantile = 0.9;
  // Threads for the nearest-neighbour searches (< 1: one per core); the result is the same for
  // any count.
  int num_threads = -1;

  bool IsValid(std::string* reason) const;
};

struct CloudComparison {
  size_t num_reference = 0;
  size_t num_reconstruction = 0;
  double threshold = 0.0;
  double accuracy = 0.0;      // distance within which accuracy_quantile of the reconstruction lies
  double completeness = 0.0;  // share of the reference within threshold of the reconstruction
  double precision = 0.0;     // share of the reconstruction within threshold of the reference
  double f_score = 0.0;       // harmonic mean of precision and completeness
  double mean_reconstruction_to_reference = 0.0;
  double mean_reference_to_reconstruction = 0.0;
  double chamfer = 0.0;  // mean of the two mean nearest-neighbour distances

  std::string Summary() const;
};

// Compares `reconstruction` against `reference` with nearest-neighbour searches (exact k-d trees)
// in both directions. Both must be non-empty and the options valid (CHECKed).
CloudComparison CompareClouds(const std::vector<Eigen::Vector3f>& reference,
                              const std::vector<Eigen::Vector3f>& reconstruction,
                              const CompareOptions& options);

// The points of a PLY file for comparison: a mesh (a PLY with faces; polygons are fanned into
// triangles) is sampled with `mesh_samples` points spread uniformly over its surface area (fixed
// seed, so repeatable); a point cloud is returned as it is. Throws InputError naming the path
// when it cannot be read or holds no points.
std::vector<Eigen::Vector3f> ReadComparablePoints(const std::string& path, int mesh_samples);

// The median distance from a point to its nearest other point (a k-d tree; `num_threads` < 1:
// one per core, the same result for any count): a cloud's own sampling step. Non-finite points
// are left out; 0 with fewer than two points.
double MedianNeighbourSpacing(const std::vector<Eigen::Vector3f>& points, int num_threads = -1);

}  // namespace exporter
}  // namespace raycarve
