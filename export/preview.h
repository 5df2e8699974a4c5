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
// `max_width` pixels wide. RGB, CV_8UC3; empty when there are no views.
cv::Mat PreviewImage(const TriangleMesh& mesh, const std::vector<CalibratedView>& views,
                     int count = 3, int max_width = 1600);

}  // namespace exporter
}  // namespace raycarve
