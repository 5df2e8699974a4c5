// raycarve's own PLY reader against files whose content is known: the three encodings, property
// orders and types that other tools write, faces, and bodies that lie.
#include "export/ply_reader.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "export/point_cloud_io.h"
#include "export/surface_mesh.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

// Little- or big-endian bytes of a value.
template <typename T>
std::string Bytes(T value, bool big_endian) {
  std::string bytes(sizeof(T), '\0');
  std::memcpy(bytes.data(), &value, sizeof(T));
  if (big_endian) std::reverse(bytes.begin(), bytes.end());
  return bytes;
}

// Two vertices (uchar red before the float coordinates, as some writers order them; a quality
// property raycarve does not take) and a quad, in the given format.
std::string QuadFile(const std::string& format) {
  std::string header = "ply\nformat " + format +
                       " 1.0\ncomment made by a test\nelement vertex 4\nproperty uchar red\n"
                       "property float x\nproperty float y\nproperty double z\nproperty uchar "
                       "green\nproperty uchar blue\nproperty float quality\nproperty float nx\n"
                       "property float ny\nproperty float nz\nelement face 1\nproperty list "
                       "uchar int vertex_indices\nelement edge 1\nproperty int vertex1\nproperty "
                       "int vertex2\nend_header\n";
  const float xyz[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0.5f}};
  if (format == "ascii") {
    for (int v = 0; v < 4; ++v) {
      header += std::to_string(10 * v) + " " + std::to_string(xyz[v][0]) + " " +
                std::to_string(xyz[v][1]) + " " + std::to_string(xyz[v][2]) + " 20 30 0.5 0 0 1\n";
    }
    return header + "4 0 1 2 3\n0 2\n";
  }
  const bool big = format == "binary_big_endian";
  for (int v = 0; v < 4; ++v) {
    header += static_cast<char>(10 * v);
    header += Bytes(xyz[v][0], big) + Bytes(xyz[v][1], big) +
              Bytes(static_cast<double>(xyz[v][2]), big);
    header += static_cast<char>(20);
    header += static_cast<char>(30);
    header += Bytes(0.5f, big) + Bytes(0.0f, big) + Bytes(0.0f, big) + Bytes(1.0f, big);
  }
  header += static_cast<char>(4);
  for (int index : {0, 1, 2, 3}) header += Bytes(index, big);
  header += Bytes(0, big) + Bytes(2, big);
  return header;
}

std::string WriteTemporary(const std::string& name, const std::string& bytes) {
  const std::string path = testing::MakeTemporaryDirectory("ply_reader") + "/" + name;
  testing::WriteFile(path, bytes);
  return path;
}

TEST(PlyReader, ReadsTheSameQuadInEveryEncoding) {
  for (const std::string format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(format);
    const PlyData data = ReadPly(WriteTemporary("quad.ply", QuadFile(format)));
    ASSERT_EQ(data.xyz.size(), 4u);
    EXPECT_EQ(data.xyz[2], Eigen::Vector3f(1, 1, 0));
    EXPECT_EQ(data.xyz[3], Eigen::Vector3f(0, 1, 0.5f));
    ASSERT_EQ(data.rgb.size(), 4u);
    EXPECT_EQ(data.rgb[3], (Eigen::Matrix<uint8_t, 3, 1>(30, 20, 30)));
    ASSERT_EQ(data.normals.size(), 4u);
    EXPECT_EQ(data.normals[1], Eigen::Vector3f(0, 0, 1));
    // The quad as a fan of two triangles; the edge element is read past.
    ASSERT_EQ(data.triangles.size(), 2u);
    EXPECT_EQ(data.triangles[0], Eigen::Vector3i(0, 1, 2));
    EXPECT_EQ(data.triangles[1], Eigen::Vector3i(0, 2, 3));
  }
}

