#include "carve/surface_evidence.h"

#include <algorithm>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "carve/patch_correlation.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

SyntheticScene TexturedScene() {
  SyntheticSceneOptions options = testing::SceneOptions(8, 320, 240, false, 1500);
  options.detail_texture = true;
  return GenerateSyntheticScene(options);
}

// The rule the tests use: two views, the 99% quantile with masks.
ThresholdRule Rule(ConsistencyMethod method, bool masked, double fallback, double pattern_fallback) {
  ThresholdRule rule;
  rule.test_method = method;
  rule.min_views = 2;
  rule.masked = masked;
  rule.quantile = 0.99;
  rule.fallback = fallback;
  rule.pattern_fallback = pattern_fallback;
  return rule;
}

TEST(ThresholdEstimate, QuantilesInterpolateAndTheEqualErrorPointSitsBetweenTheLists) {
  const std::vector<double> values = {0, 10, 20, 30, 40};
  EXPECT_DOUBLE_EQ(ThresholdEstimate::Quantile(values, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(ThresholdEstimate::Quantile(values, 0.5), 20.0);
  EXPECT_DOUBLE_EQ(ThresholdEstimate::Quantile(values, 0.875), 35.0);
  EXPECT_DOUBLE_EQ(ThresholdEstimate::Quantile(values, 1.0), 40.0);
  EXPECT_DOUBLE_EQ(ThresholdEstimate::Quantile({}, 0.5), 0.0);
  // Surface errors 1..10, front errors 6..15: at t = 8 two of ten surface values lie above and
  // three of ten front values at or below; at 7 three above and two below.
  std::vector<double> surface, front;
  for (int i = 1; i <= 10; ++i) {
    surface.push_back(i);
    front.push_back(i + 5);
  }
  EXPECT_DOUBLE_EQ(ThresholdEstimate::EqualError(surface, front), 8.0);
  // Weighted: a carved surface voxel may be 3x as likely as a kept front voxel: at t = 7 (3 of
  // 10 above) against 3 x (2 of 10).
  EXPECT_DOUBLE_EQ(ThresholdEstimate::EqualError(surface, front, 3.0), 7.0);
  // Fully separated lists: the largest surface value.
  EXPECT_DOUBLE_EQ(ThresholdEstimate::EqualError({1, 2, 3}, {10, 11}), 3.0);
}

TEST(GatherVoxelPixels, CountsExactlyThePixelsWhoseRayMeetsTheCube) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(3, 80, 60));
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  const VoxelGrid grid(scene.object_box, 12);
  for (const Eigen::Vector3i& voxel : {Eigen::Vector3i(2, 3, 1), Eigen::Vector3i(6, 6, 2)}) {
    for (const CalibratedView& view : views) {
      ViewColourStats stats;
      GatherVoxelPixels(view, grid, voxel, &stats);
      int expected = 0;
      const Eigen::Matrix3d world_from_pixel = view.WorldFromPixel();
      for (int row = 0; row < view.height; ++row) {
        for (int col = 0; col < view.width; ++col) {
          double t = 0.0;
          expected += testing::RayEntersVoxel(grid, voxel, view.centre,
                                              world_from_pixel * Eigen::Vector3d(col + 0.5, row + 0.5, 1),
                                              &t);
        }
      }
      EXPECT_NEAR(stats.count, expected, 1 + expected / 20) << view.name;
      EXPECT_GT(expected, 0);
    }
  }
}

