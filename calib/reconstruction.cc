#include "calib/reconstruction.h"

#include <cmath>
#include <string>

#include "calib/input_error.h"

namespace raycarve {

void ValidateReconstruction(const Reconstruction& reconstruction, const std::string& source) {
  for (const auto& [camera_id, camera] : reconstruction.cameras) {
    ValidateCamera(camera, source);
  }
  for (const auto& [image_id, image] : reconstruction.images) {
    const std::string where = source + ": image " + std::to_string(image_id) + " ('" +
                              image.name + "')";
    if (reconstruction.cameras.count(image.camera_id) == 0) {
      throw InputError(where + ": camera_id " + std::to_string(image.camera_id) +
                       " is not in the model's cameras");
    }
    const Eigen::Vector4d q = image.cam_from_world.rotation.coeffs();
    if (!q.allFinite() || !image.cam_from_world.translation.allFinite()) {
      throw InputError(where + ": pose (QW QX QY QZ TX TY TZ) is not finite");
    }
    if (!(q.norm() > 1e-12)) {
      throw InputError(where + ": pose quaternion has zero norm");
    }
    for (size_t i = 0; i < image.points2D.size(); ++i) {
      const Point2D& point2D = image.points2D[i];
      if (!point2D.xy.allFinite()) {
        throw InputError(where + ": points2D[" + std::to_string(i) + "] is not finite");
      }
      if (point2D.point3D_id != kInvalidPoint3DId &&
          reconstruction.points3D.count(point2D.point3D_id) == 0) {
        throw InputError(where + ": points2D[" + std::to_string(i) + "] refers to point3D_id " +
                         std::to_string(point2D.point3D_id) + ", which the model does not have");
      }
    }
  }
  for (const auto& [point3D_id, point3D] : reconstruction.points3D) {
    const std::string where = source + ": point3D " + std::to_string(point3D_id);
    if (!point3D.xyz.allFinite()) {
      throw InputError(where + ": XYZ is not finite");
    }
    for (const TrackElement& element : point3D.track) {
      const auto image = reconstruction.images.find(element.image_id);
      if (image == reconstruction.images.end()) {
        throw InputError(where + ": track refers to image_id " +
                         std::to_string(element.image_id) + ", which the model does not have");
      }
      if (element.point2D_idx >= image->second.points2D.size()) {
        throw InputError(where + ": track element (image " + std::to_string(element.image_id) +
                         ", point2D_idx " + std::to_string(element.point2D_idx) +
                         ") is beyond that image's " +
                         std::to_string(image->second.points2D.size()) + " points2D");
      }
    }
  }
}

}  // namespace raycarve
