// Photos as users bring them: grey ones, damaged ones. Each case runs the `raycarve` program.
#include <filesystem>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/test_support.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;

using testing::RunRaycarve;

// A generated studio project (plain backdrop) in `folder`.
void MakeProject(const std::string& folder) {
  std::string output;
  ASSERT_EQ(RunRaycarve("synth --output_path " + folder +
                    " --views 6 --width 128 --height 96 --points 400 --backdrop uniform",
                &output),
            0)
      << output;
}

// Rewrites photo `name` of `project` as one-channel grey, 8 or 16 bits.
void MakeGrey(const std::string& project, const std::string& name, int depth) {
  const std::string path = project + "/images/" + name;
  cv::Mat grey;
  cv::cvtColor(cv::imread(path, cv::IMREAD_COLOR), grey, cv::COLOR_BGR2GRAY);
  if (depth == CV_16U) grey.convertTo(grey, CV_16U, 257.0);
  ASSERT_TRUE(cv::imwrite(path, grey));
}

using testing::JsonNumber;

TEST(PhotoInput, GreyPhotosAreCarvedAndNeverMaskedWhole) {
  const std::string root = testing::MakeTemporaryDirectory("photo_input_grey");
  for (int depth : {CV_8U, CV_16U}) {
    const std::string project = root + "/grey" + std::to_string(depth);
    MakeProject(project);
    for (const auto& entry : fs::directory_iterator(project + "/images")) {
      MakeGrey(project, entry.path().filename().string(), depth);
    }
    std::string output;
    ASSERT_EQ(RunRaycarve("carve --workspace_path " + project + " --resolution 32", &output), 0) << output;
    EXPECT_EQ(output.find("kept nothing"), std::string::npos) << output;
    const std::string report = testing::ReadFileBytes(project + "/raycarve/report.json");
    EXPECT_GT(JsonNumber(report, "cloud_points"), 1000) << report;
  }
  // One grey photo among colour ones.
  const std::string mixed = root + "/mixed";
  MakeProject(mixed);
  MakeGrey(mixed, "view002.png", CV_8U);
  std::string output;
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + mixed + " --resolution 32", &output), 0) << output;
  EXPECT_EQ(output.find("kept nothing"), std::string::npos) << output;
  const std::string report = testing::ReadFileBytes(mixed + "/raycarve/report.json");
  EXPECT_GT(JsonNumber(report, "cloud_points"), 1000) << report;
  // No photo's mask is all background.
  for (const auto& entry : fs::directory_iterator(mixed + "/raycarve/masks")) {
    const cv::Mat mask = cv::imread(entry.path().string(), cv::IMREAD_GRAYSCALE);
    EXPECT_GT(cv::countNonZero(mask), 0) << entry.path();
  }
}

TEST(PhotoInput, APhotoOfTheBackdropAloneIsCarvedWithoutAMask) {
  // view002's photo shows only the backdrop (the object left out of it): a mask of it would be
  // all background, and the visual hull would carve away everything it sees. The sparse points
  // that land on it say its colour is the object's, so it gets no mask (and a mask that would
  // still come out empty is dropped: view_reader.cc).
  const std::string root = testing::MakeTemporaryDirectory("photo_input_all_backdrop");
  const std::string project = root + "/project";
  MakeProject(project);
  const std::string path = project + "/images/view002.png";
  cv::Mat photo = cv::imread(path);
  photo.setTo(photo.at<cv::Vec3b>(0, 0));
  ASSERT_TRUE(cv::imwrite(path, photo));
  std::string output;
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + project + " --resolution 32", &output), 0)
      << output;
  EXPECT_NE(output.find(path + ": no plain backdrop"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(project + "/raycarve/masks/view002.png.png"));
  EXPECT_TRUE(fs::exists(project + "/raycarve/masks/view001.png.png"));
  EXPECT_EQ(output.find("kept nothing"), std::string::npos) << output;
}

