#include "calib/middlebury.h"

#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "tests/test_support.h"

namespace raycarve {
namespace {

Eigen::Vector2i Vga(const std::string&) { return {640, 480}; }

const char kTwoViews[] =
    "2\n"
    "a.png 1500 0 300 0 1510 250 0 0 1  1 0 0 0 1 0 0 0 1  0.1 0.2 0.6\n"
    "b.png 1500 0 300 0 1510 250 0 0 1  0 -1 0 1 0 0 0 0 1  0 0 0.7\n";

TEST(Middlebury, ParsesViewsIntoPinholeCamerasSharingIntrinsics) {
  std::istringstream stream(kTwoViews);
  const Reconstruction model = ReadMiddleburyParameters(stream, "x_par.txt", Vga, MiddleburyImportOptions());
  ASSERT_EQ(model.images.size(), 2u);
  ASSERT_EQ(model.cameras.size(), 1u);  // identical K and size: one camera
  const Camera& camera = model.cameras.begin()->second;
  EXPECT_EQ(camera.model, CameraModelId::kPinhole);
  EXPECT_EQ(camera.params, (std::vector<double>{1500, 1510, 300.5, 250.5}));
  EXPECT_EQ(camera.width, 640u);
  const Image& b = model.images.at(2);
  EXPECT_EQ(b.name, "b.png");
  // P = K [R | t]: R maps world x to camera y.
  EXPECT_TRUE((b.cam_from_world * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(0, 1, 0.7)));
  EXPECT_TRUE(model.points3D.empty());

  MiddleburyImportOptions literal;
  literal.principal_point_offset = 0.0;
  std::istringstream again(kTwoViews);
  EXPECT_EQ(ReadMiddleburyParameters(again, "x", Vga, literal).cameras.begin()->second.params[2], 300.0);
}

void ExpectError(const std::string& text, std::initializer_list<std::string> parts) {
  std::istringstream stream(text);
  try {
    ReadMiddleburyParameters(stream, "set_par.txt", Vga, MiddleburyImportOptions());
    ADD_FAILURE() << "accepted: " << text;
  } catch (const InputError& error) {
    for (const std::string& part : parts) {
      EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
    }
  }
}

TEST(Middlebury, BadFilesNameTheLineAndField) {
  ExpectError("", {"set_par.txt", "empty"});
  ExpectError("two\n", {"line 1", "number of images"});
  ExpectError("3\n" + std::string(kTwoViews).substr(2), {"announces 3", "holds 2"});
  ExpectError("1\n" + std::string(kTwoViews).substr(2), {"line 3", "more image lines"});
  ExpectError("1\na.png 1500 0 300 0 1510 250 0 0 1 1 0 0 0 1 0 0 0 1 0.1 0.2\n", {"line 2", "'t3'", "missing"});
  ExpectError("1\na.png 1500 0 300 0 1510 250 0 0 1 1 0 0 0 1 0 0 0 1 0.1 x 0.6\n", {"line 2", "'t2'", "'x'"});
  ExpectError("1\na.png 1500 2 300 0 1510 250 0 0 1 1 0 0 0 1 0 0 0 1 0.1 0.2 0.6\n", {"line 2", "skew"});
  ExpectError("1\na.png 1500 0 300 0 1510 250 0 0 1 1 0 0 0 2 0 0 0 1 0.1 0.2 0.6\n", {"line 2", "not a rotation"});
  // Off by 1e-3 is not a rotation printed to 7 digits.
  ExpectError("1\na.png 1500 0 300 0 1510 250 0 0 1 1 0.001 0 0 1 0 0 0 1 0.1 0.2 0.6\n", {"not a rotation"});
  // A reflection is orthonormal but not a rotation.
  ExpectError("1\na.png 1500 0 300 0 1510 250 0 0 1 -1 0 0 0 1 0 0 0 1 0.1 0.2 0.6\n", {"not a rotation"});
  ExpectError("1\na.png 1500 0 300 0 1510 250 0 0 1 1 0 0 0 1 0 0 0 1 0.1 nan 0.6\n", {"'t2'"});
  ExpectError("2\na.png 1500 0 3 0 1500 2 0 0 1 1 0 0 0 1 0 0 0 1 0 0 1\na.png 1500 0 3 0 1500 2 0 0 1 1 0 0 0 1 0 0 0 1 0 0 1\n",
              {"duplicate", "a.png"});
  // A focal length of a pixel in a photo 640 wide: a field of view wider than any lens.
  ExpectError("1\na.png 1 0 300 0 1 250 0 0 1 1 0 0 0 1 0 0 0 1 0.1 0.2 0.6\n",
              {"line 2", "focal length 1 px", "less than 1%"});
  ExpectError("1\na.png 4e-320 0 300 0 4e-320 250 0 0 1 1 0 0 0 1 0 0 0 1 0.1 0.2 0.6\n",
              {"line 2", "focal length"});
}

TEST(Middlebury, RotationsPrintedToSevenDigitsAreTakenAndOrthonormalised) {
  // A rotation about z by 0.3 rad, printed to 7 significant digits (|R R^T - I| about 1e-7) and
  // then nudged by 2e-6, as the shipped dinoR_par.txt is.
  const double c = std::cos(0.3), s = std::sin(0.3);
  char line[512];
  std::snprintf(line, sizeof(line),
                "1\na.png 1500 0 300 0 1510 250 0 0 1 %.7g %.7g 0 %.7g %.7g 0 0 0 1.000002 0.1 0.2 0.6\n",
                c, -s, s, c);
  std::istringstream stream(line);
  const Reconstruction model = ReadMiddleburyParameters(stream, "x_par.txt", Vga, MiddleburyImportOptions());
  const Eigen::Matrix3d R = model.images.begin()->second.cam_from_world.rotation.toRotationMatrix();
  EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(R(0, 0), c, 1e-5);
  EXPECT_NEAR(R(1, 0), s, 1e-5);
}

TEST(Middlebury, MissingPhotoIsNamed) {
  RAYCARVE_REQUIRE_DATA("middlebury/templeSparseRing/templeSR_par.txt");
  const std::string empty = testing::MakeTemporaryDirectory("middlebury_empty");
  try {
    ImportMiddlebury(data_path, empty, MiddleburyImportOptions());
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(empty + "/templeSR0001.png"), std::string::npos)
        << error.what();
  }
}

// Every shipped calibration imports (dinoR and dinoSR print rotations orthonormal to 1.6e-6).
TEST(Middlebury, EveryShippedCalibrationImports) {
  RAYCARVE_REQUIRE_DATA("middlebury");
  const std::pair<const char*, size_t> sets[] = {
      {"templeSparseRing/templeSR_par.txt", 16}, {"dinoSparseRing/dinoSR_par.txt", 16},
      {"dinoRing/dinoR_par.txt", 48}};
  for (const auto& [file, images] : sets) {
    const std::string path = data_path + "/" + file;
    const std::string folder = path.substr(0, path.rfind('/'));
    const Reconstruction model = ImportMiddlebury(path, folder, MiddleburyImportOptions());
    EXPECT_EQ(model.images.size(), images) << file;
  }
}

// The imported calibration of the real set against its README's tight box and its photos.
TEST(MiddleburyTemple, ReadmeBoxProjectsInsideEveryPhotoAndCoversTheObject) {
  RAYCARVE_REQUIRE_DATA("middlebury/templeSparseRing");
  const Reconstruction model = ImportMiddlebury(data_path + "/templeSR_par.txt", data_path,
                                                MiddleburyImportOptions());
  ASSERT_EQ(model.images.size(), 16u);
  const Eigen::AlignedBox3d box = testing::ReadMiddleburyReadmeBox(data_path + "/README.txt");
  for (const auto& [image_id, image] : model.images) {
    const Camera& camera = model.cameras.at(image.camera_id);
    double min_x = 1e9, min_y = 1e9, max_x = -1e9, max_y = -1e9;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d in_camera =
          image.cam_from_world * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
      ASSERT_GT(in_camera.z(), 0.0) << image.name;
      const Eigen::Vector2d pixel = camera.ImgFromCam(in_camera.hnormalized());
      EXPECT_TRUE(pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() <= camera.width &&
                  pixel.y() <= camera.height)
          << image.name << " corner " << corner << " at " << pixel.transpose();
      min_x = std::min(min_x, pixel.x());
      min_y = std::min(min_y, pixel.y());
      max_x = std::max(max_x, pixel.x());
      max_y = std::max(max_y, pixel.y());
    }
    // The object is bright on black: its pixels must lie within the box's projection.
    const cv::Mat grey = cv::imread(data_path + "/" + image.name, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(grey.empty());
    int object = 0, inside = 0;
    for (int row = 0; row < grey.rows; ++row) {
      for (int col = 0; col < grey.cols; ++col) {
        if (grey.at<uint8_t>(row, col) < 60) continue;
        ++object;
        const double x = col + 0.5, y = row + 0.5;
        if (x >= min_x && x <= max_x && y >= min_y && y <= max_y) ++inside;
      }
    }
    EXPECT_GT(object, 5000) << image.name;
    EXPECT_GT(static_cast<double>(inside) / object, 0.99) << image.name;
  }
}

TEST(MiddleburyTemple, ImportAgreesWithCOLMAPsModelOfTheCalibrationUpToTheHalfPixel) {
  RAYCARVE_REQUIRE_DATA("middlebury/templeSparseRing");
  const Reconstruction imported = ImportMiddlebury(data_path + "/templeSR_par.txt", data_path,
                                                   MiddleburyImportOptions());
  const Reconstruction given = ReadModel(data_path + "/colmap/given");
  std::map<std::string, const Image*> by_name;
  for (const auto& [id, image] : given.images) by_name[image.name] = &image;
  ASSERT_EQ(by_name.size(), imported.images.size());
  for (const auto& [id, image] : imported.images) {
    ASSERT_EQ(by_name.count(image.name), 1u) << image.name;
    const Image& other = *by_name.at(image.name);
    EXPECT_LT(image.cam_from_world.rotation.angularDistance(other.cam_from_world.rotation), 1e-9);
    EXPECT_LT((image.cam_from_world.translation - other.cam_from_world.translation).norm(), 1e-9);
    const std::vector<double>& ours = imported.cameras.at(image.camera_id).params;
    const std::vector<double>& theirs = given.cameras.at(other.camera_id).params;
    EXPECT_DOUBLE_EQ(ours[0], theirs[0]);
    EXPECT_DOUBLE_EQ(ours[1], theirs[1]);
    // The shared model copied K's principal point literally; raycarve adds half a pixel.
    EXPECT_NEAR(ours[2] - theirs[2], 0.5, 1e-9);
    EXPECT_NEAR(ours[3] - theirs[3], 0.5, 1e-9);
  }
}

}  // namespace
}  // namespace raycarve
