// The supporting plane against scenes whose answer is known: an object on a tilted table seen
// from above, a ball with no table, a table seen from below, a floor under a denser slanted roof,
// a floor in front of a denser backdrop wall, a floor under a tilted band of loose points and a
// floor at a grazing angle holding few points; a tilted plane settling on a floor's points.
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
  const SupportingPlane plane = FitSupportingPlane(scene.points, scene.cameras, PhotosUp(), 0.01);
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
  EXPECT_FALSE(FitSupportingPlane(ball.points, ball.cameras, PhotosUp(), 0.01).found);
  // Cameras under the table: the plane's normal turns to them, and the ball lies below it.
  Scene under = TableScene(Eigen::Vector3d::Zero(), n, true);
  for (Eigen::Vector3d& camera : under.cameras) camera.z() = -camera.z();
  const SupportingPlane plane = FitSupportingPlane(under.points, under.cameras, PhotosUp(), 0.01);
  EXPECT_LT(plane.normal.z(), -0.999);
  EXPECT_GT(plane.below_share, 0.3);
  EXPECT_FALSE(plane.found);
  EXPECT_FALSE(FitSupportingPlane({}, under.cameras, PhotosUp(), 0.01).found);
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
  const SupportingPlane plane = FitSupportingPlane(scene.points, scene.cameras, PhotosUp(), 0.01);
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

TEST(GroundUnder, ALoneUncheckedPointPastTheEdgeDoesNotStretchTheGround) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  const Eigen::Vector3d origin(1.0, 2.0, -0.5);
  Scene scene = TableScene(origin, n, true);
  const SupportingPlane plane = FitSupportingPlane(scene.points, scene.cameras, PhotosUp(), 0.01);
  ASSERT_TRUE(plane.found) << plane.Summary();
  // Two wrong matches on the plane 4 from the table's centre (its disc reaches 2), one of them
  // seen by a third photo; a pair of points 0.05 apart past the other side.
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  const Eigen::Vector3d lone = origin + 4.0 * u, checked = origin + 4.0 * v;
  const Eigen::Vector3d pair = origin - 4.0 * u, beside = pair + 0.05 * v;
  std::vector<Eigen::Vector3d> points = scene.points;
  points.insert(points.end(), {lone, checked, pair, beside});
  std::vector<bool> seen_by_three(points.size(), false);
  seen_by_three[points.size() - 3] = true;
  const Ground ground = GroundUnder(plane, points, {}, seen_by_three);
  ASSERT_FALSE(ground.empty());
  EXPECT_EQ(ground.lone_points, 1);
  const GroundMap map(ground);
  EXPECT_EQ(map.At(origin + 3.0 * u - 0.3 * n), GroundMap::Foot::kNeither);  // not stretched
  EXPECT_EQ(map.At(origin + 3.0 * v - 0.3 * n), GroundMap::Foot::kGround);   // the checked one
  EXPECT_EQ(map.At(origin - 3.0 * u - 0.3 * n), GroundMap::Foot::kGround);   // the pair
  // No flags: every point counts, as before.
  const Ground all = GroundUnder(plane, points, {});
  EXPECT_EQ(all.lone_points, 0);
  EXPECT_EQ(GroundMap(all).At(origin + 3.0 * u - 0.3 * n), GroundMap::Foot::kGround);
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
  const SupportingPlane plane = FitSupportingPlane(points, cameras, PhotosUp(), 0.01);
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
  const SupportingPlane none = FitSupportingPlane(no_floor, cameras, PhotosUp(), 0.01);
  EXPECT_FALSE(none.found) << none.Summary();
  EXPECT_LT(none.densest_on_share, 0.0);
}

// The pose of a level camera at `centre` looking at `target` (z up), turned `quarters` quarter
// turns about its axis (a portrait photo).
Rigid3d LevelCamera(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, int quarters) {
  const Eigen::Vector3d forward = (target - centre).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d rotation;
  rotation << right.transpose(), forward.cross(right).transpose(), forward.transpose();
  rotation = Eigen::AngleAxisd(quarters * M_PI / 2.0, Eigen::Vector3d::UnitZ()) * rotation;
  Rigid3d pose;
  pose.rotation = Eigen::Quaterniond(rotation);
  pose.translation = -rotation * centre;
  return pose;
}

