#include "export/background_check.h"

#include <gtest/gtest.h>

#include "samples/synthetic_scene.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace exporter {
namespace {

TEST(BackgroundCheck, TrueSurfacePointsAreOnTheObjectAndPointsInTheAirAreNot) {
  const SyntheticScene scene =
      GenerateSyntheticScene(testing::SceneOptions(6, 200, 150, /*uniform_backdrop=*/true));
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
