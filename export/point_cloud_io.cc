#include "export/point_cloud_io.h"

#include <cerrno>
#include <cmath>
#include <fstream>

#include <filesystem>

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
    errno = 0;
    std::ofstream file(temporary, std::ios::binary);
    file << "ply\nformat binary_little_endian 1.0\ncomment raycarve: no points\nelement vertex 0\n"
            "property float x\nproperty float y\nproperty float z\nproperty float nx\n"
            "property float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n"
            "property uchar blue\nend_header\n";
    file.close();
    if (!file) ThrowWriteFailure(temporary, "the point cloud", errno);
    RenameIntoPlace(temporary, path);
    return;
  }
  pcl::PLYWriter writer;
  errno = 0;
  if (writer.write(temporary, cloud, /*binary=*/true, /*use_camera=*/false) != 0) {
    ThrowWriteFailure(temporary, "the point cloud (PCL)", errno);
  }
  RenameIntoPlace(temporary, path);
}

std::vector<ColouredPoint> ReadPointCloudPly(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(path + ": point cloud file not found");
  }
  const PlyData data = ReadPly(path);
  std::vector<ColouredPoint> points(data.xyz.size());
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].xyz = data.xyz[i];
    if (!data.normals.empty()) points[i].normal = data.normals[i];
    if (!data.rgb.empty()) points[i].rgb = data.rgb[i];
  }
  return points;
}

}  // namespace exporter
}  // namespace raycarve
