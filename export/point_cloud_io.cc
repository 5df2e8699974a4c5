#include "export/point_cloud_io.h"

#include <filesystem>

#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "calib/atomic_file.h"
#include "calib/input_error.h"

namespace raycarve {
namespace exporter {

void WritePointCloudPly(const std::vector<ColouredPoint>& points, const std::string& path) {
  pcl::PointCloud<pcl::PointXYZRGBNormal> cloud;
  cloud.reserve(points.size());
  for (const ColouredPoint& point : points) {
    pcl::PointXYZRGBNormal p;
    p.x = point.xyz.x();
    p.y = point.xyz.y();
    p.z = point.xyz.z();
    p.normal_x = point.normal.x();
    p.normal_y = point.normal.y();
    p.normal_z = point.normal.z();
    p.curvature = 0.0f;
    p.r = point.rgb[0];
    p.g = point.rgb[1];
    p.b = point.rgb[2];
    p.a = 255;
    cloud.push_back(p);
  }
  cloud.width = static_cast<uint32_t>(cloud.size());
  cloud.height = 1;
  const std::string temporary = TemporaryPathFor(path);
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
  pcl::PointCloud<pcl::PointXYZRGBNormal> cloud;
  pcl::PLYReader reader;
  if (reader.read(path, cloud) != 0) {
    throw InputError(path + ": PCL could not read it as a PLY point cloud");
  }
  std::vector<ColouredPoint> points;
  points.reserve(cloud.size());
  for (const pcl::PointXYZRGBNormal& p : cloud) {
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
