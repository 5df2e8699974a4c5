#include "pipeline/tile_plan.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "tests/test_support.h"

namespace raycarve {
namespace {

// The plan's ray file carries each ray's view, direction and length: a distant pixel's ray is
// infinite, a ground pixel's ends near the ground (carve/ground_pixels.h); a tile job that read
// every ray as infinite would carve through the floor.
TEST(TilePlanRays, DistantAndGroundRaysReadBackWithTheirLengths) {
  const std::string folder = testing::MakeTemporaryDirectory("tile_plan_rays");
  TilePlan plan;
  plan.plan_id = "0123456789abcdef";
  DistantPixels found;
  found.textured = 100;
  found.distant = 7;
  found.nearer = 2;
  found.grown = 30;
  found.photos_judged = 3;
  found.rays.push_back({0, Eigen::Vector3d(0.0, 0.0, 1.0), std::numeric_limits<double>::infinity()});
  found.rays.push_back({2, Eigen::Vector3d(0.6, 0.0, 0.8), 4.25});
  const std::string path = folder + "/distant.bin";
  WriteDistantPixels(path, plan.plan_id, found);
  const DistantPixels read = ReadDistantPixels(path, plan);
  ASSERT_EQ(read.rays.size(), 2u);
  EXPECT_EQ(read.rays[0].view, 0);
  EXPECT_TRUE(std::isinf(read.rays[0].length));
  EXPECT_EQ(read.rays[1].view, 2);
  EXPECT_EQ(read.rays[1].direction, Eigen::Vector3d(0.6, 0.0, 0.8));
  EXPECT_EQ(read.rays[1].length, 4.25);
  EXPECT_EQ(read.textured, 100);
  EXPECT_EQ(read.distant, 7);
  EXPECT_EQ(read.photos_judged, 3);
  // A ray of no length is refused, naming the file and the ray.
  found.rays[1].length = 0.0;
  WriteDistantPixels(path, plan.plan_id, found);
  try {
    ReadDistantPixels(path, plan);
    ADD_FAILURE() << "a ray of length 0 was read";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("distant.bin: ray 1"), std::string::npos) << message;
    EXPECT_NE(message.find("positive length"), std::string::npos) << message;
  }
  // Another plan's file is refused.
  TilePlan other = plan;
  other.plan_id = "fedcba9876543210";
  EXPECT_THROW(ReadDistantPixels(path, other), InputError);
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace raycarve
