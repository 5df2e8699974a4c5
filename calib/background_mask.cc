#include "calib/background_mask.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <glog/logging.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/input_error.h"

namespace raycarve {

bool BackgroundOptions::IsValid(std::string* reason) const {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    *reason = "background tolerance must be a positive number";
    return false;
  }
  if (mode == Mode::kColour && !((colour.array() >= 0).all() && (colour.array() <= 255).all())) {
    *reason = "background colour must be three numbers in [0, 255]";
    return false;
  }
  return true;
}

BackgroundOptions::Mode ParseBackground(const std::string& text, Eigen::Vector3d* colour) {
  if (text == "none") return BackgroundOptions::Mode::kNone;
  if (text == "auto") return BackgroundOptions::Mode::kAuto;
  std::vector<double> values;
  bool numbers = true;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    char* end = nullptr;
    values.push_back(std::strtod(item.c_str(), &end));
    numbers = numbers && !item.empty() && end == item.c_str() + item.size();
  }
  if (!numbers || values.size() != 3) {
    throw InputError("--background_colour '" + text + "' is not none, auto or R,G,B (e.g. 0,0,0)");
  }
  *colour = Eigen::Vector3d(values[0], values[1], values[2]);
  return BackgroundOptions::Mode::kColour;
}

bool EstimateBackdropColour(const cv::Mat& rgb, double tolerance, Eigen::Vector3d* colour) {
  CHECK_EQ(rgb.type(), CV_8UC3);
  const int band_rows = std::max(1, rgb.rows / 50), band_cols = std::max(1, rgb.cols / 50);
  std::vector<cv::Vec3b> border;
  for (int row = 0; row < rgb.rows; ++row) {
    const bool edge_row = row < band_rows || row >= rgb.rows - band_rows;
    for (int col = 0; col < rgb.cols; ++col) {
      if (edge_row || col < band_cols || col >= rgb.cols - band_cols) {
        border.push_back(rgb.at<cv::Vec3b>(row, col));
      }
    }
  }
  for (int k = 0; k < 3; ++k) {
    std::vector<int> channel(border.size());
    for (size_t i = 0; i < border.size(); ++i) channel[i] = border[i][k];
    std::nth_element(channel.begin(), channel.begin() + channel.size() / 2, channel.end());
    (*colour)[k] = channel[channel.size() / 2];
  }
  size_t close = 0;
  for (const cv::Vec3b& p : border) {
    close += (Eigen::Vector3d(p[0], p[1], p[2]) - *colour).norm() <= tolerance;
  }
  return close >= 0.8 * border.size();
}

cv::Mat ObjectMaskFromBackdrop(const cv::Mat& rgb, const Eigen::Vector3d& backdrop, double tolerance) {
  CHECK_EQ(rgb.type(), CV_8UC3);
  cv::Mat mask(rgb.size(), CV_8UC1);
  const double tolerance2 = tolerance * tolerance;
  for (int row = 0; row < rgb.rows; ++row) {
    const cv::Vec3b* pixels = rgb.ptr<cv::Vec3b>(row);
    uint8_t* out = mask.ptr<uint8_t>(row);
    for (int col = 0; col < rgb.cols; ++col) {
      double d2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double d = pixels[col][k] - backdrop[k];
        d2 += d * d;
      }
      out[col] = d2 > tolerance2 ? 255 : 0;
    }
  }
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::Mat::ones(3, 3, CV_8U));
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, cv::Mat::ones(5, 5, CV_8U));
  return mask;
}

}  // namespace raycarve

