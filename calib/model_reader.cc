#include "calib/model_reader.h"

#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <vector>

#include <glog/logging.h>

#include "calib/image_reader.h"
#include "calib/input_error.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "raycarve reads COLMAP's little-endian binary files by memcpy");

namespace raycarve {
namespace {

// Reads little-endian values from a COLMAP binary file and names the record and field of any
// truncation in its error.
class BinaryReader {
 public:
  BinaryReader(std::istream& stream, const std::string& source)
      : stream_(stream), source_(source) {}

  void SetRecord(const char* kind, uint64_t index, uint64_t count) {
    kind_ = kind;
    index_ = index;
    count_ = count;
  }

  template <typename T>
  T Read(const char* field) {
    T value;
    stream_.read(reinterpret_cast<char*>(&value), sizeof(T));
    if (stream_.gcount() != static_cast<std::streamsize>(sizeof(T))) {
      Fail(field, "file is truncated");
    }
    return value;
  }

  std::string ReadNullTerminated(const char* field) {
    std::string text;
    char c;
    while (stream_.get(c)) {
      if (c == '\0') return text;
      text.push_back(c);
    }
    Fail(field, "file is truncated (no terminating NUL)");
    return text;
  }

  // Checks that `count` records of at least `min_record_bytes` each fit in what is left of the
  // stream, so that a corrupted count fails at once instead of after a huge allocation.
  void CheckCountFits(uint64_t count, uint64_t min_record_bytes, const char* field) {
    const std::streampos here = stream_.tellg();
    if (here < 0) return;
    stream_.seekg(0, std::ios::end);
    const std::streampos end = stream_.tellg();
    stream_.seekg(here);
    if (end < 0) return;
    const uint64_t remaining = static_cast<uint64_t>(end - here);
    if (min_record_bytes > 0 && count > remaining / min_record_bytes) {
      std::ostringstream message;
      message << "count " << count << " needs at least " << count << " x " << min_record_bytes
              << " bytes but only " << remaining << " remain (wrong count or truncated file)";
      Fail(field, message.str());
    }
  }

  void ExpectEnd() {
    if (stream_.peek() != std::char_traits<char>::eof()) {
      // kind_ is unset when the count is 0 and no record was read.
      throw InputError(source_ + ": trailing data after the " + std::to_string(count_) + " " +
                       (kind_ != nullptr ? std::string(kind_) + " " : std::string()) +
                       "records that the count field announces (wrong count?)");
    }
  }

  [[noreturn]] void Fail(const char* field, const std::string& what) const {
    std::ostringstream message;
    message << source_ << ": ";
    if (kind_ != nullptr) {
      message << kind_ << " record " << index_ + 1 << " of " << count_ << ": ";
    }
    message << "field '" << field << "': " << what;
    throw InputError(message.str());
  }

 private:
  std::istream& stream_;
  const std::string& source_;
  const char* kind_ = nullptr;
  uint64_t index_ = 0;
  uint64_t count_ = 0;
};

// Splits text files into lines and whitespace-separated tokens, and parses tokens strictly in
// the "C" locale, naming the line and field in errors.
class TextReader {
 public:
  TextReader(std::istream& stream, const std::string& source)
      : stream_(stream), source_(source) {}

  // Next line that is neither empty nor a comment; false at the end of the stream.
  bool NextDataLine() {
    while (NextLine()) {
      const size_t first = line_.find_first_not_of(" \t\r");
      if (first != std::string::npos && line_[first] != '#') return true;
    }
    return false;
  }

  // Next line as it is (it may be empty); false at the end of the stream.
  bool NextLine() {
    if (!std::getline(stream_, line_)) return false;
    ++line_number_;
    if (!line_.empty() && line_.back() == '\r') line_.pop_back();
    Tokenize();
    return true;
  }

  const std::vector<std::string>& tokens() const { return tokens_; }
  const std::string& line() const { return line_; }

  template <typename T>
  T Parse(size_t index, const char* field) const {
    if (index >= tokens_.size()) Fail(field, "missing");
    const std::string& token = tokens_[index];
    T value{};
    const char* begin = token.data();
    const char* end = begin + token.size();
    // For doubles "nan" and "inf" parse; ValidateReconstruction rejects them with the record.
    const auto result = std::from_chars(begin, end, value);
    if (result.ec != std::errc() || result.ptr != end) {
      Fail(field, "'" + token + (std::is_floating_point_v<T>
                                     ? "' is not a number"
                                     : "' is not a valid integer of this field's range"));
    }
    return value;
  }

