#include "calib/model_writer.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <locale>

#include "calib/atomic_file.h"
#include "calib/input_error.h"

namespace raycarve {
namespace {

template <typename T>
void Put(std::ostream& stream, T value) {
  stream.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

void PrepareText(std::ostream& stream) {
  stream.imbue(std::locale::classic());
  stream.precision(17);
}

void WriteAtomically(const std::filesystem::path& path,
                     const std::function<void(std::ostream&)>& write,
                     bool binary) {
  const std::string temporary = TemporaryPathFor(path.string());
  {
    errno = 0;
    std::ofstream stream(temporary, binary ? std::ios::binary : std::ios::out);
    if (!stream) {
      throw InputError(temporary + ": cannot open for writing: " + std::strerror(errno));
    }
    write(stream);
    stream.close();
    if (!stream) ThrowWriteFailure(temporary, "the model file", errno);
  }
  RenameIntoPlace(temporary, path.string());
}

}  // namespace

std::string ModelFormatToString(ModelFormat format) {
  return format == ModelFormat::kBinary ? "BIN" : "TXT";
}

ModelFormat ModelFormatFromString(const std::string& text) {
  if (text == "BIN") return ModelFormat::kBinary;
  if (text == "TXT") return ModelFormat::kText;
  throw InputError("model format '" + text + "' is not one of BIN, TXT");
}

void WriteCamerasBinary(const Reconstruction& reconstruction, std::ostream& stream) {
  Put<uint64_t>(stream, reconstruction.cameras.size());
  for (const auto& [camera_id, camera] : reconstruction.cameras) {
    Put<uint32_t>(stream, camera_id);
    Put<int32_t>(stream, static_cast<int32_t>(camera.model));
    Put<uint64_t>(stream, camera.width);
    Put<uint64_t>(stream, camera.height);
    for (double param : camera.params) Put<double>(stream, param);
  }
}

void WriteImagesBinary(const Reconstruction& reconstruction, std::ostream& stream) {
  Put<uint64_t>(stream, reconstruction.images.size());
  for (const auto& [image_id, image] : reconstruction.images) {
    Put<uint32_t>(stream, image_id);
    const Eigen::Quaterniond& q = image.cam_from_world.rotation;
    for (double value : {q.w(), q.x(), q.y(), q.z()}) Put<double>(stream, value);
    for (int k = 0; k < 3; ++k) Put<double>(stream, image.cam_from_world.translation[k]);
    Put<uint32_t>(stream, image.camera_id);
    stream.write(image.name.c_str(), image.name.size() + 1);
    Put<uint64_t>(stream, image.points2D.size());
    for (const Point2D& point2D : image.points2D) {
      Put<double>(stream, point2D.xy.x());
      Put<double>(stream, point2D.xy.y());
      Put<uint64_t>(stream, point2D.point3D_id);
    }
  }
}

void WritePoints3DBinary(const Reconstruction& reconstruction, std::ostream& stream) {
  Put<uint64_t>(stream, reconstruction.points3D.size());
  for (const auto& [point3D_id, point3D] : reconstruction.points3D) {
    Put<uint64_t>(stream, point3D_id);
    for (int k = 0; k < 3; ++k) Put<double>(stream, point3D.xyz[k]);
    for (int k = 0; k < 3; ++k) Put<uint8_t>(stream, point3D.color[k]);
    Put<double>(stream, point3D.error);
    Put<uint64_t>(stream, point3D.track.size());
    for (const TrackElement& element : point3D.track) {
      Put<uint32_t>(stream, element.image_id);
      Put<uint32_t>(stream, element.point2D_idx);
    }
  }
}

void WriteCamerasText(const Reconstruction& reconstruction, std::ostream& stream) {
  PrepareText(stream);
  stream << "# Camera list with one line of data per camera:\n"
         << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
         << "# Number of cameras: " << reconstruction.cameras.size() << "\n";
  for (const auto& [camera_id, camera] : reconstruction.cameras) {
    stream << camera_id << " " << CameraModelName(camera.model) << " " << camera.width << " "
           << camera.height;
    for (double param : camera.params) stream << " " << param;
    stream << "\n";
  }
}

void WriteImagesText(const Reconstruction& reconstruction, std::ostream& stream) {
  PrepareText(stream);
  stream << "# Image list with two lines of data per image:\n"
         << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
         << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
         << "# Number of images: " << reconstruction.images.size() << "\n";
  for (const auto& [image_id, image] : reconstruction.images) {
    const Eigen::Quaterniond& q = image.cam_from_world.rotation;
    const Eigen::Vector3d& t = image.cam_from_world.translation;
    stream << image_id << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " "
           << t.x() << " " << t.y() << " " << t.z() << " " << image.camera_id << " "
           << image.name << "\n";
    bool first = true;
    for (const Point2D& point2D : image.points2D) {
      if (!first) stream << " ";
      first = false;
      stream << point2D.xy.x() << " " << point2D.xy.y() << " ";
      if (point2D.point3D_id == kInvalidPoint3DId) {
        stream << -1;
      } else {
        stream << point2D.point3D_id;
      }
    }
    stream << "\n";
  }
}

void WritePoints3DText(const Reconstruction& reconstruction, std::ostream& stream) {
  PrepareText(stream);
  stream << "# 3D point list with one line of data per point:\n"
         << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
         << "# Number of points: " << reconstruction.points3D.size() << "\n";
  for (const auto& [point3D_id, point3D] : reconstruction.points3D) {
    stream << point3D_id << " " << point3D.xyz.x() << " " << point3D.xyz.y() << " "
           << point3D.xyz.z() << " " << static_cast<int>(point3D.color[0]) << " "
           << static_cast<int>(point3D.color[1]) << " " << static_cast<int>(point3D.color[2])
           << " " << point3D.error;
    for (const TrackElement& element : point3D.track) {
      stream << " " << element.image_id << " " << element.point2D_idx;
    }
    stream << "\n";
  }
}

void WriteModel(const Reconstruction& reconstruction, const std::string& path, ModelFormat format) {
  std::error_code error;
  std::filesystem::create_directories(path, error);
  if (error) {
    throw InputError(path + ": cannot create the model folder: " + error.message());
  }
  const std::filesystem::path folder(path);
  const bool binary = format == ModelFormat::kBinary;
  const std::string extension = binary ? ".bin" : ".txt";
  using Writer = void (*)(const Reconstruction&, std::ostream&);
  const std::pair<const char*, Writer> files[] = {
      {"cameras", binary ? WriteCamerasBinary : WriteCamerasText},
      {"images", binary ? WriteImagesBinary : WriteImagesText},
      {"points3D", binary ? WritePoints3DBinary : WritePoints3DText},
  };
  for (const auto& [stem, writer] : files) {
    WriteAtomically(
        folder / (std::string(stem) + extension),
        [&, writer = writer](std::ostream& stream) { writer(reconstruction, stream); },
        binary);
  }
}

}  // namespace raycarve
