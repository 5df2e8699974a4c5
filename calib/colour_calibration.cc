#include "calib/colour_calibration.h"

#include <cmath>
#include <map>
#include <sstream>

#include <ceres/ceres.h>

namespace raycarve {
namespace {

// One observation: gain * colour + offset - observed, per channel.
struct ObservationResidual {
  explicit ObservationResidual(const Eigen::Vector3d& observed) : observed_(observed) {}
  template <typename T>
  bool operator()(const T* gain, const T* offset, const T* colour, T* residual) const {
    for (int c = 0; c < 3; ++c) residual[c] = gain[c] * colour[c] + offset[c] - T(observed_[c]);
    return true;
  }
  Eigen::Vector3d observed_;
};

// The prior: gain 1 and offset 0, weighted (offset in units of 255).
struct PriorResidual {
  explicit PriorResidual(double weight) : weight_(weight) {}
  template <typename T>
  bool operator()(const T* gain, const T* offset, T* residual) const {
    for (int c = 0; c < 3; ++c) {
      residual[c] = T(weight_ * 255.0) * (gain[c] - T(1.0));
      residual[3 + c] = T(weight_) * offset[c];
    }
    return true;
  }
  double weight_;
};

// Bilinear RGB at a COLMAP pixel (x, y) of a CV_8UC3 image; false outside the usable pixels.
bool Sample(const CalibratedView& view, const Eigen::Vector2d& pixel, Eigen::Vector3d* rgb) {
  const double x = pixel.x() - 0.5, y = pixel.y() - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= view.width || y0 + 1 >= view.height) return false;
  const double fx = x - x0, fy = y - y0;
  *rgb = Eigen::Vector3d::Zero();
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      const int row = y0 + dy, col = x0 + dx;
      if (!view.valid.empty() && view.valid.at<uint8_t>(row, col) == 0) return false;
      if (!view.mask.empty() && view.mask.at<uint8_t>(row, col) == 0) return false;
      const cv::Vec3b& p = view.image.at<cv::Vec3b>(row, col);
      const double w = (dx ? fx : 1.0 - fx) * (dy ? fy : 1.0 - fy);
      *rgb += w * Eigen::Vector3d(p[0], p[1], p[2]);
    }
  }
  return true;
}

struct Observation {
  int view = 0;
  Eigen::Vector3d rgb;
};

double MeanSpread(const std::vector<std::vector<Observation>>& tracks,
                  const std::vector<ColourCorrection>& corrections) {
  double total = 0.0;
  for (const std::vector<Observation>& track : tracks) {
    std::vector<Eigen::Vector3d> colours;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Observation& o : track) {
      const ColourCorrection& k = corrections[o.view];
      colours.push_back((o.rgb - k.offset).cwiseQuotient(k.gain));
      mean += colours.back() / track.size();
    }
    double sum = 0.0;
    for (const Eigen::Vector3d& c : colours) sum += (c - mean).squaredNorm();
    total += std::sqrt(sum / colours.size());
  }
  return tracks.empty() ? 0.0 : total / tracks.size();
}

}  // namespace

std::string ColourCalibration::Summary() const {
  std::ostringstream text;
  text.precision(3);
  text << "colour calibration from " << points_used << " sparse points (" << observations_used
       << " observations): their spread across photos " << spread_before << " -> " << spread_after
       << " RGB";
  return text.str();
}

bool ColourCalibrationPays(const ColourCalibration& calibration) {
  return calibration.points_used > 0 &&
         calibration.spread_after <= kColourCalibrationPays * calibration.spread_before;
}

bool ColourCalibrationModeFromString(const std::string& text, ColourCalibrationMode* mode) {
  if (text == "auto") {
    *mode = ColourCalibrationMode::kAuto;
  } else if (text == "1" || text == "true") {
    *mode = ColourCalibrationMode::kOn;
  } else if (text == "0" || text == "false") {
    *mode = ColourCalibrationMode::kOff;
  } else {
    return false;
  }
  return true;
}

