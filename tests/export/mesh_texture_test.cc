// The texture atlas against answers known by construction: a patterned photo of a flat
// rectangle that the textured mesh must draw back, a triangle no photo sees whole that must keep
// its vertices' colours, and the OBJ and glTF files read back.
#include "export/mesh_texture.h"
#include "export/mesh_formats.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <tiny_gltf.h>

#include "export/mesh_renderer.h"
#include "export/preview.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

// An 80x60 pinhole view at the origin looking down +z (x right, y down), f = 100, whose photo is
// a pattern that differs at every pixel: a 4-pixel check over two gradients.
CalibratedView PatternView() {
  CalibratedView view = testing::PinholeViewAtOrigin(80, 60, 100);
  view.image = cv::Mat(view.height, view.width, CV_8UC3);
  for (int row = 0; row < view.height; ++row) {
    for (int col = 0; col < view.width; ++col) {
      const bool check = ((col / 4) + (row / 4)) % 2 == 0;
      view.image.at<cv::Vec3b>(row, col) =
          cv::Vec3b(static_cast<uint8_t>(3 * col), static_cast<uint8_t>(4 * row), check ? 220 : 30);
    }
  }
  return view;
}

// The rectangle over pixels 10..70 across and 10..50 down at depth 4, as a grid of 6 x 4 quads
// of two triangles each, wound to face the camera; grey vertex colours.
TriangleMesh Rectangle(const CalibratedView& view) {
  TriangleMesh mesh;
  for (int j = 0; j <= 4; ++j) {
    for (int i = 0; i <= 6; ++i) {
      const double x = 10 + 10 * i, y = 10 + 10 * j, z = 4.0;
      mesh.vertices.emplace_back(static_cast<float>((x - view.K(0, 2)) / view.K(0, 0) * z),
                                 static_cast<float>((y - view.K(1, 2)) / view.K(1, 1) * z),
                                 static_cast<float>(z));
    }
  }
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 6; ++i) {
      const int a = j * 7 + i, b = a + 1, c = a + 8, d = a + 7;
      mesh.triangles.emplace_back(a, c, b);  // counter-clockwise on the screen: facing the camera
      mesh.triangles.emplace_back(a, d, c);
    }
  }
  mesh.colours.assign(mesh.vertices.size(), Eigen::Matrix<uint8_t, 3, 1>(128, 128, 128));
  ComputeVertexNormals(&mesh);
  return mesh;
}

TEST(TextureMeshFromPhotos, TheTexturedMeshDrawsThePhotoBack) {
  const std::vector<CalibratedView> views = {PatternView()};
  TriangleMesh mesh = Rectangle(views[0]);
  const std::vector<std::vector<uint32_t>> seen_by(mesh.vertices.size(), {0});
  const MeshTextureSummary summary = TextureMeshFromPhotos(views, seen_by, {}, &mesh);
  ASSERT_TRUE(mesh.textured());
  EXPECT_EQ(summary.triangles, 48);
  EXPECT_EQ(summary.textured, 48);
  EXPECT_EQ(summary.charts, 1);  // one photo, one connected piece
  EXPECT_DOUBLE_EQ(summary.scale, 1.0);
  for (const Eigen::Vector2f& uv : mesh.corner_uvs) {
    EXPECT_TRUE(uv.x() >= 0.0f && uv.x() <= 1.0f && uv.y() >= 0.0f && uv.y() <= 1.0f);
  }
  const Rendering rendering = RenderMesh(mesh, views[0]);
  double error = 0.0;
  int pixels = 0;
  for (int row = 10; row < 50; ++row) {
    for (int col = 10; col < 70; ++col) {
      ASSERT_NE(rendering.silhouette.at<uint8_t>(row, col), 0);
      const cv::Vec3b drawn = rendering.image.at<cv::Vec3b>(row, col);
      const cv::Vec3b photo = views[0].image.at<cv::Vec3b>(row, col);
      for (int k = 0; k < 3; ++k) error += std::abs(drawn[k] - photo[k]);
      ++pixels;
    }
  }
  // Drawn back at the photo's own pixels: the same colours to within rounding.
  EXPECT_LT(error / (3.0 * pixels), 1.0);
  // Without the texture the grey vertex colours are all that is drawn.
  TriangleMesh plain = mesh;
  plain.texture.release();
  EXPECT_EQ(RenderMesh(plain, views[0]).image.at<cv::Vec3b>(30, 40), cv::Vec3b(128, 128, 128));
}

