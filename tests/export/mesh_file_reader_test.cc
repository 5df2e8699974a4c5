// Reading glTF back: raycarve's own mesh.glb (textured and vertex-coloured) must draw as the mesh
// it was written from; node transforms place the vertices; damaged files are refused with the
// file named, never read past their buffers.
#include "export/mesh_file_reader.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <tiny_gltf.h>

#include "calib/input_error.h"
#include "export/mesh_formats.h"
#include "export/mesh_renderer.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

// A quad at depth 4 filling the middle of an 80x60 view at the origin (f = 100), as two
// triangles facing the camera, with a texture of 16x16 texels that differ everywhere and
// vertex colours of their own.
TriangleMesh TexturedQuad() {
  TriangleMesh mesh;
  mesh.vertices = {{-1.2f, -0.8f, 4.0f}, {1.2f, -0.8f, 4.0f}, {1.2f, 0.8f, 4.0f}, {-1.2f, 0.8f, 4.0f}};
  mesh.normals.assign(4, Eigen::Vector3f(0.0f, 0.0f, -1.0f));
  mesh.colours = {{200, 10, 10}, {10, 200, 10}, {10, 10, 200}, {120, 120, 30}};
  mesh.triangles = {{0, 2, 1}, {0, 3, 2}};
  mesh.corner_uvs = {{0.0f, 0.0f}, {1.0f, 1.0f}, {1.0f, 0.0f}, {0.0f, 0.0f}, {0.0f, 1.0f}, {1.0f, 1.0f}};
  mesh.texture = cv::Mat(16, 16, CV_8UC3);
  for (int row = 0; row < 16; ++row) {
    for (int col = 0; col < 16; ++col) {
      mesh.texture.at<cv::Vec3b>(row, col) = cv::Vec3b(static_cast<uint8_t>(16 * col),
                                                       static_cast<uint8_t>(16 * row),
                                                       (row + col) % 2 ? 230 : 20);
    }
  }
  return mesh;
}

double MeanDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  const cv::Scalar mean = cv::mean(difference);
  return (mean[0] + mean[1] + mean[2]) / 3.0;
}

// `read` (the textured quad written and read back) has the quad's corners (the writers split
// vertices by texture coordinates: positions are compared) and draws as the quad does: the same
// pixels covered, the texture within a level on average (the atlas moves it by a column, and
// bilinear samples near its edge differ).
void ExpectDrawsAsTheOriginal(const TriangleMesh& mesh, const TriangleMesh& read) {
  ASSERT_TRUE(read.textured());
  ASSERT_EQ(read.triangles.size(), 2u);
  for (size_t t = 0; t < 2; ++t) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(read.vertices[read.triangles[t][k]], mesh.vertices[mesh.triangles[t][k]]);
    }
  }
  const CalibratedView view = testing::PinholeViewAtOrigin(80, 60, 100);
  const Rendering original = RenderMesh(mesh, view);
  const Rendering again = RenderMesh(read, view);
  EXPECT_EQ(cv::countNonZero(original.silhouette != again.silhouette), 0);
  ASSERT_GT(cv::countNonZero(original.silhouette), 2000);
  EXPECT_LT(MeanDifference(original.image, again.image), 1.0);
}

TEST(ReadGltf, RaycarvesTexturedGlbDrawsAsTheMeshItWasWrittenFrom) {
  const std::string folder = testing::MakeTemporaryDirectory("gltf_textured");
  const TriangleMesh mesh = TexturedQuad();
  WriteGlb(mesh, folder + "/mesh.glb");
  ExpectDrawsAsTheOriginal(mesh, ReadModelFile(folder + "/mesh.glb"));
}

TEST(ReadObj, RaycarvesTexturedObjDrawsAsTheMeshItWasWrittenFrom) {
  const std::string folder = testing::MakeTemporaryDirectory("obj_textured");
  const TriangleMesh mesh = TexturedQuad();
  WriteTexturedObj(mesh, folder + "/mesh.obj");
  ExpectDrawsAsTheOriginal(mesh, ReadModelFile(folder + "/mesh.obj"));
  // Damaged: a face past the vertices, a texture that is not there.
  testing::WriteFile(folder + "/far.obj", "v 0 0 1\nv 1 0 1\nv 0 1 1\nf 1 2 9\n");
  try {
    ReadObj(folder + "/far.obj");
    ADD_FAILURE() << "far.obj was read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(folder + "/far.obj"), std::string::npos) << error.what();
  }
  std::filesystem::remove(folder + "/mesh_texture.png");
  try {
    ReadObj(folder + "/mesh.obj");
    ADD_FAILURE() << "mesh.obj was read without its texture";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("mesh_texture.png"), std::string::npos) << error.what();
  }
}

// The textured quad without its texture (vertex colours only), written as `path` (GLB).
TriangleMesh WritePlainQuadGlb(const std::string& path) {
  TriangleMesh mesh = TexturedQuad();
  mesh.corner_uvs.clear();
  mesh.texture = cv::Mat();
  WriteGlb(mesh, path);
  return mesh;
}

