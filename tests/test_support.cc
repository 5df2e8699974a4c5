#include "tests/test_support.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace raycarve {
namespace testing {

namespace {

// The folders MakeTemporaryDirectory made, removed when the test program exits (kept when
// RAYCARVE_KEEP_TEST_FILES is set, to look at a failure's files).
class TemporaryDirectories {
 public:
  ~TemporaryDirectories() {
    const char* keep = std::getenv("RAYCARVE_KEEP_TEST_FILES");
    if (keep != nullptr && *keep != '\0') return;
    for (const std::filesystem::path& path : paths_) {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  }
  void Add(const std::filesystem::path& path) { paths_.push_back(path); }

 private:
  std::vector<std::filesystem::path> paths_;
};

TemporaryDirectories& MadeDirectories() {
  static TemporaryDirectories directories;
  return directories;
}

}  // namespace

std::string MakeTemporaryDirectory(const std::string& name) {
  std::random_device device;
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("raycarve_test_" + name + "_" + std::to_string(getpid()) + "_" + std::to_string(device()));
  std::filesystem::remove_all(path);
  std::filesystem::create_directories(path);
  MadeDirectories().Add(path);
  return path.string();
}

std::string DataDirectory() {
  if (const char* env = std::getenv("RAYCARVE_DATA_DIR"); env != nullptr && *env != '\0') {
    return std::filesystem::exists(env) ? std::string(env) : std::string();
  }
  if (const char* source = std::getenv("RAYCARVE_SOURCE_DIR"); source != nullptr) {
    const std::filesystem::path path = std::filesystem::path(source) / ".." / "shared" / "data";
    if (std::filesystem::exists(path)) return std::filesystem::canonical(path).string();
  }
  return "";
}

int RunShell(const std::string& command, std::string* output) {
  output->clear();
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  std::array<char, 4096> buffer;
  size_t count;
  while ((count = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    output->append(buffer.data(), count);
  }
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string RaycarveBinary() {
  const char* binary = std::getenv("RAYCARVE_BINARY");
  return binary == nullptr ? std::string() : std::string(binary);
}

int RunRaycarve(const std::string& arguments, std::string* output) {
  return RunShell("'" + RaycarveBinary() + "' " + arguments, output);
}

void ExpectUserError(const std::string& arguments, std::initializer_list<std::string> parts) {
  std::string output;
  const int status = RunRaycarve(arguments, &output);
  EXPECT_EQ(status, 1) << arguments << "\n" << output;
  EXPECT_NE(output.find("error: "), std::string::npos) << output;
  for (const std::string& part : parts) {
    EXPECT_NE(output.find(part), std::string::npos) << "'" << part << "' not in:\n" << output;
  }
  for (const char* crash :
       {"Check failed", "Aborted", "Segmentation", "terminate", "AddressSanitizer", "unexpected error"}) {
    EXPECT_EQ(output.find(crash), std::string::npos) << output;
  }
}

double JsonNumber(const std::string& json, const std::string& key) {
  const size_t at = json.find("\"" + key + "\":");
  EXPECT_NE(at, std::string::npos) << key;
  return at == std::string::npos ? NAN : std::stod(json.substr(at + key.size() + 3));
}

std::string ReportBoxText(const std::string& report) {
  const size_t bounds = report.find("\"bounds\":");
  EXPECT_NE(bounds, std::string::npos);
  if (bounds == std::string::npos) return "";
  std::string text;
  for (const std::string key : {"\"min\": [", "\"max\": ["}) {
    const size_t open = report.find(key, bounds);
    const size_t close = report.find(']', open);
    EXPECT_NE(open, std::string::npos) << key;
    if (open == std::string::npos || close == std::string::npos) return "";
    std::string values = report.substr(open + key.size(), close - open - key.size());
    values.erase(std::remove(values.begin(), values.end(), ' '), values.end());
    text += (text.empty() ? "" : ",") + values;
  }
  return text;
}

std::map<std::string, std::string> FolderSnapshot(const std::string& folder) {
  std::map<std::string, std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    if (entry.is_regular_file()) files[entry.path().string()] = ReadFileBytes(entry.path());
  }
  return files;
}

bool ColmapAvailable() {
  std::string output;
  return RunShell("command -v colmap", &output) == 0;
}

void WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream stream(path, std::ios::binary);
  stream << bytes;
  if (!stream) {
    ADD_FAILURE() << "cannot write " << path;
  }
}

std::string ReadFileBytes(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << stream.rdbuf();
  return bytes.str();
}

}  // namespace testing
}  // namespace raycarve