TEST(TextureMeshFromPhotos, TheAtlasIsTheSameOnAnyNumberOfThreads) {
  // Two photos, each seeing one half of the rectangle: several charts.
  std::vector<CalibratedView> views = {PatternView(), PatternView()};
  cv::flip(views[1].image, views[1].image, 1);
  TriangleMesh mesh = Rectangle(views[0]);
  std::vector<std::vector<uint32_t>> seen_by(mesh.vertices.size());
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const int column = static_cast<int>(v % 7);
    if (column <= 3) seen_by[v].push_back(0);
    if (column >= 3) seen_by[v].push_back(1);
  }
  TriangleMesh one = mesh, two = mesh;
  MeshTextureOptions options;
  options.num_threads = 1;
  const MeshTextureSummary first = TextureMeshFromPhotos(views, seen_by, options, &one);
  options.num_threads = 2;
  TextureMeshFromPhotos(views, seen_by, options, &two);
  EXPECT_GE(first.charts, 2);
  EXPECT_EQ(first.textured, 48);
  ASSERT_EQ(one.texture.size(), two.texture.size());
  EXPECT_EQ(cv::norm(one.texture, two.texture, cv::NORM_INF), 0.0);
  EXPECT_EQ(one.corner_uvs, two.corner_uvs);
}

TEST(TextureMeshFromPhotos, ATriangleNoPhotoSeesWholeKeepsItsVertexColours) {
  const std::vector<CalibratedView> views = {PatternView()};
  TriangleMesh mesh = Rectangle(views[0]);
  std::vector<std::vector<uint32_t>> seen_by(mesh.vertices.size(), {0});
  // The first quad's far corner unseen: the six triangles around it have no photo.
  seen_by[8].clear();
  mesh.colours[0] = {200, 0, 0};
  mesh.colours[1] = {0, 200, 0};
  mesh.colours[8] = {0, 0, 200};
  const MeshTextureSummary summary = TextureMeshFromPhotos(views, seen_by, {}, &mesh);
  EXPECT_EQ(summary.textured, 48 - 6);
  const Rendering rendering = RenderMesh(mesh, views[0]);
  // Triangle (0, 8, 1): corners at pixels (10, 10), (20, 20), (20, 10); near its centroid the
  // three colours blend about equally, as the vertex colours would draw them.
  const cv::Vec3b centre = rendering.image.at<cv::Vec3b>(13, 16);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(centre[k], 200.0 / 3.0, 25.0) << k;
}

TEST(TextureMeshFromPhotos, AnAtlasOverTheLimitIsNotMadeAndTheVertexColoursStay) {
  const std::vector<CalibratedView> views = {PatternView()};
  TriangleMesh mesh = Rectangle(views[0]);
  // The rectangle's 48 triangles 8 times over (the copies share its vertices), none seen whole by
  // a photo: 384 cells of 4 x 4 texels need more than a 64 x 64 atlas, and such cells do not
  // shrink.
  const std::vector<Eigen::Vector3i> once = mesh.triangles;
  for (int copy = 1; copy < 8; ++copy) mesh.triangles.insert(mesh.triangles.end(), once.begin(), once.end());
  const std::vector<std::vector<uint32_t>> unseen(mesh.vertices.size());
  MeshTextureOptions options;
  options.max_atlas_side = 64;
  MeshTextureSummary summary = TextureMeshFromPhotos(views, unseen, options, &mesh);
  EXPECT_TRUE(summary.too_large);
  EXPECT_EQ(summary.atlas_width, 0);
  EXPECT_GT(summary.needed_width * static_cast<int64_t>(summary.needed_height), 64 * 64);
  EXPECT_TRUE(mesh.texture.empty());
  EXPECT_TRUE(mesh.corner_uvs.empty());
  EXPECT_NE(summary.Summary().find("keeps its vertex colours"), std::string::npos) << summary.Summary();
  // The same mesh with a limit it fits: an atlas.
  options.max_atlas_side = 256;
  summary = TextureMeshFromPhotos(views, unseen, options, &mesh);
  EXPECT_FALSE(summary.too_large);
  EXPECT_GT(summary.atlas_width, 0);
  EXPECT_FALSE(mesh.texture.empty());
}

