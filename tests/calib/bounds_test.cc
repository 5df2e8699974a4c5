#include "calib/bounds.h"

#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "samples/synthetic_scene.h"
#include "tests/test_support.h"
#include "tests/scene_options.h"

namespace raycarve {
namespace {

// Points uniformly inside `box`, each with a track of `track` images and the given error.
void AddPoints(const Eigen::AlignedBox3d& box,
               int count,
               int track,
               double error,
               std::mt19937_64* random,
               Reconstruction* model) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int i = 0; i < count; ++i) {
    Point3D point;
    point.xyz = box.min() + box.sizes().cwiseProduct(
                                Eigen::Vector3d(uniform(*random), uniform(*random), uniform(*random)));
    point.error = error;
    point.track.resize(track);
    model->points3D.emplace(model->points3D.size() + 1, point);
  }
}

const Eigen::AlignedBox3d kObject(Eigen::Vector3d(-1, -2, 0), Eigen::Vector3d(1, 2, 3));

// A model of pinhole cameras (640x480, f 500) at `centres`, each looking at `targets[i]` with
// its image's up towards +z, and 400 points spread over a sphere of radius 0.5 at the origin.
Reconstruction CamerasLookingAt(const std::vector<Eigen::Vector3d>& centres,
                                const std::vector<Eigen::Vector3d>& targets) {
  Reconstruction model;
  model.cameras[1] = testing::MakeCamera(1, CameraModelId::kPinhole, 640, 480, {500, 500, 320, 240});
  for (size_t i = 0; i < centres.size(); ++i) {
    const Eigen::Vector3d z = (targets[i] - centres[i]).normalized();
    const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d rows;
    rows << x.transpose(), y.transpose(), z.transpose();
    Image image;
    image.image_id = static_cast<image_t>(i + 1);
    image.camera_id = 1;
    image.name = "view" + std::to_string(i) + ".png";
    image.cam_from_world.rotation = Eigen::Quaterniond(rows);
    image.cam_from_world.translation = -(rows * centres[i]);
    model.images[image.image_id] = image;
  }
  std::mt19937 random(3);
  std::normal_distribution<double> normal;
  for (int p = 0; p < 400; ++p) {
    Point3D point;
    point.xyz = 0.5 * Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
    point.track = {{1, 0}, {2, 0}};
    model.points3D[static_cast<point3D_t>(p + 1)] = point;
  }
  return model;
}

TEST(DescribeCapture, TellsCamerasAroundAPointFromCamerasFacingOneWay) {
  const double kPi = 3.14159265358979;
  std::vector<Eigen::Vector3d> centres, targets;
  // A ring high above the object (60 degrees up), all looking at it: object-centred.
  for (int i = 0; i < 12; ++i) {
    const double a = 2.0 * kPi * i / 12;
    centres.emplace_back(2.0 * std::cos(a), 2.0 * std::sin(a), 2.0 * std::tan(kPi / 3));
    targets.emplace_back(0, 0, 0);
  }
  CaptureLayout layout = DescribeCapture(CamerasLookingAt(centres, targets));
  EXPECT_TRUE(layout.object_centred) << layout.Summary();
  EXPECT_LT(layout.focus.norm(), 1e-6);
  EXPECT_NEAR(layout.camera_distance, 4.0, 1e-6);
  EXPECT_NEAR(layout.cone_half_angle_degrees, 30.0, 1e-6);
  EXPECT_NEAR(layout.largest_gap_degrees, 30.0, 1e-6);
  // The points a photo frames around the focus: the sphere, with a tenth of margin.
  EXPECT_EQ(layout.focus_box_points, 400);
  EXPECT_NEAR(layout.focus_box.max().x(), 0.5 + 0.1, 0.05);
  // Half a ring at the object's height: a wide arc, object-centred.
  centres.clear();
  targets.clear();
  for (int i = 0; i < 9; ++i) {
    const double a = kPi * i / 8;
    centres.emplace_back(3.0 * std::cos(a), 3.0 * std::sin(a), 0.3);
    targets.emplace_back(0, 0, 0);
  }
  layout = DescribeCapture(CamerasLookingAt(centres, targets));
  EXPECT_TRUE(layout.object_centred) << layout.Summary();
  // A forward-facing grid of 4 x 3 cameras 5 units in front of a scene, all converging on it:
  // a narrow cone, a scene.
  centres.clear();
  targets.clear();
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      centres.emplace_back(-0.75 + 0.5 * col, -5.0, -0.5 + 0.5 * row);
      targets.emplace_back(0, 0, 0);
    }
  }
  layout = DescribeCapture(CamerasLookingAt(centres, targets));
  EXPECT_FALSE(layout.object_centred) << layout.Summary();
  EXPECT_LT(layout.cone_half_angle_degrees, kMinRingConeDegrees);
  // A walk along a facade: cameras on a line 4 units in front of it, each looking straight
  // ahead at the wall (axes parallel but for a slight turn towards the middle): a scene.
  centres.clear();
  targets.clear();
  for (int i = 0; i < 10; ++i) {
    centres.emplace_back(-4.5 + i, -4.0, 0.0);
    targets.emplace_back(0.9 * (-4.5 + i), 0.0, 0.0);
  }
  layout = DescribeCapture(CamerasLookingAt(centres, targets));
  EXPECT_FALSE(layout.object_centred) << layout.Summary();
}

