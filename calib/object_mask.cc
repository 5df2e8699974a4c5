// ObjectMaskFromModel: a photo's object mask from its backdrop model (declared in
// background_mask.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "calib/background_mask.h"
#include "calib/border_band.h"

namespace raycarve {
namespace {

// The photo's pixels whose rays may meet the volume: the convex hull of the volume's outline
// (`box_hull`, at full size) at `scale`, grown by a margin for the camera's distortion; every
// pixel when there is no outline.
cv::Mat VolumeOutlineMask(const cv::Size& size, double scale, const std::vector<cv::Point>& box_hull) {
  cv::Mat inside_box(size, CV_8UC1, cv::Scalar(255));
  if (box_hull.size() >= 3) {
    std::vector<cv::Point> scaled, hull;
    for (const cv::Point& p : box_hull) {
      scaled.emplace_back(static_cast<int>(std::lround(p.x * scale)),
                          static_cast<int>(std::lround(p.y * scale)));
    }
    cv::convexHull(scaled, hull);
    inside_box.setTo(0);
    cv::fillConvexPoly(inside_box, hull, cv::Scalar(255));
    // A margin for the camera's distortion between the sampled outline's points.
    const int margin = 2 + size.width / 100;
    cv::dilate(inside_box, inside_box, cv::Mat::ones(2 * margin + 1, 2 * margin + 1, CV_8U));
  }
  return inside_box;
}

// Each pixel's colour class: the backdrop's colours, a shade of them (darker or lighter by a
// gain), or neither. A shade is probable backdrop only where it is reached from the backdrop's
// colours through neighbours that differ by at most half the tolerance (a soft shadow, a
// vignette, a gradient): a dark part of the object that happens to share a backdrop colour's
// hue is not, since its edge against the backdrop is sharp. *reached marks the shades reached.
enum : uint8_t { kPlain = 0, kShade = 1, kObject = 2, kFrame = 3 };
cv::Mat ColourClasses(const cv::Mat& work, const BackdropModel& model, double tolerance,
                      const BorderBand& band, cv::Mat* reached_out) {
  cv::Mat colour_class(work.size(), CV_8UC1);
  std::vector<cv::Point> frontier;
  for (int row = 0; row < work.rows; ++row) {
    const cv::Vec3b* pixels = work.ptr<cv::Vec3b>(row);
    uint8_t* klass = colour_class.ptr<uint8_t>(row);
    for (int col = 0; col < work.cols; ++col) {
      const Eigen::Vector3d p = ToVector(pixels[col]);
      if (band.InFrame(row, col, work.rows, work.cols)) {
        klass[col] = kFrame;
      } else if (BackdropDistance(p, model, 1.0, 1.0) <= tolerance) {
        klass[col] = kPlain;
        frontier.emplace_back(col, row);
      } else {
        klass[col] = BackdropDistance(p, model, kShadowGain, kLightGain) <= tolerance ? kShade
                                                                                      : kObject;
      }
    }
  }
  cv::Mat& reached = *reached_out;
  reached = cv::Mat(work.size(), CV_8UC1, cv::Scalar(0));
  for (const cv::Point& p : frontier) reached.at<uint8_t>(p) = 1;
  const double step2 = 0.25 * tolerance * tolerance;
  while (!frontier.empty()) {
    const cv::Point p = frontier.back();
    frontier.pop_back();
    const Eigen::Vector3d colour = ToVector(work.at<cv::Vec3b>(p));
    const cv::Point neighbours[4] = {{p.x + 1, p.y}, {p.x - 1, p.y}, {p.x, p.y + 1}, {p.x, p.y - 1}};
    for (const cv::Point& q : neighbours) {
      if (q.x < 0 || q.y < 0 || q.x >= work.cols || q.y >= work.rows) continue;
      if (reached.at<uint8_t>(q) || colour_class.at<uint8_t>(q) != kShade) continue;
      if ((ToVector(work.at<cv::Vec3b>(q)) - colour).squaredNorm() > step2) continue;
      reached.at<uint8_t>(q) = 1;
      frontier.push_back(q);
    }
  }

  return colour_class;
}

// GrabCut's labels from the colour classes, and the colour rule alone (object: neither
// backdrop nor frame) in *colour_rule; the sparse points' pixels (`object_seeds`, full-size
// coordinates) become sure object, listed in *seed_pixels. Counts of object-like and
// backdrop-like pixels in *object_like, *backdrop_like.
cv::Mat GrabCutLabels(const cv::Mat& colour_class, const cv::Mat& reached, const cv::Mat& inside_box,
                      const std::vector<Eigen::Vector2d>& object_seeds, double scale,
                      cv::Mat* colour_rule_out, std::vector<cv::Point>* seed_pixels,
                      int* object_like_out, int* backdrop_like_out, ObjectMaskReport* report) {
  const cv::Size size = colour_class.size();
  cv::Mat& colour_rule = *colour_rule_out;
  int& object_like = *object_like_out;
  int& backdrop_like = *backdrop_like_out;
  cv::Mat labels(size, CV_8UC1);
  colour_rule = cv::Mat(size, CV_8UC1);
  object_like = 0;
  backdrop_like = 0;
  for (int row = 0; row < size.height; ++row) {
    uint8_t* label = labels.ptr<uint8_t>(row);
    uint8_t* rule = colour_rule.ptr<uint8_t>(row);
    const uint8_t* in_box = inside_box.ptr<uint8_t>(row);
    const uint8_t* klass = colour_class.ptr<uint8_t>(row);
    const uint8_t* shade_reached = reached.ptr<uint8_t>(row);
    for (int col = 0; col < size.width; ++col) {
      rule[col] = klass[col] == kShade || klass[col] == kObject ? 255 : 0;
      if (klass[col] == kFrame || in_box[col] == 0) {
        label[col] = cv::GC_BGD;
      } else if (klass[col] == kPlain) {
        // The backdrop's own colours stay backdrop: the cut would otherwise close real openings
        // (between a temple's columns) that its smoothness finds too thin.
        label[col] = cv::GC_BGD;
      } else {
        label[col] = klass[col] == kShade && shade_reached[col] ? cv::GC_PR_BGD : cv::GC_PR_FGD;
      }
      const bool object = label[col] == cv::GC_PR_FGD;
      object_like += object;
      backdrop_like += !object;
    }
  }
  for (const Eigen::Vector2d& seed : object_seeds) {
    const cv::Point at(static_cast<int>(std::floor(seed.x() * scale)),
                       static_cast<int>(std::floor(seed.y() * scale)));
    if (at.x < 0 || at.y < 0 || at.x >= size.width || at.y >= size.height) continue;
    if (labels.at<uint8_t>(at) == cv::GC_BGD) continue;  // frame, border or outside the volume
    labels.at<uint8_t>(at) = cv::GC_FGD;
    seed_pixels->push_back(at);
    ++report->seeds;
    ++object_like;
  }
  return labels;
}

// OpenCV's GrabCut over `labels` within the volume's outline; an empty mask when it cannot run
// (too few pixels of either kind) or fails.
cv::Mat RunGrabCut(const cv::Mat& work, const cv::Mat& labels, const cv::Mat& inside_box,
                   ObjectMaskReport* report) {
  cv::Mat mask;
  // Only the volume's outline (and a margin) can hold object: the cut runs there.
  cv::Rect region(0, 0, work.cols, work.rows);
  if (report->cut_to_box) {
    std::vector<cv::Point> inside;
    cv::findNonZero(inside_box, inside);
    region = inside.empty() ? cv::Rect() : cv::boundingRect(inside);
  }
  try {
    cv::Mat region_labels = labels(region).clone();
    const cv::Mat under = region_labels != cv::GC_BGD;
    const cv::Mat object = (region_labels & 1) != 0;
    if (cv::countNonZero(object) >= 64 && cv::countNonZero(~object) >= 64 &&
        cv::countNonZero(under) > 0) {
      cv::Mat background_model, object_model;
      // GrabCut seeds its colour models by k-means on OpenCV's per-thread generator: a fixed
      // state gives the same mask on any thread.
      const uint64 saved_state = cv::theRNG().state;
      cv::theRNG().state = 0x9e3779b97f4a7c15ULL;
      cv::grabCut(work(region), region_labels, cv::Rect(), background_model, object_model, 2,
                  cv::GC_INIT_WITH_MASK);
      cv::theRNG().state = saved_state;
      mask = cv::Mat::zeros(work.size(), CV_8UC1);
      mask(region).setTo(255, (region_labels & 1) != 0);  // GC_FGD and GC_PR_FGD are odd
      report->refined = true;
    }
  } catch (const cv::Exception& error) {
    LOG(WARNING) << "GrabCut failed (" << error.what() << "); the colour rule's mask is used";
  }
  return mask;
}

// The cut may take a whole region of object colours for backdrop: a cloth behind the object
// (right), or the object's own shadowed side (wrong). The sparse points tell them apart: a
// region the cut took whose sparse points are at least a quarter as dense as on the object it
// kept is object, and goes back into *mask.
void RestoreSeededRegions(const cv::Mat& colour_rule, const cv::Mat& inside_box,
                          const std::vector<cv::Point>& seed_pixels, cv::Mat* mask_io,
                          ObjectMaskReport* report) {
  cv::Mat& mask = *mask_io;
  cv::Mat removed = colour_rule & inside_box & ~mask;
  for (const cv::Point& p : seed_pixels) removed.at<uint8_t>(p) = 255;
  cv::Mat components;
  const int count = cv::connectedComponents(removed, components, 8, CV_32S);
  std::vector<int> seeds_in(count, 0), area(count, 0);
  for (int row = 0; row < components.rows; ++row) {
    const int* c = components.ptr<int>(row);
    for (int col = 0; col < components.cols; ++col) ++area[c[col]];
  }
  cv::Mat seed_mask(mask.size(), CV_8UC1, cv::Scalar(0));
  for (const cv::Point& p : seed_pixels) seed_mask.at<uint8_t>(p) = 255;
  const cv::Mat kept = mask & ~seed_mask;
  int kept_seeds = 0;
  for (const cv::Point& p : seed_pixels) {
    // A seed touching the kept object is on it; one the cut left alone inside a region it
    // took speaks for that region.
    bool touches_kept = false;
    for (int dy = -1; dy <= 1 && !touches_kept; ++dy) {
      for (int dx = -1; dx <= 1 && !touches_kept; ++dx) {
        const cv::Point q(p.x + dx, p.y + dy);
        touches_kept = q.x >= 0 && q.y >= 0 && q.x < kept.cols && q.y < kept.rows &&
                       kept.at<uint8_t>(q) != 0;
      }
    }
    const int c = components.at<int>(p);
    if (touches_kept || area[c] <= 1) {
      ++kept_seeds;
    } else {
      ++seeds_in[c];
    }
  }
  const double density = static_cast<double>(kept_seeds) / std::max(1, cv::countNonZero(mask));
  std::vector<uint8_t> restore(count, 0);
  for (int c = 1; c < count; ++c) {
    restore[c] = area[c] > 1 && seeds_in[c] >= 2 && seeds_in[c] >= 0.25 * density * area[c];
    report->regions_restored += restore[c];
  }
  if (report->regions_restored > 0) {
    for (int row = 0; row < components.rows; ++row) {
      const int* c = components.ptr<int>(row);
      uint8_t* out = mask.ptr<uint8_t>(row);
      for (int col = 0; col < components.cols; ++col) {
        if (restore[c[col]]) out[col] = 255;
      }
    }
  }
}

// Back at full size: along the outline, within the blur of the scaling, the colour rule
// decides per pixel.
void RefineOutlineAtFullSize(const cv::Mat& rgb, const BackdropModel& model, double tolerance,
                             double scale, const cv::Mat& inside_box, cv::Mat* mask_io) {
  cv::Mat& mask = *mask_io;
  cv::resize(mask, mask, rgb.size(), 0, 0, cv::INTER_LINEAR);
  cv::threshold(mask, mask, 127, 255, cv::THRESH_BINARY);
  // Along the outline, within the blur of the scaling, the colour rule decides per pixel.
  const int reach = static_cast<int>(std::ceil(1.0 / scale)) + 1;
  const cv::Mat kernel = cv::Mat::ones(2 * reach + 1, 2 * reach + 1, CV_8U);
  cv::Mat grown, shrunk, full_box;
  cv::dilate(mask, grown, kernel);
  cv::erode(mask, shrunk, kernel);
  cv::resize(inside_box, full_box, rgb.size(), 0, 0, cv::INTER_NEAREST);
  const int full_frame[4] = {model.frame[0], model.frame[1], model.frame[2], model.frame[3]};
  const BorderBand full_band = MakeBand(rgb, full_frame);
  for (int row = 0; row < rgb.rows; ++row) {
    const uint8_t* g = grown.ptr<uint8_t>(row);
    const uint8_t* e = shrunk.ptr<uint8_t>(row);
    const uint8_t* b = full_box.ptr<uint8_t>(row);
    uint8_t* out = mask.ptr<uint8_t>(row);
    const cv::Vec3b* pixels = rgb.ptr<cv::Vec3b>(row);
    for (int col = 0; col < rgb.cols; ++col) {
      if (g[col] == e[col]) continue;  // not near the outline
      const bool object = b[col] != 0 && !full_band.InFrame(row, col, rgb.rows, rgb.cols) &&
                          BackdropDistance(ToVector(pixels[col]), model, 1.0, 1.0) > tolerance;
      // Near the outline a pixel stays object only when its colour is not the backdrop's,
      // and becomes object only when it is neither backdrop nor a shade of it.
      out[col] = out[col] != 0 ? (object ? 255 : 0)
                               : (object && BackdropDistance(ToVector(pixels[col]), model,
                                                             kShadowGain, kLightGain) >
                                                tolerance
                                      ? 255
                                      : 0);
    }
  }
}

}  // namespace

cv::Mat ObjectMaskFromModel(const cv::Mat& rgb,
                            const BackdropModel& model,
                            const BackgroundOptions& options,
                            const std::vector<Eigen::Vector2d>& object_seeds,
                            const std::vector<cv::Point>& box_hull,
                            ObjectMaskReport* report) {
  const double tolerance = options.tolerance;
  const bool refine = options.refine;
  CHECK_EQ(rgb.type(), CV_8UC3);
  CHECK(model.found);
  ObjectMaskReport local;
  if (report == nullptr) report = &local;
  *report = ObjectMaskReport();
  // GrabCut works on at most kWorkSide pixels a side; the result is scaled back, and its
  // outline re-decided by the colour rule at full resolution.
  constexpr double kWorkSide = 320.0;
  const double scale = std::min(1.0, kWorkSide / std::max(rgb.rows, rgb.cols));
  cv::Mat work = rgb;
  if (scale < 1.0) cv::resize(rgb, work, cv::Size(), scale, scale, cv::INTER_AREA);
  int frame[4];
  for (int k = 0; k < 4; ++k) frame[k] = static_cast<int>(std::ceil(model.frame[k] * scale));
  const BorderBand band = MakeBand(work, frame);

  const cv::Mat inside_box = VolumeOutlineMask(work.size(), scale, box_hull);
  report->cut_to_box = box_hull.size() >= 3;
  cv::Mat reached;
  const cv::Mat colour_class = ColourClasses(work, model, tolerance, band, &reached);
  cv::Mat colour_rule;
  std::vector<cv::Point> seed_pixels;
  int object_like = 0, backdrop_like = 0;
  const cv::Mat labels = GrabCutLabels(colour_class, reached, inside_box, object_seeds, scale,
                                       &colour_rule, &seed_pixels, &object_like, &backdrop_like,
                                       report);
  cv::Mat mask;
  if (refine && object_like >= 64 && backdrop_like >= 64) {
    mask = RunGrabCut(work, labels, inside_box, report);
  }
  if (!mask.empty() && !seed_pixels.empty()) {
    RestoreSeededRegions(colour_rule, inside_box, seed_pixels, &mask, report);
  }
  if (mask.empty()) mask = colour_rule & inside_box;
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::Mat::ones(3, 3, CV_8U));
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, cv::Mat::ones(5, 5, CV_8U));
  if (scale < 1.0) RefineOutlineAtFullSize(rgb, model, tolerance, scale, inside_box, &mask);
  report->object_share = static_cast<double>(cv::countNonZero(mask)) / mask.total();
  return mask;
}

}  // namespace raycarve