TEST(PlyReader, ReadsWhatRaycarveWritesAndColoursGivenAsFloats) {
  std::vector<ColouredPoint> points(3);
  for (int i = 0; i < 3; ++i) {
    points[i].xyz = Eigen::Vector3f(i, 2.0f * i, -0.25f * i);
    points[i].normal = Eigen::Vector3f(0, 1, 0);
    points[i].rgb << 5 * i, 100, 255;
  }
  const std::string folder = testing::MakeTemporaryDirectory("ply_reader_own");
  WritePointCloudPly(points, folder + "/cloud.ply");
  const std::vector<ColouredPoint> read = ReadPointCloudPly(folder + "/cloud.ply");
  ASSERT_EQ(read.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(read[i].xyz, points[i].xyz);
    EXPECT_EQ(read[i].normal, points[i].normal);
    EXPECT_EQ(read[i].rgb, points[i].rgb);
  }
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.colours.assign(3, Eigen::Matrix<uint8_t, 3, 1>(1, 2, 3));
  mesh.triangles = {{0, 1, 2}};
  ComputeVertexNormals(&mesh);
  WriteMeshPly(mesh, folder + "/mesh.ply");
  const TriangleMesh back = ReadMeshOrCloudPly(folder + "/mesh.ply");
  EXPECT_EQ(back.vertices, mesh.vertices);
  EXPECT_EQ(back.colours, mesh.colours);
  EXPECT_EQ(back.triangles, mesh.triangles);

  // Colours as floats in 0-1 (some tools write them so): scaled to bytes.
  const PlyData floats = ReadPly(WriteTemporary(
      "floats.ply",
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty "
      "float z\nproperty float red\nproperty float green\nproperty float blue\nend_header\n"
      "1 2 3 1.0 0.5 0\n"));
  ASSERT_EQ(floats.rgb.size(), 1u);
  EXPECT_EQ(floats.rgb[0], (Eigen::Matrix<uint8_t, 3, 1>(255, 128, 0)));
  EXPECT_TRUE(floats.normals.empty());
  EXPECT_TRUE(floats.triangles.empty());
}

// Expects ReadPly to refuse `bytes` with a message naming the file and holding `part`.
void ExpectRefused(const std::string& bytes, const std::string& part) {
  const std::string path = WriteTemporary("bad.ply", bytes);
  try {
    ReadPly(path);
    ADD_FAILURE() << "accepted: " << bytes.substr(0, 200);
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(part), std::string::npos) << message << " (expected: " << part << ")";
  }
}

TEST(PlyReader, RefusesBodiesThatLieWithTheFileAndTheValueNamed) {
  const std::string xyz_header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float "
      "y\nproperty float z\nend_header\n";
  // The header's count fits the bytes, but the body ends inside the second vertex (the header
  // check counts bytes per record; here a list-free record is cut short).
  const std::string three_floats = Bytes(1.0f, false) + Bytes(2.0f, false) + Bytes(3.0f, false);
  ExpectRefused("ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
                "property float y\nproperty float z\nelement face 1\nproperty list uchar int "
                "vertex_indices\nend_header\n" +
                    three_floats + std::string(1, '\3') + Bytes(0, false),
                "face 0's vertex_indices");
  // A non-finite coordinate, by vertex.
  ExpectRefused(xyz_header + three_floats + Bytes(1.0f, false) +
                    Bytes(std::numeric_limits<float>::quiet_NaN(), false) + Bytes(0.0f, false),
                "vertex 1 has a non-finite coordinate");
  // A double too large for a float coordinate.
  ExpectRefused("ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
                "property double z\nend_header\n1e308 0 0\n",
                "vertex 0 has a non-finite coordinate");
  // A float that is finite but so large that differences overflow (found by fuzzing: FLANN's
  // k-d tree recursed until the stack ran out on such a mesh).
  ExpectRefused(xyz_header + three_floats + Bytes(1.0f, false) + Bytes(3e38f, false) +
                    Bytes(0.0f, false),
                "vertex 1 has a coordinate beyond 1e30");
  // A face naming a vertex the file does not have.
  ExpectRefused("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
                "face 0 refers to vertex 7 of 3");
  // A list count larger than what remains.
  ExpectRefused("ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
                "property float y\nproperty float z\nelement face 1\nproperty list uint int "
                "vertex_indices\nend_header\n" +
                    three_floats + Bytes(uint32_t{4000000000u}, false),
                "announces");
  // ASCII tokens that are not numbers, or not integers where the type is one.
  ExpectRefused("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n1 two 3\n",
                "'two' of vertex 0's y is not a number");
  ExpectRefused("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                "property float z\nproperty uchar red\nend_header\n1 2 3 4.5\n",
                "vertex 0's red is not an integer");
  // An ASCII body that stops early.
  ExpectRefused("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n1.5 2.5 3.5\n4 5\n",
                "ends inside vertex 1's z");
  // Two vertex elements (found by fuzzing: the second one's vertices had no colours).
  ExpectRefused("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                "property float z\nproperty uchar red\nelement vertex 1\nproperty float x\n"
                "property float y\nproperty float z\nend_header\n1 2 3 4\n5 6 7\n",
                "element 'vertex' appears twice");
  // A list whose count is a float.
  ExpectRefused("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                "property float z\nelement face 0\nproperty list float int vertex_indices\n"
                "end_header\n1 2 3\n",
                "count of type 'float'");
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
