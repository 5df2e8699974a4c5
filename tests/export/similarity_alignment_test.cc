#include "export/similarity_alignment.h"

#include <random>

#include <gtest/gtest.h>

#include "calib/input_error.h"

namespace raycarve {
namespace exporter {
namespace {

Similarity3 KnownSimilarity() {
  Similarity3 s;
  s.scale = 2.7;
  s.rotation = Eigen::AngleAxisd(0.9, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  s.translation = Eigen::Vector3d(4.0, -1.5, 0.25);
  return s;
}

// Camera centres on a ring, as an object ring is shot.
std::vector<Eigen::Vector3d> Ring(int n) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    points.emplace_back(std::cos(a), std::sin(a), 0.3 + 0.05 * std::sin(3 * a));
  }
  return points;
}

TEST(SimilarityAlignment, RecoversAKnownSimilarityExactlyAndDespiteNoiseAndOutliers) {
  const Similarity3 truth = KnownSimilarity();
  const std::vector<Eigen::Vector3d> source = Ring(16);
  std::vector<Eigen::Vector3d> target;
  for (const Eigen::Vector3d& p : source) target.push_back(truth(p));

  Alignment exact = AlignPoints(source, target);
  EXPECT_NEAR(exact.transform.scale, truth.scale, 1e-9);
  EXPECT_LT((exact.transform.rotation - truth.rotation).norm(), 1e-9);
  EXPECT_LT((exact.transform.translation - truth.translation).norm(), 1e-8);
  EXPECT_EQ(exact.num_inliers, 16);
  EXPECT_LT(exact.rms, 1e-8);

  // Noise of 0.5% of the spread, and two cameras put far off (a bad registration).
  std::mt19937 random(2);
  std::normal_distribution<double> noise(0.0, 0.005 * truth.scale);
  for (Eigen::Vector3d& p : target) p += Eigen::Vector3d(noise(random), noise(random), noise(random));
  target[3] += Eigen::Vector3d(2.0, 0.0, 0.0);
  target[11] += Eigen::Vector3d(0.0, -3.0, 1.0);
  const Alignment robust = AlignPoints(source, target);
  EXPECT_EQ(robust.num_inliers, 14);
  EXPECT_NEAR(robust.transform.scale, truth.scale, 0.01 * truth.scale);
  EXPECT_LT((robust.transform.rotation - truth.rotation).norm(), 0.01);
  EXPECT_LT(robust.rms, 0.02 * truth.scale);
  // The closed form alone is pulled by the two bad pairs; the robust refinement is not.
  EXPECT_GT(robust.rms_before_refinement, 3.0 * robust.rms);
}

TEST(SimilarityAlignment, RefusesTooFewOrCollinearPoints) {
  const std::vector<Eigen::Vector3d> two = {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()};
  EXPECT_THROW(AlignPoints(two, two), InputError);
  const std::vector<Eigen::Vector3d> line = {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(),
                                             2.0 * Eigen::Vector3d::UnitX()};
  EXPECT_THROW(AlignPoints(line, line), InputError);
  EXPECT_THROW(AlignPoints(Ring(5), Ring(4)), InputError);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