namespace raycarve {
namespace testing {

Reconstruction RandomReconstruction(uint64_t seed, int num_images, int num_points3D) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Reconstruction reconstruction;
  for (CameraModelId model : SupportedCameraModels()) {
    Camera camera;
    camera.camera_id = static_cast<camera_t>(static_cast<int>(model) + 1);
    camera.model = model;
    camera.width = 640 + static_cast<int>(model);
    camera.height = 480;
    for (int k = 0; k < CameraModelNumParams(model); ++k) {
      camera.params.push_back(k < 2 ? 500.0 + 10 * uniform(random) : uniform(random) * 0.1 + (k < 4 ? 300.0 : 0.0));
    }
    reconstruction.cameras.emplace(camera.camera_id, camera);
  }
  for (int i = 0; i < num_images; ++i) {
    Image image;
    image.image_id = static_cast<image_t>(3 * i + 2);
    image.camera_id = static_cast<camera_t>(1 + i % reconstruction.cameras.size());
    image.name = "folder/photo " + std::to_string(i) + ".png";
    image.cam_from_world.rotation =
        Eigen::Quaterniond(uniform(random), uniform(random), uniform(random), uniform(random))
            .normalized();
    image.cam_from_world.translation =
        Eigen::Vector3d(uniform(random), uniform(random), uniform(random)) * 3.0;
    const int num_points2D = 3 + static_cast<int>(5 * (uniform(random) + 1));
    for (int k = 0; k < num_points2D; ++k) {
      Point2D point2D;
      point2D.xy = Eigen::Vector2d(320 + 300 * uniform(random), 240 + 200 * uniform(random));
      image.points2D.push_back(point2D);
    }
    reconstruction.images.emplace(image.image_id, image);
  }
  point3D_t next_id = 7;
  for (int p = 0; p < num_points3D; ++p) {
    Point3D point3D;
    point3D.xyz = Eigen::Vector3d(uniform(random), uniform(random), uniform(random)) * 5.0;
    point3D.color << static_cast<uint8_t>(random() % 256), static_cast<uint8_t>(random() % 256),
        static_cast<uint8_t>(random() % 256);
    point3D.error = 0.5 * (uniform(random) + 1.0);
    // Attach to free points2D of two or three images.
    for (auto& [image_id, image] : reconstruction.images) {
      if (point3D.track.size() >= 3 || random() % 2 == 0) continue;
      for (point2D_t k = 0; k < image.points2D.size(); ++k) {
        if (image.points2D[k].point3D_id == kInvalidPoint3DId) {
          image.points2D[k].point3D_id = next_id;
          point3D.track.push_back({image_id, k});
          break;
        }
      }
    }
    reconstruction.points3D.emplace(next_id, point3D);
    next_id += 2;
  }
  return reconstruction;
}

void ExpectSameReconstruction(const Reconstruction& a,
                              const Reconstruction& b,
                              double rotation_tolerance) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  ASSERT_EQ(a.images.size(), b.images.size());
  ASSERT_EQ(a.points3D.size(), b.points3D.size());
  for (const auto& [id, camera] : a.cameras) {
    ASSERT_EQ(b.cameras.count(id), 1u) << "camera " << id;
    const Camera& other = b.cameras.at(id);
    EXPECT_EQ(camera.model, other.model) << "camera " << id;
    EXPECT_EQ(camera.width, other.width) << "camera " << id;
    EXPECT_EQ(camera.height, other.height) << "camera " << id;
    EXPECT_EQ(camera.params, other.params) << "camera " << id;
  }
  for (const auto& [id, image] : a.images) {
    ASSERT_EQ(b.images.count(id), 1u) << "image " << id;
    const Image& other = b.images.at(id);
    EXPECT_EQ(image.name, other.name);
    EXPECT_EQ(image.camera_id, other.camera_id) << "image " << id;
    if (rotation_tolerance == 0.0) {
      EXPECT_EQ(image.cam_from_world.rotation.coeffs(), other.cam_from_world.rotation.coeffs())
          << "image " << id;
    } else {
      EXPECT_LE((image.cam_from_world.rotation.coeffs() - other.cam_from_world.rotation.coeffs())
                    .cwiseAbs()
                    .maxCoeff(),
                rotation_tolerance)
          << "image " << id;
    }
    EXPECT_EQ(image.cam_from_world.translation, other.cam_from_world.translation) << "image " << id;
    ASSERT_EQ(image.points2D.size(), other.points2D.size()) << "image " << id;
    for (size_t k = 0; k < image.points2D.size(); ++k) {
      EXPECT_EQ(image.points2D[k].xy, other.points2D[k].xy) << "image " << id << " point " << k;
      EXPECT_EQ(image.points2D[k].point3D_id, other.points2D[k].point3D_id);
    }
  }
  for (const auto& [id, point3D] : a.points3D) {
    ASSERT_EQ(b.points3D.count(id), 1u) << "point3D " << id;
    const Point3D& other = b.points3D.at(id);
    EXPECT_EQ(point3D.xyz, other.xyz) << "point3D " << id;
    EXPECT_EQ(point3D.color, other.color) << "point3D " << id;
    EXPECT_EQ(point3D.error, other.error) << "point3D " << id;
    ASSERT_EQ(point3D.track.size(), other.track.size()) << "point3D " << id;
    for (size_t k = 0; k < point3D.track.size(); ++k) {
      EXPECT_EQ(point3D.track[k].image_id, other.track[k].image_id);
      EXPECT_EQ(point3D.track[k].point2D_idx, other.track[k].point2D_idx);
    }
  }
}

}  // namespace testing
}  // namespace raycarve

