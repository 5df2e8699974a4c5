#include "calib/atomic_file.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "tests/test_support.h"

namespace raycarve {
namespace {

TEST(AtomicFile, TemporaryNameSitsBesideTheFileAndKeepsItsExtension) {
  EXPECT_EQ(TemporaryPathFor("out/carve/mesh.ply"), "out/carve/.tmp.mesh.ply");
  EXPECT_EQ(TemporaryPathFor("report.json"), ".tmp.report.json");
}

TEST(AtomicFile, RenameReplacesTheFileOrNamesItOnFailure) {
  const std::string folder = testing::MakeTemporaryDirectory("atomic");
  const std::string path = folder + "/a.txt";
  testing::WriteFile(path, "old");
  testing::WriteFile(TemporaryPathFor(path), "new");
  RenameIntoPlace(TemporaryPathFor(path), path);
  EXPECT_EQ(testing::ReadFileBytes(path), "new");
  EXPECT_FALSE(std::filesystem::exists(TemporaryPathFor(path)));
  try {
    RenameIntoPlace(folder + "/missing", folder + "/b.txt");
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(folder + "/b.txt"), std::string::npos);
  }
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace raycarve
