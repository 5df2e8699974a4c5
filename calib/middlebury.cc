#include "calib/middlebury.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <locale>
#include <set>
#include <sstream>
#include <vector>

#include <Eigen/Dense>
#include <glog/logging.h>
#include <opencv2/imgcodecs.hpp>

#include "calib/image_reader.h"
#include "calib/input_error.h"

namespace raycarve {
namespace {

constexpr int kNumValues = 21;
const char* const kFieldNames[kNumValues] = {"k11", "k12", "k13", "k21", "k22", "k23", "k31",
                                             "k32", "k33", "r11", "r12", "r13", "r21", "r22",
                                             "r23", "r31", "r32", "r33", "t1",  "t2",  "t3"};

}  // namespace

bool MiddleburyImportOptions::IsValid(std::string* reason) const {
  if (!std::isfinite(principal_point_offset) || std::abs(principal_point_offset) > 1.0) {
    *reason = "principal_point_offset must be a finite number of at most one pixel";
    return false;
  }
  return true;
}

namespace {

// Throws InputError naming the file, the line and the field.
struct LineError {
  const std::string& source;
  const int& line_number;
  [[noreturn]] void operator()(const std::string& field, const std::string& what) const {
    throw InputError(source + ": line " + std::to_string(line_number) + ": field '" + field +
                     "': " + what);
  }
};

// The kNumValues finite numbers after an image line's name.
void ParseValues(std::istringstream& parse, const LineError& fail, double values[kNumValues]) {
  for (int k = 0; k < kNumValues; ++k) {
    std::string token;
    if (!(parse >> token)) fail(kFieldNames[k], "missing");
    std::istringstream number(token);
    number.imbue(std::locale::classic());
    if (!(number >> values[k]) || !number.eof() || !std::isfinite(values[k])) {
      fail(kFieldNames[k], "'" + token + "' is not a finite number");
    }
  }
}

// R, orthonormal only to the files' printed digits, replaced by the nearest rotation; throws when
// it is no rotation. *max_deviation grows to its largest |R R^T - I| entry.
Eigen::Matrix3d CheckedRotation(Eigen::Matrix3d R, const LineError& fail, double* max_deviation) {
  // The files print R to about 7 significant digits, so it is orthonormal only to about 1e-6
  // (the shipped dinoR_par.txt and dinoSR_par.txt: 1.6e-6). Within kRotationTolerance it is
  // taken and replaced by the nearest rotation (SVD); beyond, it is not a rotation.
  const double deviation = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(deviation <= kRotationTolerance) || std::abs(R.determinant() - 1.0) > 3.0 * kRotationTolerance) {
    fail("r11..r33", "R is not a rotation matrix (R R^T differs from I by " +
                         std::to_string(deviation) + ", det " + std::to_string(R.determinant()) + ")");
  }
  *max_deviation = std::max(*max_deviation, deviation);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  R = svd.matrixU() * svd.matrixV().transpose();
  return R;
}

// The id of the PINHOLE camera of K at `size` in `reconstruction`, added when new.
camera_t CameraIdOf(const Eigen::Matrix3d& K, const Eigen::Vector2i& size,
                    const MiddleburyImportOptions& options, const std::string& context,
                    Reconstruction* reconstruction) {
  Camera camera;
  camera.model = CameraModelId::kPinhole;
  camera.width = size.x();
  camera.height = size.y();
  camera.params = {K(0, 0),
                   K(1, 1),
                   K(0, 2) + options.principal_point_offset,
                   K(1, 2) + options.principal_point_offset};
  camera_t camera_id = 0;
  for (const auto& [id, existing] : reconstruction->cameras) {
    if (existing.params == camera.params && existing.width == camera.width &&
        existing.height == camera.height) {
      camera_id = id;
    }
  }
  if (camera_id == 0) {
    camera_id = static_cast<camera_t>(reconstruction->cameras.size() + 1);
    camera.camera_id = camera_id;
    ValidateCamera(camera, context);
    reconstruction->cameras.emplace(camera_id, camera);
  }
  return camera_id;
}

}  // namespace