ColourCalibration EstimateColourCalibration(const Reconstruction& reconstruction,
                                            const std::vector<CalibratedView>& views,
                                            const ColourCalibrationOptions& options) {
  ColourCalibration result;
  std::map<image_t, int> view_of;
  for (size_t v = 0; v < views.size(); ++v) {
    view_of[views[v].image_id] = static_cast<int>(v);
    ColourCorrection correction;
    correction.image_id = views[v].image_id;
    correction.name = views[v].name;
    result.corrections.push_back(correction);
  }
  std::vector<std::vector<Observation>> tracks;
  for (const auto& [id, point] : reconstruction.points3D) {
    std::vector<Observation> track;
    for (const TrackElement& element : point.track) {
      const auto found = view_of.find(element.image_id);
      if (found == view_of.end()) continue;
      const CalibratedView& view = views[found->second];
      if (!(view.Depth(point.xyz) > 0.0)) continue;
      Observation observation;
      observation.view = found->second;
      if (Sample(view, view.Project(point.xyz), &observation.rgb)) track.push_back(observation);
    }
    if (static_cast<int>(track.size()) >= options.min_track_length) tracks.push_back(track);
  }
  result.points_used = static_cast<int>(tracks.size());
  if (tracks.empty()) return result;
  result.spread_before = MeanSpread(tracks, result.corrections);

  std::vector<Eigen::Vector3d> gains(views.size(), Eigen::Vector3d::Ones());
  std::vector<Eigen::Vector3d> offsets(views.size(), Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> colours(tracks.size(), Eigen::Vector3d::Zero());
  ceres::Problem problem;
  std::vector<bool> used(views.size(), false);
  for (size_t j = 0; j < tracks.size(); ++j) {
    for (const Observation& o : tracks[j]) colours[j] += o.rgb / tracks[j].size();
    for (const Observation& o : tracks[j]) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ObservationResidual, 3, 3, 3, 3>(
              new ObservationResidual(o.rgb)),
          new ceres::HuberLoss(options.loss_scale), gains[o.view].data(), offsets[o.view].data(),
          colours[j].data());
      used[o.view] = true;
      ++result.corrections[o.view].observations;
      ++result.observations_used;
    }
  }
  for (size_t v = 0; v < views.size(); ++v) {
    if (!used[v]) continue;
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorResidual, 6, 3, 3>(
                                 new PriorResidual(options.prior_weight)),
                             nullptr, gains[v].data(), offsets[v].data());
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_SCHUR;
  solver.max_num_iterations = 50;
  // Corrections to a tenth of an RGB unit need no more: 8 iterations instead of 45 on dinoRing
  // (48 photos, 18,238 observations), 0.17 s instead of 1.0, the same spreads to 3 digits.
  solver.function_tolerance = 1e-4;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  for (size_t v = 0; v < views.size(); ++v) {
    if (!used[v]) continue;
    result.corrections[v].gain = gains[v].cwiseMax(1e-3);
    result.corrections[v].offset = offsets[v];
  }
  result.spread_after = MeanSpread(tracks, result.corrections);
  return result;
}

void ApplyColourCalibration(const ColourCalibration& calibration,
                            std::vector<CalibratedView>* views) {
  for (size_t v = 0; v < views->size() && v < calibration.corrections.size(); ++v) {
    const ColourCorrection& k = calibration.corrections[v];
    cv::Mat& image = (*views)[v].image;
    uint8_t table[3][256];
    for (int c = 0; c < 3; ++c) {
      for (int value = 0; value < 256; ++value) {
        table[c][value] = cv::saturate_cast<uint8_t>(std::lround((value - k.offset[c]) / k.gain[c]));
      }
    }
    for (int row = 0; row < image.rows; ++row) {
      cv::Vec3b* pixel = image.ptr<cv::Vec3b>(row);
      for (int col = 0; col < image.cols; ++col) {
        for (int c = 0; c < 3; ++c) pixel[col][c] = table[c][pixel[col][c]];
      }
    }
  }
}

}  // namespace raycarve