// Four cameras on a line 2 wide, 5 in front of a scene at the origin (all looking along +y,
// 500 px focal length), seeing `near` points in the cube of side 2 there and `far` points on a
// wall 25 away.
Reconstruction ForwardScene(int near, int far) {
  std::vector<Eigen::Vector3d> centres, targets;
  for (int i = 0; i < 4; ++i) {
    centres.emplace_back(-1.0 + 2.0 * i / 3.0, -5.0, 0.0);
    targets.emplace_back(-1.0 + 2.0 * i / 3.0, 0.0, 0.0);
  }
  Reconstruction model = CamerasLookingAt(centres, targets);
  model.points3D.clear();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int p = 0; p < near + far; ++p) {
    Point3D point;
    point.xyz = p < near ? Eigen::Vector3d(unit(random), unit(random), unit(random))
                         : Eigen::Vector3d(10.0 * unit(random), 20.0, 5.0 * unit(random));
    point.track = {{1, 0}, {2, 0}, {3, 0}, {4, 0}};
    model.points3D[static_cast<point3D_t>(p + 1)] = point;
  }
  return model;
}

TEST(ResolveSceneDepth, NarrowsAForwardCapturesBoxToWhatItsBaselinePlacesInDepth) {
  const std::map<image_t, double> focal = {{1, 500.0}, {2, 500.0}, {3, 500.0}, {4, 500.0}};
  const Eigen::AlignedBox3d all(Eigen::Vector3d(-10, -1, -5), Eigen::Vector3d(10, 20, 5));
  // A voxel of 21/128 = 0.16. The cube: 5 away, rays 22 degrees apart, 0.01 a pixel: placed to
  // 0.03 a pixel. The wall: 25 away, 4.6 degrees, 0.05 a pixel: to 0.63, over two voxels.
  const DepthResolution depth = ResolveSceneDepth(ForwardScene(400, 300), focal, all, 128);
  EXPECT_NEAR(depth.voxel, 21.0 / 128, 1e-9);
  EXPECT_EQ(depth.points, 700);
  EXPECT_EQ(depth.resolved, 400);
  ASSERT_FALSE(depth.box.isEmpty()) << depth.Summary();
  // The cube, trimmed at 2% per axis, with a tenth of its side as margin.
  EXPECT_TRUE(depth.box.contains(Eigen::Vector3d(0.9, 0.9, -0.9)));
  EXPECT_LT(depth.box.max().y(), 1.3);
  EXPECT_GT(depth.box.min().x(), -1.3);
  EXPECT_NE(depth.Summary().find("400 of 700"), std::string::npos) << depth.Summary();
  // Every point placed (a finer baseline: the wall alone is 5 away): the box is kept.
  EXPECT_TRUE(ResolveSceneDepth(ForwardScene(400, 0), focal, all, 128).box.isEmpty());
  // Most points too far: the capture is of what lies far, and the box is kept.
  const DepthResolution mostly_far = ResolveSceneDepth(ForwardScene(200, 500), focal, all, 128);
  EXPECT_EQ(mostly_far.resolved, 200);
  EXPECT_TRUE(mostly_far.box.isEmpty());
  // A finer grid asks more of the baseline: at 2048 (a voxel of 0.01) only the cube's nearest
  // points (4 away, placed to 0.018) are within two voxels: under half, the box is kept.
  const DepthResolution fine = ResolveSceneDepth(ForwardScene(400, 300), focal, all, 2048);
  EXPECT_GT(fine.resolved, 0);
  EXPECT_LT(fine.resolved, 200);
  EXPECT_TRUE(fine.box.isEmpty());
  // Images without a focal length are not used.
  EXPECT_EQ(ResolveSceneDepth(ForwardScene(400, 300), {{1, 500.0}}, all, 128).points, 0);
}