Reconstruction ReadMiddleburyParameters(
    std::istream& stream,
    const std::string& source,
    const std::function<Eigen::Vector2i(const std::string& name)>& image_size,
    const MiddleburyImportOptions& options) {
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  stream.imbue(std::locale::classic());
  std::string line;
  int line_number = 0;
  const LineError fail{source, line_number};
  long long count = -1;
  while (std::getline(stream, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream parse(line);
    parse.imbue(std::locale::classic());
    if (!(parse >> count) || count <= 0) fail("number of images", "must be a positive integer");
    break;
  }
  if (count < 0) throw InputError(source + ": empty file: no number of images on the first line");

  Reconstruction reconstruction;
  std::set<std::string> names;
  image_t next_image_id = 1;
  double max_deviation = 0.0;
  while (std::getline(stream, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (static_cast<long long>(names.size()) == count) {
      fail("name", "more image lines than the count " + std::to_string(count) + " on line 1");
    }
    std::istringstream parse(line);
    parse.imbue(std::locale::classic());
    std::string name;
    parse >> name;
    double values[kNumValues];
    ParseValues(parse, fail, values);
    if (!names.insert(name).second) fail("name", "duplicate image name '" + name + "'");

    Eigen::Matrix3d K, R;
    K << values[0], values[1], values[2], values[3], values[4], values[5], values[6], values[7],
        values[8];
    R << values[9], values[10], values[11], values[12], values[13], values[14], values[15],
        values[16], values[17];
    const Eigen::Vector3d t(values[18], values[19], values[20]);
    if (K(0, 1) != 0.0 || K(1, 0) != 0.0) fail("k12", "non-zero skew cannot be a PINHOLE camera");
    if (K(2, 0) != 0.0 || K(2, 1) != 0.0 || K(2, 2) != 1.0) {
      fail("k31..k33", "the last row of K must be (0 0 1)");
    }
    if (!(K(0, 0) > 0.0) || !(K(1, 1) > 0.0)) fail("k11", "focal lengths must be positive");
    R = CheckedRotation(R, fail, &max_deviation);
    const Eigen::Vector2i size = image_size(name);

    const camera_t camera_id = CameraIdOf(K, size, options,
                                          source + ": line " + std::to_string(line_number),
                                          &reconstruction);

    Image image;
    image.image_id = next_image_id++;
    image.camera_id = camera_id;
    image.name = name;
    image.cam_from_world.rotation = Eigen::Quaterniond(R).normalized();
    image.cam_from_world.translation = t;
    reconstruction.images.emplace(image.image_id, std::move(image));
  }
  if (static_cast<long long>(names.size()) != count) {
    throw InputError(source + ": line 1 announces " + std::to_string(count) +
                     " images but the file holds " + std::to_string(names.size()));
  }
  if (max_deviation > 0.0) {
    LOG(INFO) << source << ": rotations orthonormalised (largest |R R^T - I| entry "
              << max_deviation << ", within the " << kRotationTolerance << " the files' digits allow)";
  }
  return reconstruction;
}

Reconstruction ImportMiddlebury(const std::string& par_path,
                                const std::string& image_path,
                                const MiddleburyImportOptions& options) {
  std::ifstream stream(par_path);
  if (!stream) throw InputError(par_path + ": cannot open the calibration file");
  auto image_size = [&](const std::string& name) {
    const std::string path = (std::filesystem::path(image_path) / name).string();
    if (!std::filesystem::is_regular_file(path)) {
      throw InputError(path + ": photo named in " + par_path + " not found");
    }
    const cv::Mat photo = ReadImage(path, cv::IMREAD_UNCHANGED);
    if (photo.empty()) throw InputError(path + ": cannot be decoded as an image");
    return Eigen::Vector2i(photo.cols, photo.rows);
  };
  return ReadMiddleburyParameters(stream, par_path, image_size, options);
}

}  // namespace raycarve