// Cameras at eye level on an arc in front of a backdrop wall (y = 2), an object on the floor
// (z = 0) between them: the wall holds more points than the floor, nothing lies behind it and
// every camera is in front of it, so without the photos' up it passes for the support. Held
// level, the photos say the floor is level and the wall is not.
TEST(FitSupportingPlane, TheFloorLevelWithThePhotosUpBeforeADenserBackdrop) {
  std::mt19937_64 random(9);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> points, cameras;
  for (int i = 0; i < 100; ++i) {  // the floor, in front of the wall
    points.emplace_back(4.0 * unit(random) - 2.0, 4.0 * unit(random) - 2.0, 0.0);
  }
  for (int i = 0; i < 220; ++i) {  // the backdrop wall
    points.emplace_back(4.0 * unit(random) - 2.0, 2.0, 3.0 * unit(random));
  }
  for (int i = 0; i < 180; ++i) {  // a box of 1 x 1 x 1 on the floor
    const double a = unit(random), b = unit(random);
    const int face = i % 5;
    points.emplace_back(face == 0 ? -0.5 : face == 1 ? 0.5 : a - 0.5,
                        face == 2 ? -0.5 : face == 3 ? 0.5 : b - 0.5,
                        face < 2 ? b : face < 4 ? a : 1.0);
  }
  std::vector<Rigid3d> poses;
  for (int i = 0; i < 9; ++i) {  // an arc of 120 degrees, 1.2 above the floor
    const double a = -M_PI / 2.0 + (i - 4) * M_PI / 12.0;
    cameras.emplace_back(5.0 * std::cos(a), 5.0 * std::sin(a), 1.2);
    poses.push_back(LevelCamera(cameras.back(), {0.0, 0.0, 0.5}, i == 3 ? 1 : 0));
  }
  const SupportingPlane wall = FitSupportingPlane(points, cameras, PhotosUp(), 0.01);
  ASSERT_TRUE(wall.found) << wall.Summary();
  EXPECT_LT(wall.normal.y(), -0.9999);
  EXPECT_LT(wall.angle_to_photos_up, 0.0);  // not known, not said

  const PhotosUp up = EstimatePhotosUp(poses);
  ASSERT_TRUE(up.Known());
  EXPECT_EQ(up.turned, 1);  // the portrait photo
  const SupportingPlane floor = FitSupportingPlane(points, cameras, up, 0.01);
  ASSERT_TRUE(floor.found) << floor.Summary();
  EXPECT_GT(floor.normal.z(), 0.9999);
  EXPECT_NEAR(floor.offset, 0.0, 1e-3);
  // The cameras look 8 degrees down at the box, and from an arc, not a ring: their mean up leans
  // towards the wall by about that much.
  EXPECT_LT(floor.angle_to_photos_up, 8.0);
  EXPECT_NEAR(floor.densest_on_share, wall.on_plane_share, 1e-9);
  EXPECT_NEAR(floor.densest_angle_to_photos_up, 90.0 + floor.angle_to_photos_up, 0.5);
  EXPECT_NE(floor.Summary().find("degrees from the photos' up"), std::string::npos);

  // Without the floor the wall is the support still: no level plane holds a tenth of the points.
  std::vector<Eigen::Vector3d> no_floor(points.begin() + 100, points.end());
  const SupportingPlane only_wall = FitSupportingPlane(no_floor, cameras, up, 0.01);
  ASSERT_TRUE(only_wall.found) << only_wall.Summary();
  EXPECT_LT(only_wall.normal.y(), -0.9999);
  EXPECT_NEAR(only_wall.angle_to_photos_up, 90.0 + floor.angle_to_photos_up, 0.5);
  EXPECT_LT(only_wall.densest_on_share, 0.0);
}