TEST(Bounds, ContainTheObjectAndIgnoreFarOutliers) {
  std::mt19937_64 random(3);
  Reconstruction model;
  AddPoints(kObject, 2000, 3, 0.5, &random, &model);
  // 0.5% gross outliers, far away, with good tracks: only the trimming can remove them.
  AddPoints(Eigen::AlignedBox3d(Eigen::Vector3d(50, 50, 50), Eigen::Vector3d(60, 60, 60)),
            10, 3, 0.5, &random, &model);
  // Bad points that the filters remove: short tracks and high errors, even farther out.
  AddPoints(Eigen::AlignedBox3d(Eigen::Vector3d(-90, -90, -90), Eigen::Vector3d(-80, -80, -80)),
            200, 1, 0.5, &random, &model);
  AddPoints(Eigen::AlignedBox3d(Eigen::Vector3d(80, 80, 80), Eigen::Vector3d(90, 90, 90)),
            200, 4, 7.0, &random, &model);

  const Bounds bounds = ComputeBounds(model, BoundsOptions(), "test");
  EXPECT_EQ(bounds.num_points, 2410);
  EXPECT_EQ(bounds.num_short_track, 200);
  EXPECT_EQ(bounds.num_high_error, 200);
  EXPECT_EQ(bounds.num_used, 2010);
  // Trimming 1% per end and adding 10% of the largest extent covers the object...
  EXPECT_TRUE(bounds.box.contains(kObject)) << bounds.Summary();
  // ...without reaching for the outliers: at most the margin beyond the object.
  const Eigen::AlignedBox3d reach(kObject.min().array() - 0.11 * 4, kObject.max().array() + 0.11 * 4);
  EXPECT_TRUE(reach.contains(bounds.box)) << bounds.Summary();
  EXPECT_FALSE(bounds.Summary().empty());
}

TEST(Bounds, WithoutTrimmingOutliersStretchTheBox) {
  std::mt19937_64 random(4);
  Reconstruction model;
  AddPoints(kObject, 500, 3, 0.5, &random, &model);
  AddPoints(Eigen::AlignedBox3d(Eigen::Vector3d(50, 50, 50), Eigen::Vector3d(60, 60, 60)),
            3, 3, 0.5, &random, &model);
  BoundsOptions options;
  options.trim_fraction = 0.0;
  EXPECT_GT(ComputeBounds(model, options, "test").box.max().x(), 50.0);
}

