#include "plugin/workspace.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "calib/model_writer.h"
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

}  // namespace
}  // namespace raycarve
