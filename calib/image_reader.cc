#include "calib/image_reader.h"

#include <cerrno>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <vector>

#include <jpeglib.h>
#include <opencv2/imgcodecs.hpp>

#include "calib/input_error.h"

namespace raycarve {
namespace {

// libjpeg's error manager with its warnings made errors: both jump back with the message.
struct StrictJpegErrors {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = {0};
};

[[noreturn]] void JumpWithMessage(j_common_ptr info) {
  StrictJpegErrors* errors = reinterpret_cast<StrictJpegErrors*>(info->err);
  (*info->err->format_message)(info, errors->message);
  std::longjmp(errors->jump, 1);
}

void OnJpegMessage(j_common_ptr info, int level) {
  if (level < 0) JumpWithMessage(info);  // a warning: the data is damaged
}

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};

bool StartsLikeJpeg(std::FILE* file) {
  unsigned char magic[3] = {0, 0, 0};
  const bool jpeg = std::fread(magic, 1, 3, file) == 3 && magic[0] == 0xFF && magic[1] == 0xD8 &&
                    magic[2] == 0xFF;
  std::rewind(file);
  return jpeg;
}

std::unique_ptr<std::FILE, FileCloser> OpenForReading(const std::string& path) {
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw InputError(path + ": cannot open for reading: " + std::strerror(errno));
  return file;
}

// CheckJpegStrictly on an open file.
void CheckJpegFile(const std::string& path, std::FILE* file) {
  if (!StartsLikeJpeg(file)) return;
  jpeg_decompress_struct info;
  StrictJpegErrors errors;
  info.err = jpeg_std_error(&errors.manager);
  errors.manager.error_exit = JumpWithMessage;
  errors.manager.emit_message = OnJpegMessage;
  std::vector<JSAMPLE> row;
  if (setjmp(errors.jump) != 0) {
    jpeg_destroy_decompress(&info);
    throw InputError(path + ": damaged JPEG (" + errors.message +
                     "): raycarve does not carve with a photo or mask that cannot be read whole");
  }
  jpeg_create_decompress(&info);
  jpeg_stdio_src(&info, file);
  jpeg_read_header(&info, TRUE);
  jpeg_start_decompress(&info);
  row.resize(static_cast<size_t>(info.output_width) * info.output_components);
  JSAMPROW rows[1] = {row.data()};
  while (info.output_scanline < info.output_height) jpeg_read_scanlines(&info, rows, 1);
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
}

}  // namespace

std::string WhyNotAFile(const std::string& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) return "not found";
  if (error) return "cannot be reached: " + error.message();
  if (status.type() == std::filesystem::file_type::directory) return "is a folder, not a file";
  if (status.type() != std::filesystem::file_type::regular) {
    return "is a FIFO, socket or device, not a file";
  }
  return "";
}

void CheckJpegStrictly(const std::string& path) {
  const std::unique_ptr<std::FILE, FileCloser> file = OpenForReading(path);
  CheckJpegFile(path, file.get());
}

cv::Size ReadImageSize(const std::string& path) {
  const std::string why = WhyNotAFile(path);
  if (!why.empty()) throw InputError(path + ": " + why);
  const std::unique_ptr<std::FILE, FileCloser> file = OpenForReading(path);
  if (StartsLikeJpeg(file.get())) {
    jpeg_decompress_struct info;
    StrictJpegErrors errors;
    info.err = jpeg_std_error(&errors.manager);
    errors.manager.error_exit = JumpWithMessage;
    errors.manager.emit_message = OnJpegMessage;
    if (setjmp(errors.jump) != 0) {
      jpeg_destroy_decompress(&info);
      throw InputError(path + ": damaged JPEG header (" + errors.message + ")");
    }
    jpeg_create_decompress(&info);
    jpeg_stdio_src(&info, file.get());
    jpeg_read_header(&info, TRUE);
    const cv::Size size(static_cast<int>(info.image_width), static_cast<int>(info.image_height));
    jpeg_destroy_decompress(&info);
    return size;
  }
  // PNG: the signature, then the IHDR chunk's width and height, big-endian.
  unsigned char head[24] = {0};
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (std::fread(head, 1, sizeof(head), file.get()) == sizeof(head) &&
      std::memcmp(head, kPng, 8) == 0 && std::memcmp(head + 12, "IHDR", 4) == 0) {
    const auto big_endian = [&](int at) {
      return (static_cast<uint32_t>(head[at]) << 24) | (static_cast<uint32_t>(head[at + 1]) << 16) |
             (static_cast<uint32_t>(head[at + 2]) << 8) | head[at + 3];
    };
    const uint32_t width = big_endian(16), height = big_endian(20);
    if (width == 0 || height == 0 || width > 1u << 30 || height > 1u << 30) {
      throw InputError(path + ": PNG header gives a size of " + std::to_string(width) + " x " +
                       std::to_string(height));
    }
    return cv::Size(static_cast<int>(width), static_cast<int>(height));
  }
  const cv::Mat image = ReadImage(path, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw InputError(path + ": not an image OpenCV can read");
  return image.size();
}

cv::Mat ReadImage(const std::string& path, int flags) {
  const std::string why = WhyNotAFile(path);
  if (!why.empty()) throw InputError(path + ": " + why);
  CheckJpegFile(path, OpenForReading(path).get());
  // COLMAP reads the pixels as stored and registers them so; OpenCV would turn a photo by its
  // EXIF orientation (a phone held upright: 3000x4000 against COLMAP's 4000x3000, or upside
  // down: the same size, silently turned). IMREAD_UNCHANGED ignores the orientation already.
  if (flags != cv::IMREAD_UNCHANGED) flags |= cv::IMREAD_IGNORE_ORIENTATION;
  try {
    return cv::imread(path, flags);
  } catch (const cv::Exception& error) {
    throw InputError(path + ": OpenCV refuses to decode it (" + error.err + ")");
  }
}

}  // namespace raycarve
