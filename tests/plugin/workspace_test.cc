#include "pipeline/workspace.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "calib/model_writer.h"
#include "pipeline/project.h"
#include "plugin/commands.h"
#include "tests/test_support.h"

namespace raycarve {
namespace {

TEST(Workspace, FindsColmapLayoutsInOrder) {
  const std::string root = testing::MakeTemporaryDirectory("workspace");
  EXPECT_THROW(ResolveWorkspace(root, "", ""), InputError);
  std::filesystem::create_directories(root + "/dense/sparse");
  testing::WriteFile(root + "/dense/sparse/cameras.bin", "");
  WorkspacePaths paths = ResolveWorkspace(root, "", "");
  EXPECT_EQ(paths.layout, "dense/sparse");
  EXPECT_EQ(paths.image_path, root + "/dense/images");
  std::filesystem::create_directories(root + "/sparse");
  testing::WriteFile(root + "/sparse/cameras.txt", "");
  EXPECT_EQ(ResolveWorkspace(root, "", "").layout, "sparse");
  std::filesystem::create_directories(root + "/sparse/0");
  testing::WriteFile(root + "/sparse/0/cameras.bin", "");
  paths = ResolveWorkspace(root, "", "");
  EXPECT_EQ(paths.layout, "sparse/0");
  EXPECT_EQ(paths.model_path, root + "/sparse/0");
  EXPECT_EQ(paths.image_path, root + "/images");
  EXPECT_EQ(ResolveWorkspace(root, "", "/photos").image_path, "/photos");
  paths = ResolveWorkspace("", "/m", "/i");
  EXPECT_EQ(paths.model_path, "/m");
  EXPECT_EQ(paths.image_path, "/i");
  EXPECT_THROW(ResolveWorkspace("", "/m", ""), InputError);
  EXPECT_THROW(ResolveWorkspace("", "", ""), InputError);
  std::filesystem::remove_all(root);
}

TEST(Workspace, SeveralMapperModelsGiveTheLargestOrTheOneAskedFor) {
  const std::string root = testing::MakeTemporaryDirectory("workspace_models");
  // As colmap mapper leaves them: sparse/0 with 3 images, sparse/1 with 6 (binary), sparse/2
  // with 4 (text).
  WriteModel(testing::RandomReconstruction(1, 3), root + "/sparse/0", ModelFormat::kBinary);
  WriteModel(testing::RandomReconstruction(2, 6), root + "/sparse/1", ModelFormat::kBinary);
  WriteModel(testing::RandomReconstruction(3, 4), root + "/sparse/2", ModelFormat::kText);
  const std::vector<ModelCandidate> models = NumberedModels(root + "/sparse");
  ASSERT_EQ(models.size(), 3u);
  EXPECT_EQ(models[0].num_images, 3);
  EXPECT_EQ(models[1].num_images, 6);
  EXPECT_EQ(models[2].num_images, 4);
  WorkspacePaths paths = ResolveWorkspace(root, "", "");
  EXPECT_EQ(paths.layout, "sparse/1");
  EXPECT_EQ(paths.model_path, root + "/sparse/1");
  EXPECT_EQ(paths.image_path, root + "/images");
  EXPECT_EQ(ResolveWorkspace(root, "", "", 2).model_path, root + "/sparse/2");
  EXPECT_EQ(ResolveWorkspace(root, "", "", 0).model_path, root + "/sparse/0");
  try {
    ResolveWorkspace(root, "", "", 7);
    FAIL() << "a model index that does not exist was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("--model_index 7: no model in sparse/7"),
              std::string::npos)
        << error.what();
  }
  std::filesystem::remove_all(root);
}

TEST(PhotoMemory, ARealSizeProjectFitsAtTheDefaultMaxImageSizeAndIsRefusedAtFullSize) {
  // 200 photos of 12 megapixels on a machine of 24 GiB.
  Reconstruction project;
  project.cameras.emplace(
      1, testing::MakeCamera(1, CameraModelId::kSimpleRadial, 4000, 3000, {3500.0, 2000.0, 1500.0, 0.01}));
  for (image_t id = 1; id <= 200; ++id) {
    Image image;
    image.image_id = id;
    image.camera_id = 1;
    image.name = "photo" + std::to_string(id) + ".jpg";
    project.images.emplace(id, image);
  }
  const double machine = 24.0 * (1 << 30);
  EXPECT_NO_THROW(CheckPhotosFitInMemory(project, kDefaultMaxImageSize, machine));
  try {
    CheckPhotosFitInMemory(project, 0, machine);
    FAIL() << "200 photos of 12 MP at full size accepted";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("200 photos of up to 4000x3000"), std::string::npos) << message;
    EXPECT_NE(message.find("--max_image_size 3000"), std::string::npos) << message;
  }
  // The suggestion fits.
  EXPECT_NO_THROW(CheckPhotosFitInMemory(project, 3000, machine));
}

TEST(SfmPassThrough, GivesEachColmapOptionToTheStepThatTakesItsSection) {
  const ColmapPassThrough passed = SplitColmapOptions(
      "SiftExtraction.max_num_features=4096,Mapper.ba_refine_focal_length=0,"
      "SiftMatching.max_ratio=0.7,ImageReader.default_focal_length_factor=1.5");
  EXPECT_EQ(passed.extractor,
            (std::vector<std::string>{"--SiftExtraction.max_num_features", "4096",
                                      "--ImageReader.default_focal_length_factor", "1.5"}));
  EXPECT_EQ(passed.matcher, (std::vector<std::string>{"--SiftMatching.max_ratio", "0.7"}));
  EXPECT_EQ(passed.mapper, (std::vector<std::string>{"--Mapper.ba_refine_focal_length", "0"}));
  EXPECT_TRUE(SplitColmapOptions("").mapper.empty());
  EXPECT_THROW(SplitColmapOptions("PatchMatchStereo.window_radius=5"), InputError);
  EXPECT_THROW(SplitColmapOptions("Mapper.min_num_matches"), InputError);
  EXPECT_THROW(SplitColmapOptions("min_num_matches=3"), InputError);
}

}  // namespace
}  // namespace raycarve