namespace raycarve {
namespace {

// The pixels of line `d` from one side: 0 top, 1 bottom, 2 left, 3 right.
std::vector<cv::Vec3b> LinePixels(const cv::Mat& rgb, int side, int d) {
  std::vector<cv::Vec3b> line;
  if (side < 2) {
    const int row = side == 0 ? d : rgb.rows - 1 - d;
    for (int col = 0; col < rgb.cols; ++col) line.push_back(rgb.at<cv::Vec3b>(row, col));
  } else {
    const int col = side == 2 ? d : rgb.cols - 1 - d;
    for (int row = 0; row < rgb.rows; ++row) line.push_back(rgb.at<cv::Vec3b>(row, col));
  }
  return line;
}

Eigen::Vector3d MedianColour(const std::vector<cv::Vec3b>& pixels) {
  Eigen::Vector3d median = Eigen::Vector3d::Zero();
  if (pixels.empty()) return median;
  std::vector<int> channel(pixels.size());
  for (int k = 0; k < 3; ++k) {
    for (size_t i = 0; i < pixels.size(); ++i) channel[i] = pixels[i][k];
    std::nth_element(channel.begin(), channel.begin() + channel.size() / 2, channel.end());
    median[k] = channel[channel.size() / 2];
  }
  return median;
}

Eigen::Vector3d ToVector(const cv::Vec3b& p) { return Eigen::Vector3d(p[0], p[1], p[2]); }

double ShareWithin(const std::vector<cv::Vec3b>& pixels, const Eigen::Vector3d& colour,
                   double tolerance) {
  size_t close = 0;
  for (const cv::Vec3b& p : pixels) close += (ToVector(p) - colour).norm() <= tolerance;
  return pixels.empty() ? 0.0 : static_cast<double>(close) / pixels.size();
}

// Width of the frame on one side: the outermost lines that are each uniform (90% of their
// pixels within tolerance of their median) and differ from the line just inside the widest
// frame allowed.
int FrameWidth(const cv::Mat& rgb, int side, double tolerance) {
  const int extent = side < 2 ? rgb.rows : rgb.cols;
  const int widest = static_cast<int>(extent * 0.025);
  if (widest < 1 || 2 * widest + 4 > extent) return 0;
  const Eigen::Vector3d inside = MedianColour(LinePixels(rgb, side, widest + 1));
  int width = 0;
  for (int d = 0; d < widest; ++d) {
    const std::vector<cv::Vec3b> line = LinePixels(rgb, side, d);
    const Eigen::Vector3d median = MedianColour(line);
    if (ShareWithin(line, median, tolerance) < 0.9 || (median - inside).norm() <= tolerance) break;
    width = d + 1;
  }
  return width;
}

// The band of 2% of rows and columns inside the frame, as `border` (pixels, at most ~40,000
// by a regular stride) and as a test of whether a pixel lies in it.
struct BorderBand {
  int top, bottom, left, right;  // first row/col inside the band's inner edge, per side
  int frame[4];
  bool InFrame(int row, int col, int rows, int cols) const {
    return row < frame[0] || row >= rows - frame[1] || col < frame[2] || col >= cols - frame[3];
  }
  bool InBand(int row, int col, int rows, int cols) const {
    return !InFrame(row, col, rows, cols) &&
           (row < top || row >= rows - bottom || col < left || col >= cols - right);
  }
};

BorderBand MakeBand(const cv::Mat& rgb, const int frame[4]) {
  BorderBand band;
  for (int k = 0; k < 4; ++k) band.frame[k] = frame[k];
  const int band_rows = std::max(1, rgb.rows / 50), band_cols = std::max(1, rgb.cols / 50);
  band.top = frame[0] + band_rows;
  band.bottom = frame[1] + band_rows;
  band.left = frame[2] + band_cols;
  band.right = frame[3] + band_cols;
  return band;
}

}  // namespace

std::string BackdropModel::Summary() const {
  std::ostringstream text;
  if (!found) {
    text << "no plain backdrop (the border needs more than " << kMaxBackdropColours
         << " colours; " << std::lround(100.0 * explained) << "% explained";
    if (!object_colours.empty()) {
      text << ", after " << std::lround(100.0 * object_border_share)
           << "% in the object's colours was set aside";
    }
    text << ")";
    return text.str();
  }
  text << colours.size() << (colours.size() == 1 ? " colour (" : " colours (");
  for (size_t i = 0; i < colours.size(); ++i) {
    text << (i > 0 ? "; " : "") << std::lround(colours[i][0]) << "," << std::lround(colours[i][1])
         << "," << std::lround(colours[i][2]) << " " << std::lround(100.0 * shares[i]) << "%";
  }
  text << ")";
  const int widest = std::max({frame[0], frame[1], frame[2], frame[3]});
  if (widest > 0) {
    text << ", frame " << frame[0] << "/" << frame[1] << "/" << frame[2] << "/" << frame[3]
         << " px";
  }
  if (!object_colours.empty()) {
    text << "; " << std::lround(100.0 * object_border_share)
         << "% of the border in the object's colours (sparse points) set aside";
  }
  return text.str();
}

namespace {

// Clusters `samples` (CV_32F, one RGB row each) into `count` colours with a fixed random state
// (the same clusters on every run and thread); returns each sample's cluster.
cv::Mat ClusterColours(const cv::Mat& samples, int count, cv::Mat* centres) {
  cv::RNG& rng = cv::theRNG();
  const uint64 saved_state = rng.state;
  rng.state = 0x9e3779b97f4a7c15ULL;
  cv::Mat labels;
  cv::kmeans(samples, count, labels,
             cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 20, 0.5), 2,
             cv::KMEANS_PP_CENTERS, *centres);
  rng.state = saved_state;
  return labels;
}

cv::Mat SampleMatrix(const std::vector<cv::Vec3b>& pixels) {
  cv::Mat samples(static_cast<int>(pixels.size()), 3, CV_32F);
  for (size_t i = 0; i < pixels.size(); ++i) {
    for (int k = 0; k < 3; ++k) samples.at<float>(static_cast<int>(i), k) = pixels[i][k];
  }
  return samples;
}

// Sets aside the pixels of `border` in the object's colours (EstimateBackdropModel): the border's
// colours are clustered; a cluster is the object's when the share of the seeds' colours within
// `tolerance` of its colour is at least kObjectSeedDensity times the share of the photo's pixels
// (sampled) within `tolerance` of it. Its pixels leave `border`; `model` records which and how
// many.
void SetAsideObjectColours(const cv::Mat& rgb, double tolerance,
                           const std::vector<Eigen::Vector2d>& seeds,
                           std::vector<cv::Vec3b>* border, BackdropModel* model) {
  std::vector<Eigen::Vector3d> seed_colours;
  for (const Eigen::Vector2d& seed : seeds) {
    const int col = static_cast<int>(std::floor(seed.x()));
    const int row = static_cast<int>(std::floor(seed.y()));
    if (col < 0 || row < 0 || col >= rgb.cols || row >= rgb.rows) continue;
    seed_colours.push_back(ToVector(rgb.at<cv::Vec3b>(row, col)));
  }
  if (static_cast<int>(seed_colours.size()) < kMinColourSeeds ||
      static_cast<int>(border->size()) < kMaxBackdropColours) {
    return;
  }
  cv::Mat centres;
  const cv::Mat labels = ClusterColours(SampleMatrix(*border), kMaxBackdropColours, &centres);
  std::vector<std::vector<cv::Vec3b>> members(kMaxBackdropColours);
  for (size_t i = 0; i < border->size(); ++i) {
    members[labels.at<int>(static_cast<int>(i))].push_back((*border)[i]);
  }
  // The photo's pixels on a grid of about 40,000.
  const int step = std::max(1, static_cast<int>(std::sqrt(rgb.total() / 40000.0)));
  std::vector<Eigen::Vector3d> photo;
  for (int row = step / 2; row < rgb.rows; row += step) {
    for (int col = step / 2; col < rgb.cols; col += step) {
      photo.push_back(ToVector(rgb.at<cv::Vec3b>(row, col)));
    }
  }
  std::vector<bool> object(kMaxBackdropColours, false);
  for (int c = 0; c < kMaxBackdropColours; ++c) {
    if (members[c].size() < 0.03 * border->size()) continue;  // as below: too few to judge
    const Eigen::Vector3d colour = MedianColour(members[c]);
    const auto share = [&colour, tolerance](const std::vector<Eigen::Vector3d>& colours) {
      int64_t close = 0;
      for (const Eigen::Vector3d& other : colours) close += (other - colour).norm() <= tolerance;
      return static_cast<double>(close) / std::max<size_t>(1, colours.size());
    };
    object[c] = share(seed_colours) >= kObjectSeedDensity * share(photo);
    if (object[c]) model->object_colours.push_back(colour);
  }
  if (model->object_colours.empty()) return;
  std::vector<cv::Vec3b> kept;
  for (size_t i = 0; i < border->size(); ++i) {
    if (!object[labels.at<int>(static_cast<int>(i))]) kept.push_back((*border)[i]);
  }
  model->object_border_share = 1.0 - static_cast<double>(kept.size()) / border->size();
  border->swap(kept);
}

// Describes `border` by the fewest colours (1 to kMaxBackdropColours) that bring 80% of it within
// `tolerance`: sets `model`'s found, colours, shares and explained.
void DescribeBorder(const std::vector<cv::Vec3b>& border, double tolerance, BackdropModel* model) {
  model->found = false;
  model->colours.clear();
  model->shares.clear();
  model->explained = 0.0;
  if (border.size() < 16) return;
  // One colour: the median, as EstimateBackdropColour.
  const Eigen::Vector3d median = MedianColour(border);
  model->explained = ShareWithin(border, median, tolerance);
  if (model->explained >= 0.8) {
    model->found = true;
    model->colours = {median};
    model->shares = {model->explained};
    return;
  }
  const cv::Mat samples = SampleMatrix(border);
  for (int count = 2; count <= kMaxBackdropColours; ++count) {
    cv::Mat centres;
    const cv::Mat labels = ClusterColours(samples, count, &centres);
    std::vector<std::vector<cv::Vec3b>> members(count);
    for (size_t i = 0; i < border.size(); ++i) {
      members[labels.at<int>(static_cast<int>(i))].push_back(border[i]);
    }
    std::vector<Eigen::Vector3d> colours;
    for (const auto& cluster : members) {
      // A cluster of under 3% of the border is the object touching it, or noise.
      if (cluster.size() >= 0.03 * border.size()) colours.push_back(MedianColour(cluster));
    }
    size_t close = 0;
    std::vector<size_t> nearest_count(colours.size(), 0);
    for (const cv::Vec3b& p : border) {
      double best = std::numeric_limits<double>::infinity();
      size_t which = 0;
      for (size_t c = 0; c < colours.size(); ++c) {
        const double d = (ToVector(p) - colours[c]).norm();
        if (d < best) best = d, which = c;
      }
      if (best <= tolerance) ++close, ++nearest_count[which];
    }
    model->explained = static_cast<double>(close) / border.size();
    if (model->explained >= 0.8) {
      model->found = true;
      model->colours = colours;
      for (size_t c = 0; c < colours.size(); ++c) {
        model->shares.push_back(static_cast<double>(nearest_count[c]) / border.size());
      }
      return;
    }
  }
}

}  // namespace

