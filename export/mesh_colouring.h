#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "calib/calibrated_view.h"
#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

struct MeshColouringOptions {
  // Vertices seen by fewer photos than this take the colour of their seen neighbours instead.
  int min_views = 2;
  // A vertex is seen in a photo when it faces the camera, projects onto a valid (and, with a
  // mask, object) pixel, and lies at most this far (world units) behind the mesh's own depth at
  // that pixel. Must be > 0; a voxel's size is the natural scale.
  double depth_tolerance = 0.0;
  // Samples further than this many times the median distance from the samples' median colour
  // (at least kMinOutlierDistance RGB units) are left out: a highlight, an occluder the model
  // does not hold, a photo whose pose is off.
  double outlier_factor = 2.5;
  // Threads (0 or less: every core); the colours do not depend on it.
  int num_threads = 0;

  bool IsValid(std::string* reason) const;
};

struct MeshColouringSummary {
  int64_t vertices = 0;
  int64_t from_photos = 0;      // seen by min_views or more photos
  int64_t from_neighbours = 0;  // seen by fewer: the mean of their coloured neighbours
  int64_t uncoloured = 0;       // no coloured vertex connects to them: grey 128
  double mean_views = 0.0;      // photos per vertex coloured from photos
  double seconds = 0.0;
  double SeenShare() const { return vertices > 0 ? static_cast<double>(from_photos) / vertices : 0.0; }
  std::string Summary() const;
};

// One view that sees a vertex: it faces the camera (the cosine between its normal and the ray to
// the camera is `facing` > 0), projects onto a valid (and, with a mask, object) pixel, and lies at
// most `depth_tolerance` behind the mesh's own depth there (RenderMesh's depth buffer).
struct VertexSighting {
  uint32_t view = 0;
  float facing = 0.0f;
};
// Per vertex, the views that see it, in increasing view order. Needs mesh.normals, and a closed
// mesh wound as MeshSolidVoxels winds it, seen from outside: the depth buffer is drawn from the
// front faces alone (RenderMesh's front_faces_only).
// `on_rim`, when given, gets per vertex whether it lies on a silhouette's rim: in some view with
// a mask it is not hidden (at most depth_tolerance behind the mesh's depth, facing or not) and
// projects onto an object pixel within `rim_voxels` voxel widths (`voxel_size`, projected at
// its depth) of the background. The views are drawn on `num_threads` threads (0 or less: every
// core). `mask_distances`, when given, holds MaskDistances(views), for callers that find the
// sightings again and again (the masks do not change).
std::vector<std::vector<VertexSighting>> FindVertexSightings(
    const std::vector<CalibratedView>& views, const TriangleMesh& mesh, double depth_tolerance,
    std::vector<uint8_t>* on_rim = nullptr, double voxel_size = 0.0, double rim_voxels = 1.0,
    int num_threads = 0, const std::vector<cv::Mat>* mask_distances = nullptr);

// Per view with a mask, each object pixel's distance (pixels) to the nearest background pixel
// (CV_32FC1, cv::distanceTransform's DIST_L2 with a 3x3 mask); empty for a view without a mask.
std::vector<cv::Mat> MaskDistances(const std::vector<CalibratedView>& views, int num_threads = 0);

// Bilinear sample of an RGB image (CV_8UC3) at a COLMAP pixel position (pixel centres at +0.5);
// false outside the image's centres. (Inline: the mesh refinement calls it tens of millions of
// times.)
inline bool SampleBilinear(const cv::Mat& image, const Eigen::Vector2d& pixel, Eigen::Vector3f* colour) {
  const double u = pixel.x() - 0.5, v = pixel.y() - 0.5;
  if (!(u >= 0.0 && v >= 0.0 && u <= image.cols - 1 && v <= image.rows - 1)) return false;
  const int c0 = std::min(static_cast<int>(u), image.cols - 2 < 0 ? 0 : image.cols - 2);
  const int r0 = std::min(static_cast<int>(v), image.rows - 2 < 0 ? 0 : image.rows - 2);
  const int c1 = std::min(c0 + 1, image.cols - 1), r1 = std::min(r0 + 1, image.rows - 1);
  const float fu = static_cast<float>(u - c0), fv = static_cast<float>(v - r0);
  const cv::Vec3b& p00 = image.at<cv::Vec3b>(r0, c0);
  const cv::Vec3b& p01 = image.at<cv::Vec3b>(r0, c1);
  const cv::Vec3b& p10 = image.at<cv::Vec3b>(r1, c0);
  const cv::Vec3b& p11 = image.at<cv::Vec3b>(r1, c1);
  for (int k = 0; k < 3; ++k) {
    (*colour)[k] = (1 - fv) * ((1 - fu) * p00[k] + fu * p01[k]) + fv * ((1 - fu) * p10[k] + fu * p11[k]);
  }
  return true;
}


// The colour of `view`'s photo at a COLMAP pixel position, bilinear between pixel centres; false
// where the position is outside the photo's data (invalid pixels) or, with a mask, off the object.
inline bool SamplePhoto(const CalibratedView& view, const Eigen::Vector2d& pixel, Eigen::Vector3f* colour) {
  const int col = static_cast<int>(std::floor(pixel.x()));
  const int row = static_cast<int>(std::floor(pixel.y()));
  if (col < 0 || row < 0 || col >= view.width || row >= view.height) return false;
  if (view.valid.at<uint8_t>(row, col) == 0) return false;
  if (!view.mask.empty() && view.mask.at<uint8_t>(row, col) == 0) return false;
  return SampleBilinear(view.image, pixel, colour);
}


// Colours every vertex of `mesh` from the photos at their own resolution: in each view the mesh
// is drawn with a depth buffer (RenderMesh) to find the vertices the view sees; each seen vertex
// takes a sample (bilinear, at its projection) weighted by the cosine between its normal and the
// ray to the camera; the vertex's colour is the weighted mean of its samples without outliers.
// Needs mesh->normals. `seen_by`, when given, gets per vertex the indices (into `views`) of the
// views that see it, in increasing order.
MeshColouringSummary ColourMeshFromPhotos(const std::vector<CalibratedView>& views,
                                          const MeshColouringOptions& options,
                                          TriangleMesh* mesh,
                                          std::vector<std::vector<uint32_t>>* seen_by = nullptr);

}  // namespace exporter
}  // namespace raycarve
