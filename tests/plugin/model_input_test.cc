// Damaged and unusual COLMAP models given to the `raycarve` program: each is named with its record
// and field, exit status 1, never a crash or an allocation the file's counts ask for.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/plugin/project_fixture.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;
using testing::ExpectUserError;
using testing::JsonNumber;

class ModelInput : public testing::SmallRadialProject {};

TEST_F(ModelInput, TruncatedBinaryFileIsNamedWithRecordAndField) {
  const std::string model = CopyModel("truncated");
  const std::string images = model + "/images.bin";
  const std::string bytes = testing::ReadFileBytes(images);
  testing::WriteFile(images, bytes.substr(0, bytes.size() / 2));
  ExpectUserError("model_info --input_path " + model, {images, "image record", "field '"});
}

TEST_F(ModelInput, CorruptedCountAndUnknownCameraModelAreNamed) {
  std::string model = CopyModel("corrupted_count");
  std::string bytes = testing::ReadFileBytes(model + "/points3D.bin");
  const uint64_t huge = uint64_t{1} << 62;
  bytes.replace(0, 8, reinterpret_cast<const char*>(&huge), 8);
  testing::WriteFile(model + "/points3D.bin", bytes);
  ExpectUserError("model_info --input_path " + model,
                  {model + "/points3D.bin", "num_points3D", "wrong count"});

  model = CopyModel("unknown_model");
  bytes = testing::ReadFileBytes(model + "/cameras.bin");
  const int32_t eucm = 16;
  bytes.replace(8 + 4, 4, reinterpret_cast<const char*>(&eucm), 4);
  testing::WriteFile(model + "/cameras.bin", bytes);
  ExpectUserError("model_info --input_path " + model,
                  {model + "/cameras.bin", "camera 1", "model_id", "EUCM"});

  // A count of 0 followed by any byte (found by fuzzing: it crashed before any record was read).
  for (const char* file : {"cameras.bin", "images.bin", "points3D.bin"}) {
    model = CopyModel(std::string("zero_count_") + file);
    testing::WriteFile(model + "/" + file, std::string(8, '\0') + "x");
    ExpectUserError("model_info --input_path " + model,
                    {model + "/" + file, "trailing data after the 0 records"});
  }
}

TEST_F(ModelInput, SizesAFileAnnouncesAreCheckedBeforeAnythingIsAllocated) {
  // A camera of 200000 x 200000 pixels (found by fuzzing: render allocated a 120 GB image).
  const std::string model = CopyModel("huge_camera");
  std::string bytes = testing::ReadFileBytes(model + "/cameras.bin");
  const uint64_t side = 200000;
  bytes.replace(8 + 4 + 4, 8, reinterpret_cast<const char*>(&side), 8);
  bytes.replace(8 + 4 + 4 + 8, 8, reinterpret_cast<const char*>(&side), 8);
  testing::WriteFile(model + "/cameras.bin", bytes);
  ExpectUserError("model_info --input_path " + model,
                  {model, "camera 1", "200000x200000", "larger than any photo"});

  // A PNG whose header claims 60000 x 60000 pixels: OpenCV refuses it, and the photo is named.
  const std::string project = *root_ + "/huge_png";
  fs::remove_all(project);
  fs::copy(Project(), project, fs::copy_options::recursive);
  const std::string huge(
      "\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00\xea\x60\x00"
      "\x00\xea\x60\x08\x02\x00\x00\x00\x0f\xb0\xe2\x15\x00\x00\x00\x0b\x49\x44\x41\x54\x78"
      "\x9c\x63\x60\x40\x05\x00\x00\x10\x00\x01\x39\xbd\x8f\x65\x00\x00\x00\x00\x49\x45\x4e"
      "\x44\xae\x42\x60\x82",
      68);
  std::string first_photo;
  for (const auto& entry : fs::directory_iterator(project + "/images")) {
    if (first_photo.empty() || entry.path().string() < first_photo) first_photo = entry.path().string();
  }
  ASSERT_FALSE(first_photo.empty());
  testing::WriteFile(first_photo, huge);
  ExpectUserError("carve --workspace_path " + project + " --output_path " + project + "/out",
                  {first_photo, "OpenCV refuses to decode it"});
}

