#include "calib/model_reader.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "calib/model_writer.h"
#include "tests/test_support.h"

namespace raycarve {
namespace {

using testing::RandomReconstruction;

// Expects `body` to throw InputError whose message contains every one of `parts`.
template <typename Body>
void ExpectInputError(Body body, std::initializer_list<std::string> parts) {
  try {
    body();
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& error) {
    const std::string message = error.what();
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
    }
  }
}

std::string Bytes(void (*writer)(const Reconstruction&, std::ostream&), const Reconstruction& r) {
  std::ostringstream stream;
  writer(r, stream);
  return stream.str();
}

TEST(ModelReader, ReadsHandWrittenTextModel) {
  std::istringstream cameras(
      "# comment\n"
      "1 SIMPLE_RADIAL 640 480 500.5 320 240 -0.01\r\n"
      "\n"
      "2 PINHOLE 100 80 90 91 50 40\n");
  std::istringstream images(
      "# Image list\n"
      "5 1 0 0 0 0.1 -0.2 3 1 my photo.png\n"
      "10.5 20.25 -1 30 40 9\n"
      "6 0.7071067811865476 0 0.7071067811865476 0 0 0 0 2 b.jpg\n"
      "\n");
  std::istringstream points("9 1.5 -2 3e-1 255 0 17 0.25 5 1\n");
  Reconstruction model;
  ReadCamerasText(cameras, "cameras.txt", &model);
  ReadImagesText(images, "images.txt", &model);
  ReadPoints3DText(points, "points3D.txt", &model);
  ValidateReconstruction(model, "test");

  ASSERT_EQ(model.cameras.size(), 2u);
  EXPECT_EQ(model.cameras.at(1).model, CameraModelId::kSimpleRadial);
  EXPECT_EQ(model.cameras.at(1).params, (std::vector<double>{500.5, 320, 240, -0.01}));
  EXPECT_EQ(model.cameras.at(2).width, 100u);
  ASSERT_EQ(model.images.size(), 2u);
  const Image& image = model.images.at(5);
  EXPECT_EQ(image.name, "my photo.png");
  EXPECT_EQ(image.camera_id, 1u);
  EXPECT_EQ(image.cam_from_world.translation, Eigen::Vector3d(0.1, -0.2, 3));
  ASSERT_EQ(image.points2D.size(), 2u);
  EXPECT_EQ(image.points2D[0].xy, Eigen::Vector2d(10.5, 20.25));
  EXPECT_EQ(image.points2D[0].point3D_id, kInvalidPoint3DId);
  EXPECT_EQ(image.points2D[1].point3D_id, 9u);
  EXPECT_TRUE(model.images.at(6).points2D.empty());  // the empty second line
  const Point3D& point = model.points3D.at(9);
  EXPECT_EQ(point.xyz, Eigen::Vector3d(1.5, -2, 0.3));
  EXPECT_EQ(point.color, (Eigen::Matrix<uint8_t, 3, 1>(255, 0, 17)));
  ASSERT_EQ(point.track.size(), 1u);
  EXPECT_EQ(point.track[0].image_id, 5u);
  EXPECT_EQ(point.track[0].point2D_idx, 1u);
  // Camera centre = -R^T t: identity rotation.
  EXPECT_TRUE(image.ProjectionCenter().isApprox(Eigen::Vector3d(-0.1, 0.2, -3)));
}

TEST(ModelWriter, BinaryAndTextRoundTripsAreExact) {
  for (uint64_t seed : {1u, 2u, 3u}) {
    const Reconstruction original = RandomReconstruction(seed);
    for (ModelFormat format : {ModelFormat::kBinary, ModelFormat::kText}) {
      const std::string folder = testing::MakeTemporaryDirectory("roundtrip");
      WriteModel(original, folder, format);
      const Reconstruction read = ReadModel(folder);
      SCOPED_TRACE(ModelFormatToString(format));
      testing::ExpectSameReconstruction(original, read);
      std::filesystem::remove_all(folder);
    }
  }
}

TEST(ModelReader, EveryTruncationOfEveryBinaryFileIsAnErrorNamingTheFile) {
  const Reconstruction model = RandomReconstruction(4, 3, 10);
  const struct {
    const char* name;
    void (*write)(const Reconstruction&, std::ostream&);
    void (*read)(std::istream&, const std::string&, Reconstruction*);
  } files[] = {{"cameras.bin", WriteCamerasBinary, ReadCamerasBinary},
               {"images.bin", WriteImagesBinary, ReadImagesBinary},
               {"points3D.bin", WritePoints3DBinary, ReadPoints3DBinary}};
  for (const auto& file : files) {
    const std::string bytes = Bytes(file.write, model);
    for (size_t length = 0; length < bytes.size(); ++length) {
      std::istringstream stream(bytes.substr(0, length));
      Reconstruction target;
      try {
        file.read(stream, file.name, &target);
        ADD_FAILURE() << file.name << " truncated to " << length << " of " << bytes.size()
                      << " bytes was accepted";
      } catch (const InputError& error) {
        EXPECT_EQ(std::string(error.what()).rfind(file.name, 0), 0u) << error.what();
      }
    }
    std::istringstream whole(bytes);
    Reconstruction target;
    EXPECT_NO_THROW(file.read(whole, file.name, &target));
  }
}

TEST(ModelReader, TruncationNamesTheRecordAndField) {
  const Reconstruction model = RandomReconstruction(5, 3, 10);
  const std::string bytes = Bytes(WriteImagesBinary, model);
  // Cut inside the last image's points2D: its count no longer fits what remains.
  std::istringstream stream(bytes.substr(0, bytes.size() - 5));
  Reconstruction target;
  ExpectInputError([&] { ReadImagesBinary(stream, "sparse/images.bin", &target); },
                   {"sparse/images.bin", "image record 3 of 3", "num_points2D", "truncated"});
}

TEST(ModelReader, CorruptedCountsAreErrorsNotAllocations) {
  const Reconstruction model = RandomReconstruction(6, 3, 10);
  std::string bytes = Bytes(WritePoints3DBinary, model);
  const uint64_t huge = uint64_t{1} << 60;
  bytes.replace(0, 8, reinterpret_cast<const char*>(&huge), 8);
  std::istringstream stream(bytes);
  Reconstruction target;
  ExpectInputError([&] { ReadPoints3DBinary(stream, "points3D.bin", &target); },
                   {"points3D.bin", "num_points3D", "wrong count"});

  // A count smaller than the records present leaves trailing data.
  std::string cameras = Bytes(WriteCamerasBinary, model);
  const uint64_t fewer = model.cameras.size() - 1;
  cameras.replace(0, 8, reinterpret_cast<const char*>(&fewer), 8);
  std::istringstream camera_stream(cameras);
  ExpectInputError([&] { ReadCamerasBinary(camera_stream, "cameras.bin", &target); },
                   {"cameras.bin", "trailing data"});
}

TEST(ModelReader, UnknownModelIdInBinaryNamesFileCameraAndModel) {
  Reconstruction model;
  model.cameras.emplace(3, testing::MakeCamera(3, CameraModelId::kPinhole, 10, 10, {1, 1, 5, 5}));
  std::string bytes = Bytes(WriteCamerasBinary, model);
  const int32_t newer = 12;  // SIMPLE_DIVISION in later COLMAP
  bytes.replace(8 + 4, 4, reinterpret_cast<const char*>(&newer), 4);
  std::istringstream stream(bytes);
  Reconstruction target;
  ExpectInputError([&] { ReadCamerasBinary(stream, "cameras.bin", &target); },
                   {"cameras.bin", "camera 3", "model_id", "SIMPLE_DIVISION"});
}

TEST(ModelReader, MalformedTextNamesLineAndField) {
  Reconstruction target;
  std::istringstream wrong_count("1 OPENCV 640 480 500 500 320 240\n");
  ExpectInputError([&] { ReadCamerasText(wrong_count, "cameras.txt", &target); },
                   {"cameras.txt", "line 1", "PARAMS", "needs 8"});
  std::istringstream bad_number("1 PINHOLE 640 480 500 5O0 320 240\n");
  ExpectInputError([&] { ReadCamerasText(bad_number, "cameras.txt", &target); },
                   {"line 1", "PARAMS", "'5O0'"});
  std::istringstream unknown("# c\n2 FISHEYE 640 480 1 2 3 4\n");
  ExpectInputError([&] { ReadCamerasText(unknown, "cameras.txt", &target); },
                   {"camera 2", "FISHEYE"});
  std::istringstream odd_points("1 1 0 0 0 0 0 0 1 a.png\n1 2\n");
  ExpectInputError([&] { ReadImagesText(odd_points, "images.txt", &target); },
                   {"images.txt", "line 2", "POINTS2D", "triples"});
  std::istringstream colour("1 0 0 0 300 0 0 1\n");
  ExpectInputError([&] { ReadPoints3DText(colour, "points3D.txt", &target); },
                   {"points3D.txt", "line 1", "'R'"});
  std::istringstream duplicate("1 PINHOLE 1 1 1 1 1 1\n1 PINHOLE 1 1 1 1 1 1\n");
  Reconstruction fresh;
  ExpectInputError([&] { ReadCamerasText(duplicate, "cameras.txt", &fresh); },
                   {"duplicate camera id 1"});
}

class ModelFolderTest : public ::testing::Test {
 protected:
  void SetUp() override { folder_ = testing::MakeTemporaryDirectory("model_folder"); }
  void TearDown() override { std::filesystem::remove_all(folder_); }
  void Write(const std::string& name, const std::string& text) {
    testing::WriteFile(folder_ + "/" + name, text);
  }
  std::string folder_;
};

TEST_F(ModelFolderTest, NaNPoseIsRejectedNamingTheImageAndPose) {
  Write("cameras.txt", "1 PINHOLE 640 480 500 500 320 240\n");
  Write("images.txt", "4 nan 0 0 0 0 0 1 1 a.png\n\n");
  Write("points3D.txt", "");
  ExpectInputError([&] { ReadModel(folder_); }, {folder_, "image 4", "a.png", "pose", "not finite"});
}

TEST_F(ModelFolderTest, ZeroQuaternionAndDanglingReferencesAreRejected) {
  Write("cameras.txt", "1 PINHOLE 640 480 500 500 320 240\n");
  Write("images.txt", "4 0 0 0 0 0 0 1 1 a.png\n\n");
  Write("points3D.txt", "");
  ExpectInputError([&] { ReadModel(folder_); }, {"image 4", "zero norm"});
  Write("images.txt", "4 1 0 0 0 0 0 1 2 a.png\n\n");
  ExpectInputError([&] { ReadModel(folder_); }, {"image 4", "camera_id 2"});
  Write("images.txt", "4 1 0 0 0 0 0 1 1 a.png\n1 2 77\n");
  ExpectInputError([&] { ReadModel(folder_); }, {"image 4", "point3D_id 77"});
  Write("images.txt", "4 1 0 0 0 0 0 1 1 a.png\n1 2 -1\n");
  Write("points3D.txt", "8 0 0 0 1 2 3 0.5 4 0 4 1\n");
  ExpectInputError([&] { ReadModel(folder_); }, {"point3D 8", "point2D_idx 1"});
  Write("points3D.txt", "8 0 0 0 1 2 3 0.5 9 0\n");
  ExpectInputError([&] { ReadModel(folder_); }, {"point3D 8", "image_id 9"});
  Write("cameras.txt", "1 PINHOLE 640 480 -500 500 320 240\n");
  Write("points3D.txt", "");
  ExpectInputError([&] { ReadModel(folder_); }, {"camera 1", "focal length"});
}

TEST_F(ModelFolderTest, EmptyModelReadsAsEmpty) {
  Write("cameras.txt", "# Number of cameras: 0\n");
  Write("images.txt", "");
  Write("points3D.txt", "");
  const Reconstruction model = ReadModel(folder_);
  EXPECT_TRUE(model.cameras.empty());
  EXPECT_TRUE(model.images.empty());
  EXPECT_TRUE(model.points3D.empty());
}

TEST_F(ModelFolderTest, MissingFolderOrFilesAreNamed) {
  ExpectInputError([&] { ReadModel(folder_ + "/nope"); }, {folder_ + "/nope", "does not exist"});
  Write("cameras.txt", "");
  ExpectInputError([&] { ReadModel(folder_); }, {folder_, "images.bin nor images.txt"});
}

TEST_F(ModelFolderTest, BinaryIsPreferredOverTextAndRigsFramesAreIgnored) {
  const Reconstruction binary_model = RandomReconstruction(7, 2, 5);
  WriteModel(binary_model, folder_, ModelFormat::kBinary);
  // A different model in text beside it, and COLMAP >= 3.12's extra files.
  WriteModel(RandomReconstruction(8, 3, 6), folder_, ModelFormat::kText);
  Write("rigs.bin", std::string(16, '\x01'));
  Write("frames.bin", std::string(16, '\x02'));
  testing::ExpectSameReconstruction(binary_model, ReadModel(folder_));
}

}  // namespace
}  // namespace raycarve