// The floor's points lie close to their plane; a plane tilted 4 degrees through the floor and a
// band of scattered points above it (wrong matches over a chequered floor seen at a grazing
// angle, the foot of clutter) holds more of them within the tolerance, but loosely. The floor is
// the plane that holds its points closely (MSAC), not the one that holds the most.
TEST(FitSupportingPlane, TheFloorHoldingItsPointsCloselyBeforeATiltedBandHoldingMore) {
  constexpr double kTolerance = 0.05;
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.002);
  const auto disc_point = [&] {
    const double r = 2.0 * std::sqrt(unit(random)), a = 2.0 * M_PI * unit(random);
    return Eigen::Vector2d(r * std::cos(a), r * std::sin(a));
  };
  std::vector<Eigen::Vector3d> points, cameras;
  for (int i = 0; i < 120; ++i) {  // the floor z = 0
    const Eigen::Vector2d q = disc_point();
    points.emplace_back(q.x(), q.y(), noise(random));
  }
  int band = 0;
  for (int i = 0; i < 150; ++i) {  // within the tolerance of z = 0.06 + 0.07 x, spread evenly
    const Eigen::Vector2d q = disc_point();
    points.emplace_back(q.x(), q.y(), 0.06 + 0.07 * q.x() + kTolerance * (2.0 * unit(random) - 1.0));
    band += std::abs(points.back().z()) > kTolerance;  // off the floor's band
  }
  for (int i = 0; i < 600; ++i) {  // a ball of radius 0.5 resting on the floor
    const double z = 2.0 * unit(random) - 1.0, a = 2.0 * M_PI * unit(random);
    const double s = std::sqrt(1.0 - z * z);
    points.emplace_back(0.5 * s * std::cos(a), 0.5 * s * std::sin(a), 0.5 + 0.5 * z);
  }
  for (int i = 0; i < 12; ++i) {
    const double a = 2.0 * M_PI * i / 12.0;
    cameras.emplace_back(4.0 * std::cos(a), 4.0 * std::sin(a), 3.0);
  }
  // The tilted plane holds more points within the tolerance than the floor does.
  const Eigen::Vector3d tilted_normal = Eigen::Vector3d(-0.07, 0.0, 1.0).normalized();
  int on_floor = 0, on_tilted = 0;
  for (const Eigen::Vector3d& p : points) {
    on_floor += std::abs(p.z()) <= kTolerance;
    on_tilted += std::abs(tilted_normal.dot(p - Eigen::Vector3d(0.0, 0.0, 0.06))) <= kTolerance;
  }
  ASSERT_GT(on_tilted, on_floor + 20);
  ASSERT_GT(band, 50);

  const SupportingPlane plane = FitSupportingPlane(points, cameras, PhotosUp(), kTolerance);
  ASSERT_TRUE(plane.found) << plane.Summary();
  EXPECT_GT(plane.normal.z(), std::cos(0.5 * M_PI / 180.0)) << plane.Summary();
  // Refined by least squares on the points within the tolerance: the band's few there lift it.
  EXPECT_NEAR(plane.offset, 0.0, 0.2 * kTolerance) << plane.Summary();
}