TEST_F(ModelInput, ModelInfoDescribesAModelWhosePointsBoundNoVolume) {
  // One image, no points: nothing to bound a volume with, but a model to list.
  const std::string model = *root_ + "/one_image";
  fs::create_directories(model);
  testing::WriteFile(model + "/cameras.txt", "1 PINHOLE 640 480 500 500 320 240\n");
  testing::WriteFile(model + "/images.txt", "1 1 0 0 0 0 0 5 1 view001.png\n\n");
  testing::WriteFile(model + "/points3D.txt", "");
  std::string output;
  ASSERT_EQ(Run("model_info --input_path " + model, &output), 0) << output;
  EXPECT_NE(output.find("view001.png"), std::string::npos) << output;
  EXPECT_NE(output.find("bounds: none ("), std::string::npos) << output;
  ASSERT_EQ(Run("model_info --format json --input_path " + model, &output), 0) << output;
  EXPECT_NE(output.find("\"error\""), std::string::npos) << output;
}

TEST_F(ModelInput, ModelInfoListsImageNamesOfAnyLength) {
  const std::string model = CopyModel("long_name", "TXT");
  std::string text = testing::ReadFileBytes(model + "/images.txt");
  const size_t at = text.find("view001.png");
  ASSERT_NE(at, std::string::npos);
  const std::string name = std::string(300, 'n') + ".png";
  text.replace(at, 11, name);
  testing::WriteFile(model + "/images.txt", text);
  std::string output;
  ASSERT_EQ(Run("model_info --input_path " + model, &output), 0) << output;
  EXPECT_NE(output.find(name + " "), std::string::npos) << output;
}

TEST_F(ModelInput, APointCloudWithANonFiniteCoordinateIsNamedNotAborted) {
  // Found by fuzzing: PCL's k-d tree aborted the process on a NaN.
  const std::string folder = *root_ + "/nan_cloud";
  fs::create_directories(folder);
  // Binary little-endian, so that the NaN and the infinity are exact.
  auto write_cloud = [](const std::string& path, std::vector<float> xyz) {
    std::string bytes =
        "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(xyz.size() / 3) +
        "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    bytes.append(reinterpret_cast<const char*>(xyz.data()), xyz.size() * sizeof(float));
    testing::WriteFile(path, bytes);
  };
  const float nan = std::nanf(""), inf = std::numeric_limits<float>::infinity();
  write_cloud(folder + "/good.ply", {0, 0, 0, 1, 0, 0, 0, 1, 0});
  write_cloud(folder + "/nan.ply", {0, 0, 0, nan, 0, 0, 0, 1, 0});
  write_cloud(folder + "/inf.ply", {0, 0, 0, 1, 0, 0, 0, inf, 0});
  ExpectUserError("compare --reference " + folder + "/good.ply --input " + folder + "/nan.ply",
                  {folder + "/nan.ply", "vertex 1", "non-finite"});
  ExpectUserError("compare --reference " + folder + "/inf.ply --input " + folder + "/good.ply",
                  {folder + "/inf.ply", "vertex 2", "non-finite"});
}

TEST_F(ModelInput, NaNPoseIsNamed) {
  const std::string model = CopyModel("nan_pose", "TXT");
  std::ifstream in(model + "/images.txt");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The first data line: "IMAGE_ID QW ..." -> replace QW by nan.
  size_t line = 0;
  while (text[line] == '#') line = text.find('\n', line) + 1;
  const size_t qw = text.find(' ', line) + 1;
  text.replace(qw, text.find(' ', qw) - qw, "nan");
  testing::WriteFile(model + "/images.txt", text);
  ExpectUserError("model_info --input_path " + model, {model, "image 1", "view001.png", "pose", "not finite"});
}

TEST_F(ModelInput, EmptyModelIsAClearErrorForEveryCommandThatNeedsContent) {
  const std::string model = *root_ + "/empty";
  fs::create_directories(model);
  for (const char* file : {"cameras.txt", "images.txt", "points3D.txt"}) {
    testing::WriteFile(model + "/" + file, "");
  }
  // model_info describes what there is, and why no volume can be bounded.
  std::string output;
  ASSERT_EQ(Run("model_info --input_path " + model, &output), 0) << output;
  EXPECT_NE(output.find("bounds: none"), std::string::npos) << output;
  EXPECT_NE(output.find("no 3D points"), std::string::npos) << output;
  EXPECT_NE(output.find("--bbox"), std::string::npos) << output;
  ExpectUserError("calibrate --input_path " + model + " --image_path " + Project() +
                      "/images --output_path " + *root_ + "/empty_out",
                  {model, "no registered images"});
  ExpectUserError("model_info --input_path " + *root_ + "/nowhere", {*root_ + "/nowhere", "does not exist"});
}

}  // namespace
}  // namespace raycarve
