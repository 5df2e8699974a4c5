#pragma once
// A picture of the model to look at: the mesh drawn into a few of the photos' cameras, beside
// the photos.

#include <vector>

#include <opencv2/core.hpp>

#include "calib/calibrated_view.h"
#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

// Rows of photo | the mesh drawn from that photo's camera (RenderMesh: its texture when it has
// one, else its vertex colours; black where it does not cover), for `count` views spread evenly
// over `views` (all of them when fewer), each pair scaled down so that a row is at most
// `max_width` pixels wide; then a row of three renders of the model from directions no photo was
// taken from (ViewsFromOutside). RGB, CV_8UC3; empty when there are no views.
cv::Mat PreviewImage(const TriangleMesh& mesh, const std::vector<CalibratedView>& views,
                     int count = 3, int max_width = 1600);

// The photos' up direction in the world (EstimatePhotosUp: the mean of their cameras' -y axes,
// up in a photo, with photos turned a quarter turned back), unit; +z where they cancel out (or
// there are none).
Eigen::Vector3d UpOfPhotos(const std::vector<CalibratedView>& views);

// `count` pinhole cameras of `width` x `height` (40 degrees across) framing the whole mesh from
// the directions farthest from the photos': of above, below (the photos' mean up, their camera
// -y axes) and sixteen around and above the model, each next one the farthest from the photos and
// those already taken. Empty for an empty mesh or no views.
std::vector<CalibratedView> ViewsFromOutside(const TriangleMesh& mesh,
                                             const std::vector<CalibratedView>& views, int count,
                                             int width, int height);

}  // namespace exporter
}  // namespace raycarve