TEST(ReadGltf, VertexColoursComeBackAsTheirSrgbBytes) {
  const std::string folder = testing::MakeTemporaryDirectory("gltf_colours");
  const TriangleMesh mesh = WritePlainQuadGlb(folder + "/plain.glb");
  const TriangleMesh read = ReadGltf(folder + "/plain.glb");
  EXPECT_FALSE(read.textured());
  ASSERT_EQ(read.colours.size(), mesh.colours.size());
  for (size_t v = 0; v < mesh.colours.size(); ++v) {
    EXPECT_EQ(read.vertices[v], mesh.vertices[v]);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(read.colours[v][c], mesh.colours[v][c], 1) << v;
  }
}

TEST(ReadGltf, NodeTransformsPlaceTheVertices) {
  // raycarve's GLB turned into a .gltf whose node is scaled by 2, turned 90 degrees about z and
  // moved by (1, 2, 3): each vertex v must come back as R * 2v + t.
  const std::string folder = testing::MakeTemporaryDirectory("gltf_transform");
  const TriangleMesh mesh = WritePlainQuadGlb(folder + "/plain.glb");
  tinygltf::TinyGLTF io;
  tinygltf::Model model;
  std::string error, warning;
  ASSERT_TRUE(io.LoadBinaryFromFile(&model, &error, &warning, folder + "/plain.glb")) << error;
  model.nodes[0].scale = {2.0, 2.0, 2.0};
  model.nodes[0].rotation = {0.0, 0.0, std::sqrt(0.5), std::sqrt(0.5)};  // x, y, z, w
  model.nodes[0].translation = {1.0, 2.0, 3.0};
  ASSERT_TRUE(io.WriteGltfSceneToFile(&model, folder + "/moved.gltf", false, true, true, false));
  const TriangleMesh read = ReadGltf(folder + "/moved.gltf");
  ASSERT_EQ(read.vertices.size(), mesh.vertices.size());
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3f& p = mesh.vertices[v];
    const Eigen::Vector3f expected(1.0f - 2.0f * p.y(), 2.0f + 2.0f * p.x(), 3.0f + 2.0f * p.z());
    EXPECT_LT((read.vertices[v] - expected).norm(), 1e-5f) << v;
    // Normals turn with the node (and stay unit).
    EXPECT_LT((read.normals[v] - Eigen::Vector3f(0.0f, 0.0f, -1.0f)).norm(), 1e-5f);
  }
}

TEST(ReadGltf, DamagedFilesAreRefusedNamingTheFile) {
  const std::string folder = testing::MakeTemporaryDirectory("gltf_damaged");
  TriangleMesh mesh = TexturedQuad();
  WriteGlb(mesh, folder + "/mesh.glb");
  const std::string bytes = testing::ReadFileBytes(folder + "/mesh.glb");
  const auto expect_refused = [&](const std::string& path, const std::string& part) {
    try {
      ReadGltf(path);
      ADD_FAILURE() << path << " was read";
    } catch (const InputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      EXPECT_NE(message.find(part), std::string::npos) << message;
    }
  };
  testing::WriteFile(folder + "/cut.glb", bytes.substr(0, bytes.size() / 2));
  expect_refused(folder + "/cut.glb", "not a readable glTF");
  testing::WriteFile(folder + "/text.glb", "solid nothing\n");
  expect_refused(folder + "/text.glb", "not a readable glTF");
  expect_refused(folder + "/missing.glb", "not a readable glTF");
  // An accessor whose count reaches past its buffer view, and an index past the vertices.
  tinygltf::TinyGLTF io;
  tinygltf::Model model;
  std::string error, warning;
  ASSERT_TRUE(io.LoadBinaryFromFile(&model, &error, &warning, folder + "/mesh.glb")) << error;
  tinygltf::Model long_count = model;
  long_count.accessors[long_count.meshes[0].primitives[0].attributes.at("POSITION")].count = 1000000;
  ASSERT_TRUE(io.WriteGltfSceneToFile(&long_count, folder + "/long.glb", false, true, false, true));
  expect_refused(folder + "/long.glb", "reach past its buffer view");
  tinygltf::Model far_index = model;
  const tinygltf::Accessor& indices = far_index.accessors[far_index.meshes[0].primitives[0].indices];
  const tinygltf::BufferView& view = far_index.bufferViews[indices.bufferView];
  uint32_t far = 1000;
  std::memcpy(far_index.buffers[view.buffer].data.data() + view.byteOffset + indices.byteOffset, &far, 4);
  ASSERT_TRUE(io.WriteGltfSceneToFile(&far_index, folder + "/far.glb", false, true, false, true));
  expect_refused(folder + "/far.glb", "past the primitive's");
  // A texture whose PNG header announces 100,000 x 100,000 pixels: refused before decoding.
  std::string huge = bytes;
  const size_t png = huge.find("\x89PNG\r\n\x1a\n");
  ASSERT_NE(png, std::string::npos);
  for (const size_t at : {png + 16, png + 20}) {
    const char size[4] = {0, 0x01, static_cast<char>(0x86), static_cast<char>(0xA0)};  // 100000
    huge.replace(at, 4, size, 4);
  }
  testing::WriteFile(folder + "/huge.glb", huge);
  expect_refused(folder + "/huge.glb", "announces 100000 x 100000 pixels");
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