TEST(Bounds, TheRoomAroundTheObjectIsLeftOut) {
  // The generated scene in a textured room whose floor and wall hold as many sparse points as the
  // scene: the room is framed by the few photos facing it, the scene by all of them.
  SyntheticSceneOptions options = testing::SceneOptions(12, 160, 120, false, 1500);
  options.backdrop = Backdrop::kRoom;
  const SyntheticScene room = GenerateSyntheticScene(options);
  BoundsOptions keep_all;
  keep_all.min_framed_share = 0.0;
  const Bounds blind = ComputeBounds(room.reconstruction, keep_all, "room");
  const Bounds bounds = ComputeBounds(room.reconstruction, BoundsOptions(), "room");
  // Without the rule the box reaches the wall (radius 9) on every side.
  EXPECT_GT(blind.box.sizes().head<2>().minCoeff(), 15.0) << blind.Summary();
  EXPECT_EQ(blind.num_unframed, 0);
  // With it the box holds the scene (the ground square is 3 wide) and a little of the floor.
  EXPECT_GT(bounds.num_unframed, bounds.num_points / 4) << bounds.Summary();
  EXPECT_TRUE(bounds.box.contains(room.object_box.min()) && bounds.box.contains(room.object_box.max()))
      << bounds.Summary();
  EXPECT_LT(bounds.box.sizes().head<2>().maxCoeff(), 6.0) << bounds.Summary();
  EXPECT_NE(bounds.Summary().find("room around"), std::string::npos) << bounds.Summary();

  // The same scene under the patchwork sky has no room: nothing is dropped, the box is the same
  // as without the rule.
  options.backdrop = Backdrop::kPatchwork;
  const SyntheticScene open = GenerateSyntheticScene(options);
  const Bounds open_bounds = ComputeBounds(open.reconstruction, BoundsOptions(), "open");
  EXPECT_EQ(open_bounds.num_unframed, 0) << open_bounds.Summary();
  EXPECT_TRUE(open_bounds.box.isApprox(ComputeBounds(open.reconstruction, keep_all, "open").box));
}

TEST(Bounds, ErrorsNameTheSourceAndSayWhatDroppedThePoints) {
  Reconstruction empty;
  try {
    ComputeBounds(empty, BoundsOptions(), "sparse/0");
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("sparse/0"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("no 3D points"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("--bbox"), std::string::npos);
  }
  std::mt19937_64 random(5);
  Reconstruction filtered;
  AddPoints(kObject, 5, 1, 0.5, &random, &filtered);
  AddPoints(kObject, 7, 3, 9.0, &random, &filtered);
  try {
    ComputeBounds(filtered, BoundsOptions(), "sparse/0");
    FAIL();
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("all 12 3D points"), std::string::npos) << message;
    EXPECT_NE(message.find("5 with track length < 2"), std::string::npos) << message;
    EXPECT_NE(message.find("7 with error > 2"), std::string::npos) << message;
  }
  Reconstruction single;
  AddPoints(Eigen::AlignedBox3d(Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1)), 3, 3, 0.1,
            &random, &single);
  EXPECT_THROW(ComputeBounds(single, BoundsOptions(), "x"), InputError);
}

TEST(Bounds, ExplicitBoxIsCheckedAndOptionsValidated) {
  EXPECT_TRUE(ExplicitBounds(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 2, 3)).is_explicit);
  EXPECT_THROW(ExplicitBounds(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 3)), InputError);
  EXPECT_THROW(ExplicitBounds(Eigen::Vector3d(0, std::nan(""), 0), Eigen::Vector3d(1, 1, 1)),
               InputError);
  std::string reason;
  BoundsOptions options;
  EXPECT_TRUE(options.IsValid(&reason));
  options.trim_fraction = 0.5;
  EXPECT_FALSE(options.IsValid(&reason));
  EXPECT_NE(reason.find("trim_fraction"), std::string::npos);
  options = BoundsOptions();
  options.margin = -1;
  EXPECT_FALSE(options.IsValid(&reason));
  options = BoundsOptions();
  options.min_framed_share = 1.5;
  EXPECT_FALSE(options.IsValid(&reason));
  EXPECT_NE(reason.find("min_framed_share"), std::string::npos);
}

