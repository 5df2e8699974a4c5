// The supporting plane against scenes whose answer is known: an object on a tilted table seen
// from above, a ball with no table, and a table seen from below.
#include "export/supporting_plane.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace raycarve {
namespace exporter {
namespace {

// 500 points on the plane through `origin` with unit normal `n` (a disc of radius 2), 300 on a
// ball of radius 0.5 resting on it; cameras on a ring 3 above it.
struct Scene {
  std::vector<Eigen::Vector3d> points, cameras;
};
Scene TableScene(const Eigen::Vector3d& origin, const Eigen::Vector3d& n, bool with_table) {
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  Scene scene;
  for (int i = 0; with_table && i < 500; ++i) {
    const double r = 2.0 * std::sqrt(unit(random)), a = 2.0 * M_PI * unit(random);
    scene.points.push_back(origin + r * std::cos(a) * u + r * std::sin(a) * v);
  }
  for (int i = 0; i < 300; ++i) {
    const double z = 2.0 * unit(random) - 1.0, a = 2.0 * M_PI * unit(random);
    const double s = std::sqrt(1.0 - z * z);
    scene.points.push_back(origin + 0.5 * n + 0.5 * (s * std::cos(a) * u + s * std::sin(a) * v + z * n));
  }
  for (int i = 0; i < 12; ++i) {
    const double a = 2.0 * M_PI * i / 12.0;
    scene.cameras.push_back(origin + 3.0 * n + 4.0 * (std::cos(a) * u + std::sin(a) * v));
  }
  return scene;
}

TEST(FitSupportingPlane, FindsTheTableUnderAnObjectOrientedTowardsTheCameras) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  const Eigen::Vector3d origin(1.0, 2.0, -0.5);
  const Scene scene = TableScene(origin, n, true);
  const SupportingPlane plane = FitSupportingPlane(scene.points, scene.cameras, 0.01);
  ASSERT_TRUE(plane.found) << plane.Summary();
  EXPECT_GT(plane.normal.dot(n), 0.9999);
  EXPECT_NEAR(plane.normal.dot(origin) + plane.offset, 0.0, 1e-3);
  // The table's 500 of 800 points, and a few of the ball's where it rests on the table.
  EXPECT_NEAR(plane.on_plane_share, 500.0 / 800.0, 0.02);
  EXPECT_EQ(plane.below_share, 0.0);
  EXPECT_EQ(plane.cameras_above_share, 1.0);
  EXPECT_NE(plane.Summary().find("a supporting plane"), std::string::npos);
}

TEST(FitSupportingPlane, ABallAloneOrATableSeenFromBelowIsNoSupport) {
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  const Scene ball = TableScene(Eigen::Vector3d::Zero(), n, false);
  EXPECT_FALSE(FitSupportingPlane(ball.points, ball.cameras, 0.01).found);
  // Cameras under the table: the plane's normal turns to them, and the ball lies below it.
  Scene under = TableScene(Eigen::Vector3d::Zero(), n, true);
  for (Eigen::Vector3d& camera : under.cameras) camera.z() = -camera.z();
  const SupportingPlane plane = FitSupportingPlane(under.points, under.cameras, 0.01);
  EXPECT_LT(plane.normal.z(), -0.999);
  EXPECT_GT(plane.below_share, 0.3);
  EXPECT_FALSE(plane.found);
  EXPECT_FALSE(FitSupportingPlane({}, under.cameras, 0.01).found);
}

TEST(GroundUnder, TheTablesPointsMakeTheGroundAndAStepDownMakesHoles) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  const Eigen::Vector3d origin(1.0, 2.0, -0.5);
  Scene scene = TableScene(origin, n, true);
  // 40 points 0.4 below the table around 3 from its centre: a floor beyond its edge.
  const Eigen::Vector3d u = n.unitOrthogonal();
  for (int i = 0; i < 40; ++i) {
    scene.points.push_back(origin - 0.4 * n + (3.0 + 0.01 * i) * u + 0.02 * i * n.cross(u));
  }
  const SupportingPlane plane = FitSupportingPlane(scene.points, scene.cameras, 0.01);
  ASSERT_TRUE(plane.found) << plane.Summary();
  const Ground ground = GroundUnder(plane, scene.points, scene.points);
  ASSERT_FALSE(ground.empty());
  EXPECT_GE(ground.footprint.size(), 500u);
  EXPECT_LT(ground.footprint.size(), 540u);  // and the few of the ball that touch the table
  EXPECT_EQ(ground.holes.size(), 40u);
  EXPECT_GE(ground.outline.size(), 8u);  // the disc's hull
  // 500 points over a disc of radius 2: spacing about 0.08, reach twice that.
  EXPECT_GT(ground.radius, 0.08);
  EXPECT_LT(ground.radius, 0.3);
  for (const Eigen::Vector3d& point : ground.footprint) {
    EXPECT_NEAR(n.dot(point - origin), 0.0, 1e-3);  // the feet lie on the plane
  }
  const GroundMap map(ground);
  EXPECT_EQ(map.At(origin + 1.5 * n.cross(u) - 0.3 * n), GroundMap::Foot::kGround);
  EXPECT_EQ(map.At(origin + 3.1 * u - 0.3 * n), GroundMap::Foot::kNearHole);
  EXPECT_EQ(map.At(origin - 3.0 * u - 0.3 * n), GroundMap::Foot::kNeither);
  // No support, no ground.
  EXPECT_TRUE(GroundUnder(SupportingPlane(), scene.points, scene.points).empty());
  // Every point twice (a point seen twice at the same place): the same reach.
  std::vector<Eigen::Vector3d> twice = scene.points;
  twice.insert(twice.end(), scene.points.begin(), scene.points.end());
  EXPECT_NEAR(GroundUnder(plane, twice, twice).radius, ground.radius, 1e-6);
  // Holes come from the points given for them only (the caller's checked points): the same
  // footprint, no hole.
  const Ground no_holes = GroundUnder(plane, scene.points, {});
  EXPECT_EQ(no_holes.footprint.size(), ground.footprint.size());
  EXPECT_TRUE(no_holes.holes.empty());
  EXPECT_EQ(no_holes.radius, ground.radius);
}

