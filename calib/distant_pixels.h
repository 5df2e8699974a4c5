#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "calib/calibrated_view.h"

namespace raycarve {

// Photo pixels that show something far beyond the volume: sky, clouds, far hills. Without masks
// such pixels are the only evidence that the space in front of them is empty where their colours
// also agree across the photos (a smooth or coarsely patterned sky seen through empty space from
// nearby cameras shows them the same colour, and voxel colouring keeps what agrees).
//
// The test is geometric. Between two photos i and j, what lies at infinity moves by the infinite
// homography H = K_j R_j R_i^T K_i^-1 (the rotation alone); a point inside the volume moves by
// its parallax, along the epipolar line, to where the segment of i's ray inside the volume
// projects in j. A textured patch around pixel p of photo i is distant when it matches photo j at
// H p (zero-mean normalised correlation, the patch warped by H) clearly better than anywhere on
// that segment, and the segment's far end lies at least `min_parallax` pixels from H p (the
// photos resolve the volume's depth there). A pixel is distant when `min_agreeing_views` other
// photos say so and none finds it clearly nearer. Plain patches say nothing either way and are
// never judged by themselves: a plain region (connected pixels whose patch is not textured) is
// distant when a quarter or more of the judged pixels on its rim (and three at least) are, few
// are nearer, and it holds none of the photo's sparse points (the blue between clouds, a patch of
// a patterned sky, bounded by edges that move as the sky does; a plain wall's rim moves with the
// wall, and the detail on it holds points).
struct DistantOptions {
  int max_side = 640;        // photos are judged reduced to at most this many pixels a side
  int patch_radius = 3;      // patches of (2r + 1)^2 pixels at that size
  int stride = 2;            // a pixel judged every `stride` pixels along rows and columns
  double min_parallax = 3.0;  // pixels, at the reduced size
  double min_correlation = 0.85;  // a patch matches where its correlation reaches this
  double min_advantage = 0.2;     // and beats the other hypothesis by this much
  int min_agreeing_views = 2;
  int max_partners = 4;  // other photos asked per pixel (those farthest from it first)
  // A patch is textured when its grey standard deviation reaches this many times the photo's
  // noise (ImageNoiseSigma) and at least `min_texture` grey levels.
  double texture_noise_factor = 4.0;
  double min_texture = 4.0;
  // A patch is judged only when each of its four quadrants (the centre's row and column shared)
  // is textured too: at an occluder's edge the plain side of the patch says nothing of where
  // that side lies, and the textured side alone would carry the match (FindGroundPixels: a plain
  // box's foot on a textured floor). Off for the distant test (a sky's edge is its own).
  bool textured_quadrants = false;
  // Whether plain regions are judged by their rims (above).
  bool grow_plain_regions = true;
  // Whether a grown pixel's ray is kept only where the photos asked see its colour where the
  // surface puts its point (for the sky: its direction), as they see a sky's: most of the photos
  // asked (the pairs of the test above, up to max_partners) must see the pixel's colour there (3 x
  // 3 pixels' mean, within the photo's plain spread, the smallest standard deviation of a textured
  // patch, after each photo's gain, the median ratio of their colours at the pixels found). A
  // plain object that runs into a sky of its colour without an edge merges with it into one region,
  // but moves with its parallax: the other photos see what lies beside or behind it there.
  // Measured (generated eye-level capture, patchwork sky): a light stripe of a box merged with a
  // sky cell of its colour in about twenty of 36 photos and the rays hollowed the box.
  bool check_grown_colour = true;
  // Whether a judged pixel found casts the rays of every pixel of its stride cell (those it stands
  // for, judged with it), not its own alone: rays every `stride` pixels leave voxels of a pixel or
  // two between them untouched (FindGroundPixels sets it: room arc F 89.1% -> 92.5%). Off for the
  // sky: with it, and the plain regions' every pixel, patchwork forward fell 90.0 -> 89.4%.
  bool cell_rays = false;
  int num_threads = 1;  // < 1: one per hardware thread

