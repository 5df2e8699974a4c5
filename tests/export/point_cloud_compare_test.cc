#include "export/point_cloud_compare.h"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <pcl/PolygonMesh.h>
#include <pcl/conversions.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include "calib/input_error.h"
#include "export/point_cloud_io.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

// A square grid of points on the plane z = `z`, x in [0, x_max], y in [0, 1], spacing 0.01.
std::vector<Eigen::Vector3f> Plane(float z, float x_max) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i <= static_cast<int>(x_max * 100 + 0.5f); ++i) {
    for (int j = 0; j <= 100; ++j) points.emplace_back(i * 0.01f, j * 0.01f, z);
  }
  return points;
}

TEST(CompareClouds, AConstantOffsetGivesThatAccuracyAndAllOrNothingMatches) {
  const std::vector<Eigen::Vector3f> reference = Plane(0.0f, 1.0f);
  const std::vector<Eigen::Vector3f> shifted = Plane(0.004f, 1.0f);
  CompareOptions options;
  options.threshold = 0.005;
  const CloudComparison near = CompareClouds(reference, shifted, options);
  EXPECT_NEAR(near.accuracy, 0.004, 1e-6);
  EXPECT_NEAR(near.chamfer, 0.004, 1e-6);
  EXPECT_DOUBLE_EQ(near.precision, 1.0);
  EXPECT_DOUBLE_EQ(near.completeness, 1.0);
  EXPECT_DOUBLE_EQ(near.f_score, 1.0);
  options.threshold = 0.003;
  const CloudComparison far = CompareClouds(reference, shifted, options);
  EXPECT_DOUBLE_EQ(far.precision, 0.0);
  EXPECT_DOUBLE_EQ(far.completeness, 0.0);
  EXPECT_DOUBLE_EQ(far.f_score, 0.0);
}

TEST(CompareClouds, AHalfReconstructionIsPreciseButHalfComplete) {
  const std::vector<Eigen::Vector3f> reference = Plane(0.0f, 1.0f);
  const std::vector<Eigen::Vector3f> half = Plane(0.0f, 0.5f);
  CompareOptions options;
  options.threshold = 0.001;
  const CloudComparison result = CompareClouds(reference, half, options);
  EXPECT_DOUBLE_EQ(result.precision, 1.0);
  EXPECT_NEAR(result.completeness, 51.0 / 101.0, 1e-9);  // columns x <= 0.5 of 101
  EXPECT_NEAR(result.f_score, 2 * result.completeness / (1 + result.completeness), 1e-12);
  EXPECT_DOUBLE_EQ(result.accuracy, 0.0);
  EXPECT_GT(result.mean_reference_to_reconstruction, 0.1);  // the missing half is far away
  EXPECT_FALSE(result.Summary().empty());
}

TEST(CompareClouds, AccuracyIsTheQuantileOfTheDistances) {
  // 9 points on the reference, 1 outlier 1.0 away: the 90% distance ignores it, 100% does not.
  std::vector<Eigen::Vector3f> reference = Plane(0.0f, 1.0f);
  std::vector<Eigen::Vector3f> input(reference.begin(), reference.begin() + 9);
  input.emplace_back(0.0f, 0.0f, 1.0f);
  CompareOptions options;
  EXPECT_DOUBLE_EQ(CompareClouds(reference, input, options).accuracy, 0.0);
  options.accuracy_quantile = 1.0;
  EXPECT_NEAR(CompareClouds(reference, input, options).accuracy, 1.0, 1e-6);
  std::string reason;
  options.threshold = 0.0;
  EXPECT_FALSE(options.IsValid(&reason));
}

// Random points in the unit cube (a fixed seed).
std::vector<Eigen::Vector3f> RandomPoints(int n, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<Eigen::Vector3f> points(n);
  for (Eigen::Vector3f& p : points) {
    p = Eigen::Vector3f(uniform(random), uniform(random), uniform(random));
  }
  return points;
}

// The exact answers, by trying every pair.
std::vector<double> BruteForceNearest(const std::vector<Eigen::Vector3f>& queries,
                                     const std::vector<Eigen::Vector3f>& target, bool skip_self) {
  std::vector<double> nearest;
  for (size_t i = 0; i < queries.size(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j < target.size(); ++j) {
      if (skip_self && i == j) continue;
      best = std::min(best, static_cast<double>((queries[i] - target[j]).norm()));
    }
    nearest.push_back(best);
  }
  return nearest;
}