// A slanted roof above a floor holds more points than the floor (wrong matches along a repeated
// pattern do the same on a tilted plane): the densest plane has the floor and a ball below it, so
// it is no support, and the floor, the densest plane with nothing below it, is.
TEST(FitSupportingPlane, FindsTheFloorUnderADenserPlaneThatIsNoSupport) {
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> points, cameras;
  for (int i = 0; i < 120; ++i) {  // the floor z = 0, a disc of radius 2
    const double r = 2.0 * std::sqrt(unit(random)), a = 2.0 * M_PI * unit(random);
    points.emplace_back(r * std::cos(a), r * std::sin(a), 0.0);
  }
  for (int i = 0; i < 130; ++i) {  // a ball of radius 0.4 resting on it
    const double z = 2.0 * unit(random) - 1.0, a = 2.0 * M_PI * unit(random);
    const double s = std::sqrt(1.0 - z * z);
    points.emplace_back(0.4 * s * std::cos(a), 0.4 * s * std::sin(a), 0.4 + 0.4 * z);
  }
  for (int i = 0; i < 250; ++i) {  // the roof z = 1 + 0.5 x over [-1, 1]^2
    const double x = 2.0 * unit(random) - 1.0, y = 2.0 * unit(random) - 1.0;
    points.emplace_back(x, y, 1.0 + 0.5 * x);
  }
  for (int i = 0; i < 12; ++i) {
    const double a = 2.0 * M_PI * i / 12.0;
    cameras.emplace_back(4.0 * std::cos(a), 4.0 * std::sin(a), 5.0);
  }
  const SupportingPlane plane = FitSupportingPlane(points, cameras, 0.01);
  ASSERT_TRUE(plane.found) << plane.Summary();
  EXPECT_GT(plane.normal.z(), 0.9999);
  EXPECT_NEAR(plane.offset, 0.0, 1e-3);
  EXPECT_NEAR(plane.on_plane_share, 120.0 / 500.0, 0.02);  // and the ball's lowest few
  EXPECT_EQ(plane.below_share, 0.0);
  // The roof was the densest plane, with the floor and the ball under it.
  EXPECT_NEAR(plane.densest_on_share, 0.5, 0.02);
  EXPECT_GT(plane.densest_below_share, 0.4);
  EXPECT_NE(plane.Summary().find("the densest plane"), std::string::npos);

  // Without the floor, nothing with the ball and the roof is a support: the roof has the ball
  // below it, and no other plane holds a tenth of the points.
  std::vector<Eigen::Vector3d> no_floor(points.begin() + 120, points.end());
  const SupportingPlane none = FitSupportingPlane(no_floor, cameras, 0.01);
  EXPECT_FALSE(none.found) << none.Summary();
  EXPECT_LT(none.densest_on_share, 0.0);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