// Two triangles sharing an edge, textured from a 64 x 32 atlas whose right half is `step` levels
// brighter: in one chart (both in the left half) the edge is inside it and nothing steps; in two
// (the second triangle's copy in the right half) the edge is a seam that steps by `step`.
TEST(MeasureTextureSeams, ASeamStepsByTheChartsDifferenceAndAChartsInsideDoesNot) {
  constexpr int kStep = 30;
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.texture = cv::Mat(32, 64, CV_8UC3, cv::Scalar::all(100));
  mesh.texture(cv::Rect(32, 0, 32, 32)).setTo(cv::Scalar::all(100 + kStep));
  const Eigen::Vector2f texels[4] = {{4, 4}, {28, 4}, {28, 28}, {4, 28}};
  const auto set_uvs = [&](float shift) {
    mesh.corner_uvs.clear();
    for (int t = 0; t < 2; ++t) {
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector2f at = texels[mesh.triangles[t][k]] + Eigen::Vector2f(t == 1 ? shift : 0.0f, 0.0f);
        mesh.corner_uvs.push_back(at.cwiseQuotient(Eigen::Vector2f(64, 32)));
      }
    }
  };
  set_uvs(0.0f);
  TextureSeams seams = MeasureTextureSeams(mesh);
  EXPECT_EQ(seams.inner_edges, 1);
  EXPECT_EQ(seams.seam_edges, 0);
  EXPECT_NEAR(seams.inner_step, 0.0, 1e-9);
  set_uvs(32.0f);
  seams = MeasureTextureSeams(mesh);
  EXPECT_EQ(seams.inner_edges, 0);
  EXPECT_EQ(seams.seam_edges, 1);
  EXPECT_NEAR(seams.seam_step, kStep, 1e-3);
  // No texture, no figures.
  mesh.texture.release();
  seams = MeasureTextureSeams(mesh);
  EXPECT_EQ(seams.seam_edges + seams.inner_edges, 0);
}

TEST(WriteTexturedObj, TheFilesReadBack) {
  const std::vector<CalibratedView> views = {PatternView()};
  TriangleMesh mesh = Rectangle(views[0]);
  TextureMeshFromPhotos(views, std::vector<std::vector<uint32_t>>(mesh.vertices.size(), {0}), {},
                        &mesh);
  const std::string folder = testing::MakeTemporaryDirectory("mesh_texture");
  WriteTexturedObj(mesh, folder + "/mesh.obj");
  std::ifstream obj(folder + "/mesh.obj");
  int v = 0, vt = 0, vn = 0, f = 0;
  bool mtllib = false, usemtl = false;
  for (std::string line; std::getline(obj, line);) {
    v += line.rfind("v ", 0) == 0;
    vt += line.rfind("vt ", 0) == 0;
    vn += line.rfind("vn ", 0) == 0;
    f += line.rfind("f ", 0) == 0;
    mtllib |= line == "mtllib mesh.mtl";
    usemtl |= line == "usemtl raycarve";
  }
  EXPECT_EQ(v, 35);
  EXPECT_EQ(vn, 35);
  EXPECT_EQ(vt, 35);  // one chart: each vertex one texture coordinate
  EXPECT_EQ(f, 48);
  EXPECT_TRUE(mtllib && usemtl);
  EXPECT_NE(testing::ReadFileBytes(folder + "/mesh.mtl").find("map_Kd mesh_texture.png"),
            std::string::npos);
  const cv::Mat png = cv::imread(folder + "/mesh_texture.png", cv::IMREAD_COLOR);
  EXPECT_EQ(png.size(), mesh.texture.size());

  WriteGlb(mesh, folder + "/mesh.glb");
  EXPECT_EQ(testing::ReadFileBytes(folder + "/mesh.glb").substr(0, 4), "glTF");
  tinygltf::TinyGLTF loader;
  // The embedded PNG is checked above; the loader need not decode it.
  loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int,
                           const unsigned char*, int, void*) { return true; },
                        nullptr);
  tinygltf::Model model;
  std::string error, warning;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &error, &warning, folder + "/mesh.glb")) << error;
  ASSERT_EQ(model.meshes.size(), 1u);
  const tinygltf::Primitive& primitive = model.meshes[0].primitives[0];
  ASSERT_TRUE(primitive.attributes.count("TEXCOORD_0"));
  EXPECT_EQ(model.accessors[primitive.attributes.at("POSITION")].count, 35u);
  EXPECT_EQ(model.accessors[primitive.indices].count, 3u * 48u);
  EXPECT_EQ(model.images.size(), 1u);
  EXPECT_EQ(model.images[0].mimeType, "image/png");

  // Untextured, the vertex colours go in instead.
  TriangleMesh plain = Rectangle(views[0]);
  WriteGlb(plain, folder + "/plain.glb");
  tinygltf::Model plain_model;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&plain_model, &error, &warning, folder + "/plain.glb"))
      << error;
  ASSERT_TRUE(plain_model.meshes[0].primitives[0].attributes.count("COLOR_0"));
  EXPECT_TRUE(plain_model.images.empty());
  // glTF's vertex colours are linear: read back through the sRGB curve, they are the mesh's.
  const tinygltf::Accessor& colours =
      plain_model.accessors[plain_model.meshes[0].primitives[0].attributes.at("COLOR_0")];
  ASSERT_EQ(colours.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
  ASSERT_TRUE(colours.normalized);
  ASSERT_EQ(colours.count, plain.vertices.size());
  const tinygltf::BufferView& colour_view = plain_model.bufferViews[colours.bufferView];
  const uint8_t* data = plain_model.buffers[0].data.data() + colour_view.byteOffset + colours.byteOffset;
  for (size_t v = 0; v < colours.count; ++v) {
    for (int c = 0; c < 3; ++c) {
      uint16_t linear = 0;
      std::memcpy(&linear, data + (4 * v + c) * 2, 2);
      const double l = linear / 65535.0;
      const double srgb = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
      EXPECT_NEAR(255.0 * srgb, plain.colours[v][c], 0.5) << "vertex " << v << " channel " << c;
    }
  }
}

