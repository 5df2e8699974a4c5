#include "export/point_cloud_io.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <filesystem>

#include <pcl/console/print.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include "calib/atomic_file.h"
#include "calib/input_error.h"

namespace raycarve {
namespace exporter {
namespace {

// COLMAP's fused.ply vertex: x y z nx ny nz red green blue, in that order. PCL's PLY writer names
// normal_x "nx" and splits the packed rgb into red, green and blue.
struct EIGEN_ALIGN16 FusedPoint {
  PCL_ADD_POINT4D;
  float normal_x;
  float normal_y;
  float normal_z;
  PCL_ADD_RGB;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

}  // namespace
}  // namespace exporter
}  // namespace raycarve

POINT_CLOUD_REGISTER_POINT_STRUCT(raycarve::exporter::FusedPoint,
                                  (float, x, x)(float, y, y)(float, z, z)
                                  (float, normal_x, normal_x)(float, normal_y, normal_y)
                                  (float, normal_z, normal_z)(float, rgb, rgb))

namespace raycarve {
namespace exporter {

void WritePointCloudPly(const std::vector<ColouredPoint>& points, const std::string& path) {
  pcl::PointCloud<FusedPoint> cloud;
  cloud.reserve(points.size());
  for (const ColouredPoint& point : points) {
    FusedPoint p;
    p.x = point.xyz.x();
    p.y = point.xyz.y();
    p.z = point.xyz.z();
    p.normal_x = point.normal.x();
    p.normal_y = point.normal.y();
    p.normal_z = point.normal.z();
    p.r = point.rgb[0];
    p.g = point.rgb[1];
    p.b = point.rgb[2];
    p.a = 255;
    cloud.push_back(p);
  }
  cloud.width = static_cast<uint32_t>(cloud.size());
  cloud.height = 1;
  const std::string temporary = TemporaryPathFor(path);
  if (cloud.empty()) {
    // PCL refuses to write an empty cloud; an empty carve still gets a valid PLY, with the same
    // properties, that every reader opens.
    std::ofstream file(temporary, std::ios::binary);
    file << "ply\nformat binary_little_endian 1.0\ncomment raycarve: no points\nelement vertex 0\n"
            "property float x\nproperty float y\nproperty float z\nproperty float nx\n"
            "property float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n"
            "property uchar blue\nend_header\n";
    if (!file) throw InputError(temporary + ": cannot write the point cloud");
    file.close();
    RenameIntoPlace(temporary, path);
    return;
  }
  pcl::PLYWriter writer;
  if (writer.write(temporary, cloud, /*binary=*/true, /*use_camera=*/false) != 0) {
    throw InputError(temporary + ": PCL could not write the point cloud");
  }
  RenameIntoPlace(temporary, path);
}

uint64_t CheckPlyHeader(const std::string& path) {
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
  struct Element {
    std::string name;
    uint64_t count = 0;
    uint64_t min_bytes = 0;  // binary: one record's fixed part
    uint64_t values = 0;     // properties per record
    bool x = false, y = false, z = false;
  };
  std::vector<Element> elements;
  std::string format;
  uint64_t grid_cols = 0, grid_rows = 0;
  bool ended = false;
  auto type_bytes = [&](const std::string& type) -> uint64_t {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
        type == "float32") {
      return 4;
    }
    if (type == "double" || type == "float64") return 8;
    throw InputError(path + ": PLY property type '" + type + "' is not one PLY has");
  };
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
      Element element;
      std::string count;
      words >> element.name >> count;
      if (count.empty() || count.find_first_not_of("0123456789") != std::string::npos ||
          count.size() > 19) {
        throw InputError(path + ": PLY element '" + element.name + "' has no valid count ('" +
                         count + "')");
      }
      element.count = std::stoull(count);
      elements.push_back(element);
    } else if (keyword == "property") {
      if (elements.empty()) throw InputError(path + ": PLY property before any element");
      Element& element = elements.back();
      std::string type, name;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> name;
        if (element.name == "vertex") {
          throw InputError(path + ": PLY element 'vertex' has a list property ('" + name +
                           "'), which no reader here takes");
        }
        element.min_bytes += type_bytes(count_type);
        type_bytes(item_type);
      } else {
        words >> name;
        element.min_bytes += type_bytes(type);
      }
      ++element.values;
      element.x = element.x || name == "x";
      element.y = element.y || name == "y";
      element.z = element.z || name == "z";
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
  const uint64_t body = size - std::min<uint64_t>(size, header_bytes);
  uint64_t needed = 0, vertices = 0;
  bool has_vertex = false;
  for (const Element& element : elements) {
    const uint64_t per_record = format == "ascii" ? 2 * element.values : element.min_bytes;
    if (per_record > 0 && element.count > (body - std::min(body, needed)) / per_record) {
      throw InputError(path + ": PLY element '" + element.name + "' announces " +
                       std::to_string(element.count) + " records but the file holds only " +
                       std::to_string(body) + " bytes after its header (wrong count or truncated file)");
    }
    needed += element.count * per_record;
    if (element.name == "vertex") {
      has_vertex = true;
      vertices = element.count;
      if (!(element.x && element.y && element.z)) {
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
  return vertices;
}

std::vector<ColouredPoint> ReadPointCloudPly(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(path + ": point cloud file not found");
  }
  if (CheckPlyHeader(path) == 0) return {};
  // (A PLY with no vertices, an empty carve, is valid; PCL's reader would index its empty
  // buffer, so it is answered from the header.)
  pcl::PointCloud<pcl::PointXYZRGBNormal> cloud;
  pcl::PLYReader reader;
  // Fields a file lacks (curvature, normals, colours) are expected; only errors are worth saying.
  const pcl::console::VERBOSITY_LEVEL verbosity = pcl::console::getVerbosityLevel();
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  const int status = reader.read(path, cloud);
  pcl::console::setVerbosityLevel(verbosity);
  if (status != 0) {
    throw InputError(path + ": PCL could not read it as a PLY point cloud");
  }
  std::vector<ColouredPoint> points;
  points.reserve(cloud.size());
  for (const pcl::PointXYZRGBNormal& p : cloud) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      throw InputError(path + ": vertex " + std::to_string(points.size()) +
                       " has a non-finite coordinate (NaN or infinity)");
    }
    ColouredPoint point;
    point.xyz = Eigen::Vector3f(p.x, p.y, p.z);
    point.normal = Eigen::Vector3f(p.normal_x, p.normal_y, p.normal_z);
    point.rgb << p.r, p.g, p.b;
    points.push_back(point);
  }
  return points;
}

}  // namespace exporter
}  // namespace raycarve
