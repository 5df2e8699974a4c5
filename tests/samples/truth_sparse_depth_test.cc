// samples/truth_sparse_depth on what `raycarve holdout` writes: a generated scene's exact sparse
// points lie on the truth, so the truth draws every one at its depth; a point moved behind the
// true surface along its ray is one the truth hides.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "calib/model_reader.h"

#include "tests/test_support.h"

namespace raycarve {
namespace {

using testing::JsonNumber;

// Runs the program (its path in TRUTH_SPARSE_DEPTH) with `arguments`: its exit status, and its
// last line (the JSON) in *json.
int RunTruthSparseDepth(const std::string& arguments, std::string* json) {
  const char* program = std::getenv("TRUTH_SPARSE_DEPTH");
  if (program == nullptr) return -1;
  const std::string out = testing::MakeTemporaryDirectory("truth_sparse_depth_out") + "/out.txt";
  const std::string command = std::string(program) + " " + arguments + " > " + out + " 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty()) *json = line;
  }
  return status;
}

TEST(TruthSparseDepth, ExactPointsLieOnTheTruthAndAPointPushedBehindIsHidden) {
  if (std::getenv("TRUTH_SPARSE_DEPTH") == nullptr) GTEST_SKIP() << "TRUTH_SPARSE_DEPTH not set";
  const std::string root = testing::MakeTemporaryDirectory("truth_sparse_depth");
  std::string output;
  ASSERT_EQ(testing::RunRaycarve("synth --output_path " + root + "/scene --views 8 --width 128 "
                                 "--height 96 --backdrop room --points 400",
                                 &output),
            0)
      << output;
  ASSERT_EQ(testing::RunRaycarve("holdout --workspace_path " + root + "/scene --every 4 "
                                 "--resolution 32 --output_path " + root + "/out",
                                 &output),
            0)
      << output;
  const std::string holdout = testing::ReadFileBytes(root + "/out/holdout/holdout.json");
  const std::string tolerance = std::to_string(JsonNumber(holdout, "sparse_depth_tolerance"));
  const std::string csv = root + "/out/holdout/sparse_depth.csv";
  std::string json;
  const std::string scene = root + "/scene ";
  ASSERT_EQ(RunTruthSparseDepth(scene + csv + " " + tolerance + " simple room", &json), 0) << json;
  const double points = JsonNumber(json, "points");
  EXPECT_GT(points, 20);
  // The CSV holds every point holdout counted (its last "sparse_points" is the overall one).
  const std::string overall = holdout.substr(holdout.rfind("\"sparse_points\":"));
  EXPECT_EQ(points, JsonNumber(overall, "sparse_points"));
  EXPECT_EQ(JsonNumber(json, "truth_at_depth_points"), points) << json;
  EXPECT_EQ(JsonNumber(json, "truth_hidden_points"), 0) << json;
  // The first point moved half as far again along its ray from its view's camera: behind the
  // surface it lay on, so the truth hides it.
  const Reconstruction model = ReadModel(root + "/scene/sparse/0");
  std::ifstream in(csv);
  std::string header, first, line;
  std::getline(in, header);
  std::getline(in, first);
  std::string moved_csv = header + "\n";
  {
    std::stringstream fields(first);
    std::string view, x, y, z, depth;
    std::getline(fields, view, ',');
    std::getline(fields, x, ',');
    std::getline(fields, y, ',');
    std::getline(fields, z, ',');
    std::getline(fields, depth, ',');
    std::string rest;
    std::getline(fields, rest);
    Eigen::Vector3d centre = Eigen::Vector3d::Constant(std::nan(""));
    for (const auto& [id, image] : model.images) {
      if (image.name == view) centre = image.cam_from_world.Inverse().translation;
    }
    ASSERT_TRUE(centre.allFinite()) << view;
    const Eigen::Vector3d point(std::stod(x), std::stod(y), std::stod(z));
    const Eigen::Vector3d moved = centre + 1.5 * (point - centre);
    char text[256];
    std::snprintf(text, sizeof(text), "%s,%.9g,%.9g,%.9g,%.9g,%s\n", view.c_str(), moved.x(),
                  moved.y(), moved.z(), 1.5 * std::stod(depth), rest.c_str());
    moved_csv += text;
  }
  while (std::getline(in, line)) moved_csv += line + "\n";
  const std::string moved_path = root + "/moved.csv";
  std::ofstream(moved_path) << moved_csv;
  ASSERT_EQ(RunTruthSparseDepth(scene + moved_path + " " + tolerance + " simple room", &json), 0)
      << json;
  EXPECT_EQ(JsonNumber(json, "truth_hidden_points"), 1) << json;
  EXPECT_EQ(JsonNumber(json, "truth_at_depth_points"), points - 1) << json;
}

}  // namespace
}  // namespace raycarve