// On the generated scene the voxels holding true surface points agree far better than the voxels
// two voxels in front of them, and the threshold is chosen between them as documented.
TEST(EstimateThreshold, SeparatesTheSurfaceFromTheSpaceInFrontAndChoosesByTheDocumentedRule) {
  const SyntheticScene scene = TexturedScene();
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  const std::vector<SurfacePoint> points = testing::SceneSurfacePoints(scene);
  ASSERT_GT(points.size(), 100u);
  const VoxelGrid grid(scene.object_box, 96);
  const ThresholdEstimate unmasked =
      EstimateThreshold(views, grid, points, Rule(ConsistencyMethod::kMeanColour, false, -7.0, 0.5));
  EXPECT_EQ(unmasked.points_judged, static_cast<int>(unmasked.surface_errors.size()));
  EXPECT_GT(unmasked.points_judged, static_cast<int>(points.size()) * 9 / 10);
  ASSERT_GT(unmasked.front_errors.size(), points.size() / 2);
  const double surface_median = ThresholdEstimate::Quantile(unmasked.surface_errors, 0.5);
  const double front_median = ThresholdEstimate::Quantile(unmasked.front_errors, 0.5);
  std::cout << unmasked.Summary() << "\n";
  EXPECT_LT(2.0 * surface_median, front_median);
  // The rule leaves out the points whose two voxels both agree to the last quantisation step.
  const size_t drop = unmasked.uninformative;
  EXPECT_DOUBLE_EQ(
      unmasked.threshold,
      ThresholdEstimate::EqualError(
          std::vector<double>(unmasked.surface_errors.begin() + drop, unmasked.surface_errors.end()),
          std::vector<double>(unmasked.front_errors.begin() + drop, unmasked.front_errors.end()),
          ThresholdEstimate::kFrontWeight));
  EXPECT_GT(unmasked.threshold, surface_median);
  EXPECT_LT(unmasked.threshold, front_median);
  EXPECT_GT(unmasked.FrontCarved(), 0.5);

  const ThresholdEstimate masked =
      EstimateThreshold(testing::SceneViews(scene, /*with_masks=*/true), grid, points,
                        Rule(ConsistencyMethod::kMeanColour, true, -7.0, 0.5));
  EXPECT_NEAR(masked.threshold, ThresholdEstimate::Quantile(masked.surface_errors, 0.99), 1e-9);
  EXPECT_GT(masked.threshold, unmasked.threshold);

  // Too few points: the fallback.
  const std::vector<SurfacePoint> few(points.begin(), points.begin() + 5);
  const ThresholdEstimate fallback =
      EstimateThreshold(views, grid, few, Rule(ConsistencyMethod::kMeanColour, false, -7.0, 0.5));
  EXPECT_EQ(fallback.threshold, -7.0);
}

// A view sees a point unless a solid voxel lies on its sight line farther than the margin from
// the point; a view behind the camera or out of frame never does; the track always does.
TEST(SeenThrough, KeepsTheTrackAndTheViewsWhoseSightLineNoSolidVoxelBlocks) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(8, 160, 120));
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  const VoxelGrid grid(scene.object_box, 32);
  const Eigen::Vector3d point = scene.object_box.center();
  std::vector<uint64_t> none((grid.num_voxels() + 63) / 64, 0);
  const Volume empty(grid, none);
  std::vector<int> in_frame;
  for (int v = 0; v < static_cast<int>(views.size()); ++v) {
    const Eigen::Vector2d pixel = views[v].Project(point);
    if (views[v].Depth(point) > 0.0 && pixel.x() >= 0 && pixel.y() >= 0 &&
        pixel.x() < views[v].width && pixel.y() < views[v].height) {
      in_frame.push_back(v);
    }
  }
  ASSERT_GE(in_frame.size(), 4u);
  std::vector<int> seen = SeenThrough(views, empty, point, 0.0, {});
  EXPECT_EQ(seen, in_frame);

  // A solid voxel halfway from the point to the first view's centre (inside the grid) blocks
  // that view alone; within the margin it does not.
  const int blocked = in_frame[0];
  std::vector<uint64_t> one = none;
  const Eigen::Vector3d towards = (views[blocked].centre - point).normalized();
  const Eigen::Vector3d blocker = point + towards * 8.0 * grid.voxel_size();
  ASSERT_TRUE(grid.Contains(grid.VoxelOf(blocker)));
  const int64_t index = grid.Index(grid.VoxelOf(blocker));
  one[index >> 6] |= uint64_t{1} << (index & 63);
  const Volume walled(grid, one);
  seen = SeenThrough(views, walled, point, 2.0 * grid.voxel_size(), {});
  EXPECT_EQ(std::count(seen.begin(), seen.end(), blocked), 0);
  EXPECT_EQ(seen.size(), in_frame.size() - 1);
  seen = SeenThrough(views, walled, point, 10.0 * grid.voxel_size(), {});
  EXPECT_EQ(seen, in_frame);
  // The track is kept as it is, first, though the wall blocks it.
  seen = SeenThrough(views, walled, point, 2.0 * grid.voxel_size(), {blocked});
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.front(), blocked);
  EXPECT_EQ(seen.size(), in_frame.size());
  // A solid grid: nothing but the track.
  std::vector<uint64_t> all((grid.num_voxels() + 63) / 64, ~uint64_t{0});
  EXPECT_EQ(SeenThrough(views, Volume(grid, all), point, 2.0 * grid.voxel_size(), {3}),
            std::vector<int>{3});
}

