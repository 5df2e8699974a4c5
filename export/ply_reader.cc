#include "export/ply_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "calib/input_error.h"

namespace raycarve {
namespace exporter {

namespace {

// The largest coordinate a PLY vertex may have (see ReadPly).
constexpr float kMaxPlyCoordinate = 1e30f;

// An element of a PLY header as parsed, with what its records need at least.
struct Element {
  PlyElement element;
  uint64_t min_bytes = 0;  // binary: one record's fixed part
  uint64_t values = 0;     // properties per record
  bool x = false, y = false, z = false;
};

// The bytes of a PLY property type; throws InputError naming `path` for a type PLY does not have.
uint64_t PlyTypeBytes(const std::string& path, const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
      type == "float32") {
    return 4;
  }
  if (type == "double" || type == "float64") return 8;
  throw InputError(path + ": PLY property type '" + type + "' is not one PLY has");
}

// An "element NAME COUNT" line's rest (`words`), appended to `elements`.
void ParseElementLine(const std::string& path,
                      std::istringstream& words,
                      std::vector<Element>* elements_io) {
  std::vector<Element>& elements = *elements_io;
  Element element;
  std::string count;
  words >> element.element.name >> count;
  if (count.empty() || count.find_first_not_of("0123456789") != std::string::npos ||
      count.size() > 19) {
    throw InputError(path + ": PLY element '" + element.element.name +
                     "' has no valid count ('" + count + "')");
  }
  element.element.count = std::stoull(count);
  // Found by fuzzing: a second vertex element gave vertices without the first's colours.
  for (const Element& earlier : elements) {
    if ((element.element.name == "vertex" || element.element.name == "face") &&
        earlier.element.name == element.element.name) {
      throw InputError(path + ": PLY element '" + element.element.name + "' appears twice");
    }
  }
  elements.push_back(element);
}

// A "property ..." line's rest (`words`), added to the last element.
void ParsePropertyLine(const std::string& path,
                       const std::string& line,
                       std::istringstream& words,
                       std::vector<Element>* elements_io) {
  std::vector<Element>& elements = *elements_io;
  if (elements.empty()) throw InputError(path + ": PLY property before any element");
  Element& element = elements.back();
  std::string type, name;
  words >> type;
  PlyProperty property;
  if (type == "list") {
    std::string count_type, item_type;
    words >> count_type >> item_type >> name;
    if (element.element.name == "vertex") {
      throw InputError(path + ": PLY element 'vertex' has a list property ('" + name +
                       "'), which no reader here takes");
    }
    element.min_bytes += PlyTypeBytes(path, count_type);
    PlyTypeBytes(path, item_type);
    if (count_type == "float" || count_type == "float32" || count_type == "double" ||
        count_type == "float64") {
      throw InputError(path + ": PLY list property '" + name + "' has a count of type '" +
                       count_type + "' (an integer type is needed)");
    }
    property.type = item_type;
    property.count_type = count_type;
  } else {
    words >> name;
    element.min_bytes += PlyTypeBytes(path, type);
    property.type = type;
  }
  if (name.empty()) throw InputError(path + ": PLY property line '" + line + "' has no name");
  property.name = name;
  element.element.properties.push_back(property);
  ++element.values;
  element.x = element.x || name == "x";
  element.y = element.y || name == "y";
  element.z = element.z || name == "z";
}

// The parsed header checked against the file: each element's records fit in the bytes after the
// header, there are vertices with x, y and z, and an obj_info grid fits in them.
PlyHeader CheckedHeader(const std::string& path,
                        const std::string& format,
                        const std::vector<Element>& elements,
                        uint64_t size,
                        size_t header_bytes,
                        uint64_t grid_cols,
                        uint64_t grid_rows) {
  const uint64_t body = size - std::min<uint64_t>(size, header_bytes);
  uint64_t needed = 0, vertices = 0;
  bool has_vertex = false;
  PlyHeader header;
  header.format = format;
  header.header_bytes = header_bytes;
  header.file_bytes = size;
  for (const Element& parsed : elements) {
    const PlyElement& element = parsed.element;
    header.elements.push_back(element);
    const uint64_t per_record = format == "ascii" ? 2 * parsed.values : parsed.min_bytes;
    if (per_record > 0 && element.count > (body - std::min(body, needed)) / per_record) {
      throw InputError(path + ": PLY element '" + element.name + "' announces " +
                       std::to_string(element.count) + " records but the file holds only " +
                       std::to_string(body) + " bytes after its header (wrong count or truncated file)");
    }
    needed += element.count * per_record;
    if (element.name == "vertex") {
      has_vertex = true;
      vertices = element.count;
      if (!(parsed.x && parsed.y && parsed.z)) {
        throw InputError(path + ": PLY element 'vertex' has no x, y and z properties");
      }
    }
  }
  if (!has_vertex) throw InputError(path + ": PLY file has no 'vertex' element");
  if (grid_cols > 0 && grid_rows > 0 &&
      (grid_cols > vertices || grid_rows > vertices || grid_cols * grid_rows > vertices)) {
    throw InputError(path + ": PLY obj_info num_cols x num_rows (" + std::to_string(grid_cols) +
                     " x " + std::to_string(grid_rows) + ") is more than its " +
                     std::to_string(vertices) + " vertices");
  }
  header.vertices = vertices;
  return header;
}

}  // namespace

PlyHeader ParsePlyHeader(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open");
  file.seekg(0, std::ios::end);
  const uint64_t size = static_cast<uint64_t>(file.tellg());
  file.seekg(0);
  constexpr size_t kMaxHeaderBytes = 1 << 16;
  std::string line;
  size_t header_bytes = 0;
  auto next_line = [&]() -> bool {
    if (!std::getline(file, line)) return false;
    header_bytes += line.size() + 1;
    if (header_bytes > kMaxHeaderBytes) {
      throw InputError(path + ": PLY header longer than " + std::to_string(kMaxHeaderBytes) +
                       " bytes (no end_header?)");
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next_line() || line != "ply") throw InputError(path + ": not a PLY file (no 'ply' on line 1)");
  std::vector<Element> elements;
  std::string format;
  uint64_t grid_cols = 0, grid_rows = 0;
  bool ended = false;
  while (next_line()) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") {
      ended = true;
      break;
    }
    if (keyword == "format") {
      words >> format;
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian") {
        throw InputError(path + ": PLY format '" + format + "' is not one PLY has");
      }
    } else if (keyword == "element") {
      ParseElementLine(path, words, &elements);
    } else if (keyword == "property") {
      ParsePropertyLine(path, line, words, &elements);
    } else if (keyword == "obj_info") {
      std::string key;
      uint64_t value = 0;
      words >> key >> value;
      if (key == "num_cols") grid_cols = value;
      if (key == "num_rows") grid_rows = value;
    } else if (keyword != "comment" && !keyword.empty()) {
      // Found by fuzzing: PCL skips an unknown line and files the properties after it under the
      // element before, where a list property trips an assertion.
      throw InputError(path + ": PLY header line '" + line.substr(0, 80) +
                       "' is not one PLY has (format, element, property, comment, obj_info)");
    }
  }
  if (!ended) throw InputError(path + ": PLY header has no end_header");
  if (format.empty()) throw InputError(path + ": PLY header has no format line");
  return CheckedHeader(path, format, elements, size, header_bytes, grid_cols, grid_rows);
}