// The real sets: bounds from COLMAP models made by the real program contain the object's tight
// box given in the set's README (in the calibration's frame).
class RealBounds : public ::testing::TestWithParam<std::string> {};

TEST_P(RealBounds, FromTheCalibrationFrameModelContainTheReadmeBox) {
  RAYCARVE_REQUIRE_DATA("middlebury/" + GetParam() + "/colmap/given");
  const Eigen::AlignedBox3d object = testing::ReadMiddleburyReadmeBox(
      testing::DataDirectory() + "/middlebury/" + GetParam() + "/README.txt");
  const Bounds bounds = ComputeBounds(ReadModel(data_path), BoundsOptions(), data_path);
  EXPECT_TRUE(bounds.box.contains(object)) << bounds.Summary();
  // And they are a bound, not the world: within 3x the object's extent on every axis.
  EXPECT_TRUE((bounds.box.sizes().array() < 3.0 * object.sizes().array()).all()) << bounds.Summary();
}

INSTANTIATE_TEST_SUITE_P(Middlebury,
                         RealBounds,
                         ::testing::Values("templeSparseRing", "dinoSparseRing", "dinoRing"));

// In COLMAP's own SfM frame. The object is represented by the calibration-frame model's points
// that lie in the README box (triangulated with the calibration's poses, independently of the SfM
// points), carried over by the similarity that maps the calibration's camera centres onto the
// SfM ones (Umeyama). (The box's own corners are no test: rotated into the SfM frame they stand
// far off the object.)
class RealSfmBounds : public ::testing::TestWithParam<std::string> {};

TEST_P(RealSfmBounds, FromStructureFromMotionContainTheObjectMovedIntoItsFrame) {
  RAYCARVE_REQUIRE_DATA("middlebury/" + GetParam() + "/colmap/sfm");
  const std::string set = testing::DataDirectory() + "/middlebury/" + GetParam();
  const Reconstruction sfm = ReadModel(set + "/colmap/sfm");
  const Reconstruction given = ReadModel(set + "/colmap/given");
  std::map<std::string, Eigen::Vector3d> given_centres;
  for (const auto& [id, image] : given.images) given_centres[image.name] = image.ProjectionCenter();
  Eigen::Matrix3Xd from(3, sfm.images.size()), to(3, sfm.images.size());
  int column = 0;
  for (const auto& [id, image] : sfm.images) {
    ASSERT_EQ(given_centres.count(image.name), 1u) << image.name;
    from.col(column) = given_centres.at(image.name);
    to.col(column) = image.ProjectionCenter();
    ++column;
  }
  const Eigen::Matrix4d sfm_from_given = Eigen::umeyama(from, to, true);
  const Eigen::AlignedBox3d object = testing::ReadMiddleburyReadmeBox(set + "/README.txt");
  const Bounds bounds = ComputeBounds(sfm, BoundsOptions(), set + "/colmap/sfm");
  int on_object = 0, inside = 0;
  for (const auto& [id, point3D] : given.points3D) {
    if (!object.contains(point3D.xyz)) continue;
    ++on_object;
    const Eigen::Vector3d moved = (sfm_from_given * point3D.xyz.homogeneous()).hnormalized();
    if (bounds.box.contains(moved)) ++inside;
  }
  EXPECT_GT(on_object, 500);
  EXPECT_EQ(inside, on_object) << bounds.Summary();
}

// dinoSparseRing is left out: its SfM poses fit the calibration's camera centres only to 0.026
// rms (4.1% of the ring radius, about 30% of the dino's size; measured), so the moved object
// points are too uncertain to judge containment. temple and dinoRing fit to 0.0027 rms (0.5%).
INSTANTIATE_TEST_SUITE_P(Middlebury,
                         RealSfmBounds,
                         ::testing::Values("templeSparseRing", "dinoRing"));

}  // namespace
}  // namespace raycarve