BackdropModel EstimateBackdropModel(const cv::Mat& rgb, double tolerance,
                                    const std::vector<Eigen::Vector2d>& object_seeds) {
  CHECK_EQ(rgb.type(), CV_8UC3);
  BackdropModel model;
  for (int side = 0; side < 4; ++side) model.frame[side] = FrameWidth(rgb, side, tolerance);
  const BorderBand band = MakeBand(rgb, model.frame);
  std::vector<cv::Vec3b> border;
  const int64_t band_pixels = 2LL * (band.top - model.frame[0]) * rgb.cols +
                              2LL * (band.left - model.frame[2]) * rgb.rows;
  const int stride = static_cast<int>(std::max<int64_t>(1, band_pixels / 40000));
  int64_t index = 0;
  for (int row = 0; row < rgb.rows; ++row) {
    for (int col = 0; col < rgb.cols; ++col) {
      if (band.InBand(row, col, rgb.rows, rgb.cols) && index++ % stride == 0) {
        border.push_back(rgb.at<cv::Vec3b>(row, col));
      }
    }
  }
  DescribeBorder(border, tolerance, &model);
  // A border that is not a few plain colours is a natural scene, whatever lies on it; one that
  // is may owe some of its colours to the object running out of the frame.
  if (!model.found) return model;
  SetAsideObjectColours(rgb, tolerance, object_seeds, &border, &model);
  if (!model.object_colours.empty()) DescribeBorder(border, tolerance, &model);
  return model;
}

double BackdropDistance(const Eigen::Vector3d& rgb, const BackdropModel& model, double darkest,
                        double brightest) {
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& colour : model.colours) {
    const double norm2 = colour.squaredNorm();
    const double scale =
        norm2 < 1e-9 ? 1.0 : std::clamp(rgb.dot(colour) / norm2, darkest, brightest);
    best = std::min(best, (rgb - scale * colour).norm());
  }
  return best;
}

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
                            double tolerance,
                            bool refine,
                            const std::vector<Eigen::Vector2d>& object_seeds,
                            const std::vector<cv::Point>& box_hull,
                            ObjectMaskReport* report) {
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