// Cameras on a ring at eye level: the floor is seen at a grazing angle and holds few of the
// points (under a tenth), fewer than the ball and the box on it, or the wall behind them. No plane
// holding a tenth of them could be a support, but the floor's points spread around what stands on
// it, more widely than all the points do; the ball's cap, where it touches the floor, spreads a
// fraction as wide, and without the floor no level plane is taken.
TEST(FitSupportingPlane, AFloorSeenAtAGrazingAngleSpreadsAroundWhatStandsOnIt) {
  std::mt19937_64 random(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> floor, above, cameras;
  constexpr double kTolerance = 0.03;
  for (int i = 0; i < 40; ++i) {  // the floor: a disc of radius 2.5, heights off by 0.6 tolerances
    const double r = 2.5 * std::sqrt(unit(random)), a = 2.0 * M_PI * unit(random);
    floor.emplace_back(r * std::cos(a), r * std::sin(a), kTolerance * (1.2 * unit(random) - 0.6));
  }
  for (int i = 0; i < 300; ++i) {  // a ball of radius 0.5 resting on it
    const double z = 2.0 * unit(random) - 1.0, a = 2.0 * M_PI * unit(random);
    const double s = std::sqrt(1.0 - z * z);
    above.emplace_back(0.5 * s * std::cos(a), 0.5 * s * std::sin(a), 0.5 + 0.5 * z);
  }
  for (int i = 0; i < 160; ++i) {  // a box of 0.8 x 0.8 x 0.8 beside it, no points underneath
    const double a = 0.8 * unit(random), b = 0.8 * unit(random);
    const int face = i % 5;
    above.emplace_back(0.6 + (face == 0 ? 0.0 : face == 1 ? 0.8 : a),
                       -0.4 + (face == 2 ? 0.0 : face == 3 ? 0.8 : b),
                       face < 2 ? b : face < 4 ? a : 0.8);
  }
  for (int i = 0; i < 150; ++i) {  // the wall behind, from the floor up
    above.emplace_back(4.0 * unit(random) - 2.0, 2.0, 2.0 * unit(random));
  }
  std::vector<Rigid3d> poses;
  for (int i = 0; i < 24; ++i) {
    const double a = 2.0 * M_PI * i / 24.0;
    cameras.emplace_back(5.0 * std::cos(a), 5.0 * std::sin(a), 0.6);
    poses.push_back(LevelCamera(cameras.back(), {0.0, 0.0, 0.4}, 0));
  }
  const PhotosUp up = EstimatePhotosUp(poses);
  ASSERT_TRUE(up.Known());
  std::vector<Eigen::Vector3d> points = above;
  points.insert(points.end(), floor.begin(), floor.end());

  const SupportingPlane plane = FitSupportingPlane(points, cameras, up, kTolerance);
  ASSERT_TRUE(plane.found) << plane.Summary();
  EXPECT_TRUE(plane.found_by_spread);
  // Level: the floor's points, not a plane tilted through some of them and the box's foot.
  EXPECT_GT(plane.normal.z(), std::cos(0.5 * M_PI / 180.0)) << plane.Summary();
  EXPECT_NEAR(plane.offset, 0.0, 0.25 * kTolerance) << plane.Summary();
  EXPECT_LT(plane.on_plane_share, kMinSupportShareWithNothingBelow);
  EXPECT_GE(plane.spread_ratio, kMinWideSupportSpread);
  EXPECT_NE(plane.Summary().find("a floor around what stands on it"), std::string::npos);
  // Without the photos' up, nothing says which plane is level: the wide rule is not applied.
  EXPECT_FALSE(FitSupportingPlane(points, cameras, PhotosUp(), kTolerance).found_by_spread);

  // Without the floor: the ball's cap at z = 0 holds nothing below it but spreads a fraction as
  // widely as the points; the wall, with the cameras in front of it, is taken as before.
  const SupportingPlane no_floor = FitSupportingPlane(above, cameras, up, kTolerance);
  EXPECT_FALSE(no_floor.found_by_spread) << no_floor.Summary();
  EXPECT_FALSE(no_floor.found && no_floor.Level()) << no_floor.Summary();
  // A ball alone.
  const std::vector<Eigen::Vector3d> ball(above.begin(), above.begin() + 300);
  EXPECT_FALSE(FitSupportingPlane(ball, cameras, up, kTolerance).found);
}

// A plane tilted 3 degrees through a floor's points (and the foot of a wall on it) settles on the
// floor: the floor's points it leaves just under it pull it down, and it holds them all; points
// further under (wrong matches) stay out of it.
TEST(SettleOnPoints, ATiltedPlaneSettlesOnTheFloorsPoints) {
  std::mt19937_64 random(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  constexpr double kTolerance = 0.03;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i) {  // the floor, 2 x 2, heights off by half a tolerance at most
    points.emplace_back(2.0 * unit(random) - 1.0, 2.0 * unit(random) - 1.0,
                        kTolerance * (unit(random) - 0.5));
  }
  for (int i = 0; i < 100; ++i) {  // a wall's foot along x = 1, rising from the floor
    points.emplace_back(1.0, 2.0 * unit(random) - 1.0, 0.5 * unit(random));
  }
  for (int i = 0; i < 10; ++i) {  // wrong matches well under the floor
    points.emplace_back(2.0 * unit(random) - 1.0, 2.0 * unit(random) - 1.0, -0.5);
  }
  const double tilt = 3.0 * M_PI / 180.0;
  Eigen::Vector3d normal(-std::sin(tilt), 0.0, std::cos(tilt));  // rises towards the wall
  double offset = 0.0;
  int under_before = 0;
  for (const Eigen::Vector3d& p : points) under_before += normal.dot(p) + offset < -kTolerance;
  ASSERT_GT(under_before, 40);  // the floor's points on the far side from the wall

  ASSERT_TRUE(SettleOnPoints(points, kTolerance, &normal, &offset));
  EXPECT_GT(normal.z(), std::cos(0.2 * M_PI / 180.0)) << normal.transpose();
  EXPECT_NEAR(offset, 0.0, 0.2 * kTolerance);
  int on = 0, under = 0;
  for (const Eigen::Vector3d& p : points) {
    const double d = normal.dot(p) + offset;
    on += std::abs(d) <= kTolerance;
    under += d < -kTolerance;
  }
  EXPECT_GE(on, 200);      // the floor, and the wall's lowest points
  EXPECT_EQ(under, 10);    // the wrong matches alone

  // Nothing within reach: the plane as given.
  Eigen::Vector3d far_normal = Eigen::Vector3d::UnitZ();
  double far_offset = -5.0;
  EXPECT_FALSE(SettleOnPoints(points, kTolerance, &far_normal, &far_offset));
  EXPECT_EQ(far_offset, -5.0);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