uint64_t CheckPlyHeader(const std::string& path) { return ParsePlyHeader(path).vertices; }

namespace {

// Where a value goes when the vertex or face element is read.
enum class Slot { kNone, kX, kY, kZ, kNx, kNy, kNz, kRed, kGreen, kBlue, kFaceList };

Slot VertexSlot(const std::string& name) {
  if (name == "x") return Slot::kX;
  if (name == "y") return Slot::kY;
  if (name == "z") return Slot::kZ;
  if (name == "nx" || name == "normal_x") return Slot::kNx;
  if (name == "ny" || name == "normal_y") return Slot::kNy;
  if (name == "nz" || name == "normal_z") return Slot::kNz;
  if (name == "red" || name == "r" || name == "diffuse_red") return Slot::kRed;
  if (name == "green" || name == "g" || name == "diffuse_green") return Slot::kGreen;
  if (name == "blue" || name == "b" || name == "diffuse_blue") return Slot::kBlue;
  return Slot::kNone;
}

int TypeBytes(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "double" || type == "float64") return 8;
  return 4;  // int, uint, float (ParsePlyHeader admits no other)
}

bool IsFloatType(const std::string& type) {
  return type == "float" || type == "float32" || type == "double" || type == "float64";
}

// Names a value in errors: "<element> <record>'s <property>[ count]".
struct ValueName {
  const std::string* element = nullptr;
  uint64_t record = 0;
  const std::string* property = nullptr;
  bool count = false;
  std::string Text() const {
    return *element + " " + std::to_string(record) + "'s " + *property + (count ? " count" : "");
  }
};

