// `raycarve sfm` drives the real `colmap` (CPU): COLMAP's cameras agree with the calibration
// after a similarity alignment, the project it leaves carves, and bad requests are refused.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "calib/model_reader.h"
#include "export/similarity_alignment.h"
#include "pipeline/workspace.h"
#include "tests/test_support.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;

std::string Raycarve() { return "'" + testing::RaycarveBinary() + "' "; }

// The camera centres of `recovered` and of `truth` for the images both hold (by name).
void MatchCentres(const Reconstruction& recovered,
                  const Reconstruction& truth,
                  std::vector<Eigen::Vector3d>* source,
                  std::vector<Eigen::Vector3d>* target,
                  std::vector<std::pair<Eigen::Matrix3d, Eigen::Matrix3d>>* rotations = nullptr) {
  for (const auto& [id, image] : recovered.images) {
    for (const auto& [truth_id, truth_image] : truth.images) {
      if (truth_image.name != image.name) continue;
      source->push_back(image.ProjectionCenter());
      target->push_back(truth_image.ProjectionCenter());
      if (rotations != nullptr) {
        rotations->emplace_back(image.cam_from_world.rotation.toRotationMatrix(),
                                truth_image.cam_from_world.rotation.toRotationMatrix());
      }
    }
  }
}

// The mean distance of points from their centroid.
double Spread(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& point : points) centroid += point / points.size();
  double spread = 0.0;
  for (const Eigen::Vector3d& point : points) spread += (point - centroid).norm() / points.size();
  return spread;
}

// "COLMAP after SfM" on the generator: the real colmap recovers the generated cameras. The plain
// renders are too plain for it (12 views of 480x360: 750-1200 SIFT features a photo, at most 61
// inliers a pair, no model; a fine speckle on every texture registered all 12, but in two
// clusters, the repeating checkers and sky patches misleading the matching). With
// `--texture detailed` (non-repeating noise on every surface) and the studio backdrop it works.
TEST(ColmapSfm, RecoversTheGeneratedCamerasUpToASimilarityAndTheProjectCarvesTheTruth) {
  RAYCARVE_REQUIRE_COLMAP();
  const std::string root = testing::MakeTemporaryDirectory("colmap_sfm_generated");
  std::string log;
  ASSERT_EQ(testing::RunShell(Raycarve() + "synth --output_path " + root +
                                  "/scene --views 16 --width 640 --height 480 --texture detailed "
                                  "--backdrop uniform",
                              &log),
            0)
      << log;
  const Reconstruction truth = ReadModel(root + "/scene/sparse/0");
  const Camera& camera = truth.cameras.begin()->second;
  std::string params;
  for (size_t i = 0; i < camera.params.size(); ++i) {
    params += (i == 0 ? "" : ",") + std::to_string(camera.params[i]);
  }
  ASSERT_EQ(testing::RunShell(Raycarve() + "sfm --image_path " + root + "/scene/images " +
                                  "--workspace_path " + root + "/sfm --camera_model PINHOLE " +
                                  "--camera_params " + params +
                                  " --abs_pose_min_num_inliers 15 --init_min_tri_angle 8"
                                  // One thread: faster on two cores under parallel test load
                                  // (39 s against 65 s). COLMAP's runs still differ.
                                  " --num_threads 1",
                              &log),
            0)
      << log;
  const Reconstruction recovered = ReadModel(root + "/sfm/sparse/0");
  std::vector<Eigen::Vector3d> source, target;
  std::vector<std::pair<Eigen::Matrix3d, Eigen::Matrix3d>> rotations;
  MatchCentres(recovered, truth, &source, &target, &rotations);
  // Measured: 16 of 16 registered, in one model.
  ASSERT_EQ(source.size(), 16u) << log;
  const exporter::Alignment alignment = exporter::AlignPoints(source, target);
  const double ring = Spread(target);
  // After the similarity, each recovered camera looks the true way: R_true = R_recovered S^T.
  double worst_degrees = 0.0;
  for (const auto& [recovered_rotation, true_rotation] : rotations) {
    const Eigen::Matrix3d difference =
        true_rotation.transpose() * recovered_rotation * alignment.transform.rotation.transpose();
    worst_degrees = std::max(worst_degrees,
                             Eigen::AngleAxisd(difference).angle() * 180.0 / M_PI);
  }
  double worst_residual = 0.0;
  for (size_t i = 0; i < source.size(); ++i) {
    worst_residual = std::max(worst_residual, (alignment.transform(source[i]) - target[i]).norm());
  }
  std::printf("%s; ring radius %.4f; worst camera %.4f off; worst orientation error %.3f "
              "degrees\n",
              alignment.Summary().c_str(), ring, worst_residual, worst_degrees);
  // Measured: RMS 0.034-0.075 against a ring radius of 5.02 (0.7-1.5%), orientations within
  // 0.8-3.4 degrees (colmap's runs differ, even on one thread). The scene fills a quarter of each
  // photo, a weak geometry for SfM: in one CI run of many, one camera of 16 lay just beyond the
  // inlier band (5% of the ring) while the other 15 gave RMS 0.047 and the carve F 0.9985 within
  // two voxels. A frame or convention error puts every camera far off; one camera in the tail of
  // colmap's spread is colmap's.
  EXPECT_GE(alignment.num_inliers, 15);
  EXPECT_LT(worst_residual, 0.1 * ring);
  EXPECT_LT(alignment.rms, 0.03 * ring);
  EXPECT_LT(worst_degrees, 4.0);

  // The SfM project carves at the command's defaults, and its cloud, moved into the generator's
  // frame by the cameras, lies on the true surface. The recovered poses are off by about a
  // degree, so the photos agree less on the true surface than with the generator's own poses: at
  // the old default (threshold 30, no known surface) the carve went into the objects in some runs
  // (completeness 66-97% over five runs); --consistency ncc, sensitive to the pose errors, gave
  // 70-99.7% completeness over three.
  ASSERT_EQ(testing::RunShell(Raycarve() + "carve --workspace_path " + root +
                                  "/sfm --resolution 96",
                              &log),
            0)
      << log;
  // Scored within 2 voxels (0.13 in the generator's frame: the figure to read) and within 4
  // (0.26: what is asserted). COLMAP's runs differ, and on about one in three of them the
  // photos, with poses about a degree off, agree on the true surface no better than in front of
  // it ("voxels 2.0 in front: median 17.4" against the surface voxels' 99% quantile of 34.9 in
  // one run): the threshold from the data then carves too little, and the cloud lies a voxel or
  // two outside the surface while COLMAP's own sparse points lie on it (precision 0.96 within
  // 0.13). Measured over five runs of sfm, two of them bad (batched and one voxel at a time
  // alike): within 0.13 completeness 0.23-0.999 and precision 0.26-0.98; within 0.26 the worst
  // run gave 0.69 / 0.80.
  // The threshold rule's weakness is issue 15's; this test checks the pipeline: frames, sfm,
  // carve, compare.
  std::map<std::string, double> scored;
  for (const std::string& within : {std::string("0.13"), std::string("0.26")}) {
    ASSERT_EQ(testing::RunShell(Raycarve() + "compare --reference " + root + "/scene/truth.ply " +
                                    "--input " + root + "/sfm/raycarve/cloud.ply --input_model " +
                                    root + "/sfm/sparse/0 --reference_model " + root +
                                    "/scene/sparse/0 --threshold " + within + " --output_path " +
                                    root + "/compare.json",
                                &log),
              0)
        << log;
    const std::string report = testing::ReadFileBytes(root + "/compare.json");
    std::printf("within %s: %s\n", within.c_str(), report.c_str());
    for (const std::string key : {"completeness", "precision"}) {
      const size_t at = report.find("\"" + key + "\": ");
      ASSERT_NE(at, std::string::npos) << key;
      scored[key + " " + within] = std::stod(report.substr(at + key.size() + 4));
    }
  }
  EXPECT_GT(scored["completeness 0.26"], 0.5);
  EXPECT_GT(scored["precision 0.26"], 0.6);
  fs::remove_all(root);
}