  bool IsValid(std::string* reason) const;
};

// A distant pixel's ray: `view` indexes the views, `direction` is a unit world direction. The
// photo saw across empty space along it up to `length` from its centre (infinite for a distant
// pixel; where a ground pixel's ray comes near the ground, FindGroundPixels in carve/ground.h).
struct DistantRay {
  int view = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  double length = std::numeric_limits<double>::infinity();
};

struct DistantPixels {
  std::vector<DistantRay> rays;
  // Per view, at the reduced size (`factors[v]` times smaller): 255 where a judged pixel was
  // found distant, 200 inside a plain region grown from them, 128 where judged and undecided, 64
  // where found nearer, 0 elsewhere.
  std::vector<cv::Mat> masks;
  std::vector<int> factors;
  int photos_judged = 0;
  int64_t textured = 0;  // pixels judged
  int64_t distant = 0;   // of those, found distant
  int64_t nearer = 0;    // of those, found inside the volume by some photo
  int64_t grown = 0;     // pixels of plain regions whose rim is distant
  int64_t grown_refused = 0;  // of their rays, those whose colour the photos asked did not see
  double seconds = 0.0;
  std::string Summary() const;
};

// The distant pixels of `views` (undistorted, CV_8UC3 RGB) with respect to the volume `box`.
// `observations` (optional): per view, its pixels (COLMAP coordinates) of sparse points inside
// the volume; a plain region holding one is never distant. Deterministic: the result does not
// depend on the thread count.
DistantPixels FindDistantPixels(const std::vector<CalibratedView>& views,
                                const Eigen::AlignedBox3d& box,
                                const DistantOptions& options,
                                const std::vector<std::vector<Eigen::Vector2d>>& observations = {});

// The test above with another surface in place of infinity: `surface` says where the ray from
// `centre` along the unit `direction` meets the supposed surface (*at, a distance along the ray;
// infinity for the sky) and up to where the ray, if it ends there, crossed space that the photos
// can tell from it (*clear_to <= *at); false where it says nothing of that ray. A pixel matches
// the surface when its patch, each pixel's ray ending on the surface, matches the other photos
// there clearly better than anywhere on its ray inside `box` up to *clear_to, that part's far end
// lying at least `min_parallax` pixels from the surface's point. For a surface at a finite
// distance, a photo that does not tell the ray's point at *clear_to from the surface's searches
// the part it does tell apart (up to where the point comes within `min_parallax` pixels) and
// speaks for that part alone. Rays are those of the pixels found (judged and grown), with `length`
// up to where `min_agreeing_views` of the photos that agree tell the ray from the surface, at most
// *clear_to, where the surface is at a finite distance (a pixel of a found pixel's stride cell: the
// same share of the way to the surface). FindDistantPixels is this with the sky at infinity
// (clear_to: the box's far side, which every photo asked must tell apart).
using SupposedSurface = std::function<bool(const Eigen::Vector3d& centre, const Eigen::Vector3d& direction,
                                           double* at, double* clear_to)>;
DistantPixels FindPixelsOnSurface(const std::vector<CalibratedView>& views,
                                  const Eigen::AlignedBox3d& box,
                                  const DistantOptions& options,
                                  const SupposedSurface& surface,
                                  const std::vector<std::vector<Eigen::Vector2d>>& observations = {});

// The noise of a grey image (CV_32F) in grey levels: after Immerkaer, the response to the
// difference of two Laplacians, its mean absolute value over blocks of 8 x 8 pixels, the median
// of the plain blocks (within twice the tenth percentile) scaled for a Gaussian (robust to texture
// over up to four fifths of the image; images of fewer than 10 blocks: the median absolute
// response). 0 for images under 3x3.
double ImageNoiseSigma(const cv::Mat& grey);

}  // namespace raycarve
