#include "export/point_cloud_io.h"

#include <cmath>
#include <fstream>

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
struct FusedPoint {
  PCL_ADD_POINT4D;
  float normal_x;
  float normal_y;
  float normal_z;
  PCL_ADD_RGB;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
} EIGEN_ALIGN16;

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

std::vector<ColouredPoint> ReadPointCloudPly(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(path + ": point cloud file not found");
  }
  {
    // A PLY with no vertices (an empty carve) is valid; PCL's reader would index its empty
    // buffer, so it is answered here from the header.
    std::ifstream file(path, std::ios::binary);
    std::string line;
    while (std::getline(file, line) && line.rfind("end_header", 0) != 0) {
      if (line.rfind("element vertex ", 0) != 0) continue;
      std::string count = line.substr(15);
      count.erase(count.find_last_not_of(" \t\r") + 1);
      if (count == "0") return {};
    }
  }
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
