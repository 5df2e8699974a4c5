#include "calib/image_reader.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/test_support.h"

namespace raycarve {
namespace {

// A JPEG of `image` whose EXIF says it is to be shown turned by `orientation` (6: a phone held
// upright, 90 degrees clockwise; 3: upside down): an APP1 segment with one IFD entry put after
// the start-of-image marker of OpenCV's own encoding.
void WriteJpegWithOrientation(const cv::Mat& image, int orientation, const std::string& path) {
  std::vector<uint8_t> encoded;
  ASSERT_TRUE(cv::imencode(".jpg", image, encoded, {cv::IMWRITE_JPEG_QUALITY, 100}));
  const std::vector<uint8_t> app1 = {
      0xFF, 0xE1, 0x00, 0x22,                          // APP1, 34 bytes from here
      'E', 'x', 'i', 'f', 0x00, 0x00,                  // the EXIF header
      'I', 'I', 0x2A, 0x00, 0x08, 0x00, 0x00, 0x00,    // TIFF, little-endian, IFD at 8
      0x01, 0x00,                                      // one entry
      0x12, 0x01, 0x03, 0x00, 0x01, 0x00, 0x00, 0x00,  // Orientation, SHORT, one value
      static_cast<uint8_t>(orientation), 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00};                         // no next IFD
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(encoded.data()), 2);  // start of image
  file.write(reinterpret_cast<const char*>(app1.data()), static_cast<std::streamsize>(app1.size()));
  file.write(reinterpret_cast<const char*>(encoded.data() + 2),
             static_cast<std::streamsize>(encoded.size() - 2));
}

TEST(ImageReader, ReadsThePixelsAsStoredWhateverTheExifOrientationAsColmapDoes) {
  // 40 wide, 30 high: red top-left, green bottom-right, so that a turn shows.
  cv::Mat image(30, 40, CV_8UC3, cv::Scalar(128, 128, 128));
  image(cv::Rect(0, 0, 20, 15)).setTo(cv::Scalar(0, 0, 255));
  image(cv::Rect(20, 15, 20, 15)).setTo(cv::Scalar(0, 255, 0));
  const std::string folder = testing::MakeTemporaryDirectory("exif_orientation");
  for (int orientation : {6, 3}) {
    const std::string path = folder + "/photo" + std::to_string(orientation) + ".jpg";
    WriteJpegWithOrientation(image, orientation, path);
    // The file does carry an orientation OpenCV honours by default (else this test sees nothing).
    const cv::Mat turned = cv::imread(path, cv::IMREAD_COLOR);
    ASSERT_FALSE(turned.empty());
    if (orientation == 6) {
      EXPECT_EQ(turned.size(), cv::Size(30, 40));
    } else {
      EXPECT_GT(turned.at<cv::Vec3b>(25, 35)[2], 200) << "upside down: red at the bottom right";
    }
    // COLMAP 3.8 registers such a photo with its stored size (checked with `colmap
    // feature_extractor`: a 400x300 JPEG with orientation 6 gives a 400x300 camera), so raycarve
    // reads the stored pixels, in colour and in grey.
    for (int flags : {cv::IMREAD_COLOR, cv::IMREAD_GRAYSCALE, cv::IMREAD_UNCHANGED}) {
      const cv::Mat read = ReadImage(path, flags);
      ASSERT_EQ(read.size(), cv::Size(40, 30)) << "orientation " << orientation << ", flags " << flags;
      if (read.channels() == 3) {
        EXPECT_GT(read.at<cv::Vec3b>(5, 5)[2], 200) << "red stays at the top left";
        EXPECT_GT(read.at<cv::Vec3b>(25, 35)[1], 200) << "green stays at the bottom right";
      }
    }
  }
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace raycarve