  [[noreturn]] void Fail(const std::string& field, const std::string& what) const {
    throw InputError(source_ + ": line " + std::to_string(line_number_) + ": field '" + field +
                     "': " + what);
  }

 private:
  void Tokenize() {
    tokens_.clear();
    size_t position = 0;
    while (true) {
      const size_t begin = line_.find_first_not_of(" \t", position);
      if (begin == std::string::npos) break;
      const size_t end = line_.find_first_of(" \t", begin);
      tokens_.push_back(line_.substr(begin, end - begin));
      if (end == std::string::npos) break;
      position = end;
    }
  }

  std::istream& stream_;
  const std::string& source_;
  std::string line_;
  std::vector<std::string> tokens_;
  int line_number_ = 0;
};

template <typename Map, typename Key>
void CheckUnique(const Map& map, Key id, const std::string& source, const char* kind) {
  if (map.count(id) != 0) {
    throw InputError(source + ": duplicate " + kind + " id " + std::to_string(id));
  }
}

// Parses a signed point3D id from text, where -1 means "none".
point3D_t ParsePoint3DId(const TextReader& reader, size_t index) {
  if (index < reader.tokens().size() && reader.tokens()[index] == "-1") {
    return kInvalidPoint3DId;
  }
  return reader.Parse<point3D_t>(index, "POINT3D_ID");
}

std::filesystem::path PickFile(const std::filesystem::path& folder, const std::string& stem) {
  const std::filesystem::path binary = folder / (stem + ".bin");
  if (std::filesystem::exists(binary)) return binary;
  const std::filesystem::path text = folder / (stem + ".txt");
  if (std::filesystem::exists(text)) return text;
  throw InputError(folder.string() + ": not a COLMAP model folder: neither " + stem +
                   ".bin nor " + stem + ".txt exists");
}

void ReadFile(const std::filesystem::path& path,
              const std::function<void(std::istream&, const std::string&, Reconstruction*)>&
                  binary_reader,
              const std::function<void(std::istream&, const std::string&, Reconstruction*)>&
                  text_reader,
              Reconstruction* reconstruction) {
  const bool binary = path.extension() == ".bin";
  const std::string why = WhyNotAFile(path.string());
  if (!why.empty()) throw InputError(path.string() + ": " + why);
  std::ifstream stream(path, binary ? std::ios::binary : std::ios::in);
  if (!stream) {
    throw InputError(path.string() + ": cannot open for reading: " + std::strerror(errno));
  }
  (binary ? binary_reader : text_reader)(stream, path.string(), reconstruction);
}

}  // namespace

void ReadCamerasBinary(std::istream& stream, const std::string& source, Reconstruction* reconstruction) {
  BinaryReader reader(stream, source);
  const uint64_t count = reader.Read<uint64_t>("num_cameras");
  // camera_id, model_id, width, height and at least 3 parameters.
  reader.CheckCountFits(count, 4 + 4 + 8 + 8 + 3 * 8, "num_cameras");
  for (uint64_t i = 0; i < count; ++i) {
    reader.SetRecord("camera", i, count);
    Camera camera;
    camera.camera_id = reader.Read<uint32_t>("camera_id");
    const int32_t model_id = reader.Read<int32_t>("model_id");
    camera.model = CameraModelIdFromInt(
        model_id, source + ": camera " + std::to_string(camera.camera_id) + ": field 'model_id'");
    camera.width = reader.Read<uint64_t>("width");
    camera.height = reader.Read<uint64_t>("height");
    camera.params.resize(CameraModelNumParams(camera.model));
    for (double& param : camera.params) param = reader.Read<double>("params");
    CheckUnique(reconstruction->cameras, camera.camera_id, source, "camera");
    reconstruction->cameras.emplace(camera.camera_id, std::move(camera));
  }
  reader.ExpectEnd();
}

void ReadImagesBinary(std::istream& stream, const std::string& source, Reconstruction* reconstruction) {
  BinaryReader reader(stream, source);
  const uint64_t count = reader.Read<uint64_t>("num_reg_images");
  // id, 7 doubles, camera id, a NUL, the points2D count.
  reader.CheckCountFits(count, 4 + 7 * 8 + 4 + 1 + 8, "num_reg_images");
  for (uint64_t i = 0; i < count; ++i) {
    reader.SetRecord("image", i, count);
    Image image;
    image.image_id = reader.Read<uint32_t>("image_id");
    const double qw = reader.Read<double>("qvec");
    const double qx = reader.Read<double>("qvec");
    const double qy = reader.Read<double>("qvec");
    const double qz = reader.Read<double>("qvec");
    image.cam_from_world.rotation = Eigen::Quaterniond(qw, qx, qy, qz);
    for (int k = 0; k < 3; ++k) image.cam_from_world.translation[k] = reader.Read<double>("tvec");
    image.camera_id = reader.Read<uint32_t>("camera_id");
    image.name = reader.ReadNullTerminated("name");
    const uint64_t num_points2D = reader.Read<uint64_t>("num_points2D");
    reader.CheckCountFits(num_points2D, 8 + 8 + 8, "num_points2D");
    image.points2D.resize(num_points2D);
    for (Point2D& point2D : image.points2D) {
      point2D.xy.x() = reader.Read<double>("points2D.x");
      point2D.xy.y() = reader.Read<double>("points2D.y");
      point2D.point3D_id = reader.Read<uint64_t>("points2D.point3D_id");
    }
    CheckUnique(reconstruction->images, image.image_id, source, "image");
    reconstruction->images.emplace(image.image_id, std::move(image));
  }
  reader.ExpectEnd();
}

void ReadPoints3DBinary(std::istream& stream, const std::string& source, Reconstruction* reconstruction) {
  BinaryReader reader(stream, source);
  const uint64_t count = reader.Read<uint64_t>("num_points3D");
  reader.CheckCountFits(count, 8 + 3 * 8 + 3 + 8 + 8, "num_points3D");
  for (uint64_t i = 0; i < count; ++i) {
    reader.SetRecord("point3D", i, count);
    const point3D_t point3D_id = reader.Read<uint64_t>("point3D_id");
    Point3D point3D;
    for (int k = 0; k < 3; ++k) point3D.xyz[k] = reader.Read<double>("xyz");
    for (int k = 0; k < 3; ++k) point3D.color[k] = reader.Read<uint8_t>("rgb");
    point3D.error = reader.Read<double>("error");
    const uint64_t track_length = reader.Read<uint64_t>("track_length");
    reader.CheckCountFits(track_length, 4 + 4, "track_length");
    point3D.track.resize(track_length);
    for (TrackElement& element : point3D.track) {
      element.image_id = reader.Read<uint32_t>("track.image_id");
      element.point2D_idx = reader.Read<uint32_t>("track.point2D_idx");
    }
    CheckUnique(reconstruction->points3D, point3D_id, source, "point3D");
    reconstruction->points3D.emplace(point3D_id, std::move(point3D));
  }
  reader.ExpectEnd();
}

void ReadCamerasText(std::istream& stream, const std::string& source, Reconstruction* reconstruction) {
  TextReader reader(stream, source);
  while (reader.NextDataLine()) {
    Camera camera;
    camera.camera_id = reader.Parse<camera_t>(0, "CAMERA_ID");
    if (reader.tokens().size() < 2) reader.Fail("MODEL", "missing");
    camera.model = CameraModelIdFromName(
        reader.tokens()[1], source + ": camera " + std::to_string(camera.camera_id) + ": field 'MODEL'");
    camera.width = reader.Parse<uint64_t>(2, "WIDTH");
    camera.height = reader.Parse<uint64_t>(3, "HEIGHT");
    const size_t num_params = reader.tokens().size() - std::min<size_t>(4, reader.tokens().size());
    if (static_cast<int>(num_params) != CameraModelNumParams(camera.model)) {
      reader.Fail("PARAMS", CameraModelName(camera.model) + " needs " +
                                std::to_string(CameraModelNumParams(camera.model)) + " (" +
                                CameraModelParamsInfo(camera.model) + "), found " +
                                std::to_string(num_params));
    }
    for (size_t k = 0; k < num_params; ++k) {
      camera.params.push_back(reader.Parse<double>(4 + k, "PARAMS"));
    }
    CheckUnique(reconstruction->cameras, camera.camera_id, source, "camera");
    reconstruction->cameras.emplace(camera.camera_id, std::move(camera));
  }
}

void ReadImagesText(std::istream& stream, const std::string& source, Reconstruction* reconstruction) {
  TextReader reader(stream, source);
  while (reader.NextDataLine()) {
    Image image;
    image.image_id = reader.Parse<image_t>(0, "IMAGE_ID");
    const double qw = reader.Parse<double>(1, "QW");
    const double qx = reader.Parse<double>(2, "QX");
    const double qy = reader.Parse<double>(3, "QY");
    const double qz = reader.Parse<double>(4, "QZ");
    image.cam_from_world.rotation = Eigen::Quaterniond(qw, qx, qy, qz);
    image.cam_from_world.translation = Eigen::Vector3d(
        reader.Parse<double>(5, "TX"), reader.Parse<double>(6, "TY"), reader.Parse<double>(7, "TZ"));
    image.camera_id = reader.Parse<camera_t>(8, "CAMERA_ID");
    if (reader.tokens().size() < 10) reader.Fail("NAME", "missing");
    // The name is the rest of the line, so that names with spaces survive.
    const std::string& line = reader.line();
    size_t position = 0;
    for (int field = 0; field < 9; ++field) {
      position = line.find_first_not_of(" \t", position);
      position = line.find_first_of(" \t", position);
    }
    image.name = line.substr(line.find_first_not_of(" \t", position));
    image.name.erase(image.name.find_last_not_of(" \t") + 1);

    if (!reader.NextLine()) {
      reader.Fail("POINTS2D", "missing the second line of image " +
                                  std::to_string(image.image_id));
    }
    const size_t num_tokens = reader.tokens().size();
    if (num_tokens % 3 != 0) {
      reader.Fail("POINTS2D", "expected (X, Y, POINT3D_ID) triples, found " +
                                  std::to_string(num_tokens) + " values");
    }
    image.points2D.resize(num_tokens / 3);
    for (size_t k = 0; k < image.points2D.size(); ++k) {
      image.points2D[k].xy = Eigen::Vector2d(reader.Parse<double>(3 * k, "POINTS2D.X"),
                                             reader.Parse<double>(3 * k + 1, "POINTS2D.Y"));
      image.points2D[k].point3D_id = ParsePoint3DId(reader, 3 * k + 2);
    }
    CheckUnique(reconstruction->images, image.image_id, source, "image");
    reconstruction->images.emplace(image.image_id, std::move(image));
  }
}

void ReadPoints3DText(std::istream& stream, const std::string& source, Reconstruction* reconstruction) {
  TextReader reader(stream, source);
  while (reader.NextDataLine()) {
    const point3D_t point3D_id = reader.Parse<point3D_t>(0, "POINT3D_ID");
    Point3D point3D;
    point3D.xyz = Eigen::Vector3d(
        reader.Parse<double>(1, "X"), reader.Parse<double>(2, "Y"), reader.Parse<double>(3, "Z"));
    const char* const colour_fields[] = {"R", "G", "B"};
    for (int k = 0; k < 3; ++k) {
      point3D.color[k] = reader.Parse<uint8_t>(4 + k, colour_fields[k]);
    }
    point3D.error = reader.Parse<double>(7, "ERROR");
    const size_t num_track_tokens = reader.tokens().size() - 8;
    if (num_track_tokens % 2 != 0) {
      reader.Fail("TRACK", "expected (IMAGE_ID, POINT2D_IDX) pairs, found " +
                               std::to_string(num_track_tokens) + " values");
    }
    point3D.track.resize(num_track_tokens / 2);
    for (size_t k = 0; k < point3D.track.size(); ++k) {
      point3D.track[k].image_id = reader.Parse<image_t>(8 + 2 * k, "TRACK.IMAGE_ID");
      point3D.track[k].point2D_idx = reader.Parse<point2D_t>(9 + 2 * k, "TRACK.POINT2D_IDX");
    }
    CheckUnique(reconstruction->points3D, point3D_id, source, "point3D");
    reconstruction->points3D.emplace(point3D_id, std::move(point3D));
  }
}

Reconstruction ReadModel(const std::string& path) {
  const std::filesystem::path folder(path);
  if (!std::filesystem::is_directory(folder)) {
    throw InputError(path + ": model folder does not exist or is not a folder");
  }
  Reconstruction reconstruction;
  ReadFile(PickFile(folder, "cameras"), ReadCamerasBinary, ReadCamerasText, &reconstruction);
  ReadFile(PickFile(folder, "images"), ReadImagesBinary, ReadImagesText, &reconstruction);
  ReadFile(PickFile(folder, "points3D"), ReadPoints3DBinary, ReadPoints3DText, &reconstruction);
  ValidateReconstruction(reconstruction, path);
  VLOG(1) << path << ": " << reconstruction.cameras.size() << " cameras, "
          << reconstruction.images.size() << " images, " << reconstruction.points3D.size()
          << " points";
  return reconstruction;
}

}  // namespace raycarve
