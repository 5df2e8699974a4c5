#include "calib/image_reader.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <opencv2/imgcodecs.hpp>

#include "calib/input_error.h"
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

// A textured test image, as a JPEG's bytes.
std::vector<uint8_t> TexturedJpeg() {
  cv::Mat image(96, 128, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  std::vector<uint8_t> encoded;
  EXPECT_TRUE(cv::imencode(".jpg", image, encoded, {cv::IMWRITE_JPEG_QUALITY, 90}));
  return encoded;
}

void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes, size_t count) {
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(count));
}

// The InputError's message of ReadImage(path), or "" when it reads.
std::string ReadError(const std::string& path) {
  try {
    ReadImage(path, cv::IMREAD_COLOR);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(ImageReader, AJpegCutShortOrCorruptIsAnErrorNamingItAsAPngIs) {
  const std::string folder = testing::MakeTemporaryDirectory("image_reader_damaged");
  const std::vector<uint8_t> jpeg = TexturedJpeg();
  const std::string whole = folder + "/whole.jpg";
  WriteBytes(whole, jpeg, jpeg.size());
  EXPECT_EQ(ReadError(whole), "");
  EXPECT_FALSE(ReadImage(whole, cv::IMREAD_COLOR).empty());
  // Cut in half: libjpeg would fill the rest with grey and only warn.
  const std::string half = folder + "/half.jpg";
  WriteBytes(half, jpeg, jpeg.size() / 2);
  const std::string cut = ReadError(half);
  EXPECT_NE(cut.find(half), std::string::npos) << cut;
  EXPECT_NE(cut.find("damaged JPEG"), std::string::npos) << cut;
  // Bytes of the entropy-coded data overwritten by markers libjpeg does not expect there.
  std::vector<uint8_t> corrupt = jpeg;
  for (size_t k = corrupt.size() / 2; k < corrupt.size() / 2 + 64; k += 2) {
    corrupt[k] = 0xFF;
    corrupt[k + 1] = 0xD0 + (k / 2) % 8;  // restart markers out of place
  }
  const std::string damaged = folder + "/corrupt.jpg";
  WriteBytes(damaged, corrupt, corrupt.size());
  EXPECT_NE(ReadError(damaged).find("damaged JPEG"), std::string::npos) << ReadError(damaged);
  // A PNG cut short was refused already: the two formats agree now.
  std::vector<uint8_t> png;
  ASSERT_TRUE(cv::imencode(".png", cv::imread(whole), png));
  const std::string half_png = folder + "/half.png";
  WriteBytes(half_png, png, png.size() / 2);
  EXPECT_TRUE(ReadImage(half_png, cv::IMREAD_COLOR).empty() || !ReadError(half_png).empty());
}

TEST(ImageReader, SaysWhatAPathIsWhenItIsNoFile) {
  const std::string folder = testing::MakeTemporaryDirectory("image_reader_kinds");
  EXPECT_EQ(WhyNotAFile(folder + "/absent.png"), "not found");
  EXPECT_EQ(WhyNotAFile(folder), "is a folder, not a file");
  EXPECT_NE(ReadError(folder).find("is a folder"), std::string::npos);
  const std::string fifo = folder + "/pipe.png";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  EXPECT_EQ(WhyNotAFile(fifo), "is a FIFO, socket or device, not a file");
  EXPECT_NE(ReadError(fifo).find("FIFO"), std::string::npos);  // and never blocks reading it
  EXPECT_NE(ReadError("/dev/null").find("device"), std::string::npos);
}

}  // namespace
}  // namespace raycarve