// The temple ring: real photos, the Middlebury calibration as the reference.
TEST(ColmapSfm, RegistersTheTempleRingWhereItsCalibrationPutsItAndTheProjectCarves) {
  RAYCARVE_REQUIRE_COLMAP();
  RAYCARVE_REQUIRE_DATA("middlebury/templeSparseRing");
  const std::string data = testing::DataDirectory() + "/middlebury/templeSparseRing";
  const std::string root = testing::MakeTemporaryDirectory("colmap_sfm");
  const Reconstruction given = ReadModel(data + "/colmap/given");
  const Camera& camera = given.cameras.begin()->second;
  std::string params;
  for (size_t i = 0; i < camera.params.size(); ++i) {
    params += (i == 0 ? "" : ",") + std::to_string(camera.params[i]);
  }
  std::string log;
  // Known intrinsics held fixed, and registration loosened for a narrow object ring.
  ASSERT_EQ(testing::RunShell(Raycarve() + "sfm --image_path " + data + " --workspace_path " +
                                  root + "/sfm --camera_model PINHOLE --camera_params " + params +
                                  " --abs_pose_min_num_inliers 15 --init_min_tri_angle 8"
                                  // One thread: faster on two cores under parallel test load
                                  // (39 s against 65 s). COLMAP's runs still differ.
                                  " --num_threads 1",
                              &log),
            0)
      << log;
  EXPECT_NE(log.find("next            raycarve carve --workspace_path"), std::string::npos) << log;
  EXPECT_TRUE(fs::exists(root + "/sfm/database.db"));
  ASSERT_FALSE(NumberedModels(root + "/sfm/sparse").empty());

  const WorkspacePaths paths = ResolveWorkspace(root + "/sfm", "", "");
  const Reconstruction recovered = ReadModel(paths.model_path);
  std::vector<Eigen::Vector3d> source, target;
  MatchCentres(recovered, given, &source, &target);
  // Measured: 16 of 16 registered.
  EXPECT_GE(source.size(), 14u) << log;
  const exporter::Alignment alignment = exporter::AlignPoints(source, target);
  const double ring = Spread(target);
  std::printf("%s; ring radius %.4f\n", alignment.Summary().c_str(), ring);
  // Measured: RMS 0.0019 against a ring radius of about 0.56 (0.34%).
  EXPECT_EQ(alignment.num_inliers, static_cast<int>(source.size()));
  EXPECT_LT(alignment.rms, 0.01 * ring);

  // The project as the mapper left it (sparse/0, images linked) carves without path options.
  ASSERT_EQ(testing::RunShell(Raycarve() + "carve --workspace_path " + root +
                                  "/sfm --resolution 48 --threshold 60",
                              &log),
            0)
      << log;
  EXPECT_TRUE(fs::is_regular_file(root + "/sfm/raycarve/cloud.ply"));
  fs::remove_all(root);
}

