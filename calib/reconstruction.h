#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/camera.h"
#include "calib/rigid3d.h"
#include "calib/types.h"

namespace raycarve {

struct Point2D {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // pixel, COLMAP convention
  point3D_t point3D_id = kInvalidPoint3DId;
};

// A registered image: its pose, camera and 2D observations.
struct Image {
  image_t image_id = 0;
  camera_t camera_id = 0;
  std::string name;  // path relative to the image folder, as COLMAP stores it
  Rigid3d cam_from_world;
  std::vector<Point2D> points2D;

  // Camera centre in world coordinates: -R^T t.
  Eigen::Vector3d ProjectionCenter() const { return cam_from_world.Inverse().translation; }
};

struct TrackElement {
  image_t image_id = 0;
  point2D_t point2D_idx = 0;
};

struct Point3D {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Matrix<uint8_t, 3, 1> color = Eigen::Matrix<uint8_t, 3, 1>::Zero();  // RGB
  double error = -1.0;  // mean reprojection error in pixels; -1 when unknown
  std::vector<TrackElement> track;
};

// A COLMAP sparse model in memory. Ordered maps keep output deterministic.
struct Reconstruction {
  std::map<camera_t, Camera> cameras;
  std::map<image_t, Image> images;
  std::map<point3D_t, Point3D> points3D;
};

// Checks what the readers cannot check record by record, and throws InputError naming `source`
// and the field on the first problem: a camera that fails ValidateCamera, an image whose
// camera_id is unknown, a pose that is not finite or a quaternion of zero norm, a point3D_id in an
// image that no point has, a track element naming an unknown image or a point2D_idx out of range,
// non-finite coordinates. An empty model is valid here; commands that need images or points say so.
void ValidateReconstruction(const Reconstruction& reconstruction, const std::string& source);

}  // namespace raycarve
