#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/reconstruction.h"

namespace raycarve {

// A registered image ready for carving: undistorted pixels and an ideal pinhole camera.
//
// Frames and units: world coordinates of the model; pixels in COLMAP's convention (the centre of
// cv::Mat element (row r, col c) is (c + 0.5, r + 0.5), see pixel.h).
struct CalibratedView {
  image_t image_id = 0;
  std::string name;
  int width = 0;
  int height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();  // pinhole intrinsics
  Rigid3d cam_from_world;
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();  // K [R | t]
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // camera centre in world coordinates
  cv::Mat image;  // CV_8UC3, RGB order, undistorted
  cv::Mat valid;  // CV_8UC1, 255 where `image` holds a photo pixel (0 beyond the distorted frame)
  cv::Mat mask;   // CV_8UC1, 255 on the object and 0 on background; empty when no mask is known

  // Pixel (COLMAP convention) of a world point; meaningless for points with Depth() <= 0.
  // (Inline: the mesh's refinement projects tens of millions of points.)
  Eigen::Vector2d Project(const Eigen::Vector3d& world) const {
    return (P * world.homogeneous()).hnormalized();
  }
  // Depth along the optical axis (camera z) of a world point.
  double Depth(const Eigen::Vector3d& world) const;
  // Whether the photo's frame holds a world point, occlusion aside: in front of the camera, on a
  // pixel of the photo that holds photo data (`valid`, where set).
  bool FramesPoint(const Eigen::Vector3d& world) const;
  // Maps homogeneous COLMAP pixel coordinates (x, y, 1) to the world direction of their ray
  // (R^T K^-1; not normalised: a unit step of camera depth).
  Eigen::Matrix3d WorldFromPixel() const;
};

// Builds the view of `image` (seen by `camera`) from its photo `rgb` (CV_8UC3 RGB as decoded)
// and, optionally, its object mask (CV_8UC1, non-zero = object, in the photo's pixels).
// Cameras with distortion are resampled to PinholeCameraFor(camera) (the mask by nearest
// neighbour). Throws InputError naming `source` (the photo's path) when the photo's size differs
// from the camera's, or `mask_source` when the mask's size differs from the photo's.
CalibratedView MakeCalibratedView(const Camera& camera,
                                  const Image& image,
                                  const cv::Mat& rgb,
                                  const std::string& source,
                                  const cv::Mat& mask = cv::Mat(),
                                  const std::string& mask_source = "");

// The view seen through an image `factor` times smaller along each axis, for carving coarse
// voxels: each output pixel is the mean of a factor x factor block of input pixels (the last
// width % factor columns and height % factor rows are dropped), so that COLMAP pixel coordinates
// scale by 1 / factor exactly (K and P follow). A pixel is valid only where its whole block is,
// and on the object (mask) where any of its block is: background pixels may be blended into a
// silhouette's colours, but no object pixel is lost to a visual hull. factor 1 returns a copy
// sharing the pixels. CHECKs 1 <= factor <= min(width, height).
CalibratedView ReduceView(const CalibratedView& view, int factor);

// The view seen through an image `factor` times larger along each axis, for carving voxels
// smaller than a pixel: each output pixel is the bilinear interpolation of the photo at its
// centre, so that every voxel is crossed by rays and the mean of a voxel's rays approximates the
// photo's mean over its projection (a footprint, not the one pixel its centre falls in). COLMAP
// pixel coordinates scale by `factor` exactly (K and P follow). A pixel is valid only where every
// input pixel it is interpolated from is, and, with a mask, where those are all object or all
// background (a blend is the colour of neither); the mask by nearest neighbour. factor 1 returns
// a copy sharing the pixels. CHECKs 1 <= factor <= 16.
CalibratedView EnlargeView(const CalibratedView& view, int factor);

// The median over `views` of the width a pixel spans at `point` (depth / focal length, in world
// units), over the views that have it in front; 0 when none has.
double MedianPixelFootprint(const std::vector<CalibratedView>& views, const Eigen::Vector3d& point);

}  // namespace raycarve
