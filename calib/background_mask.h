#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace raycarve {

// Object masks for photos of an object on a plain backdrop (a studio set-up, the Middlebury
// sets), when the user has no mask files.
struct BackgroundOptions {
  enum class Mode {
    kNone,    // no backdrop: every pixel is used (natural scenes)
    kAuto,    // each photo's backdrop colour estimated from its border
    kColour,  // the backdrop colour given in `colour`
  };
  Mode mode = Mode::kNone;
  Eigen::Vector3d colour = Eigen::Vector3d::Zero();  // RGB 0-255, for kColour
  // A pixel farther than this from the backdrop colour (Euclidean RGB distance) is object.
  double tolerance = 30.0;
  // kAuto: refine each mask by a graph cut over colour models of object and backdrop (OpenCV's
  // GrabCut), seeded with the photo's sparse points; off, masks are the colour rule alone.
  bool refine = true;

  bool IsValid(std::string* reason) const;
};

// "none", "auto" or "R,G,B"; throws InputError naming --background_colour otherwise.
BackgroundOptions::Mode ParseBackground(const std::string& text, Eigen::Vector3d* colour);

// The backdrop colour of a photo (CV_8UC3 RGB): the per-channel median of its border pixels
// (the outermost 2% of rows and columns). Returns false when the border is not one colour (fewer
// than 80% of its pixels within `tolerance` of the median), i.e. there is no plain backdrop.
bool EstimateBackdropColour(const cv::Mat& rgb, double tolerance, Eigen::Vector3d* colour);

// The object mask (CV_8UC1, 255 = object) of a photo on a backdrop of colour `backdrop`: pixels
// farther than `tolerance` from it, cleaned of specks (opening, 3x3) and of pinholes (closing,
// 5x5). Holes larger than that stay background, since objects can have real openings.
cv::Mat ObjectMaskFromBackdrop(const cv::Mat& rgb, const Eigen::Vector3d& backdrop, double tolerance);

// What a photo's border says about its backdrop, for photos on one or several plain colours
// (a wall and a table, a gradient sweep, a vignetted cloth), behind an optional uniform frame.
struct BackdropModel {
  bool found = false;                  // the border is explained by a few plain colours
  std::vector<Eigen::Vector3d> colours;  // RGB, the per-channel median of each colour's pixels
  std::vector<double> shares;          // of the border's pixels, per colour
  double explained = 0.0;              // share of the border's pixels within tolerance of one
  int frame[4] = {0, 0, 0, 0};         // uniform frame lines at the top, bottom, left, right
  // Of the border's pixels, the share set aside as the object's own colours (where the object
  // or the surface it stands on runs out of the frame; see EstimateBackdropModel's seeds).
  double object_border_share = 0.0;
  std::vector<Eigen::Vector3d> object_colours;  // the border's colours found to be the object's
  std::string Summary() const;         // "2 colours (85,100,160 60%; ...), frame 3 px"
};

// At most this many colours make a backdrop; a border that needs more is a natural scene.
constexpr int kMaxBackdropColours = 5;

// The backdrop of a photo (CV_8UC3 RGB) from its border: a frame of uniform lines at any side
// (up to 2.5% of the photo) that differ from what lies inside them is set aside; the next band
// (2% of rows and columns) is described by the fewest colours (1 to kMaxBackdropColours, by
// k-means, deterministic) that bring 80% of its pixels within `tolerance`. With one colour this
// is EstimateBackdropColour. `found` is false when no such set exists.
//
// `object_seeds` (pixels where sparse points inside the volume fall in the photo) tell the
// object's colours from the backdrop's where the object, or the table it stands on, runs out of
// the frame and so covers part of the border. A plain backdrop has no texture and holds no
// sparse points of its own; the points that land on it come from errors (in the poses, in the
// points). The border's colours are clustered (k-means, kMaxBackdropColours); a cluster whose
// colour holds seeds at least kObjectSeedDensity times as densely as the photo as a whole (the
// share of seeds within `tolerance` of it against the share of the photo's pixels) is the
// object's, and the backdrop is described again without its border pixels. This only refines a
// backdrop found on the whole border: a border that needs more colours is a natural scene, and
// stays one. With fewer than kMinColourSeeds seeds in the photo every border pixel counts.
BackdropModel EstimateBackdropModel(const cv::Mat& rgb, double tolerance,
                                    const std::vector<Eigen::Vector2d>& object_seeds = {});
constexpr int kMinColourSeeds = 20;
// Seeds spread evenly over an object hold its colours at least as densely as the photo's average
// (the object is part of the photo); half leaves room for its plain parts. A backdrop colour holds
// only stray seeds: at most 0.26 of the average on the Middlebury sets' COLMAP models, whose worst
// poses put a sixth to a fifth of the points on the black backdrop.
constexpr double kObjectSeedDensity = 0.5;

// How far a pixel's colour is from the backdrop: the least RGB distance to one of the model's
// colours scaled by a brightness gain in [darkest, brightest] (shadows darken a backdrop, and
// vignetting darkens the border from which the colours come, without changing their hue).
double BackdropDistance(const Eigen::Vector3d& rgb, const BackdropModel& model, double darkest,
                        double brightest);
// The gains a pixel may differ by from a backdrop colour and still be probable backdrop.
constexpr double kShadowGain = 0.4;
constexpr double kLightGain = 1.8;

struct ObjectMaskReport {
  double object_share = 0.0;  // of the photo's pixels
  int seeds = 0;              // sparse points used as sure object
  bool refined = false;       // GrabCut ran (it needs both some object and some backdrop)
  bool cut_to_box = false;    // pixels whose rays miss the volume were set to backdrop
  int regions_restored = 0;   // regions the cut took that the sparse points gave back
};

// The object mask (CV_8UC1, 255 = object) of a photo whose backdrop is `model`:
//  - the frame, and pixels within options.tolerance of a backdrop colour, are backdrop;
//  - with options.refine, GrabCut (OpenCV) then decides over colour models of both, from: the frame
//    and pixels of the backdrop's colours as sure backdrop, pixels that are only a shade of them (shadows, vignetting, gradients: a gain in
//    [kShadowGain, kLightGain], reached from the backdrop's colours through neighbours that
//    differ by at most half the tolerance) as probable backdrop, the rest as probable object,
//    and `object_seeds` (pixels of sparse points inside the volume) as sure object;
//    a region the cut takes from the colour rule's object goes back when the seeds in it are at
//    least a quarter as dense as on the object it kept (the object's shadowed side, not a cloth);
//  - `box_hull` (the volume's outline in the photo, possibly empty): pixels outside it are sure
//    backdrop, since no carving can use them;
//  - then cleaned of specks (opening 3x3) and pinholes (closing 5x5).
cv::Mat ObjectMaskFromModel(const cv::Mat& rgb,
                            const BackdropModel& model,
                            const BackgroundOptions& options,
                            const std::vector<Eigen::Vector2d>& object_seeds,
                            const std::vector<cv::Point>& box_hull,
                            ObjectMaskReport* report);

}  // namespace raycarve
