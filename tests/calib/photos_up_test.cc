// The photos' up against camera layouts whose answer is known: a ring looking down, a forward
// arc held level, portrait photos among landscape ones, cameras held every way.
#include "calib/photos_up.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace raycarve {
namespace {

// The pose of a camera at `centre` looking at `target`, held level with `up` (image -y towards
// it), then turned `quarters` quarter turns about its axis (a portrait photo: 1 or 3).
Rigid3d Looking(const Eigen::Vector3d& centre, const Eigen::Vector3d& target,
                const Eigen::Vector3d& up, int quarters = 0) {
  const Eigen::Vector3d forward = (target - centre).normalized();
  const Eigen::Vector3d right = forward.cross(up).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d rotation;  // rows: the camera's x, y, z in the world
  rotation << right.transpose(), down.transpose(), forward.transpose();
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(quarters * M_PI / 2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Rigid3d pose;
  pose.rotation = Eigen::Quaterniond(turn * rotation);
  pose.translation = -(turn * rotation) * centre;
  return pose;
}

TEST(EstimatePhotosUp, ARingLookingDownFindsUpAndItsAgreement) {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < 12; ++i) {  // 45 degrees down onto the origin
    const double a = 2.0 * M_PI * i / 12.0;
    poses.push_back(Looking({3.0 * std::cos(a), 3.0 * std::sin(a), 3.0}, Eigen::Vector3d::Zero(),
                            Eigen::Vector3d::UnitZ()));
  }
  const PhotosUp up = EstimatePhotosUp(poses);
  EXPECT_GT(up.up.z(), 1.0 - 1e-9);
  EXPECT_NEAR(up.agreement, std::sqrt(0.5), 1e-9);  // cos 45
  EXPECT_EQ(up.turned, 0);
  EXPECT_EQ(up.photos, 12);
  EXPECT_EQ(up.held_alike, 12);
  EXPECT_TRUE(up.Known());
}

TEST(EstimatePhotosUp, PortraitAndUpsideDownPhotosAreTurnedBack) {
  const Eigen::Vector3d world_up = Eigen::Vector3d(0.1, -0.2, 1.0).normalized();
  const Eigen::Vector3d side = world_up.unitOrthogonal();
  std::vector<Rigid3d> poses;
  for (int i = 0; i < 10; ++i) {  // a level arc of 90 degrees in front of a facade
    const double a = M_PI / 4.0 + M_PI / 2.0 * i / 9.0;
    const Eigen::Vector3d centre =
        4.0 * (std::cos(a) * side + std::sin(a) * world_up.cross(side)) + 0.5 * world_up;
    // Photos 2, 5 and 8 portrait (either way), photo 9 upside down.
    const int quarters = i == 2 ? 1 : i == 5 || i == 8 ? 3 : i == 9 ? 2 : 0;
    poses.push_back(Looking(centre, centre - 4.0 * (centre - centre.dot(world_up) * world_up) /
                                                 (centre - centre.dot(world_up) * world_up).norm(),
                            world_up, quarters));
  }
  const PhotosUp up = EstimatePhotosUp(poses);
  EXPECT_GT(up.up.dot(world_up), 1.0 - 1e-9);
  EXPECT_NEAR(up.agreement, 1.0, 1e-9);  // held level: every up is the world's once turned back
  EXPECT_EQ(up.turned, 4);
  EXPECT_EQ(up.held_alike, 6);
  EXPECT_TRUE(up.Known());

  // Every photo portrait, turned the same way: the right side of the frame is up.
  std::vector<Rigid3d> portrait;
  for (int i = 0; i < 12; ++i) {
    const double a = 2.0 * M_PI * i / 12.0;
    portrait.push_back(Looking({3.0 * std::cos(a), 3.0 * std::sin(a), 1.0},
                               Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 1));
  }
  const PhotosUp turned = EstimatePhotosUp(portrait);
  EXPECT_GT(turned.up.z(), 1.0 - 1e-9);
  EXPECT_EQ(turned.turned, 12);
  EXPECT_EQ(turned.held_alike, 12);
  EXPECT_TRUE(turned.Known());
}

TEST(EstimatePhotosUp, CamerasHeldEveryWaySayNothing) {
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  std::vector<Rigid3d> poses;
  for (int i = 0; i < 200; ++i) {
    Rigid3d pose;
    pose.rotation = Eigen::Quaterniond(normal(random), normal(random), normal(random),
                                       normal(random)).normalized();
    poses.push_back(pose);
  }
  const PhotosUp up = EstimatePhotosUp(poses);
  EXPECT_LT(up.held_alike, kMinPhotosHeldAlike * 200);
  EXPECT_FALSE(up.Known()) << up.agreement << " " << up.held_alike;
  const PhotosUp none = EstimatePhotosUp({});
  EXPECT_FALSE(none.Known());
  EXPECT_EQ(none.up, Eigen::Vector3d::UnitZ());
}

}  // namespace
}  // namespace raycarve
