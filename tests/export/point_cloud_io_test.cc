#include "export/point_cloud_io.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

std::vector<ColouredPoint> SomePoints() {
  std::vector<ColouredPoint> points(3);
  points[0].xyz = Eigen::Vector3f(1.5f, -2.0f, 0.25f);
  points[0].normal = Eigen::Vector3f(0, 0, 1);
  points[0].rgb << 255, 10, 0;
  points[1].xyz = Eigen::Vector3f(0, 1e-3f, 7);
  points[1].normal = Eigen::Vector3f(0.6f, 0.8f, 0);
  points[1].rgb << 1, 2, 3;
  points[2].xyz = Eigen::Vector3f(-4, 5, -6);
  return points;
}

TEST(PointCloudIo, WritesBinaryPlyWithFusedPlyPropertiesAndReadsItBack) {
  const std::string folder = testing::MakeTemporaryDirectory("ply");
  const std::string path = folder + "/cloud.ply";
  WritePointCloudPly(SomePoints(), path);
  EXPECT_FALSE(std::filesystem::exists(folder + "/.tmp.cloud.ply"));

  const std::string bytes = testing::ReadFileBytes(path);
  const std::string header = bytes.substr(0, bytes.find("end_header"));
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos) << header;
  EXPECT_NE(header.find("element vertex 3"), std::string::npos) << header;
  // Exactly COLMAP's fused.ply vertex, in its order.
  const std::string vertex = header.substr(header.find("element vertex"));
  EXPECT_EQ(vertex.substr(vertex.find('\n') + 1, vertex.find("element face") - vertex.find('\n') - 1),
            "property float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\n")
      << header;
  const std::vector<ColouredPoint> read = ReadPointCloudPly(path);
  const std::vector<ColouredPoint> original = SomePoints();
  ASSERT_EQ(read.size(), original.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].xyz, original[i].xyz);
    EXPECT_EQ(read[i].normal, original[i].normal);
    EXPECT_EQ(read[i].rgb, original[i].rgb);
  }
  std::filesystem::remove_all(folder);
}

TEST(PointCloudIo, AnEmptyCloudIsWrittenAsAValidEmptyPly) {
  const std::string path = testing::MakeTemporaryDirectory("empty_ply") + "/empty.ply";
  WritePointCloudPly({}, path);
  const std::string bytes = testing::ReadFileBytes(path);
  EXPECT_EQ(bytes.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(bytes.find("element vertex 0\n"), std::string::npos);
  EXPECT_NE(bytes.find("property uchar blue\nend_header\n"), std::string::npos);
  EXPECT_TRUE(ReadPointCloudPly(path).empty());
}

TEST(PointCloudIo, MissingOrBrokenFilesAreNamed) {
  const std::string folder = testing::MakeTemporaryDirectory("ply_bad");
  EXPECT_THROW(ReadPointCloudPly(folder + "/none.ply"), InputError);
  testing::WriteFile(folder + "/broken.ply", "ply\nformat ascii 1.0\nelement vertex 5\nend_header\n1 2\n");
  try {
    ReadPointCloudPly(folder + "/broken.ply");
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("broken.ply"), std::string::npos);
  }
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