// Tracks cut to two neighbouring views (as SIFT's are: the photos that matched a point) judge the
// space in front of the surface from nearly one direction, and the threshold falls; judged from
// every view that sees each point through the object's own volume, the estimate comes back
// towards the one of the full tracks (every view that sees the point).
TEST(EstimateThreshold, PointsJudgedFromTheViewsThatSeeThemNotTheirNarrowTracks) {
  const SyntheticScene scene = TexturedScene();
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  const std::vector<SurfacePoint> full = testing::SceneSurfacePoints(scene);
  ASSERT_GT(full.size(), 100u);
  std::vector<SurfacePoint> narrow = full;
  for (SurfacePoint& point : narrow) point.views.resize(2);
  const VoxelGrid grid(scene.object_box, 64);
  // The object's volume: the visual hull of its masks at the grid.
  CarveOptions hull = testing::Options(64, 1e9);
  hull.lod_levels = 1;
  const CarveResult carved =
      CarveVolume(testing::SceneViews(scene, /*with_masks=*/true), scene.object_box, hull);

  const ThresholdRule rule = Rule(ConsistencyMethod::kMeanColour, false, -7.0, 0.5);
  const ThresholdEstimate from_full = EstimateThreshold(views, grid, full, rule);
  const ThresholdEstimate from_narrow = EstimateThreshold(views, grid, narrow, rule);
  ThresholdRule seen_rule = rule;
  seen_rule.seen_through = &carved.volume;
  const ThresholdEstimate from_seen = EstimateThreshold(views, grid, narrow, seen_rule);
  std::cout << "full tracks: " << from_full.Summary() << "\nnarrow: " << from_narrow.Summary()
            << "\nseen: " << from_seen.Summary() << "\n";
  EXPECT_EQ(from_narrow.views_judged, from_narrow.track_views);
  EXPECT_EQ(from_narrow.track_views, 2 * from_narrow.points_in_grid);
  // The hull of eight views is fat: fewer views see through it than see the object (2.9 a point
  // against the full tracks' 4.0), but more than the two of the track.
  EXPECT_GT(from_seen.views_judged, from_seen.track_views * 13 / 10);
  EXPECT_LT(from_seen.views_judged, from_full.views_judged);
  const double front_narrow = ThresholdEstimate::Quantile(from_narrow.front_errors, 0.5);
  const double front_seen = ThresholdEstimate::Quantile(from_seen.front_errors, 0.5);
  EXPECT_GT(front_seen, 1.15 * front_narrow);
  EXPECT_LT(from_narrow.threshold, from_full.threshold);
  EXPECT_GT(from_seen.threshold, from_narrow.threshold);
  EXPECT_LT(std::abs(from_seen.threshold - from_full.threshold),
            std::abs(from_narrow.threshold - from_full.threshold));
  // A long list is sampled (every k-th point, at most kMaxSeenThroughPoints): the same points
  // five times over give the same threshold from a sample of them.
  std::vector<SurfacePoint> many;
  for (int copy = 0; copy < 5; ++copy) many.insert(many.end(), narrow.begin(), narrow.end());
  ASSERT_GT(many.size(), ThresholdEstimate::kMaxSeenThroughPoints);
  const ThresholdEstimate sampled = EstimateThreshold(views, grid, many, seen_rule);
  EXPECT_LE(static_cast<size_t>(sampled.points_in_grid), ThresholdEstimate::kMaxSeenThroughPoints);
  EXPECT_GT(static_cast<size_t>(sampled.points_in_grid), ThresholdEstimate::kMaxSeenThroughPoints / 2);
  EXPECT_NEAR(sampled.threshold, from_seen.threshold, 0.1 * from_seen.threshold);
  // With masks the rule stays on the tracks.
  ThresholdRule masked_rule = seen_rule;
  masked_rule.masked = true;
  const ThresholdEstimate masked =
      EstimateThreshold(testing::SceneViews(scene, true), grid, narrow, masked_rule);
  EXPECT_EQ(masked.views_judged, masked.track_views);
}

