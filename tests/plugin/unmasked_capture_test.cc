// A capture without masks, as most COLMAP users have: the generated scene on a textured floor that
// runs on beyond the volume, in a textured room, photographed from a ring, its exact masks kept
// out of the project. Carved and held out at the defaults and with the colour test off.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tests/test_support.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;
using testing::JsonNumber;
using testing::RunRaycarve;

TEST(UnmaskedCapture, TheSubjectIsCarvedInItsOwnBoxWithoutTheBoxsWalls) {
  const std::string root = testing::MakeTemporaryDirectory("unmasked_capture");
  const std::string scene = root + "/scene";
  std::string output;
  ASSERT_EQ(RunRaycarve("synth --output_path " + scene +
                            " --backdrop room --views 12 --width 320 --height 240",
                        &output),
            0)
      << output;
  fs::rename(scene + "/masks", root + "/truth_masks");
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + scene, &output), 0) << output;
  // The cameras stand around the subject: the box goes round their focus, and the summary says
  // what would help (masks).
  EXPECT_NE(output.find("cameras around a point (object-centred)"), std::string::npos) << output;
  EXPECT_NE(output.find("the volume: the box around their focus"), std::string::npos) << output;
  EXPECT_NE(output.find("give the subject's masks (--mask_path"), std::string::npos) << output;
  const std::string report = testing::ReadFileBytes(scene + "/raycarve/report.json");
  EXPECT_NE(report.find("\"kind\": \"object\""), std::string::npos);
  EXPECT_NE(report.find("\"around_focus\": true"), std::string::npos);
  EXPECT_GT(JsonNumber(report, "box_wall_triangles_removed"), 0);
  // The cloud against the truth at two voxels (measured: F-score 91.2%, precision 84.4%).
  const double voxel = JsonNumber(report, "voxel_size");
  ASSERT_EQ(RunRaycarve("compare --reference_path " + scene + "/truth.ply --input_path " + scene +
                            "/raycarve/cloud.ply --threshold " + std::to_string(2.0 * voxel) +
                            " --output_path " + root + "/compare.json",
                        &output),
            0)
      << output;
  EXPECT_GT(JsonNumber(testing::ReadFileBytes(root + "/compare.json"), "f_score"), 0.88);
  // Held out, scored inside the truth's silhouettes and against the photos' sparse points: the
  // colour test against no colour test (measured: 23.53 against 14.46 dB; 93.6% of the sparse
  // points at their depth and 3.1% hidden, against 31.8% and 67.7%).
  const auto held_out = [&](const std::string& name, const std::string& flags) {
    EXPECT_EQ(RunRaycarve("holdout --workspace_path " + scene + " --every 4 --output_path " + root +
                              "/" + name + " --score_mask_path " + root + "/truth_masks" + flags,
                          &output),
              0)
        << output;
    return testing::ReadFileBytes(root + "/" + name + "/holdout/holdout.json");
  };
  const std::string defaults = held_out("defaults", "");
  const std::string colour_off = held_out("colour_off", " --threshold 1000000");
  EXPECT_GT(JsonNumber(defaults, "mean_psnr_db"), JsonNumber(colour_off, "mean_psnr_db") + 5.0);
  EXPECT_GT(JsonNumber(defaults, "sparse_points"), 1000);
  EXPECT_GT(JsonNumber(defaults, "sparse_at_depth_share"), 0.9);
  EXPECT_LT(JsonNumber(defaults, "sparse_hidden_share"), 0.05);
  EXPECT_LT(JsonNumber(colour_off, "sparse_at_depth_share"), 0.5);
}

// Forward-facing photos (a grid of positions in front of the scene, as before a facade): a scene,
// whose box keeps every sparse point the filters keep.
TEST(UnmaskedCapture, ForwardFacingPhotosAreASceneAndKeepTheSparsePointsBox) {
  const std::string root = testing::MakeTemporaryDirectory("unmasked_forward");
  std::string output;
  ASSERT_EQ(RunRaycarve("synth --output_path " + root + " --layout forward --backdrop room "
                        "--views 8 --width 128 --height 96 --points 600",
                        &output),
            0)
      << output;
  fs::remove_all(root + "/masks");
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + root + " --resolution 32", &output), 0) << output;
  EXPECT_NE(output.find("cameras facing one way (a scene)"), std::string::npos) << output;
  const std::string report = testing::ReadFileBytes(root + "/raycarve/report.json");
  EXPECT_NE(report.find("\"kind\": \"scene\""), std::string::npos);
  EXPECT_NE(report.find("\"around_focus\": false"), std::string::npos);
}

}  // namespace
}  // namespace raycarve