// The body's values one at a time, in either encoding.
class PlyBody {
 public:
  PlyBody(const std::string& path, const PlyHeader& header) : path_(path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw InputError(path + ": cannot open");
    // The body is at most the file's size, which exists on disk: no header field sizes it.
    bytes_.resize(header.file_bytes - std::min(header.file_bytes, header.header_bytes));
    file.seekg(static_cast<std::streamoff>(header.header_bytes));
    file.read(bytes_.data(), static_cast<std::streamsize>(bytes_.size()));
    if (file.gcount() != static_cast<std::streamsize>(bytes_.size())) {
      throw InputError(path + ": cannot read the PLY body");
    }
    ascii_ = header.format == "ascii";
    swap_ = header.format == "binary_big_endian";
  }

  // The next value of `type`, as a double; `what` names it in errors.
  double Next(const std::string& type, const ValueName& what) {
    return ascii_ ? NextText(type, what) : NextBinary(type, what);
  }

  uint64_t remaining() const { return bytes_.size() - at_; }

 private:
  double NextText(const std::string& type, const ValueName& what) {
    while (at_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[at_]))) ++at_;
    const size_t start = at_;
    while (at_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[at_]))) ++at_;
    if (start == at_) throw InputError(path_ + ": PLY body ends inside " + what.Text());
    const std::string token(bytes_.data() + start, at_ - start);
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size()) {
      throw InputError(path_ + ": PLY value '" + token.substr(0, 40) + "' of " + what.Text() +
                       " is not a number");
    }
    if (!IsFloatType(type) && value != std::floor(value)) {
      throw InputError(path_ + ": PLY value '" + token.substr(0, 40) + "' of " + what.Text() +
                       " is not an integer (" + type + ")");
    }
    return value;
  }

  double NextBinary(const std::string& type, const ValueName& what) {
    const int size = TypeBytes(type);
    if (bytes_.size() - at_ < static_cast<size_t>(size)) {
      throw InputError(path_ + ": PLY body ends inside " + what.Text() + " (truncated file)");
    }
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + at_, size);  // no unaligned reads
    at_ += size;
    if (swap_) std::reverse(raw, raw + size);
    if (type == "char" || type == "int8") return static_cast<int8_t>(raw[0]);
    if (type == "uchar" || type == "uint8") return raw[0];
    if (type == "short" || type == "int16") return Load<int16_t>(raw);
    if (type == "ushort" || type == "uint16") return Load<uint16_t>(raw);
    if (type == "int" || type == "int32") return Load<int32_t>(raw);
    if (type == "uint" || type == "uint32") return Load<uint32_t>(raw);
    if (type == "float" || type == "float32") return Load<float>(raw);
    return Load<double>(raw);
  }

  template <typename T>
  static T Load(const unsigned char* raw) {
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }

  const std::string& path_;
  std::vector<char> bytes_;
  size_t at_ = 0;
  bool ascii_ = false;
  bool swap_ = false;
};

uint8_t ColourByte(double value, const std::string& type) {
  if (!std::isfinite(value)) return 0;
  const double scaled = IsFloatType(type) ? value * 255.0 : value;
  return static_cast<uint8_t>(std::clamp(std::lround(std::clamp(scaled, -1.0, 256.0)), 0L, 255L));
}

}  // namespace

namespace {

// A list property's count and items; a face's vertex indices (`slot` kFaceList) are checked
// against the `num_vertices` read so far and fanned into `triangles`. `polygon` is a buffer.
void ReadListProperty(const std::string& path,
                      const PlyProperty& property,
                      Slot slot,
                      uint64_t record,
                      size_t num_vertices,
                      ValueName what,
                      PlyBody* body_io,
                      std::vector<int>* polygon_buffer,
                      std::vector<Eigen::Vector3i>* triangles) {
  PlyBody& body = *body_io;
  std::vector<int>& polygon = *polygon_buffer;
  what.count = true;
  const double count = body.Next(property.count_type, what);
  what.count = false;
  // Each item takes at least one byte (binary) or two characters (ASCII).
  if (!(count >= 0.0) || count > static_cast<double>(body.remaining())) {
    throw InputError(path + ": PLY list " + what.Text() + " announces " +
                     std::to_string(count) + " items, more than the file holds");
  }
  polygon.clear();
  for (int64_t k = 0; k < static_cast<int64_t>(count); ++k) {
    const double item = body.Next(property.type, what);
    if (slot != Slot::kFaceList) continue;
    if (!(item >= 0.0) || item >= static_cast<double>(num_vertices)) {
      throw InputError(path + ": face " + std::to_string(record) + " refers to vertex " +
                       std::to_string(static_cast<long long>(item)) + " of " +
                       std::to_string(num_vertices));
    }
    polygon.push_back(static_cast<int>(item));
  }
  for (size_t k = 2; k < polygon.size(); ++k) {
    triangles->emplace_back(polygon[0], polygon[k - 1], polygon[k]);
  }
}

}  // namespace