// Every photo's exposure and white balance changed (a gain and an offset per view and channel):
// the mean-colour test's errors on the true surface nearly double, while the patch test's
// barely move, and it still tells the surface from the space in front of it.
TEST(PatchCorrelation, IgnoresExposureAndWhiteBalanceAndTellsTheSurfaceFromTheSpaceInFront) {
  const SyntheticScene scene = TexturedScene();
  std::vector<CalibratedView> views = testing::SceneViews(scene);
  std::vector<CalibratedView> exposed = views;
  for (size_t v = 0; v < exposed.size(); ++v) {
    const double gain = 0.65 + 0.1 * v;
    const cv::Scalar offset(5.0 * (v % 3), -4.0 * (v % 2), 6.0 * ((v + 1) % 2));
    cv::Mat changed;
    exposed[v].image.convertTo(changed, CV_8UC3, gain);
    changed += offset;
    exposed[v].image = changed;
  }
  const std::vector<SurfacePoint> points = testing::SceneSurfacePoints(scene);
  const VoxelGrid grid(scene.object_box, 96);
  const ThresholdEstimate plain = EstimateThreshold(
      views, grid, points, Rule(ConsistencyMethod::kPatchCorrelation, false, 30, 0.5));
  const ThresholdEstimate changed = EstimateThreshold(
      exposed, grid, points, Rule(ConsistencyMethod::kPatchCorrelation, false, 30, 0.5));
  std::cout << "plain photos: " << plain.Summary() << "\nexposure changed: " << changed.Summary()
            << "\n";
  ASSERT_GT(plain.surface_pattern_errors.size(), points.size() / 2);
  ASSERT_GT(changed.surface_pattern_errors.size(), points.size() / 2);
  const double colour_plain = ThresholdEstimate::Quantile(plain.surface_errors, 0.5);
  const double colour_changed = ThresholdEstimate::Quantile(changed.surface_errors, 0.5);
  const double pattern_plain = ThresholdEstimate::Quantile(plain.surface_pattern_errors, 0.5);
  const double pattern_changed = ThresholdEstimate::Quantile(changed.surface_pattern_errors, 0.5);
  // Measured (8 views of 320x240, 96 voxels): mean-colour median 18.6 -> 35.8; patterns (1 - NCC)
  // 0.29 -> 0.29, against 0.73 in front.
  EXPECT_GT(colour_changed, 1.5 * colour_plain);
  EXPECT_LT(pattern_changed, pattern_plain + 0.03);
  EXPECT_LT(pattern_changed, 0.35);
  EXPECT_GT(ThresholdEstimate::Quantile(changed.front_pattern_errors, 0.5), 2.0 * pattern_changed);
}

TEST(PatchCorrelation, AUniformPatchIsNotTexturedAndAMinorityOfViewsDoesNotVeto) {
  CalibratedView view;
  view.width = 64;
  view.height = 48;
  view.K << 60, 0, 32, 0, 60, 24, 0, 0, 1;
  view.image = cv::Mat(48, 64, CV_8UC3, cv::Scalar(120, 90, 60));
  std::vector<CalibratedView> views;
  // Five cameras on an arc looking at the origin from z = -2 (world z towards the plane z = 0).
  for (int i = 0; i < 5; ++i) {
    CalibratedView v = view;
    const double angle = (i - 2) * 0.08;
    v.centre = Eigen::Vector3d(2.0 * std::sin(angle), 0.0, -2.0 * std::cos(angle));
    const Eigen::Matrix3d world_from_cam =
        Eigen::AngleAxisd(-angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
    v.cam_from_world.rotation = Eigen::Quaterniond(world_from_cam.transpose());
    v.cam_from_world.translation = -(world_from_cam.transpose() * v.centre);
    v.P = v.K * v.cam_from_world.ToMatrix();
    views.push_back(v);
  }
  std::vector<ViewColourStats> stats(5);
  for (int i = 0; i < 5; ++i) {
    stats[i].view = i;
    stats[i].count = 10;
  }
  EXPECT_FALSE(CorrelatePatches(views, Eigen::Vector3d::Zero(), 0.1, stats).textured);

  // A texture painted on the plane z = 0, seen by each view: the same pattern in all.
  for (CalibratedView& v : views) {
    for (int row = 0; row < v.height; ++row) {
      for (int col = 0; col < v.width; ++col) {
        // The point of z = 0 this pixel sees.
        const Eigen::Matrix3d world_from_pixel = v.WorldFromPixel();
        const Eigen::Vector3d d = world_from_pixel * Eigen::Vector3d(col + 0.5, row + 0.5, 1);
        const Eigen::Vector3d p = v.centre + (-v.centre.z() / d.z()) * d;
        const double value = 128 + 90 * std::sin(40 * p.x()) * std::cos(33 * p.y());
        v.image.at<cv::Vec3b>(row, col) = cv::Vec3b(value, value, value);
      }
    }
  }
  const PatchCorrelation agreed = CorrelatePatches(views, Eigen::Vector3d::Zero(), 0.1, stats);
  ASSERT_TRUE(agreed.textured);
  EXPECT_LT(agreed.error(), 0.1);
  // One view of five sees an occluder (noise): the worst quarter is dropped.
  cv::randu(views[4].image, cv::Scalar::all(0), cv::Scalar::all(255));
  const PatchCorrelation one_off = CorrelatePatches(views, Eigen::Vector3d::Zero(), 0.1, stats);
  EXPECT_LT(one_off.error(), 0.2);
  // A voxel three patch widths in front of the plane: each view sees another part of it.
  const PatchCorrelation front =
      CorrelatePatches(views, Eigen::Vector3d(0, 0, -0.6), 0.1, stats);
  EXPECT_GT(front.error(), 0.4);
}

}  // namespace
}  // namespace raycarve
