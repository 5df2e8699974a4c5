#include "pipeline/carve_request.h"

#include <cmath>
#include <limits>

#include "calib/input_error.h"
#include "export/surface_mesh.h"

namespace raycarve {

CarveRequest::CarveRequest() {
  view_options.max_image_size = kDefaultMaxImageSize;
  options.num_threads = -1;
  options.lod_levels = kAutomaticLevels;
  options.supersample = CarveOptions::kAutomaticSupersample;
  options.min_component_voxels = kDefaultMinComponentVoxels;
  options.auto_threshold = true;
  options.protect_surface_points = true;
  options.free_space_margin_voxels = kDefaultFreeSpaceMarginVoxels;
  options.unsupported_component_points = kDefaultFloaterExpectedPoints;
  options.repair_silhouettes = true;
}

ColourCalibrationMode ColourCalibrationModeOf(const CarveRequest& request) {
  ColourCalibrationMode mode = ColourCalibrationMode::kAuto;
  ColourCalibrationModeFromString(request.colour_calibration, &mode);
  return mode;
}

void FinishCarveRequest(CarveRequest* request) {
  std::string reason;
  if (!request->view_options.background.IsValid(&reason)) throw InputError(reason);
  if (!request->options.IsValid(&reason)) throw InputError(reason);
  if (!(request->min_voxel_pixels >= 0.0) || !std::isfinite(request->min_voxel_pixels)) {
    throw InputError("--min_voxel_pixels: must be a number >= 0 (0: never refuse), got " +
                     std::to_string(request->min_voxel_pixels));
  }
  if (request->options.num_threads != -1 &&
      (request->options.num_threads < 1 || request->options.num_threads > 1024)) {
    throw InputError("--num_threads: must be -1 (every core) or 1 to 1024, got " +
                     std::to_string(request->options.num_threads));
  }
  if (request->mesh_max_faces > static_cast<uint64_t>(std::numeric_limits<int32_t>::max())) {
    throw InputError("--mesh_max_faces: at most " +
                     std::to_string(std::numeric_limits<int32_t>::max()) + ", got " +
                     std::to_string(request->mesh_max_faces));
  }
  request->mesh.max_triangles = static_cast<int64_t>(request->mesh_max_faces);
  const int max_image_size = request->view_options.max_image_size;
  if (max_image_size > 0 && max_image_size < CarveOptions::kMinReducedSide) {
    throw InputError("--max_image_size " + std::to_string(max_image_size) + ": photos reduced below " +
                     std::to_string(CarveOptions::kMinReducedSide) +
                     " pixels cannot show the object's colours; give at least " +
                     std::to_string(CarveOptions::kMinReducedSide) + ", or 0 for full size");
  }
  if (request->cloud_min_views < 1) {
    throw InputError("--cloud_min_views: must be >= 1, got " + std::to_string(request->cloud_min_views));
  }
  // --num_threads holds for every stage: loading the photos, carving, meshing, colouring, and
  // the libraries' own parallel loops.
  request->mesh.num_threads = request->options.num_threads;
  request->view_options.num_threads = request->options.num_threads;
  exporter::SetLibraryThreads(request->options.num_threads);
  request->mesh.min_views = request->options.min_views;
  // The mesh drops what is smaller than the iso-surface of the smallest speck the carve keeps
  // (a cube of min_component_voxels voxels: 6 faces of n^(2/3) vertices).
  const double speck = static_cast<double>(std::max(request->options.min_component_voxels, 0));
  request->mesh.min_component_vertices = static_cast<int64_t>(std::ceil(6.0 * std::pow(speck, 2.0 / 3.0)));
  if (!request->mesh.IsValid(&reason)) throw InputError("--mesh_*: " + reason);
}

}  // namespace raycarve
