#include "calib/background_mask.h"

#include "calib/border_band.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <glog/logging.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/border_band.h"
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

}  // namespace raycarve
