#include "plugin/workspace.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "calib/input_error.h"
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

}  // namespace
}  // namespace raycarve
