#include "export/background_check.h"

#include <gtest/gtest.h>

#include "samples/synthetic_scene.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace exporter {
namespace {

TEST(BackgroundCheck, TrueSurfacePointsAreOnTheObjectAndPointsInTheAirAreNot) {
  SyntheticSceneOptions options;
  options.num_views = 6;
  options.width = 200;
  options.height = 150;
  options.num_surface_samples = 0;
  options.uniform_backdrop = true;
  const SyntheticScene scene = GenerateSyntheticScene(options);
  const std::vector<CalibratedView> views = testing::SceneViews(scene, /*with_masks=*/true);

  std::vector<Eigen::Vector3f> surface;
  for (const Eigen::Vector3d& p : SampleTrueSurface(scene, 5000, 1, 2)) surface.push_back(p.cast<float>());
  const BackgroundCheck on_object = CheckBackground(surface, views);
  EXPECT_GT(on_object.num_points, 1000u);
  // Measured 0: true surface points project onto the object's silhouette.
  EXPECT_LT(on_object.share, 0.01);

  std::vector<Eigen::Vector3f> air;  // a layer well above the sphere, box and ground
  for (int i = -10; i <= 10; ++i) {
    for (int j = -10; j <= 10; ++j) air.emplace_back(0.1f * i, 0.1f * j, 2.0f);
  }
  const BackgroundCheck in_air = CheckBackground(air, views);
  EXPECT_EQ(in_air.num_points, air.size());
  EXPECT_GT(in_air.share, 0.95);  // measured 1

  // Views without masks judge nothing.
  EXPECT_EQ(CheckBackground(air, testing::SceneViews(scene)).num_points, 0u);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