TEST(PhotoInput, ADamagedJpegPhotoIsNamedAndNothingIsCarved) {
  const std::string root = testing::MakeTemporaryDirectory("photo_input_jpeg");
  const std::string project = root + "/project";
  MakeProject(project);
  // view003's photo as a JPEG (under its own name: decoders go by the content), cut in half.
  const std::string path = project + "/images/view003.png";
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", cv::imread(path), jpeg));
  testing::WriteFile(path, std::string(jpeg.begin(), jpeg.begin() + jpeg.size() / 2));
  std::string output;
  EXPECT_EQ(RunRaycarve("carve --workspace_path " + project + " --resolution 32", &output), 1) << output;
  EXPECT_NE(output.find(path), std::string::npos) << output;
  EXPECT_NE(output.find("damaged JPEG"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(project + "/raycarve/report.json"));
}

TEST(PhotoInput, ImplausibleValuesAreRefusedSayingWhichAndWhy) {
  const std::string root = testing::MakeTemporaryDirectory("photo_input_plausible");
  const std::string project = root + "/project";
  std::string output;
  ASSERT_EQ(RunRaycarve("synth --output_path " + project + " --views 4 --width 96 --height 72 " +
                            "--points 300 --camera_model OPENCV_FISHEYE",
                        &output),
            0)
      << output;
  const auto refused = [&](const std::string& arguments, std::initializer_list<std::string> parts) {
    EXPECT_EQ(RunRaycarve(arguments, &output), 1) << arguments << "\n" << output;
    for (const std::string& part : parts) {
      EXPECT_NE(output.find(part), std::string::npos) << "'" << part << "' not in:\n" << output;
    }
  };
  refused("carve --workspace_path " + project + " --max_image_size 1", {"--max_image_size 1", "at least 48"});
  refused("carve --workspace_path " + project + " --margin 1e308", {"margin must be in [0, 100]"});
  // A fisheye coefficient that folds the image: no undistorted pixel has a source.
  const std::string model = root + "/folded";
  ASSERT_EQ(RunRaycarve("model_converter --input_path " + project + "/sparse/0 --output_path " +
                            model + " --output_type TXT",
                        &output),
            0)
      << output;
  std::string cameras = testing::ReadFileBytes(model + "/cameras.txt");
  const size_t line = cameras.find("OPENCV_FISHEYE");
  ASSERT_NE(line, std::string::npos);
  // The 8 numbers after the size are fx fy cx cy k1 k2 k3 k4: k1 becomes -1e12.
  std::istringstream fields(cameras.substr(line, cameras.find('\n', line) - line));
  std::vector<std::string> words{std::istream_iterator<std::string>(fields), {}};
  ASSERT_EQ(words.size(), 11u);
  words[7] = "-1e12";
  std::string edited;
  for (const std::string& word : words) edited += (edited.empty() ? "" : " ") + word;
  cameras.replace(line, cameras.find('\n', line) - line, edited);
  testing::WriteFile(model + "/cameras.txt", cameras);
  refused("calibrate --input_path " + model + " --image_path " + project + "/images --output_path " +
              root + "/folded_out",
          {"view001.png", "folds the image"});
}

// Masks are decided for the capture: the same cameras and scene photographed in front of a plain
// backdrop (automatic masks) and under a patchwork sky (none); photos of the second replace some
// of the first's.
TEST(PhotoInput, ABackdropFoundInAMinorityOfThePhotosIsNotUsed) {
  const std::string root = testing::MakeTemporaryDirectory("photo_input_minority");
  const std::string scene = " --views 6 --width 128 --height 96 --points 400 --backdrop ";
  std::string output;
  ASSERT_EQ(RunRaycarve("synth --output_path " + root + "/natural" + scene + "patchwork", &output), 0)
      << output;
  for (const int replaced : {4, 2}) {
    const std::string project = root + "/studio" + std::to_string(replaced);
    ASSERT_EQ(RunRaycarve("synth --output_path " + project + scene + "uniform", &output), 0) << output;
    for (int view = 1; view <= replaced; ++view) {
      const std::string name = "/images/view00" + std::to_string(view) + ".png";
      fs::copy_file(root + "/natural" + name, project + name, fs::copy_options::overwrite_existing);
    }
    ASSERT_EQ(RunRaycarve("carve --workspace_path " + project + " --resolution 32", &output), 0)
        << output;
    const std::string report = testing::ReadFileBytes(project + "/raycarve/report.json");
    if (replaced == 4) {
      // 2 of 6 with a backdrop: a minority, dropped; every photo carved whole.
      EXPECT_NE(output.find("a backdrop found in 2 of 6 photos only (a minority)"), std::string::npos)
          << output;
      EXPECT_EQ(JsonNumber(report, "backdrop_masks_dropped"), 2);
      EXPECT_EQ(JsonNumber(report, "masks_from_backdrop"), 0);
      EXPECT_FALSE(fs::exists(project + "/raycarve/masks"));
    } else {
      // 4 of 6: the capture's backdrop, its masks used.
      EXPECT_EQ(JsonNumber(report, "backdrop_masks_dropped"), 0);
      EXPECT_EQ(JsonNumber(report, "masks_from_backdrop"), 4);
    }
  }
}

}  // namespace
}  // namespace raycarve