TEST(PreviewImage, PhotoBesideTheMeshFromItsCamera) {
  const std::vector<CalibratedView> views = {PatternView(), PatternView()};
  TriangleMesh mesh = Rectangle(views[0]);
  const cv::Mat preview = PreviewImage(mesh, views, 3, 1600);
  // Two views: two rows (the first and the last), photo | render, full size; then a row of three
  // renders from outside the photos' directions, a third of the width each, a row high.
  ASSERT_EQ(preview.size(), cv::Size(160, 180));
  EXPECT_EQ(cv::norm(preview(cv::Rect(0, 0, 80, 60)), views[0].image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(preview(cv::Rect(80, 0, 80, 60)), RenderMesh(mesh, views[0]).image,
                     cv::NORM_INF),
            0.0);
  // Narrower than two photos: each row scaled down to fit.
  EXPECT_EQ(PreviewImage(mesh, views, 1, 80).size(), cv::Size(80, 60));
  EXPECT_TRUE(PreviewImage(mesh, {}, 3, 1600).empty());
}

TEST(ViewsFromOutside, FarFromThePhotosAndFramingTheWholeMesh) {
  const std::vector<CalibratedView> views = {PatternView()};
  const TriangleMesh mesh = Rectangle(views[0]);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& v : mesh.vertices) centre += v.cast<double>();
  centre /= static_cast<double>(mesh.vertices.size());
  const Eigen::Vector3d photo = (views[0].centre - centre).normalized();
  const std::vector<CalibratedView> outside = ViewsFromOutside(mesh, views, 3, 120, 90);
  ASSERT_EQ(outside.size(), 3u);
  // One photo: the first view looks from the opposite side (the nearest candidate to it is 45
  // degrees off), each at least 80 degrees from the photo's direction.
  EXPECT_LT(photo.dot((outside[0].centre - centre).normalized()), std::cos(130.0 * M_PI / 180.0));
  for (const CalibratedView& view : outside) {
    EXPECT_LT(photo.dot((view.centre - centre).normalized()), std::cos(80.0 * M_PI / 180.0));
    for (const Eigen::Vector3f& v : mesh.vertices) {
      EXPECT_GT(view.Depth(v.cast<double>()), 0.0);
      const Eigen::Vector2d pixel = view.Project(v.cast<double>());
      EXPECT_GE(pixel.x(), 0.0);
      EXPECT_LE(pixel.x(), view.width);
      EXPECT_GE(pixel.y(), 0.0);
      EXPECT_LE(pixel.y(), view.height);
    }
  }
  // From behind, the flat rectangle shows its back (both sides are drawn); the next two see it
  // edge-on (90 degrees from the photo), as a flat model is from its sides.
  EXPECT_GT(cv::countNonZero(RenderMesh(mesh, outside[0]).silhouette), 1000);
  EXPECT_TRUE(ViewsFromOutside(TriangleMesh(), views, 3, 120, 90).empty());
}

// Middlebury's dino ring was photographed with the camera on its side: the top of every photo
// points along the ring. The views from outside and the page's 3D view take the photos' up
// turned back, the world's.
TEST(PhotosUp, PhotosAllTurnedAQuarterGiveTheWorldsUp) {
  std::vector<CalibratedView> views;
  for (int i = 0; i < 16; ++i) {  // half a ring: the photos' tops do not cancel out
    const double a = M_PI * i / 15.0;
    const Eigen::Vector3d centre(3.0 * std::cos(a), 3.0 * std::sin(a), 1.5);
    const Eigen::Vector3d forward(-std::cos(a), -std::sin(a), 0.0);  // level
    const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
    Eigen::Matrix3d level;
    level << right.transpose(), forward.cross(right).transpose(), forward.transpose();
    // Turned a quarter about the optical axis: the photo's x axis is the world's up or down.
    const Eigen::Matrix3d turned =
        Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix() * level;
    CalibratedView view;
    view.cam_from_world.rotation = Eigen::Quaterniond(turned);
    view.cam_from_world.translation = -turned * centre;
    view.centre = centre;
    views.push_back(view);
  }
  EXPECT_GT(UpOfPhotos(views).z(), 1.0 - 1e-9);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