PlyData ReadPly(const std::string& path) {
  const PlyHeader header = ParsePlyHeader(path);
  PlyBody body(path, header);
  PlyData data;
  for (const PlyElement& element : header.elements) {
    const bool is_vertex = element.name == "vertex";
    const bool is_face = element.name == "face";
    std::vector<Slot> slots;
    bool normals = false, colours = false;
    for (const PlyProperty& property : element.properties) {
      Slot slot = Slot::kNone;
      if (is_vertex && property.count_type.empty()) slot = VertexSlot(property.name);
      if (is_face && !property.count_type.empty() &&
          (property.name == "vertex_indices" || property.name == "vertex_index")) {
        slot = Slot::kFaceList;
      }
      normals = normals || slot == Slot::kNx;
      colours = colours || slot == Slot::kRed;
      slots.push_back(slot);
    }
    if (is_vertex) {
      // ParsePlyHeader has checked the count against the bytes the body holds.
      data.xyz.reserve(element.count);
      if (normals) data.normals.reserve(element.count);
      if (colours) data.rgb.reserve(element.count);
    }
    std::vector<int> polygon;
    for (uint64_t record = 0; record < element.count; ++record) {
      Eigen::Vector3d xyz = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
      Eigen::Matrix<uint8_t, 3, 1> rgb = Eigen::Matrix<uint8_t, 3, 1>::Zero();
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        ValueName what{&element.name, record, &property.name, false};
        if (!property.count_type.empty()) {
          ReadListProperty(path, property, slots[p], record, data.xyz.size(), what, &body,
                           &polygon, &data.triangles);
          continue;
        }
        const double value = body.Next(property.type, what);
        switch (slots[p]) {
          case Slot::kX: xyz.x() = value; break;
          case Slot::kY: xyz.y() = value; break;
          case Slot::kZ: xyz.z() = value; break;
          case Slot::kNx: normal.x() = value; break;
          case Slot::kNy: normal.y() = value; break;
          case Slot::kNz: normal.z() = value; break;
          case Slot::kRed: rgb[0] = ColourByte(value, property.type); break;
          case Slot::kGreen: rgb[1] = ColourByte(value, property.type); break;
          case Slot::kBlue: rgb[2] = ColourByte(value, property.type); break;
          default: break;
        }
      }
      if (!is_vertex) continue;
      const Eigen::Vector3f point = xyz.cast<float>();
      if (!point.allFinite()) {
        throw InputError(path + ": vertex " + std::to_string(record) +
                         " has a non-finite coordinate (NaN or infinity)");
      }
      // Differences of coordinates (extents, distances, k-d tree splits) must stay finite in
      // float: beyond 1e30 no scene is measured, and FLANN's tree recursed without end there.
      if ((point.array().abs() > kMaxPlyCoordinate).any()) {
        throw InputError(path + ": vertex " + std::to_string(record) +
                         " has a coordinate beyond 1e30 (" + std::to_string(point.x()) + ", " +
                         std::to_string(point.y()) + ", " + std::to_string(point.z()) + ")");
      }
      data.xyz.push_back(point);
      if (normals) {
        const Eigen::Vector3f n = normal.cast<float>();
        data.normals.push_back(n.allFinite() ? n : Eigen::Vector3f::Zero());
      }
      if (colours) data.rgb.push_back(rgb);
    }
  }
  // One vertex element (ParsePlyHeader): every vertex has its normal and colour, or none does.
  if (data.normals.size() != data.xyz.size()) data.normals.clear();
  if (data.rgb.size() != data.xyz.size()) data.rgb.clear();
  return data;
}

}  // namespace exporter
}  // namespace raycarve