TEST(CompareClouds, NearestNeighboursAreExactAndTheSameOnAnyNumberOfThreads) {
  // Enough queries that four threads each take a share.
  const std::vector<Eigen::Vector3f> reconstruction = RandomPoints(20000, 1);
  const std::vector<Eigen::Vector3f> reference = RandomPoints(300, 2);
  const std::vector<double> to_reference = BruteForceNearest(reconstruction, reference, false);
  const std::vector<double> to_reconstruction = BruteForceNearest(reference, reconstruction, false);
  double mean_to_reference = 0.0, mean_to_reconstruction = 0.0;
  for (double d : to_reference) mean_to_reference += d / to_reference.size();
  for (double d : to_reconstruction) mean_to_reconstruction += d / to_reconstruction.size();
  CompareOptions options;
  options.threshold = 0.05;
  for (int threads : {1, 4}) {
    options.num_threads = threads;
    const CloudComparison result = CompareClouds(reference, reconstruction, options);
    EXPECT_NEAR(result.mean_reconstruction_to_reference, mean_to_reference, 1e-6) << threads;
    EXPECT_NEAR(result.mean_reference_to_reconstruction, mean_to_reconstruction, 1e-6) << threads;
    const double within = std::count_if(to_reference.begin(), to_reference.end(),
                                        [](double d) { return d <= 0.05; });
    EXPECT_NEAR(result.precision, within / to_reference.size(), 1e-4) << threads;
  }
  // A cloud's own spacing: every point's nearest other point.
  const std::vector<Eigen::Vector3f> cloud = RandomPoints(9000, 3);
  std::vector<double> spacing = BruteForceNearest(cloud, cloud, true);
  std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
  for (int threads : {1, 3}) {
    EXPECT_NEAR(MedianNeighbourSpacing(cloud, threads), spacing[spacing.size() / 2], 1e-6)
        << threads;
  }
}

TEST(ReadComparablePoints, SamplesMeshesUniformlyOverTheirAreaAndKeepsClouds) {
  const std::string folder = testing::MakeTemporaryDirectory("compare_mesh");
  // A box 2 x 1 x 1 as 12 triangles: faces of area 2, 2, 2, 2, 1, 1 (total 10).
  pcl::PointCloud<pcl::PointXYZ> corners;
  for (int c = 0; c < 8; ++c) corners.push_back(pcl::PointXYZ(2.0f * (c & 1), (c >> 1) & 1, (c >> 2) & 1));
  pcl::PolygonMesh mesh;
  pcl::toPCLPointCloud2(corners, mesh.cloud);
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    pcl::Vertices quad;  // quads, fanned into triangles by the reader
    quad.vertices = {f[0], f[1], f[2], f[3]};
    mesh.polygons.push_back(quad);
  }
  ASSERT_EQ(pcl::io::savePLYFileBinary(folder + "/box.ply", mesh), 0);
  const std::vector<Eigen::Vector3f> samples = ReadComparablePoints(folder + "/box.ply", 10000);
  ASSERT_EQ(samples.size(), 10000u);
  int on_x_ends = 0;
  for (const Eigen::Vector3f& p : samples) {
    const float to_face = std::min({std::abs(p.x()), std::abs(p.x() - 2), std::abs(p.y()),
                                    std::abs(p.y() - 1), std::abs(p.z()), std::abs(p.z() - 1)});
    ASSERT_LT(to_face, 1e-5f) << p.transpose();
    on_x_ends += std::abs(p.x()) < 1e-6f || std::abs(p.x() - 2) < 1e-6f;
  }
  EXPECT_NEAR(on_x_ends / 10000.0, 0.2, 0.02);  // the two 1 x 1 ends hold 2 / 10 of the area

  WritePointCloudPly({ColouredPoint(), ColouredPoint()}, folder + "/cloud.ply");
  EXPECT_EQ(ReadComparablePoints(folder + "/cloud.ply", 10000).size(), 2u);
  EXPECT_THROW(ReadComparablePoints(folder + "/none.ply", 10), InputError);
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