namespace raycarve {
namespace testing {

Eigen::AlignedBox3d ReadMiddleburyReadmeBox(const std::string& readme_path) {
  const std::string text = ReadFileBytes(readme_path);
  const size_t at = text.find("bounding box");
  EXPECT_NE(at, std::string::npos) << readme_path;
  std::vector<double> values;
  size_t position = at;
  while (values.size() < 6) {
    position = text.find_first_of("-0123456789", position);
    if (position == std::string::npos) break;
    size_t used = 0;
    values.push_back(std::stod(text.substr(position), &used));
    position += used;
  }
  EXPECT_EQ(values.size(), 6u) << readme_path;
  values.resize(6, 0.0);
  return Eigen::AlignedBox3d(Eigen::Vector3d(values[0], values[1], values[2]),
                             Eigen::Vector3d(values[3], values[4], values[5]));
}

}  // namespace testing
}  // namespace raycarve

namespace raycarve {
namespace testing {

CalibratedView PinholeViewLookingAtOrigin(const Eigen::Vector3d& centre, int width, int height,
                                          double focal) {
  CalibratedView view;
  view.width = width;
  view.height = height;
  view.K << focal, 0, 0.5 * width, 0, focal, 0.5 * height, 0, 0, 1;
  const Eigen::Vector3d forward = -centre.normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d(0.3, 1, 0.1)).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d rotation;
  rotation << right.transpose(), down.transpose(), forward.transpose();
  view.cam_from_world.rotation = Eigen::Quaterniond(rotation);
  view.cam_from_world.translation = -rotation * centre;
  view.centre = centre;
  view.P = view.K * view.cam_from_world.ToMatrix();
  view.valid = cv::Mat(height, width, CV_8UC1, cv::Scalar(255));
  return view;
}

Camera MakeCamera(camera_t id, CameraModelId model, int width, int height,
                  std::vector<double> params) {
  Camera camera;
  camera.camera_id = id;
  camera.model = model;
  camera.width = width;
  camera.height = height;
  camera.params = std::move(params);
  return camera;
}

CalibratedView PinholeViewAtOrigin(int width, int height, double focal) {
  CalibratedView view;
  view.width = width;
  view.height = height;
  view.K << focal, 0, 0.5 * width, 0, focal, 0.5 * height, 0, 0, 1;
  view.P = view.K * view.cam_from_world.ToMatrix();
  view.valid = cv::Mat(height, width, CV_8UC1, cv::Scalar(255));
  return view;
}

Eigen::Vector3d CellColour(int a, int b, int salt) {
  uint32_t hash = static_cast<uint32_t>(a * 73856093) ^ static_cast<uint32_t>(b * 19349663) ^
                  static_cast<uint32_t>(salt * 83492791);
  hash = (hash ^ (hash >> 13)) * 0x5bd1e995u;
  hash ^= hash >> 15;
  return Eigen::Vector3d(40 + (hash & 0xbf), 40 + ((hash >> 8) & 0xbf), 40 + ((hash >> 16) & 0xbf));
}

cv::Mat TraceViewImage(
    CalibratedView* view,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&, const Eigen::Vector3d&, bool*)>& trace) {
  view->image = cv::Mat(view->height, view->width, CV_8UC3);
  cv::Mat flagged(view->height, view->width, CV_8UC1, cv::Scalar(0));
  const Eigen::Matrix3d world_from_pixel = view->WorldFromPixel();
  for (int row = 0; row < view->height; ++row) {
    for (int col = 0; col < view->width; ++col) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      bool flag = false;
      for (int s = 0; s < 9; ++s) {
        const Eigen::Vector2d at(col + (s % 3 + 0.5) / 3.0, row + (s / 3 + 0.5) / 3.0);
        sum += trace(view->centre, (world_from_pixel * at.homogeneous()).normalized(), &flag);
      }
      view->image.at<cv::Vec3b>(row, col) =
          cv::Vec3b(static_cast<uint8_t>(sum.x() / 9), static_cast<uint8_t>(sum.y() / 9),
                    static_cast<uint8_t>(sum.z() / 9));
      const Eigen::Vector2d centre(col + 0.5, row + 0.5);
      trace(view->centre, (world_from_pixel * centre.homogeneous()).normalized(), &flag);
      flagged.at<uint8_t>(row, col) = flag ? 255 : 0;
    }
  }
  return flagged;
}

}  // namespace testing
}  // namespace raycarve