TEST(ColmapSfm, RefusesMissingColmapTooFewPhotosAndExistingProjects) {
  const std::string root = testing::MakeTemporaryDirectory("colmap_sfm_errors");
  std::string log;
  ASSERT_EQ(testing::RunShell(Raycarve() + "synth --output_path " + root +
                                  "/scene --views 3 --width 64 --height 48 --points 50",
                              &log),
            0)
      << log;
  const std::string base = Raycarve() + "sfm --image_path " + root + "/scene/images ";
  EXPECT_EQ(testing::RunShell(base + "--workspace_path " + root + "/a --colmap_path /no/colmap",
                              &log),
            1);
  EXPECT_NE(log.find("/no/colmap: no such program (install"), std::string::npos) << log;
  fs::create_directories(root + "/b");
  testing::WriteFile(root + "/b/database.db", "not empty");
  EXPECT_EQ(testing::RunShell(base + "--workspace_path " + root + "/b", &log), 1);
  EXPECT_NE(log.find("never overwrites"), std::string::npos) << log;
  EXPECT_EQ(testing::ReadFileBytes(root + "/b/database.db"), "not empty");
  fs::create_directories(root + "/one");
  fs::copy_file(root + "/scene/images/view001.png", root + "/one/view001.png");
  EXPECT_EQ(testing::RunShell(Raycarve() + "sfm --image_path " + root + "/one --workspace_path " +
                                  root + "/c",
                              &log),
            1);
  EXPECT_NE(log.find("1 photos found"), std::string::npos) << log;
  EXPECT_EQ(testing::RunShell(base + "--workspace_path " + root + "/d --camera_model PINHOLE "
                                     "--camera_params 1,2,3",
                              &log),
            1);
  EXPECT_NE(log.find("PINHOLE takes 4 parameters, got 3"), std::string::npos) << log;
  EXPECT_EQ(testing::RunShell(base + "--workspace_path " + root + "/e --camera_model DIVISION",
                              &log),
            1);
  EXPECT_NE(log.find("--camera_model"), std::string::npos) << log;
  fs::remove_all(root);
}

// A phone's photos in portrait and landscape: COLMAP refuses one camera for them, so sfm gives
// each photo its own; COLMAP's progress is shown as it runs.
TEST(ColmapSfm, PhotosOfTwoSizesRegisterWithACameraEach) {
  RAYCARVE_REQUIRE_COLMAP();
  const std::string root = testing::MakeTemporaryDirectory("colmap_sfm_two_sizes");
  std::string log;
  for (const std::string& part : {std::string("a --views 8 --width 480 --height 360"),
                                  std::string("b --views 7 --width 360 --height 480 --seed 7")}) {
    ASSERT_EQ(testing::RunShell(Raycarve() + "synth --texture detailed --backdrop room "
                                             "--output_path " + root + "/" + part,
                                &log),
              0)
        << log;
  }
  fs::create_directories(root + "/photos");
  for (const char* part : {"a", "b"}) {
    for (const auto& entry : fs::directory_iterator(root + "/" + part + "/images")) {
      fs::copy_file(entry.path(), root + "/photos/" + part + "_" + entry.path().filename().string());
    }
  }
  // One camera for all is refused before COLMAP runs, with the reason.
  EXPECT_EQ(testing::RunShell(Raycarve() + "sfm --image_path " + root + "/photos --workspace_path " +
                                  root + "/one_camera --single_camera 1",
                              &log),
            1);
  EXPECT_NE(log.find("2 different sizes"), std::string::npos) << log;
  ASSERT_EQ(testing::RunShell(Raycarve() + "sfm --image_path " + root + "/photos --workspace_path " +
                                  root + "/sfm --num_threads 1",
                              &log),
            0)
      << log;
  EXPECT_NE(log.find("photos of 2 sizes (7 of 360x480, 8 of 480x360): one camera per photo"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("colmap| Processed file [15/15]"), std::string::npos) << log;
  EXPECT_NE(log.find("colmap| Matching block [2/2, 2/2]"), std::string::npos) << log;
  const Reconstruction model = ReadModel(root + "/sfm/sparse/0");
  EXPECT_EQ(model.cameras.size(), model.images.size());
  // Measured: 15 of 15 registered.
  EXPECT_GE(model.images.size(), 13u) << log;
  fs::remove_all(root);
}

}  // namespace
}  // namespace raycarve
