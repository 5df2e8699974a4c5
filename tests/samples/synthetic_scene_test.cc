#include "samples/synthetic_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "samples/scene_tracing.h"
#include "tests/test_support.h"
#include "tests/scene_options.h"

namespace raycarve {
namespace {

SyntheticSceneOptions Small() { return testing::SceneOptions(6, 200, 150, false, 600); }

TEST(SyntheticScene, SameOptionsGiveTheSameSceneBitForBit) {
  const SyntheticScene a = GenerateSyntheticScene(Small());
  const SyntheticScene b = GenerateSyntheticScene(Small());
  testing::ExpectSameReconstruction(a.reconstruction, b.reconstruction);
  for (const auto& [id, photo] : a.photos) {
    EXPECT_EQ(cv::norm(photo, b.photos.at(id), cv::NORM_INF), 0.0);
  }
  SyntheticSceneOptions other = Small();
  other.seed = 2;
  EXPECT_NE(GenerateSyntheticScene(other).reconstruction.points3D.begin()->second.xyz,
            a.reconstruction.points3D.begin()->second.xyz);
}

// Largest channel difference between each observation's pixel (shifted `shift` pixels right) and
// its point's true colour, sorted.
std::vector<int> ColourDifferences(const SyntheticScene& scene, int shift) {
  std::vector<int> differences;
  for (const auto& [id, point3D] : scene.reconstruction.points3D) {
    for (const TrackElement& element : point3D.track) {
      const Point2D& point2D =
          scene.reconstruction.images.at(element.image_id).points2D.at(element.point2D_idx);
      const cv::Mat& photo = scene.photos.at(element.image_id);
      const int col = std::min(photo.cols - 1, static_cast<int>(point2D.xy.x()) + shift);
      const cv::Vec3b pixel = photo.at<cv::Vec3b>(static_cast<int>(point2D.xy.y()), col);
      int difference = 0;
      for (int k = 0; k < 3; ++k) {
        difference = std::max(difference, std::abs(pixel[k] - point3D.color[k]));
      }
      differences.push_back(difference);
    }
  }
  std::sort(differences.begin(), differences.end());
  return differences;
}

TEST(SyntheticScene, EveryPointIsSeenByTwoViewsAndItsPixelsShowItsColour) {
  const SyntheticScene scene = GenerateSyntheticScene(Small());
  const Reconstruction& model = scene.reconstruction;
  ASSERT_GT(model.points3D.size(), 200u);
  for (const auto& [id, point3D] : model.points3D) {
    EXPECT_GE(point3D.track.size(), 2u);
    EXPECT_TRUE(scene.object_box.contains(point3D.xyz));
    for (const TrackElement& element : point3D.track) {
      EXPECT_EQ(model.images.at(element.image_id).points2D.at(element.point2D_idx).point3D_id, id);
    }
  }
  // The pixel under each observation shows the point's colour (median difference 0, measured);
  // a quarter of them straddle a texture edge or silhouette at this small size. Three pixels off,
  // the median difference is large (44, measured), so the check does see position.
  const std::vector<int> at_point = ColourDifferences(scene, 0);
  const std::vector<int> shifted = ColourDifferences(scene, 3);
  EXPECT_LE(at_point[at_point.size() / 2], 2);
  EXPECT_GE(shifted[shifted.size() / 2], 20);
}

// Elevation (degrees above the horizontal) and azimuth (degrees) of a centre seen from the
// point every camera looks at, (0, 0, 0.35).
Eigen::Vector2d ElevationAzimuth(const Eigen::Vector3d& centre) {
  const Eigen::Vector3d d = centre - Eigen::Vector3d(0.0, 0.0, 0.35);
  return Eigen::Vector2d(std::asin(d.z() / d.norm()), std::atan2(d.y(), d.x())) * 180.0 / M_PI;
}

TEST(SyntheticScene, CameraLayoutsPutTheCamerasWhereTheySay) {
  const int n = 12;
  const std::vector<Eigen::Vector3d> ring = CameraCentres(CameraLayout::kRing, n);
  const std::vector<Eigen::Vector3d> close = CameraCentres(CameraLayout::kClose, n);
  const std::vector<Eigen::Vector3d> arc = CameraCentres(CameraLayout::kArc, n);
  const std::vector<Eigen::Vector3d> dome = CameraCentres(CameraLayout::kHemisphere, n);
  ASSERT_EQ(ring.size(), 12u);
  ASSERT_EQ(close.size(), 12u);
  ASSERT_EQ(arc.size(), 12u);
  ASSERT_EQ(dome.size(), 12u);
  const Eigen::Vector3d target(0.0, 0.0, 0.35);
  double arc_low = 1e9, arc_high = -1e9;
  for (int i = 0; i < n; ++i) {
    // The close ring is the ring at 0.6 of its distance, in the same directions.
    EXPECT_NEAR((close[i] - target).norm(), 0.6 * (ring[i] - target).norm(), 1e-9);
    EXPECT_NEAR((close[i] - target).normalized().dot((ring[i] - target).normalized()), 1.0, 1e-12);
    const Eigen::Vector2d up = ElevationAzimuth(dome[i]);
    EXPECT_NEAR((dome[i] - target).norm(), 5.6, 1e-9);
    EXPECT_GE(up.x(), 12.0 - 1e-9);
    EXPECT_LE(up.x(), 72.0 + 1e-9);
    const double azimuth = ElevationAzimuth(arc[i]).y();
    arc_low = std::min(arc_low, azimuth);
    arc_high = std::max(arc_high, azimuth);
  }
  // The arc spans 150 degrees, ends included; the ring goes all round.
  EXPECT_NEAR(arc_high - arc_low, 150.0, 1e-6);
  EXPECT_LT(ElevationAzimuth(dome.front()).x(), 20.0);
  EXPECT_GT(ElevationAzimuth(dome.back()).x(), 64.0);
  // Each layout's cameras see the scene's centre in the middle of the photo.
  for (CameraLayout layout : {CameraLayout::kRing, CameraLayout::kHemisphere, CameraLayout::kArc,
                              CameraLayout::kClose}) {
    SyntheticSceneOptions options = Small();
    options.num_views = 4;
    options.num_surface_samples = 0;
    options.layout = layout;
    const SyntheticScene scene = GenerateSyntheticScene(options);
    for (const auto& [id, image] : scene.reconstruction.images) {
      const Eigen::Vector3d local = image.cam_from_world * target;
      EXPECT_GT(local.z(), 0.0);
      EXPECT_NEAR(local.x() / local.z(), 0.0, 1e-9) << CameraLayoutToString(layout);
      EXPECT_NEAR(local.y() / local.z(), 0.0, 1e-9) << CameraLayoutToString(layout);
      EXPECT_GT(cv::countNonZero(scene.masks.at(id)), 0) << CameraLayoutToString(layout);
    }
  }
  CameraLayout parsed = CameraLayout::kRing;
  EXPECT_TRUE(CameraLayoutFromString("hemisphere", &parsed));
  EXPECT_EQ(parsed, CameraLayout::kHemisphere);
  EXPECT_FALSE(CameraLayoutFromString("dome", &parsed));
}

TEST(SyntheticScene, DetailedTextureChangesThePhotosNotTheGeometryAndPointsShowTheirColours) {
  const SyntheticScene plain = GenerateSyntheticScene(Small());
  SyntheticSceneOptions options = Small();
  options.detail_texture = true;
  const SyntheticScene detailed = GenerateSyntheticScene(options);
  // Same cameras, points, observations and masks; other colours.
  ASSERT_EQ(detailed.reconstruction.points3D.size(), plain.reconstruction.points3D.size());
  for (const auto& [id, point3D] : plain.reconstruction.points3D) {
    EXPECT_EQ(detailed.reconstruction.points3D.at(id).xyz, point3D.xyz);
  }
  double changed = 0.0;
  for (const auto& [id, photo] : plain.photos) {
    EXPECT_EQ(cv::norm(detailed.masks.at(id), plain.masks.at(id), cv::NORM_INF), 0.0);
    changed += cv::norm(detailed.photos.at(id), photo, cv::NORM_L1) / (photo.total() * 3.0);
  }
  // Mean change per channel over whole photos (the sky is unchanged): 2.87 grey levels, measured.
  EXPECT_GT(changed / plain.photos.size(), 1.0);
  // The noise is part of the surface colour: each point's pixels still show its colour, once
  // pixels are small against the finest noise (at 200x150 a pixel averages it). Measured at
  // 800x600: median 9 at the points, 28 three pixels off.
  options.width = 800;
  options.height = 600;
  options.num_views = 3;
  const SyntheticScene large = GenerateSyntheticScene(options);
  const int at_point = ColourDifferences(large, 0)[ColourDifferences(large, 0).size() / 2];
  const int shifted = ColourDifferences(large, 3)[ColourDifferences(large, 3).size() / 2];
  std::printf("median colour difference at the points %d, 3 pixels off %d\n", at_point, shifted);
  EXPECT_LE(at_point, 12);
  EXPECT_GT(shifted, 2 * at_point);
}

TEST(SyntheticScene, ThePapersSceneShowsItsTeapotWhereItsModelPutsIt) {
  RAYCARVE_REQUIRE_DATA("teapot/teapot_bezier.txt");
  SyntheticSceneOptions options = Small();
  options.scene = SceneKind::kPaper;
  options.teapot_path = data_path;
  options.num_surface_samples = 1500;
  const SyntheticScene scene = GenerateSyntheticScene(options);
  // The teapot (0.3 of the patches' 3.15 height) is the tallest object.
  EXPECT_NEAR(scene.object_box.max().z(), 0.945, 1e-6);
  int on_teapot = 0, observations = 0, on_mask = 0;
  for (const auto& [id, point3D] : scene.reconstruction.points3D) {
    EXPECT_GE(point3D.track.size(), 2u);
    EXPECT_TRUE(scene.object_box.contains(point3D.xyz));
    // The teapot stands at (0.25, -0.35) with a radius of about 0.45 (body 1.5 x 0.3).
    const Eigen::Vector2d from_axis = point3D.xyz.head<2>() - Eigen::Vector2d(0.25, -0.35);
    on_teapot += point3D.xyz.z() > 0.05 && from_axis.norm() < 0.55;
    // Observations lie on the object mask (the scene, not the sky).
    for (const TrackElement& element : point3D.track) {
      const Point2D& point2D =
          scene.reconstruction.images.at(element.image_id).points2D.at(element.point2D_idx);
      const cv::Mat& mask = scene.masks.at(element.image_id);
      ++observations;
      on_mask += mask.at<uint8_t>(static_cast<int>(point2D.xy.y()),
                                  static_cast<int>(point2D.xy.x())) == 255;
    }
  }
  EXPECT_GT(on_teapot, 50);
  // All but points on a silhouette, whose pixel is mostly sky (measured: 30 of 4282).
  std::printf("%d of %d observations on the mask, %d points on the teapot\n", on_mask,
              observations, on_teapot);
  EXPECT_GT(on_mask, 0.97 * observations);
  const std::vector<int> at_point = ColourDifferences(scene, 0);
  const std::vector<int> shifted = ColourDifferences(scene, 3);
  EXPECT_LE(at_point[at_point.size() / 2], 2);
  EXPECT_GE(shifted[shifted.size() / 2], 20);
  options.teapot_path = data_path + ".missing";
  EXPECT_THROW(GenerateSyntheticScene(options), InputError);
}

TEST(SyntheticScene, WritesAColmapProjectThatReadsBack) {
  const SyntheticScene scene = GenerateSyntheticScene(Small());
  const std::string root = testing::MakeTemporaryDirectory("synthetic_project");
  WriteSyntheticProject(scene, root);
  testing::ExpectSameReconstruction(scene.reconstruction, ReadModel(root + "/sparse/0"));
  for (const auto& [id, image] : scene.reconstruction.images) {
    EXPECT_TRUE(std::filesystem::is_regular_file(root + "/images/" + image.name)) << image.name;
  }
  std::filesystem::remove_all(root);
}

TEST(SyntheticScene, OptionsAreChecked) {
  std::string reason;
  SyntheticSceneOptions options;
  EXPECT_TRUE(options.IsValid(&reason));
  options.num_views = 1;
  EXPECT_FALSE(options.IsValid(&reason));
  options = SyntheticSceneOptions();
  options.camera_model = CameraModelId::kOpenCv;
  options.camera_params = {1, 2, 3};
  EXPECT_FALSE(options.IsValid(&reason));
  EXPECT_NE(reason.find("OPENCV"), std::string::npos);
  options = SyntheticSceneOptions();
  options.exposure_spread = 1.0;
  EXPECT_FALSE(options.IsValid(&reason));
  EXPECT_NE(reason.find("exposure_spread"), std::string::npos);
  options = SyntheticSceneOptions();
  options.specular = -0.1;
  EXPECT_FALSE(options.IsValid(&reason));
  EXPECT_NE(reason.find("specular"), std::string::npos);
}

TEST(SyntheticScene, ExposureAndHighlightsChangeThePhotosNotTheScene) {
  SyntheticSceneOptions options = Small();
  const SyntheticScene plain = GenerateSyntheticScene(options);
  options.exposure_spread = 0.3;
  const SyntheticScene exposed = GenerateSyntheticScene(options);
  options.exposure_spread = 0.0;
  options.specular = 1.0;
  const SyntheticScene glossy = GenerateSyntheticScene(options);
  testing::ExpectSameReconstruction(plain.reconstruction, exposed.reconstruction);
  testing::ExpectSameReconstruction(plain.reconstruction, glossy.reconstruction);
  std::vector<double> gains;
  for (const auto& [id, photo] : plain.photos) {
    EXPECT_EQ(cv::countNonZero(plain.masks.at(id) != exposed.masks.at(id)), 0);
    EXPECT_EQ(cv::countNonZero(plain.masks.at(id) != glossy.masks.at(id)), 0);
    // Exposure: the whole photo by one gain (the mean brightness's ratio, clipping aside).
    gains.push_back(cv::mean(exposed.photos.at(id))[0] / cv::mean(photo)[0]);
    // Highlights only brighten, and only some pixels.
    cv::Mat darker, changed;
    cv::compare(glossy.photos.at(id), photo, darker, cv::CMP_LT);
    cv::compare(glossy.photos.at(id), photo, changed, cv::CMP_NE);
    EXPECT_EQ(cv::countNonZero(darker.reshape(1)), 0);
    EXPECT_LT(cv::countNonZero(changed.reshape(1)), static_cast<int>(photo.total()));
  }
  const auto [low, high] = std::minmax_element(gains.begin(), gains.end());
  EXPECT_LT(*low, 0.85);
  EXPECT_GT(*high, 1.15);
  EXPECT_GT(*low, 0.69);
  EXPECT_LT(*high, 1.31);
  // Some photo shows a highlight.
  bool highlight = false;
  for (const auto& [id, photo] : plain.photos) {
    cv::Mat changed;
    cv::compare(glossy.photos.at(id), photo, changed, cv::CMP_NE);
    highlight = highlight || cv::countNonZero(changed.reshape(1)) > 20;
  }
  EXPECT_TRUE(highlight);
}

// The truth that holdout's sparse points are checked against (samples/truth_sparse_depth): the
// first solid surface along a ray, the objects, the ground square and the backdrop's floor, table
// or wall, and nothing where only sky lies ahead.
TEST(SyntheticScene, FirstSolidDistanceMeetsTheObjectsTheGroundAndTheBackdropsSolids) {
  using scene_tracing::FirstSolidDistance;
  SyntheticSceneOptions options;
  const std::shared_ptr<const SceneGeometry> g = MakeSceneGeometry(options);
  const Eigen::Vector3d camera(0.0, -6.0, 1.0);
  // Towards the sphere's centre: its near side, whatever the backdrop.
  const Eigen::Vector3d to_sphere = scene_tracing::kSphereCentre - camera;
  for (const Backdrop backdrop : {Backdrop::kPatchwork, Backdrop::kRoom, Backdrop::kCloudy}) {
    EXPECT_NEAR(FirstSolidDistance(*g, backdrop, camera, to_sphere.normalized()),
                to_sphere.norm() - scene_tracing::kSphereRadius, 1e-9);
  }
  // Straight down onto the ground square, beside the objects.
  EXPECT_NEAR(FirstSolidDistance(*g, Backdrop::kPatchwork, Eigen::Vector3d(1.2, -1.2, 1.0),
                                 -Eigen::Vector3d::UnitZ()),
              1.0, 1e-9);
  // Level, away from the scene: the room's wall 3 away (radius 9), sky in the patchwork.
  const Eigen::Vector3d away = -Eigen::Vector3d::UnitY();
  EXPECT_NEAR(FirstSolidDistance(*g, Backdrop::kRoom, camera, away), 3.0, 1e-9);
  EXPECT_TRUE(std::isinf(FirstSolidDistance(*g, Backdrop::kPatchwork, camera, away)));
  // Down at 45 degrees away from the scene: the field (or the room's floor) beyond the square.
  const Eigen::Vector3d down = Eigen::Vector3d(0.0, -1.0, -1.0).normalized();
  EXPECT_NEAR(FirstSolidDistance(*g, Backdrop::kCloudy, camera, down), std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(FirstSolidDistance(*g, Backdrop::kRoom, camera, down), std::sqrt(2.0), 1e-9);
  EXPECT_TRUE(std::isinf(FirstSolidDistance(*g, Backdrop::kPatchwork, camera, down)));
  // The studio table reaches a radius of 14: met at y = -11, not at y = -26.
  const Eigen::Vector3d steep = Eigen::Vector3d(0.0, -1.0, -0.2).normalized();
  const Eigen::Vector3d shallow = Eigen::Vector3d(0.0, -1.0, -0.05).normalized();
  EXPECT_NEAR(FirstSolidDistance(*g, Backdrop::kTwoTone, camera, steep), 5.0 * std::sqrt(1.04), 1e-9);
  EXPECT_TRUE(std::isinf(FirstSolidDistance(*g, Backdrop::kTwoTone, camera, shallow)));
  EXPECT_TRUE(std::isinf(FirstSolidDistance(*g, Backdrop::kUniform, camera, steep)));
}

}  // namespace
}  // namespace raycarve
